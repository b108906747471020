"""Builds the Python package `volscissors` with the project's CMake build (see pyproject.toml).

The extension is built in $VOLSCISSORS_BUILD_DIR (default: build/ of the source tree, configured
there if it is not yet) with the interpreter running pip; the package is python/volscissors (the
pure-Python modules) plus the extension from build/python/volscissors.
"""
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.abspath(os.environ.get("VOLSCISSORS_BUILD_DIR", os.path.join(HERE, "build")))


class CMakeBuildPy(build_py):
    def run(self):
        if not os.path.isfile(os.path.join(BUILD, "CMakeCache.txt")):
            subprocess.check_call(["cmake", "-S", HERE, "-B", BUILD, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DVS_BUILD_TESTS=OFF", "-DVS_BUILD_BENCH=OFF",
                                   f"-DPython_EXECUTABLE={sys.executable}"])
        jobs = os.environ.get("JOBS", str(os.cpu_count() or 1))
        subprocess.check_call(["cmake", "--build", BUILD, "--target", "volscissors_python", "-j", jobs])
        package = os.path.join(BUILD, "python", "volscissors")
        if not glob.glob(os.path.join(package, "_core*.so")):
            sys.exit(f"setup.py: no extension in {package}: CMake found no pybind11 for {sys.executable}?")
        super().run()  # the pure-Python modules of python/volscissors
        out = os.path.join(self.build_lib, "volscissors")
        for ext in glob.glob(os.path.join(package, "_core*.so")):
            shutil.copy2(ext, out)


class BinaryDistribution(Distribution):
    def has_ext_modules(self):
        return True  # a platform wheel: the package holds a compiled extension


# setuptools' own scratch files go into the CMake build folder, not the source tree.
scratch = os.path.join(BUILD, "python-setuptools")
os.makedirs(scratch, exist_ok=True)
setup(packages=["volscissors"], package_dir={"volscissors": "python/volscissors"}, cmdclass={"build_py": CMakeBuildPy}, distclass=BinaryDistribution,
      options={"build": {"build_base": scratch}, "egg_info": {"egg_base": scratch}})
