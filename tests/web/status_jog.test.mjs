// Honest status and safe jogging, as the user sees them: the badge says "reached" only within
// the tolerance and "best effort · unreachable: <reason>" otherwise; a click on a slider's track
// moves its joint by at most one jog step; a jog into self-collision is refused with the reason
// and the links it would have made collide turn red in 3D. `shapectl serve` on the default
// YuMi + foam bar scene; Chromium headless via playwright-core.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startServer, launchChromium, waitFor, openPage, RawWebSocket, openSession, closeSession } from './support.mjs';
import { ControllerStatus, Shortfall, Message, Command } from '../../web/js/protocol.js';
import { JOG_STEP } from '../../web/js/joint_jog.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const state = (page) => hooks(page, () => window.shapectl.state);
const badge = (page) => hooks(page, () => {
  const b = document.getElementById('status');
  return { text: b.textContent, kind: b.className, reason: document.getElementById('status-reason').textContent };
});
const RED = [1, 42 / 255, 42 / 255];  // robot_view.js COLLIDING_COLOR, sRGB

// One command from another program on the session; resolves with its reply.
let nextId = 1;
async function send(ws, type, fields = {}) {
  const id = nextId++;
  const from = ws.messages.length;
  ws.sendJson({ type, id, ...fields });
  // Replies are short; the streamed states are not parsed.
  const reply = await ws.next((m) => m.text && m.text.length < 2000 && JSON.parse(m.text).id === id, 15000, from);
  ws.messages.length = 0;  // the states streamed meanwhile are not needed
  return JSON.parse(reply.text);
}

