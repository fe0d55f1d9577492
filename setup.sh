#!/usr/bin/env bash
# Installs, from Debian 12's own packages, whatever depthbench needs and this
# machine lacks. Run as root (CI does) or with sudo available.
#   ./setup.sh          what building and running depthbench needs
#   ./setup.sh --tests  that, plus what the test suite needs
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-tools
  libglm-dev libceres-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfmt-dev
  libmpfr-dev libgmp-dev libsqlite3-dev libbenchmark-dev
  # The Vulkan backend's tests run with the validation layer on; the
  # libFuzzer targets and the sanitizer build need clang's runtime.
  vulkan-validationlayers googletest libgtest-dev clang-14 libclang-rt-14-dev
)
if [[ "${1:-}" == "--tests" ]]; then
  packages+=()
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
