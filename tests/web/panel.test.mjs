// The side panel and the view's tools, as a user at 1280×800 sees them: a panel that fits,
// scrolls and does not jump as numbers change; Delete only when there is something to remove; the
// convergence plot's axis, range, editing band, log scale and hover read-out; frames, scale
// bar, hover read-out, view presets, screenshot and `?` help in the 3D view; a notice when
// another client changes the shared session. Real mouse and keyboard events; the page's
// window.shapectl hooks only report.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { startServer, launchChromium, waitFor, differingFraction, openPage, RawWebSocket, openSession, closeSession } from './support.mjs';
import { Command, LinkKind } from '../../web/js/protocol.js';

const hooks = (page, f, arg) => page.evaluate(f, arg);
const state = (page) => hooks(page, () => window.shapectl.state);
const tools = (page, name, arg) => page.evaluate(([n, a]) => window.shapectl.tools[n](a), [name, arg]);

// Page-space rectangle of `selector`.
const rect = (page, selector) => page.locator(selector).evaluate((e) => e.getBoundingClientRect().toJSON());

async function clickCentroid(page) {
  const centre = await hooks(page, () => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
  await page.mouse.click(centre.x, centre.y);
  return waitFor(async () => (await state(page)).targets[0], 'a target from the click');
}

// Drags with the left button from `from` to `to` in small steps, as a hand would.
async function drag(page, from, to) {
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(to.x, to.y, { steps: 25 });
  await page.mouse.up();
}

describe('side panel and view tools', () => {
  let server, browser, page;

  let session;
  before(async () => {
    session = await openSession();
    ({ server, browser, page } = session);
  });

  after(async () => {
    await closeSession(session);  // fails on any console problem of the run
  });

  it('offers Delete only for a selected target that exists', async () => {
    assert.equal((await state(page)).targets.length, 0);
    assert.equal(await page.locator('#delete').isDisabled(), true, 'Delete without targets');
    const target = await clickCentroid(page);
    await waitFor(() => page.locator('#delete').isEnabled(), 'Delete enabled with the target selected');
    assert.equal(await hooks(page, () => window.shapectl.selected), target.node);
    await page.click('#clear');
    await waitFor(async () => (await state(page)).targets.length === 0, 'targets cleared');
    await waitFor(() => page.locator('#delete').isDisabled(), 'Delete disabled again');
    assert.equal(await page.locator('#notice').isVisible(), false, 'our own clear is no news');
  });

  it('fits 1280×800: the panel scrolls to every joint and the help line, nothing wider than it', async () => {
    const { innerWidth, innerHeight } = await hooks(page, () => ({ innerWidth, innerHeight }));
    assert.deepEqual([innerWidth, innerHeight], [1280, 800]);
    const doc = await hooks(page, () => ({ w: document.documentElement.scrollWidth, h: document.documentElement.scrollHeight }));
    assert.ok(doc.w <= 1280 && doc.h <= 800, `the page itself does not scroll: ${JSON.stringify(doc)}`);
    const panel = await rect(page, '#panel');
    assert.ok(panel.right <= 1280 && panel.bottom <= 800 && panel.top >= 0, `panel ${JSON.stringify(panel)}`);
    const overflow = await page.locator('#panel').evaluate((e) => ({ style: getComputedStyle(e).overflowY, sw: e.scrollWidth, cw: e.clientWidth }));
    assert.equal(overflow.style, 'auto');
    assert.ok(overflow.sw <= overflow.cw, `nothing cut off at the side: ${JSON.stringify(overflow)}`);
    const rows = await page.locator('#joints .joint').count();
    assert.equal(rows, 14);
    for (const selector of ['#joints .joint >> nth=13', '#joints .joint >> nth=0', 'section.help', '#plot']) {
      const element = page.locator(selector);
      await element.scrollIntoViewIfNeeded();
      const r = await element.evaluate((e) => e.getBoundingClientRect().toJSON());
      assert.ok(r.top >= panel.top - 0.5 && r.bottom <= panel.bottom + 0.5 && r.right <= panel.right + 0.5,
        `${selector} reachable in the panel: ${JSON.stringify(r)}`);
    }
    await page.locator('#panel').evaluate((e) => { e.scrollTop = 0; });
  });

  it('keeps the panel still while numbers and messages change', async () => {
    // Everything below the changing lines, as the page lays it out.
    const probe = () => ['#numbers-line', '#status-detail', '.buttons', '#plot', '#joints .joint'].map((s) => document.querySelector(s).getBoundingClientRect().top);
    const start = await hooks(page, probe);
    // Live: add a target and drag it, so the status, errors, rate and joints all change.
    const target = await clickCentroid(page);
    const from = await hooks(page, (n) => window.shapectl.nodePosition(n), target.node);
    const sampling = hooks(page, (f) => new Promise((done) => {
      const probeFn = new Function(`return (${f})()`);
      const seen = [];
      const end = performance.now() + 2500;
      const tick = () => { seen.push(probeFn()); if (performance.now() < end) requestAnimationFrame(tick); else done(seen); };
      tick();
    }), probe.toString());
    const [start2d, end2d] = await hooks(page, (ps) => ps.map((p) => window.shapectl.worldToPage(p)), [from, [from[0], from[1], from[2] + 0.028]]);
    await drag(page, start2d, end2d);
    const seen = await sampling;
    for (const tops of seen) assert.deepEqual(tops, start, 'nothing moved while the session changed');
    // Numbers up to their boxes' widths move nothing after them on the line (longer texts wrap
    // whole instead of being cut: panel_controls.test.mjs).
    const lefts = await hooks(page, () => {
      const set = (id, text) => { document.getElementById(id).textContent = text; };
      const measure = () => [...document.querySelectorAll('#numbers-line > span')].map((e) => e.getBoundingClientRect().left);
      set('error-mean', '–'); set('error-max', '0.01'); set('rate', '–');
      const narrow = measure();
      set('error-mean', '123.45'); set('error-max', '999.99'); set('rate', '9999');
      return { narrow, wide: measure() };
    });
    assert.deepEqual(lefts.wide, lefts.narrow, 'the numbers do not push each other');
  });

  it('draws the convergence plot in mm with a robust range, merged editing spans and a log option', async () => {
    // A plot of its own with known samples: 0.2–0.6 mm, one 50 mm spike, editing flags that
    // flicker every sample for 3 s.
    const result = await hooks(page, async () => {
      const { ConvergencePlot } = await import('/js/plot.js');
      const canvas = document.createElement('canvas');
      canvas.width = 320; canvas.height = 160;
      const plot = new ConvergencePlot(canvas, document.createElement('div'));
      for (let k = 0; k < 600; k++) {
        const t = k / 30, error = k === 300 ? 0.05 : 0.0004 + 0.0002 * Math.sin(k / 20);
        plot.add(t, [error, null, null, null], t > 5 && t < 8 && k % 2 === 0);
      }
      plot.draw();
      const pixels = plot.context.getImageData(0, 0, 320, 160).data;
      const at = (x, y) => pixels.subarray(4 * (y * 320 + x), 4 * (y * 320 + x) + 4);
      // Rows with the orange line (below the 6 px off-scale marks at the top).
      let top = 160, bottom = 0;
      for (let y = 24; y < 160 - 16; y++)
        for (let x = 40; x < 314; x++) {
          const [r, g, b, a] = at(x, y);
          if (a > 200 && r > 200 && g > 100 && g < 180 && b < 80) { top = Math.min(top, y); bottom = Math.max(bottom, y); }
        }
      // Runs of the editing band along a row under the line.
      let runs = 0, inBand = false;
      for (let x = 35; x < 314; x++) {
        const [r, g, , a] = at(x, 160 - 16 - 3);
        const band = a > 40 && r > 2 * g;
        if (band && !inBand) runs++;
        inBand = band;
      }
      const linear = { top: plot.top, clipped: plot.clipped, lineRows: bottom - top, runs };
      plot.log = true;
      plot.draw();
      return { linear, log: { top: plot.top, clipped: plot.clipped } };
    });
    assert.equal(result.linear.top, 1, 'the spike does not set the range: 0–1 mm');
    assert.ok(result.linear.clipped >= 1, 'the spike is marked off the scale');
    assert.ok(result.linear.lineRows > 30, `the 0.4 mm wave spans ${result.linear.lineRows} px`);
    assert.equal(result.linear.runs, 1, 'one editing span, not a barcode');
    assert.equal(result.log.top, 100, 'the log axis reaches the spike');
    assert.equal(result.log.clipped, 0);
  });

  it('reads out the plot under the pointer and switches the page plot to log', async () => {
    assert.ok((await state(page)).targets.length > 0, 'a target from the test before');
    await page.locator('#plot').scrollIntoViewIfNeeded();
    const box = await page.locator('#plot').boundingBox();
    await page.mouse.move(box.x + box.width - 20, box.y + box.height / 2);
    const text = await waitFor(async () => {
      const t = await page.locator('#plot-readout').textContent();
      return /mean error \d+\.\d{3} mm/.test(t) && t;
    }, 'the read-out');
    assert.match(text, /^-?\d+\.\d s: /);
    await page.locator('#plot-log').check();
    assert.equal((await hooks(page, () => window.shapectl.plot())).log, true);
    await page.locator('#plot-log').uncheck();
    await page.mouse.move(box.x - 200, box.y);
  });

  it('draws the world frame and a tool frame at each TCP', async () => {
    const scene = await hooks(page, () => window.shapectl.scene);
    const origins = await tools(page, 'toolOrigins');
    assert.ok(scene.robot.end_effectors.length >= 2);
    assert.deepEqual(Object.keys(origins).sort(), scene.robot.end_effectors.map((e) => e.name).sort());
    // Paused, so the poses hold still while compared.
    await page.click('#pause');
    const paused = await waitFor(async () => { const p = await state(page); return p.paused && p; }, 'paused');
    await page.waitForTimeout(200);
    const held = await state(page);
    const got = await tools(page, 'toolOrigins');
    for (const e of scene.robot.end_effectors) {
      const m = held.links[e.link];
      const expected = [0, 1, 2].map((i) => m[i] * e.tcp[0] + m[4 + i] * e.tcp[1] + m[8 + i] * e.tcp[2] + m[12 + i]);
      assert.ok(Math.hypot(...got[e.name].map((v, i) => v - expected[i])) < 1e-6, `${e.name}: ${got[e.name]} vs ${expected}`);
    }
    assert.ok(paused.paused);
    const withFrames = await page.locator('#view canvas').screenshot();
    await page.locator('#show-frames').uncheck();
    await page.waitForTimeout(200);
    const without = await page.locator('#view canvas').screenshot();
    await page.locator('#show-frames').check();
    const share = await differingFraction(page, withFrames, without);
    assert.ok(share > 1e-4, `the frames cover ${share} of the view`);
    await page.click('#pause');
    await waitFor(async () => !(await state(page)).paused, 'resumed');
  });

  it('shows node, position and error under the pointer', async () => {
    const s = await state(page);
    const target = s.targets[0];
    // The handle sits at the target, 2.8 cm above its node after the drag.
    const at = await hooks(page, (p) => window.shapectl.worldToPage(p), target.position);
    await page.mouse.move(at.x, at.y);
    const hovered = await waitFor(() => tools(page, 'hovered'), 'a hover read-out');
    assert.equal(hovered.node, target.node);
    const node = await hooks(page, (n) => window.shapectl.nodePosition(n), target.node);
    assert.ok(Math.abs(hovered.error - Math.hypot(...hovered.target.map((v, i) => v - hovered.position[i]))) < 1e-9);
    assert.ok(Math.hypot(...hovered.position.map((v, i) => v - node[i])) < 1e-3);
    const text = await page.locator('#hover-readout').textContent();
    assert.match(text, new RegExp(`^node ${target.node} at \\(-?\\d+\\.\\d, -?\\d+\\.\\d, -?\\d+\\.\\d\\) mm`));
    assert.match(text, /target \(.*\) mm · error \d+\.\d mm/);
    assert.equal(await page.locator('#hover-readout').isVisible(), true);
    // Off the object: no read-out.
    const corner = await rect(page, '#view');
    await page.mouse.move(corner.left + 5, corner.bottom - 40);
    await waitFor(async () => !(await page.locator('#hover-readout').isVisible()), 'the read-out to go');
  });

  it('keeps the read-out current when a target moves under a still pointer', async () => {
    await page.click('#pause');  // the node stays where the pointer is
    const paused = await waitFor(async () => { const p = await state(page); return p.paused && p; }, 'paused');
    const { node } = paused.targets[0];
    const at = await hooks(page, (n) => window.shapectl.nodeToPage(n), node);
    await page.mouse.move(at.x, at.y);
    const before = await waitFor(async () => { const h = await tools(page, 'hovered'); return h?.node === node && h; }, 'the node under the pointer');
    // Another page moves the target 1 cm down; the pointer does not move.
    const moved = before.target.map((v, i) => (i === 2 ? v - 0.01 : v));
    const ws = await RawWebSocket.connect(server.port);
    ws.sendJson({ type: 'set_targets', id: 7, targets: [{ node, position: moved }] });
    await ws.next((m) => m.text && JSON.parse(m.text).id === 7);
    ws.close();
    const after = await waitFor(async () => {
      const h = await tools(page, 'hovered');
      return h?.node === node && Math.hypot(...h.target.map((v, i) => v - moved[i])) < 1e-12 && h;
    }, 'the read-out to show the moved target');
    assert.ok(Math.abs(after.error - Math.hypot(...moved.map((v, i) => v - after.position[i]))) < 1e-9);
    assert.match(await page.locator('#hover-readout').textContent(), new RegExp(`target \\(.*\\) mm · error ${(1000 * after.error).toFixed(1)} mm`));
    await page.click('#pause');
    await waitFor(async () => !(await state(page)).paused, 'resumed');
  });

  it('turns the camera to the presets 1, 3, 7, 0 and sizes the scale bar to the view', async () => {
    await page.mouse.click(5, 5);  // keys to the page, not the last checkbox (off the object: no target)
    const expected = { 1: [-1, 0, 0], 3: [0, 1, 0], 7: [0, 0, -1], 0: [-1, 1, -1].map((v) => v / Math.sqrt(3)) };
    for (const [key, direction] of Object.entries(expected)) {
      await page.keyboard.press(key);
      const d = await hooks(page, () => window.shapectl.cameraDirection());
      assert.ok(Math.hypot(...d.map((v, i) => v - direction[i])) < 2e-3, `key ${key}: looking along ${d}`);
    }
    // Front view: a bar of `metres` along y at the orbit centre spans `pixels` on screen.
    const frames = await hooks(page, () => window.shapectl.frames);
    await page.keyboard.press('1');
    await waitFor(async () => (await hooks(page, () => window.shapectl.frames)) > frames, 'the front view drawn');
    const bar = await tools(page, 'scaleBar');
    const centre = await tools(page, 'orbitTarget');
    const [a, b] = await hooks(page, ([c, m]) => [window.shapectl.worldToPage(c), window.shapectl.worldToPage([c[0], c[1] + m, c[2]])], [centre, bar.metres]);
    const onScreen = Math.hypot(a.x - b.x, a.y - b.y);
    assert.ok(Math.abs(onScreen - bar.pixels) < 0.02 * bar.pixels, `bar ${bar.pixels} px vs ${onScreen} px on screen`);
    assert.ok(bar.pixels >= 60 && bar.pixels <= 150, `${bar.pixels} px`);
    assert.match(bar.label, /^\d+ (mm|cm|m)$/);
    const shown = await page.locator('#scale-bar i').boundingBox();
    assert.ok(Math.abs(shown.width - bar.pixels) < 1.5, `drawn ${shown.width} px`);
    assert.match(await page.locator('#scale-bar').textContent(), /grid 10 cm/);
    // Zooming changes the bar with the view.
    const view = await rect(page, '#view');
    await page.mouse.move(view.left + view.width / 2, view.top + view.height / 2);
    await page.mouse.wheel(0, 600);
    await waitFor(async () => (await tools(page, 'scaleBar')).pixels !== bar.pixels || (await tools(page, 'scaleBar')).metres !== bar.metres, 'the bar to follow the zoom');
  });

  it('saves the view as a PNG', async () => {
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#screenshot')]);
    assert.match(download.suggestedFilename(), /^shapectl-yumi_bar-\d{4}-\d\d-\d\dT\d\d-\d\d-\d\d\.png$/);
    const png = readFileSync(await download.path());
    assert.deepEqual([...png.subarray(0, 8)], [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
    const canvas = await page.locator('#view canvas').evaluate((c) => [c.width, c.height]);
    assert.deepEqual([png.readUInt32BE(16), png.readUInt32BE(20)], canvas);
    // Not blank: it differs from a blank canvas as much as the view does.
    const blank = await hooks(page, ([w, h]) => { const c = document.createElement('canvas'); c.width = w; c.height = h; const g = c.getContext('2d'); g.fillStyle = '#1d2025'; g.fillRect(0, 0, w, h); return c.toDataURL('image/png').split(',')[1]; }, canvas);
    const share = await differingFraction(page, Buffer.from(blank, 'base64'), png);
    assert.ok(share > 0.05, `the PNG shows the scene (${share} of it differs from blank)`);
  });

  it('lists every key in the ? help, and Esc closes it', async () => {
    assert.equal(await page.locator('#help').isVisible(), false);
    await page.keyboard.press('?');
    await waitFor(() => page.locator('#help').isVisible(), 'the help');
    const keys = await page.locator('#help kbd').allTextContents();
    for (const key of ['c', 'Esc', 'Space', 'Delete', 'f', 'x / y / z', 'Ctrl+Z', 'Ctrl+Shift+Z', 'Ctrl+Y', '1 / 3 / 7 / 0', 't', '?'])
      assert.ok(keys.some((k) => k.split(/,\s*|\s\(/).includes(key) || k.startsWith(key + ' (')), `"${key}" in ${JSON.stringify(keys)}`);
    const r = await rect(page, '#help');
    assert.ok(r.top >= 0 && r.left >= 0 && r.bottom <= 800 && r.right <= 1280, `help on screen: ${JSON.stringify(r)}`);
    await page.keyboard.press('Escape');
    await waitFor(async () => !(await page.locator('#help').isVisible()), 'the help to close');
    await page.click('#help-button');
    assert.equal(await page.locator('#help').isVisible(), true);
    await page.keyboard.press('?');
    assert.equal(await page.locator('#help').isVisible(), false);
  });

  it('tells when another client clears the targets or switches the scene, not when this page does', async () => {
    const other = await RawWebSocket.connect(server.port);
    try {
      if ((await state(page)).targets.length === 0) await clickCentroid(page);
      other.sendJson({ type: Command.ClearTargets });
      await waitFor(() => page.locator('#notice').isVisible(), 'a notice');
      assert.match(await page.locator('#notice').textContent(), /Another page removed the targets/);
      await waitFor(() => page.locator('#delete').isDisabled(), 'Delete disabled: its target is gone');
      other.sendJson({ type: Command.LoadScene, scene: 'yumi_frame.json' });
      await waitFor(async () => /switched the scene to yumi_frame\.json/.test(await page.locator('#notice').textContent()), 'the scene notice');
      await waitFor(async () => (await state(page)).scene === 'yumi_frame.json', 'the new scene');
      // This page switches back itself: no notice about that.
      await page.locator('#scene-select').selectOption('yumi_bar.json');
      await waitFor(async () => (await hooks(page, () => window.shapectl.ready)) && (await state(page)).scene === 'yumi_bar.json', 'back on the bar');
      await page.waitForTimeout(300);
      assert.doesNotMatch(await page.locator('#notice').textContent(), /yumi_bar/);
    } finally {
      other.close();
    }
    assert.deepEqual(page.problems, []);
  });
});

describe('side panel with a robot link', () => {
  let server, browser;
  before(async () => {
    server = await startServer(['--robot', LinkKind.Sim]);
    browser = await launchChromium();
  });
  after(async () => {
    await browser?.close();
    await server?.stop();
  });

  it('says nothing about a scene change at start-up', async () => {
    const page = await openPage(browser, server.url);
    await waitFor(async () => (await state(page)).link?.connected, 'sim link feedback');
    await page.waitForTimeout(300);
    const link = await page.locator('#link-status').textContent();
    assert.match(link, /disarmed/);
    assert.doesNotMatch(link, /scene changed/);
    assert.equal(await page.locator('#toast').isVisible(), false);
    assert.equal(await page.locator('#notice').isVisible(), false);
    assert.deepEqual(page.problems, []);
  });
});
