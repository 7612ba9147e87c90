"""setup.py — `pip install .` for the orbis Python module, built through CMake, offline.

Contract: builds only the _orbis extension target with CMake (Ninja when present, ccache when
present) in build/pip-<python tag> of the source tree, for the interpreter running pip, and packages
python/orbis/ with it, the type stubs, and the shipped vocabulary in orbis/data/. Needs nothing
from a package index: `pip install --no-build-isolation --no-index .` uses the setuptools, wheel
and numpy already installed (Debian: python3-setuptools python3-wheel python3-numpy). ORBIS_JOBS
caps the build's parallel jobs; ORBIS_CMAKE_ARGS adds configure arguments.
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
VOCABULARY = ROOT / "vocabulary" / "orbis_orb_k10_L5.bin"


def library_version() -> str:
    """The version orbis::versionString() returns (src/util/version.cpp)."""
    text = (ROOT / "src" / "util" / "version.cpp").read_text()
    return re.search(r'return "([^"]+)"', text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name: str) -> None:
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Configures the whole project with only the Python module switched on, builds _orbis."""

    def build_extension(self, ext: Extension) -> None:
        build_dir = ROOT / "build" / f"pip-{sys.implementation.cache_tag}"
        configure = ["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                     "-DORBIS_BUILD_PYTHON=ON", "-DORBIS_BUILD_TESTS=OFF", "-DORBIS_BUILD_EXAMPLES=OFF",
                     "-DORBIS_BUILD_CLI=OFF", f"-DPython3_EXECUTABLE={sys.executable}"]
        if shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists():
            configure += ["-G", "Ninja"]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        configure += shlex.split(os.environ.get("ORBIS_CMAKE_ARGS", ""))
        jobs = os.environ.get("ORBIS_JOBS", str(os.cpu_count() or 1))
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "_orbis", "--parallel", jobs], check=True)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = build_dir / "python" / "orbis" / f"_orbis{suffix}"
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


class BuildPackage(build_py):
    """The pure-Python package plus the shipped vocabulary (orbis/data/)."""

    def run(self) -> None:
        super().run()
        data = Path(self.build_lib) / "orbis" / "data"
        data.mkdir(parents=True, exist_ok=True)
        shutil.copy2(VOCABULARY, data / VOCABULARY.name)


setup(
    name="orbis",
    version=library_version(),
    description="ORB-SLAM2 visual SLAM (stereo, RGB-D) as a C++20 library, with Python bindings",
    license="BSD-3-Clause",
    python_requires=">=3.9",
    install_requires=["numpy"],
    packages=["orbis"],
    package_dir={"orbis": "python/orbis"},
    package_data={"orbis": ["*.pyi", "py.typed"]},
    ext_modules=[CMakeExtension("orbis._orbis")],
    cmdclass={"build_ext": CMakeBuild, "build_py": BuildPackage},
    zip_safe=False,
)
