#!/bin/sh
# Packs depthbench for a machine that has a Vulkan driver but no package
# registry (a GPU box reached only by copying files to it): the installed
# program with its data folder (cmake --install: bin/depthbench and
# share/depthbench, the shaders and shared/ headers it compiles at run time
# among them), and every shared library it loads that such a machine may
# lack, the Vulkan loader (libvulkan.so.1) included. Run it again after
# every build; the folder it writes is self-contained, and the commit the
# program was built from is recorded in it (depthbench --version).
#
#   bench/tools/package_for_device.sh BUILD_DIR OUT_DIR
#   (copy OUT_DIR to the GPU machine, then there:)
#   OUT_DIR/run.sh list
#   OUT_DIR/run.sh speed --json speed.json
#
# Left out on purpose: the C library family (libc, libm, libpthread, libdl,
# librt, the dynamic loader) and the C++ runtime (libstdc++, libgcc_s),
# which every Linux machine has, in a version at least as new as the one
# this was built with (glibc 2.34 at most is required), and which the GPU
# driver loads too: two copies of them in one process is what breaks.
# The NVIDIA Vulkan driver (libGLX_nvidia.so.0) does not start without
# glvnd (libGLdispatch.so.0, libEGL.so.1, libGLX.so.0, libGL.so.1,
# libOpenGL.so.0, libGLESv2.so.2), which a GPU container image may lack:
# they are packed with what they need when this machine has them (Debian's
# libglvnd0, libegl1, libglx0, libgl1, libopengl0, libgles2), and run.sh
# points glvnd at the NVIDIA EGL vendor file when there is one.
set -eu

if [ $# -ne 2 ]; then
  echo "usage: $0 BUILD_DIR OUT_DIR" >&2
  exit 2
fi
build=$1
out=$2
binary="$build/bench/depthbench"
if [ ! -x "$binary" ]; then
  echo "$0: $binary does not exist or is not executable; build first (cmake --build $build)" >&2
  exit 2
fi

rm -rf "$out"
cmake --install "$build" --prefix "$out" >/dev/null
mkdir -p "$out/lib"

# Every library ldd resolves for the program and for glvnd, but the C and
# C++ runtimes.
glvnd=""
for name in libGLdispatch.so.0 libEGL.so.1 libGLX.so.0 libGL.so.1 libOpenGL.so.0 libGLESv2.so.2; do
  for dir in /usr/lib/x86_64-linux-gnu /lib/x86_64-linux-gnu; do
    if [ -e "$dir/$name" ]; then
      glvnd="$glvnd $dir/$name"
      break
    fi
  done
done
# The batch-building benchmark too, where it was built (bin/; it measures
# the host's share of a sweep on the GPU machine's own cores).
microbench="$build/bench/depthbench_batch_microbench"
if [ -x "$microbench" ]; then cp "$microbench" "$out/bin/"; else microbench=""; fi
for object in "$binary" $microbench $glvnd; do
  if [ "$object" != "$binary" ] && [ "$object" != "$microbench" ]; then cp -L "$object" "$out/lib/"; fi
  ldd "$object" | awk '$2 == "=>" && $3 ~ /^\// { print $3 }' | while read -r library; do
    case $(basename "$library") in
      libc.so.*|libm.so.*|libpthread.so.*|libdl.so.*|librt.so.*|ld-linux*|libstdc++.so.*|libgcc_s.so.*) ;;
      *) cp -L "$library" "$out/lib/" ;;
    esac
  done
done
if [ ! -e "$out/lib/libvulkan.so.1" ]; then
  echo "$0: ldd did not find libvulkan.so.1 for $binary" >&2
  exit 1
fi

cat > "$out/run.sh" <<'SCRIPT'
#!/bin/sh
# Runs the packed depthbench with its own libraries. Where no Vulkan driver
# is named (VK_DRIVER_FILES, VK_ICD_FILENAMES), the NVIDIA driver's manifest
# is used if one of its usual places holds it; likewise its glvnd EGL
# vendor file.
here=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -z "${VK_ICD_FILENAMES:-}" ]; then
  for manifest in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json \
                  /etc/vulkan/icd.d/nvidia_icd.json; do
    if [ -f "$manifest" ]; then
      export VK_DRIVER_FILES="$manifest"
      break
    fi
  done
fi
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ]; then
  for vendor in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json; do
    if [ -f "$vendor" ]; then
      export __EGL_VENDOR_LIBRARY_FILENAMES="$vendor"
      break
    fi
  done
fi
exec "$here/bin/depthbench" "$@"
SCRIPT
chmod +x "$out/run.sh"
du -sh "$out"
