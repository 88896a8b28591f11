// Records the image sequences in docs/demo/: a target dragged up and along (drag-NN.png) and a
// centre-line sketched and followed (sketch-NN.png): the 3D view, at 1280×800, as a user sees it. `node scripts/record_demo.mjs [OUT_DIR]` after a build (SHAPECTL_CLI names another binary).
// Run by hand when the page changes, never by the tests: a recording is no assertion.
import { mkdirSync } from 'node:fs';
import path from 'node:path';
import { launchChromium, openPage, sourceDir, startServer, waitFor } from '../tests/web/support.mjs';

const FRAMES = 6;
const out = process.argv[2] ?? path.join(sourceDir, 'docs/demo');
mkdirSync(out, { recursive: true });
const server = await startServer([]);
const browser = await launchChromium();
try {
  const page = await openPage(browser, server.url);
  const hooks = (f, arg) => page.evaluate(f, arg);
  const state = () => hooks(() => window.shapectl.state);
  const toPage = (points) => hooks((ps) => ps.map((p) => window.shapectl.worldToPage(p)), points);
  const view = await page.locator('#view').boundingBox();
  const frame = async (name, k) => {
    await waitFor(() => hooks(() => !window.shapectl.renderPending), 'the frame to be drawn');
    await page.screenshot({ path: path.join(out, `${name}-${String(k + 1).padStart(2, '0')}.png`), clip: view });
  };

  // A drag: click the bar's centre, drag the handle 4 cm up and 4 cm along y, one frame per step;
  // the last frames show the robot following.
  const centre = await hooks(() => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
  await page.mouse.click(centre.x, centre.y);
  const target = await waitFor(async () => (await state()).targets[0], 'a target');
  const start = target.position;
  const steps = await toPage(Array.from({ length: FRAMES - 2 }, (_, k) => [start[0], start[1] + 0.01 * (k + 1), start[2] + 0.01 * (k + 1)]));
  await page.mouse.move(centre.x, centre.y);
  await page.mouse.down();
  for (let k = 0; k < steps.length; k++) {
    await page.mouse.move(steps[k].x, steps[k].y, { steps: 5 });
    await frame('drag', k);
  }
  await page.mouse.up();
  await waitFor(async () => (await state()).error.mean < 0.002, 'the robot to follow', 60000);
  await frame('drag', FRAMES - 2);
  await waitFor(async () => (await state()).error.mean < 0.001, 'the target reached', 60000);
  await frame('drag', FRAMES - 1);

  // A sketch: face the bar, draw an arch (frames while drawing), then the followed centre-line.
  await page.click('#clear');
  await page.click('#face-bar');
  await page.click('#sketch');
  const { center, direction, length } = (await hooks(() => window.shapectl.scene)).bar;
  const arch = await toPage(Array.from({ length: 24 }, (_, k) => {
    const t = k / 23, s = (t - 0.5) * length;
    return center.map((c, i) => c + direction[i] * s + (i === 2 ? 0.03 * Math.sin(Math.PI * t) : 0));
  }));
  await page.mouse.move(arch[0].x, arch[0].y);
  await page.mouse.down();
  const perFrame = Math.ceil(arch.length / (FRAMES - 2));
  for (let k = 1; k < arch.length; k++) {
    await page.mouse.move(arch[k].x, arch[k].y, { steps: 3 });
    if (k % perFrame === 0) await frame('sketch', k / perFrame - 1);
  }
  await frame('sketch', FRAMES - 3);
  await page.mouse.up();
  await waitFor(async () => (await state()).centerline.length >= 2, 'the centre-line');
  await waitFor(async () => (await state()).error.mean < 0.003, 'the robot to follow the sketch', 60000);
  await frame('sketch', FRAMES - 2);
  await waitFor(async () => ['converged', 'stuck'].includes((await state()).status), 'the optimizer to settle', 60000).catch(() => {});
  await frame('sketch', FRAMES - 1);
  if (page.problems.length) throw new Error(`the page reported: ${page.problems.join('; ')}`);
  console.log(`frames: ${out}`);
} finally {
  await browser.close();
  await server.stop();
}
