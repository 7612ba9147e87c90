"""Type stubs of the compiled extension orbis._orbis (python/src/*.cpp); see the orbis package.

Contract: mirrors every class, function and keyword the extension defines, so editors complete
it and type checkers check calls. Arrays are numpy.ndarray; shapes and dtypes are in docstrings.
"""

from __future__ import annotations

import enum
import os
from pathlib import Path
from typing import Any, Dict, Iterator, List, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

PathLike = Union[str, "os.PathLike[str]"]
TrajectoryLike = Union[PathLike, npt.ArrayLike]

__version__: str

class Error(RuntimeError):
    """An orbis failure caused by outside input; source is the file or origin, where the line or key."""

    source: str
    where: str

class MissingFileError(FileNotFoundError, Error):
    """A file given to orbis does not exist."""

# ---- settings -------------------------------------------------------------------------------

class OrbParams:
    features: int
    scale_factor: float
    levels: int
    ini_th_fast: int
    min_th_fast: int
    right_features_factor: int
    def __init__(self) -> None: ...

class Settings:
    @staticmethod
    def load(path: PathLike, sensor: Optional[str] = None) -> Settings: ...
    @property
    def source(self) -> Path: ...
    @property
    def sensor(self) -> str: ...
    @property
    def camera(self) -> Dict[str, Any]: ...
    @property
    def distortion(self) -> Tuple[float, float, float, float, float]: ...
    orb: OrbParams
    fps: float
    @property
    def rgb_order(self) -> bool: ...
    @property
    def th_depth(self) -> float: ...
    @property
    def depth_map_factor(self) -> float: ...
    @property
    def seed(self) -> int: ...

# ---- vocabulary and features ------------------------------------------------------------------

class Vocabulary:
    @staticmethod
    def load(path: PathLike) -> Vocabulary: ...
    @staticmethod
    def default_path() -> Path: ...
    @staticmethod
    def default() -> Vocabulary: ...
    @staticmethod
    def train(images: Any, k: int = 10, L: int = 5, seed: int = 1, threads: int = 1,
              weighting: str = "tf-idf") -> Vocabulary: ...
    def save(self, path: PathLike) -> None: ...
    @property
    def k(self) -> int: ...
    @property
    def L(self) -> int: ...
    @property
    def word_count(self) -> int: ...
    @property
    def node_count(self) -> int: ...
    @property
    def weighting(self) -> str: ...
    def words(self, descriptors: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint32]: ...
    def transform(self, descriptors: npt.NDArray[np.uint8]) -> Dict[int, float]: ...

def extract_orb(image: npt.NDArray[np.uint8], params: OrbParams = ...) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]: ...

# ---- datasets ---------------------------------------------------------------------------------

class Frame:
    @property
    def index(self) -> int: ...
    @property
    def timestamp(self) -> float: ...
    @property
    def image(self) -> npt.NDArray[np.uint8]: ...
    @property
    def left(self) -> npt.NDArray[np.uint8]: ...
    @property
    def right(self) -> Optional[npt.NDArray[np.uint8]]: ...
    @property
    def depth(self) -> Optional[npt.NDArray[np.uint16]]: ...
    @property
    def warnings(self) -> List[str]: ...

class FrameIterator:
    def __iter__(self) -> FrameIterator: ...
    def __next__(self) -> Frame: ...

class Dataset:
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> Frame: ...
    def __iter__(self) -> Iterator[Frame]: ...
    @property
    def kind(self) -> str: ...
    @property
    def sensor(self) -> str: ...
    @property
    def root(self) -> Path: ...
    @property
    def camera(self) -> Dict[str, Any]: ...
    @property
    def ground_truth(self) -> npt.NDArray[np.float64]: ...
    @property
    def timestamps(self) -> npt.NDArray[np.float64]: ...
    @property
    def warnings(self) -> List[str]: ...

def open_dataset(kind: str, path: PathLike, sensor: Optional[str] = None, sequence: str = "",
                 depth_scale: Optional[float] = None, max_depth_dt: float = 0.02, rectify: bool = True,
                 strict: bool = False, tolerate_bad_frames: bool = True) -> Dataset: ...

# ---- trajectories -----------------------------------------------------------------------------

def read_trajectory(path: PathLike, format: Optional[str] = None, times: Optional[str] = None) -> npt.NDArray[np.float64]: ...
def write_trajectory(path: PathLike, trajectory: npt.ArrayLike, format: str = "tum") -> None: ...

# ---- SLAM -------------------------------------------------------------------------------------

class TrackingState(enum.Enum):
    NOT_INITIALISED = 0
    OK = 1
    LOST = 2

TrackResult = Tuple[TrackingState, Optional[npt.NDArray[np.float64]]]

