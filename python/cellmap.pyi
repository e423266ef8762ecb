# SPDX-License-Identifier: Apache-2.0
"""Type stubs of the cellmap module (python/*.cpp; docs/python.md).

A box is a float64 array of 10 values [cx, cy, cz, hx, hy, hz, qw, qx, qy, qz]: centre and half extents in
metres, rotation R_CB as a unit quaternion, in the cell frame. Arrays of boxes keep the 10 values last.
"""
from typing import Callable, Optional, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

FloatArray = npt.NDArray[np.float64]
IdArray = npt.NDArray[np.uint64]


class Error(ValueError):
    """A refusal of the C++ side: a bad file, value or credentials; the message names it."""


class Environment:
    def __init__(self, cell: str, version: int, stamp_ns: int, boxes: npt.ArrayLike,
                 ids: Optional[npt.ArrayLike] = None) -> None: ...
    @property
    def cell(self) -> str: ...
    @property
    def version(self) -> int: ...
    @property
    def stamp_ns(self) -> int: ...
    @property
    def ids(self) -> IdArray: ...  # (N,)
    @property
    def centers(self) -> FloatArray: ...  # (N, 3)
    @property
    def half_extents(self) -> FloatArray: ...  # (N, 3)
    @property
    def rotations(self) -> FloatArray: ...  # (N, 4) w, x, y, z
    @property
    def unknown(self) -> npt.NDArray[np.bool_]: ...  # (N,)
    @property
    def boxes(self) -> FloatArray: ...  # (N, 10)
    def __len__(self) -> int: ...
    def __eq__(self, other: object) -> bool: ...


class EnvironmentDelta:
    @property
    def cell(self) -> str: ...
    @property
    def from_version(self) -> int: ...
    @property
    def to_version(self) -> int: ...
    @property
    def stamp_ns(self) -> int: ...
    @property
    def added(self) -> IdArray: ...
    @property
    def modified(self) -> IdArray: ...
    @property
    def removed(self) -> IdArray: ...


class EnvironmentSubscriber:
    def __init__(self, domain: int = 0, cell: str = "cell", security: Optional[str] = None,
                 role: str = "planner",
                 on_change: Optional[Callable[[Environment, EnvironmentDelta], None]] = None) -> None: ...
    def environment(self) -> Optional[Environment]: ...
    def wait(self, timeout: Optional[float] = None, version: Optional[int] = None) -> Optional[Environment]: ...
    def stats(self) -> dict[str, int]: ...
    def last_error(self) -> str: ...
    def close(self) -> None: ...
    def __enter__(self) -> "EnvironmentSubscriber": ...
    def __exit__(self, *args: object) -> None: ...


class SignedDistance(TypedDict):
    distance: float
    point_a: FloatArray  # (3,)
    point_b: FloatArray  # (3,)
    normal: FloatArray  # (3,), from a to b


class BatchDistance(TypedDict):
    distance: FloatArray  # robot's leading axes + (E,)
    point_a: FloatArray  # ... + (E, 3)
    point_b: FloatArray
    normal: FloatArray


class Blocking(TypedDict):
    checkpoint: int
    t: float
    robot_box: int
    box_id: int
    unknown: bool
    distance: float
    point: FloatArray  # (3,)


def distance(a: npt.ArrayLike, b: npt.ArrayLike) -> SignedDistance: ...
def batch_distance(robot: npt.ArrayLike, environment: npt.ArrayLike,
                   out: Optional[BatchDistance] = None) -> BatchDistance: ...
def _batch_distance_seconds(robot: npt.ArrayLike, environment: npt.ArrayLike, repeats: int) -> float: ...
def sphere_cover(box: npt.ArrayLike, n: int) -> FloatArray: ...  # (n, 4)
def sphere_set_distance(a: npt.ArrayLike, b: npt.ArrayLike) -> float: ...
def sphere_box_distance(sphere: npt.ArrayLike, box: npt.ArrayLike) -> float: ...
def read_boxes(path: str) -> Environment: ...
def write_boxes(path: str, environment: Environment) -> None: ...


class PathChecker:
    def __init__(self, urdf: str, tool_link: str) -> None: ...
    @property
    def dof(self) -> int: ...
    @property
    def boxes(self) -> int: ...
    def place(self, q: npt.ArrayLike) -> FloatArray: ...  # (R, 10)
    def blocked(self, control_points: npt.ArrayLike, environment: Environment, checkpoints: int = 50,
                margin: float = 0.0, ignore_unknown: bool = False) -> Optional[Blocking]: ...
