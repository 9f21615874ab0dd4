// One point's series over the scales of a stack (/api/stack/series), as a small line plot: x the
// scale t (log axis when every t > 0, as the stack's default spacing), y the quantity; the dot marks
// the scale slider's scale.
export class SeriesPlot {
  constructor(canvas) {
    this.canvas = canvas;
    this.scales = [];
    this.values = null;  // Float32Array, one per scale
    this.name = '';
    this.current = 0;
  }

  // Canvas position of scale j with value v (for the plot and its tests).
  position(j, v) {
    const { width: w, height: h } = this.canvas;
    const m = { l: 48, r: 10, t: 10, b: 26 };
    const t = this.scales;
    const log = t.every((x) => x > 0);
    const f = (x) => (log ? Math.log(x) : x);
    const x0 = f(t[0]), x1 = f(t[t.length - 1]);
    const x = m.l + (x1 > x0 ? (f(t[j]) - x0) / (x1 - x0) : 0.5) * (w - m.l - m.r);
    const [lo, hi] = this.range();
    const y = h - m.b - (hi > lo ? (v - lo) / (hi - lo) : 0.5) * (h - m.t - m.b);
    return [x, y];
  }

  range() {
    let lo = Infinity, hi = -Infinity;
    for (const v of this.values || []) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!(hi >= lo)) return [0, 1];
    const pad = hi > lo ? 0.05 * (hi - lo) : Math.abs(hi) * 0.05 || 1;
    return [lo - pad, hi + pad];
  }

  draw() {
    const g = this.canvas.getContext('2d');
    const { width: w, height: h } = this.canvas;
    g.clearRect(0, 0, w, h);
    if (!this.values || this.scales.length === 0) return;
    const [lo, hi] = this.range();
    g.strokeStyle = '#3a3e47';
    g.strokeRect(48, 10, w - 58, h - 36);
    g.fillStyle = '#aab';
    g.font = '10px system-ui, sans-serif';
    g.textAlign = 'right';
    g.fillText((hi).toPrecision(3), 45, 16);
    g.fillText((lo).toPrecision(3), 45, h - 26);
    g.textAlign = 'left';
    g.fillText(`t = ${this.scales[0].toPrecision(3)}`, 48, h - 12);
    g.textAlign = 'right';
    g.fillText(`t = ${this.scales[this.scales.length - 1].toPrecision(3)}`, w - 10, h - 12);
    g.textAlign = 'center';
    g.fillText(this.name, (w + 38) / 2, h - 2);
    g.strokeStyle = '#4f9bff';
    g.lineWidth = 1.5;
    g.beginPath();
    this.values.forEach((v, j) => {
      const [x, y] = this.position(j, v);
      if (j === 0) g.moveTo(x, y); else g.lineTo(x, y);
    });
    g.stroke();
    g.fillStyle = '#9fc3ff';
    this.values.forEach((v, j) => {
      const [x, y] = this.position(j, v);
      g.fillRect(x - 1.5, y - 1.5, 3, 3);
    });
    const j = Math.min(this.current, this.values.length - 1);
    const [x, y] = this.position(j, this.values[j]);
    g.fillStyle = '#ffcc33';
    g.beginPath();
    g.arc(x, y, 4, 0, 2 * Math.PI);
    g.fill();
  }
}
