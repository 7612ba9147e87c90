"""orbis: ORB-SLAM2 visual SLAM (monocular, stereo and RGB-D) from Python, with NumPy in and out.

Contract: this package is the public face of the compiled extension ``orbis._orbis``. It
re-exports the SLAM classes, settings, vocabulary, trajectory I/O and errors at the top level,
and groups the rest by area: ``orbis.datasets`` (TUM / EuRoC / KITTI readers), ``orbis.sources``
(videos, image folders, live cameras as iterators), ``orbis.eval``
(ATE, RPE, KITTI metric, the same numbers as ``orbis eval``) and ``orbis.ba`` (BAL problems and
the bundle-adjustment solver); ``orbis.sweep`` (studies of sequences x settings x repeats on a
Dask cluster) is imported on demand. Poses are 4 x 4 camera-to-world float64 matrices; trajectories
are (N, 8) float64 arrays of TUM rows ``t x y z qx qy qz qw``.

Example::

    import orbis
    data = orbis.datasets.tum("rgbd_dataset_freiburg3_teddy")
    slam = orbis.RgbdSlam(orbis.Settings.load("TUM3.yaml"), deterministic=True)
    for frame in data:
        state, pose = slam.track(frame.image, frame.depth, frame.timestamp)
    slam.shutdown()
    print(orbis.eval.ate(data.ground_truth, slam.trajectory()).rmse)
"""

from __future__ import annotations

import numpy as _np

from . import _orbis
from ._orbis import (
    Error,
    MissingFileError,
    MonocularFisheyeSlam,
    MonocularSlam,
    OrbParams,
    RgbdSlam,
    Settings,
    StereoSlam,
    TrackingState,
    Vocabulary,
    calibrate,
    extract_orb,
    read_trajectory,
    settings_keys,
    write_trajectory,
)
from . import ba, datasets, eval, sources  # noqa: E402  (the submodules import the names above)

_pinhole_monocular_new = MonocularSlam.__new__


def _monocular_slam_new(cls, *args, **kwargs):
    """MonocularSlam(settings) of a fisheye (Camera.type: KannalaBrandt8) is a MonocularFisheyeSlam:
    the settings pick the lens model, as `orbis run --settings` does."""
    settings = args[0] if args else kwargs.get("settings")
    if cls is MonocularSlam and isinstance(settings, Settings) and settings.camera.get("model") == "kannala_brandt":
        return MonocularFisheyeSlam(*args, **kwargs)
    return _pinhole_monocular_new(cls, *args, **kwargs)


MonocularSlam.__new__ = _monocular_slam_new

__version__: str = _orbis.__version__

__all__ = [
    "Error",
    "MissingFileError",
    "MonocularFisheyeSlam",
    "MonocularSlam",
    "OrbParams",
    "RgbdSlam",
    "Settings",
    "StereoSlam",
    "TrackingState",
    "Vocabulary",
    "ba",
    "calibrate",
    "datasets",
    "eval",
    "extract_orb",
    "pose_matrices",
    "read_trajectory",
    "settings_keys",
    "sources",
    "write_trajectory",
    "__version__",
]


def pose_matrices(trajectory: _np.ndarray) -> tuple[_np.ndarray, _np.ndarray]:
    """Splits (N, 8) TUM rows into timestamps (N,) and camera-to-world matrices (N, 4, 4)."""
    rows = _np.asarray(trajectory, dtype=_np.float64)
    if rows.ndim != 2 or rows.shape[1] != 8:
        raise ValueError(f"trajectory: expected shape (N, 8), got {rows.shape}")
    x, y, z, w = (rows[:, k] for k in (4, 5, 6, 7))
    norm = _np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    poses = _np.zeros((len(rows), 4, 4))
    poses[:, 0, 0] = 1 - 2 * (y * y + z * z)
    poses[:, 0, 1] = 2 * (x * y - z * w)
    poses[:, 0, 2] = 2 * (x * z + y * w)
    poses[:, 1, 0] = 2 * (x * y + z * w)
    poses[:, 1, 1] = 1 - 2 * (x * x + z * z)
    poses[:, 1, 2] = 2 * (y * z - x * w)
    poses[:, 2, 0] = 2 * (x * z - y * w)
    poses[:, 2, 1] = 2 * (y * z + x * w)
    poses[:, 2, 2] = 1 - 2 * (x * x + y * y)
    poses[:, :3, 3] = rows[:, 1:4]
    poses[:, 3, 3] = 1
    return rows[:, 0].copy(), poses
