// Shared by the browser and fuzz tests: start `shapectl serve` on a free port, launch Debian's
// Chromium headless through playwright-core, and a minimal raw WebSocket client.
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import net from 'node:net';
import crypto from 'node:crypto';
import { fileURLToPath } from 'node:url';

// Absolute: playwright-core is imported by a path under it (a relative one is a bare specifier).
export const sourceDir = process.env.SHAPECTL_SOURCE_DIR ? path.resolve(process.env.SHAPECTL_SOURCE_DIR) : path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const cli = process.env.SHAPECTL_CLI ?? path.join(sourceDir, 'build/shapectl');
export const buildDir = path.dirname(cli);  // where tests may write (screenshots), not the sources

export async function loadPlaywright() {
  return import(path.join(sourceDir, 'web/node_modules/playwright-core/index.mjs'));
}

// Starts the server on port 0 and resolves once it printed its URL. It serves sourceDir's web/,
// whatever its own default: a CLI built elsewhere then serves the pages under test.
export function startServer(args = []) {
  const web = args.includes('--web-root') ? [] : ['--web-root', path.join(sourceDir, 'web')];
  const proc = spawn(cli, ['serve', ...web, ...args, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
  let log = '';
  proc.stderr.on('data', (d) => { log += d; });
  return new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error(`server did not start:\n${out}\n${log}`)), 60000);
    proc.on('exit', (code) => reject(new Error(`server exited with ${code}:\n${out}\n${log}`)));
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/open (http:\/\/127\.0\.0\.1:(\d+)\/)/);
      if (!m) return;
      clearTimeout(timer);
      resolve({
        url: m[1], port: Number(m[2]), proc,
        get log() { return log; },
        alive: () => proc.exitCode === null && proc.signalCode === null,
        stop: () => new Promise((done) => { if (proc.exitCode !== null) return done(); proc.on('exit', done); proc.kill('SIGTERM'); }),
      });
    });
  });
}

export const chromiumFlags = ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync'];

export async function launchChromium() {
  const { chromium } = await loadPlaywright();
  const userDataDir = mkdtempSync(path.join(tmpdir(), 'shapectl-chromium-'));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium', headless: true, args: chromiumFlags,
    viewport: { width: 1280, height: 800 },
  });
  const browser = {
    context,
    pages: [],  // every page openPage opened: their problems are checked at close
    // Closes the browser; fails when any page raised a console error or warning, or an
    // exception, at any time during the run (not only where a test looked).
    close: async () => {
      await context.close();
      rmSync(userDataDir, { recursive: true, force: true });
      const problems = browser.pages.flatMap((p) => p.problems);
      if (problems.length) throw new Error(`the page raised ${problems.length} console problem(s): ${JSON.stringify(problems.slice(0, 10))}`);
    },
  };
  return browser;
}

// Headless Chromium's software compositor reads every WebGL canvas back and says so as a
// console warning; a bare canvas that only clears gets it too. The browser's, not the page's.
const COMPOSITOR_READBACK = /^\[\.WebGL-0x[0-9a-f]+\]GL Driver Message \(OpenGL, Performance, [A-Z_]+, High\): GPU stall due to ReadPixels/;

// A new page of `browser` at `url`, once it shows the scene. `page.problems` collects what the
// page must never raise: uncaught exceptions and console errors and warnings.
export async function openPage(browser, url) {
  const page = await browser.context.newPage();
  page.problems = [];
  browser.pages.push(page);
  page.on('pageerror', (e) => page.problems.push(`exception: ${e.message}`));
  page.on('console', (m) => {
    if ((m.type() === 'error' || m.type() === 'warning') && !COMPOSITOR_READBACK.test(m.text()))
      page.problems.push(`${m.type()}: ${m.text()}`);
  });
  await page.addInitScript(installScreenshotDecoder);
  await page.goto(url);
  try {
    await waitFor(() => page.evaluate(() => window.shapectl?.ready), 'the page to show the scene');
  } catch (e) {
    const parts = await page.evaluate(() => ({ scene: !!window.shapectl?.scene, state: !!window.shapectl?.state,
      positions: window.shapectl?.positions().length, frames: window.shapectl?.frames, connection: document.getElementById('connection')?.textContent }));
    throw new Error(`${e.message}: ${JSON.stringify(parts)}; problems: ${JSON.stringify(page.problems)}`);
  }
  return page;
}

// Put into every page openPage opens, for the pixel checks below: decodes a PNG screenshot
// (base64) into {width, height, data (RGBA bytes), scale (device pixels per page pixel)}.
function installScreenshotDecoder() {
  window.decodeScreenshot = async (base64) => {
    const image = new Image();
    image.src = `data:image/png;base64,${base64}`;
    await image.decode();
    const c = document.createElement('canvas');
    c.width = image.width; c.height = image.height;
    const g = c.getContext('2d');
    g.drawImage(image, 0, 0);
    return { width: c.width, height: c.height, data: g.getImageData(0, 0, c.width, c.height).data, scale: image.width / window.innerWidth };
  };
}

