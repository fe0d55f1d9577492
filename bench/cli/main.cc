// depthbench: a test bench and fuzzer for the shader code that
// reconstructs view- and world-space position from a depth buffer.
#include "bench/cli/app.h"

int main(int argc, char** argv) { return depthbench::cli::RunDepthbench(argc, argv); }
