"""tests/python/test_install.py — the package `cmake --install` lays out imports on its own.

Contract: installing the build's `python` component into a fresh prefix gives a package that a
fresh interpreter (PYTHONPATH = the prefix's site-packages folder only) imports with the
library's version and whose default vocabulary is the copy installed beside it. Needs the build
folder ($ORBIS_BUILD_DIR and $ORBIS_PYTHON_INSTALL_DIR, set by ctest); skipped without them.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import orbis


def test_installed_package_imports_from_a_fresh_prefix(tmp_path: Path) -> None:
    build, site = os.environ.get("ORBIS_BUILD_DIR"), os.environ.get("ORBIS_PYTHON_INSTALL_DIR")
    if not build or not site:
        pytest.skip("run by ctest (needs ORBIS_BUILD_DIR and ORBIS_PYTHON_INSTALL_DIR)")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix), "--component", "python"],
                   check=True, capture_output=True)
    env = {**os.environ, "PYTHONPATH": str(prefix / site)}
    env.pop("ORBIS_VOCABULARY", None)
    probe = "import orbis; print(orbis.__version__); print(orbis.__file__); print(orbis.Vocabulary.default_path())"
    version, package, vocabulary = subprocess.run([sys.executable, "-c", probe], check=True, capture_output=True,
                                                  text=True, cwd=tmp_path, env=env).stdout.split()
    assert version == orbis.__version__
    assert Path(package).is_relative_to(prefix) and Path(vocabulary).is_relative_to(prefix)
