// Convergence plot (paper Fig. 7): the errors over the last 30 s in mm, one line per series,
// with the spans when someone was editing targets shaded red; a legend names the series
// that have values in the window. Linear or log y axis; the linear range follows the bulk of the
// values, so one spike does not flatten sub-mm detail (values above the top are drawn clipped,
// with a mark). Hovering shows the values at that time in a read-out.
const WINDOW_S = 30;
const MIN_TOP_MM = 1;          // the linear y axis shows at least 0–1 mm, the paper's goal
const RANGE_QUANTILE = 0.98;   // the linear top covers this share of the values in the window
const LOG_FLOOR_MM = 1e-3;     // the log axis' lowest decade: 1 µm
const EDIT_GAP_S = 1.0;        // editing spans closer than this are one span (no barcode)
const MIN_SPAN_PX = 2;         // a lone editing sample still shows

// The series, in the order of the values given to add() and drawn in that order: the observed
// error, what a user with a real object watches, last and on top. Each state field's meaning is
// in docs/gui.md. Colours match the 3D view where they mean the same (cyan: observed).
export const SERIES = Object.freeze([
  { name: 'error', label: 'mean error', colour: '#ff8c1a', title: 'the model against the targets it is aimed at' },
  // Wider, so it still shows where the observed error (within the camera's noise of it) covers it.
  { name: 'true', label: 'true error', colour: '#4ade80', title: 'the simulated world against the targets (serve --world)', width: 4 },
  { name: 'model', label: 'model error', colour: '#c4a5ff', title: 'RMS observed − predicted at the markers' },
  { name: 'observed', label: 'observed error', colour: '#22d3ee', title: 'the observed object against the targets' },
]);

// The linear y axis for errors up to `mm`: its top, the smallest 1, 2 or 5 × 10^k at or above
// `mm` (so the scale changes in steps, not with every sample), and the grid step.
function linearScale(mm) {
  const decade = 10 ** Math.floor(Math.log10(mm));
  for (const [m, lines] of [[1, 5], [2, 4], [5, 5]]) if (m * decade >= mm) return { top: m * decade, step: m * decade / lines };
  return { top: 10 * decade, step: 2 * decade };
}

// The value at `quantile` of `values` (sorted in place).
function quantileOf(values, quantile) {
  values.sort((a, b) => a - b);
  return values[Math.min(values.length - 1, Math.floor(quantile * values.length))];
}

// Tick label: as many decimals as the value needs, at most 3.
const tickLabel = (mm) => (mm === 0 ? '0' : mm >= 1 ? mm.toFixed(0) : mm.toFixed(Math.min(3, Math.ceil(-Math.log10(mm) - 1e-9))));

export class ConvergencePlot {
  // `legend`: an element that gets one entry per series. Optional: `readout`, an element that
  // shows the values under the pointer; `logScale`, a checkbox switching the y axis to log.
  constructor(canvas, legend, { readout = null, logScale = null } = {}) {
    this.canvas = canvas;
    this.samples = [];  // {t, values: one error (m) or null per SERIES entry, editing}
    this.legendEntries = SERIES.map((s) => {
      const entry = document.createElement('span');
      entry.className = 'legend-entry';
      entry.dataset.series = s.name;
      entry.title = s.title;
      entry.hidden = true;
      const swatch = document.createElement('i');
      swatch.style.background = s.colour;
      entry.append(swatch, s.label);
      legend.append(entry);
      return entry;
    });
    this.shown = SERIES.map(() => false);  // per series: any value in the window
    this.log = false;
    this.readout = readout;
    this.hoverX = null;   // CSS px in the canvas of the pointer, null when not over it
    this.layout = null;   // the last draw's {first, tStart, x(t)}: for the hover read-out
    this.clipped = 0;     // samples above the linear top in the last draw
    this.top = null;      // the last draw's y axis top, mm
    // Sharp on high-density screens: the drawing buffer at device pixels.
    const ratio = window.devicePixelRatio || 1;
    this.width = canvas.width;
    this.height = canvas.height;
    canvas.style.width = `${this.width}px`;
    canvas.style.height = `${this.height}px`;
    canvas.width = Math.round(this.width * ratio);
    canvas.height = Math.round(this.height * ratio);
    this.context = canvas.getContext('2d');
    this.context.scale(ratio, ratio);
    if (logScale) logScale.addEventListener('change', () => { this.log = logScale.checked; this.draw(); });
    canvas.addEventListener('pointermove', (e) => { this.hoverX = e.offsetX; this.draw(); });
    canvas.addEventListener('pointerleave', () => { this.hoverX = null; this.draw(); });
  }

