#!/usr/bin/env bash
# run1.sh SEED [BIN] [TAG]: one seed, dump + debug + probe
S=$1; B=${2:-/work/wt/forkE/build/test_tracking}; T=${3:-p}
D=/work/s43/forkE
t=$((S % 100)); blk=$((S / 100))
if [ $t -le 12 ]; then
  VS_R12501=${PROBE-1} VS_FAMILY_DUMP=$D/dump VS_FAMILY_DEBUG=1 VS_FAMILY_BLIND=${blk}01 $B --gtest_filter="Blind/VesselFamilyVariants.*${S}" > $D/log/$T$S.txt 2>&1
  grep '^\[variant' $D/log/$T$S.txt
else
  VS_R12501=${PROBE-1} VS_FAMILY_DUMP=$D/dump VS_FAMILY_DEBUG=1 VS_FAMILY_SEEDS=$S $B --gtest_filter='Sweep/VesselFamily.*' > $D/log/$T$S.txt 2>&1
  grep '^\[family' $D/log/$T$S.txt
fi
