// Regenerates the README's screenshot, docs/gui.png: the default scene with one target dragged
// 3 cm up and reached. Run by `bash scripts/screenshot.sh`, never by the tests (they must not
// write into tracked files).
import path from 'node:path';
import { startServer, launchChromium, waitFor, sourceDir } from '../tests/web/support.mjs';

const server = await startServer([]);
const browser = await launchChromium();
try {
  const page = await browser.context.newPage();
  const hooks = (f, arg) => page.evaluate(f, arg);
  const state = () => hooks(() => window.shapectl.state);
  await page.goto(server.url);
  await waitFor(() => hooks(() => window.shapectl?.ready), 'the page to show the scene');

  const centre = await hooks(() => window.shapectl.worldToPage(window.shapectl.objectCentroid()));
  await page.mouse.click(centre.x, centre.y);
  const picked = await waitFor(async () => (await state()).targets[0], 'a target from the click');
  const start = await hooks((n) => window.shapectl.nodePosition(n), picked.node);
  const stroke = await hooks((ps) => ps.map((p) => window.shapectl.worldToPage(p)),
    Array.from({ length: 11 }, (_, k) => [start[0], start[1], start[2] + 0.003 * k]));
  await page.mouse.move(stroke[0].x, stroke[0].y);
  await page.mouse.down();
  for (const p of stroke.slice(1)) await page.mouse.move(p.x, p.y, { steps: 3 });
  await page.mouse.up();
  await waitFor(async () => (await state()).error.mean < 1e-3, 'the target to be reached', 90000);
  const file = path.join(sourceDir, 'docs/gui.png');
  await page.screenshot({ path: file });
  console.log(`wrote ${file}`);
} finally {
  await browser.close();
  await server.stop();
}
