// The Joints panel: a row per active joint, grouped under the arm it moves (the scene's
// robot.joint_arms; "other" for the rest), in chain order, labelled by its place in the chain
// (full name and limits on hover), with a slider and a numeric field in degrees. While paused
// the joints jog safely (joint_jog.js): every step sent moves a joint at most JOG_STEP, at most
// one step per JOG_INTERVAL_MS. A slider's thumb follows the pointer while dragged (with Shift a
// tenth as fast) and its joint walks after it while the button is held; a click on the track or
// an arrow key moves one step (Shift+arrow: a tenth of one); a typed angle is walked to. A
// refused step (self-collision) or resuming the optimizer ends a walk.
import { boundedJog, chainOrder, JOG_STEP, limitText } from './joint_jog.js';

const DEG = 180 / Math.PI;
export const JOG_INTERVAL_MS = 33;  // ~30 steps a second, as the states stream
const FINE = 0.1;                   // Shift: drags and arrow keys a tenth as fast
const THUMB_PX = 10;                // the slider thumb's width (style.css, .joint input[type=range])
const HOLD_MS = 500;                // after a step, the thumb waits this long for a state that has it

const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

export class JointPanel {
  // `box`: the element the groups go in; `jog(joint, value)`: sends a jog, a promise that
  // rejects when the server refuses it.
  constructor(box, jog) {
    this.box = box;
    this.jog = jog;
    this.joints = [];    // per θ index: {k, row, slider, field, mark, lo, hi, goal, sent, sentAt, drag}
    this.state = null;   // the last state
    this.timer = null;   // the walking interval while a joint has a goal
  }

  setRobot(robot) {
    this.stop();
    this.box.replaceChildren();
    this.joints = [];
    this.state = null;
    if (!robot) return;
    const groups = new Map();  // arm → its element, in chain order
    for (const k of chainOrder(robot)) {
      const arm = robot.joint_arms[k] ?? 'other';
      if (!groups.has(arm)) groups.set(arm, group(arm));
      groups.get(arm).append(this.row(robot, k));
    }
    const other = groups.get('other');
    groups.delete('other');
    this.box.append(...groups.values(), ...(other ? [other] : []));
  }

  row(robot, k) {
    const name = robot.joint_names[k];
    const lo = robot.lower_limits[k] ?? -Math.PI, hi = robot.upper_limits[k] ?? Math.PI;
    const place = robot.chain_positions[k];
    const row = document.createElement('div');
    row.className = 'joint';
    row.title = `${name}: joint ${place} in its chain, ${limitText(robot.lower_limits[k], robot.upper_limits[k])}`;
    row.innerHTML = `<span class="name">${place}</span>
      <input type="range" min="${lo}" max="${hi}" step="any" aria-label="${name}" data-joint="${k}">
      <input type="number" class="angle" step="0.1" min="${(lo * DEG).toFixed(1)}" max="${(hi * DEG).toFixed(1)}"
        aria-label="${name} in degrees" data-angle="${k}"><div class="limit"><i></i></div>`;
    const [slider, field] = row.querySelectorAll('input');
    const j = { k, row, slider, field, mark: row.querySelector('.limit i'), lo, hi, goal: null, sent: null, sentAt: -Infinity, drag: null };
    this.joints[k] = j;
    slider.addEventListener('pointerdown', (e) => this.press(j, e));
    slider.addEventListener('pointermove', (e) => this.move(j, e));
    slider.addEventListener('pointerup', () => this.release(j));
    slider.addEventListener('pointercancel', () => this.release(j));
    slider.addEventListener('keydown', (e) => this.key(j, e));
    // Keys the page does not take itself (PageUp, Home, …): one step towards where they point.
    slider.addEventListener('input', () => this.walk(j, Number(slider.value), true));
    field.addEventListener('change', () => {
      const degrees = Number(field.value);
      if (field.value.trim() !== '' && Number.isFinite(degrees)) this.walk(j, degrees / DEG, false);
    });
    return row;
  }

  // ---- the slider's pointer: the thumb follows it, the joint walks after the thumb ----
  press(j, e) {
    if (e.button !== 0 || j.slider.disabled) return;
    e.preventDefault();  // the page drags the thumb, not the browser
    j.slider.setPointerCapture(e.pointerId);
    j.slider.focus();
    // Pressed on the thumb: grabbed where it is; on the track: the thumb jumps there.
    const onThumb = Math.abs(e.clientX - this.thumbX(j)) <= THUMB_PX / 2;
    const start = onThumb ? Number(j.slider.value) : this.valueAt(j, e.clientX);
    // The thumb is at `value` for the pointer at `x`; `last`: the pointer's last x.
    j.drag = { x: e.clientX, value: start, shift: e.shiftKey, last: e.clientX, moved: false };
    this.walk(j, start, false);
  }

