"""tests/python/test_fisheye_settings.py — fisheye settings in the Python Slam classes, and stereo
calibration from Python.

Contract: MonocularSlam built from settings with Camera.type: KannalaBrandt8 runs the fisheye
pipeline (a MonocularFisheyeSlam) and gives `orbis run`'s deterministic trajectory byte for byte;
StereoSlam built from a fisheye rig's rectified stereo settings (LEFT./RIGHT. blocks with
LEFT.type: KannalaBrandt8) rectifies raw pairs on load, as `orbis run images L --right R
--settings` does, to the same trajectory; orbis.calibrate(left, pattern, right=...) calibrates a
stereo rig as `orbis calibrate images L --right R --json` does.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import orbis
from conftest import run_cli

SIZE = ("--width", 320, "--height", 240)


@pytest.fixture(scope="module")
def fisheye_mono(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fisheye") / "mono"
    # The room loop at its usual pace (300 frames a loop): monocular needs its parallax to start.
    run_cli(cli, "synth", folder, "--camera", "fisheye", "--fov", 180, "--frames", 300, *SIZE, "--seed", 1, "--noise", 4,
            "--threads", 2)
    return folder


@pytest.fixture(scope="module")
def fisheye_rig(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fisheye") / "rig"
    run_cli(cli, "synth", folder / "sequence", "--layout", "euroc", "--camera", "fisheye", "--fov", 180, "--frames", 40,
            *SIZE, "--seed", 2)
    # The same rig's true rectified stereo settings, as `orbis calibrate --right` writes them.
    run_cli(cli, "synth", folder / "board", "--pattern", "chessboard:7x5:0.03", "--camera", "fisheye", "--fov", 180,
            *SIZE, "--views", 1, "--rig", "--baseline", 0.1)
    data = (folder / "sequence" / "mav0" / "cam0" / "data.csv").read_text().splitlines()
    (folder / "times.txt").write_text("".join(f"{int(line.split(',')[0]) / 1e9:.9f}\n" for line in data if not line.startswith("#")))
    return folder


def test_monocular_slam_runs_fisheye_settings_as_the_cli(cli: Path, fisheye_mono: Path, tmp_path: Path) -> None:
    settings = fisheye_mono / "settings_mono.yaml"
    run_cli(cli, "run", "tum", fisheye_mono, "--sensor", "mono", "--settings", settings, "--deterministic",
            "--max-frames", 90, "--out", tmp_path / "cli")
    slam = orbis.MonocularSlam(orbis.Settings.load(settings), deterministic=True)
    assert isinstance(slam, orbis.MonocularFisheyeSlam)
    with slam:
        for index, frame in enumerate(orbis.datasets.tum(fisheye_mono, sensor="mono")):
            if index == 90:
                break
            slam.track(frame)
    slam.save_trajectory(tmp_path / "python.txt")
    expected = (tmp_path / "cli" / "trajectory.txt").read_bytes()
    assert len([line for line in expected.splitlines() if not line.startswith(b"#")]) > 20
    assert (tmp_path / "python.txt").read_bytes() == expected


def test_stereo_slam_rectifies_a_fisheye_rig_on_load_as_the_cli(cli: Path, fisheye_rig: Path, tmp_path: Path) -> None:
    cams = fisheye_rig / "sequence" / "mav0"
    settings = fisheye_rig / "board" / "truth.yaml"
    loaded = orbis.Settings.load(settings)
    assert loaded.camera["model"] == "stereo" and loaded.camera["baseline"] == pytest.approx(0.1, rel=1e-6)
    run_cli(cli, "run", "images", cams / "cam0" / "data", "--right", cams / "cam1" / "data", "--times",
            fisheye_rig / "times.txt", "--settings", settings, "--deterministic", "--out", tmp_path / "cli")
    with orbis.StereoSlam(loaded, deterministic=True) as slam:
        left = orbis.sources.images(cams / "cam0" / "data", times=fisheye_rig / "times.txt", grey=True)
        right = orbis.sources.images(cams / "cam1" / "data", times=fisheye_rig / "times.txt", grey=True)
        for l, r in zip(left, right):
            slam.track(l.image, r.image, l.timestamp)
    slam.save_trajectory(tmp_path / "python.txt")
    assert slam.stats()["tracked"] == 40
    assert (tmp_path / "python.txt").read_bytes() == (tmp_path / "cli" / "trajectory.txt").read_bytes()


def test_calibrate_a_stereo_rig_as_the_cli(cli: Path, tmp_path: Path) -> None:
    views = tmp_path / "views"
    run_cli(cli, "synth", views, "--pattern", "chessboard:7x5:0.04", "--views", 8, *SIZE, "--fx", 260, "--noise", 1,
            "--seed", 4, "--rig", "--baseline", 0.08)
    result = orbis.calibrate(views / "left", "chessboard:7x5:0.04", right=views / "right", out=tmp_path / "rig.yaml")
    program = json.loads(run_cli(cli, "calibrate", "images", views / "left", "--right", views / "right", "--pattern",
                                 "chessboard:7x5:0.04", "--out", tmp_path / "cli.yaml", "--json"))
    for key in ("fx", "fy", "cx", "cy", "rms", "views_used", "model"):
        assert result[key] == program[key], key
    assert result["right"]["fx"] == program["right"]["fx"]
    # The rig's fit runs the same arithmetic; OpenCV's threads may move its last digits.
    for key in ("baseline", "baseline_std", "stereo_rms"):
        assert result[key] == pytest.approx(program[key], rel=1e-6), key
    assert result["baseline"] == pytest.approx(0.08, rel=0.02)
    camera = orbis.Settings.load(tmp_path / "rig.yaml").camera
    assert camera["model"] == "stereo" and camera["bf"] == pytest.approx(result["rectified"]["bf"], rel=1e-9)
