#!/usr/bin/env bash
# Takes a screenshot of a grader HTML report with headless Chromium (Debian's `chromium` package):
#   cargo run --release --bin grader -- --all --html report && tools/screenshot-report.sh report
# writes report/screenshot.png. Chromium's background services are off: this machine is offline.
set -euo pipefail
dir=${1:?usage: tools/screenshot-report.sh REPORT_DIR}
command -v chromium >/dev/null || { echo "chromium is not installed (apt-get install chromium)" >&2; exit 1; }
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --user-data-dir="$profile" --window-size=1200,3000 \
  --screenshot="$dir/screenshot.png" "file://$(realpath "$dir")/index.html" 2>/dev/null
echo "wrote $dir/screenshot.png"
