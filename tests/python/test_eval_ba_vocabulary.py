"""tests/python/test_eval_ba_vocabulary.py — metrics, the BA solver and vocabulary training from Python.

Contract: orbis.eval.ate / rpe / kitti return exactly the numbers `orbis eval ... --json` prints
for the same files (paths or arrays); solve_bal reaches the costs `orbis ba --json` reports on the
same BAL file; Vocabulary.train on NumPy descriptors is deterministic across thread counts and
round-trips through save/load; long C++ calls release the GIL (another Python thread runs).
"""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import orbis
from conftest import run_cli


def cli_json(cli: Path, *args: object) -> dict:
    return json.loads(run_cli(cli, *args, "--json"))


STATISTICS = ("rmse", "mean", "median", "max", "min", "std")


@pytest.mark.parametrize("align", ["se3", "sim3", "none"])
def test_ate_equals_the_cli(cli: Path, synthetic: Path, cli_run: Path, align: str) -> None:
    gt, est = synthetic / "groundtruth.txt", cli_run / "trajectory.txt"
    expected = cli_json(cli, "eval", "ate", gt, est, "--align", align)
    for result in (orbis.eval.ate(gt, est, align=align),
                   orbis.eval.ate(orbis.read_trajectory(gt), orbis.read_trajectory(est), align=align)):
        assert [getattr(result, k) for k in STATISTICS] == [expected[k] for k in STATISTICS]
        assert result.count == expected["matched"] == 60 and result.scale == expected["scale"]
        assert result.errors.shape == (60,) and result.aligned_estimate.shape == (60, 8)


@pytest.mark.parametrize("delta, unit", [(10, "frames"), (1.0, "m")])
def test_rpe_equals_the_cli(cli: Path, synthetic: Path, cli_run: Path, delta: float, unit: str) -> None:
    gt, est = synthetic / "groundtruth.txt", cli_run / "trajectory.txt"
    expected = cli_json(cli, "eval", "rpe", gt, est, "--delta", delta, "--delta-unit", unit)
    result = orbis.eval.rpe(gt, est, delta=delta, delta_unit=unit)
    assert [getattr(result, k) for k in STATISTICS] == [expected[k] for k in STATISTICS]
    assert result.rotation_deg == {**expected["rotation_deg"], "count": result.count}
    assert result.count == expected["pairs"] > 0 and result.matched == expected["matched"]


