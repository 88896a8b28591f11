// Convergence plot (paper Fig. 7): mean error over time, with the spans when someone was
// editing targets shaded red.
const WINDOW_S = 30;

export class ConvergencePlot {
  constructor(canvas) {
    this.canvas = canvas;
    this.samples = [];  // {t, error (m), editing}
  }

  reset(history) {
    this.samples = history.map(([t, error, editing]) => ({ t, error, editing: !!editing }));
  }

  add(t, error, editing) {
    const last = this.samples[this.samples.length - 1];
    if (last && t <= last.t) return;
    this.samples.push({ t, error: error ?? 0, editing });
    const cutoff = t - 4 * WINDOW_S;
    if (this.samples[0].t < cutoff) this.samples = this.samples.filter((s) => s.t >= cutoff);
  }

  draw() {
    const c = this.canvas, g = c.getContext('2d');
    const w = c.width, h = c.height, pad = { l: 34, r: 4, t: 6, b: 16 };
    g.clearRect(0, 0, w, h);
    if (this.samples.length === 0) return;
    const tEnd = this.samples[this.samples.length - 1].t, tStart = tEnd - WINDOW_S;
    const visible = this.samples.filter((s) => s.t >= tStart);
    const maxMm = Math.max(1, ...visible.map((s) => 1000 * s.error)) * 1.1;
    const x = (t) => pad.l + (t - tStart) / WINDOW_S * (w - pad.l - pad.r);
    const y = (mm) => h - pad.b - mm / maxMm * (h - pad.t - pad.b);

    g.fillStyle = 'rgba(220, 50, 50, 0.35)';
    for (let i = 0; i < visible.length - 1; i++)
      if (visible[i].editing) g.fillRect(x(visible[i].t), pad.t, x(visible[i + 1].t) - x(visible[i].t), h - pad.t - pad.b);

    g.strokeStyle = '#555'; g.fillStyle = '#999'; g.font = '10px sans-serif';
    g.beginPath(); g.moveTo(pad.l, pad.t); g.lineTo(pad.l, h - pad.b); g.lineTo(w - pad.r, h - pad.b); g.stroke();
    g.fillText(maxMm.toFixed(maxMm < 10 ? 1 : 0), 2, pad.t + 8);
    g.fillText('0', 2, h - pad.b);
    g.fillText(`-${WINDOW_S} s`, pad.l, h - 3);
    g.fillText('now', w - pad.r - 20, h - 3);

    g.strokeStyle = '#ff8c1a'; g.lineWidth = 1.5;
    g.beginPath();
    visible.forEach((s, i) => (i ? g.lineTo : g.moveTo).call(g, x(s.t), y(1000 * s.error)));
    g.stroke();
  }
}