  // `history`: the scene message's [[t, mean error, editing], ...]; the other series start empty.
  reset(history) {
    this.samples = history.map(([t, error, editing]) => ({ t, values: [error, null, null, null], editing: !!editing }));
  }

  // `values`: one error in m (or null) per SERIES entry.
  add(t, values, editing) {
    const last = this.samples[this.samples.length - 1];
    if (last && t <= last.t) return;
    this.samples.push({ t, values, editing });
    // Trimmed once per window, not per sample.
    if (this.samples[0].t < t - 2 * WINDOW_S) this.samples.splice(0, this.firstVisible(t - WINDOW_S));
  }

  firstVisible(tStart) {
    let k = 0;
    while (k < this.samples.length && this.samples[k].t < tStart) k++;
    return k;
  }

  // The editing spans among the visible samples, [t0, t1] each, with short gaps merged.
  editingSpans(first) {
    const spans = [];
    for (let k = first; k < this.samples.length; k++) {
      const s = this.samples[k];
      if (!s.editing) continue;
      const end = this.samples[k + 1]?.t ?? s.t;
      const last = spans[spans.length - 1];
      if (last && s.t - last[1] < EDIT_GAP_S) last[1] = end;
      else spans.push([s.t, end]);
    }
    return spans;
  }

  // The y axis: {y(mm) → px, ticks: [mm], top} for the visible values `mm` (all series).
  yAxis(mm, pad) {
    const h = this.height, span = h - pad.t - pad.b;
    if (this.log) {
      const positive = mm.filter((v) => v > 0);
      const low = Math.max(LOG_FLOOR_MM, 10 ** Math.floor(Math.log10(Math.min(...positive, MIN_TOP_MM))));
      const high = Math.max(10 * low, 10 ** Math.ceil(Math.log10(Math.max(...positive, MIN_TOP_MM))));
      const decades = Math.log10(high / low);
      const ticks = Array.from({ length: decades + 1 }, (_, k) => low * 10 ** k);
      return { top: high, ticks, y: (v) => h - pad.b - Math.log10(Math.max(v, low) / low) / decades * span };
    }
    // The top covers the bulk of the values and the newest ones (what the user watches now).
    const newest = mm.length ? mm[mm.length - 1] : 0;
    const bulk = mm.length ? quantileOf(mm.slice(), RANGE_QUANTILE) : 0;
    const { top, step } = linearScale(Math.max(MIN_TOP_MM, 1.05 * Math.max(bulk, newest)));
    const ticks = [];
    for (let k = 0; k * step <= top + 1e-9; k++) ticks.push(k * step);
    return { top, ticks, y: (v) => h - pad.b - Math.min(v, top) / top * span };
  }

