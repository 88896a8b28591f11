// The calibration part of the Real object panel: the Calibrate button and the automatic switch,
// the controller's current model (E, ν, ρ), and the last calibration's fitted values with their
// standard deviations in readable units (docs/calibration.md). Shows a state's "model" and
// "calibration"; the commands go out through the callbacks.
import { Parameter, Unit } from './protocol.js';
import { decimalsFor, formatValue, formatWithDeviation, shownUnit } from './units.js';

const LABELS = {
  [Parameter.YoungsModulus]: "Young's modulus",
  [Parameter.PoissonRatio]: "Poisson's ratio",
  [Parameter.Density]: 'density',
};

// "grip_offsets.left.x" → "left grip x"; unknown names as they came.
function parameterLabel(name) {
  if (LABELS[name]) return LABELS[name];
  const [group, endEffector, coordinate] = name.split('.');
  return group === Parameter.GripOffsets && coordinate ? `${endEffector} grip ${coordinate}` : name;
}

// Why a held parameter was held: its direction's deviation in units of its typical size
// (docs/calibration.md); null when the observations do not see that direction at all.
export function heldExplanation(deviation) {
  if (deviation === null || !Number.isFinite(deviation)) return 'the observations do not constrain it at all';
  return `the observations leave it undetermined: ± ${deviation.toPrecision(2)} × its typical size (identifiable below 0.1)`;
}

// The verdict cell of a fitted parameter (docs/calibration.md, "Verdicts"): a short word, its
// style, and the row's hover text: the interval, the prior, what it trades off with and what
// would determine it.
export function verdictOf(p) {
  const verdict = p.verdict ?? (p.held ? 'not determined' : 'determined');
  const short = { determined: 'determined', 'weakly determined': 'weak', 'not determined': 'held' }[verdict] ?? verdict;
  const lines = [`${parameterLabel(p.name)}: ${verdict}`];
  if (p.prior !== null && p.prior !== undefined) lines.push(`prior: ± ${p.prior.toPrecision(2)} ${p.unit} around its start`);
  if (p.implausible) lines.push('implausible: more than 3 prior σ from its start (a model error it absorbs?)');
  if (p.trades_off_with?.length) lines.push(`trades off with ${p.trades_off_with.join(', ')}`);
  if (p.suggestion) lines.push(p.suggestion);
  const className = p.implausible ? 'warning' : verdict === 'determined' ? '' : 'muted';
  return { short: p.implausible ? `${short}, implausible` : short, className, explanation: lines.join('\n') };
}

const mm = (m) => (Number.isFinite(m) ? (1000 * m).toFixed(2) : '–');

// Writes only changes: states arrive 30 times a second.
function setText(element, text) {
  if (element.textContent !== text) element.textContent = text;
}

function cell(text, className) {
  const td = document.createElement('td');
  td.textContent = text;
  if (className) td.className = className;
  return td;
}

export class CalibrationPanel {
  // elements: {button, auto, status, model, table, summary, error};
  // callbacks: {calibrate() → promise settled by the reply, setAutomatic(on)}.
  constructor(elements, callbacks) {
    this.elements = elements;
    this.callbacks = callbacks;
    this.requesting = false;  // a calibrate command awaits its reply
    this.shownResult = null;  // JSON of the result in the table, to rebuild it only on change
    this.calibration = null;  // the last state's "calibration"
    elements.button.addEventListener('click', () => this.calibrate());
    elements.auto.addEventListener('change', () => callbacks.setAutomatic(elements.auto.checked));
  }

  calibrate() {
    this.requesting = true;
    this.showControls();
    this.callbacks.calibrate().finally(() => { this.requesting = false; this.showControls(); });
  }

  // A state message: its "model" and "calibration" (either may be missing from older servers).
  update(state) {
    this.calibration = state.calibration ?? null;
    this.showModel(state.model);
    this.showControls();
    this.showResult(this.calibration?.result ?? null);
    const error = this.calibration?.error ?? '';
    setText(this.elements.error, error);
    this.elements.error.hidden = !error;
  }

  showModel(model) {
    const line = model
      ? `model: E ${formatValue(model.youngs_modulus, Unit.Pascal)} kPa · ν ${formatValue(model.poisson_ratio, Unit.None)}` +
        ` · ρ ${formatValue(model.density, Unit.KilogramPerCubicMetre)} kg/m³`
      : '';
    const m = this.elements.model;
    if (m.textContent === line) return;
    setText(m, line);
    m.title = (model?.grip_offsets ?? []).map((g) =>
      `${g.end_effector} grip offset: ${g.position.map((v) => formatValue(v, Unit.Metre, 2)).join(', ')} mm, ` +
      `${g.rpy.map((v) => formatValue(v, Unit.Radian, 2)).join(', ')}°`).join('\n');
  }

  showControls() {
    const c = this.calibration, { button, auto, status } = this.elements;
    const busy = this.requesting || !!c?.running;
    button.disabled = busy || !c || c.frames === 0;
    setText(button, busy ? 'Calibrating…' : 'Calibrate');
    button.classList.toggle('busy', busy);
    button.ariaBusy = String(busy);
    auto.disabled = !c;
    auto.checked = !!c?.automatic;
    setText(status, !c ? 'no calibration in this session'
      : c.frames === 0 ? 'no observed frames yet'
      : `${c.frames} frame${c.frames === 1 ? '' : 's'}${busy ? ', calibrating…' : ''}`);
  }

  showResult(result) {
    const json = result ? JSON.stringify(result) : null;
    if (json === this.shownResult) return;
    this.shownResult = json;
    const { table, summary } = this.elements;
    table.hidden = !result;
    summary.hidden = !result;
    const body = table.tBodies[0];
    body.replaceChildren();
    if (!result) return;
    const unidentified = new Map((result.unidentified ?? []).map((u) => [u.held, u.standard_deviation]));
    for (const p of result.parameters) {
      const row = document.createElement('tr');
      row.dataset.parameter = p.name;
      const { scale, symbol } = shownUnit(p.unit);
      const decimals = decimalsFor(p.fitted * scale, p.held ? NaN : p.standard_deviation * scale);
      row.append(cell(parameterLabel(p.name)), cell(formatValue(p.initial, p.unit, decimals), 'number'));
      if (p.held) {
        // Kept at its start: that value, muted (the verdict column says "held").
        const held = cell(formatValue(p.initial, p.unit, decimals), 'number muted');
        // That deviation is in units of the parameter's typical size (docs/calibration.md).
        if (unidentified.has(p.name)) held.title = heldExplanation(unidentified.get(p.name));
        row.append(held);
      } else {
        row.append(cell(formatWithDeviation(p.fitted, p.standard_deviation, p.unit), 'number'));
      }
      row.append(cell(symbol, 'unit'));
      const v = verdictOf(p);
      row.append(cell(v.short, v.className));
      row.dataset.verdict = p.verdict ?? (p.held ? 'not determined' : 'determined');
      row.title = v.explanation;
      body.append(row);
    }
    const notes = result.reason && (!result.converged || !result.applied) ? ` (${result.reason})` : '';
    summary.textContent = `RMS ${mm(result.rms_before)} → ${mm(result.rms_after)} mm · ` +
      `${result.iterations} iterations · ${result.seconds.toFixed(2)} s · ` +
      `${result.converged ? '' : 'not converged, '}${result.applied ? 'applied' : 'not applied'}${notes}`;
  }
}