  move(j, e) {
    const drag = j.drag;
    if (!drag) return;
    // Shift pressed or let go: on from where the thumb is, at the other rate.
    if (e.shiftKey !== drag.shift) Object.assign(drag, { x: drag.last, value: j.goal, shift: e.shiftKey });
    const width = j.slider.getBoundingClientRect().width - THUMB_PX;
    const goal = drag.value + (e.clientX - drag.x) / width * (j.hi - j.lo) * (drag.shift ? FINE : 1);
    drag.moved ||= e.clientX !== drag.last;
    drag.last = e.clientX;
    this.setGoal(j, goal);
  }

  // Released: the joint stays where it got (the thumb comes back to it).
  release(j) {
    if (!j.drag) return;
    j.drag = null;
    this.setGoal(j, j.sent);
  }

  key(j, e) {
    const direction = { ArrowRight: 1, ArrowUp: 1, ArrowLeft: -1, ArrowDown: -1 }[e.key];
    if (!direction || !e.shiftKey) return;  // plain arrows: the input event, one step
    e.preventDefault();
    this.walk(j, this.from(j) + direction * FINE * JOG_STEP, true);
  }

  // ---- walking ----
  // Sets `j` walking to `value` (rad), the first step now; `once`: that step only.
  walk(j, value, once) {
    this.setGoal(j, value);
    this.step(j);
    if (once) { j.goal = null; j.slider.value = this.from(j); }
    else if (!this.timer) this.timer = setInterval(() => this.tick(), JOG_INTERVAL_MS);
  }

  setGoal(j, value) {
    j.goal = value === null ? null : clamp(value, j.lo, j.hi);
    if (j.goal !== null) j.slider.value = j.goal;
  }

  // Where the next step starts: the last one sent, until a state has had time to show it.
  from(j) {
    return j.sent ?? this.state.joints[j.k];
  }

  step(j) {
    if (j.goal === null || !this.state?.paused) return;
    const from = this.from(j), value = boundedJog(j.goal, from);
    if (value === from) return;
    j.sent = value;
    j.sentAt = performance.now();
    // Refused: the joint is where the state says, the walk ends.
    this.jog(j.k, value).catch(() => { j.sent = null; j.drag = null; this.setGoal(j, null); });
  }

  // A step for every joint walking: held drags once they moved, typed angles until there.
  tick() {
    let walking = false;
    for (const j of this.joints) {
      if (!j || j.goal === null) continue;
      if (!j.drag || j.drag.moved) this.step(j);
      if (!j.drag && this.from(j) === j.goal) this.setGoal(j, null);
      walking ||= j.goal !== null;
    }
    if (!walking) this.stop();
  }

  stop() {
    clearInterval(this.timer);
    this.timer = null;
    for (const j of this.joints) if (j) Object.assign(j, { goal: null, drag: null });
  }

  // ---- shown from the state ----
  update(state) {
    this.state = state;
    if (!state.paused && this.timer) this.stop();
    const now = performance.now();
    for (const j of this.joints) {
      if (!j) continue;
      const v = state.joints[j.k];
      j.slider.disabled = j.field.disabled = !state.paused;
      // The thumb shows the goal while walking; else the joint, once a state had time to show the last step.
      if (j.goal === null && now - j.sentAt > HOLD_MS) { j.sent = null; j.slider.value = v; }
      if (document.activeElement !== j.field) j.field.value = (Math.abs(v * DEG) < 0.05 ? 0 : v * DEG).toFixed(1);  // no "-0.0"
      j.mark.style.left = `calc(${(100 * (v - j.lo) / (j.hi - j.lo)).toFixed(2)}% - 1px)`;
      const margin = 0.05 * (j.hi - j.lo);
      j.row.classList.toggle('near-limit', v < j.lo + margin || v > j.hi - margin);
    }
  }

  // Page x of the thumb's centre, and the value under page x `x`.
  thumbX(j) {
    const r = j.slider.getBoundingClientRect();
    return r.left + THUMB_PX / 2 + (Number(j.slider.value) - j.lo) / (j.hi - j.lo) * (r.width - THUMB_PX);
  }

  valueAt(j, x) {
    const r = j.slider.getBoundingClientRect();
    return clamp(j.lo + (x - r.left - THUMB_PX / 2) / (r.width - THUMB_PX) * (j.hi - j.lo), j.lo, j.hi);
  }
}

// An arm's group: its heading and, after it, its rows.
function group(arm) {
  const element = document.createElement('div');
  element.className = 'arm';
  const heading = document.createElement('h3');
  heading.textContent = arm;
  element.append(heading);
  return element;
}
