// `shapectl serve --robot sim`: the link's status is in every state, and arm/disarm work over
// the WebSocket (the page's Arm/Disarm buttons send the same commands).
import { describe, it, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startServer, RawWebSocket, waitFor } from './support.mjs';
import { Command, LinkKind, Message } from '../../web/js/protocol.js';

describe('robot link in the GUI session', () => {
  let server, ws;
  before(async () => {
    server = await startServer(['--robot', LinkKind.Sim]);
    ws = await RawWebSocket.connect(server.port);
  });
  after(async () => {
    ws?.close();
    await server?.stop();
  });

  const latest = () => ws.json((m) => m.type === Message.State).pop();
  const reply = (id) => ws.next((m) => m.text?.includes(`"id":"${id}"`)).then((m) => JSON.parse(m.text));

  it('reports the link, arms and disarms it', async () => {
    const scene = JSON.parse((await ws.next((m) => m.text?.includes(`"type":"${Message.Scene}"`))).text);
    assert.equal(scene.link, true);
    const connected = await waitFor(() => latest()?.link?.connected && latest(), 'sim link feedback');
    assert.equal(connected.link.kind, LinkKind.Sim);
    assert.equal(connected.link.armed, false, 'starts disarmed');
    ws.sendJson({ type: Command.Arm, id: 'arm' });
    assert.equal((await reply('arm')).type, Message.Ok);
    await waitFor(() => latest().link.armed, 'armed');
    ws.sendJson({ type: Command.Disarm, id: 'disarm' });
    assert.equal((await reply('disarm')).type, Message.Ok);
    const disarmed = await waitFor(() => !latest().link.armed && latest(), 'disarmed');
    assert.match(disarmed.link.reason, /GUI/);
  });
});
