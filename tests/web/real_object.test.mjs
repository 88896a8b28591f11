// The Real object panel end to end. `serve --robot sim --world WORLD.json` with a world whose
// bar is 1.5× as stiff as the model's: the convergence plot draws the observed and true errors,
// and Calibrate fits Young's modulus and shows it with its standard deviation. Then a plain
// `serve`: a point cloud sent in an `observe` message is drawn over the model. What is checked
// is what the user sees: the plot's pixels, the panel's text, the 3D view's points and pixels.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { startServer, launchChromium, openPage, waitFor, differingFraction, RawWebSocket, sourceDir, closeAll, openSession, closeSession } from './support.mjs';
import { Command, LinkKind, Message, Parameter } from '../../web/js/protocol.js';
import { SERIES } from '../../web/js/plot.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const state = (page) => hooks(page, () => window.shapectl.state);
const text = (page, selector) => page.locator(selector).textContent();

// The default scene with Young's modulus × `stiffer`, written to `dir` (its robot files by
// absolute path): the "real" object of `serve --world`.
function writeWorld(dir, stiffer) {
  const scenes = path.join(sourceDir, 'scenes');
  const world = JSON.parse(readFileSync(path.join(scenes, 'yumi_bar.json'), 'utf8'));
  world.object.material.youngs_modulus *= stiffer;
  world.robot.urdf = path.resolve(scenes, world.robot.urdf);
  world.robot.collision_spheres = path.resolve(scenes, world.robot.collision_spheres);
  const file = path.join(dir, 'world.json');
  writeFileSync(file, JSON.stringify(world));
  return file;
}

// Pixels of the convergence plot within a small distance of `hex` ('#rrggbb').
function plotPixelsOf(page, hex) {
  return hooks(page, (colour) => {
    const target = [1, 3, 5].map((i) => parseInt(colour.slice(i, i + 2), 16));
    // Read from a copy: repeated reads of the page's own canvas make Chromium warn on its console.
    const plot = document.getElementById('plot'), copy = document.createElement('canvas');
    copy.width = plot.width; copy.height = plot.height;
    const g = copy.getContext('2d', { willReadFrequently: true });
    g.drawImage(plot, 0, 0);
    const data = g.getImageData(0, 0, copy.width, copy.height).data;
    let count = 0;
    for (let i = 0; i < data.length; i += 4)
      if (data[i + 3] > 200 && Math.abs(data[i] - target[0]) + Math.abs(data[i + 1] - target[1]) + Math.abs(data[i + 2] - target[2]) < 40) count++;
    return count;
  }, hex);
}

// The nodes on the bar's top face in its middle 60 % (away from the grips), each with its
// position and where it lies along the bar (m from the centre).
async function topNodes(page) {
  return hooks(page, () => {
    const { bar } = window.shapectl.scene, x = window.shapectl.positions(), n = x.length / 3;
    const along = (i) => [0, 1, 2].reduce((s, a) => s + (x[3 * i + a] - bar.center[a]) * bar.direction[a], 0);
    let top = -Infinity;
    for (let i = 0; i < n; i++) top = Math.max(top, x[3 * i + 2]);
    const nodes = [];
    for (let i = 0; i < n; i++)
      if (x[3 * i + 2] > top - 0.002 && Math.abs(along(i)) < 0.3 * bar.length)
        nodes.push({ node: i, position: x.slice(3 * i, 3 * i + 3), along: along(i) });
    return nodes;
  });
}

