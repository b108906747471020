#!/usr/bin/env python3
"""The layering policy of volscissors, and the check that the tree follows it.

Run as scripts/check-deps.sh [REPO_ROOT] (CI: .ci/run). Exit 0 when the tree follows the policy,
1 listing every violation (file, include, rule), 2 when the policy itself is inconsistent.

THE POLICY (the one place where the allowed edges are written down; docs/ARCHITECTURE.md draws it)

Every C/C++ file of src/, cli/, viewer/, python/, bench/, fuzz/, examples/ and tests/ belongs to an
*owner*: `src/<module>`, `cli`, `viewer/app`, `viewer/gl`, `viewer/window`, `python`, `bench`,
`fuzz`, `examples`, `tests/<folder>`. Each quoted include is resolved to the file it names (the
including file's folder first, then src/, viewer/, cli/, tests/, python/src/) and the edge
owner -> owner of the included file must be allowed:

  core modules (src/, GUI-free, one static library each, layered bottom-up):
    base        util
    data        volume, mesh                         -> base
    algorithms  graph, features, cost, phantom,      -> base, data, and ALGORITHM_EDGES only
                render, meshops
    tools       scissors, tracking, surface,         -> base, data, algorithms except phantom;
                cutting, quantify                       never another tool
    io          io                                   -> base, data, meshops (nothing in the core
                                                        includes io: the core never reads files)
  front ends:
    cli           -> src/ (any module); the `view` command (cli/cmd_view.cpp only) also opens
                     the viewer (viewer/app, viewer/window)
    viewer/app    -> src/ (GL-free: tools, script, session)
    viewer/gl     -> src/, viewer/app
    viewer/window -> src/, viewer/app, viewer/gl           (the viewer never includes cli/)
    python        -> src/
  harnesses:
    bench -> src/, viewer/;  fuzz -> src/;  examples -> the installed core (not io)
    tests/<module> -> what test_<module> links: the module, its TEST_DEPS, their closures;
    tests/cli -> src/, cli;  tests/viewer -> src/, viewer/;  every test folder -> the helpers of
    tests/ (tests/common, its own, another folder's).

Besides the policy, a src module's includes must be covered by the DEPS it declares in
CMakeLists.txt (transitively), each declared DEPS must be used and allowed, and the declared graph
has no cycle.

Packages (angle includes, and target_link_libraries in every CMakeLists.txt) are allowed only in
the owners listed in PACKAGES: ITK, GDCM, libpng and zlib only in src/io (zlib and libpng also in tests/io, which crafts
inputs); VTK only in src/meshops;
Boost only in src/cutting; GL, EGL, GLFW and ImGui only in viewer/gl and viewer/window; pybind11
only in python; CLI11 only in cli; Google Benchmark only in bench; GoogleTest only in tests.
Eigen, nlohmann_json and the C/C++ standard libraries are allowed everywhere.
"""
import os
import re
import sys

BASE = ["util"]
DATA = ["volume", "mesh"]
ALGORITHMS = ["graph", "features", "cost", "phantom", "render", "meshops"]
TOOLS = ["scissors", "tracking", "surface", "cutting", "quantify"]
IO = ["io"]
# The only edges between algorithm modules: costs are made from features and searched on graphs.
ALGORITHM_EDGES = {"cost": ["features", "graph"]}


def core_allowed():
    """Allowed dependencies of each src/ module, from the layers above."""
    allowed = {}
    for m in BASE:
        allowed[m] = set()
    for m in DATA:
        allowed[m] = set(BASE)
    for m in ALGORITHMS:
        allowed[m] = set(BASE) | set(DATA) | set(ALGORITHM_EDGES.get(m, []))
    for m in TOOLS:
        allowed[m] = set(BASE) | set(DATA) | (set(ALGORITHMS) - {"phantom"})
    for m in IO:
        allowed[m] = set(BASE) | set(DATA) | {"meshops"}
    return allowed


CORE = BASE + DATA + ALGORITHMS + TOOLS  # what volscissors::core installs (io is separate)
VIEWER_PARTS = ["viewer/app", "viewer/gl", "viewer/window"]


def src_owners(mods):
    return {"src/" + m for m in mods}


