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
  libopenimageio-dev libopenexr-dev nlohmann-json3-dev
  # command lines and text
  libcli11-dev libfmt-dev
  # threads
  libtbb-dev
  # block codecs
  libsquish-dev
  # capture ray tracer and scene loading
  libembree-dev libassimp-dev
  # player: GL, window, headless, maths, HUD
  libglm-dev libglfw3-dev libosmesa6-dev libgl-dev libopengl-dev libglx-dev libegl-dev libimgui-dev xvfb xauth
  # tests and benchmarks; clang + its runtime for the libFuzzer run of tools/test.sh; clang-format
  # for the style check
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev clang-format
  # measurement peers and plots
  ffmpeg zstd xz-utils gnuplot-nox
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "calf setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "calf setup: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "calf setup: done"