// Fraction of pixels that differ between two PNG screenshots, decoded by `page` itself.
export async function differingFraction(page, pngA, pngB) {
  return page.evaluate(async ([a, b]) => {
    const [p, q] = [(await window.decodeScreenshot(a)).data, (await window.decodeScreenshot(b)).data];
    let differing = 0;
    for (let i = 0; i < p.length; i += 4)
      if (Math.abs(p[i] - q[i]) + Math.abs(p[i + 1] - q[i + 1]) + Math.abs(p[i + 2] - q[i + 2]) > 30) differing++;
    return differing / (p.length / 4);
  }, [pngA.toString('base64'), pngB.toString('base64')]);
}

// Which of `points` (page coordinates) have a pixel of `rgb` ([r, g, b], within `tolerance`
// summed over the channels) within `radius` pixels in the PNG screenshot `png` of the whole
// page: an array of booleans, one per point.
export async function colourNear(page, png, points, rgb, { radius = 3, tolerance = 60 } = {}) {
  return page.evaluate(async ([base64, points, rgb, radius, tolerance]) => {
    const { width, height, data, scale } = await window.decodeScreenshot(base64);
    return points.map(({ x, y }) => {
      for (let dy = -radius; dy <= radius; dy++) {
        for (let dx = -radius; dx <= radius; dx++) {
          const px = Math.round(x * scale) + dx, py = Math.round(y * scale) + dy;
          if (px < 0 || py < 0 || px >= width || py >= height) continue;
          const i = 4 * (py * width + px);
          if (Math.abs(data[i] - rgb[0]) + Math.abs(data[i + 1] - rgb[1]) + Math.abs(data[i + 2] - rgb[2]) <= tolerance) return true;
        }
      }
      return false;
    });
  }, [png.toString('base64'), points, rgb, radius, tolerance]);
}

// The [r, g, b] of the PNG screenshot `png` of the whole page at each of `points` (page
// coordinates).
export async function pixelsAt(page, png, points) {
  return page.evaluate(async ([base64, points]) => {
    const { width, data, scale } = await window.decodeScreenshot(base64);
    return points.map(({ x, y }) => {
      const i = 4 * (Math.round(y * scale) * width + Math.round(x * scale));
      return [data[i], data[i + 1], data[i + 2]];
    });
  }, [png.toString('base64'), points]);
}

// Closes the browser, then stops the server even when closing failed (on a console problem).
export async function closeAll(browser, server) {
  try {
    await browser?.close();
  } finally {
    await server?.stop();
  }
}

// Polls `probe` (sync or async) until it returns a truthy value; fails after `timeoutMs`.
export async function waitFor(probe, what, timeoutMs = 30000) {
  const end = Date.now() + timeoutMs;
  let last;
  while (Date.now() < end) {
    last = await probe();
    if (last) return last;
    await new Promise((r) => setTimeout(r, 50));
  }
  throw new Error(`timed out waiting for ${what} (last: ${JSON.stringify(last)})`);
}

