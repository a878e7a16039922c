#!/bin/sh
# Makes the README's report image (docs/report-scale-factor.png) from
# scratch: a simulated continuous-rotation run of a coil with a knee at
# 48 degC on a quadratic background (0.02 ppm/degC^2; 100 deg/s, chamber
# -40..+60 degC, 0.01 deg/sqrt(h)), its scale-factor fit with its report (fit/sf.html),
# and the top of that report rendered by scripts/render-report.sh.
#
#   scripts/readme-report.sh [OUT.png]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/docs/report-scale-factor.png}
case "$out" in
/*) ;;
*) out=$(pwd)/$out ;;
esac
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$root"
flock /tmp/cargo-build.lock cargo build --quiet --release -p gyro-lab
lab=$root/target/release/gyro-lab
cd "$work"
"$lab" simulate scale-factor --quadratic-ppm-per-c2 0.02 --rate-dps 100 --arw-dpsh 0.01 \
    --out knee-on-curve.csv >/dev/null
mkdir -p fit
"$lab" fit scale-factor --data knee-on-curve.csv --out fit/sf.toml >/dev/null
"$root/scripts/render-report.sh" fit/sf.html "$out" 1100 1450
