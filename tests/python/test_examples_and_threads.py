"""tests/python/test_examples_and_threads.py — the examples run, and a session survives threads.

Contract: examples/python/run_sequence.py tracks the rendered RGB-D room and writes a TUM
trajectory with every frame; plot_trajectory.py turns it and the ground truth into a PNG and
prints the ATE `orbis.eval.ate` computes. A threaded (real-time mode) RgbdSlam tracked from one
Python thread while another reads its trajectory, map and counts neither crashes nor loses frames.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np

import orbis

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


def run_example(name: str, *args: object, cwd: Path) -> str:
    """Runs an example in `cwd` with the orbis package under test importable."""
    package_parent = str(Path(orbis.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([package_parent, os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)], cwd=cwd, env=env, check=True,
                          capture_output=True, text=True).stdout


def test_runner_and_plot_examples(synthetic: Path, tmp_path: Path) -> None:
    printed = run_example("run_sequence.py", "tum", synthetic, synthetic / "settings.yaml", cwd=tmp_path)
    assert "'tracked': 60" in printed and "ATE" in printed
    estimate = orbis.read_trajectory(tmp_path / "trajectory.txt")
    assert estimate.shape == (60, 8)
    printed = run_example("plot_trajectory.py", synthetic / "groundtruth.txt", "trajectory.txt", "plot.png",
                          cwd=tmp_path)
    rmse = orbis.eval.ate(synthetic / "groundtruth.txt", tmp_path / "trajectory.txt").rmse
    assert f"ATE {rmse * 1000:.2f} mm" in printed
    assert (tmp_path / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / "plot.png").stat().st_size > 20000


def test_threaded_session_read_while_tracking(synthetic: Path) -> None:
    data = orbis.datasets.tum(synthetic)
    slam = orbis.RgbdSlam(orbis.Settings.load(synthetic / "settings.yaml", sensor="rgbd"))  # mapping on its own threads
    done = threading.Event()
    reads: list[int] = []
    failures: list[BaseException] = []

    def read_meanwhile() -> None:
        try:
            while not done.is_set():
                rows, points = slam.trajectory(), slam.map_points()
                assert rows.shape[1] == 8 and points.shape[1] == 3
                reads.append(slam.stats()["frames"])
        except BaseException as e:  # noqa: BLE001 (reported by the main thread)
            failures.append(e)

    reader = threading.Thread(target=read_meanwhile)
    reader.start()
    try:
        for frame in data:
            slam.track(frame.image, frame.depth, frame.timestamp)
    finally:
        done.set()
        reader.join()
    slam.shutdown()
    assert not failures, failures
    assert len(reads) > 10 and reads == sorted(reads)
    stats = slam.stats()
    assert stats["frames"] == 60 and stats["tracked"] >= 55 and stats["keyframes"] > 5
    assert np.all(np.diff(slam.trajectory()[:, 0]) > 0)
