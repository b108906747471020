#!/usr/bin/env bash
# The main job on an embedded default: no user file needed. Each stage writes into
# demo-out/ and prints a short summary. Stages using ../shared/data fall back to the
# project's own phantoms when that folder is missing.
set -euo pipefail
BUILD=${1:-build}
VS="$BUILD/volscissors"
OUT=demo-out
DATA=../shared/data
mkdir -p "$OUT"
export VS_DEMO_OUT="$OUT"

for stage in scripts/demo.d/*.sh; do
  # shellcheck source=/dev/null
  source "$stage"
done