class _Slam:
    def trajectory(self) -> npt.NDArray[np.float64]: ...
    def keyframe_trajectory(self) -> npt.NDArray[np.float64]: ...
    def save_trajectory(self, path: PathLike, format: str = "tum", keyframes: bool = False) -> None: ...
    def map_points(self) -> npt.NDArray[np.float32]: ...
    def stats(self) -> Dict[str, int]: ...
    def timing(self) -> List[Dict[str, Any]]: ...
    @property
    def state(self) -> TrackingState: ...
    @property
    def camera(self) -> Dict[str, Any]: ...
    localisation_only: bool
    def shutdown(self) -> None: ...
    def save_map(self, path: PathLike) -> None: ...
    def load_map(self, path: PathLike) -> None: ...
    def __exit__(self, *args: Any) -> None: ...

class StereoSlam(_Slam):
    @overload
    def __init__(self, settings: Settings, vocabulary: Optional[Vocabulary] = None, *, deterministic: bool = False,
                 localisation_only: bool = False, loop_closing: bool = True, seed: int = 0,
                 fps: Optional[float] = None) -> None: ...
    @overload
    def __init__(self, dataset: Dataset, vocabulary: Optional[Vocabulary] = None, *, deterministic: bool = False,
                 localisation_only: bool = False, loop_closing: bool = True, seed: int = 0,
                 fps: Optional[float] = None) -> None: ...
    @overload
    def track(self, left: npt.NDArray[np.uint8], right: npt.NDArray[np.uint8], timestamp: float) -> TrackResult: ...
    @overload
    def track(self, frame: Frame) -> TrackResult: ...
    def __enter__(self) -> StereoSlam: ...

class RgbdSlam(_Slam):
    @overload
    def __init__(self, settings: Settings, vocabulary: Optional[Vocabulary] = None, *, deterministic: bool = False,
                 localisation_only: bool = False, loop_closing: bool = True, seed: int = 0,
                 fps: Optional[float] = None) -> None: ...
    @overload
    def __init__(self, dataset: Dataset, vocabulary: Optional[Vocabulary] = None, *, deterministic: bool = False,
                 localisation_only: bool = False, loop_closing: bool = True, seed: int = 0,
                 fps: Optional[float] = None) -> None: ...
    @overload
    def track(self, image: npt.NDArray[np.uint8], depth: Union[npt.NDArray[np.uint16], npt.NDArray[np.float32]],
              timestamp: float) -> TrackResult: ...
    @overload
    def track(self, frame: Frame) -> TrackResult: ...
    def __enter__(self) -> RgbdSlam: ...

# ---- evaluation -------------------------------------------------------------------------------

class AteResult:
    rmse: float
    mean: float
    median: float
    max: float
    min: float
    std: float
    count: int
    scale: float
    alignment: npt.NDArray[np.float64]
    errors: npt.NDArray[np.float64]
    aligned_estimate: npt.NDArray[np.float64]

class RpeResult:
    rmse: float
    mean: float
    median: float
    max: float
    min: float
    std: float
    count: int
    rotation_deg: Dict[str, float]
    matched: int
    times: npt.NDArray[np.float64]
    translation_errors: npt.NDArray[np.float64]
    rotation_errors_deg: npt.NDArray[np.float64]

def ate(gt: TrajectoryLike, est: TrajectoryLike, align: str = "se3", max_dt: float = 0.02,
        format: Optional[str] = None, gt_times: Optional[str] = None, est_times: Optional[str] = None) -> AteResult: ...
def rpe(gt: TrajectoryLike, est: TrajectoryLike, delta: float = 1.0, delta_unit: str = "frames", align: str = "none",
        max_dt: float = 0.02, format: Optional[str] = None, gt_times: Optional[str] = None,
        est_times: Optional[str] = None) -> RpeResult: ...
def kitti_metric(gt: TrajectoryLike, est: TrajectoryLike, align: str = "none", max_dt: float = 0.02,
                 format: Optional[str] = None, gt_times: Optional[str] = None,
                 est_times: Optional[str] = None) -> Dict[str, Any]: ...

# ---- bundle adjustment ------------------------------------------------------------------------

class BalProblem:
    def __init__(self, cameras: npt.ArrayLike, points: npt.ArrayLike, camera_index: npt.ArrayLike,
                 point_index: npt.ArrayLike, pixels: npt.ArrayLike) -> None: ...
    cameras: npt.NDArray[np.float64]
    points: npt.NDArray[np.float64]
    @property
    def observations(self) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    def write(self, path: PathLike) -> None: ...

def read_bal(path: PathLike) -> BalProblem: ...
def solve_bal(problem: BalProblem, huber: float = 1.0, max_iterations: int = 50, function_tolerance: float = 1e-6,
              linear_solver: str = "auto") -> Dict[str, Any]: ...
