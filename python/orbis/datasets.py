"""orbis.datasets: benchmark sequences (TUM RGB-D, EuRoC MAV, KITTI odometry) as frame sequences.

Contract: each opener returns an ``orbis._orbis.Dataset``: ``len(d)``, ``d[i]`` (negative
indices too) and ``for frame in d`` give ``Frame`` objects loaded on demand (timestamp, ``image``
/ ``left`` uint8, ``right``, ``depth`` raw uint16 or None), with ``d.camera`` (dict),
``d.ground_truth`` ((N, 8) TUM rows, camera-to-world, left/colour camera) and ``d.timestamps``.
Only the text files are read when opening; a missing folder raises ``orbis.MissingFileError``, a
malformed file ``orbis.Error`` naming the file and line. ``tolerate_bad_frames`` (default True, as
``orbis run``) makes an unreadable image an error of that frame only.
"""

from __future__ import annotations

import os
from typing import Optional, Union

from ._orbis import Dataset, Frame, FrameIterator, open_dataset

__all__ = ["Dataset", "Frame", "FrameIterator", "euroc", "kitti", "open", "tum"]

PathLike = Union[str, "os.PathLike[str]"]


def tum(path: PathLike, *, depth_scale: Optional[float] = None, max_depth_dt: float = 0.02,
        sensor: Optional[str] = None, strict: bool = False, tolerate_bad_frames: bool = True) -> Dataset:
    """A TUM RGB-D sequence (rgb.txt, depth.txt, groundtruth.txt): RGB-D, or 'mono' with sensor.

    depth_scale: raw depth / scale = metres (default 5000, 5208 for freiburg2, as ORB-SLAM2).
    """
    return open_dataset("tum", path, sensor=sensor, depth_scale=depth_scale, max_depth_dt=max_depth_dt,
                        strict=strict, tolerate_bad_frames=tolerate_bad_frames)


def euroc(path: PathLike, *, rectify: bool = True, sensor: Optional[str] = None, strict: bool = False,
          tolerate_bad_frames: bool = True) -> Dataset:
    """A EuRoC MAV sequence (the folder holding mav0/): stereo pairs, rectified on load."""
    return open_dataset("euroc", path, sensor=sensor, rectify=rectify, strict=strict,
                        tolerate_bad_frames=tolerate_bad_frames)


def kitti(path: PathLike, *, sequence: str = "", sensor: Optional[str] = None, strict: bool = False,
          tolerate_bad_frames: bool = True) -> Dataset:
    """A KITTI odometry sequence (image_0/, image_1/, times.txt, calib.txt), or the dataset root
    with sequence="06" (sequences/06 and poses/06.txt)."""
    return open_dataset("kitti", path, sensor=sensor, sequence=sequence, strict=strict,
                        tolerate_bad_frames=tolerate_bad_frames)


def open(kind: str, path: PathLike, **options: object) -> Dataset:  # noqa: A001 (mirrors openDataset)
    """Any of the three by name: kind 'tum', 'euroc' or 'kitti'; options as the openers above."""
    return open_dataset(kind, path, **options)  # type: ignore[arg-type]
