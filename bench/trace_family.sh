#!/usr/bin/env bash
# The vessel family sweep (issue 21): `trace` with defaults, every terminal given, on the seeds
# FIRST-LAST of makeVesselFamilyCase; one line per seed (mean distance, share within 1 voxel,
# radius error) and the failures. Thin trees (the variant forced, as before session 12): test seeds
# 9201-9230, tune on 1-40. Every variant as the seed draws it (thin, wide lumen, kissing, parallel;
# `variants`): tune on 501-560; blind seeds 9501-9512 (VS_FAMILY_BLIND=1, docs/notes/tracking.md).
#   bench/trace_family.sh [BUILD_DIR] [FIRST-LAST] [thin|variants]
set -euo pipefail
BUILD=${1:-build}
SEEDS=${2:-9201-9230}
WHICH=${3:-thin}
FILTER='Sweep/VesselFamily.*'
[ "$WHICH" = variants ] && FILTER='Sweep/VesselFamilyVariants.*'
VS_FAMILY_SEEDS=$SEEDS "$BUILD/test_tracking" --gtest_filter="$FILTER" 2>&1 |
  grep -E '^\[family|^\[variant|^\[support|Failure|Expected|Which is|FAILED|PASSED' || true
