// The CLI's JSON files, written and read by the page (README: `solve --targets`, `statics
// --joints`): TARGETS.json is {"targets": [{"node", "position"}]} or {"centerline": [[x, y, z]]}
// (optionally "units": "m", "cm" or "mm"), JOINTS.json {"joints": {name: rad}}. World frame,
// metres (read files are converted), radians.

// A state's targets as TARGETS.json: the centre-line when one is followed (its targets derive
// from it), else the targets.
export function targetsFileBody(state) {
  if (state.centerline.length >= 2) return { centerline: state.centerline };
  return { targets: state.targets.map((t) => ({ node: t.node, position: t.position })) };
}

// A state's joints as JOINTS.json, named as in the scene's robot.
export function jointsFileBody(state, robot) {
  return { joints: Object.fromEntries(robot.joint_names.map((name, k) => [name, state.joints[k]])) };
}

// What a loaded file asks for: {targets?, centerline?, joints?} with joints in `robot`'s active
// joint order, positions in metres. A result file of `solve`, `statics` or `run` works too (its
// joints, and its targets; `run` gives its joints as arrays beside "joint_names"). Throws an Error
// naming the file and the field when it is neither.
export function readTargetsOrJoints(name, text, robot) {
  let json;
  try {
    json = JSON.parse(text);
  } catch (e) {
    throw new Error(`${name}: not JSON (${e.message})`);
  }
  if (json === null || typeof json !== 'object' || Array.isArray(json))
    throw new Error(`${name}: expected an object with "targets", "centerline" or "joints"`);
  const units = json.units ?? 'm';
  if (!Object.hasOwn(METRES_PER_UNIT, units))
    throw new Error(`${name}: units: expected "m", "cm" or "mm", got ${JSON.stringify(json.units)}`);
  const scale = METRES_PER_UNIT[units];
  const out = {};
  if (Array.isArray(json.centerline) && json.centerline.length >= 2) out.centerline = json.centerline.map((p, k) => metres(point(name, `centerline[${k}]`, p), scale));
  else if (Array.isArray(json.targets)) out.targets = json.targets.map((t, k) => target(name, k, t, scale));
  if (json.joints !== undefined) out.joints = jointValues(name, namedJoints(json), robot);
  if (!out.targets && !out.centerline && !out.joints)
    throw new Error(`${name}: expected "targets", "centerline" or "joints"; found ${Object.keys(json).join(', ') || 'nothing'}`);
  return out;
}

function point(name, field, p) {
  if (!Array.isArray(p) || p.length !== 3 || !p.every(Number.isFinite))
    throw new Error(`${name}: ${field}: expected [x, y, z] (m), got ${JSON.stringify(p)}`);
  return p;
}

const METRES_PER_UNIT = { m: 1, cm: 0.01, mm: 0.001 };

function metres(p, scale) {
  return scale === 1 ? p : p.map((c) => c * scale);
}

function target(name, k, t, scale) {
  if (!Number.isInteger(t?.node) || t.node < 0) throw new Error(`${name}: targets[${k}].node: expected a node index, got ${JSON.stringify(t?.node)}`);
  return { node: t.node, position: metres(point(name, `targets[${k}].position`, t.position), scale) };
}

// {name: rad}: as written, or from `run`'s "joint_names" and "joints" arrays.
function namedJoints(json) {
  if (!Array.isArray(json.joints) || !Array.isArray(json.joint_names)) return json.joints;
  return Object.fromEntries(json.joint_names.map((joint, k) => [joint, json.joints[k]]));
}

function jointValues(name, joints, robot) {
  if (!robot) throw new Error(`${name}: joints: this scene has no robot`);
  if (joints === null || typeof joints !== 'object' || Array.isArray(joints))
    throw new Error(`${name}: joints: expected {name: rad}`);
  return robot.joint_names.map((joint) => {
    const value = joints[joint];
    if (!Number.isFinite(value)) throw new Error(`${name}: joints.${joint}: expected a number (rad), got ${JSON.stringify(value)}`);
    return value;
  });
}