def front_allowed(all_modules):
    src_all = src_owners(all_modules)
    return {
        "cli": src_all | {"cli"},
        "viewer/app": src_all | {"viewer/app"},
        "viewer/gl": src_all | {"viewer/app", "viewer/gl"},
        "viewer/window": src_all | set(VIEWER_PARTS),
        "python": src_all | {"python"},
        "bench": src_all | set(VIEWER_PARTS) | {"bench"},
        "fuzz": src_all | {"fuzz"},
        "examples": src_owners(CORE) | {"examples"},
        "tests/cli": src_all | {"cli", "tests/cli", "tests/common"},
        "tests/viewer": src_all | set(VIEWER_PARTS) | {"tests/viewer", "tests/common"},
        "tests/common": src_all | {"tests/common"},
    }


# One file per door between front ends: (file, owner it may include besides its own policy).
DOORS = {
    "cli/cmd_view.cpp": {"viewer/app", "viewer/window"},
}

# package -> (angle-include pattern, CMake link-token pattern, owners allowed)
PACKAGES = {
    "ITK": (r"itk[A-Z_]\w*\.h|itk_\w+\.h", r"\$\{ITK_LIBRARIES\}|\bITK::|\bITK[A-Z]\w*", {"src/io", "fuzz"}),
    "GDCM": (r"gdcm\w*\.h", r"\bgdcm\w+", {"src/io"}),
    "VTK": (r"vtk\w*\.h", r"\bVTK::", {"src/meshops"}),
    "Boost": (r"boost/", r"\bBoost::", {"src/cutting"}),
    "libpng": (r"png\.h", r"\bPNG::", {"src/io", "tests/io"}),
    "zlib": (r"zlib\.h", r"\bZLIB::", {"src/io", "tests/io"}),  # tests/io crafts gzipped inputs
    "OpenGL/EGL/GLFW/ImGui": (r"GL/|GLES\d*/|EGL/|GLFW/|imgui|backends/imgui",
                              r"\bOpenGL::|\bglfw\b|\$\{IMGUI_LIBRARY\}", {"viewer/gl", "viewer/window"}),
    "pybind11": (r"pybind11/", r"\bpybind11::", {"python"}),
    "CLI11": (r"CLI/", r"\bCLI11::", {"cli"}),
    "Google Benchmark": (r"benchmark/", r"\bbenchmark::", {"bench"}),
    "GoogleTest": (r"gtest/|gmock/", r"\bGTest::", {"tests"}),
}

# CMake target -> owner, for the package link check (patterns matched against the target as written).
TARGET_OWNERS = [
    (r"vs_cli|volscissors", "cli"),
    (r"vs_viewer_app", "viewer/app"),
    (r"vs_viewer", "viewer/window"),
    (r"_core", "python"),
    (r"fuzz_.*", "fuzz"),
    (r"test_.*", "tests"),
    (r"bench_.*|\$\{name\}", "bench"),  # the top-level loop over bench/*.cpp
    (r"volscissors_core", "src"),
    (r"vs_(\w+)", None),  # -> src/<module>
]

SCANNED = ["src", "cli", "viewer", "python", "bench", "fuzz", "examples", "tests"]
INCLUDE_ROOTS = ["src", "viewer", "cli", "tests", "python/src"]
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cc", ".c")


def policy_problems(allowed):
    """The rules the table itself must keep, so that editing one line cannot break the layering."""
    out = []
    for m, deps in allowed.items():
        if m not in IO and set(IO) & deps:
            out.append(f"policy: core module {m} may not depend on io")
        if m in TOOLS:
            for d in deps & set(TOOLS):
                out.append(f"policy: tool {m} may not depend on tool {d}")
    return out


def parse_modules(root):
    text = open(os.path.join(root, "CMakeLists.txt")).read()
    text = re.sub(r"#[^\n]*", "", text)
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

        def mods(xs):
            return [x[3:] for x in xs if x.startswith("vs_")] + [x[4:] for x in xs if x.startswith("vs::")]

        deps[name], test_deps[name] = mods(d), mods(t)
    return deps, test_deps


def closure(deps, start):
    seen, stack = set(), list(start)
    while stack:
        m = stack.pop()
        if m in seen:
            continue
        seen.add(m)
        stack.extend(deps.get(m, []))
    return seen


