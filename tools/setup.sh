#!/usr/bin/env bash
# Installs every Debian package calf needs to build, test and run its demo.
# Idempotent: packages already installed are skipped, and when all are present
# apt-get is not called at all (so a second run costs well under a second).
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates
  # format: compression and hashing
  libzstd-dev liblzma-dev libxxhash-dev
  # capture sets: images and manifests
  libopenimageio-dev libopenexr-dev libpng-dev nlohmann-json3-dev
  # command lines and text
  libcli11-dev libfmt-dev
  # threads
  libtbb-dev
  # block codecs
  libsquish-dev
  # capture ray tracer and scene loading
  libembree-dev libassimp-dev
  # textured models the texture tests load when present (BoxTextured, CesiumMilkTruck)
  assimp-testmodels
  # player: GL, window, headless, maths, HUD
  libglm-dev libglfw3-dev libosmesa6-dev libgl-dev libopengl-dev libglx-dev libegl-dev libimgui-dev xvfb xauth
  # tests and benchmarks; clang + its runtime for the libFuzzer run of tools/test.sh; clang-format
  # for the style check
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev clang-format
  # measurement peers and plots
  ffmpeg zstd xz-utils gnuplot-nox
  # sharded pipeline (docs/FARM.md): the single-node Slurm of tests/cli/slurm_pipeline.sh, GNU
  # parallel for tools/farm/parallel_run.sh, GNU time for the per-task time and memory lines
  slurmctld slurmd slurm-client munge parallel time
)

# node and npm for the glTF-Validator below, from Debian when the machine has none.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# Khronos' glTF-Validator (npm), the second glTF reader of the export tests
# (tests/export/gltf_validate.js), pinned, into build/npm; node and npm from Debian when the
# machine has none.
GLTF_VALIDATOR_VERSION=2.0.0-dev.3.10
install_gltf_validator() {
  local dir
  dir="$(cd "$(dirname "$0")/.." && pwd)/build/npm"
  if [ -f "$dir/node_modules/gltf-validator/package.json" ] &&
     grep -q "\"version\": \"$GLTF_VALIDATOR_VERSION\"" "$dir/node_modules/gltf-validator/package.json"; then
    return
  fi
  mkdir -p "$dir"
  npm install --no-save --no-audit --no-fund --loglevel=error --prefix "$dir" \
    "gltf-validator@$GLTF_VALIDATOR_VERSION" >/dev/null
  echo "calf setup: glTF-Validator $GLTF_VALIDATOR_VERSION installed in $dir"
}
if [ ${#missing[@]} -eq 0 ]; then
  echo "calf setup: all ${#PACKAGES[@]} packages already installed"
  install_gltf_validator
  exit 0
fi

echo "calf setup: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "calf setup: done"
install_gltf_validator
