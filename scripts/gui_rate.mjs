// Does the GUI stay responsive while the optimizer works? After a build:
//   node scripts/gui_rate.mjs [SCENE.json …] [--seconds 15] [--rate 30] [--jump 0.10] [--browser]
// (SHAPECTL_CLI names another binary). For each scene (default: scenes/yumi_bar.json and
// scenes/yumi_bar_12k.json) it starts `shapectl serve`, connects to /ws as a page does, puts a
// target on the bar's top-middle node --jump metres above it, then drags it 1 cm sideways every
// 0.5 s (like a user), and records when each state message arrives. It prints the configured
// rate, the median / p90 / max interval between state messages, how many of them carried a new
// optimizer iterate, how soon a change shows in the states, the time from a change to "reached"
// / "best effort", and the server's CPU. With --browser a headless Chromium page watches the
// same session: its state handling and requestAnimationFrame rates. Last, the longest pause of
// the states when the scene is switched between the given (bundled) scenes.
// A benchmark (docs/benchmarks.md), not a test: it asserts nothing and is not in CTest.
import { readFileSync, readdirSync } from 'node:fs';
import path from 'node:path';
import { monitorEventLoopDelay, performance } from 'node:perf_hooks';
import { Command, ControllerStatus, Message, POSITIONS_MAGIC } from '../web/js/protocol.js';
import { RawWebSocket, launchChromium, openPage, sourceDir, startServer } from '../tests/web/support.mjs';

const DRAG_STEP_METRES = 0.01;  // each drag change moves the target this far sideways (+y)
const DRAG_PERIOD_MS = 500;
const CLOCK_TICKS_PER_SECOND = 100;  // Linux' USER_HZ for /proc/*/stat
const STOPPED = new Set([ControllerStatus.Reached, ControllerStatus.BestEffort, ControllerStatus.Failed]);

function parseArguments(argv) {
  const options = { scenes: [], seconds: 15, rate: 30, jump: 0.10, browser: false };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--seconds') options.seconds = Number(argv[++i]);
    else if (a === '--rate') options.rate = Number(argv[++i]);
    else if (a === '--jump') options.jump = Number(argv[++i]);
    else if (a === '--browser') options.browser = true;
    else if (a.startsWith('--')) throw new Error(`gui_rate.mjs: unknown option ${a}; known: --seconds, --rate, --jump, --browser`);
    else options.scenes.push(path.resolve(a));
  }
  if (!(options.seconds > 2)) throw new Error('gui_rate.mjs: --seconds: expected a number above 2');
  if (!(Math.abs(options.jump) <= 1)) throw new Error('gui_rate.mjs: --jump: expected metres from -1 to 1');
  if (!(options.rate > 0)) throw new Error('gui_rate.mjs: --rate: expected a positive number');
  if (!options.scenes.length) options.scenes = ['yumi_bar.json', 'yumi_bar_12k.json'].map((f) => path.join(sourceDir, 'scenes', f));
  return options;
}

const quantile = (sorted, q) => sorted.length ? sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))] : NaN;
const intervals = (times) => times.slice(1).map((t, k) => t - times[k]).sort((a, b) => a - b);
const ms = (x) => (Number.isFinite(x) ? x.toFixed(1) : '–');
const summary = (gaps) => `median ${ms(quantile(gaps, 0.5))} ms, p90 ${ms(quantile(gaps, 0.9))} ms, max ${ms(gaps.at(-1))} ms (${gaps.length} intervals)`;

// CPU seconds of a process, in total and per thread ({tid: seconds}).
function cpuSeconds(pid) {
  const seconds = (stat) => {
    const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');  // after "pid (comm) "
    return (Number(fields[11]) + Number(fields[12])) / CLOCK_TICKS_PER_SECOND;  // utime + stime
  };
  const threads = {};
  for (const tid of readdirSafe(`/proc/${pid}/task`)) {
    try { threads[tid] = seconds(readFileSync(`/proc/${pid}/task/${tid}/stat`, 'utf8')); } catch { /* exited */ }
  }
  return { total: seconds(readFileSync(`/proc/${pid}/stat`, 'utf8')), threads, at: performance.now() };
}

function readdirSafe(dir) {
  try { return readdirSync(dir); } catch { return []; }
}

