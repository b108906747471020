#!/usr/bin/env python3
"""scripts/check-deps.sh enforces the layering policy: a scratch copy of the tree passes as it is,
and fails, naming the file and the rule, once one forbidden include or link is planted in it.
Usage: check_deps_test.py [REPO_ROOT] (ctest: layering_check_deps)."""
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
FOLDERS = ["src", "cli", "viewer", "python", "bench", "fuzz", "examples", "tests", "scripts"]
KEEP = (".h", ".hpp", ".cpp", ".cc", ".c", ".txt", ".py", ".sh", ".in", ".cmake")

# (what, folder to plant a new file in, its text, an edit (file, regex, replacement) or None, expected words)
CASES = [
    ("core module on io, even with its DEPS edited", "src/render",
     '#include "io/volume_io.h"\n', ("CMakeLists.txt", r"(vs_module\(render\s+DEPS)", r"\1 vs_io"),
     ["src/render",
 "the core never reads files"]),
    ("tool on tool, even with its DEPS edited", "src/surface",
     '#include "tracking/tracker.h"\n', ("CMakeLists.txt", r"(vs_module\(surface\s+DEPS)", r"\1 vs_tracking"),
     ["src/surface",
 "tools never depend on each other"]),
    ("undeclared module dependency", "src/volume",
 '#include "mesh/tri_mesh.h"\n', None,
     ["src/volume",
 "data module volume may not depend on data module mesh"]),
    ("core on a front end", "src/util",
 '#include "args.h"\n', None,
     ["src/util",
 "never includes a front end"]),
    ("viewer on cli", "viewer/app",
 '#include "command.h"\n', None,
     ["viewer/app",
 "the viewer never includes cli/"]),
    ("cli on the viewer outside `view`", "cli",
 '#include "gl/raycaster.h"\n', None,
     ["cli",
 "include only src/"]),
    ("python on cli", "python/src",
 '#include "args.h"\n', None,
     ["python/src",
 "include only src/"]),
    ("bench on cli", "bench",
 '#include "progress_line.h"\n', None,
     ["bench",
 "include only src/"]),
    ("fuzz on the viewer", "fuzz",
 '#include "app/script.h"\n', None,
     ["fuzz",
 "include only src/"]),
    ("test beyond what it links", "tests/render",
 '#include "io/volume_io.h"\n', None,
     ["tests/render",
 "test_render links only"]),
    ("ITK outside io", "src/meshops",
 "#include <itkImage.h>\n", None,
     ["src/meshops",
 "ITK is allowed only in"]),
    ("VTK in a front end", "python/src",
 "#include <vtkPolyData.h>\n", None,
     ["python/src",
 "VTK is allowed only in src/meshops"]),
    ("GL in the viewer's GL-free part", "viewer/app",
 "#include <GL/gl.h>\n", None,
     ["viewer/app",
 "OpenGL/EGL/GLFW/ImGui is allowed only in"]),
    ("VTK linked into a core module", None, None,
     ("CMakeLists.txt", r"(target_link_libraries\(vs_cutting PRIVATE)", r"\1 VTK::CommonCore"),
     ["target_link_libraries(vs_cutting", "links VTK, allowed only in src/meshops"]),
]


def copy_tree(dst):
    def ignore(d, names):
        return [n for n in names if n.startswith(".") or n.startswith("build")
                or (os.path.isfile(os.path.join(d, n)) and not n.endswith(KEEP))]
    for f in FOLDERS:
        if os.path.isdir(os.path.join(ROOT, f)):
            shutil.copytree(os.path.join(ROOT, f), os.path.join(dst, f), ignore=ignore)
    shutil.copy(os.path.join(ROOT, "CMakeLists.txt"), dst)


def run(tree):
    r = subprocess.run(["bash", os.path.join(tree, "scripts", "check-deps.sh"), tree],
                       capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def edit(path, pattern, repl):
    text = open(path).read()
    new, n = re.subn(pattern, repl, text, count=1)
    assert n == 1, f"test out of date: {pattern!r} not in {path}"
    open(path, "w").write(new)


def main():
    failures = 0
    with tempfile.TemporaryDirectory(prefix="vs-layering-") as tmp:
        clean = os.path.join(tmp, "clean")
        copy_tree(clean)
        rc, out = run(clean)
        if rc != 0:
            print("FAIL: the unmodified copy does not pass:\n" + out)
            return 1
        print("ok: unmodified copy passes")
        for i, (what, plant, text, extra, expect) in enumerate(CASES):
            tree = os.path.join(tmp, f"case{i}")
            shutil.copytree(clean, tree)
            if plant:
                assert os.path.isdir(os.path.join(tree, plant)), f"test out of date: {plant}/ is gone"
                with open(os.path.join(tree, plant, "planted_by_test.cpp"), "w") as f:
                    f.write(text)
            if extra:
                edit(os.path.join(tree, extra[0]), extra[1], extra[2])
            rc, out = run(tree)
            missing = [w for w in expect if w not in out]
            if rc != 1 or missing:
                failures += 1
                print(f"FAIL: {what}: exit {rc}, missing {missing} in:\n{out}")
            else:
                print(f"ok: {what}: refused")
            shutil.rmtree(tree)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