describe('status and jogging', () => {
  let server, browser, page, ws;

  let session;
  before(async () => {
    session = await openSession([], { socket: true });
    ({ server, browser, page, ws } = session);
  });

  after(async () => {
    await closeSession(session);  // fails on any console problem of the run
  });

  it('says reached for a reachable target, in green', async () => {
    const centre = await hooks(page, () => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
    await page.mouse.click(centre.x, centre.y);  // a target where the node is: reachable
    const s = await waitFor(async () => { const s = await state(page); return s.targets.length === 1 && s.status === ControllerStatus.Reached && s; },
      'the status to say reached', 60000);
    assert.ok(s.error.max <= s.tolerance, `max error ${s.error.max} m within ${s.tolerance} m`);
    await waitFor(async () => (await badge(page)).kind.includes('ok'), 'the badge to turn green');
    const b = await badge(page);
    assert.match(b.text, /^reached \(≤ 1\.0 mm\)$/);
  });

  it('says best effort with a reason for an unreachable target, never reached', async () => {
    const s0 = await state(page);
    const node = s0.targets[0].node;
    const up = (await hooks(page, (n) => window.shapectl.nodePosition(n), node)).map((v, i) => v + (i === 2 ? 1.0 : 0));
    assert.equal((await send(ws, Command.SetTarget, { node, position: up })).type, Message.Ok);
    const seen = new Set();
    const s = await waitFor(async () => {
      const [st, b] = [await state(page), await badge(page)];
      if (st.targets[0]?.position[2] === up[2]) seen.add(b.text.split(' ')[0]);
      return st.targets[0]?.position[2] === up[2] && st.status === ControllerStatus.BestEffort && st;
    }, 'the status to say best effort', 180000);
    assert.ok(!seen.has('reached'), `the badge showed ${[...seen]}`);
    assert.ok(s.error.max > s.tolerance);
    assert.ok(s.unreachable.length > 0 && s.unreachable.every((r) => Object.values(Shortfall).includes(r)),
      `reasons ${JSON.stringify(s.unreachable)}: ${s.status_reason}`);
    await waitFor(async () => (await badge(page)).text.startsWith('best effort'), 'the badge to say best effort');
    const b = await badge(page);
    assert.equal(b.text, `best effort · unreachable: ${s.unreachable.join(', ')}`);
    assert.match(b.kind, /bad/);
    assert.match(b.reason, /above the tolerance 1\.0 mm; /);
    assert.deepEqual(page.problems, []);
  });

  it('moves a joint by at most one jog step for a click on its slider track', async () => {
    await page.click('#reset');
    await waitFor(async () => (await state(page)).targets.length === 0, 'reset');
    await page.click('#pause');
    const paused = await waitFor(async () => { const s = await state(page); return s.paused && s; }, 'paused');
    const k = 0;
    const slider = page.locator(`#joints input[data-joint="${k}"]`);
    await waitFor(() => slider.isEnabled(), 'the slider to be enabled');
    await slider.scrollIntoViewIfNeeded();  // the panel scrolls at 1280×800
    const box = await slider.boundingBox();
    // Far from the thumb: 90 % along the track (the thumb is near the middle for joint 1).
    await page.mouse.click(box.x + 0.9 * box.width, box.y + box.height / 2);
    const moved = await waitFor(async () => { const s = await state(page); return s.joints[k] !== paused.joints[k] && s; }, 'the joint to move');
    await page.waitForTimeout(500);  // anything else the click sent has arrived by now
    const after = await state(page);
    const step = Math.abs(after.joints[k] - paused.joints[k]);
    assert.ok(step > 0 && step <= JOG_STEP + 1e-9, `one click moved joint ${k} by ${step} rad (jog step ${JOG_STEP})`);
    assert.equal(moved.last_error, '');
    // The server bounds a jog too: a program asking for a 1 rad jump is refused.
    const jump = await send(ws, Command.SetJoint, { joint: k, value: after.joints[k] + 1 });
    assert.equal(jump.type, Message.Error);
    assert.match(jump.message, /jog refused: yumi_joint_1_l: expected a step of at most 0\.05 rad/);
  });

  it('refuses a jog into self-collision with the reason and draws those links red', async () => {
    const scene = await hooks(page, () => window.shapectl.scene);
    const { lower_limits: lower, upper_limits: upper, reference_joints: reference } = scene.robot;
    // Another program walks joints in server-sized steps until a jog is refused for collision.
    let found = null;
    for (const [k, dir] of [[7, 1], [0, -1], [1, 1], [8, 1]]) {
      await send(ws, Command.Reset);
      await waitFor(async () => (await state(page)).joints.every((v, j) => Math.abs(v - reference[j]) < 1e-9), 'the reference joints');
      let value = reference[k], reply;
      for (;;) {
        const next = value + dir * 0.04;
        if (next < lower[k] || next > upper[k]) break;
        reply = await send(ws, Command.SetJoint, { joint: k, value: next });
        if (reply.type !== Message.Ok) break;
        value = next;
      }
      if (reply?.type === Message.Error && /self-collision/.test(reply.message)) { found = { k, dir, value }; break; }
    }
    assert.ok(found, 'no joint of the YuMi jogged into self-collision');
    const { k, dir, value } = found;
    const before = await waitFor(async () => { const s = await state(page); return Math.abs(s.joints[k] - value) < 1e-9 && s; },
      'the last allowed jog to be applied', 60000);
    assert.ok(before.min_clearance >= 0);
    // Now the user: the arrow key on that slider, one jog step a press, until refused.
    const slider = page.locator(`#joints input[data-joint="${k}"]`);
    await slider.focus();
    const errors = await hooks(page, () => window.shapectl.stats.errors.length);
    for (let press = 0; press < 10; press++) {
      await page.keyboard.press(dir > 0 ? 'ArrowRight' : 'ArrowLeft');
      await page.waitForTimeout(150);
      if ((await hooks(page, () => window.shapectl.stats.errors)).slice(errors).some((e) => /self-collision/.test(e))) break;
    }
    const refusals = (await hooks(page, () => window.shapectl.stats.errors)).slice(errors);
    const refusal = refusals.find((e) => /self-collision/.test(e));
    assert.ok(refusal, `no refusal after 10 presses: ${JSON.stringify(refusals)}`);
    assert.match(refusal, /^jog refused: self-collision: \S+ and \S+ would overlap by \d+\.\d mm$/);
    assert.match(await page.locator('#toast').textContent(), /self-collision/);
    const s = await waitFor(async () => { const s = await state(page); return s.jog_refused_links.length === 2 && s; }, 'the refused links in the state');
    assert.ok(s.min_clearance >= 0, `the robot stayed out of collision (clearance ${s.min_clearance} m)`);
    const links = scene.robot.links.map((l) => l.name);
    assert.deepEqual(s.jog_refused_links.map((l) => links[l]).sort(), refusal.match(/: (\S+) and (\S+) would/).slice(1).sort());
    await page.waitForTimeout(200);
    const colors = await hooks(page, () => window.shapectl.robotColors());
    for (const l of s.jog_refused_links) {
      assert.ok(colors[l].visuals.length > 0, `${links[l]} has visuals`);
      for (const v of colors[l].visuals) v.rgb.forEach((c, i) => assert.ok(Math.abs(c - RED[i]) < 0.01, `${links[l]} drawn ${v.rgb}`));
    }
    const others = colors.filter((_, l) => !s.jog_refused_links.includes(l)).flatMap((c) => c.visuals);
    assert.ok(others.every((v) => v.rgb.some((c, i) => Math.abs(c - RED[i]) > 0.05)), 'only those links are red');
    // With the collision spheres shown, the closest pair is highlighted.
    await hooks(page, () => window.shapectl.setSpheresVisible(true));
    const spheres = await hooks(page, () => window.shapectl.highlightedSpheres());
    assert.deepEqual(spheres.spheres, [...s.closest_pair.spheres].sort((a, b) => a - b));
    assert.ok(spheres.visible);
    // Resuming clears the refusal's red.
    await page.click('#pause');
    await waitFor(async () => { const st = await state(page); return !st.paused && st.jog_refused_links.length === 0; }, 'resumed');
    await waitFor(async () => (await hooks(page, () => window.shapectl.robotColors()))[s.jog_refused_links[0]].visuals
      .every((v) => v.rgb.some((c, i) => Math.abs(c - RED[i]) > 0.05)), 'the red to go');
    assert.deepEqual(page.problems, []);
  });
});
