"""Monocular SLAM on a webcam, a video file or a folder of images, in a dozen lines.

usage: python3 webcam.py SETTINGS.yaml [SOURCE]
  SOURCE: a camera index (default 0), /dev/videoN, a video file or URL, or an image folder.
Writes trajectory.txt (TUM, camera-to-world) and prints the counts; Ctrl-C stops it cleanly.
"""

import sys
from pathlib import Path

import orbis

settings = orbis.Settings.load(sys.argv[1], sensor="mono")  # your camera's calibration
source_name = sys.argv[2] if len(sys.argv) > 2 else "0"
if Path(source_name).is_dir():
    frames = orbis.sources.images(source_name)
elif source_name.isdigit() or source_name.startswith("/dev/video"):
    frames = orbis.sources.camera(source_name)
else:
    frames = orbis.sources.video(source_name)

slam = orbis.MonocularSlam(settings)
try:
    for frame in frames:
        state, pose = slam.track(frame.image, frame.timestamp)
        if pose is not None:
            print(f"\r{frame.index:6d} {state.name:16s} x={pose[0, 3]:+.3f} y={pose[1, 3]:+.3f} z={pose[2, 3]:+.3f}",
                  end="", flush=True)
except KeyboardInterrupt:
    pass
dropped = frames.dropped  # frames a live camera delivered while tracking was busy
frames.close()
slam.shutdown()
slam.save_trajectory("trajectory.txt")
print(f"\n{slam.stats()} dropped={dropped}")