def owner_of(rel):
    parts = rel.split("/")
    top = parts[0]
    if top in ("src", "tests") and len(parts) > 2:
        return top + "/" + parts[1]
    if top == "viewer" and len(parts) > 2 and parts[1] in ("app", "gl", "window"):
        return "viewer/" + parts[1]
    if top == "viewer":
        return "viewer/window" if len(parts) > 2 else "viewer"
    return top


quoted_re = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)
angle_re = re.compile(r"^\s*#\s*include\s*<([^>]+)>", re.M)


def source_files(root):
    for top in SCANNED:
        base = os.path.join(root, top)
        if not os.path.isdir(base):
            continue
        for dirpath, dirnames, files in os.walk(base):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "build")
            for f in sorted(files):
                if f.endswith(SOURCE_EXT):
                    yield os.path.relpath(os.path.join(dirpath, f), root)


def resolve(root, rel, inc):
    """The repository-relative file a quoted include names, or None."""
    candidates = [os.path.dirname(rel)] + INCLUDE_ROOTS
    for c in candidates:
        p = os.path.normpath(os.path.join(c, inc))
        if not p.startswith("..") and os.path.isfile(os.path.join(root, p)):
            return p
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    deps, test_deps = parse_modules(root)
    allowed_core = core_allowed()

    bad_policy = policy_problems(allowed_core)
    if bad_policy:
        print("check-deps: the layering policy in scripts/check_deps.py breaks its own rules:", file=sys.stderr)
        for p in bad_policy:
            print("  " + p, file=sys.stderr)
        return 2

    problems = []
    for name in deps:
        if name not in allowed_core:
            problems.append(f"CMakeLists.txt: vs_{name} has no layer in scripts/check_deps.py "
                            f"(add src/{name} to BASE, DATA, ALGORITHMS, TOOLS or IO there)")
    for name, ds in deps.items():
        for d in ds:
            if d not in deps:
                problems.append(f"CMakeLists.txt: vs_{name} depends on vs_{d}, which is not a vs_module")
            elif name in allowed_core and d not in allowed_core[name]:
                problems.append(f"CMakeLists.txt: vs_{name} may not depend on vs_{d} "
                                f"({layer_reason(name, d)}; policy in scripts/check_deps.py)")
    for name in deps:
        if name in closure(deps, deps[name]):
            problems.append(f"CMakeLists.txt: dependency cycle through vs_{name}")

    fronts = front_allowed(list(deps))
    used = {name: set() for name in deps}
    n_files = 0
    for rel in source_files(root):
        n_files += 1
        owner = owner_of(rel)
        text = open(os.path.join(root, rel), errors="replace").read()
        # quoted includes: the edge between owners
        for inc in quoted_re.findall(text):
            target = resolve(root, rel, inc)
            if target is None:
                first = inc.split("/")[0]
                if "/" in inc and first in deps:
                    target = f"src/{inc}"  # a missing header of a module still names the module
                else:
                    continue
            towner = owner_of(target)
            if towner == owner:
                continue
            why = edge_problem(owner, towner, rel, deps, test_deps, allowed_core, fronts)
            if why is None and owner.startswith("src/") and towner.startswith("src/"):
                used[owner[4:]].add(towner[4:])
            if why:
                problems.append(f'{rel}: includes "{inc}" ({towner}): {why}')
        # angle includes: packages
        for inc in angle_re.findall(text):
            for pkg, (inc_pat, _, owners) in PACKAGES.items():
                if re.match(r"(?:" + inc_pat + r")", inc):
                    if not owner_allows_package(owner, owners):
                        problems.append(f"{rel}: includes <{inc}>: {pkg} is allowed only in "
                                        + ", ".join(sorted(owners)) + f", not in {owner}")
    for name in sorted(deps):
        for d in deps[name]:
            if d in deps and d not in used[name]:
                problems.append(f"CMakeLists.txt: vs_{name} declares vs_{d} but src/{name}/ includes nothing from it")

    problems += link_problems(root, deps)

    if problems:
        print("check-deps: the tree breaks the layering policy (scripts/check_deps.py):", file=sys.stderr)
        for p in problems:
            print("  " + p, file=sys.stderr)
        return 1
    print(f"check-deps: {len(deps)} modules, {n_files} files in {', '.join(SCANNED)}: "
          "includes, declared dependencies and packages follow the layering policy")
    return 0


