# Sourced by the tests that drive a program from outside calf (a browser, Blender):
#   require_tools NAME NPM_DIR TOOL...
# TOOL is a command on PATH, or npm:PACKAGE for a package under NPM_DIR/node_modules. When one is
# missing, the test is skipped (exit 77, one line), except with CI=true, where it fails (exit 1):
# tools/setup.sh installs every one of them.
require_tools() {
  local name=$1 npm_dir=$2 tool
  shift 2
  local missing=()
  for tool in "$@"; do
    case $tool in
      npm:*) [ -f "$npm_dir/node_modules/${tool#npm:}/package.json" ] || missing+=("$tool") ;;
      *) command -v "$tool" >/dev/null || missing+=("$tool") ;;
    esac
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "${CI:-}" = "true" ]; then
    echo "$name: FAILED: ${missing[*]} missing with CI=true (tools/setup.sh installs them)"
    exit 1
  fi
  echo "$name: skipped: ${missing[*]} missing (tools/setup.sh installs them)"
  exit 77
}
