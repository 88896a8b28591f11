"""shapectl: shape control of elastic objects held by a robot, from Python.

The library's model and algorithms (the same code as the `shapectl` command): load a scene (from
a file or a dict of the same schema), solve the object's statics at joint angles, take
sensitivities dx/dθ, the robot's kinematics, optimize joints for a target shape, run the
continuous controller in a background thread, or calibrate the model to observations.
Many independent solves on a Dask cluster: shapectl.batch (imported on its own; needs dask).

Arrays are float64 numpy arrays: positions (n, 3) in metres, world frame, mesh node order;
joints (m,) in radians, in the scene's active-joint order; sensitivities (3n, m).
Bad input raises ValueError with the CLI's message, or TypeError for a value of the wrong type
(a bool, str, complex number, object or masked array: nothing is coerced); a computation that
fails raises SolverError.
Long computations release the GIL, so other Python threads run meanwhile.
Importing the module applies the CLI's process-wide tuning (thread counts, OpenBLAS's idle
threads, the heap; docs/runtime.md); configure_runtime(...) changes it, runtime_settings() shows it.

    import shapectl
    scene = shapectl.Scene.load("scenes/yumi_bar.json")
    eq = shapectl.statics(scene)                     # eq.positions: (425, 3)
"""

from ._shapectl import (
    CalibrationResult,
    Controller,
    ControllerSnapshot,
    FittedParameter,
    FrameFit,
    GrippedObject,
    HistoryEntry,
    Kinematics,
    LimitViolation,
    ObjectState,
    Pose,
    Robot,
    Scene,
    SolveResult,
    SolveTiming,
    SolverError,
    SpherePair,
    StaticsResult,
    StaticsSolution,
    UnidentifiedDirection,
    calibrate,
    configure_runtime,
    kinematics,
    runtime_settings,
    solve,
    statics,
)

__all__ = [
    "CalibrationResult",
    "Controller",
    "ControllerSnapshot",
    "FittedParameter",
    "FrameFit",
    "GrippedObject",
    "HistoryEntry",
    "Kinematics",
    "LimitViolation",
    "ObjectState",
    "Pose",
    "Robot",
    "Scene",
    "SolveResult",
    "SolveTiming",
    "SolverError",
    "SpherePair",
    "StaticsResult",
    "StaticsSolution",
    "UnidentifiedDirection",
    "calibrate",
    "configure_runtime",
    "kinematics",
    "runtime_settings",
    "solve",
    "statics",
]
