// The CLI's JSON files, written and read by the page (README: `solve --targets`, `statics
// --joints`): TARGETS.json is {"targets": [{"node", "position"}]} or {"centerline": [[x, y, z]]},
// JOINTS.json {"joints": {name: rad}}. World frame, metres, radians.

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
// joint order. A result file of `solve`, `statics` or `run` works too (its joints, and its
// targets). Throws an Error naming the file and the field when it is neither.
export function readTargetsOrJoints(name, text, robot) {
  let json;
  try {
    json = JSON.parse(text);
  } catch (e) {
    throw new Error(`${name}: not JSON (${e.message})`);
  }
  if (json === null || typeof json !== 'object' || Array.isArray(json))
    throw new Error(`${name}: expected an object with "targets", "centerline" or "joints"`);
  const out = {};
  if (Array.isArray(json.centerline) && json.centerline.length >= 2) out.centerline = json.centerline.map((p, k) => point(name, `centerline[${k}]`, p));
  else if (Array.isArray(json.targets)) out.targets = json.targets.map((t, k) => target(name, k, t));
  if (json.joints !== undefined) out.joints = jointValues(name, json.joints, robot);
  if (!out.targets && !out.centerline && !out.joints)
    throw new Error(`${name}: expected "targets", "centerline" or "joints"; found ${Object.keys(json).join(', ') || 'nothing'}`);
  return out;
}

function point(name, field, p) {
  if (!Array.isArray(p) || p.length !== 3 || !p.every(Number.isFinite))
    throw new Error(`${name}: ${field}: expected [x, y, z] (m), got ${JSON.stringify(p)}`);
  return p;
}

function target(name, k, t) {
  if (!Number.isInteger(t?.node) || t.node < 0) throw new Error(`${name}: targets[${k}].node: expected a node index, got ${JSON.stringify(t?.node)}`);
  return { node: t.node, position: point(name, `targets[${k}].position`, t.position) };
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
