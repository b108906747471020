#!/usr/bin/env bash
# Checks C++ sources against the repository's .clang-format without changing them.
#   scripts/check-format.sh            every tracked .h/.hpp/.cpp/.cc file
#   scripts/check-format.sh FILE...    only these files
# Exit 0 when all are formatted, 1 listing the offenders (fix: clang-format -i FILE...),
# 2 when clang-format is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

CLANG_FORMAT="${CLANG_FORMAT:-}"
if [ -z "$CLANG_FORMAT" ]; then
  for c in clang-format clang-format-14 clang-format-15 clang-format-16; do
    if command -v "$c" >/dev/null; then CLANG_FORMAT="$c"; break; fi
  done
fi
[ -n "$CLANG_FORMAT" ] || { echo "check-format: clang-format not found (apt-get install clang-format)" >&2; exit 2; }

if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files '*.h' '*.hpp' '*.cpp' '*.cc')
fi

offenders=()
for f in "${files[@]}"; do
  [ -f "$f" ] || { echo "check-format: $f: no such file" >&2; exit 2; }
  if ! "$CLANG_FORMAT" --style=file --dry-run --Werror "$f" >/dev/null 2>&1; then offenders+=("$f"); fi
done

if [ ${#offenders[@]} -gt 0 ]; then
  echo "check-format: ${#offenders[@]} of ${#files[@]} file(s) differ from .clang-format (fix: $CLANG_FORMAT -i FILE):" >&2
  printf '  %s\n' "${offenders[@]}" >&2
  exit 1
fi
echo "check-format: ${#files[@]} file(s) match .clang-format"
