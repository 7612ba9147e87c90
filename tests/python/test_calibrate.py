"""orbis.calibrate against `orbis calibrate --json` on rendered chessboard views: the same result,
the settings file it writes loads as the camera, and bad input raises orbis.Error."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

import orbis


def run_cli(cli: Path, *args: object) -> str:
    return subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, text=True).stdout


@pytest.fixture(scope="module")
def board_views(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("calibration") / "views"
    run_cli(cli, "synth", folder, "--pattern", "chessboard:7x5:0.04", "--views", 10, "--width", 320,
            "--height", 240, "--fx", 260, "--distortion=-0.2,0.05,0,0", "--noise", 1, "--seed", 4)
    return folder / "images"


def test_calibrate_matches_the_program(cli: Path, board_views: Path, tmp_path: Path) -> None:
    result = orbis.calibrate(board_views, "chessboard:7x5:0.04", out=tmp_path / "camera.yaml",
                             report=tmp_path / "report")
    program = json.loads(run_cli(cli, "calibrate", "images", board_views, "--pattern", "chessboard:7x5:0.04",
                                 "--out", tmp_path / "cli.yaml", "--json"))
    for key in ("fx", "fy", "cx", "cy", "rms", "views_used", "model"):
        assert result[key] == program[key], key
    assert result["distortion"] == program["distortion"]
    assert abs(result["fx"] / 260 - 1) < 0.02  # a handful of small rendered views: a sanity bound, not the accuracy bar
    assert result["parameters"]["fx"]["std"] > 0
    camera = orbis.Settings.load(tmp_path / "camera.yaml").camera
    assert camera["model"] == "pinhole" and camera["fx"] == pytest.approx(result["fx"], rel=1e-9)
    assert (tmp_path / "report" / "coverage.png").is_file()
    assert (tmp_path / "report" / "undistorted.png").is_file()


def test_calibrate_bad_input(tmp_path: Path, board_views: Path) -> None:
    with pytest.raises(orbis.Error, match="not a folder"):
        orbis.calibrate(tmp_path / "missing", "chessboard:7x5:0.04")
    with pytest.raises(orbis.Error, match="no image shows the pattern"):
        orbis.calibrate(board_views, "chessboard:9x6:0.04")
    with pytest.raises(orbis.Error, match="expected chessboard"):
        orbis.calibrate(board_views, "checkers:7x5")
