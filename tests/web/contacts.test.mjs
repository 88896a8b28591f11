// Obstacles and contacts in the 3D view (docs/contact.md): the YuMi's bar held over a peg it
// sags onto, with a table, a box and a ball beside it. Checked in the page's scene graph against
// the server's messages (each obstacle drawn where the scene puts it, an arrow per contact
// point along its force to the scale shown) and in a screenshot (the contact dots are drawn,
// and gone once the Contacts box is unticked). Then the bundled scenes/yumi_cable_table.json.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { openBarSession, waitFor, colourNear, RawWebSocket } from './support.mjs';
import { Command, Message } from '../../web/js/protocol.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const close = (a, b, tolerance, what) =>
  a.forEach((v, i) => assert.ok(Math.abs(v - b[i]) <= tolerance, `${what}: ${a} vs ${b}`));
const CONTACT_YELLOW = [0xff, 0xe1, 0x4d];  // contacts_view.js

// scenes/yumi_bar.json (its bar: centre (0.39047, 0, 0.25527), 3 cm square, 32 cm along y) with
// a peg across its middle 0.5 mm below it, within the default 1 mm contact distance from the
// start, so the sagging bar rests on it; the table, box and ball touch nothing.
const BAR_BOTTOM = 0.25527 - 0.015;
const PEG_RADIUS = 0.01;
const PEG_Z = BAR_BOTTOM - 0.0005 - PEG_RADIUS;
const OBSTACLES = [
  { name: 'table', plane: { point: [0, 0, 0.1], normal: [0, 0, 2] } },
  { name: 'peg', capsule: { a: [0.33, 0, PEG_Z], b: [0.45, 0, PEG_Z], radius: PEG_RADIUS } },
  { name: 'block', box: { size: [0.06, 0.04, 0.02], pose: { position: [0.55, 0.2, 0.11], rpy: [0, 0, 0.3] } } },
  { name: 'ball', sphere: { center: [0.55, -0.2, 0.13], radius: 0.03 } },
  // On the left upper arm, off the link's origin and turned: drawn at the link's pose.
  { name: 'cuff', link: 'yumi_link_3_l', box: { size: [0.02, 0.03, 0.04], pose: { position: [0.08, 0.08, 0.01], rpy: [0.3, 0, 0] } } },
];
const CUFF_IN_LINK = [0.08, 0.08, 0.01];

