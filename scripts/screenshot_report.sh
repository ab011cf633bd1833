#!/usr/bin/env bash
# Screenshot of an evaluation report's report.html in headless Chromium (Debian's `chromium`).
#   bash scripts/screenshot_report.sh [REPORT_DIR] [OUT_PNG] [WIDTH] [HEIGHT]
# Defaults: reports/default, <REPORT_DIR>/screenshot.png, 1300 x 5000 px (a long page: the whole
# report down to the first env's figures). Install the browser once with:
#   apt-get update && apt-get install -y chromium
set -euo pipefail
report_dir="${1:-reports/default}"
out="${2:-$report_dir/screenshot.png}"
width="${3:-1300}"
height="${4:-5000}"
page="$(cd "$report_dir" && pwd)/report.html"
[ -f "$page" ] || { echo "no report.html in $report_dir (run python evaluate.py first)" >&2; exit 2; }
browser="$(command -v chromium || command -v chromium-browser || true)"
[ -n "$browser" ] || { echo "chromium not found: apt-get install -y chromium" >&2; exit 2; }
profile="$(mktemp -d)"
trap 'rm -rf "$profile"' EXIT
# The flags keep a headless, root-run browser off the network and away from first-run tasks.
"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --hide-scrollbars --user-data-dir="$profile" --window-size="$width,$height" \
  --virtual-time-budget=3000 --screenshot="$(realpath -m "$out")" "file://$page" 2>/dev/null
echo "wrote $out"
