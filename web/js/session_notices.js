// Notices when another page changes the shared session: it switched the scene, or the targets
// vanished (cleared, reset, removed). This page's own commands of those kinds, sent within the
// last few seconds, explain a change, so they give no notice.
import { Command } from './protocol.js';

const OWN_CHANGE_S = 3;  // a change this soon after our own command is ours
const CLEARING = new Set([Command.ClearTargets, Command.Reset, Command.RemoveTarget, Command.LoadScene,
  Command.SetTargets, Command.SetCenterline]);

export class SessionNotices {
  // `notify(text)`: shows a notice.
  constructor(notify) {
    this.notify = notify;
    this.sentAt = new Map();  // command type → performance.now() when this page last sent it
    this.sceneName = null;
    this.targetCount = 0;
  }

  // Every command this page sends.
  sent(type) { if (CLEARING.has(type)) this.sentAt.set(type, performance.now()); }

  own(...types) {
    const now = performance.now();
    return types.some((type) => now - (this.sentAt.get(type) ?? -Infinity) < 1000 * OWN_CHANGE_S);
  }

  setScene(scene) {
    if (this.sceneName !== null && !this.own(Command.LoadScene))
      this.notify(`Another page switched the scene to ${scene.scene}`);
    this.sceneName = scene.scene;
    this.targetCount = 0;
  }

  setState(state) {
    if (state.scene !== this.sceneName) return;  // the scene message is on its way
    const count = state.targets.length;
    if (this.targetCount > 0 && count === 0 && !this.own(...CLEARING))
      this.notify(`Another page removed the targets (${this.targetCount})`);
    this.targetCount = count;
  }
}
