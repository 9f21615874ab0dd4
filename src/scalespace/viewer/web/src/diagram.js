// The persistence diagram (Sec. 2.3.3): one dot per component at (birth scale, death scale) on log
// axes; a click selects the nearest dot's component.
import { viridis } from './colors.js';

export class PersistenceDiagram {
  constructor(canvas, components, scales, onPick) {
    this.canvas = canvas;
    this.components = components;
    this.lo = Math.log(scales[0]);
    this.hi = Math.log(scales[scales.length - 1]);
    if (!(this.hi > this.lo)) this.hi = this.lo + 1;
    this.maxPersistence = components.reduce((m, c) => Math.max(m, c.persistence), 1);
    this.minPersistence = 0;
    this.selected = new Set();
    canvas.addEventListener('click', (e) => {
      const r = canvas.getBoundingClientRect();
      const id = this.pick((e.clientX - r.left) * canvas.width / r.width,
                           (e.clientY - r.top) * canvas.height / r.height);
      if (id >= 0) onPick(id, e.shiftKey);
    });
  }

  position(c) {
    const m = 28, w = this.canvas.width - m - 8, h = this.canvas.height - m - 8;
    const fx = (Math.log(c.birth_scale) - this.lo) / (this.hi - this.lo);
    const fy = (Math.log(c.death_scale) - this.lo) / (this.hi - this.lo);
    return [m + fx * w, 8 + (1 - fy) * h];
  }

  // The component whose dot is nearest to (x, y) within 10 px, among those shown; -1 if none.
  pick(x, y) {
    let best = -1, bestD = 100;
    for (const c of this.components) {
      if (c.persistence < this.minPersistence) continue;
      const [px, py] = this.position(c);
      const d = (px - x) ** 2 + (py - y) ** 2;
      if (d < bestD) { bestD = d; best = c.id; }
    }
    return best;
  }

  draw() {
    const g = this.canvas.getContext('2d');
    const W = this.canvas.width, H = this.canvas.height;
    g.clearRect(0, 0, W, H);
    g.strokeStyle = '#555'; g.fillStyle = '#aab'; g.font = '10px sans-serif';
    const [x0, y0] = this.position({ birth_scale: Math.exp(this.lo), death_scale: Math.exp(this.lo) });
    const [x1, y1] = this.position({ birth_scale: Math.exp(this.hi), death_scale: Math.exp(this.hi) });
    g.beginPath(); g.moveTo(x0, y0); g.lineTo(x1, y1); g.stroke();  // the diagonal: death = birth
    g.strokeRect(x0, y1, x1 - x0, y0 - y1);
    g.fillText('birth scale →', x0 + 4, H - 4);
    g.save(); g.translate(10, y0 - 4); g.rotate(-Math.PI / 2); g.fillText('death scale →', 0, 0); g.restore();
    g.fillText(Math.exp(this.lo).toPrecision(2), x0, y0 + 11);
    g.fillText(Math.exp(this.hi).toPrecision(2), x1 - 24, y0 + 11);
    for (const c of this.components) {
      const [px, py] = this.position(c);
      const shown = c.persistence >= this.minPersistence;
      const [r, gr, b] = viridis(c.persistence / this.maxPersistence);
      g.fillStyle = shown ? `rgb(${r | 0},${gr | 0},${b | 0})` : '#444';
      g.beginPath(); g.arc(px, py, shown ? 3 : 2, 0, 2 * Math.PI); g.fill();
    }
    g.strokeStyle = '#ff5050'; g.lineWidth = 2;
    for (const id of this.selected) {
      const [px, py] = this.position(this.components[id]);
      g.beginPath(); g.arc(px, py, 6, 0, 2 * Math.PI); g.stroke();
    }
    g.lineWidth = 1;
  }
}
