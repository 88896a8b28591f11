// One honest reason for an unreachable target (issue 36 item 2), as the user meets it: a target
// typed 1.2 m above the foam bar's middle, five times (after a reset, and after the target was
// back at its node), says the same *best effort · unreachable: reach* each time, with the same
// distances. Real mouse clicks (the object, Reset) and keys (the Target z field, Enter).
// `shapectl serve` on the default YuMi + foam bar scene; Chromium headless via playwright-core.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync } from 'node:fs';
import path from 'node:path';
import { openSession, closeSession, waitFor, buildDir, centreNodeOnPage } from './support.mjs';
import { ControllerStatus, Shortfall } from '../../web/js/protocol.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const state = (page) => hooks(page, () => window.shapectl.state);
const badge = (page) => hooks(page, () => ({
  text: document.getElementById('status').textContent,
  reason: document.getElementById('status-reason').textContent,
}));
const UP = 1200;  // mm above the node: the YuMi's arms are 0.56 m long

// Clicks the node nearest the object's centroid; resolves with its new target.
async function clickCentre(page) {
  const centre = await centreNodeOnPage(page);
  await page.mouse.click(centre.x, centre.y);
  const s = await waitFor(async () => { const s = await state(page); return s.targets.length === 1 && s; }, 'a target from the click');
  return s.targets[0];
}

// Types `mm` into the Target z field with the keyboard and presses Enter; resolves once the
// server has the target there and the optimizer stopped for it.
async function typeZ(page, mm) {
  await page.click('#target-z');
  await page.keyboard.press('Control+a');
  await page.keyboard.type(String(mm));
  await page.keyboard.press('Enter');
  return waitFor(async () => {
    const s = await state(page);
    const t = s.targets[0];
    return t && Math.abs(1000 * t.position[2] - mm) < 1e-6 && s.status !== ControllerStatus.Optimizing && s;
  }, `the optimizer to stop for z = ${mm} mm`, 120000);
}

describe('an unreachable target', () => {
  let session, page;
  before(async () => {
    session = await openSession();
    ({ page } = session);
  });
  after(async () => {
    await closeSession(session);  // fails on any console problem of the run
  });

  it('gives the same reason five times, from a reset and from another target', async () => {
    let target = await clickCentre(page);
    const home = Math.round(1000 * target.position[2] * 1000) / 1000;  // mm, as the field shows it
    const seen = [];
    for (let k = 0; k < 5; k++) {
      if (k > 0 && k % 2 === 0) {  // from the reference pose: Reset, then the same click
        await page.click('#reset');
        await waitFor(async () => (await state(page)).targets.length === 0, 'the reset');
        const again = await clickCentre(page);
        assert.equal(again.node, target.node, 'the click picks the same node after a reset');
        target = again;
      } else if (k > 0) {  // from wherever the target back at its node leaves the arms
        await typeZ(page, home);
      }
      const s = await typeZ(page, home + UP);
      assert.equal(s.status, ControllerStatus.BestEffort, `${s.status}: ${s.status_reason}`);
      assert.deepEqual(s.unreachable, [Shortfall.Reach], s.status_reason);
      await waitFor(async () => (await badge(page)).reason === `${s.status_reason}`, 'the reason line');
      const b = await badge(page);
      // The reach clause depends on the target alone: the same words and numbers every time.
      const reach = b.reason.split('; ').find((part) => part.startsWith('reach: '));
      assert.ok(reach, b.reason);
      seen.push({ text: b.text, reach, error: s.error.max, joints: s.joints });
    }
    for (const x of seen) {
      assert.equal(x.text, 'best effort · unreachable: reach');
      assert.equal(x.reach, seen[0].reach);
    }
    assert.match(seen[0].reach, /^reach: node \d+'s target is [\d.]+ m from joint '\w+', where the arm gripping with link '\w+' starts: [\d.]+ m beyond the [\d.]+ m it reaches with that node unstretched/);
    mkdirSync(path.join(buildDir, 'gui-screenshots'), { recursive: true });
    await page.screenshot({ path: path.join(buildDir, 'gui-screenshots', 'unreachable.png') });
    console.log(JSON.stringify(seen.map((x) => ({ error: x.error, reach: x.reach }))));
  });
});
