#!/bin/sh
# Runs the README's "The lab, step by step" as a user would: every shell
# block of that section, top to bottom, in a fresh scratch folder inside the
# repository (so `cargo lab` and `cargo xtask` resolve), stopping at the
# first command that fails. The benchmarks (the section's last block) are
# left out: they take minutes to an hour.
#
#   scripts/readme-walkthrough.sh [--keep]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$root/target"
work=$(mktemp -d "$root/target/readme-walkthrough.XXXXXX")
[ "${1:-}" = "--keep" ] || trap 'rm -rf "$work"' EXIT
# The section's shell blocks, up to the benchmarks.
awk '
  /^## The lab, step by step/ { on = 1; next }
  on && /^\*\*Benchmarks\*\*/ { exit }
  on && /^## / { exit }
  on && /^```sh$/ { inblock = 1; next }
  on && inblock && /^```$/ { inblock = 0; next }
  on && inblock { print }
' "$root/README.md" > "$work/steps.sh"
[ -s "$work/steps.sh" ] || { echo "no steps found in README.md" >&2; exit 1; }
cd "$work"
echo "running $(grep -c '^cargo\|^[A-Z_]*=.* cargo' steps.sh) commands of README.md in $work" >&2
sh -eux steps.sh > steps.log 2>&1 || {
  echo "README walkthrough FAILED; the last lines of its log ($work/steps.log):" >&2
  tail -n 30 steps.log >&2
  trap - EXIT
  exit 1
}
echo "README walkthrough: every step ran" >&2
