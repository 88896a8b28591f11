// Safe jogging from the joint sliders: each input event (a click on the track, a key, a drag
// step) moves a joint at most JOG_STEP from where it was, so one click cannot swing an arm.
// The server bounds every jog as well (its scene message's limits.max_jog_step) and refuses a
// jog into self-collision with the reason.

export const JOG_STEP = Math.PI / 180;  // 1° per event

// The value to send for a slider asked to go to `requested` from `current`.
export function boundedJog(requested, current, step = JOG_STEP) {
  return Math.min(current + step, Math.max(current - step, requested));
}

// Active joint indices in chain order (the scene's robot.chain_order; θ order without it).
export function chainOrder(robot) {
  return robot.chain_order ?? robot.joint_names.map((_, k) => k);
}

// "−168.5° … 168.5°" for a joint's limits (null: unbounded).
export function limitText(lower, upper) {
  const deg = (v) => (v === null || v === undefined ? '∞' : `${(v * 180 / Math.PI).toFixed(1)}°`.replace('-', '−'));
  return `${lower === null || lower === undefined ? '−∞' : deg(lower)} … ${deg(upper)}`;
}