def long_drive(frames: int, seed: int) -> np.ndarray:
    """A 1 km drive on a wavy road, as TUM rows (the KITTI metric needs 100-800 m segments)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0, 1000, frames)
    heading = 0.3 * np.sin(s / 80) + rng.normal(0, 0.002, frames).cumsum() * (seed > 0)
    x, z = np.cumsum(np.cos(heading)) * s[1], np.cumsum(np.sin(heading)) * s[1]
    half = -heading / 2  # rotation about the camera's y axis (KITTI: y down)
    return np.column_stack([np.arange(frames) * 0.1, x, np.zeros(frames), z,
                            np.zeros(frames), np.sin(half), np.zeros(frames), np.cos(half)])


def test_kitti_metric_equals_the_cli(cli: Path, tmp_path: Path) -> None:
    gt, est = tmp_path / "gt.txt", tmp_path / "est.txt"
    orbis.write_trajectory(gt, long_drive(1000, 0), format="kitti")
    orbis.write_trajectory(est, long_drive(1000, 1), format="kitti")
    expected = cli_json(cli, "eval", "kitti", gt, est)
    result = orbis.eval.kitti(gt, est)
    assert result["t_rel"] == expected["t_rel"] > 0 and result["r_rel"] == expected["r_rel"]
    assert result["segments"] == expected["segments"] > 0 and result["matched"] == 1000
    assert result["per_length"] == expected["per_length"]


def small_bal_problem(tmp_path: Path) -> Path:
    """Six cameras around 200 points, measurements from the true values, then everything nudged."""
    rng = np.random.default_rng(7)
    points = rng.uniform(-1, 1, (200, 3))
    cameras = np.zeros((6, 9))
    cameras[:, 0:3] = rng.normal(0, 0.05, (6, 3))
    cameras[:, 5] = -6.0  # P = R X + t; BAL looks down -z
    cameras[:, 3:5] = rng.normal(0, 0.3, (6, 2))
    cameras[:, 6], cameras[:, 7], cameras[:, 8] = 500.0, 0.01, 0.0
    truth = orbis.ba.BalProblem(cameras, points, np.repeat(np.arange(6), 200), np.tile(np.arange(200), 6),
                                np.zeros((1200, 2)))
    noisy = orbis.ba.BalProblem(cameras + rng.normal(0, 1e-3, cameras.shape) * [1, 1, 1, 1, 1, 1, 0, 0, 0],
                                points + rng.normal(0, 0.02, points.shape), *truth.observations[:2],
                                pixels_of(truth))
    noisy.write(tmp_path / "problem.txt")
    return tmp_path / "problem.txt"


def pixels_of(problem: orbis.ba.BalProblem) -> np.ndarray:
    cam_index, point_index, _ = problem.observations
    cameras, points = problem.cameras[cam_index], problem.points[point_index]
    angle = np.linalg.norm(cameras[:, :3], axis=1, keepdims=True)
    axis = cameras[:, :3] / np.maximum(angle, 1e-12)
    rotated = (points * np.cos(angle) + np.cross(axis, points) * np.sin(angle)
               + axis * (axis * points).sum(1, keepdims=True) * (1 - np.cos(angle)))
    p = -(rotated + cameras[:, 3:6])[:, :2] / (rotated + cameras[:, 3:6])[:, 2:3]
    n = (p * p).sum(1, keepdims=True)
    return cameras[:, 6:7] * (1 + cameras[:, 7:8] * n + cameras[:, 8:9] * n * n) * p


def test_bal_solve_equals_the_cli(cli: Path, tmp_path: Path) -> None:
    path = small_bal_problem(tmp_path)
    expected = cli_json(cli, "ba", path)
    problem = orbis.ba.read_bal(path)
    before = problem.points.copy()
    summary = orbis.ba.solve_bal(problem)
    assert summary["initial_cost"] == expected["initial_cost"] > 1.0
    assert summary["final_cost"] == expected["final_cost"] < 1e-6 * expected["initial_cost"]
    assert summary["iterations"] == expected["iterations"]
    assert not np.array_equal(problem.points, before)  # solved in place


def random_descriptors(images: int, per_image: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    centres = rng.integers(0, 256, (40, 32), dtype=np.uint8)
    out = []
    for _ in range(images):
        noise = rng.integers(0, 256, (per_image, 32), dtype=np.uint8) & rng.integers(0, 256, (per_image, 32), dtype=np.uint8) & 0x11
        out.append(centres[rng.integers(0, 40, per_image)] ^ noise)
    return out


def test_vocabulary_training_is_deterministic_and_round_trips(tmp_path: Path) -> None:
    images = random_descriptors(20, 300, 5)
    one = orbis.Vocabulary.train(images, k=4, L=3, seed=9, threads=1)
    two = orbis.Vocabulary.train(iter(images), k=4, L=3, seed=9, threads=2)
    one.save(tmp_path / "one.bin")
    two.save(tmp_path / "two.bin")
    assert (tmp_path / "one.bin").read_bytes() == (tmp_path / "two.bin").read_bytes()
    loaded = orbis.Vocabulary.load(tmp_path / "one.bin")
    assert (loaded.k, loaded.L, loaded.weighting) == (4, 3, "tf-idf") and 10 < loaded.word_count <= 64
    np.testing.assert_array_equal(loaded.words(images[0]), one.words(images[0]))
    bow = loaded.transform(images[0])
    assert abs(sum(bow.values()) - 1.0) < 1e-5 and set(bow) <= set(loaded.words(images[0]).tolist())


def test_orb_extraction_feeds_the_shipped_vocabulary(synthetic: Path) -> None:
    image = orbis.datasets.tum(synthetic)[0].image
    keypoints, descriptors = orbis.extract_orb(image)
    assert keypoints.shape[1] == 5 and descriptors.shape == (len(keypoints), 32) and len(keypoints) > 300
    assert np.all((keypoints[:, 0] >= 0) & (keypoints[:, 0] < image.shape[1]))
    words = orbis.Vocabulary.default().words(descriptors)
    assert words.dtype == np.uint32 and len(np.unique(words)) > 50


def test_long_calls_release_the_gil() -> None:
    """A thread counting in Python keeps counting while C++ trains (a call that held the GIL would
    let it run only at the interpreter's 5 ms switch points: about 1 % of its free rate)."""
    images = random_descriptors(4, 40000, 3)
    ticks = 0
    done = threading.Event()

    def count() -> None:
        nonlocal ticks
        while not done.is_set():
            ticks += 1

    def ticks_during(call) -> tuple[int, float]:
        before, start = ticks, time.perf_counter()
        call()
        return ticks - before, time.perf_counter() - start

    counter = threading.Thread(target=count)
    counter.start()
    try:
        free, free_seconds = ticks_during(lambda: time.sleep(0.3))  # sleep releases the GIL
        during, seconds = ticks_during(lambda: orbis.Vocabulary.train(images, k=10, L=3, seed=1))
    finally:
        done.set()
        counter.join()
    assert seconds > 0.05, "training too short to tell"
    assert during > 0.1 * free / free_seconds * seconds, f"{during} ticks in {seconds:.3f} s; free: {free} in {free_seconds:.3f} s"
