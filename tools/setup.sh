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
  # AV1 colour: SVT-AV1 encodes 4:2:0, libaom 4:4:4, dav1d decodes
  libsvtav1enc-dev libaom-dev libdav1d-dev
  # capture sets: images and manifests
  libopenimageio-dev libopenexr-dev libpng-dev nlohmann-json3-dev
  # command lines and text; man pages generated from each command's --help
  libcli11-dev libfmt-dev help2man man-db
  # threads
  libtbb-dev
  # block codecs
  libsquish-dev
  # capture ray tracer and scene loading
  libembree-dev libassimp-dev
  # export: glTF writer (header-only) and meshoptimizer (EXT_meshopt_compression); headless
  # Chromium, the browser of the three.js export test
  libtinygltf-dev libmeshoptimizer-dev chromium
  # textured models the texture tests load when present (BoxTextured, CesiumMilkTruck)
  assimp-testmodels
  # player: GL, window, headless, maths, HUD
  libglm-dev libglfw3-dev libosmesa6-dev libgl-dev libopengl-dev libglx-dev libegl-dev libimgui-dev xvfb xauth
  # tests and benchmarks; clang + its runtime for the libFuzzer run of tools/test.sh; clang-format
  # for the style check
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev clang-format
  # the clean-room conformance reader (tests/conformance/clean_room/calf_clean_room.py): Python
  # with its zstd and xxHash bindings, so that it reads the clips without calf
  python3 python3-zstandard python3-xxhash
  # measurement peers and plots
  ffmpeg zstd xz-utils gnuplot-nox
  # sharded pipeline (docs/FARM.md): the single-node Slurm of tests/cli/slurm_pipeline.sh, GNU
  # parallel for tools/farm/parallel_run.sh, GNU time for the per-task time and memory lines
  slurmctld slurmd slurm-client munge parallel time
  # Blender: the add-on's tests and the demo's optional part (blender/calf_capture, Cycles), and
  # the export's OBJ import test (tests/export/blender_compare.sh); numpy for Blender's glTF
  # exporter (tests/blender/export_gltf.py)
  blender python3-numpy
)

# node and npm for the glTF-Validator below, from Debian when the machine has none.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# The npm packages of the export tests, pinned, into build/npm: Khronos' glTF-Validator (the
# second glTF reader, tests/export/gltf_validate.js), three.js and playwright-core (the browser
# test, tests/export/three_compare.js, which drives Debian's chromium); and the web player's
# decoder (web/, docs/WEB.md): hash-wasm (XXH3-64, XXH64), fzstd (zstd) and xz-decompress
# (LZMA2, through xz-embedded in WebAssembly), each pure JavaScript or WebAssembly, for node and
# the browser alike; and for AV1 colour where WebCodecs has no AV1 decoder (node), libav.js's
# av1-opus variant (libaom's decoder in WebAssembly).
# node and npm from Debian when the machine has none.
NPM_PACKAGES=(gltf-validator@2.0.0-dev.3.10 three@0.187.0 playwright-core@1.64.1
              hash-wasm@4.13.0 fzstd@0.1.1 xz-decompress@0.2.3
              @libav.js/variant-av1-opus@6.10.9)
install_npm_packages() {
  local dir p name version
  dir="$(cd "$(dirname "$0")/.." && pwd)/build/npm"
  local wanted=()
  for p in "${NPM_PACKAGES[@]}"; do
    name="${p%@*}"
    version="${p##*@}"
    if ! [ -f "$dir/node_modules/$name/package.json" ] ||
       ! grep -q "\"version\": \"$version\"" "$dir/node_modules/$name/package.json"; then
      wanted+=("$p")
    fi
  done
  if [ ${#wanted[@]} -eq 0 ]; then return; fi
  mkdir -p "$dir"
  # All pinned packages at once: npm install --no-save removes what the command does not name.
  npm install --no-save --no-audit --no-fund --loglevel=error --prefix "$dir" \
    "${NPM_PACKAGES[@]}" >/dev/null
  echo "calf setup: ${NPM_PACKAGES[*]} installed in $dir"
}
if [ ${#missing[@]} -eq 0 ]; then
  echo "calf setup: all ${#PACKAGES[@]} packages already installed"
  install_npm_packages
  exit 0
fi

echo "calf setup: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "calf setup: done"
install_npm_packages
