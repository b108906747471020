#!/usr/bin/env bash
# Checks that the module graph declared in CMakeLists.txt matches the includes:
#  - every `#include "M/..."` in src/<mod>/ names <mod> itself or a module in the transitive
#    closure of <mod>'s DEPS (an undeclared dependency would build only by accident of link order);
#  - every vs_<dep> in <mod>'s DEPS is included somewhere in src/<mod>/ (no stale declarations);
#  - the declared graph has no cycle;
#  - tests/<mod>/ includes only what vs_<mod>, its TEST_DEPS and their closures provide (plus
#    tests/common/ and the test folder's own helpers); tests/cli/ may include any module.
# Usage: scripts/check-deps.sh [REPO_ROOT]. Exit 0 when consistent, 1 listing every mismatch.
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
exec python3 - "$root" <<'PY'
import os, re, sys

root = sys.argv[1]
text = open(os.path.join(root, "CMakeLists.txt")).read()
text = re.sub(r"#[^\n]*", "", text)  # CMake comments

deps, test_deps = {}, {}
for m in re.finditer(r"\bvs_module\(\s*([A-Za-z0-9_]+)([^)]*)\)", text):
    name, args = m.group(1), m.group(2).split()
    section, d, t = None, [], []
    for a in args:
        if a in ("DEPS", "TEST_DEPS"):
            section = a
        elif section == "DEPS":
            d.append(a)
        elif section == "TEST_DEPS":
            t.append(a)
    mods = lambda xs: [x[3:] for x in xs if x.startswith("vs_")] + [x[4:] for x in xs if x.startswith("vs::")]
    deps[name], test_deps[name] = mods(d), mods(t)

problems = []
for name, ds in deps.items():
    for d in ds:
        if d not in deps:
            problems.append(f"CMakeLists.txt: vs_{name} depends on vs_{d}, which is not a vs_module")


def closure(start):
    seen, stack = set(), list(start)
    while stack:
        m = stack.pop()
        if m in seen:
            continue
        seen.add(m)
        stack.extend(deps.get(m, []))
    return seen


for name in deps:
    if name in closure(deps[name]):
        problems.append(f"CMakeLists.txt: dependency cycle through vs_{name}")

include_re = re.compile(r'^\s*#\s*include\s*"([^"/]+)/[^"]*"', re.M)


def includes(folder):
    """(file, included top-level folder) for every quoted include with a folder part."""
    out = []
    if not os.path.isdir(folder):
        return out
    for dirpath, _, files in os.walk(folder):
        for f in sorted(files):
            if f.endswith((".h", ".hpp", ".cpp", ".cc")):
                path = os.path.join(dirpath, f)
                for inc in include_re.findall(open(path, errors="replace").read()):
                    out.append((os.path.relpath(path, root), inc))
    return out


for name in sorted(deps):
    allowed = closure(deps[name]) | {name}
    used = set()
    for path, inc in includes(os.path.join(root, "src", name)):
        used.add(inc)
        if inc not in allowed:
            problems.append(f'{path}: includes "{inc}/..." but vs_{name} does not depend on vs_{inc} '
                            f"(add it to DEPS in CMakeLists.txt, or move the code)")
    for d in deps[name]:
        if d not in used:
            problems.append(f"CMakeLists.txt: vs_{name} declares vs_{d} but src/{name}/ includes nothing from it")

tests = os.path.join(root, "tests")
for name in sorted(os.listdir(tests)) if os.path.isdir(tests) else []:
    folder = os.path.join(tests, name)
    if not os.path.isdir(folder) or name in ("common", "cli") or name not in deps:
        continue  # helpers, CLI tests (link everything), front ends with their own CMakeLists.txt
    allowed = closure([name] + test_deps[name]) | {"common"}
    for path, inc in includes(folder):
        if inc not in allowed and not os.path.exists(os.path.join(folder, inc)):
            problems.append(f'{path}: includes "{inc}/..." but test_{name} links only vs_{name}'
                            + (" and " + ", ".join("vs_" + t for t in test_deps[name]) if test_deps[name] else "")
                            + " (add it to TEST_DEPS in CMakeLists.txt)")

if problems:
    print("check-deps: the module graph in CMakeLists.txt does not match the includes:", file=sys.stderr)
    for p in problems:
        print("  " + p, file=sys.stderr)
    sys.exit(1)
print(f"check-deps: {len(deps)} modules, declared dependencies match the includes")
PY
