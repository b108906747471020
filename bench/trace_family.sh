#!/usr/bin/env bash
# The vessel family sweep (issue 21): `trace` with defaults, every terminal given, on the seeds
# FIRST-LAST of makeVesselFamilyCase; one line per seed (mean distance, share within 1 voxel,
# radius error) and the failures. Test seeds (docs/notes/tracking.md): 9201-9230; tune on 1-40.
#   bench/trace_family.sh [BUILD_DIR] [FIRST-LAST]
set -euo pipefail
BUILD=${1:-build}
SEEDS=${2:-9201-9230}
VS_FAMILY_SEEDS=$SEEDS "$BUILD/test_tracking" --gtest_filter='Sweep/VesselFamily.*' 2>&1 |
  grep -E '^\[family|Failure|Expected|Which is|FAILED|PASSED' || true
