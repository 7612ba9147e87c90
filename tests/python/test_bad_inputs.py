"""tests/python/test_bad_inputs.py — bad input raises the right Python exception, never crashes.

Contract: wrong dtype or a non-array -> TypeError; wrong or mismatched shape, a non-increasing
timestamp, an unknown option name -> ValueError; a missing file -> orbis.MissingFileError (a
FileNotFoundError and an orbis.Error); a malformed file -> orbis.Error naming file and key or
line; misuse of a session (track after shutdown, map loaded after tracking) -> orbis.Error.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import orbis

SETTINGS = Path(__file__).resolve().parents[2] / "examples" / "settings"


@pytest.fixture(scope="module")
def rgbd() -> orbis.RgbdSlam:
    return orbis.RgbdSlam(orbis.Settings.load(SETTINGS / "TUM3.yaml"), deterministic=True)


GREY = np.zeros((480, 640), np.uint8)
DEPTH = np.zeros((480, 640), np.uint16)


@pytest.mark.parametrize("image, depth, error, message", [
    (GREY.astype(np.float32), DEPTH, TypeError, "image: expected dtype uint8"),
    (GREY, DEPTH.astype(np.int32), TypeError, "depth: expected dtype uint16"),
    (GREY.tolist(), DEPTH, TypeError, "expected a numpy.ndarray"),
    (GREY, None, TypeError, "got NoneType"),
    (GREY[:, :320], DEPTH[:, :320], ValueError, "the camera is 640 x 480"),
    (GREY, DEPTH[:240], ValueError, "differ in size|the camera"),
    (np.zeros((480, 640, 2), np.uint8), DEPTH, ValueError, r"expected shape \(H, W\) or \(H, W, 3\)"),
    (GREY, np.zeros((480, 640, 1), np.uint16), ValueError, r"expected shape \(H, W\)"),
    (np.zeros((0, 640), np.uint8), DEPTH, ValueError, "empty"),
])
def test_wrong_images(rgbd: orbis.RgbdSlam, image, depth, error, message) -> None:
    with pytest.raises(error, match=message):
        rgbd.track(image, depth, 1.0)


def test_colour_and_metric_depth_are_accepted_and_timestamps_must_increase(rgbd: orbis.RgbdSlam) -> None:
    rgbd.track(np.zeros((480, 640, 3), np.uint8), np.zeros((480, 640), np.float32), 10.0)
    with pytest.raises(ValueError, match="does not increase"):
        rgbd.track(GREY, DEPTH, 10.0)
    with pytest.raises(ValueError, match="does not increase"):
        rgbd.track(GREY, DEPTH, float("nan"))
    with pytest.raises(TypeError):
        rgbd.track(GREY, DEPTH, "11")  # type: ignore[call-overload]


def test_missing_files(tmp_path: Path) -> None:
    missing = tmp_path / "nothing.yaml"
    for load in (orbis.Settings.load, orbis.Vocabulary.load, orbis.read_trajectory, orbis.ba.read_bal,
                 orbis.datasets.tum, orbis.datasets.kitti):
        with pytest.raises(orbis.MissingFileError) as caught:
            load(missing)
        assert isinstance(caught.value, FileNotFoundError) and isinstance(caught.value, orbis.Error)
        assert caught.value.filename == str(missing) and caught.value.source == str(missing)
    with pytest.raises(FileNotFoundError):
        orbis.eval.ate(missing, missing)


def test_malformed_files_name_the_file_and_key(tmp_path: Path) -> None:
    text = (SETTINGS / "TUM3.yaml").read_text().replace("Camera.fx:", "Camera.fx_gone:")
    (tmp_path / "broken.yaml").write_text(text)
    with pytest.raises(orbis.Error, match="Camera.fx") as caught:
        orbis.Settings.load(tmp_path / "broken.yaml")
    assert isinstance(caught.value, RuntimeError) and not isinstance(caught.value, FileNotFoundError)
    assert caught.value.source == str(tmp_path / "broken.yaml") and "Camera.fx" in caught.value.where
    (tmp_path / "traj.txt").write_text("0 0 0 0 0 0 0 1\n1 0 0 zero 0 0 0 1\n")
    with pytest.raises(orbis.Error, match="line 2"):
        orbis.read_trajectory(tmp_path / "traj.txt")
    (tmp_path / "vocabulary.bin").write_bytes(b"\0" * 100)
    with pytest.raises(orbis.Error, match="vocabulary.bin"):
        orbis.Vocabulary.load(tmp_path / "vocabulary.bin")


def test_bad_option_names_and_arrays() -> None:
    with pytest.raises(ValueError, match="sensor"):
        orbis.Settings.load(SETTINGS / "TUM3.yaml", sensor="lidar")
    with pytest.raises(ValueError, match="this class needs stereo"):
        orbis.StereoSlam(orbis.Settings.load(SETTINGS / "TUM3.yaml"))
    rows = np.array([[0, 0, 0, 0, 0, 0, 0, 1], [1, 1, 0, 0, 0, 0, 0, 1.0]])
    with pytest.raises(ValueError, match="align"):
        orbis.eval.ate(rows, rows, align="affine")
    with pytest.raises(ValueError, match=r"shape \(N, 8\)"):
        orbis.eval.ate(rows[:, :7], rows)
    with pytest.raises(ValueError, match="does not increase"):
        orbis.write_trajectory("/tmp/never.txt", rows[::-1])
    with pytest.raises(ValueError, match="kind"):
        orbis.datasets.open("bag", ".")
    with pytest.raises(ValueError, match=r"\(N, 32\)"):
        orbis.Vocabulary.train([np.zeros((5, 31), np.uint8)])
    with pytest.raises(TypeError, match="uint8"):
        orbis.Vocabulary.train([np.zeros((5, 32), np.int16)])
    with pytest.raises(orbis.Error, match="no training descriptors"):
        orbis.Vocabulary.train([np.zeros((0, 32), np.uint8)])


def test_session_misuse(rgbd: orbis.RgbdSlam, tmp_path: Path) -> None:
    with pytest.raises(orbis.Error, match="before the first frame"):
        rgbd.save_map(tmp_path / "m.map")
        rgbd.load_map(tmp_path / "m.map")
    rgbd.shutdown()
    with pytest.raises(orbis.Error, match="after shutdown"):
        rgbd.track(GREY, DEPTH, 100.0)
