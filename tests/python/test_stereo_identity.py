"""tests/python/test_stereo_identity.py — StereoSlam from Python gives the C++ program's trajectory.

Contract: on a rendered KITTI-layout stereo sequence, StereoSlam in deterministic mode writes a
trajectory.txt byte-identical to `orbis run kitti --deterministic`'s, both when built from the
settings file (left/right arrays fed to track) and when built from the dataset's own calibration
(Frame objects fed to track; `orbis run` without --settings).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import orbis
from conftest import run_cli


@pytest.mark.parametrize("with_settings", [True, False])
def test_stereo_trajectory_is_byte_identical_to_the_cli(cli: Path, synthetic_stereo: Path, tmp_path: Path,
                                                        with_settings: bool) -> None:
    settings = synthetic_stereo / "settings.yaml"
    run_cli(cli, "run", "kitti", synthetic_stereo, "--deterministic", "--out", tmp_path / "cli",
            *(["--settings", settings] if with_settings else []))
    data = orbis.datasets.kitti(synthetic_stereo)
    assert data.sensor == "stereo" and len(data) == 40
    source = orbis.Settings.load(settings, sensor="stereo") if with_settings else data
    with orbis.StereoSlam(source, deterministic=True) as slam:
        for frame in data:
            if with_settings:
                slam.track(frame.left, frame.right, frame.timestamp)
            else:
                slam.track(frame)
    slam.save_trajectory(tmp_path / "python.txt")
    if with_settings:
        assert slam.stats()["tracked"] == 40
    expected = (tmp_path / "cli" / "trajectory.txt").read_bytes()
    rows = [line for line in expected.splitlines() if not line.startswith(b"#")]
    assert len(rows) == slam.stats()["tracked"] > 10
    assert (tmp_path / "python.txt").read_bytes() == expected
