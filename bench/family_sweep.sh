#!/usr/bin/env bash
# The vessel family's tuning sweep (issue 21), one line per seed, for comparing two builds with
# bench/family_compare.py: every variant as drawn (501-560), thin trees (1-40), the twelve-seed
# given blocks 10201..13412 (VS_FAMILY_BLIND=<b>01, three per variant) into OUT/sweep.txt; the thin
# forced blocks 10221-10232 .. 13421-13432 into OUT/thin.txt. The seeds are tuning-grade (looked at);
# the blind sets are in docs/notes/tracking.md. Two test processes run at once.
#   bench/family_sweep.sh BUILD_DIR OUT_DIR [LAST_BLOCK (default 134)]
set -uo pipefail
if [ $# -lt 2 ] || [ ! -x "$1/test_tracking" ]; then
  echo "usage: bench/family_sweep.sh BUILD_DIR OUT_DIR [LAST_BLOCK (default 134)]" >&2
  exit 2
fi
BUILD=$(cd "$1" && pwd)
OUT=$2
LAST=${3:-134}
mkdir -p "$OUT"
T="$BUILD/test_tracking"
keep() { grep -E '^\[family|^\[variant' || true; }
{
  VS_FAMILY_SEEDS=501-560 "$T" --gtest_filter='Sweep/VesselFamilyVariants.*' 2>&1 | keep
  VS_FAMILY_SEEDS=1-40 "$T" --gtest_filter='Sweep/VesselFamily.*' 2>&1 | keep
  for b in $(seq 102 "$LAST"); do
    VS_FAMILY_BLIND=${b}01 "$T" --gtest_filter='Blind/VesselFamilyVariants.*' 2>&1 | keep
  done
} >"$OUT/sweep.txt" &
{
  for b in $(seq 102 "$LAST"); do
    VS_FAMILY_SEEDS=${b}21-${b}32 "$T" --gtest_filter='Sweep/VesselFamily.*' 2>&1 | keep
  done
} >"$OUT/thin.txt" &
wait
echo "family sweep: $(wc -l <"$OUT/sweep.txt") sweep lines, $(wc -l <"$OUT/thin.txt") thin forced lines in $OUT"
