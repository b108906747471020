#!/usr/bin/env bash
# A scan of the vessel family over whole blocks of seeds (issue 21): for each block b in
# FIRST..LAST, the twelve given seeds b01-b12 (VS_FAMILY_BLIND=<b>01, three per variant) into
# OUT/given.txt and the twelve thin forced seeds b21-b32 into OUT/thin.txt, one line per seed, for
# bench/family_compare.py. Which blocks are tuning-grade, held out or blind is written in
# docs/notes/tracking.md; a held-out range is run once, at the end. Two test processes run at once.
#   bench/family_scan.sh BUILD_DIR OUT_DIR FIRST_BLOCK LAST_BLOCK
set -uo pipefail
if [ $# -lt 4 ] || [ ! -x "$1/test_tracking" ]; then
  echo "usage: bench/family_scan.sh BUILD_DIR OUT_DIR FIRST_BLOCK LAST_BLOCK" >&2
  exit 2
fi
T="$(cd "$1" && pwd)/test_tracking"
OUT=$2
mkdir -p "$OUT"
keep() { grep -E '^\[family|^\[variant' || true; }
{
  for b in $(seq "$3" "$4"); do
    VS_FAMILY_BLIND=${b}01 "$T" --gtest_filter='Blind/VesselFamilyVariants.*' 2>&1 | keep
  done
} >"$OUT/given.txt" &
{
  for b in $(seq "$3" "$4"); do
    VS_FAMILY_SEEDS=${b}21-${b}32 "$T" --gtest_filter='Sweep/VesselFamily.*' 2>&1 | keep
  done
} >"$OUT/thin.txt"
wait
echo "family scan: blocks $3-$4, $(wc -l <"$OUT/given.txt") given and $(wc -l <"$OUT/thin.txt") thin forced lines in $OUT"
