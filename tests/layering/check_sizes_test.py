#!/usr/bin/env python3
"""scripts/check_sizes.py enforces the size rule (no source file over 800 lines, no function over
150 in src/, cli/, viewer/, python/): a scratch copy of the tree passes as it is, and fails, naming
the file or function, once an oversized function or file is planted in it; a function of exactly
150 lines, comments and strings with braces, and a test file of any size do not count.
Usage: check_sizes_test.py [REPO_ROOT] (ctest: layering_check_sizes)."""
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
FOLDERS = ["src", "cli", "viewer", "python", "scripts"]
KEEP = (".h", ".hpp", ".cpp", ".cc", ".py")


def function(name, lines, prefix="int", extra=""):
    """A C++ function of exactly `lines` lines (signature to closing brace)."""
    body = [f"  x += {i};{extra}" for i in range(lines - 3)]
    return "\n".join([f"{prefix} {name}(int x) {{"] + body + ["  return x;", "}"]) + "\n"


# (what, file to write, its text, expected exit, expected words)
CASES = [
    ("a 151-line function in src/", "src/util/planted_by_test.cpp", function("tooLong", 151), 1,
     ["src/util/planted_by_test.cpp:1: function tooLong is 151 lines"]),
    ("a 151-line member function defined in a class in viewer/", "viewer/app/planted_by_test.h",
     "struct Planted {\n" + function("tooLong", 151, prefix="  int", extra="") + "};\n", 1,
     ["viewer/app/planted_by_test.h:2: function tooLong is 151 lines"]),
    ("a 151-line lambda returned by a CLI command's setup", "cli/planted_by_test.cpp",
     "auto setup() {\n  return [](int x) {\n" + "".join(f"    x += {i};\n" for i in range(147)) + "    return x;\n  };\n}\n",
     1, ["cli/planted_by_test.cpp:1: function setup is 152 lines"]),
    ("a 151-line constructor with an initialiser list in python/", "python/src/planted_by_test.cpp",
     "struct P { int a, b; P(int x); };\nP::P(int x) : a(x), b{x} {\n" + "".join(f"  a += {i};\n" for i in range(149))
     + "}\n", 1, ["function P::P is 151 lines"]),
    ("an 801-line file of short functions", "src/volume/planted_by_test.cpp",
     "".join(function(f"f{i}", 8) for i in range(100)) + "\n", 1,
     ["src/volume/planted_by_test.cpp: 801 lines"]),
    ("a 150-line function and braces in comments and strings", "src/mesh/planted_by_test.cpp",
     "// {{{ not code\nconst char* s = \"{{\";\n/* } */\n" + function("justRight", 150), 0, ["size check: ok"]),
    ("a test file of any size", "tests/planted_by_test.cpp", function("longTest", 400), 0, ["size check: ok"]),
]


def copy_tree(dst):
    def ignore(d, names):
        return [n for n in names if n.startswith(".") or n.startswith("build")
                or (os.path.isfile(os.path.join(d, n)) and not n.endswith(KEEP))]
    for f in FOLDERS:
        if os.path.isdir(os.path.join(ROOT, f)):
            shutil.copytree(os.path.join(ROOT, f), os.path.join(dst, f), ignore=ignore)
    os.makedirs(os.path.join(dst, "tests"), exist_ok=True)


def run(tree):
    r = subprocess.run([sys.executable, os.path.join(tree, "scripts", "check_sizes.py"), tree],
                       capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    failures = 0
    with tempfile.TemporaryDirectory(prefix="vs-sizes-") as tmp:
        clean = os.path.join(tmp, "clean")
        copy_tree(clean)
        rc, out = run(clean)
        if rc != 0:
            print("FAIL: the unmodified copy does not pass:\n" + out)
            return 1
        print("ok: unmodified copy passes")
        for i, (what, path, text, expect_rc, expect) in enumerate(CASES):
            tree = os.path.join(tmp, f"case{i}")
            shutil.copytree(clean, tree)
            target = os.path.join(tree, path)
            assert os.path.isdir(os.path.dirname(target)), f"test out of date: {os.path.dirname(path)}/ is gone"
            with open(target, "w") as f:
                f.write(text)
            rc, out = run(tree)
            missing = [w for w in expect if w not in out]
            if rc != expect_rc or missing:
                failures += 1
                print(f"FAIL: {what}: exit {rc} (expected {expect_rc}), missing {missing} in:\n{out}")
            else:
                print(f"ok: {what}: exit {rc}")
            shutil.rmtree(tree)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
