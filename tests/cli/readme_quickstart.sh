#!/usr/bin/env bash
# The README's quick start, run verbatim: the commands between <!-- quickstart-model --> and
# <!-- /quickstart-model --> (a model file captured, ground truth, encode, calf-info, calf-verify,
# headless playback against the ground truth), then those of the quickstart-ingest block on a
# Seurat manifest made from the first capture (tests/capture/foreign_from_capture). Passes when
# every command succeeds, both playbacks print their mean PSNR and the ingested capture plays
# within 1 dB of the capture it was made from (the ingest of the same views keeps the picture).
# Usage: readme_quickstart.sh README BIN_DIR FOREIGN WORK_DIR
set -euo pipefail
readme=$1 bin=$2 foreign=$3 work=$4
block() {  # the fenced commands between <!-- NAME --> and <!-- /NAME -->
  awk -v first="<!-- $1 -->" -v last="<!-- /$1 -->" '
    $0 == first { inside = 1; next }
    $0 == last { inside = 0 }
    inside && /^```/ { fence = !fence; next }
    inside && fence { print }' "$readme"
}
model=$(block quickstart-model)
ingest=$(block quickstart-ingest)
if [ -z "$model" ] || [ -z "$ingest" ]; then
  echo "readme_quickstart: README.md has no quickstart-model / quickstart-ingest block"
  exit 1
fi
model_file=$(sed -n 's/^MODEL=//p' <<<"$model")
if [ ! -f "$model_file" ]; then  # Debian's assimp-testmodels, which tools/setup.sh installs
  echo "readme_quickstart: $model_file missing (assimp-testmodels)"
  [ "${CI:-}" = "true" ] && exit 1
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
cd "$work"
export PATH="$bin:$PATH"
bash -euo pipefail -c "$model" >model.log 2>&1 || { cat model.log; echo "readme_quickstart: the model block failed"; exit 1; }
cat model.log
"$foreign" seurat spider seurat ray_depth
bash -euo pipefail -c "$ingest" >ingest.log 2>&1 || { cat ingest.log; echo "readme_quickstart: the ingest block failed"; exit 1; }
cat ingest.log
native=$(sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p' model.log)
ingested=$(sed -n 's/^mean PSNR \([0-9.]*\) dB.*/\1/p' ingest.log)
if [ -z "$native" ] || [ -z "$ingested" ] || [ ! -s spider.png ]; then
  echo "readme_quickstart: a playback printed no mean PSNR, or the contact sheet is missing"
  exit 1
fi
if ! awk -v a="$native" -v b="$ingested" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1) }'; then
  echo "readme_quickstart: the ingested capture plays at $ingested dB, the capture at $native dB"
  exit 1
fi
echo "readme_quickstart: the README's commands ran; capture $native dB, ingested $ingested dB"
