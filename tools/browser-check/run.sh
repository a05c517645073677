#!/usr/bin/env bash
# Runs the browser check on the accelcal report.
#   tools/browser-check/run.sh [--screenshots DIR] [REPORT_HTML]
# REPORT_HTML defaults to report/index.html at the repository root. Works from any directory;
# a relative REPORT_HTML is taken relative to the current directory.
# Needs node/npm and Debian's chromium (apt-get install -y chromium). The first run installs
# playwright-core (npm ci) into tools/browser-check/node_modules; no browser is downloaded.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"

args=()
report=""
while [ $# -gt 0 ]; do
  case "$1" in
    --screenshots|--chromium)
      [ $# -ge 2 ] || { echo "run.sh: $1 needs a value" >&2; exit 2; }
      args+=("$1" "$(realpath -m -- "$2")"); shift 2 ;;
    --screenshots=*|--chromium=*)
      args+=("${1%%=*}" "$(realpath -m -- "${1#*=}")"); shift ;;
    -h|--help)
      sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*)
      echo "run.sh: unknown option $1" >&2; exit 2 ;;
    *)
      [ -z "$report" ] || { echo "run.sh: more than one report given" >&2; exit 2; }
      report="$(realpath -m -- "$1")"; shift ;;
  esac
done
[ -n "$report" ] || report="$root/report/index.html"

command -v node >/dev/null || { echo "run.sh: node is not installed" >&2; exit 2; }

# Install playwright-core when it is missing or differs from the lock file.
if [ ! -f "$here/node_modules/playwright-core/package.json" ] \
   || ! cmp -s "$here/package-lock.json" "$here/node_modules/.package-lock.json.installed" 2>/dev/null; then
  echo "run.sh: installing npm packages (npm ci) in $here" >&2
  (cd "$here" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error >&2)
  cp "$here/package-lock.json" "$here/node_modules/.package-lock.json.installed"
fi

exec node "$here/check.js" "${args[@]}" "$report"
