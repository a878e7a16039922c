#!/bin/sh
# Renders a gyro-lab report (report.html) to a PNG with headless Chromium,
# as the README shows one: the top of the page (the verdict and the first
# plots) at a fixed window size.
#
#   scripts/render-report.sh REPORT.html OUT.png [WIDTH HEIGHT]
#
# Installs Chromium through apt-get when it is missing (needs root). The
# report is self-contained (inline SVG), so nothing is fetched; the
# browser's own network features are switched off too. Where Python's PIL
# is installed the PNG is reduced to a 64-colour palette (a third of the
# size; the plots use a few colours), as for the README's.
set -eu
if [ $# -lt 2 ]; then
    echo "usage: $0 REPORT.html OUT.png [WIDTH HEIGHT]" >&2
    exit 2
fi
report=$1
out=$2
width=${3:-1200}
height=${4:-1600}
if [ ! -f "$report" ]; then
    echo "$0: $report: no such file" >&2
    exit 2
fi
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
    apt-get install -y chromium >/dev/null
    browser=$(command -v chromium)
fi
abs=$(cd "$(dirname "$report")" && pwd)/$(basename "$report")
case "$out" in
/*) png=$out ;;
*) png=$(pwd)/$out ;;
esac
sandbox=""
if [ "$(id -u)" = 0 ]; then
    sandbox="--no-sandbox"
fi
"$browser" --headless $sandbox --disable-gpu --disable-background-networking \
    --disable-component-update --no-first-run --hide-scrollbars \
    --force-device-scale-factor=1 --window-size="$width,$height" \
    --screenshot="$png" "file://$abs" >/dev/null 2>&1
test -s "$png"
if python3 -c 'import PIL' 2>/dev/null; then
    if python3 - "$png" <<'PY'
import sys
from PIL import Image
path = sys.argv[1]
im = Image.open(path).convert("RGB")
im.quantize(colors=64, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)
PY
    then :; else echo "$0: palette reduction skipped (the PNG is full colour)" >&2; fi
fi
echo "$png"
