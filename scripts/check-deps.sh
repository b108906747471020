#!/usr/bin/env bash
# The layering check: every folder's includes, the module graph declared in CMakeLists.txt and the
# packages each part links follow the policy written in scripts/check_deps.py (its docstring lists
# the allowed edges; docs/ARCHITECTURE.md draws them).
# Usage: scripts/check-deps.sh [REPO_ROOT]. Exit 0 when the tree follows it, 1 listing every violation.
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
exec python3 "$(dirname "$0")/check_deps.py" "$root"
