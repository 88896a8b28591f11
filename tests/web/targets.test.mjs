// What the user sees of targets, centre-lines and grips, and how targets are edited: checked
// from the page's pixels and the rendered scene, not only from the server's state. `shapectl
// serve` on the bundled YuMi scenes, Debian's Chromium headless, real mouse and keyboard events.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { startServer, launchChromium, waitFor, openPage, colourNear, pixelsAt, RawWebSocket, sourceDir, closeAll, centreNodeOnPage } from './support.mjs';

const cli = process.env.SHAPECTL_CLI ?? path.join(sourceDir, 'build/shapectl');
const ORANGE = [0xff, 0x8c, 0x1a];      // targets and the followed centre-line
const SKETCH = [0xff, 0xe0, 0x8a];      // the stroke being drawn
const GRIP_RED = [0xff, 0x22, 0x22];
const hooks = (page, f, arg) => page.evaluate(f, arg);
const state = (page) => hooks(page, () => window.shapectl.state);
const toPage = (page, points) => hooks(page, (ps) => ps.map((p) => window.shapectl.worldToPage(p)), points);
const fraction = (flags) => flags.filter(Boolean).length / flags.length;
const distance = (a, b) => Math.hypot(...a.map((v, i) => v - b[i]));

async function shot(page, layers = {}) {
  await hooks(page, (l) => window.shapectl.setLayers(l), layers);
  return page.screenshot();
}

// Presses at the first point, moves through the others in small steps, and (unless `hold`)
// releases at the last one.
async function stroke(page, points, { hold = false } = {}) {
  await page.mouse.move(points[0].x, points[0].y);
  await page.mouse.down();
  for (const p of points.slice(1)) {
    await page.mouse.move(p.x, p.y, { steps: 3 });
    await page.waitForTimeout(15);
  }
  if (!hold) await page.mouse.up();
}

// Every node of the object inside the 3D view's box.
async function objectInView(page) {
  await waitFor(() => hooks(page, () => window.shapectl.ready), 'the page to draw');
  const { nodes, view } = await hooks(page, () => window.shapectl.objectOnPage());
  const outside = nodes.filter((p) => p.x < view.left || p.x > view.right || p.y < view.top || p.y > view.bottom);
  return { outside: outside.length, nodes: nodes.length };
}

async function gripsDrawn(page) {
  await waitFor(() => hooks(page, () => window.shapectl.ready), 'the page to draw');
  const scene = await hooks(page, () => window.shapectl.scene);
  const nodes = scene.grips.flatMap((g) => g.nodes);
  const points = await hooks(page, (ns) => ns.map((n) => window.shapectl.nodeToPage(n)), nodes);
  return fraction(await colourNear(page, await shot(page), points, GRIP_RED, { radius: 2 }));
}

// Clicks the node nearest the object's centroid (a bent object's centroid may lie off it).
async function addTargetAtCentre(page) {
  await waitFor(() => hooks(page, () => window.shapectl.ready), 'the page to draw');
  const centre = await centreNodeOnPage(page);
  const before = (await state(page)).targets.length;
  await page.mouse.click(centre.x, centre.y);
  const s = await waitFor(async () => { const s = await state(page); return s.targets.length > before && s; }, 'a target from the click')
    .catch(async (e) => {
      const seen = await hooks(page, () => ({ sketch: document.getElementById('sketch').className, status: window.shapectl.state.status }));
      throw new Error(`${e.message}; clicked at ${JSON.stringify(centre)}, page: ${JSON.stringify(seen)}`);
    });
  return s.targets[s.targets.length - 1];
}

async function targetOf(page, node) {
  return (await state(page)).targets.find((t) => t.node === node);
}

