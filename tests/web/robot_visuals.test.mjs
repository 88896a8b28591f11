// What the page draws of the robot, checked in its scene graph: the URDF's material colours on
// the bundled YuMi (expected values read from the URDF itself, not from the server), and with
// `serve --robot sim` the ghost robot at the measured joints, shown only while the link is armed.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { startServer, launchChromium, openPage, waitFor, sourceDir, RawWebSocket, closeAll } from './support.mjs';
import { Command, LinkKind, Message } from '../../web/js/protocol.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
// Largest difference between two lists of poses (16 numbers each).
const poseDistance = (a, b) => Math.max(...a.flatMap((pose, k) => pose.map((v, i) => Math.abs(v - b[k][i]))));

// Per link name, the rgba of each primitive visual in file order (null: no colour), from the
// robot-level named materials and inline ones. Enough URDF for the bundled YuMi.
function urdfVisualColors(file) {
  const xml = readFileSync(file, 'utf8');
  const named = new Map();
  for (const m of xml.matchAll(/<material name="([^"]+)">\s*<color rgba="([^"]+)"\s*\/>\s*<\/material>/g))
    named.set(m[1], m[2].trim().split(/\s+/).map(Number));
  const links = new Map();
  for (const link of xml.matchAll(/<link name="([^"]+)"\s*(?:\/>|>([\s\S]*?)<\/link>)/g)) {
    const colors = [];
    for (const visual of (link[2] ?? '').matchAll(/<visual>([\s\S]*?)<\/visual>/g)) {
      if (/<mesh/.test(visual[1])) continue;  // not drawn as a primitive
      const inline = visual[1].match(/<color rgba="([^"]+)"/);
      const ref = visual[1].match(/<material name="([^"]+)"/);
      colors.push(inline ? inline[1].trim().split(/\s+/).map(Number) : (ref ? named.get(ref[1]) ?? null : null));
    }
    links.set(link[1], colors);
  }
  return links;
}

describe('robot visuals in the 3D view', () => {
  let server, browser, page;
  before(async () => {
    server = await startServer(['--robot', LinkKind.Sim]);
    browser = await launchChromium();
    page = await openPage(browser, server.url);
  });
  after(async () => {
    await closeAll(browser, server);  // fails on any console problem of the run
  });

  it('draws each visual in its URDF material colour', async () => {
    // Solid links: a link hiding the object would be drawn see-through (occlusion.js).
    await page.click('#see-through-arms');
    await waitFor(() => hooks(page, () => window.shapectl.ready), 'the page to draw solid links');
    const expected = urdfVisualColors(path.join(sourceDir, 'data/robots/yumi/yumi.urdf'));
    const drawn = await hooks(page, () => window.shapectl.robotColors());
    let coloured = 0;
    for (const link of drawn) {
      const colors = expected.get(link.name);
      assert.ok(colors, `link ${link.name} is in the URDF`);
      assert.equal(link.visuals.length, colors.length, `link ${link.name}: one mesh per visual`);
      link.visuals.forEach((v, k) => {
        if (!colors[k]) return;
        coloured++;
        v.rgb.forEach((c, i) => assert.ok(Math.abs(c - colors[k][i]) < 1e-3, `${link.name} visual ${k}: ${v.rgb} vs ${colors[k]}`));
        assert.equal(v.opacity, colors[k][3]);
      });
    }
    assert.ok(coloured > 10, `the YuMi's coloured visuals are drawn (${coloured})`);
    assert.deepEqual(page.problems, []);
  });

  it('shows a translucent ghost at the measured joints while armed, hides it when disarmed', async () => {
    await waitFor(() => hooks(page, () => window.shapectl.state?.link?.connected), 'sim link feedback');
    assert.equal((await hooks(page, () => window.shapectl.ghost())).visible, false, 'hidden while disarmed');

    // Jog the optimizer's first joint far (paused, disarmed: the sim robot stays), then arm: the
    // sim robot then moves there at its 0.5 rad/s, so for seconds the measured pose differs
    // from the optimizer's and the ghost must follow the measured one.
    const ws = await RawWebSocket.connect(server.port);
    const reply = (id) => ws.next((m) => m.text?.includes(`"id":"${id}"`)).then((m) => JSON.parse(m.text));
    const { scene, state } = await hooks(page, () => ({ scene: window.shapectl.scene, state: window.shapectl.state }));
    const [lo, hi] = [scene.robot.lower_limits[0], scene.robot.upper_limits[0]];
    const joints = [...state.joints];
    const far = joints[0] - lo > hi - joints[0] ? 0.9 * lo + 0.1 * hi : 0.1 * lo + 0.9 * hi;
    ws.sendJson({ type: Command.SetPaused, paused: true, id: 'pause' });
    assert.equal((await reply('pause')).type, Message.Ok);
    // In jog steps: the server moves a joint at most limits.max_jog_step per jog.
    for (let n = 0; joints[0] !== far; n++) {
      const step = scene.limits.max_jog_step;
      joints[0] = Math.abs(far - joints[0]) <= step ? far : joints[0] + Math.sign(far - joints[0]) * step;
      ws.sendJson({ type: Command.SetJoints, joints, id: `jog${n}` });
      const answer = await reply(`jog${n}`);
      assert.equal(answer.type, Message.Ok, `jog ${n}: ${answer.message}`);
    }
    ws.close();

    await page.click('#arm');
    // The state the page shows and the ghost as drawn, read together.
    const shown = () => hooks(page, () => ({ state: window.shapectl.state, ghost: window.shapectl.ghost() }));
    const armed = await waitFor(async () => {
      const s = await shown();
      return s.state.link.armed && s.state.measured_links && poseDistance(s.state.measured_links, s.state.links) > 0.01 && s;
    }, 'armed, the measured robot away from the optimizer\'s');
    assert.equal(armed.ghost.visible, true, 'shown while armed');
    assert.equal(armed.ghost.links.length, armed.state.measured_links.length);
    assert.ok(poseDistance(armed.ghost.links, armed.state.measured_links) < 1e-9, 'the ghost is at measured_links');
    const visuals = armed.ghost.colors.flatMap((l) => l.visuals);
    assert.ok(visuals.length > 10 && visuals.every((v) => v.opacity < 0.5), 'the ghost is translucent');
    assert.equal(armed.ghost.meshes, visuals.length, 'the ghost has no collision spheres');

    await page.click('#disarm');
    const disarmed = await waitFor(async () => { const s = await shown(); return !s.state.link.armed && s; }, 'disarmed');
    assert.equal(disarmed.ghost.visible, false, 'hidden once disarmed');
    assert.deepEqual(page.problems, []);
  });
});
