// Every name that goes over the WebSocket to `shapectl serve` (docs/gui.md), in one place for
// the page and its tests: compare against these, never against a string literal. They must
// match the server's names (src/shapectl/server/, control/controller.cpp, link/).

// Commands, client → server (the order of the server's list; the fuzz test picks by index).
export const Command = Object.freeze({
  Ping: 'ping',
  SetTarget: 'set_target',
  RemoveTarget: 'remove_target',
  SetTargets: 'set_targets',
  ClearTargets: 'clear_targets',
  SetCenterline: 'set_centerline',
  SetPaused: 'set_paused',
  SetJoint: 'set_joint',
  SetJoints: 'set_joints',
  Reset: 'reset',
  LoadScene: 'load_scene',
  Arm: 'arm',
  Disarm: 'disarm',
  Observe: 'observe',
  SetFeedback: 'set_feedback',
  Calibrate: 'calibrate',
  SetAutoCalibration: 'set_auto_calibration',
});

// Text messages, server → client: a reply to a command (to its sender) or a broadcast.
export const Message = Object.freeze({
  Ok: 'ok',
  Error: 'error',
  Scene: 'scene',
  State: 'state',
});

// A state's "status": what the optimizer is doing, and once it stopped, whether the targets were
// met: "reached" (every target error within the state's "tolerance"), "best effort" (stopped
// above it; why in "unreachable" and "status_reason"), or "failed" (see "status_reason").
// The same list as ControllerStatus in src/shapectl/control/controller.hpp (to_string there).
export const ControllerStatus = Object.freeze({
  Idle: 'idle',  // no targets
  Optimizing: 'optimizing',
  Reached: 'reached',
  BestEffort: 'best effort',
  Paused: 'paused',
  Failed: 'failed',
});

// A state's "unreachable": why a best effort stays above the tolerance (src/shapectl/control/
// shortfall.hpp says how each is found). Empty: a local minimum.
export const Shortfall = Object.freeze({
  JointLimit: 'joint limit',
  Collision: 'collision',
  Reach: 'reach',
  Buckling: 'buckling',
});

// A state's "link.kind", and the `serve --robot` value that chooses it.
export const LinkKind = Object.freeze({
  Sim: 'sim',
  Egm: 'egm',
});

// A robot visual's "kind" in the scene message.
export const ShapeKind = Object.freeze({
  Sphere: 'sphere',
  Box: 'box',
  Cylinder: 'cylinder',
  Mesh: 'mesh',  // with "url" (null when the server could not find it), "format", "scale", "file"
});

// A mesh visual's "format": also the extension of its "url".
export const MeshFormat = Object.freeze({
  Stl: 'stl',
  Obj: 'obj',
  Dae: 'dae',
});

// A calibration parameter's "name" in a state's "calibration.result.parameters" (and
// "unidentified[].held"); a grip offset's name goes on with its end effector and coordinate,
// "grip_offsets.left.x".
export const Parameter = Object.freeze({
  YoungsModulus: 'youngs_modulus',
  PoissonRatio: 'poisson_ratio',
  Density: 'density',
  GripOffsets: 'grip_offsets',
});

// A calibration parameter's "unit" (SI).
export const Unit = Object.freeze({
  Pascal: 'Pa',
  None: '',
  KilogramPerCubicMetre: 'kg/m^3',
  Metre: 'm',
  Radian: 'rad',
});

// The first four bytes of a binary positions frame.
export const POSITIONS_MAGIC = 'POS1';