  draw() {
    const g = this.context, w = this.width, h = this.height, pad = { l: 34, r: 6, t: 18, b: 16 };
    g.clearRect(0, 0, w, h);
    const n = this.samples.length;
    this.shown.fill(false);
    this.layout = null;
    this.clipped = 0;
    if (n === 0) return this.finish();
    const tEnd = this.samples[n - 1].t, tStart = tEnd - WINDOW_S, first = this.firstVisible(tStart);

    const mm = [];  // every visible value, mm, in time order per series' samples
    for (let k = first; k < n; k++)
      for (let s = 0; s < SERIES.length; s++) {
        const v = this.samples[k].values[s];
        if (v === null || v === undefined) continue;
        this.shown[s] = true;
        mm.push(1000 * v);
      }
    const axis = this.yAxis(mm, pad), y = axis.y;
    this.top = axis.top;
    const x = (t) => pad.l + (t - tStart) / WINDOW_S * (w - pad.l - pad.r);
    this.layout = { first, tStart, x };

    g.fillStyle = 'rgba(220, 50, 50, 0.35)';
    for (const [t0, t1] of this.editingSpans(first))
      g.fillRect(x(t0), pad.t, Math.max(MIN_SPAN_PX, x(t1) - x(t0)), h - pad.t - pad.b);

    // Grid and axes, labelled in mm.
    g.font = '10px sans-serif';
    g.lineWidth = 1;
    g.textAlign = 'right';
    axis.ticks.forEach((v, k) => {
      const yy = Math.round(y(v)) + 0.5;
      g.strokeStyle = k === 0 ? '#555' : '#2c3038';
      g.beginPath(); g.moveTo(pad.l, yy); g.lineTo(w - pad.r, yy); g.stroke();
      g.fillStyle = '#999';
      g.fillText(tickLabel(v), pad.l - 4, yy + 3);
    });
    g.strokeStyle = '#555';
    g.beginPath(); g.moveTo(pad.l + 0.5, pad.t); g.lineTo(pad.l + 0.5, h - pad.b); g.stroke();
    g.textAlign = 'left';
    g.fillText(this.log ? 'error, mm (log)' : 'error, mm', 4, 10);
    g.fillText(`−${WINDOW_S} s`, pad.l, h - 3);
    g.textAlign = 'right';
    g.fillText('now', w - pad.r, h - 3);

    SERIES.forEach((series, s) => {
      if (!this.shown[s]) return;
      g.strokeStyle = series.colour;
      g.fillStyle = series.colour;
      g.lineWidth = series.width ?? 1.5;
      g.beginPath();
      let drawing = false;  // a null value breaks the line
      for (let k = first; k < n; k++) {
        const v = this.samples[k].values[s];
        if (v === null || v === undefined) { drawing = false; continue; }
        if (drawing) g.lineTo(x(this.samples[k].t), y(1000 * v));
        else g.moveTo(x(this.samples[k].t), y(1000 * v));
        drawing = true;
      }
      g.stroke();
      // Off the top: a small triangle at the top edge says "more than shown here".
      if (this.log) return;
      for (let k = first; k < n; k++) {
        const v = this.samples[k].values[s];
        if (v === null || v === undefined || 1000 * v <= axis.top) continue;
        this.clipped++;
        const xx = x(this.samples[k].t);
        g.beginPath(); g.moveTo(xx - 3, pad.t + 5); g.lineTo(xx + 3, pad.t + 5); g.lineTo(xx, pad.t); g.fill();
      }
    });
    this.drawHover(pad);
    this.finish();
  }

  // The hovered time: a cursor line, and its values in the read-out.
  drawHover(pad) {
    const sample = this.hoveredSample();
    if (!sample) return;
    const g = this.context, xx = Math.round(this.layout.x(sample.t)) + 0.5;
    g.strokeStyle = '#ddd';
    g.lineWidth = 1;
    g.beginPath(); g.moveTo(xx, pad.t); g.lineTo(xx, this.height - pad.b); g.stroke();
  }

  // The visible sample nearest the pointer, or null.
  hoveredSample() {
    if (this.hoverX === null || !this.layout) return null;
    let best = null, bestDistance = Infinity;
    for (let k = this.layout.first; k < this.samples.length; k++) {
      const d = Math.abs(this.layout.x(this.samples[k].t) - this.hoverX);
      if (d < bestDistance) { bestDistance = d; best = this.samples[k]; }
    }
    return best;
  }

  finish() {
    this.legendEntries.forEach((entry, s) => {
      if (entry.hidden === this.shown[s]) entry.hidden = !this.shown[s];
    });
    if (!this.readout) return;
    const sample = this.hoveredSample();
    const text = sample ? this.readoutText(sample) : 'hover the plot for values';
    if (this.readout.textContent !== text) this.readout.textContent = text;
  }

  // "−3.2 s: mean error 0.412 mm · observed error 0.398 mm (editing)".
  readoutText(sample) {
    const last = this.samples[this.samples.length - 1];
    const values = SERIES.map((s, k) => [s.label, sample.values[k]])
      .filter(([, v]) => v !== null && v !== undefined)
      .map(([label, v]) => `${label} ${(1000 * v).toFixed(3)} mm`);
    return `${(sample.t - last.t).toFixed(1)} s: ${values.join(' · ') || 'no error'}${sample.editing ? ' (editing)' : ''}`;
  }
}
