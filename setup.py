"""The build step of `pip install .` (pyproject.toml): the `posefilter._posefilter` extension
is built by the project's CMake (the library and the pybind11 module, Release, no tests or
benchmarks) in build/pip, or in $POSEFILTER_CMAKE_BUILD_DIR (a build folder already
configured is only built, with its own settings), then copied into the wheel."""
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("POSEFILTER_CMAKE_BUILD_DIR") or os.path.join(ROOT, "build", "pip")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DPython3_EXECUTABLE=" + sys.executable, "-DPOSEFILTER_BUILD_TESTS=OFF",
                                   "-DPOSEFILTER_BUILD_BENCH=OFF"])
        subprocess.check_call(["cmake", "--build", build, "--target", "_posefilter", "-j", str(os.cpu_count() or 2)])
        built = glob.glob(os.path.join(build, "python", "posefilter", "_posefilter*.so"))
        if not built:
            sys.exit("posefilter: CMake built no _posefilter module in %s (see its configure warnings: "
                     "python3-dev, pybind11-dev, python3-numpy)" % build)
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built[0], dest)


setup(ext_modules=[Extension("posefilter._posefilter", sources=[])], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": os.path.join("build", "setuptools")},
               "egg_info": {"egg_base": os.path.join("build")}})
