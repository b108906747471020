#!/usr/bin/env bash
# measure.sh K BUILD [stages...]: copies volscissors + test_tracking to /work/s46/mK (unless there),
# runs the stages into /work/s46/mKout (DONE_<stage> markers). Stages: sw scan150 scan140 scan70 scan60
# scan50 scan80 depth mk flat held heldflat
set -u
K=$1; B=$2; shift 2
M=/work/s46/fork/bin$K; O=/work/s46/fork/out$K
mkdir -p $M $O
[ -x $M/volscissors ] || cp $B/volscissors $B/test_tracking $M/
R=/work/wt/fork
ST=${*:-sw scan150 scan140 scan70 scan60 scan50 scan80 depth mk flat}
for s in $ST; do
  case $s in
    sw) $R/bench/family_sweep.sh $M $O/sw 129 ;;
    scan1[0-9][0-9]|scan[0-9][0-9]) b=${s#scan}; $R/bench/family_scan.sh $M $O/$s $b $((b + 9)) ;;  # scan150 = blocks 150-159 (the session-46 slip ran ${b}0..${b}9)
    depth) VS_DATA=/work/shared/data $R/bench/trace_depth.sh $M $O/depth 2>$O/depth.err ;;
    mk) VS_DATA=/work/shared/data $R/bench/trace_must_keep.sh $M $O/mk >$O/mk.txt 2>&1; echo "rc $?" >>$O/mk.txt ;;
    flat) mkdir -p $O/flat; VS_FAMILY_SEEDS=601-640 VS_FAMILY_VARIANT=flat $M/test_tracking --gtest_filter='Sweep/VesselFamilyVariants.*' 2>&1 | grep -E '^\[family|^\[variant|^\[flat' > $O/flat/flat.txt ;;
    held) $R/bench/family_scan.sh $M $O/held 160 169 ;;
    heldflat) mkdir -p $O/heldflat; for f in 16041 16141; do VS_FAMILY_BLIND=$f VS_FAMILY_VARIANT=flat $M/test_tracking --gtest_filter='Blind/VesselFamilyVariants.*' 2>&1 | grep -E '^\[family|^\[variant|^\[flat|OK|FAILED'; done > $O/heldflat/flat.txt ;;
  esac
  touch $O/DONE_$s
done
