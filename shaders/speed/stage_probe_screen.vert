#version 450
// The stage probe's full-screen triangle (stage_probe.frag): it covers the
// viewport's width * height pixels, each once.
void main() {
  vec2 corner = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  gl_Position = vec4(corner * 2.0 - 1.0, 0.5, 1.0);
}
