// The object stays visible (issue 36): the robot links between the camera and the object are drawn
// see-through, solid again once the camera moved away, clicks reach the object through them, and
// `f` frames the object, not the robot.
// `shapectl serve` on the bundled YuMi bar, Debian's Chromium headless, real mouse and keyboard
// events; the page's hooks only report (link opacities as drawn, camera, projections).
// Screenshots of an occluded view with and without see-through arms go to <build>/gui-screenshots/.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync } from 'node:fs';
import path from 'node:path';
import { waitFor, openSession, closeSession, buildDir, pixelsAt } from './support.mjs';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const shots = path.join(buildDir, 'gui-screenshots');
const AIMED = 'yumi_link_5_r';  // the right arm's link the camera looks through at the object
const HIDING_OPACITY = 0.3;
const distance = (a, b) => Math.hypot(...a.map((v, i) => v - b[i]));
const unit = (v) => v.map((x) => x / Math.hypot(...v));

// Per link name, its visuals' opacities as drawn (links without visuals left out).
async function opacities(page) {
  const links = await hooks(page, () => window.shapectl.robotColors());
  return Object.fromEntries(links.filter((l) => l.visuals.length).map((l) => [l.name, l.visuals.map((v) => v.opacity)]));
}

// The names of the links drawn see-through (any visual below full opacity), once drawn and no
// fade is left (a fading view keeps asking for frames: not ready).
async function seeThroughLinks(page) {
  return waitFor(async () => {
    if (!await hooks(page, () => window.shapectl.ready)) return false;
    const now = await opacities(page);
    const fading = Object.values(now).flat().some((o) => o > HIDING_OPACITY + 1e-6 && o < 1 - 1e-6);
    return !fading && Object.keys(now).filter((name) => now[name].some((o) => o < 1 - 1e-6)).sort();
  }, 'the fades to settle');
}

// The world centre of a link's visuals, from the scene's visual poses and the state's link pose.
async function visualCentre(page, name) {
  return hooks(page, (name) => {
    const { scene, state } = window.shapectl;
    const k = scene.robot.links.findIndex((l) => l.name === name);
    const T = state.links[k];
    const centres = scene.robot.links[k].visuals.map(({ pose: p }) =>
      [0, 1, 2].map((i) => T[i] * p[12] + T[4 + i] * p[13] + T[8 + i] * p[14] + T[12 + i]));
    return [0, 1, 2].map((i) => centres.reduce((sum, c) => sum + c[i], 0) / centres.length);
  }, name);
}

// OrbitControls' angles of the camera about the orbit centre, z up: azimuth and polar angle.
function angles(offset) {
  const [x, y, z] = offset;
  return { theta: Math.atan2(x, -y), phi: Math.acos(z / Math.hypot(x, y, z)) };
}

// A real left-drag on the view's background that orbits the camera to look from `direction`
// (from the orbit centre towards the camera): OrbitControls turns 2π per canvas height dragged.
async function orbitTo(page, direction) {
  const { eye, centre, height, rect } = await hooks(page, () => {
    const r = document.querySelector('#view canvas').getBoundingClientRect();
    return { eye: window.shapectl.cameraPosition(), centre: window.shapectl.tools.orbitTarget(),
      height: document.querySelector('#view canvas').clientHeight, rect: { left: r.left, top: r.top, right: r.right, bottom: r.bottom } };
  });
  const from = angles(eye.map((v, i) => v - centre[i])), to = angles(direction);
  const turn = Math.atan2(Math.sin(to.theta - from.theta), Math.cos(to.theta - from.theta));
  const dx = -turn * height / (2 * Math.PI), dy = -(to.phi - from.phi) * height / (2 * Math.PI);
  // Start in a corner away from the drag, off the object (a press there would add a target).
  const start = { x: dx > 0 ? rect.left + 60 : rect.right - 60, y: dy > 0 ? rect.top + 60 : rect.bottom - 100 };
  await page.mouse.move(start.x, start.y);
  await page.mouse.down();
  for (let k = 1; k <= 10; k++) await page.mouse.move(start.x + dx * k / 10, start.y + dy * k / 10);
  await page.mouse.up();
  const now = await hooks(page, () => window.shapectl.cameraPosition());
  const looking = unit(now.map((v, i) => v - centre[i]));
  assert.ok(distance(looking, unit(direction)) < 0.02, `the drag turned the camera to ${looking}, not ${unit(direction)}`);
  assert.equal((await hooks(page, () => window.shapectl.state)).targets.length, 0, 'the drag added no target');
}