// The node nearest the middle of the bar's top face, and its position (from a positions frame).
function topMiddleNode(positions, bar) {
  const up = [0, 0, 1];
  const goal = bar.center.map((c, k) => c + up[k] * bar.thickness / 2);
  let best = 0, bestDistance = Infinity;
  for (let i = 0; i < positions.length / 3; i++) {
    const d = Math.hypot(positions[3 * i] - goal[0], positions[3 * i + 1] - goal[1], positions[3 * i + 2] - goal[2]);
    if (d < bestDistance) { best = i; bestDistance = d; }
  }
  return { node: best, position: [positions[3 * best], positions[3 * best + 1], positions[3 * best + 2]] };
}

function parsePositions(buffer) {
  if (buffer.length < 16 || buffer.subarray(0, 4).toString() !== POSITIONS_MAGIC) return null;
  const count = buffer.readUInt32LE(4);
  const out = new Float64Array(3 * count);
  for (let k = 0; k < 3 * count; k++) out[k] = buffer.readFloatLE(16 + 4 * k);
  return out;
}

// Records every message's arrival time (ms, performance.now()) as the socket receives it.
async function connectRecorder(port) {
  const ws = await RawWebSocket.connect(port);
  const recorder = { ws, states: [], positionFrames: 0, scene: null, firstPositions: null, errors: [] };
  const take = () => {
    const now = performance.now();
    for (const m of ws.messages.splice(0)) {
      if (m.binary) {
        recorder.positionFrames++;
        recorder.firstPositions ??= parsePositions(m.binary);
        continue;
      }
      if (!m.text) continue;
      const message = JSON.parse(m.text);
      if (message.type === Message.State) {
        recorder.states.push({ at: now, seq: message.seq, iterations: message.iterations, status: message.status,
          error: message.error?.mean, target: message.targets?.[0]?.position });
      } else if (message.type === Message.Scene) recorder.scene = message;
      else if (message.type === Message.Error) recorder.errors.push(message.message);
    }
  };
  const wake = ws.wake.bind(ws);
  ws.wake = () => { take(); wake(); };
  take();
  return recorder;
}

