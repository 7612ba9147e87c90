"""tests/python/conftest.py — shared fixtures of the Python binding tests.

Contract: `cli` is the orbis program the bindings are compared with ($ORBIS_CLI, set by ctest to
the build's program; else `orbis` on PATH; the tests that need it are skipped only when neither
exists). `synthetic` renders, once per session, the small RGB-D sequence of the issue
(`orbis synth DIR --layout tum --frames 60 --width 320 --height 240 --fx 250 --seed 3`), and
`cli_run` runs `orbis run tum DIR --settings DIR/settings.yaml --deterministic` on it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def cli() -> Path:
    given = os.environ.get("ORBIS_CLI")
    if given:
        assert Path(given).is_file(), f"ORBIS_CLI={given} does not exist"
        return Path(given)
    found = shutil.which("orbis")
    if not found:
        pytest.skip("no orbis program (set ORBIS_CLI)")
    return Path(found)


def run_cli(cli: Path, *args: object) -> str:
    done = subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, text=True)
    return done.stdout


@pytest.fixture(scope="session")
def synthetic(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("synthetic") / "room"
    run_cli(cli, "synth", folder, "--layout", "tum", "--frames", 60, "--width", 320, "--height", 240,
            "--fx", 250, "--seed", 3)
    return folder


@pytest.fixture(scope="session")
def cli_run(cli: Path, synthetic: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("cli_run")
    run_cli(cli, "run", "tum", synthetic, "--settings", synthetic / "settings.yaml", "--deterministic",
            "--out", out, "--save-map", out / "room.map")
    return out


@pytest.fixture(scope="session")
def synthetic_stereo(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A rendered 40-frame rectified stereo sequence in the KITTI layout (640 x 480)."""
    folder = tmp_path_factory.mktemp("synthetic_stereo") / "room"
    run_cli(cli, "synth", folder, "--layout", "kitti", "--frames", 40, "--seed", 3)
    return folder
