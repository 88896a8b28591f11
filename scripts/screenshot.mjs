// Regenerates docs/gui.png, the README's screenshot: `node scripts/screenshot.mjs` after a build
// (SHAPECTL_CLI names another binary). The default scene with the simulated robot holding a
// bar 1.5× stiffer than the model's, a target dragged 2 cm up, feedback on, a few seconds of the
// closed loop; 1280×800.
// Run by hand when the page changes, never by the tests: a screenshot is no assertion.
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { launchChromium, openPage, sourceDir, startServer, waitFor } from '../tests/web/support.mjs';

// The "real" bar: 1.5× as stiff as the model's (its files' paths made absolute).
function writeWorld(dir) {
  const scenes = path.join(sourceDir, 'scenes');
  const world = JSON.parse(readFileSync(path.join(scenes, 'yumi_bar.json'), 'utf8'));
  world.object.material.youngs_modulus *= 1.5;
  world.robot.urdf = path.resolve(scenes, world.robot.urdf);
  world.robot.collision_spheres = path.resolve(scenes, world.robot.collision_spheres);
  const file = path.join(dir, 'world.json');
  writeFileSync(file, JSON.stringify(world));
  return file;
}

const out = process.argv[2] ?? path.join(sourceDir, 'docs/gui.png');
const dir = mkdtempSync(path.join(tmpdir(), 'shapectl-screenshot-'));
const server = await startServer(['--robot', 'sim', '--world', writeWorld(dir)]);
const browser = await launchChromium();
try {
  const page = await openPage(browser, server.url);
  await page.setViewportSize({ width: 1280, height: 800 });
  const hooks = (f, arg) => page.evaluate(f, arg);
  const state = () => hooks(() => window.shapectl.state);
  // Click the bar's centre: a target there; drag it up 2 cm in steps.
  const centre = await hooks(() => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
  await page.mouse.click(centre.x, centre.y);
  const target = await waitFor(async () => (await state()).targets[0], 'a target');
  const start = await hooks((n) => window.shapectl.nodePosition(n), target.node);
  const stroke = await hooks((ps) => ps.map((p) => window.shapectl.worldToPage(p)),
    Array.from({ length: 6 }, (_, k) => [start[0], start[1], start[2] + 0.004 * k]));
  await page.mouse.move(stroke[0].x, stroke[0].y);
  await page.mouse.down();
  for (const p of stroke.slice(1)) await page.mouse.move(p.x, p.y, { steps: 3 });
  await page.mouse.up();
  await page.click('#arm');
  await page.click('#feedback');
  await waitFor(async () => (await state()).observations > 40, 'the closed loop to run', 60000);
  await page.screenshot({ path: out });
  if (page.problems.length) throw new Error(`the page reported: ${page.problems.join('; ')}`);
  console.log(`screenshot: ${out}`);
} finally {
  await browser.close();
  await server.stop();
  rmSync(dir, { recursive: true, force: true });
}