async function waitUntil(probe, what, timeoutMs = 60000) {
  const end = Date.now() + timeoutMs;
  while (!probe()) {
    if (Date.now() > end) throw new Error(`gui_rate.mjs: timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 20));
  }
}

// Whether state `s` shows the target of `change` (so the controller has applied it).
const sameTarget = (s, change) => s.target?.every((v, k) => Math.abs(v - change.target[k]) < 1e-9);

const sleepUntil = (t) => new Promise((r) => setTimeout(r, Math.max(0, t - performance.now())));

// A headless page on the session: counts its handled states, scene renders and rAF callbacks.
async function watchInBrowser(url) {
  const browser = await launchChromium();
  const page = await openPage(browser, url);
  await page.evaluate(() => {
    const r = { frames: [], running: true };
    window.rateProbe = r;
    const loop = (t) => { r.frames.push(t); if (r.running) requestAnimationFrame(loop); };
    requestAnimationFrame(loop);
  });
  const stateTimes = new Set();
  const poll = setInterval(async () => {
    try { for (const t of await page.evaluate(() => window.shapectl.stats.stateTimes)) stateTimes.add(t); } catch { /* closing */ }
  }, 1000);
  const start = await page.evaluate(() => ({ renders: window.shapectl.frames, states: window.shapectl.stats.states, now: performance.now() }));
  return {
    // The page's numbers since the start, read at the end of the measured window.
    async read() {
      clearInterval(poll);
      const end = await page.evaluate(() => {
        window.rateProbe.running = false;
        return { renders: window.shapectl.frames, states: window.shapectl.stats.states, now: performance.now(),
          frames: window.rateProbe.frames, stateTimes: window.shapectl.stats.stateTimes };
      });
      for (const t of end.stateTimes) stateTimes.add(t);
      const seconds = (end.now - start.now) / 1000;
      const times = [...stateTimes].filter((t) => t >= start.now).sort((a, b) => a - b);
      return { seconds, statesPerSecond: (end.states - start.states) / seconds, stateGaps: intervals(times),
        rendersPerSecond: (end.renders - start.renders) / seconds, rafGaps: intervals(end.frames),
        rafPerSecond: end.frames.length / seconds };
    },
    async close() {
      try { await browser.close(); } catch (e) { console.log(`  (page: ${e.message.slice(0, 200)})`); }
    },
  };
}

async function measure(scene, options) {
  const server = await startServer([scene, '--rate', String(options.rate)]);
  const page = options.browser ? await watchInBrowser(server.url) : null;
  const recorder = await connectRecorder(server.port);
  const loop = monitorEventLoopDelay({ resolution: 5 });
  try {
    await waitUntil(() => recorder.scene && recorder.firstPositions && recorder.states.length, 'the scene, positions and a state');
    const { node, position } = topMiddleNode(recorder.firstPositions, recorder.scene.bar);
    let id = 1;
    const changes = [];  // {at, target}: each target change sent
    const send = (offsetY) => {
      const target = [position[0], position[1] + offsetY, position[2] + options.jump];
      changes.push({ at: performance.now(), target });
      recorder.ws.sendJson({ type: Command.SetTarget, id: id++, node, position: target });
    };

    loop.enable();
    const cpu0 = cpuSeconds(server.proc.pid);
    const t0 = performance.now();
    send(0);
    // Let the jump settle for a third of the run, then drag until two thirds of it.
    const dragStart = t0 + options.seconds * 1000 / 3, dragEnd = t0 + options.seconds * 2000 / 3;
    for (let t = dragStart, k = 1; t <= dragEnd; t += DRAG_PERIOD_MS, k++) {
      await sleepUntil(t);
      send(k * DRAG_STEP_METRES);
    }
    await sleepUntil(t0 + options.seconds * 1000);
    const cpu1 = cpuSeconds(server.proc.pid);
    loop.disable();
    const pageNumbers = page && await page.read();
    // After the last change: keep listening (up to a minute) until the optimizer stops.
    const stopped = (change) => recorder.states.find((s) => s.at > change.at && sameTarget(s, change) && STOPPED.has(s.status));
    const giveUp = performance.now() + 60000;
    while (!stopped(changes.at(-1)) && performance.now() < giveUp) await new Promise((r) => setTimeout(r, 100));
    const recorded = recorder.states.filter((s) => s.at >= t0 && s.at <= cpu1.at);

    const wall = (cpu1.at - cpu0.at) / 1000;
    const threadCpu = Object.entries(cpu1.threads).map(([tid, s]) => [tid, s - (cpu0.threads[tid] ?? 0)])
      .filter(([, s]) => s > 0.05).sort((a, b) => b[1] - a[1]);
    const newIterate = recorded.filter((s, k) => k > 0 && s.iterations > recorded[k - 1].iterations).length;
    const optimizing = recorded.filter((s) => s.status === ControllerStatus.Optimizing);
    // A change is applied in the first state showing its target, then optimized until stopped.
    const applied = changes.map((c) => recorder.states.find((s) => s.at > c.at && sameTarget(s, c))?.at - c.at);
    const stopOf = (c) => { const s = stopped(c); return s && { ms: s.at - c.at, status: s.status, error: s.error }; };
    const report = {
      scene: path.basename(scene), nodes: recorder.scene.node_count, target_node: node,
      rate: options.rate, jump_cm: Math.round(100 * options.jump), period_ms: 1000 / options.rate, seconds: wall,
      states: recorded.length, states_per_second: recorded.length / wall,
      all: intervals(recorded.map((s) => s.at)),
      // Between consecutive states that both say "optimizing" (not across idle spells).
      while_optimizing: recorded.slice(1).flatMap((s, k) => (s.status === ControllerStatus.Optimizing &&
        recorded[k].status === ControllerStatus.Optimizing ? [s.at - recorded[k].at] : [])).sort((a, b) => a - b),
      optimizing_states: optimizing.length, new_iterate_states: newIterate,
      iterations: (recorded.at(-1)?.iterations ?? 0) - (recorded[0]?.iterations ?? 0),
      position_frames: recorder.positionFrames,
      // The jump's, then the drags' (a change superseded before the controller took it is never
      // shown: the controller applies only the newest targets).
      changes: changes.length, jump_shown: applied[0],
      drags_shown: applied.slice(1).filter(Number.isFinite).sort((a, b) => a - b),
      jump: stopOf(changes[0]), settled: stopOf(changes.at(-1)),
      cpu_percent: 100 * (cpu1.total - cpu0.total) / wall,
      threads: threadCpu.map(([tid, s]) => `${tid}: ${(100 * s / wall).toFixed(0)} %`),
      client_loop_max_ms: loop.max / 1e6, errors: recorder.errors,
    };
    if (page) report.page = pageNumbers;
    if (process.env.GUI_RATE_TRACE) {
      for (const [k, s] of recorded.entries()) if (k === 0 || s.status !== recorded[k - 1].status || s.iterations !== recorded[k - 1].iterations)
        console.log(`  ${((s.at - t0) / 1000).toFixed(3)} s ${s.status} it ${s.iterations} seq ${s.seq} err ${(1000 * s.error).toFixed(2)} mm`);
    }
    return report;
  } finally {
    recorder.ws.close();
    await page?.close();
    await server.stop();
  }
}

// The one pause the stream is known to have: `load_scene` builds the new scene on the server's
// thread. Switches between the given scenes (they must be bundled ones, scenes/*.json) and back,
// and measures the longest gap between states from each switch until 3 s after it.
async function measureSwitches(scenes) {
  const names = scenes.filter((f) => path.dirname(f) === path.join(sourceDir, 'scenes')).map((f) => path.basename(f));
  if (names.length < 2) return;
  const server = await startServer([path.join(sourceDir, 'scenes', names[0])]);
  const recorder = await connectRecorder(server.port);
  try {
    await waitUntil(() => recorder.states.length, 'a state');
    let id = 1;
    for (const name of [...names.slice(1), names[0]]) {
      const at = performance.now();
      recorder.ws.sendJson({ type: Command.LoadScene, id: id++, scene: name });
      await sleepUntil(at + 3000);
      const times = [at, ...recorder.states.filter((s) => s.at > at).map((s) => s.at)];
      console.log(`switch to ${name}: longest gap between states ${ms(intervals(times).at(-1))} ms`);
    }
  } finally {
    recorder.ws.close();
    await server.stop();
  }
}

function print(r) {
  const late = r.all.filter((g) => g > 2 * r.period_ms).length;
  const stop = (s) => (s ? `${(s.ms / 1000).toFixed(2)} s (${s.status}, mean error ${(1000 * s.error).toFixed(2)} mm)` : 'not stopped');
  console.log(`${r.scene}: ${r.nodes} nodes, target on node ${r.target_node}, ${r.changes} target changes in ${r.seconds.toFixed(1)} s`);
  console.log(`  configured rate ${r.rate}/s (every ${ms(r.period_ms)} ms); received ${r.states} states, ${r.states_per_second.toFixed(1)}/s`);
  console.log(`  interval, all states:       ${summary(r.all)}; ${late} over 2 periods`);
  console.log(`  interval, while optimizing: ${summary(r.while_optimizing)}`);
  console.log(`  states carrying a new iterate: ${r.new_iterate_states} of ${r.states} (${r.optimizing_states} said optimizing); ${r.iterations} iterations; ${r.position_frames} position frames`);
  console.log(`  change → first state showing it: jump ${ms(r.jump_shown)} ms; drags: ${r.drags_shown.length} of ${r.changes - 1} shown, median ${ms(quantile(r.drags_shown, 0.5))} ms, max ${ms(r.drags_shown.at(-1))} ms`);
  console.log(`  ${r.jump_cm} cm jump → stopped: ${stop(r.jump)}; last drag change → stopped: ${stop(r.settled)}`);
  console.log(`  server CPU ${r.cpu_percent.toFixed(0)} % of one core (threads: ${r.threads.join(', ')}); client event-loop delay max ${ms(r.client_loop_max_ms)} ms`);
  if (r.errors.length) console.log(`  error replies: ${r.errors.slice(0, 3).join('; ')}`);
  if (r.page) {
    const p = r.page;
    console.log(`  page: ${p.statesPerSecond.toFixed(1)} states/s handled, interval ${summary(p.stateGaps)}`);
    console.log(`  page: ${p.rendersPerSecond.toFixed(1)} renders/s; requestAnimationFrame ${p.rafPerSecond.toFixed(1)}/s, interval ${summary(p.rafGaps)}`);
  }
}

let options;
try {
  options = parseArguments(process.argv.slice(2));
} catch (e) {
  console.error(e.message);
  process.exit(1);
}
console.log(`gui_rate: ${options.seconds} s per scene, --rate ${options.rate}, --jump ${options.jump}${options.browser ? ', with a headless page' : ''}; ${new Date().toISOString()}`);
for (const scene of options.scenes) print(await measure(scene, options));
await measureSwitches(options.scenes);
