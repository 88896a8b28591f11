"""Type stubs of the compiled module (docstrings are on the objects themselves).
Attributes are read-only properties."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int32]
Joints = Union[None, Mapping[str, float], Sequence[float], npt.ArrayLike]
Targets = Union[str, os.PathLike, Mapping[str, Any]]

class SolverError(RuntimeError): ...

class Pose:
    position: FloatArray  # (3,)
    rotation: FloatArray  # (3, 3)

class LimitViolation:
    joint: str
    value: float
    lower: float
    upper: float

class Robot:
    @staticmethod
    def load(urdf: Union[str, os.PathLike]) -> Robot: ...
    name: str
    link_names: List[str]
    joint_names: List[str]
    lower_limits: FloatArray
    upper_limits: FloatArray
    has_collision_spheres: bool
    warnings: List[str]

class Scene:
    @staticmethod
    def load(path: Union[str, os.PathLike]) -> Scene: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any], base_dir: Union[str, os.PathLike] = ".") -> Scene: ...
    def to_dict(self, base_dir: Optional[Union[str, os.PathLike]] = None) -> Dict[str, Any]: ...
    source: str
    node_count: int
    tet_count: int
    tets: IntArray  # (tets, 4)
    rest_positions: FloatArray  # (n, 3)
    has_robot: bool
    robot: Optional[Robot]
    joint_names: List[str]
    reference_joints: FloatArray  # (m,)
    end_effectors: List[str]
    grip_nodes: List[List[int]]
    warnings: List[str]

class StaticsResult:
    converged: bool
    status: str
    reason: str
    iterations: int
    factorizations: int
    residual: float
    energy: float

class StaticsSolution:
    converged: bool
    status: str
    reason: str
    iterations: int
    residual: float
    energy: float
    result: StaticsResult
    loads_total: FloatArray  # (3,), N
    contacts: Optional[Dict[str, Any]]  # count, min_distance, force_total, by_obstacle, self; None without obstacles and self-contact
    positions: FloatArray  # (n, 3)
    joints: Optional[FloatArray]  # (m,)
    joint_names: List[str]
    tools: Dict[str, Pose]

def statics(scene: Scene, joints: Joints = None) -> StaticsSolution: ...

class ObjectState:
    joints: FloatArray
    positions: FloatArray  # (n, 3)
    statics: StaticsResult
    tools: Dict[str, Pose]

class GrippedObject:
    def __init__(self, scene: Scene) -> None: ...
    node_count: int
    joint_count: int
    joint_names: List[str]
    reference_joints: FloatArray
    reference_positions: FloatArray
    def solve(self, joints: Joints = None, warm_start: Optional[npt.ArrayLike] = None,
              max_iterations: int = 0) -> ObjectState: ...
    def sensitivity(self, state: ObjectState) -> FloatArray: ...  # (3n, m)

class SpherePair:
    links: Tuple[str, str]
    spheres: Tuple[int, int]
    clearance: float

class Kinematics:
    joints: FloatArray
    joint_names: List[str]
    links: Dict[str, Pose]
    tools: Dict[str, Pose]
    min_clearance: Optional[float]
    margin: Optional[float]
    closest_pairs: List[SpherePair]
    limit_violations: List[LimitViolation]

@overload
def kinematics(robot: Robot, joints: Joints = None,
               spheres: Optional[Union[str, os.PathLike]] = None) -> Kinematics: ...
@overload
def kinematics(scene: Scene, joints: Joints = None) -> Kinematics: ...

class HistoryEntry:
    iteration: int
    time: float
    error_mean: float
    objective: float

class SolveTiming:
    statics_solves: int
    statics_seconds: float
    gradient_evaluations: int
    gradient_seconds: float

class SolveResult:
    joints: FloatArray
    joint_names: List[str]
    converged: bool
    termination: str
    reason: str
    status: str  # reached, best effort, failed
    unreachable: List[str]  # joint limit, collision, reach, buckling
    status_reason: str
    tolerance: float
    iterations: int
    error_mean: float
    error_max: float
    objective: float
    min_clearance: Optional[float]
    limit_violations: List[LimitViolation]
    loads_total: FloatArray  # (3,), N
    contacts: Optional[Dict[str, Any]]  # count, min_distance, force_total, by_obstacle, self; None without obstacles and self-contact
    positions: FloatArray  # (n, 3)
    target_nodes: IntArray  # (k,)
    target_positions: FloatArray  # (k, 3)
    history: List[HistoryEntry]
    timing: SolveTiming
    tools: Dict[str, Pose]

def solve(scene: Scene, targets: Targets, *, optimizer: str = "gauss-newton",
          gradient: str = "sensitivity", max_iterations: int = 100,
          max_seconds: float = 60.0, tolerance: float = 1e-3) -> SolveResult: ...

class ControllerSnapshot:
    sequence: int
    time: float
    status: str  # idle, optimizing, reached, best effort, paused, failed
    tolerance: float
    unreachable: List[str]  # joint limit, collision, reach, buckling
    status_reason: str
    joint_names: List[str]
    joints: FloatArray
    lower_limits: FloatArray
    upper_limits: FloatArray
    links: Dict[str, Pose]
    positions: FloatArray
    target_nodes: IntArray
    target_positions: FloatArray
    error_mean: float
    error_max: float
    objective: float
    min_clearance: float
    within_limits: bool
    safe: bool
    iterations: int
    paused: bool
    last_error: str

class Controller:
    def __init__(self, scene: Scene, *, optimizer: str = "gauss-newton",
                 gradient: str = "sensitivity", start: bool = True) -> None: ...
    def start(self) -> None: ...
    def stop(self) -> None: ...
    def step(self) -> None: ...
    def set_targets(self, targets: Targets) -> None: ...
    def set_centerline(self, points: npt.ArrayLike) -> None: ...
    def clear_targets(self) -> None: ...
    def pause(self) -> None: ...
    def resume(self) -> None: ...
    def jog(self, joints: Joints) -> None: ...
    def reset(self) -> None: ...
    def snapshot(self) -> ControllerSnapshot: ...
    def wait_for_snapshot(self, after: int, timeout: float = 1.0) -> ControllerSnapshot: ...
    node_count: int
    def close(self) -> None: ...
    def __enter__(self) -> Controller: ...
    def __exit__(self, *args: Any) -> None: ...

class FittedParameter:
    name: str
    unit: str
    initial: float
    fitted: float
    standard_deviation: Optional[float]
    identifiable: bool
    verdict: str
    prior: Optional[float]
    implausible: bool
    trades_off_with: List[str]
    suggestion: str

class UnidentifiedDirection:
    not_determined: Dict[str, float]
    standard_deviation_in_scales: float
    held_at_initial_value: str
    suggestion: str

class FrameFit:
    rms_before: float
    rms_after: float
    markers: int
    points: int
    inlier_points_after: int

class CalibrationResult:
    scene: Scene
    converged: bool
    reason: str
    iterations: int
    seconds: float
    parameters: List[FittedParameter]
    identifiability: List[UnidentifiedDirection]
    implausible: List[str]
    rms_before: float
    rms_after: float
    chi_squared_per_dof: float
    frames: List[FrameFit]

Observations = Union[str, os.PathLike, Mapping[str, Any]]

def calibrate(scene: Scene, observations: Observations, *,
              fit: Optional[Union[str, Sequence[str]]] = None,
              max_iterations: int = 30, max_seconds: float = 300.0, prior: str = "",
              bounds: str = "") -> CalibrationResult: ...

def configure_runtime(*, threads: Optional[int] = None, blas_threads: Optional[int] = None,
                      blas_idle_timeout: Optional[int] = None,
                      keep_freed_heap: Optional[bool] = None,
                      start_threads: Optional[bool] = None) -> Dict[str, Union[int, bool]]: ...
def runtime_settings() -> Dict[str, Union[int, bool]]: ...
