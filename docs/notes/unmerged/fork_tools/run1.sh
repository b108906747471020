#!/usr/bin/env bash
# run1.sh SEED BIN TAG: one seed, dump + debug into /work/s46/fork/{dump,log}/TAG
S=$1; B=$2; TAG=${3:-base}
D=/work/s46/fork
mkdir -p $D/dump/$TAG $D/log/$TAG
t=$((S % 100)); blk=$((S / 100))
if [ $t -le 12 ]; then
  VS_FAMILY_DUMP=$D/dump/$TAG VS_FAMILY_DEBUG=1 VS_FAMILY_BLIND=${blk}01 $B --gtest_filter="Blind/VesselFamilyVariants.*${S}*" > $D/log/$TAG/g$S.txt 2>&1
  grep '^\[variant' $D/log/$TAG/g$S.txt
else
  VS_FAMILY_DUMP=$D/dump/$TAG VS_FAMILY_DEBUG=1 VS_FAMILY_SEEDS=$S-$S $B --gtest_filter='Sweep/VesselFamily.*' > $D/log/$TAG/t$S.txt 2>&1
  grep '^\[family' $D/log/$TAG/t$S.txt
fi
