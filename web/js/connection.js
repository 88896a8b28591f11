// The WebSocket to `shapectl serve` (protocol: docs/gui.md). Reconnects after a drop; every
// command gets an id and a promise of the server's reply.
import { Message, POSITIONS_MAGIC } from './protocol.js';

export function parsePositionsFrame(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 16) return null;
  const magic = String.fromCharCode(view.getUint8(0), view.getUint8(1), view.getUint8(2), view.getUint8(3));
  const count = view.getUint32(4, true);
  if (magic !== POSITIONS_MAGIC || buffer.byteLength !== 16 + 12 * count) return null;
  return { sequence: view.getFloat64(8, true), positions: new Float32Array(buffer, 16, 3 * count) };
}

export class Connection {
  constructor(url, handlers) {
    this.url = url;
    this.handlers = handlers;  // {scene(msg), state(msg), positions(frame), error(msg), open(), close()}
    this.nextId = 1;
    this.pending = new Map();  // id → {resolve, reject} of a command awaiting its reply
    this.retryMs = 250;
    this.ws = null;
    this.connect();
  }

  connect() {
    const ws = new WebSocket(this.url);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    ws.onopen = () => { this.retryMs = 250; this.handlers.open?.(); };
    ws.onclose = () => {
      for (const { reject } of this.pending.values()) reject(new Error('connection closed'));
      this.pending.clear();
      this.handlers.close?.();
      setTimeout(() => this.connect(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 4000);
    };
    ws.onmessage = (event) => this.receive(event.data);
  }

  receive(data) {
    if (data instanceof ArrayBuffer) {
      const frame = parsePositionsFrame(data);
      if (frame) this.handlers.positions?.(frame);
      return;
    }
    const message = JSON.parse(data);
    if (message.type === Message.Ok || message.type === Message.Error) {
      const waiting = this.pending.get(message.id);
      this.pending.delete(message.id);
      if (message.type === Message.Error) this.handlers.error?.(message);
      if (waiting) (message.type === Message.Ok ? waiting.resolve : waiting.reject)(message);
      return;
    }
    if (message.type === Message.Scene) this.handlers.scene?.(message);
    else if (message.type === Message.State) this.handlers.state?.(message);
  }

  // Sends {type, ...fields}; resolves with the "ok" reply, rejects with the "error" one.
  send(type, fields = {}) {
    if (this.ws.readyState !== WebSocket.OPEN) return Promise.reject(new Error('not connected'));
    const id = this.nextId++;
    this.ws.send(JSON.stringify({ type, id, ...fields }));
    return new Promise((resolve, reject) => this.pending.set(id, { resolve, reject }));
  }
}
