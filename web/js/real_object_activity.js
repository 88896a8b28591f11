// What the closed loop is doing, in words, for the Real object panel: whether observations are
// arriving (their rate, or how long since the last), what the feedback does with them, and the
// calibrations run and applied (docs/gui.md). States carry counts; the rate is measured here.

const mm = (m) => (Number.isFinite(m) ? (1000 * m).toFixed(1) : '–');
const degrees = (rad) => (Number.isFinite(rad) ? (rad * 180 / Math.PI).toFixed(2) : '–');

// Observations per second from the growing count in the states, over the last few seconds.
export class ObservationRate {
  constructor(windowSeconds = 3, now = () => performance.now() / 1000) {
    this.windowSeconds = windowSeconds;
    this.now = now;
    this.samples = [];      // [time, count] while the count grows
    this.lastChange = null; // when the count last grew, s
  }

  // The state's count; returns {perSecond, quietSeconds} (perSecond null until two counts).
  update(count) {
    const t = this.now();
    const last = this.samples[this.samples.length - 1];
    if (!last || count !== last[1]) {
      if (last && count < last[1]) this.samples = [];  // a new session: start over
      this.samples.push([t, count]);
      if (last) this.lastChange = t;
    }
    while (this.samples.length > 2 && t - this.samples[0][0] > this.windowSeconds) this.samples.shift();
    const first = this.samples[0], newest = this.samples[this.samples.length - 1];
    const span = t - first[0];
    const perSecond = this.samples.length > 1 && span > 0 ? (newest[1] - first[1]) / span : null;
    return { perSecond, quietSeconds: this.lastChange === null ? null : t - this.lastChange };
  }
}

// The panel's activity lines for a state and the measured rate. Nothing before the first
// observation unless the feedback is on (the line above already says "no observations yet"):
// the panel keeps its height at 1280×800 until there is something to say.
export function activityLines(state, rate) {
  const lines = [];
  const a = state.authority;
  if (!state.observations) {
    if (state.feedback) lines.push('feedback on: waiting for observations of the target nodes to correct the targets');
    return lines;
  }
  if (rate.quietSeconds !== null && rate.quietSeconds > 2) {
    lines.push(`observations: ${state.observations}, none for ${Math.round(rate.quietSeconds)} s`);
  } else {
    const perSecond = rate.perSecond === null ? '' : ` at ${rate.perSecond.toFixed(1)}/s`;
    lines.push(`observations: arriving${perSecond} (${state.observations} so far)`);
  }
  if (!state.feedback) {
    lines.push('feedback off: the robot follows the model alone');
  } else if (!a) {
    lines.push('feedback on: waiting for observations of the target nodes to correct the targets');
  } else {
    lines.push(`feedback on: targets corrected by up to ${mm(a.largest)} mm` +
      ` (at most ${mm(a.max_correction)}); joints ${degrees(a.joint_offset)}° from where the loop started`);
  }
  const c = state.calibration, applied = state.model?.updates ?? 0;
  if (c) {
    const running = c.running ? ', one running' : '';
    const mode = c.automatic ? 'automatic' : 'on request';
    lines.push(`calibrations (${mode}): ${c.runs} run, ${applied} applied to the model${running}`);
  }
  return lines;
}