// A WebSocket client on a raw TCP socket, so tests can also send what no browser would:
// binary frames, bad opcodes, unmasked or oversized frames.
export class RawWebSocket {
  static connect(port, { origin } = {}) {
    return new Promise((resolve, reject) => {
      const socket = net.connect(port, '127.0.0.1');
      const key = crypto.randomBytes(16).toString('base64');
      let buffer = Buffer.alloc(0);
      socket.once('error', reject);
      socket.on('connect', () => socket.write(
        `GET /ws HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
        `Sec-WebSocket-Key: ${key}\r\nSec-WebSocket-Version: 13\r\n${origin ? `Origin: ${origin}\r\n` : ''}\r\n`));
      const onHandshake = (d) => {
        buffer = Buffer.concat([buffer, d]);
        const end = buffer.indexOf('\r\n\r\n');
        if (end < 0) return;
        socket.off('data', onHandshake);
        const head = buffer.subarray(0, end).toString();
        if (!head.startsWith('HTTP/1.1 101')) { socket.destroy(); reject(new Error(head.split('\r\n')[0])); return; }
        resolve(new RawWebSocket(socket, buffer.subarray(end + 4)));
      };
      socket.on('data', onHandshake);
    });
  }

  constructor(socket, rest) {
    this.socket = socket;
    this.buffer = Buffer.alloc(0);
    this.messages = [];  // {text} or {binary}
    this.waiters = [];
    this.closed = false;
    socket.on('data', (d) => this.receive(d));
    socket.on('close', () => { this.closed = true; this.wake(); });
    socket.on('error', () => {});
    if (rest.length) this.receive(rest);
  }

  receive(d) {
    this.buffer = Buffer.concat([this.buffer, d]);
    for (;;) {
      const b = this.buffer;
      if (b.length < 2) break;
      let len = b[1] & 0x7f, offset = 2;
      if (len === 126) { if (b.length < 4) break; len = b.readUInt16BE(2); offset = 4; }
      else if (len === 127) { if (b.length < 10) break; len = Number(b.readBigUInt64BE(2)); offset = 10; }
      if (b.length < offset + len) break;
      const fin = (b[0] & 0x80) !== 0, payload = Buffer.from(b.subarray(offset, offset + len));
      let opcode = b[0] & 0x0f;
      this.buffer = b.subarray(offset + len);
      if (opcode === 0 || ((opcode === 1 || opcode === 2) && !fin)) {
        // Fragmented message: collect until the final frame.
        if (opcode !== 0) this.fragments = { opcode, parts: [] };
        this.fragments.parts.push(payload);
        if (!fin) continue;
        opcode = this.fragments.opcode;
        const whole = Buffer.concat(this.fragments.parts);
        this.fragments = null;
        if (opcode === 1) this.messages.push({ text: whole.toString() });
        else this.messages.push({ binary: whole });
      } else if (opcode === 1) this.messages.push({ text: payload.toString() });
      else if (opcode === 2) this.messages.push({ binary: payload });
      else if (opcode === 9) this.sendFrame(10, payload);  // pong
      else if (opcode === 8) this.messages.push({ close: payload.length >= 2 ? payload.readUInt16BE(0) : 0 });
    }
    this.wake();
  }

  wake() { for (const w of this.waiters.splice(0)) w(); }

  // One frame; `mask` false breaks the protocol on purpose (clients must mask).
  sendFrame(opcode, payload, { fin = true, mask = true, rsv = 0 } = {}) {
    const data = Buffer.isBuffer(payload) ? payload : Buffer.from(payload);
    const head = [((fin ? 0x80 : 0) | (rsv << 4) | opcode)];
    const m = mask ? 0x80 : 0;
    if (data.length < 126) head.push(m | data.length);
    else if (data.length < 65536) head.push(m | 126, data.length >> 8, data.length & 0xff);
    else { head.push(m | 127); const l = Buffer.alloc(8); l.writeBigUInt64BE(BigInt(data.length)); head.push(...l); }
    let body = data;
    if (mask) {
      const key = crypto.randomBytes(4);
      body = Buffer.from(data.map((byte, i) => byte ^ key[i % 4]));
      head.push(...key);
    }
    if (!this.socket.destroyed) this.socket.write(Buffer.concat([Buffer.from(head), body]));
  }

  sendText(text) { this.sendFrame(1, text); }
  sendJson(object) { this.sendText(JSON.stringify(object)); }

  // The next message matching `match`, from those received since `from` (index).
  async next(match, timeoutMs = 15000, from = 0) {
    const end = Date.now() + timeoutMs;
    for (;;) {
      const found = this.messages.slice(from).find(match);
      if (found) return found;
      if (this.closed) throw new Error('connection closed');
      const left = end - Date.now();
      if (left <= 0) throw new Error('timed out waiting for a message');
      await new Promise((r) => { const timer = setTimeout(r, left); this.waiters.push(() => { clearTimeout(timer); r(); }); });
    }
  }

  json(match) { return this.messages.filter((m) => m.text).map((m) => JSON.parse(m.text)).filter(match); }
  close() { this.socket.destroy(); }
}

// One test file's session: `serve` with `args`, Chromium, a page on it, and with `socket` a raw
// WebSocket beside the page. closeSession fails on any console problem of the run.
export async function openSession(args = [], { socket = false } = {}) {
  const server = await startServer(args);
  const browser = await launchChromium();
  const page = await openPage(browser, server.url);
  const ws = socket ? await RawWebSocket.connect(server.port) : null;
  return { server, browser, page, ws };
}

export async function closeSession(session) {
  session?.ws?.close();
  await closeAll(session?.browser, session?.server);
}

// A session on scenes/yumi_bar.json changed by edit(scene) (its robot files found from a copy in
// a temporary directory, which close() removes): {session, page, close}.
export async function openBarSession(name, edit) {
  const dir = mkdtempSync(path.join(tmpdir(), 'shapectl-bar-'));
  const scene = JSON.parse(readFileSync(path.join(sourceDir, 'scenes/yumi_bar.json'), 'utf8'));
  for (const key of ['urdf', 'collision_spheres']) scene.robot[key] = path.join(sourceDir, 'scenes', scene.robot[key]);
  edit(scene);
  const file = path.join(dir, name);
  writeFileSync(file, JSON.stringify(scene));
  const session = await openSession([file]);
  const close = async () => {
    try {
      await closeSession(session);  // fails on any console problem of the run
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  };
  return { session, page: session.page, close };
}

// Page coordinates of the node nearest the object's centroid (a bent object's centroid may lie
// off it): where a click adds a target at the middle of the object.
export function centreNodeOnPage(page) {
  return page.evaluate(() => {
    const c = window.shapectl.objectCentroid(), x = window.shapectl.positions();
    let nearest = 0, best = Infinity;
    for (let i = 0; i < x.length; i += 3) {
      const d = (x[i] - c[0]) ** 2 + (x[i + 1] - c[1]) ** 2 + (x[i + 2] - c[2]) ** 2;
      if (d < best) { best = d; nearest = i / 3; }
    }
    return window.shapectl.nodeToPage(nearest);
  });
}
