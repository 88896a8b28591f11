// The object's contacts with itself in the 3D view (docs/contact.md, Self-contact): the YuMi's
// bar slit through its middle (tests/data/slit_bar.py), its upper slab's middle pressed down onto
// the lower one, with contact.self and no obstacle. The page draws a green dot at each pair's
// meeting point (no arrow: a pair's forces cancel), the status line says how many pairs touch and
// their smallest gap, and the dots go with the Contacts box unticked.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { openBarSession, waitFor, sourceDir, colourNear } from './support.mjs';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const SELF_GREEN = [0x5c, 0xff, 0x6e];  // contacts_view.js

describe('self-contact', () => {
  let bar, page;
  before(async () => {
    bar = await openBarSession('slit_bar.json', (scene) => {
      scene.object.mesh = { file: path.join(sourceDir, 'tests/data/slit_bar.node') };
      scene.loads = [{ box: { min: [-0.021, -1, 0.0005], max: [0.021, 1, 0.0076] }, force: [0, 0, -0.5] }];
      scene.contact = { self: true };
    });
    ({ page } = bar);
  });
  after(() => bar?.close());

  it('draws a dot at each self-contact and counts them in the status line', async () => {
    const shown = await waitFor(async () => {
      const s = await hooks(page, () => ({ scene: window.shapectl.scene, state: window.shapectl.state, drawn: window.shapectl.contacts(),
        toggle: !document.getElementById('contacts-toggle').hidden, detail: document.getElementById('status-detail').textContent }));
      return s.state?.contacts?.self?.count > 0 && s.drawn.selfPoints.length === s.state.contacts.self.points.length && s;
    }, 'the slit pressed shut');
    const { scene, state: { contacts }, drawn } = shown;
    assert.deepEqual(scene.obstacles, []);
    assert.equal(scene.contact.self, true);
    assert.ok(shown.toggle, 'the Contacts box is offered without obstacles');
    assert.equal(contacts.count, 0);
    const self = contacts.self;
    assert.ok(self.min_distance > 0 && self.min_distance < scene.contact.distance, `gap ${self.min_distance}`);
    assert.equal(self.points.length, self.count);
    assert.equal(drawn.visible, true);
    assert.equal(drawn.points, 0, 'no obstacle contact drawn');
    assert.deepEqual(drawn.arrows, [], 'no arrows for self-contact');
    self.points.forEach((p, k) => drawn.selfPoints[k].forEach((v, i) =>
      assert.ok(Math.abs(v - p[i]) < 1e-6, `dot ${k} at its point: ${drawn.selfPoints[k]} vs ${p}`)));
    // Each part of the line kept whole; no obstacle, so no "no contact".
    assert.match(shown.detail, new RegExp(`${self.count}\\sself-contacts,\\sgap\\s\\d+\\.\\d\\d\\smm`));
    assert.doesNotMatch(shown.detail, /no contact/);
  });

  it('hides the dots when Contacts is unticked', async () => {
    await hooks(page, () => window.shapectl.setLayers({ robot: false, object: false }));  // nothing in front of the slit
    const dots = async () => {
      const { points } = await hooks(page, () => window.shapectl.state.contacts.self);
      return Promise.all(points.slice(0, 20).map((p) => hooks(page, (q) => window.shapectl.worldToPage(q), p)));
    };
    const green = async () => colourNear(page, await page.screenshot(), await dots(), SELF_GREEN, { radius: 2, tolerance: 40 });
    await waitFor(() => hooks(page, () => !window.shapectl.renderPending), 'a render');
    assert.ok((await green()).some(Boolean), 'self-contact dots are drawn');

    await page.uncheck('#show-contacts');
    await waitFor(() => hooks(page, () => !window.shapectl.renderPending), 'a render');
    assert.equal((await hooks(page, () => window.shapectl.contacts())).visible, false);
    assert.deepEqual((await green()).filter(Boolean), [], 'no self-contact dot drawn');
    await page.check('#show-contacts');
    assert.deepEqual(page.problems, []);
  });
});
