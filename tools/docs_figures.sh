#!/usr/bin/env bash
# Re-measures the figures the docs quote and rewrites them between <!-- figures:NAME --> markers
# (tools/docs_figures.py says how; --list names the blocks, --only NAME re-measures one).
#   tools/docs_figures.sh                 every block: the demo (setup and build included), then
#                                         the other measurements on its Release build
#   tools/docs_figures.sh --only NAME...  only these blocks
#   tools/docs_figures.sh --reuse         rewrites the blocks from the last run's outputs
#   tools/docs_figures.sh --check         checks the markers and the rewriting, measures nothing
set -euo pipefail
cd "$(dirname "$0")/.."
python=python3
[ -x /usr/bin/python3 ] && python=/usr/bin/python3
exec "$python" tools/docs_figures.py "$@"