describe('targets in the browser GUI', () => {
  let server, browser, page, dir;

  before(async () => {
    dir = mkdtempSync(path.join(tmpdir(), 'shapectl-targets-'));
    server = await startServer([]);
    browser = await launchChromium();
    page = await openPage(browser, server.url);
  });

  after(async () => {
    try {
      await closeAll(browser, server);  // fails on any console problem of the run
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });

  it('frames the whole object on load, on the f key and after a scene switch', async () => {
    assert.deepEqual(await objectInView(page), { outside: 0, nodes: (await hooks(page, () => window.shapectl.scene)).node_count });
    // Zoom in until part of the object leaves the view, then f brings all of it back.
    const centre = await hooks(page, () => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
    await page.mouse.move(centre.x, centre.y);
    for (let k = 0; k < 12; k++) await page.mouse.wheel(0, -300);
    await waitFor(async () => (await objectInView(page)).outside > 0, 'the zoom to cut the object off');
    await page.keyboard.press('f');
    assert.equal((await objectInView(page)).outside, 0, 'f fits the view');

    await page.selectOption('#scene-select', 'yumi_frame.json');
    await waitFor(async () => (await hooks(page, () => window.shapectl.scene)).scene === 'yumi_frame.json' &&
      (await state(page))?.scene === 'yumi_frame.json', 'the frame scene');
    assert.equal((await objectInView(page)).outside, 0, 'the frame is all in view after the switch');
    const frameGrips = await gripsDrawn(page);
    assert.ok(frameGrips > 0.5, `grip markers drawn at ${frameGrips} of the frame's gripped nodes`);

    await page.selectOption('#scene-select', 'yumi_bar.json');
    await waitFor(async () => (await state(page))?.scene === 'yumi_bar.json', 'the bar scene again');
    assert.equal((await objectInView(page)).outside, 0, 'the bar is all in view after the switch');
    const barGrips = await gripsDrawn(page);
    assert.ok(barGrips > 0.5, `grip markers drawn at ${barGrips} of the bar's gripped nodes`);
  });

  it('draws the sketch while drawing and the followed centre-line after it', async () => {
    const scene = await hooks(page, () => window.shapectl.scene);
    const { center, direction, length } = scene.bar;
    const curve = Array.from({ length: 21 }, (_, k) => {
      const t = k / 20, s = (t - 0.4) * 0.8 * length;
      return center.map((c, i) => c + direction[i] * s + (i === 2 ? 0.015 * Math.sin(Math.PI * t) : 0));
    });
    await page.click('#face-bar');
    await page.click('#sketch');
    const points = await toPage(page, curve);
    await stroke(page, points, { hold: true });
    await waitFor(() => hooks(page, () => !window.shapectl.renderPending), 'the stroke to be drawn');
    await page.waitForTimeout(100);
    // The stroke so far, in its colour, along the pointer's path (the first and last samples
    // may be dropped by the 2 mm spacing).
    const drawing = await colourNear(page, await shot(page, { targets: false }), points.slice(1, -1), SKETCH);
    assert.ok(fraction(drawing) > 0.9, `the stroke shows at ${fraction(drawing)} of the pointer's path`);
    await page.mouse.up();

    const followed = await waitFor(async () => { const s = await state(page); return s.centerline.length >= 2 && s; }, 'the centre-line on the server');
    await page.waitForTimeout(200);
    const along = await toPage(page, followed.centerline);
    // Arrows and handles hidden: only the centre-line is orange.
    const drawn = await colourNear(page, await shot(page, { targets: false }), along, ORANGE);
    assert.ok(fraction(drawn) > 0.9, `the centre-line shows at ${fraction(drawn)} of its points`);
    const bare = await colourNear(page, await shot(page, { object: false, targets: false }), along, ORANGE);
    assert.ok(fraction(bare) < 0.1, `nothing else orange there (${fraction(bare)})`);
    await shot(page);
    assert.deepEqual(page.problems, [], 'no three.js warnings while sketching');
  });

  it('keeps a target dragged behind the robot visible and grabbable', async () => {
    await page.click('#clear');
    await waitFor(async () => (await state(page)).targets.length === 0 && (await state(page)).centerline.length === 0, 'cleared');
    await page.keyboard.press('f');
    const target = await addTargetAtCentre(page);
    // Drag it (in the plane facing the camera) to where an arm is between it and the camera:
    // on the line of sight through the origin of the link nearest the camera.
    const behind = await hooks(page, (from) => {
      const s = window.shapectl.state, eye = window.shapectl.cameraPosition(), view = window.shapectl.cameraDirection();
      const depth = (p) => p.reduce((sum, v, i) => sum + (v - eye[i]) * view[i], 0);
      const plane = depth(from);
      const inFront = s.links.map((m) => [m[12], m[13], m[14]]).filter((p) => {
        const q = window.shapectl.worldToPage(p);
        return depth(p) < plane - 0.1 && q.x > 50 && q.x < 900 && q.y > 50 && q.y < 750;
      });
      const nearest = inFront.sort((a, b) => depth(a) - depth(b))[0];
      return nearest && nearest.map((v, i) => eye[i] + (v - eye[i]) * plane / depth(nearest));
    }, target.position);
    assert.ok(behind, 'a link between the camera and the target plane');
    const from = target.position, path3d = Array.from({ length: 13 }, (_, k) => from.map((v, i) => v + (behind[i] - v) * k / 12));
    await stroke(page, await toPage(page, path3d));
    await waitFor(async () => distance((await targetOf(page, target.node)).position, behind) < 0.01, 'the target behind the robot');
    await page.waitForTimeout(400);  // the local copy is dropped: drawn from the server's state
    const [where] = await toPage(page, [(await targetOf(page, target.node)).position]);
    const [withRobot] = await pixelsAt(page, await shot(page, { targets: false }), [where]);
    const [withoutRobot] = await pixelsAt(page, await shot(page, { robot: false, targets: false }), [where]);
    assert.ok(distance(withRobot, withoutRobot) > 30, `the robot covers that place (${withRobot} vs ${withoutRobot} without it)`);
    const [robotOrange] = await colourNear(page, await shot(page, { targets: false }), [where], ORANGE, { radius: 1 });
    const [handleThere] = await colourNear(page, await shot(page), [where], ORANGE, { radius: 1 });
    assert.ok(!robotOrange && handleThere, `the handle is drawn over the robot (orange without it: ${robotOrange}, with: ${handleThere})`);
    // t: a see-through robot shows what is behind it; t again: solid. Judged on a 9 x 9 grid of
    // pixels around the place (4 px apart), not on one: behind a translucent link another one
    // may show nearly the same colour at a single pixel, lighter or darker by the pose.
    const around = Array.from({ length: 81 }, (_, k) => ({ x: where.x + 4 * ((k % 9) - 4), y: where.y + 4 * (Math.floor(k / 9) - 4) }));
    const solid = await pixelsAt(page, await shot(page, { targets: false }), around);
    await page.keyboard.press('t');
    const seeThrough = await pixelsAt(page, await shot(page, { targets: false }), around);
    await page.keyboard.press('t');
    const solidAgain = await pixelsAt(page, await shot(page, { targets: false }), around);
    const changed = (pixels) => pixels.filter((p, k) => distance(p, solid[k]) > 20).length;
    assert.ok(changed(seeThrough) >= 20,
      `see-through changed ${changed(seeThrough)} of 81 pixels around the place (centre: ${seeThrough[40]} against ${solid[40]} solid, ${withoutRobot} without the robot)`);
    assert.equal(changed(solidAgain), 0, `solid again: ${solidAgain[40]} against ${solid[40]}`);
    // Grab it again where it is drawn and drag it back down.
    const back = (await targetOf(page, target.node)).position.map((v, i) => v + (from[i] - v) * 0.5);
    const again = await toPage(page, Array.from({ length: 9 }, (_, k) => behind.map((v, i) => v + (back[i] - v) * k / 8)));
    await stroke(page, again);
    await waitFor(async () => distance((await targetOf(page, target.node)).position, back) < 0.01, 'the target grabbed again');
    assert.equal((await state(page)).targets.length, 1, 'dragged, not added');
  });

  it('moves the selected target along z only with the gizmo, and along an axis with z held', async () => {
    await page.click('#reset');  // the reference pose, whatever the test before left
    await waitFor(async () => (await state(page)).targets.length === 0, 'reset');
    await page.keyboard.press('f');
    const target = await addTargetAtCentre(page);
    const gizmo = await waitFor(() => hooks(page, () => window.shapectl.gizmo()), 'the gizmo on the selected target');
    assert.equal(gizmo.node, target.node);
    const start = (await targetOf(page, target.node)).position;
    // Press on the z arrow (inside the arrow, off its plane squares), drag 60 px up and 25 px aside.
    const onZ = { x: gizmo.centre.x + 0.8 * (gizmo.z.x - gizmo.centre.x), y: gizmo.centre.y + 0.8 * (gizmo.z.y - gizmo.centre.y) };
    await stroke(page, Array.from({ length: 7 }, (_, k) => ({ x: onZ.x + 4 * k, y: onZ.y - 10 * k })));
    const moved = await waitFor(async () => {
      const t = await targetOf(page, target.node);
      return t.position[2] - start[2] > 0.005 && t;
    }, 'the target to rise');
    await page.waitForTimeout(300);
    const end = (await targetOf(page, target.node)).position;
    assert.ok(Math.abs(end[0] - start[0]) < 1e-4 && Math.abs(end[1] - start[1]) < 1e-4,
      `x and y kept to 0.1 mm: ${JSON.stringify(start)} → ${JSON.stringify(end)} (${JSON.stringify(moved.position)})`);

    // Holding z while dragging the handle: same, without the gizmo.
    const [handle] = await toPage(page, [end]);
    await page.keyboard.down('z');
    await stroke(page, Array.from({ length: 7 }, (_, k) => ({ x: handle.x + 5 * k, y: handle.y + 8 * k })));
    await page.keyboard.up('z');
    const lowered = await waitFor(async () => {
      const t = await targetOf(page, target.node);
      return end[2] - t.position[2] > 0.003 && t;
    }, 'the target to go down');
    await page.waitForTimeout(300);
    const final = (await targetOf(page, target.node)).position;
    assert.ok(Math.abs(final[0] - end[0]) < 1e-4 && Math.abs(final[1] - end[1]) < 1e-4,
      `z held: x and y kept to 0.1 mm: ${JSON.stringify(end)} → ${JSON.stringify(final)} (${JSON.stringify(lowered.position)})`);
  });

  it('lands typed coordinates exactly, and undoes and redoes them', async () => {
    const node = await hooks(page, () => window.shapectl.selected);
    const before = (await targetOf(page, node)).position;
    const typed = [412.5, -3.2, 287.9];  // mm
    await page.fill('#target-x', String(typed[0]));
    await page.fill('#target-y', String(typed[1]));
    await page.fill('#target-z', String(typed[2]));
    await page.press('#target-z', 'Enter');
    const landed = typed.map((v) => v / 1000);
    await waitFor(async () => { const t = await targetOf(page, node); return distance(t.position, landed) < 1e-12 || !t.position; }, 'the typed target on the server')
      .catch(async (e) => { throw new Error(`${e.message}: ${JSON.stringify(await targetOf(page, node))}, selected ${node}`); });
    assert.deepEqual((await targetOf(page, node)).position, landed);

    // Three typed fields are three edits; undo them one by one back to where it was.
    await page.click('#panel h1');  // out of the fields: the page's keys, not the field's undo
    for (let k = 0; k < 3; k++) await page.keyboard.press('Control+z');
    await waitFor(async () => distance((await targetOf(page, node)).position, before) < 1e-12, 'undo to the previous target');
    await page.keyboard.press('Control+Shift+z');
    await waitFor(async () => distance((await targetOf(page, node)).position, [landed[0], before[1], before[2]]) < 1e-12, 'redo of x');
    await page.keyboard.press('Control+y');
    await page.keyboard.press('Control+y');
    await waitFor(async () => distance((await targetOf(page, node)).position, landed) < 1e-12, 'redo of y and z');
  });

  it('saves targets and joints as the CLI reads them, and loads them after a reload', async () => {
    const ws = await RawWebSocket.connect(server.port);
    const asked = [{ node: 12, position: [0.40, 0.02, 0.33] }, { node: 200, position: [0.38, -0.01, 0.31] }];
    ws.sendJson({ type: 'set_targets', id: 1, targets: asked });
    await ws.next((m) => m.text && JSON.parse(m.text).id === 1);
    ws.close();
    // Saved once the optimizer has stopped: loading joints jogs the robot there, and a jog
    // further than max_jog_step (0.05 rad) from where the optimizer went on to is refused.
    const shown = await waitFor(async () => {
      const s = await state(page);
      return s.targets.length === 2 && s.status !== 'optimizing' && s;
    }, 'the two targets, optimized');

    const save = async (button) => {
      const [download] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
      const file = path.join(dir, download.suggestedFilename());
      await download.saveAs(file);
      return file;
    };
    const targetsFile = await save('#save-targets');
    const jointsFile = await save('#save-joints');
    assert.equal(path.basename(targetsFile), 'targets.json');
    const savedJoints = JSON.parse(readFileSync(jointsFile, 'utf8')).joints;
    const scene = await hooks(page, () => window.shapectl.scene);
    assert.deepEqual(Object.keys(savedJoints), scene.robot.joint_names);

    // The CLI reads both files: its result's targets are the page's.
    const scenePath = path.join(sourceDir, 'scenes/yumi_bar.json'), out = path.join(dir, 'result.json');
    execFileSync(cli, ['solve', scenePath, '--targets', targetsFile, '--out', out, '--max-iterations', '1'], { stdio: 'pipe' });
    const solved = JSON.parse(readFileSync(out, 'utf8'));
    assert.deepEqual(solved.targets.map((t) => [t.node, t.position]), shown.targets.map((t) => [t.node, t.position]));
    execFileSync(cli, ['statics', scenePath, '--joints', jointsFile, '--out', path.join(dir, 'statics.json')], { stdio: 'pipe' });

    await page.reload();
    await waitFor(() => hooks(page, () => window.shapectl.ready), 'the reloaded page');
    await page.click('#clear');
    await waitFor(async () => (await state(page)).targets.length === 0, 'cleared');
    await page.setInputFiles('#load-file', [targetsFile, jointsFile]);
    const loaded = await waitFor(async () => {
      const s = await state(page);
      return s.targets.length === 2 && s.paused && s;
    }, 'the loaded targets and joints');
    assert.deepEqual(loaded.targets.map((t) => [t.node, t.position]), solved.targets.map((t) => [t.node, t.position]));
    const joints = await waitFor(async () => {
      const s = await state(page);
      return scene.robot.joint_names.every((name, k) => Math.abs(s.joints[k] - savedJoints[name]) < 1e-12) && s;
    }, 'the loaded joints').catch(async (e) => {
      throw new Error(`${e.message}; toast: ${await page.locator('#toast').textContent()}`);
    });
    assert.ok(joints.paused, 'loading joints pauses the optimizer');
    // A file that is neither says so.
    await page.setInputFiles('#load-file', { name: 'notes.json', mimeType: 'application/json', buffer: Buffer.from('{"note": 1}') });
    await waitFor(() => page.locator('#toast').textContent().then((t) => t.includes('notes.json') && t), 'the file error as a toast');
    await page.click('#pause');
  });
});
