"""tests/python/test_slam_identity.py — the Python path gives the C++ program's trajectory.

Contract: on the rendered RGB-D sequence, RgbdSlam in deterministic mode, fed the dataset's frames
as NumPy arrays, writes a trajectory.txt and keyframes.txt byte-identical to `orbis run
--deterministic`'s; feeding Frame objects, and images that are strided views into larger arrays,
gives the same trajectory; the map the CLI saved loads into a localisation-only session that
relocalises in it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import orbis


def track_sequence(folder: Path, feed: str = "arrays", **options: object) -> orbis.RgbdSlam:
    data = orbis.datasets.tum(folder)
    settings = orbis.Settings.load(folder / "settings.yaml", sensor="rgbd")
    slam = orbis.RgbdSlam(settings, deterministic=True, **options)  # type: ignore[arg-type]
    for frame in data:
        if feed == "frames":
            state, pose = slam.track(frame)
        elif feed == "views":  # the same pixels as strided views into wider arrays
            wide_image = np.zeros((frame.image.shape[0], frame.image.shape[1] + 7) + frame.image.shape[2:], np.uint8)
            wide_image[:, 3:3 + frame.image.shape[1]] = frame.image
            wide_depth = np.zeros((frame.depth.shape[0], frame.depth.shape[1] + 5), np.uint16)
            wide_depth[:, 2:2 + frame.depth.shape[1]] = frame.depth
            state, pose = slam.track(wide_image[:, 3:3 + frame.image.shape[1]], wide_depth[:, 2:2 + frame.depth.shape[1]],
                                     frame.timestamp)
        else:
            state, pose = slam.track(frame.image, frame.depth, frame.timestamp)
        assert (pose is None) == (state != orbis.TrackingState.OK)
        if pose is not None:
            assert pose.shape == (4, 4) and pose.dtype == np.float64
            np.testing.assert_allclose(pose[3], [0, 0, 0, 1])
    slam.shutdown()
    return slam


@pytest.fixture(scope="module")
def python_run(synthetic: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[orbis.RgbdSlam, Path]:
    slam = track_sequence(synthetic)
    out = tmp_path_factory.mktemp("python_run")
    slam.save_trajectory(out / "trajectory.txt")
    slam.save_trajectory(out / "keyframes.txt", keyframes=True)
    return slam, out


def test_trajectory_files_are_byte_identical_to_the_cli(python_run, cli_run: Path) -> None:
    slam, out = python_run
    assert slam.stats()["tracked"] == 60
    for name in ("trajectory.txt", "keyframes.txt"):
        ours, theirs = (out / name).read_bytes(), (cli_run / name).read_bytes()
        assert len(theirs.splitlines()) > 10
        assert ours == theirs, f"{name} differs from orbis run's"


def test_trajectory_array_matches_the_cli_numerically(python_run, cli_run: Path) -> None:
    slam, _ = python_run
    ours, theirs = slam.trajectory(), orbis.read_trajectory(cli_run / "trajectory.txt")
    assert ours.shape == theirs.shape == (60, 8)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-6)  # the file keeps fewer digits
    times, matrices = orbis.pose_matrices(ours)
    np.testing.assert_array_equal(times, ours[:, 0])
    np.testing.assert_allclose(matrices[:, :3, 3], ours[:, 1:4])
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", matrices[:, :3, :3], matrices[:, :3, :3]),
                               np.broadcast_to(np.eye(3), (60, 3, 3)), atol=1e-9)
    points = slam.map_points()
    assert points.dtype == np.float32 and points.ndim == 2 and points.shape[1] == 3
    assert len(points) == slam.stats()["map_points"] > 100


@pytest.mark.parametrize("feed", ["frames", "views"])
def test_other_ways_of_feeding_give_the_same_trajectory(synthetic: Path, python_run, feed: str) -> None:
    slam, _ = python_run
    np.testing.assert_array_equal(track_sequence(synthetic, feed).trajectory(), slam.trajectory())


def test_saved_map_relocalises_in_localisation_mode(synthetic: Path, cli_run: Path) -> None:
    data = orbis.datasets.tum(synthetic)
    settings = orbis.Settings.load(synthetic / "settings.yaml", sensor="rgbd")
    with orbis.RgbdSlam(settings, localisation_only=True, deterministic=True) as slam:
        slam.load_map(cli_run / "room.map")
        assert slam.localisation_only
        for frame in list(data)[30:40]:
            slam.track(frame)
        stats = slam.stats()
    assert stats["keyframes_loaded"] > 0 and stats["relocalisations"] >= 1 and stats["tracked"] >= 5
    assert stats["keyframes"] == stats["keyframes_loaded"]  # localisation only: no new keyframes
    with pytest.raises(orbis.Error, match="shutdown"):
        slam.track(data[41])


def test_dataset_frames_share_their_pixels(synthetic: Path) -> None:
    data = orbis.datasets.tum(synthetic)
    frame = data[-1]
    assert frame.index == len(data) - 1 == 59 and frame.timestamp == data.timestamps[-1]
    assert np.shares_memory(frame.image, frame.left) and not frame.image.flags.owndata  # views of one cv::Mat
    assert frame.image.dtype == np.uint8 and frame.image.shape[:2] == (240, 320)
    assert frame.depth.dtype == np.uint16 and frame.depth.shape == (240, 320) and frame.right is None
    assert data.ground_truth.shape == (60, 8)
    with pytest.raises(IndexError):
        data[60]
