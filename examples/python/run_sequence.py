"""examples/python/run_sequence.py — SLAM on a TUM RGB-D or KITTI / EuRoC stereo sequence from Python.

Usage: run_sequence.py tum|kitti|euroc PATH [SETTINGS.yaml] [--sequence NN]
Writes trajectory.txt (TUM format) in the current folder, prints the counts and, when the
sequence has ground truth, the ATE. Without SETTINGS the dataset's own calibration is used.
"""
import argparse

import orbis

args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
args.add_argument("kind"), args.add_argument("path"), args.add_argument("settings", nargs="?")
args.add_argument("--sequence", default="")
a = args.parse_args()
data = orbis.datasets.open(a.kind, a.path, sequence=a.sequence)
source = orbis.Settings.load(a.settings, sensor=data.sensor) if a.settings else data
slam = (orbis.RgbdSlam if data.sensor == "rgbd" else orbis.StereoSlam)(source)
for frame in data:
    if frame.warnings:  # e.g. no depth map within 20 ms: skipped, as `orbis run` does
        continue
    state, pose = slam.track(frame)  # pose: 4 x 4 camera-to-world, None unless state is OK
slam.shutdown()
slam.save_trajectory("trajectory.txt")
print(slam.stats())
if len(data.ground_truth):
    print(f"ATE {orbis.eval.ate(data.ground_truth, slam.trajectory()).rmse * 1000:.1f} mm")
