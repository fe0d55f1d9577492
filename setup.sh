#!/usr/bin/env bash
# Installs, from Debian 12's own packages, whatever depthbench needs and this
# machine lacks. Run as root (CI does) or with sudo available.
#   ./setup.sh          what building and running depthbench needs
#   ./setup.sh --tests  that, plus what the test suite needs
# Then it installs the report page's plotting library (Vega-Lite, pinned in
# reports/package-lock.json) from npm's registry into reports/node_modules.
set -euo pipefail
cd "$(dirname "$0")"

packages=(
  build-essential cmake ninja-build pkg-config git
  glslang-dev glslang-tools spirv-tools
  libvulkan-dev mesa-vulkan-drivers vulkan-tools
  libglm-dev libceres-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfmt-dev
  libmpfr-dev libgmp-dev libsqlite3-dev libbenchmark-dev libopenexr-dev libpng-dev
  # The Vulkan backend's tests run with the validation layer on; the
  # libFuzzer targets and the sanitizer build need clang's runtime.
  vulkan-validationlayers googletest libgtest-dev clang-14 libclang-rt-14-dev
)
# npm fetches the plotting library; a machine with its own Node.js and npm
# (for example from NodeSource) keeps them.
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi
if [[ "${1:-}" == "--tests" ]]; then
  # The report test opens the page in a real headless browser and checks
  # results.json against its JSON Schema; the scheduler files' test reads
  # them as YAML.
  packages+=(chromium python3 python3-jsonschema python3-yaml)
elif [[ -n "${1:-}" ]]; then
  echo "setup: unknown option '$1'; allowed: --tests" >&2
  exit 2
fi

install_plot_library() {
  if [[ -f reports/node_modules/vega-embed/build/vega-embed.min.js ]] &&
     cmp -s reports/package-lock.json reports/node_modules/.installed-lock.json 2>/dev/null; then
    return
  fi
  echo "setup: installing the report's plotting library (npm ci --prefix reports)"
  npm ci --prefix reports --no-audit --no-fund --loglevel=error
  cp reports/package-lock.json reports/node_modules/.installed-lock.json
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
install_plot_library
