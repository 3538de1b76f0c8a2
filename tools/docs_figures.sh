#!/usr/bin/env bash
# Re-measures the figures the docs quote and rewrites them in place, between markers
# <!-- figures:NAME --> and <!-- /figures:NAME --> (each block is replaced whole, so a second run
# on the same tree changes nothing but the figures). Today one block: README.md's "demo", the
# demo's wall time, its light field's PSNR / SSIM against ground truth and its clip's bytes, with
# the commit, the machine and its load when measured.
#   tools/docs_figures.sh                 runs tools/demo.sh (setup and build included), then rewrites
#   tools/docs_figures.sh --report FILE   rewrites from a saved demo report (tools/demo.sh | tee FILE)
set -euo pipefail
cd "$(dirname "$0")/.."
report=""
if [ "${1:-}" = "--report" ]; then
  report=${2:?usage: tools/docs_figures.sh [--report FILE]}
fi
load=$(cut -d' ' -f1 /proc/loadavg)
if [ -z "$report" ]; then
  mkdir -p build/docs-figures
  report=build/docs-figures/demo-report.txt
  tools/demo.sh | tee "$report"
fi
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
cores=$(nproc)
total=$(sed -n 's/^total *\([0-9.]*\) s wall.*/\1/p' "$report")
quality=$(sed -n 's/^quality *mean PSNR \([0-9.]*\) dB, mean SSIM \([0-9.]*\).*/\1 \2/p' "$report")
clip=$(sed -n 's/^clip *[^:]*: \([0-9.]*\) MB.*/\1/p' "$report")
if [ -z "$total" ] || [ -z "$quality" ] || [ -z "$clip" ]; then
  echo "docs_figures: $report has no total / quality / clip line (a demo report?)" >&2
  exit 1
fi
read -r psnr ssim <<<"$quality"
text="The demo took **$total s** wall on this $cores-core machine (load average $load when it started;
commit $commit); its light field played at $psnr dB PSNR, $ssim SSIM against ground truth, from a
$clip MB clip. Re-measured by \`tools/docs_figures.sh\`."
replace_block() {  # FILE NAME TEXT
  local file=$1 name=$2 body=$3 tmp
  grep -qx "<!-- figures:$name -->" "$file" || { echo "docs_figures: $file has no figures:$name block" >&2; exit 1; }
  tmp=$(mktemp "$file.XXXXXX")
  BODY="$body" awk -v first="<!-- figures:$name -->" -v last="<!-- /figures:$name -->" '
    $0 == first { print; print ENVIRON["BODY"]; skip = 1; next }
    $0 == last { skip = 0 }
    !skip { print }' "$file" >"$tmp"
  mv "$tmp" "$file"
}
replace_block README.md demo "$text"
echo "docs_figures: README.md demo: $total s, $psnr dB / $ssim, $clip MB (commit $commit, load $load)"
