// Convergence plot (paper Fig. 7): the errors over the last 30 s in mm, one line per series,
// with the spans when someone was editing targets shaded red; a legend names the series
// that have values in the window.
const WINDOW_S = 30;
const MIN_TOP_MM = 1;  // the y axis shows at least 0–1 mm, the paper's goal

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

// The y axis for errors up to `mm`: its top, the smallest 1, 2 or 5 × 10^k at or above `mm`
// (so the scale changes in steps, not with every sample), and the grid step.
function yScale(mm) {
  const decade = 10 ** Math.floor(Math.log10(mm));
  for (const [m, lines] of [[1, 5], [2, 4], [5, 5]]) if (m * decade >= mm) return { top: m * decade, step: m * decade / lines };
  return { top: 10 * decade, step: 2 * decade };
}

export class ConvergencePlot {
  // `legend`: an element that gets one entry per series.
  constructor(canvas, legend) {
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

  draw() {
    const g = this.context, w = this.width, h = this.height, pad = { l: 30, r: 6, t: 18, b: 16 };
    g.clearRect(0, 0, w, h);
    const n = this.samples.length;
    this.shown.fill(false);
    if (n === 0) return this.updateLegend();
    const tEnd = this.samples[n - 1].t, tStart = tEnd - WINDOW_S, first = this.firstVisible(tStart);

    let maxMm = 0;
    for (let k = first; k < n; k++)
      for (let s = 0; s < SERIES.length; s++) {
        const v = this.samples[k].values[s];
        if (v === null || v === undefined) continue;
        this.shown[s] = true;
        maxMm = Math.max(maxMm, 1000 * v);
      }
    const { top, step } = yScale(Math.max(MIN_TOP_MM, 1.05 * maxMm));
    const x = (t) => pad.l + (t - tStart) / WINDOW_S * (w - pad.l - pad.r);
    const y = (mm) => h - pad.b - mm / top * (h - pad.t - pad.b);

    g.fillStyle = 'rgba(220, 50, 50, 0.35)';
    for (let k = first; k < n - 1; k++)
      if (this.samples[k].editing)
        g.fillRect(x(this.samples[k].t), pad.t, x(this.samples[k + 1].t) - x(this.samples[k].t), h - pad.t - pad.b);

    // Grid and axes, labelled in mm.
    g.font = '10px sans-serif';
    g.lineWidth = 1;
    g.textAlign = 'right';
    const decimals = step < 1 ? Math.ceil(-Math.log10(step) - 1e-9) : 0;
    for (let k = 0; k * step <= top + 1e-9; k++) {
      const yy = Math.round(y(k * step)) + 0.5;
      g.strokeStyle = k === 0 ? '#555' : '#2c3038';
      g.beginPath(); g.moveTo(pad.l, yy); g.lineTo(w - pad.r, yy); g.stroke();
      g.fillStyle = '#999';
      g.fillText((k * step).toFixed(decimals), pad.l - 4, yy + 3);
    }
    g.strokeStyle = '#555';
    g.beginPath(); g.moveTo(pad.l + 0.5, pad.t); g.lineTo(pad.l + 0.5, h - pad.b); g.stroke();
    g.textAlign = 'left';
    g.fillText('mm', 4, 9);
    g.fillText(`−${WINDOW_S} s`, pad.l, h - 3);
    g.textAlign = 'right';
    g.fillText('now', w - pad.r, h - 3);

    SERIES.forEach((series, s) => {
      if (!this.shown[s]) return;
      g.strokeStyle = series.colour;
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
    });
    this.updateLegend();
  }

  updateLegend() {
    this.legendEntries.forEach((entry, s) => {
      if (entry.hidden === this.shown[s]) entry.hidden = !this.shown[s];
    });
  }
}
