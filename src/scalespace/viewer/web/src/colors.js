// Colour maps: viridis for scalars (as `scalespace render`), one colour per label id.
const VIRIDIS = [
  [68, 1, 84], [72, 35, 116], [64, 67, 135], [52, 94, 141], [41, 120, 142], [32, 144, 140],
  [34, 167, 132], [68, 190, 112], [121, 209, 81], [189, 222, 38], [253, 231, 37],
];

export function viridis(x) {
  const t = Math.min(1, Math.max(0, Number.isFinite(x) ? x : 0)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(t));
  const f = t - i;
  const a = VIRIDIS[i], b = VIRIDIS[i + 1];
  return [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])];
}

// Scalars -> RGB bytes over [lo, hi].
export function scalarColors(values, lo, hi, out) {
  const lut = new Uint8Array(256 * 3);
  for (let k = 0; k < 256; ++k) lut.set(viridis(k / 255).map(Math.round), 3 * k);
  const scale = hi > lo ? 255 / (hi - lo) : 0;
  for (let i = 0; i < values.length; ++i) {
    let k = (values[i] - lo) * scale;
    k = k > 255 ? 255 : k > 0 ? k | 0 : 0;  // NaN -> 0
    out[3 * i] = lut[3 * k]; out[3 * i + 1] = lut[3 * k + 1]; out[3 * i + 2] = lut[3 * k + 2];
  }
}

// A stable, well-spread colour per id (golden-ratio hues); -1 (no component) is grey.
export function labelColor(id) {
  if (id < 0) return [110, 110, 110];
  const h = (id * 0.618033988749895) % 1;
  const s = 0.65 + 0.3 * ((id * 7) % 3) / 2, v = 0.95 - 0.25 * ((id * 5) % 2);
  const i = Math.floor(h * 6), f = h * 6 - i;
  const p = v * (1 - s), q = v * (1 - f * s), t = v * (1 - (1 - f) * s);
  const rgb = [[v, t, p], [q, v, p], [p, v, t], [p, q, v], [t, p, v], [v, p, q]][i % 6];
  return rgb.map((c) => Math.round(255 * c));
}

export function labelColors(labels, out) {
  const cache = new Map();
  for (let i = 0; i < labels.length; ++i) {
    const id = labels[i];
    let c = cache.get(id);
    if (!c) { c = labelColor(id); cache.set(id, c); }
    out[3 * i] = c[0]; out[3 * i + 1] = c[1]; out[3 * i + 2] = c[2];
  }
}

export function drawColorBar(canvas) {
  const g = canvas.getContext('2d');
  for (let x = 0; x < canvas.width; ++x) {
    const [r, gr, b] = viridis(x / (canvas.width - 1));
    g.fillStyle = `rgb(${r | 0},${gr | 0},${b | 0})`;
    g.fillRect(x, 0, 1, canvas.height);
  }
}
