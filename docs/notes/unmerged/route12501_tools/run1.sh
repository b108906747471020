#!/usr/bin/env bash
# run1.sh SEED [BIN]: one seed, dump + debug
S=$1; B=${2:-/work/s42/m0/test_tracking}
D=/work/s42/route12501
t=$((S % 100)); blk=$((S / 100))
if [ $t -le 12 ]; then
  VS_FAMILY_DUMP=$D/dump VS_FAMILY_DEBUG=1 VS_FAMILY_BLIND=${blk}01 $B --gtest_filter="Blind/VesselFamilyVariants.*${S}" > $D/log/g$S.txt 2>&1
  grep '^\[variant' $D/log/g$S.txt
else
  VS_FAMILY_DUMP=$D/dump VS_FAMILY_DEBUG=1 VS_FAMILY_SEEDS=$S $B --gtest_filter='Sweep/VesselFamily.*' > $D/log/t$S.txt 2>&1
  grep '^\[family' $D/log/t$S.txt
fi
