// WebSocket fuzz test: thousands of random, malformed, oversized and out-of-range messages, plus
// protocol-level abuse on connections of their own. Every bad message must get exactly one
// error reply; the server must keep serving everyone else, and the optimizer keep its state.
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { startServer, RawWebSocket, waitFor } from './support.mjs';
import { Command, Message } from '../../web/js/protocol.js';

// Seeded PRNG (mulberry32), so a failure can be replayed.
function rng(seed) {
  return () => {
    seed = (seed + 0x6d2b79f5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

const TYPES = Object.values(Command);
// Commands without fields, and a valid ping as text to break in various ways.
const NO_FIELD_TYPES = [Command.Ping, Command.Reset, Command.ClearTargets, Command.Arm, Command.Disarm];
const PING = JSON.stringify({ type: Command.Ping });

// Messages that are invalid by construction, in many different ways.
function badMessages(count, nodeCount, jointCount, random) {
  const pick = (a) => a[Math.floor(random() * a.length)];
  const int = (n) => Math.floor(random() * n);
  const badNumbers = [nodeCount, -1, 1.5, 1e20, -1e300, '3', null, true, [], {}, 'NaN'];
  const badPoints = [[0, 0], [0, 0, 0, 0], [11, 0, 0], [0, -1e6, 0], ['x', 0, 0], [null, 0, 0], 'abc', 7, [[0, 0, 0]]];
  const randomJson = (depth) => {
    const r = random();
    if (depth > 3 || r < 0.3) return pick([0, -1, 1e308, 'str', true, false, null, 'ü\u0000\u2028', ''.padEnd(int(300), 'x')]);
    if (r < 0.65) return Array.from({ length: int(5) }, () => randomJson(depth + 1));
    return Object.fromEntries(Array.from({ length: int(5) }, (_, k) => [pick(['type', 'id', 'node', 'x', `k${k}`]), randomJson(depth + 1)]));
  };
  const generators = [
    // Not JSON, or JSON that is not a command object.
    () => pick(['', ' ', '{', '}', '[', 'null', '42', JSON.stringify(Command.Ping), '{"type":', PING.slice(0, -1), Command.Ping, '\u0000', `${PING}}`]),
    () => JSON.stringify(randomJson(0)).replace(new RegExp(`"type":"(${NO_FIELD_TYPES.join('|')})"`), '"type":"x"'),
    () => Array.from({ length: 1 + int(200) }, () => String.fromCharCode(32 + int(95))).join(''),
    () => '['.repeat(17 + int(5000)) + ']'.repeat(int(3)),
    // Unknown or mistyped "type", unknown keys, bad ids.
    () => JSON.stringify({ type: pick(['launch', 'PING', '', 'set-target', 1, null, [Command.Ping]]) }),
    () => JSON.stringify({ type: pick(TYPES), [`extra${int(9)}`]: 1, node: 0, position: [0, 0, 0] }),
    () => JSON.stringify({ type: Command.Ping, id: pick([1.5, [], {}, true, 'x'.repeat(65)]) }),
    // Out-of-range or wrongly typed fields.
    () => JSON.stringify({ type: Command.SetTarget, id: int(1e6), node: pick(badNumbers), position: [0.4, 0, 0.3] }),
    () => JSON.stringify({ type: Command.SetTarget, node: int(nodeCount), position: pick(badPoints) }),
    () => `{"type":"${Command.SetTarget}","node":${int(nodeCount)},"position":[1e400,0,0]}`,
    () => JSON.stringify({ type: Command.SetTarget, node: int(nodeCount) }),
    () => JSON.stringify({ type: Command.RemoveTarget, node: pick(badNumbers) }),
    () => JSON.stringify({ type: Command.SetTargets, targets: pick([null, {}, 'all', [{ node: 0 }], [{ node: 0, position: [0, 0, 0] }, { node: 0, position: [0, 0, 0] }]]) }),
    () => JSON.stringify({ type: Command.SetTargets, targets: Array.from({ length: nodeCount + 1 }, (_, k) => ({ node: k, position: [0, 0, 0] })) }),
    () => JSON.stringify({ type: Command.SetCenterline, points: pick([[], [[0, 0, 0]], 'line', [[0, 0, 0], [0, 0]], [[0, 0, 0], [20, 0, 0]]]) }),
    () => JSON.stringify({ type: Command.SetCenterline, points: Array.from({ length: 2001 + int(100) }, (_, k) => [0.4, k * 1e-4, 0.3]) }),
    () => JSON.stringify({ type: Command.SetPaused, paused: pick([1, 0, 'true', null, [], undefined]) }),
    () => JSON.stringify({ type: Command.SetJoint, joint: pick([jointCount, -1, 'no_such_joint', 0.5, null]), value: 0 }),
    () => JSON.stringify({ type: Command.SetJoint, joint: int(jointCount), value: pick([100, -100, 1e400, 'x', null]) }),
    () => JSON.stringify({ type: Command.SetJoints, joints: pick([[], Array(jointCount + 1).fill(0), Array(jointCount).fill('x'), Array(jointCount).fill(50)]) }),
    () => JSON.stringify({ type: Command.LoadScene, scene: pick(['../../etc/passwd', '/etc/passwd', '', 'nope.json', 'yumi_bar.json/..', 7]) }),
    () => JSON.stringify({ type: pick([Command.Arm, Command.Disarm]) }),  // no robot link in this session
  ];
  return Array.from({ length: count }, () => pick(generators)());
}

describe('WebSocket fuzz', () => {
  let server, watcher, scene;

  before(async () => {
    server = await startServer([]);
    watcher = await RawWebSocket.connect(server.port);
    scene = JSON.parse((await watcher.next((m) => m.text?.includes(`"type":"${Message.Scene}"`))).text);
  });

  after(async () => {
    watcher?.close();
    await server?.stop();
  });

  it('answers every bad message with one error and changes nothing', async () => {
    // A session with a target being worked on.
    watcher.sendJson({ type: Command.SetTarget, id: 'setup', node: 10, position: [0.4, 0.05, 0.3] });
    await watcher.next((m) => m.text?.includes('"id":"setup"'));
    const latest = () => watcher.json((m) => m.type === Message.State).pop();
    await waitFor(() => latest()?.targets.length === 1, 'the target in the state');
    const reference = latest();

    const fuzzer = await RawWebSocket.connect(server.port);
    const messages = badMessages(3000, scene.node_count, scene.robot.joint_names.length, rng(20260517));
    let sent = 0;
    const replies = () => fuzzer.json((m) => m.type === Message.Ok || m.type === Message.Error);
    for (let batch = 0; batch < messages.length; batch += 100) {
      for (const text of messages.slice(batch, batch + 100)) { fuzzer.sendText(text); sent++; }
      if (batch % 500 === 0) { fuzzer.sendFrame(2, Buffer.from([1, 2, 3])); sent++; }  // binary
      await waitFor(() => replies().length >= sent, `replies to ${sent} messages`, 60000);
      // Drop what was read so far (keeps the buffers small).
    }
    const all = replies();
    assert.equal(all.length, sent, 'exactly one reply per message');
    const accepted = all.filter((r) => r.type === Message.Ok);
    assert.deepEqual(accepted, [], 'no fuzz message was accepted');
    assert.ok(all.every((r) => typeof r.message === 'string' && r.message.startsWith('message')), 'every error says what was wrong');

    // The session is as it was: same scene, same target, not paused; states still stream.
    const count = watcher.messages.length;
    await watcher.next((m) => m.text?.includes(`"type":"${Message.State}"`), 5000, count);
    const after = latest();
    assert.equal(after.scene, reference.scene);
    assert.equal(after.paused, false);
    assert.deepEqual(after.targets, reference.targets);
    assert.ok(after.iterations >= reference.iterations);
    assert.ok(server.alive());
    assert.match(server.log, /bad message/);
    fuzzer.close();
  });

  it('drops abusive connections without affecting the others', async () => {
    // Each breaks the protocol: the server must close that connection (and only that one).
    const abuses = [
      (ws) => ws.sendText('x'.repeat(1024 * 1024 + 10)),                      // over the size limit
      (ws) => ws.sendFrame(1, Buffer.from([0xff, 0xfe, 0x80])),               // invalid UTF-8
      (ws) => ws.sendFrame(1, PING, { mask: false }),                          // unmasked
      (ws) => ws.sendFrame(3, 'x'),                                            // reserved opcode
      (ws) => ws.sendFrame(1, PING, { rsv: 4 }),                               // reserved bits
      (ws) => ws.sendFrame(0, 'x'),                                            // continuation of nothing
      (ws) => ws.socket.write(Buffer.from([0x81, 0xff, 0x7f, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 1, 2, 3, 4])),  // absurd length
      (ws) => ws.socket.write('GET / HTTP/1.1\r\n\r\n'),                     // HTTP inside the WebSocket
    ];
    for (const [k, abuse] of abuses.entries()) {
      const ws = await RawWebSocket.connect(server.port);
      abuse(ws);
      await waitFor(() => ws.closed, `the server to close abusive connection ${k}`, 10000);
    }
    const unfinished = await RawWebSocket.connect(server.port);  // a message never finished
    unfinished.sendFrame(1, '{"type":', { fin: false });
    unfinished.close();
    // Raw TCP garbage, half a handshake, a wrong origin, and a burst of connections.
    for (const text of ['\x00\x01\x02garbage\r\n\r\n', 'GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n', 'GET /../../etc/passwd HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n']) {
      const s = net.connect(server.port, '127.0.0.1');
      s.on('error', () => {});
      s.write(text);
      await new Promise((r) => setTimeout(r, 100));
      s.destroy();
    }
    await assert.rejects(RawWebSocket.connect(server.port, { origin: 'http://evil.example' }), /403/);
    const burst = await Promise.allSettled(Array.from({ length: 40 }, () => RawWebSocket.connect(server.port)));
    assert.ok(burst.some((r) => r.status === 'rejected' && /503/.test(r.reason.message)), 'clients beyond the limit are refused');
    for (const r of burst) if (r.status === 'fulfilled') r.value.close();

    // Everyone else is unaffected: the watcher still gets states and can still command.
    const count = watcher.messages.length;
    await watcher.next((m) => m.text?.includes(`"type":"${Message.State}"`), 5000, count);
    watcher.sendJson({ type: Command.Ping, id: 'still-there' });
    await watcher.next((m) => m.text?.includes('"id":"still-there"') && m.text.includes(`"${Message.Ok}"`));
    const fresh = await RawWebSocket.connect(server.port);
    await fresh.next((m) => m.text?.includes(`"type":"${Message.Scene}"`));
    fresh.close();
    assert.ok(server.alive());
  });
});
