"""tests/python/test_own_camera.py — monocular SLAM and frame sources from Python and the program.

Contract: MonocularSlam in deterministic mode on the rendered sequence writes a trajectory
byte-identical to `orbis run tum --sensor mono --deterministic`, whether fed dataset frames or
orbis.sources.images frames, and `orbis run images` on the same folder gives the same file too;
a webcam-style loop over orbis.sources.video tracks an encoded copy (skipped without ffmpeg).
The program: Ctrl-C (SIGINT) mid-run writes every output, marks the report interrupted and exits
130; a camera that does not exist, a missing folder or video and a run without calibration exit
1 with a message naming the input.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

import orbis

from conftest import run_cli


@pytest.fixture(scope="module")
def mono_cli_run(cli: Path, synthetic: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("mono_cli_run")
    run_cli(cli, "run", "tum", synthetic, "--sensor", "mono", "--settings", synthetic / "settings_mono.yaml",
            "--deterministic", "--out", out)
    return out


def mono_settings(folder: Path) -> orbis.Settings:
    return orbis.Settings.load(folder / "settings_mono.yaml", sensor="mono")


def test_monocular_slam_matches_the_program_byte_for_byte(synthetic: Path, mono_cli_run: Path, tmp_path: Path) -> None:
    slam = orbis.MonocularSlam(mono_settings(synthetic), deterministic=True)
    for frame in orbis.datasets.tum(synthetic, sensor="mono"):
        state, pose = slam.track(frame.image, frame.timestamp)
        assert (pose is None) == (state != orbis.TrackingState.OK)
    slam.shutdown()
    assert slam.stats()["tracked"] > 15
    slam.save_trajectory(tmp_path / "trajectory.txt")
    assert (tmp_path / "trajectory.txt").read_bytes() == (mono_cli_run / "trajectory.txt").read_bytes()


def test_sources_images_and_run_images_give_the_same_trajectory(cli: Path, synthetic: Path, mono_cli_run: Path,
                                                                 tmp_path: Path) -> None:
    times = synthetic / "rgb.txt"
    slam = orbis.MonocularSlam(mono_settings(synthetic), deterministic=True)
    source = orbis.sources.images(synthetic / "rgb", times=times)
    assert not source.live and source.expected_frames == 60
    for frame in source:
        slam.track(frame)
    slam.shutdown()
    slam.save_trajectory(tmp_path / "python.txt")
    expected = (mono_cli_run / "trajectory.txt").read_bytes()
    assert (tmp_path / "python.txt").read_bytes() == expected

    run_cli(cli, "run", "images", synthetic / "rgb", "--times", times, "--settings", synthetic / "settings_mono.yaml",
            "--deterministic", "--groundtruth", synthetic / "groundtruth.txt", "--out", tmp_path / "cli")
    assert (tmp_path / "cli" / "trajectory.txt").read_bytes() == expected
    report = json.loads((tmp_path / "cli" / "report.json").read_text())
    assert report["source"]["name"] == f"images:{synthetic / 'rgb'}"
    assert report["interrupted"] is False and report["ate"]["alignment"] == "sim3"
    assert report["ate"]["matched"] == report["frames_tracked"]


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="no ffmpeg to encode the video")
def test_webcam_style_loop_over_a_video(synthetic: Path, tmp_path: Path) -> None:
    video = tmp_path / "room.mp4"
    files = sorted((synthetic / "rgb").iterdir())
    for i, f in enumerate(files):  # ffmpeg's image2 pattern wants numbered names
        os.symlink(f, tmp_path / f"{i:04d}.png")
    subprocess.run(["ffmpeg", "-loglevel", "error", "-framerate", "30", "-i", str(tmp_path / "%04d.png"),
                    "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18", str(video)], check=True)
    slam = orbis.MonocularSlam(mono_settings(synthetic), deterministic=True)
    tracked = 0
    with orbis.sources.video(str(video)) as frames:
        for frame in frames:
            state, pose = slam.track(frame.image, frame.timestamp)
            tracked += state == orbis.TrackingState.OK
        assert frames.end_reason == ""
    slam.shutdown()
    assert tracked > 15


def test_sources_name_what_is_wrong(tmp_path: Path) -> None:
    with pytest.raises(orbis.Error, match="no such folder"):
        orbis.sources.images(tmp_path / "missing")
    with pytest.raises(orbis.Error, match="no such video file"):
        orbis.sources.video(str(tmp_path / "missing.mp4"))
    with pytest.raises(orbis.Error, match="/dev/video97"):
        orbis.sources.camera(97)


def test_sigint_writes_everything_and_exits_130(cli: Path, synthetic: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    # --realtime at 4 fps: 60 frames take 15 s, so the signal lands mid-run.
    process = subprocess.Popen([str(cli), "run", "images", str(synthetic / "rgb"), "--fps", "4", "--realtime",
                                "--settings", str(synthetic / "settings_mono.yaml"), "--out", str(out),
                                "--save-map", str(out / "room.map")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(6)  # the vocabulary loaded and some frames tracked, far from the end
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    report = json.loads((out / "report.json").read_text())
    assert report["interrupted"] is True
    assert 0 < report["frames"] < 60
    for name in ("trajectory.txt", "keyframes.txt", "map.ply", "overview.png", "room.map"):
        assert (out / name).is_file(), name
    assert "interrupted" in stderr


def test_missing_inputs_exit_1_naming_them(cli: Path, synthetic: Path, tmp_path: Path) -> None:
    settings = str(synthetic / "settings_mono.yaml")
    cases = [
        (["camera", "/dev/video97", "--settings", settings], "/dev/video97"),
        (["camera", "97", "--settings", settings], "/dev/video97"),
        (["images", str(tmp_path / "none"), "--settings", settings], "no such folder"),
        (["video", str(tmp_path / "none.mp4"), "--settings", settings], "no such video file"),
        (["images", str(synthetic / "rgb")], "orbis calibrate"),
        (["images", str(synthetic / "rgb"), "--settings", settings, "--stereo", "diagonal"], "side-by-side"),
        (["tum", str(synthetic), "--fps", "30"], "not to a dataset"),
    ]
    for args, message in cases:
        done = subprocess.run([str(cli), "run", *args, "--out", str(tmp_path / "out")], capture_output=True, text=True,
                              timeout=60)
        assert done.returncode == 1, (args, done.stderr)
        assert message in done.stderr, (args, done.stderr)


def test_webcam_example_runs_on_an_image_folder(synthetic: Path, tmp_path: Path) -> None:
    from test_examples_and_threads import run_example

    printed = run_example("webcam.py", synthetic / "settings_mono.yaml", synthetic / "rgb", cwd=tmp_path)
    assert "dropped=0" in printed
    assert orbis.read_trajectory(tmp_path / "trajectory.txt").shape[0] > 15
