# Type stubs of orbis.sources (the compiled orbis._orbis.sources, re-exported).
from __future__ import annotations

import os
from typing import Any, Iterator, List, Optional, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike[str]]

class SourceFrame:
    index: int
    timestamp: float
    image: npt.NDArray[np.uint8]
    right: Optional[npt.NDArray[np.uint8]]
    depth: Optional[npt.NDArray[np.uint16]]
    warnings: List[str]

class Source:
    name: str
    live: bool
    sensor: str
    dropped: int
    end_reason: str
    expected_frames: Optional[int]
    warnings: List[str]
    def __iter__(self) -> Iterator[SourceFrame]: ...
    def __next__(self) -> SourceFrame: ...
    def close(self) -> None: ...
    def __enter__(self) -> Source: ...
    def __exit__(self, *args: Any) -> None: ...

def video(path: str, *, fps: Optional[float] = None, times: Optional[PathLike] = None, stereo: str = "none",
          grey: bool = False, realtime: bool = False, stall: float = 5.0) -> Source: ...
def images(folder: PathLike, *, fps: Optional[float] = None, times: Optional[PathLike] = None, stereo: str = "none",
           grey: bool = False, realtime: bool = False, stall: float = 5.0) -> Source: ...
def camera(device: Union[int, str] = 0, *, fps: Optional[float] = None, stereo: str = "none", grey: bool = False,
           stall: float = 5.0) -> Source: ...
