// The brush of Sec. 2.4.3 on screen: a stroke of discs drawn over the view; mask() rasterises it
// so that each projected point is tested in O(1).
export class BrushStroke {
  constructor(container, radius) {
    this.radius = radius;
    this.enabled = false;
    this.onStroke = null;
    this.samples = [];
    this.canvas = document.createElement('canvas');
    Object.assign(this.canvas.style, { position: 'absolute', left: 0, top: 0, width: '100%', height: '100%', pointerEvents: 'none' });
    container.append(this.canvas);
    this.drawing = false;
    container.addEventListener('pointerdown', (e) => {
      if (!this.enabled || e.button !== 0) return;
      this.drawing = true;
      this.samples = [];
      container.setPointerCapture(e.pointerId);
      this.add(e);
    });
    container.addEventListener('pointermove', (e) => { if (this.drawing) this.add(e); });
    container.addEventListener('pointerup', () => {
      if (!this.drawing) return;
      this.drawing = false;
      if (this.onStroke) this.onStroke();
    });
  }

  resize(w, h) { this.canvas.width = w; this.canvas.height = h; }

  add(e) {
    const r = this.canvas.getBoundingClientRect();
    const p = [e.clientX - r.left, e.clientY - r.top];
    const last = this.samples[this.samples.length - 1];
    // Fill the gap from the previous sample, so a fast stroke leaves no holes.
    if (last) {
      const d = Math.hypot(p[0] - last[0], p[1] - last[1]), step = Math.max(1, this.radius() / 2);
      for (let s = step; s < d; s += step) this.samples.push([last[0] + (p[0] - last[0]) * s / d, last[1] + (p[1] - last[1]) * s / d]);
    }
    this.samples.push(p);
    const g = this.canvas.getContext('2d');
    g.fillStyle = 'rgba(255, 80, 80, 0.35)';
    g.beginPath(); g.arc(p[0], p[1], this.radius(), 0, 2 * Math.PI); g.fill();
  }

  mask(w, h) {
    const m = new Uint8Array(w * h), r = this.radius();
    for (const [cx, cy] of this.samples) {
      for (let y = Math.max(0, Math.floor(cy - r)); y <= Math.min(h - 1, Math.ceil(cy + r)); ++y) {
        const dx = Math.sqrt(Math.max(0, r * r - (y - cy) ** 2));
        const x0 = Math.max(0, Math.ceil(cx - dx)), x1 = Math.min(w - 1, Math.floor(cx + dx));
        if (x1 >= x0) m.fill(1, y * w + x0, y * w + x1 + 1);
      }
    }
    return m;
  }

  clear() { this.canvas.getContext('2d').clearRect(0, 0, this.canvas.width, this.canvas.height); }
}