describe('the object stays visible', () => {
  let session, page;
  before(async () => {
    session = await openSession();
    ({ page } = session);
    mkdirSync(shots, { recursive: true });
  });
  after(async () => {
    await closeSession(session);  // fails on any console problem of the run
  });

  it('f frames the object: its bounding sphere fills the view, the robot reaches beyond it', async () => {
    const framing = () => hooks(page, () => {
      const x = window.shapectl.positions(), s = window.shapectl.state;
      const lo = [0, 1, 2].map((i) => Math.min(...x.filter((_, j) => j % 3 === i)));
      const hi = [0, 1, 2].map((i) => Math.max(...x.filter((_, j) => j % 3 === i)));
      const centre = lo.map((v, i) => (v + hi[i]) / 2);
      let radius = 0;
      for (let j = 0; j < x.length; j += 3) radius = Math.max(radius, Math.hypot(x[j] - centre[0], x[j + 1] - centre[1], x[j + 2] - centre[2]));
      // A point of the sphere's outline: from the centre, sideways across the line of sight.
      const d = window.shapectl.cameraDirection(), side = [d[1], -d[0], 0].map((v) => v / Math.hypot(d[0], d[1]));
      const r = document.querySelector('#view canvas').getBoundingClientRect();
      const inside = (p) => p.x >= r.left && p.x <= r.right && p.y >= r.top && p.y <= r.bottom;
      const links = s.links.map((m) => window.shapectl.worldToPage([m[12], m[13], m[14]]));
      return { centre: window.shapectl.worldToPage(centre), rim: window.shapectl.worldToPage(centre.map((v, i) => v + radius * side[i])),
        view: { x: (r.left + r.right) / 2, y: (r.top + r.bottom) / 2, half: Math.min(r.width, r.height) / 2 },
        linksOutside: links.filter((p) => !inside(p)).length, links: links.length };
    });
    const load = await framing();
    assert.equal(load.linksOutside, 0, 'on load the whole robot is framed');
    await page.keyboard.press('f');
    await waitFor(() => hooks(page, () => window.shapectl.ready), 'the framed view drawn');
    const f = await framing();
    const off = Math.hypot(f.centre.x - f.view.x, f.centre.y - f.view.y);
    assert.ok(off < 0.05 * f.view.half, `the object's centre ${JSON.stringify(f.centre)} near the view's ${JSON.stringify(f.view)}`);
    const radius = Math.hypot(f.rim.x - f.centre.x, f.rim.y - f.centre.y) / f.view.half;
    assert.ok(radius > 0.7 && radius < 1, `the object's sphere fills the view: radius ${radius.toFixed(2)} of half the view`);
    const before = Math.hypot(load.rim.x - load.centre.x, load.rim.y - load.centre.y) / load.view.half;
    assert.ok(radius > 1.5 * before, `f zoomed onto the object: radius ${radius.toFixed(2)}, ${before.toFixed(2)} framing all`);
    assert.ok(f.linksOutside >= 3, `the robot reaches out of the view: ${f.linksOutside} of ${f.links} link origins outside`);
  });

  it('draws the links between the camera and the object see-through, and solid again after', async () => {
    await page.keyboard.press('f');
    await waitFor(() => hooks(page, () => window.shapectl.ready), 'the framed view drawn');
    const front = await hooks(page, () => window.shapectl.cameraPosition().map((v, i) => v - window.shapectl.tools.orbitTarget()[i]));
    const solidBefore = await opacities(page);
    const seeThroughBefore = await seeThroughLinks(page);
    assert.ok(!seeThroughBefore.includes(AIMED), `${AIMED} solid from the front: ${seeThroughBefore}`);
    // Look at the object's centre through the middle of the aimed link.
    const centre = await hooks(page, () => window.shapectl.tools.orbitTarget());
    const link = await visualCentre(page, AIMED);
    const eyeDistance = distance(front, [0, 0, 0]);
    assert.ok(distance(link, centre) < 0.8 * eyeDistance, `${AIMED} lies between the camera and the object`);
    await orbitTo(page, link.map((v, i) => v - centre[i]));
    const seeThrough = await seeThroughLinks(page);
    assert.ok(seeThrough.includes(AIMED), `${AIMED} is see-through: ${seeThrough}`);
    const now = await opacities(page);
    assert.ok(now[AIMED].every((o) => Math.abs(o - HIDING_OPACITY) < 1e-6), `${AIMED} at ${HIDING_OPACITY}: ${now[AIMED]}`);
    // The other arm and the body are behind the object or beside it from here: solid.
    const solid = Object.keys(now).filter((name) => name.endsWith('_l') || name.startsWith('gripper_l') || name === 'yumi_body');
    assert.ok(solid.length >= 8, `links of the left arm and the body: ${solid}`);
    for (const name of solid) assert.deepEqual(now[name], solidBefore[name], `${name} stays solid`);
    assert.deepEqual(seeThrough, (await hooks(page, () => window.shapectl.hidingLinks())).sort(), 'exactly the links hiding the object');

    // The object shows through: at its centre the pixel is nearer its own colour than with the
    // Display toggle off (a real click), where the link is solid.
    const [at] = await hooks(page, (c) => [window.shapectl.worldToPage(c)], centre);
    const on = await page.screenshot({ path: path.join(shots, 'occluded-see-through.png') });
    await page.click('#see-through-arms');
    assert.deepEqual(await seeThroughLinks(page), [], 'the toggle off: every link solid');
    const offShot = await page.screenshot({ path: path.join(shots, 'occluded-solid.png') });
    await hooks(page, () => window.shapectl.setLayers({ robot: false }));
    const bare = await page.screenshot();
    await hooks(page, () => window.shapectl.setLayers({}));
    const [[withLinks], [solidLinks], [object]] = [await pixelsAt(page, on, [at]), await pixelsAt(page, offShot, [at]), await pixelsAt(page, bare, [at])];
    assert.ok(distance(withLinks, object) + 30 < distance(solidLinks, object),
      `the object shows through the link: ${withLinks} see-through, ${solidLinks} solid, ${object} without the robot`);
    await page.click('#see-through-arms');
    assert.ok((await seeThroughLinks(page)).includes(AIMED), 'the toggle on again');

    // A click there picks the object through the link: a target at a node near its centre.
    await page.mouse.click(at.x, at.y);
    const target = await waitFor(async () => (await hooks(page, () => window.shapectl.state)).targets[0], 'a target from the click');
    const node = await hooks(page, (n) => window.shapectl.nodePosition(n), target.node);
    assert.ok(distance(node, centre) < 0.03, `the clicked node ${target.node} at ${node}, the object's centre ${centre}`);
    await page.click('#clear');
    await waitFor(async () => (await hooks(page, () => window.shapectl.state)).targets.length === 0, 'cleared');

    // Back to the front: the aimed link and every other solid again, as before.
    await orbitTo(page, front);
    assert.deepEqual(await seeThroughLinks(page), seeThroughBefore, 'the same links see-through as before the turn');
    assert.deepEqual(await opacities(page), solidBefore, 'every link back at its opacity from before');
  });
});
