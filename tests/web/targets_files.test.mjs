// The page's target files and undo history without a browser (web/js/targets_file.js,
// web/js/target_history.js): the CLI's JSON shapes, clear errors for other files, and
// undo/redo order.
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { jointsFileBody, readTargetsOrJoints, targetsFileBody } from '../../web/js/targets_file.js';
import { TargetHistory, targetsSnapshot } from '../../web/js/target_history.js';

const robot = { joint_names: ['a', 'b'] };
const state = (targets, centerline = []) => ({ targets, centerline, joints: [0.1, -0.2] });
const t = (node, z) => ({ node, position: [0.4, 0, z] });

describe('target files', () => {
  it('writes the CLI shapes: targets, or the centre-line that made them, and named joints', () => {
    assert.deepEqual(targetsFileBody(state([t(3, 0.3)])), { targets: [t(3, 0.3)] });
    const line = [[0, 0, 0], [0.1, 0, 0]];
    assert.deepEqual(targetsFileBody(state([t(3, 0.3)], line)), { centerline: line });
    assert.deepEqual(jointsFileBody(state([]), robot), { joints: { a: 0.1, b: -0.2 } });
  });

  it('reads targets, centre-lines, joints and result files back', () => {
    assert.deepEqual(readTargetsOrJoints('t.json', JSON.stringify({ targets: [t(3, 0.3)] }), robot), { targets: [t(3, 0.3)] });
    assert.deepEqual(readTargetsOrJoints('j.json', JSON.stringify({ joints: { b: 2, a: 1 } }), robot), { joints: [1, 2] });
    const result = { converged: true, joints: { a: 1, b: 2 }, targets: [t(1, 0.2)], positions: [] };
    assert.deepEqual(readTargetsOrJoints('r.json', JSON.stringify(result), robot), { targets: [t(1, 0.2)], joints: [1, 2] });
    const run = { settled: true, joint_names: ['b', 'a'], joints: [2, 1], fixed_joints: {} };
    assert.deepEqual(readTargetsOrJoints('run.json', JSON.stringify(run), robot), { joints: [1, 2] });
  });

  it('reads coordinates in the file\'s "units" as metres', () => {
    const mm = { units: 'mm', targets: [{ node: 3, position: [400, 0, 300] }] };
    assert.deepEqual(readTargetsOrJoints('t.json', JSON.stringify(mm), robot), { targets: [t(3, 0.3)] });
    const line = { units: 'cm', centerline: [[0, 0, 0], [10, 0, 0]] };
    assert.deepEqual(readTargetsOrJoints('c.json', JSON.stringify(line), robot), { centerline: [[0, 0, 0], [0.1, 0, 0]] });
    assert.throws(() => readTargetsOrJoints('x.json', '{"units": "ft", "targets": []}', robot), /x\.json: units: expected "m", "cm" or "mm", got "ft"/);
  });

  it('names the file and the field of what it cannot read', () => {
    const fails = (text, pattern) => assert.throws(() => readTargetsOrJoints('x.json', text, robot), pattern);
    fails('{oops', /^Error: x\.json: not JSON/);
    fails('[1, 2]', /x\.json: expected an object with "targets", "centerline" or "joints"/);
    fails('{"note": 1}', /x\.json: expected "targets", "centerline" or "joints"; found note/);
    fails('{"targets": [{"node": -1, "position": [0, 0, 0]}]}', /x\.json: targets\[0\]\.node: expected a node index, got -1/);
    fails('{"targets": [{"node": 1, "position": [0, 0]}]}', /x\.json: targets\[0\]\.position: expected \[x, y, z\] \(m\), got \[0,0\]/);
    fails('{"joints": {"a": 1}}', /x\.json: joints\.b: expected a number \(rad\), got undefined/);
    assert.throws(() => readTargetsOrJoints('x.json', '{"joints": {"a": 1}}', null), /x\.json: joints: this scene has no robot/);
  });
});

describe('target undo history', () => {
  it('undoes edits newest first, redoes them, and forgets redo on a new edit', () => {
    const h = new TargetHistory();
    const s0 = targetsSnapshot(state([])), s1 = targetsSnapshot(state([t(1, 0.3)])), s2 = targetsSnapshot(state([t(1, 0.35)]));
    assert.equal(h.undo(s0), null, 'nothing to undo at first');
    h.record(s0);
    h.record(s1);
    assert.deepEqual(h.undo(s2), s1);
    assert.deepEqual(h.undo(s1), s0);
    assert.equal(h.canUndo, false);
    assert.deepEqual(h.redo(s0), s1);
    assert.deepEqual(h.redo(s1), s2);
    assert.equal(h.canRedo, false);
    h.undo(s2);
    h.record(s1);
    assert.equal(h.canRedo, false, 'a new edit forgets redo');
  });

  it('copies the state: later changes to it do not reach the snapshot', () => {
    const s = state([t(1, 0.3)]);
    const snapshot = targetsSnapshot(s);
    s.targets[0].position[2] = 9;
    assert.equal(snapshot.targets[0].position[2], 0.3);
  });
});