describe('the real object: plot and calibration (serve --world)', () => {
  let dir, server, browser, page, ws;

  before(async () => {
    dir = mkdtempSync(path.join(tmpdir(), 'shapectl-world-'));
    // Calibrations only when the test asks: the model stays the scene's until Calibrate. This
    // stiff foam bar sags about half a millimetre between its grips, so its stiffness shows in
    // the markers by about 0.1 mm: a camera with 30 µm noise, and only Young's modulus fitted
    // (with grip rotations free, markers on the top face cannot tell them from it: it is held).
    server = await startServer(['--robot', LinkKind.Sim, '--world', writeWorld(dir, 1.5), '--camera-sigma', '0.00003',
      '--no-online-calibration', '--fit', Parameter.YoungsModulus]);
    browser = await launchChromium();
    page = await openPage(browser, server.url);
    ws = await RawWebSocket.connect(server.port);
  });

  after(async () => {
    ws?.close();
    await closeAll(browser, server);  // fails on any console problem of the run
    if (dir) rmSync(dir, { recursive: true, force: true });
  });

  const reply = (id) => ws.next((m) => m.text?.includes(`"id":"${id}"`)).then((m) => JSON.parse(m.text));

  it('plots the observed and true errors beside the mean error, with a legend', async () => {
    const observed = SERIES.find((s) => s.name === 'observed');
    assert.equal(await plotPixelsOf(page, observed.colour), 0, 'no observed error before observations');
    assert.equal(await page.locator(`#plot-legend [data-series="${observed.name}"]`).isVisible(), false);
    // The robot follows the optimizer, so the camera sees the bar at each pose the targets ask.
    ws.sendJson({ type: Command.Arm, id: 'arm' });
    assert.equal((await reply('arm')).type, Message.Ok);
    // Targets on the top face, lifted in an arch: the camera observes the target nodes. Three
    // arches, three poses of the robot.
    const [top, { length }] = [await topNodes(page), (await hooks(page, () => window.shapectl.scene)).bar];
    for (const [k, lift] of [0.01, 0.02, 0.005].entries()) {
      const targets = top.map(({ node, position, along }) =>
        ({ node, position: [position[0], position[1], position[2] + lift * Math.cos(Math.PI * along / length)] }));
      ws.sendJson({ type: Command.SetTargets, id: `targets ${k}`, targets });
      assert.equal((await reply(`targets ${k}`)).type, Message.Ok);
      await waitFor(async () => (await state(page)).calibration.frames > k, `observed frames at ${k + 1} poses`, 60000);
    }
    const observedState = await state(page);
    assert.ok(observedState.observations > 0 && observedState.observed_error !== null && observedState.true_error !== null);

    for (const series of SERIES)
      await waitFor(() => page.locator(`#plot-legend [data-series="${series.name}"]`).isVisible(), `the legend's ${series.name} entry`);
    // The observed error's line, on top of the others: its colour in the plot's pixels.
    await waitFor(async () => (await plotPixelsOf(page, observed.colour)) >= 20, 'the observed error\'s line in the plot');
    assert.match(await text(page, '#observed'), /observed error [\d.]+ mm/);
    // The panel says what is happening: frames arriving at the camera's rate (10/s), the
    // feedback's state, no calibration yet.
    const activity = await waitFor(async () => {
      const t = await text(page, '#activity');
      return /observations: arriving at [\d.]+\/s/.test(t) && t;
    }, 'the observation rate in the panel');
    const perSecond = Number(activity.match(/arriving at ([\d.]+)\/s/)[1]);
    assert.ok(perSecond > 3 && perSecond < 15, activity);
    assert.match(activity, /feedback off: the robot follows the model alone/);
    assert.match(activity, /calibrations \(on request\): 0 run, 0 applied to the model/);
    await page.click('#feedback');
    await waitFor(async () => /feedback on: targets corrected by up to [\d.]+ mm/.test(await text(page, '#activity')),
      'the feedback\'s effect in the panel');
    await page.click('#feedback');
    await waitFor(async () => /feedback off/.test(await text(page, '#activity')), 'feedback off again');
  });

  it('calibrates from the observed frames and shows the fitted values', async () => {
    const modelBefore = await text(page, '#model');
    assert.match(modelBefore, /E 200 kPa/);
    const button = page.locator('#calibrate');
    await waitFor(() => button.isEnabled(), 'Calibrate to be enabled by observed frames');
    // Whatever the button shows between the click and the result, recorded as it changes.
    await hooks(page, () => {
      const b = document.getElementById('calibrate');
      window.calibrateLooks = [];
      new MutationObserver(() => window.calibrateLooks.push({ text: b.textContent, busy: b.classList.contains('busy'), disabled: b.disabled }))
        .observe(b, { attributes: true, childList: true, characterData: true, subtree: true });
    });
    await button.click();

    const row = page.locator(`#calibration-result tr[data-parameter="${Parameter.YoungsModulus}"]`);
    await waitFor(() => row.isVisible(), 'the result table with a Young\'s modulus row', 120000);
    const cells = await row.locator('td').allTextContents();
    assert.equal(cells[0], "Young's modulus");
    assert.equal(cells[3], 'kPa');
    // The verdict (docs/calibration.md): Young's modulus alone, seen by 30 µm markers: determined.
    assert.equal(cells[4], 'determined');
    assert.match(await row.getAttribute('title'), /^Young's modulus: determined/);
    const [fitted, deviation] = cells[2].split('±').map(Number);
    assert.ok(deviation > 0 && deviation < 0.2 * fitted, `fitted ${cells[2]} kPa`);
    assert.ok(Math.abs(fitted - 300) < Math.abs(fitted - 200), `E ${fitted} kPa: nearer the world's 300 than the model's 200`);
    assert.match(await text(page, '#calibration-summary'), /RMS [\d.]+ → [\d.]+ mm · \d+ iterations · [\d.]+ s · .*applied/);

    const looks = await hooks(page, () => window.calibrateLooks);
    assert.ok(looks.some((l) => l.busy && l.disabled && /Calibrating/.test(l.text)), `busy while calibrating: ${JSON.stringify(looks)}`);
    await waitFor(async () => !(await state(page)).calibration.running && (await button.isEnabled()), 'Calibrate ready again');
    assert.equal(await button.textContent(), 'Calibrate');

    // Applied: the model line shows the fitted stiffness.
    const result = (await state(page)).calibration.result;
    assert.ok(result.applied, `the result was applied (${result.reason})`);
    const modelAfter = await waitFor(async () => { const t = await text(page, '#model'); return t !== modelBefore && t; }, 'the model line to change');
    const shownE = Number(modelAfter.match(/E ([\d.]+) kPa/)[1]);
    assert.ok(Math.abs(shownE - fitted) <= 0.01 * fitted, `model line ${modelAfter} vs fitted ${fitted} kPa`);
    assert.equal(await page.locator('#calibration-error').isVisible(), false);
    assert.match(await text(page, '#activity'), /calibrations \(on request\): 1 run, 1 applied to the model/);
    assert.deepEqual(page.problems, []);
  });

  it('switches automatic calibration from its checkbox', async () => {
    await page.click('#auto-calibration');
    await waitFor(async () => (await state(page)).calibration.automatic, 'automatic calibration on');
    assert.equal(await page.locator('#auto-calibration').isChecked(), true);
    await page.click('#auto-calibration');
    await waitFor(async () => !(await state(page)).calibration.automatic, 'automatic calibration off');
    assert.deepEqual(page.problems, []);
  });
});

describe('the real object: an observed point cloud (serve)', () => {
  let server, browser, page, ws;

  let session;
  before(async () => {
    session = await openSession([], { socket: true });
    ({ server, browser, page, ws } = session);
  });

  after(async () => {
    await closeSession(session);  // fails on any console problem of the run
  });

  it('draws the points of the last observed frame over the model, and hides them with the checkbox', async () => {
    assert.deepEqual((await state(page)).observed_points, []);
    assert.equal(await hooks(page, () => window.shapectl.observedPointsDrawn), 0, 'nothing drawn without a cloud');

    // A frame as a depth camera would send it: 2 mm outside every fifth node, and two markers.
    const { scene, joints, x } = await hooks(page, () =>
      ({ scene: window.shapectl.scene, joints: window.shapectl.state.joints, x: window.shapectl.positions() }));
    const nodes = Array.from({ length: Math.floor(scene.node_count / 5) }, (_, k) => 5 * k);
    const points = nodes.map((i) => [x[3 * i], x[3 * i + 1], x[3 * i + 2] + 0.002]);
    const frame = {
      joints: Object.fromEntries(scene.robot.joint_names.map((name, k) => [name, joints[k]])),
      markers: [0, nodes[nodes.length - 1]].map((node) => ({ node, position: x.slice(3 * node, 3 * node + 3) })),
      points, sigma: 0.001, time: 1,
    };
    ws.sendJson({ type: Command.Observe, id: 'observe', frame });
    const answer = await ws.next((m) => m.text?.includes('"id":"observe"')).then((m) => JSON.parse(m.text));
    assert.equal(answer.type, Message.Ok, answer.message);

    await waitFor(async () => (await hooks(page, () => window.shapectl.observedPointsDrawn)) === points.length, `${points.length} points drawn`);
    const drawn = await hooks(page, () => window.shapectl.observedPoints());
    const worst = Math.max(...drawn.map((p, k) => Math.hypot(...p.map((v, a) => v - points[k][a]))));
    assert.ok(worst < 1e-6, `drawn where observed (worst ${worst} m)`);

    // On the screen: the view with the points differs from the view without them. A screenshot
    // after a frame rendered since the change.
    const shot = async () => {
      const frames = await hooks(page, () => window.shapectl.frames);
      await hooks(page, () => window.shapectl.setLayers());  // renders
      await waitFor(async () => (await hooks(page, () => window.shapectl.frames)) > frames, 'a new frame');
      return page.locator('#view canvas').screenshot();
    };
    const withPoints = await shot();
    await page.click('#show-points');
    assert.equal(await hooks(page, () => window.shapectl.observedPointsDrawn), 0, 'the points hidden');
    const withoutPoints = await shot();
    const fraction = await differingFraction(page, withPoints, withoutPoints);
    assert.ok(fraction > 1e-4, `the points cover ${fraction} of the view`);
    await page.click('#show-points');
    await waitFor(async () => (await hooks(page, () => window.shapectl.observedPointsDrawn)) === points.length, 'the points shown again');
    assert.deepEqual(page.problems, []);
  });
});
