"""pip install --no-build-isolation .  (docs/python.md)

Builds the Python package `animkit` with CMake, the one build of the library: setuptools calls
`cmake` to configure a build folder with only the extension target (no tests, examples,
benchmarks or command), builds animkit._core with the interpreter that runs pip, and copies the
module into the wheel. Offline with Debian's python3-setuptools, python3-numpy, python3-dev and
cmake; no scikit-build and no download. ANIMKIT_CMAKE_ARGS adds CMake arguments (for example
"-DAK_NO_SIMD=ON"); ANIMKIT_BUILD_JOBS sets the parallel jobs (default 2).
"""
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        return re.search(r"project\(animkit VERSION ([0-9.]+)", f.read()).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        pkg = os.path.join(build, "python-package")
        os.makedirs(build, exist_ok=True)
        args = [
            "cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
            "-DPython3_EXECUTABLE=" + sys.executable, "-DAK_PYTHON=ON", "-DAK_PYTHON_DIR=" + pkg,
            "-DAK_BUILD_TESTS=OFF", "-DAK_BUILD_EXAMPLES=OFF", "-DAK_BUILD_BENCH=OFF", "-DAK_BUILD_TOOLS=OFF",
        ]
        if shutil.which("ccache"):
            args += ["-DCMAKE_C_COMPILER_LAUNCHER=ccache", "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
        args += shlex.split(os.environ.get("ANIMKIT_CMAKE_ARGS", ""))
        subprocess.check_call(args)
        jobs = os.environ.get("ANIMKIT_BUILD_JOBS", "2")
        subprocess.check_call(["cmake", "--build", build, "--target", "animkit_python", "-j", jobs])
        built = glob.glob(os.path.join(pkg, "animkit", "_core*.so"))
        if not built:
            raise RuntimeError("CMake did not build animkit._core: is python3-dev / python3-numpy installed "
                               "for " + sys.executable + "?")
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built[0], dest)


setup(
    name="animkit",
    version=version(),
    description="Character animation and deformation: Python bindings of the animkit C library",
    license="see LICENSE",
    python_requires=">=3.8",
    install_requires=["numpy"],
    package_dir={"": "python"},
    packages=["animkit"],
    package_data={"animkit": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("animkit._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