def layer_of(m):
    for layer, mods in (("base", BASE), ("data", DATA), ("algorithm", ALGORITHMS), ("tool", TOOLS), ("io", IO)):
        if m in mods:
            return layer
    return "unlayered"


def layer_reason(frm, to):
    lf, lt = layer_of(frm), layer_of(to)
    if to in IO:
        return f"{lf} module {frm} may not include io: the core never reads files"
    if lf == "tool" and lt == "tool":
        return f"tools never depend on each other ({frm} -> {to})"
    if lf == "tool" and to == "phantom":
        return "tools do not depend on the phantom generator (tests do)"
    return f"{lf} module {frm} may not depend on {lt} module {to}"


def edge_problem(owner, towner, rel, deps, test_deps, allowed_core, fronts):
    """None when owner -> towner is allowed, else the reason."""
    if owner.startswith("src/"):
        mod = owner[4:]
        if not towner.startswith("src/"):
            return f"the core (src/) never includes a front end or harness ({towner})"
        tmod = towner[4:]
        if mod in allowed_core and tmod not in allowed_core[mod]:
            return layer_reason(mod, tmod)
        if tmod not in closure(deps, deps.get(mod, [])):
            return f"vs_{mod} does not depend on vs_{tmod} (add it to DEPS in CMakeLists.txt, or move the code)"
        return None
    if rel in DOORS and towner in DOORS[rel]:
        return None
    if owner.startswith("tests/") and towner.startswith("tests/"):
        return None  # test helpers are shared between test folders (their own includes are checked there)
    if owner.startswith("tests/") and owner not in fronts:
        mod = owner[6:]
        if mod not in deps:
            return f"tests/{mod}/ tests no module of src/ (name the folder after the module it tests)"
        ok = {"src/" + m for m in closure(deps, [mod] + test_deps.get(mod, []))} | {"tests/common", owner}
        if towner in ok:
            return None
        extra = test_deps.get(mod, [])
        return (f"test_{mod} links only vs_{mod}" + (" and " + ", ".join("vs_" + t for t in extra) if extra else "")
                + " (add it to TEST_DEPS in CMakeLists.txt)")
    if owner in fronts:
        if towner in fronts[owner]:
            return None
        if owner.startswith("viewer/") and towner == "cli":
            return "the viewer never includes cli/"
        if towner in ("cli", "python") or towner.startswith("viewer"):
            return f"front ends and harnesses include only src/ ({owner} may not include {towner})"
        return f"{owner} may not include {towner}"
    return f"{owner} is not in the layering policy"


def owner_allows_package(owner, owners):
    return owner in owners or any(owner.startswith(o + "/") for o in owners)


def link_problems(root, deps):
    out = []
    for dirpath, dirnames, files in os.walk(root):
        rel_dir = os.path.relpath(dirpath, root)
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and not d.startswith("build")
                             and not (rel_dir == "." and d in ("docs", "scripts")))
        if "CMakeLists.txt" not in files:
            continue
        path = os.path.join(dirpath, "CMakeLists.txt")
        rel = os.path.relpath(path, root)
        text = re.sub(r"#[^\n]*", "", open(path, errors="replace").read())
        for m in re.finditer(r"\btarget_link_libraries\(\s*(\S+)([^)]*)\)", text):
            target, args = m.group(1), m.group(2)
            owner = target_owner(target, deps)
            for pkg, (_, link_pat, owners) in PACKAGES.items():
                if re.search(link_pat, args) and (owner is None or not owner_allows_package(owner, owners)):
                    out.append(f"{rel}: target_link_libraries({target} ...) links {pkg}, allowed only in "
                               + ", ".join(sorted(owners)) + (f", not in {owner}" if owner else
                                                             " (target not in TARGET_OWNERS)"))
    return out


def target_owner(target, deps):
    for pat, owner in TARGET_OWNERS:
        mm = re.fullmatch(pat, target)
        if mm:
            if owner is None:
                return "src/" + mm.group(1) if mm.group(1) in deps else None
            return owner
    return None


if __name__ == "__main__":
    sys.exit(main())