describe('obstacles and contacts', () => {
  let bar, session, page;
  before(async () => {
    bar = await openBarSession('bar_on_peg.json', (scene) => { scene.obstacles = OBSTACLES; });
    ({ session, page } = bar);
  });
  after(() => bar?.close());

  it('draws every obstacle where the scene puts it', async () => {
    const { scene, drawn, centroid } = await hooks(page, () => ({
      scene: window.shapectl.scene, drawn: window.shapectl.obstacles(), centroid: window.shapectl.objectCentroid(),
    }));
    assert.deepEqual(scene.obstacles.map((o) => [o.name, o.shape]),
      [['table', 'plane'], ['peg', 'capsule'], ['block', 'box'], ['ball', 'sphere'], ['cuff', 'box']]);
    assert.deepEqual(scene.obstacles.map((o) => o.link), [null, null, null, null, 'yumi_link_3_l']);
    assert.equal(scene.contact.distance, 0.001);
    assert.deepEqual(drawn.map((o) => [o.name, o.shape, o.visible]), scene.obstacles.map((o) => [o.name, o.shape, true]));
    const [table, peg, block, ball] = drawn;
    // The plane: a square at z = 0.1 under the object's centroid (the normal was scaled to 1).
    close(scene.obstacles[0].plane.normal, [0, 0, 1], 1e-12, 'unit normal');
    close(table.centre, [centroid[0], centroid[1], 0.1], 1e-3, 'table under the object');
    // The capsule: a cylinder and two spheres around its segment; the box from its 12
    // triangles, centred at its pose; the ball at its centre.
    assert.equal(peg.meshes, 3);
    close(peg.centre, [0.39, 0, PEG_Z], 1e-6, 'peg');
    assert.equal(block.meshes, 1);
    assert.equal(scene.obstacles[2].triangles.length, 12);
    close(block.centre, [0.55, 0.2, 0.11], 1e-6, 'block');
    assert.equal(ball.meshes, 1);
    close(ball.centre, [0.55, -0.2, 0.13], 1e-6, 'ball');
  });

  it('draws a dot and an arrow along its force for each contact, to the scale it shows', async () => {
    // The state the page shows and the contacts as drawn, read together.
    const shown = await waitFor(async () => {
      const s = await hooks(page, () => ({ state: window.shapectl.state, drawn: window.shapectl.contacts(),
        scale: document.getElementById('contact-scale').textContent, detail: document.getElementById('status-detail').textContent }));
      return s.state.contacts?.count > 0 && s.drawn.points === s.state.contacts.points.length && s;
    }, 'the bar resting on the peg');
    const { state: { contacts }, drawn } = shown;
    assert.ok(contacts.by_obstacle.peg.count === contacts.count, `only the peg touches: ${JSON.stringify(contacts.by_obstacle)}`);
    assert.equal(contacts.by_obstacle.table.count, 0);
    assert.ok(contacts.force_total[2] > 0, `the peg pushes the bar up: ${contacts.force_total}`);
    assert.ok(contacts.min_distance > 0 && contacts.min_distance < 0.001, `gap ${contacts.min_distance}`);
    assert.equal(drawn.visible, true);
    assert.equal(drawn.arrows.length, contacts.points.length);
    const metresPerNewton = 0.01 / drawn.newtonsPerCm;
    let longest = 0;
    contacts.points.forEach((c, k) => {
      const [tail, tip] = drawn.arrows[k];
      close(tail, c.slice(0, 3), 1e-6, `arrow ${k} starts at its point`);
      close(tip, c.slice(0, 3).map((p, i) => p + metresPerNewton * c[3 + i]), 1e-6, `arrow ${k} along its force`);
      longest = Math.max(longest, Math.hypot(...c.slice(3)) * metresPerNewton);
    });
    assert.ok(longest > 0.012 && longest <= 0.03 + 1e-9, `the largest arrow is 1.2-3 cm (${longest} m)`);
    assert.equal(shown.scale, `(1 cm = ${+drawn.newtonsPerCm.toPrecision(3)} N)`);
    // Each part of the line is kept whole with no-break spaces.
    assert.match(shown.detail, new RegExp(`${contacts.count}\\scontacts,\\sgap\\s\\d+\\.\\d\\d\\smm`));
  });

  it('hides the dots and arrows, not the obstacles, when Contacts is unticked', async () => {
    await hooks(page, () => window.shapectl.setLayers({ robot: false }));  // nothing in front of the bar
    const dots = async () => {
      const { points } = await hooks(page, () => window.shapectl.state.contacts);
      return Promise.all(points.slice(0, 20).map((c) => hooks(page, (p) => window.shapectl.worldToPage(p), c.slice(0, 3))));
    };
    const yellow = async () => colourNear(page, await page.screenshot(), await dots(), CONTACT_YELLOW, { radius: 2, tolerance: 40 });
    assert.ok((await yellow()).some(Boolean), 'contact dots are drawn');

    await page.uncheck('#show-contacts');
    await waitFor(() => hooks(page, () => !window.shapectl.renderPending), 'a render');
    assert.equal((await hooks(page, () => window.shapectl.contacts())).visible, false);
    assert.ok((await hooks(page, () => window.shapectl.obstacles())).every((o) => o.visible), 'the obstacles stay');
    assert.deepEqual((await yellow()).filter(Boolean), [], 'no contact dot drawn');

    await page.check('#show-contacts');
    assert.equal((await hooks(page, () => window.shapectl.contacts())).visible, true);
    assert.deepEqual(page.problems, []);
  });

  it('draws an obstacle on a robot link at that link\'s pose, and moves it with the link', async () => {
    const cuff = () => hooks(page, () => {
      const { scene, state } = window.shapectl;
      const k = scene.robot.links.findIndex((l) => l.name === 'yumi_link_3_l');
      return { links: state?.links, k, drawn: window.shapectl.obstacles().find((o) => o.name === 'cuff') };
    });
    // T_world_link (column-major) applied to the box's centre in the link frame.
    const expected = (m) => [0, 1, 2].map((r) => m[12 + r] + CUFF_IN_LINK.reduce((s, p, c) => s + m[4 * c + r] * p, 0));
    const first = await waitFor(async () => { const c = await cuff(); return c.links && c; }, 'a state');
    assert.equal(first.drawn.link, 'yumi_link_3_l');
    close(first.drawn.centre, expected(first.links[first.k]), 1e-6, 'cuff at its link pose');
    assert.ok(Math.hypot(...first.drawn.centre.map((v, i) => v - CUFF_IN_LINK[i])) > 0.1, 'not at the link-frame coordinates');

    // Another program pauses and jogs yumi_joint_1_l by two jog steps: the cuff follows its link.
    const ws = await RawWebSocket.connect(session.server.port);
    const reply = (id) => ws.next((m) => m.text?.includes(`"id":"${id}"`)).then((m) => JSON.parse(m.text));
    const { scene, state } = await hooks(page, () => ({ scene: window.shapectl.scene, state: window.shapectl.state }));
    const joint = scene.robot.joint_names.indexOf('yumi_joint_1_l');
    assert.ok(joint >= 0);
    ws.sendJson({ type: Command.SetPaused, paused: true, id: 'pause' });
    assert.equal((await reply('pause')).type, Message.Ok);
    const joints = [...state.joints];
    for (let n = 0; n < 2; n++) {
      joints[joint] -= scene.limits.max_jog_step;
      ws.sendJson({ type: Command.SetJoints, joints, id: `jog${n}` });
      const answer = await reply(`jog${n}`);
      assert.equal(answer.type, Message.Ok, `jog ${n}: ${answer.message}`);
    }
    ws.close();
    const moved = await waitFor(async () => {
      const c = await cuff();
      return Math.hypot(...c.drawn.centre.map((v, i) => v - first.drawn.centre[i])) > 0.003 && c;
    }, 'the cuff moved with its link');
    close(moved.drawn.centre, expected(moved.links[moved.k]), 1e-6, 'cuff at its new link pose');
  });

  it('shows the bundled cable on its table, and nothing of the peg scene after it', async () => {
    await page.locator('#scene-select').selectOption('yumi_cable_table.json');
    const shown = await waitFor(async () => {
      const s = await hooks(page, () => ({ scene: window.shapectl.scene.scene, state: window.shapectl.state,
        obstacles: window.shapectl.obstacles(), drawn: window.shapectl.contacts() }));
      return s.scene === 'yumi_cable_table.json' && s.state?.scene === s.scene && s.state.contacts?.count > 0 &&
        s.drawn.points === s.state.contacts.points.length && s;
    }, 'the cable scene with its contacts');
    assert.deepEqual(shown.obstacles.map((o) => [o.name, o.shape, o.visible]), [['table', 'plane', true]]);
    const { contacts } = shown.state;
    assert.equal(contacts.by_obstacle.table.count, contacts.count);
    assert.deepEqual(Object.keys(contacts.by_obstacle), ['table'], 'the peg scene\'s obstacles are gone');
    assert.ok(contacts.force_total[2] > 0, 'the table pushes the cable up');
    assert.equal(shown.drawn.arrows.length, contacts.points.length);
    assert.deepEqual(page.problems, []);
  });
});
