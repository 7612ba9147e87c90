"""orbis.eval: trajectory error metrics with the numbers ``orbis eval`` prints.

Contract: ``gt`` and ``est`` are each a path (TUM, KITTI or EuRoC file, detected as the CLI
detects it, or ``format=`` for both; KITTI files may take ``gt_times=`` / ``est_times=``) or an
(N, 8) array of TUM rows ``t x y z qx qy qz qw`` (camera-to-world, increasing t). Association is
one-to-one by nearest timestamp within ``max_dt`` seconds (TUM benchmark / evo), alignment is
Umeyama over positions. Bad option names raise ValueError; nothing to evaluate, orbis.Error.

- ``ate(gt, est, align="se3"|"sim3"|"none")`` -> AteResult (rmse, mean, median, max, min, std,
  count in metres; scale, alignment 4 x 4, errors, aligned_estimate);
- ``rpe(gt, est, delta=1, delta_unit="frames"|"m", align="none")`` -> RpeResult (translation
  statistics in metres, rotation_deg dict, per-pair errors);
- ``kitti(gt, est)`` -> dict t_rel (%), r_rel (deg/100 m), segments, matched, per_length.
"""

from __future__ import annotations

from typing import Any, Dict

from ._orbis import AteResult, RpeResult
from ._orbis import ate, rpe
from ._orbis import kitti_metric as _kitti_metric

__all__ = ["AteResult", "RpeResult", "ate", "kitti", "rpe"]


def kitti(gt: Any, est: Any, *, align: str = "none", max_dt: float = 0.02, **files: Any) -> Dict[str, Any]:
    """The KITTI odometry metric (devkit's evaluate_odometry), as ``orbis eval kitti``."""
    return _kitti_metric(gt, est, align=align, max_dt=max_dt, **files)
