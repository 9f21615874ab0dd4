// The page of `scalespace view`: draws what the server computes. Every query of Sec. 2.4
// (persistence threshold, scale, brush, similarity) runs in the library on the server; the page
// only turns the answers (per-point labels, rankings) into colours, the diagram and the table.
// A scale stack's quantities (one scale for every point, one point for every scale) and a `lines`
// result's polylines come from the server the same way.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { getBytes, getJson, post, postBytes } from './api.js';
import { drawColorBar, labelColors, scalarColors } from './colors.js';
import { PersistenceDiagram } from './diagram.js';
import { BrushStroke } from './brush.js';
import { colorLines, loadLines } from './lines.js';
import { SeriesPlot } from './series.js';

const $ = (id) => document.getElementById(id);

// Everything the page knows; the end-to-end test (tests/viewer) reads it as window.scalespace.
const state = {
  manifest: null, indices: null, count: 0, positions: null, labels: null, labelsQuery: null,
  components: [], selection: [], lastBrush: null, lastSimilar: null, lastExport: null,
  timings: [], firstFrameMs: null, busy: 0, error: null,
  stackQuery: null, stackValues: null, stackRange: null, series: null,
  linesSegments: 0, linesColorBy: null,
};
window.scalespace = state;

function status(text) { $('status').textContent = text; }
function fail(error) {
  state.error = String(error.message || error);
  status(`error: ${state.error}`);
}
function progress(fraction) { $('progress').firstElementChild.style.width = `${Math.round(100 * fraction)}%`; }

// --- three.js scene: one Points object, redrawn only when something changed -----------------
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: false, powerPreference: 'high-performance' });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1b1d22);
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.screenSpacePanning = true;
const upGroup = new THREE.Group();
scene.add(upGroup);
let points = null;
let lines = null;   // THREE.LineSegments of the lines layer
let marker = null;  // the clicked point (stack series)
let frameWaiters = [];
let frameRequested = false;

function requestRender() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(() => {
    frameRequested = false;
    renderer.render(scene, camera);
    const waiters = frameWaiters;
    frameWaiters = [];
    for (const w of waiters) w();
  });
}
// Resolves once the current state has been drawn (the next frame).
function nextFrame() { return new Promise((resolve) => { frameWaiters.push(resolve); requestRender(); }); }
controls.addEventListener('change', requestRender);

// While the view is dragged, the first INTERACTIVE_POINTS points only: the server sends them
// coarse to fine, so that prefix covers the whole cloud evenly. A frame of a million points takes
// 0.4 s in software WebGL (no GPU), a quarter of them a quarter of that. The whole cloud is drawn
// again when the drag ends.
const INTERACTIVE_POINTS = 250000;
controls.addEventListener('start', () => {
  if (!points || state.count <= INTERACTIVE_POINTS) return;
  points.geometry.setDrawRange(0, INTERACTIVE_POINTS);
});
controls.addEventListener('end', () => {
  if (!points || points.geometry.drawRange.count === Infinity) return;
  points.geometry.setDrawRange(0, Infinity);
  requestRender();
});

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  brush.resize(w, h);
  requestRender();
}

// Rotations that bring the cloud's up axis to three.js' +Y (as `render --up`).
const UP = {
  z: new THREE.Euler(-Math.PI / 2, 0, 0), '-z': new THREE.Euler(Math.PI / 2, 0, 0),
  y: new THREE.Euler(0, 0, 0), '-y': new THREE.Euler(Math.PI, 0, 0),
  x: new THREE.Euler(0, 0, Math.PI / 2), '-x': new THREE.Euler(0, 0, -Math.PI / 2),
};

function resetView() {
  const [lo, hi] = state.manifest.cloud.bounds;
  const radius = Math.max(1e-9, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
  camera.near = distance / 1000;
  camera.far = distance * 10;
  camera.position.set(distance * 0.55, distance * 0.45, distance * 0.7);
  controls.target.set(0, 0, 0);
  camera.updateProjectionMatrix();
  controls.update();
  requestRender();
}

// --- colours ----------------------------------------------------------------------------------
const colorAttribute = () => points.geometry.getAttribute('color');

function showColorBar(name, lo, hi) {
  $('colorbar').classList.toggle('hidden', !name);
  $('barName').textContent = name || '';
  $('barMin').textContent = name ? lo.toPrecision(4) : '';
  $('barMax').textContent = name ? hi.toPrecision(4) : '';
}

async function colorByAttribute(name) {
  const a = state.manifest.cloud.attributes.find((x) => x.name === name);
  const values = new Float32Array(await getBytes('/api/cloud/attribute', { name }));
  scalarColors(values, a.p02, a.p98, colorAttribute().array);
  showColorBar(`${name} (2nd–98th percentile)`, a.p02, a.p98);
}

async function colorByNormals() {
  const n = new Float32Array(await getBytes('/api/cloud/normals'));
  const c = colorAttribute().array;
  for (let i = 0; i < n.length; ++i) c[i] = Math.round(127.5 * (n[i] + 1));
  showColorBar(null);
}

function colorByHeight() {
  const m = new THREE.Matrix4().makeRotationFromEuler(UP[$('upAxis').value]).elements;
  const p = state.positions, count = state.count;
  const h = new Float32Array(count);
  let lo = Infinity, hi = -Infinity;
  for (let i = 0; i < count; ++i) {
    h[i] = m[1] * p[3 * i] + m[5] * p[3 * i + 1] + m[9] * p[3 * i + 2];
    if (h[i] < lo) lo = h[i];
    if (h[i] > hi) hi = h[i];
  }
  scalarColors(h, lo, hi, colorAttribute().array);
  showColorBar('height (up axis, relative)', lo, hi);
}

function colorByLabels() {
  if (!state.labels) return;
  labelColors(state.labels, colorAttribute().array);
  showColorBar(null);
}

// --- stack: one quantity at one scale for every point, latest request wins --------------------
// The robust range of a scale's values: 2nd and 98th percentiles of (at most 65,536 evenly
// spread) finite values.
function robustRange(values) {
  const k = Math.max(1, Math.ceil(values.length / 65536));
  const v = [];
  for (let i = 0; i < values.length; i += k) if (Number.isFinite(values[i])) v.push(values[i]);
  if (v.length === 0) return [0, 0];
  const sorted = Float64Array.from(v).sort();
  const at = (q) => sorted[Math.floor(q * (sorted.length - 1))];
  let lo = at(0.02), hi = at(0.98);
  if (!(hi > lo)) { lo = sorted[0]; hi = sorted[sorted.length - 1]; }
  return [lo, hi];
}

function stackQuery() {
  return { quantity: $('stackQuantity').value, scale: $('stackScale').value };
}

async function colorByStack() {
  const query = stackQuery();
  const values = new Float32Array(await getBytes('/api/stack/values', query));
  const fixed = $('stackRange').value === 'fixed' && state.stackRange && state.stackRange.quantity === query.quantity;
  const [lo, hi] = fixed ? state.stackRange.range : robustRange(values);
  if (!fixed) state.stackRange = { quantity: query.quantity, range: [lo, hi] };
  state.stackValues = values;
  state.stackQuery = query;
  scalarColors(values, lo, hi, colorAttribute().array);
  const t = state.manifest.stack.scales[Number(query.scale)];
  showColorBar(`${query.quantity} at t = ${t.toPrecision(3)}${fixed ? ' (fixed range)' : ''}`, lo, hi);
}

let pendingStack = null;
let stackRunning = false;

// Colours by the stack at the selectors' quantity and scale; `what` names the timing entry.
function showStack(what) {
  pendingStack = { what, start: performance.now() };
  if (!stackRunning) drainStack();
}

async function drainStack() {
  stackRunning = true;
  state.busy++;
  try {
    while (pendingStack) {
      const { what, start } = pendingStack;
      pendingStack = null;
      $('colorBy').value = '__stack';
      await colorByStack();
      colorAttribute().needsUpdate = true;
      await nextFrame();
      state.timings.push({ what, ms: performance.now() - start });
      if (state.series) plotSeries();
    }
  } catch (e) {
    fail(e);
  } finally {
    stackRunning = false;
    state.busy--;
  }
}

// --- stack: a clicked point's series over the scales -------------------------------------------
const raycaster = new THREE.Raycaster();
let seriesPlot = null;

// The display index of the point under the page position (x, y), the nearest to the eye among
// those within 6 pixels of the ray; null when none.
function pickPoint(clientX, clientY) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2((clientX - rect.left) / rect.width * 2 - 1, -(clientY - rect.top) / rect.height * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const distance = camera.position.distanceTo(controls.target);
  raycaster.params.Points.threshold = 6 * 2 * distance * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) / rect.height;
  points.updateMatrixWorld();
  const hits = raycaster.intersectObject(points, false);
  return hits.length ? hits[0].index : null;
}

// Page position of displayed point k (for the end-to-end test's clicks).
function screenPosition(k) {
  points.updateMatrixWorld();
  const p = state.positions;
  const v = new THREE.Vector3(p[3 * k], p[3 * k + 1], p[3 * k + 2]).applyMatrix4(points.matrixWorld).project(camera);
  const rect = renderer.domElement.getBoundingClientRect();
  return [rect.left + (v.x + 1) / 2 * rect.width, rect.top + (1 - v.y) / 2 * rect.height];
}
state.screenPosition = screenPosition;

function plotSeries() {
  const name = $('stackQuantity').value;
  seriesPlot.values = state.series.values[name];
  seriesPlot.name = name;
  seriesPlot.current = Number($('stackScale').value);
  seriesPlot.draw();
}

async function showSeries(k) {
  const point = state.indices[k];  // the cloud's own index
  state.busy++;
  try {
    const names = state.manifest.stack.quantities.map((q) => q.name);
    const m = state.manifest.stack.scale_count;
    const raw = new Float32Array(await getBytes('/api/stack/series', { point, quantities: names.join(',') }));
    const values = {};
    names.forEach((n, q) => { values[n] = raw.subarray(q * m, (q + 1) * m); });
    state.series = { point, length: m, values };
    const p = state.positions;
    marker.geometry.getAttribute('position').array.set([p[3 * k], p[3 * k + 1], p[3 * k + 2]]);
    marker.geometry.getAttribute('position').needsUpdate = true;
    marker.visible = true;
    requestRender();
    $('seriesTitle').textContent = `point ${point.toLocaleString()}: ${m} scales`;
    plotSeries();
  } catch (e) {
    fail(e);
  } finally {
    state.busy--;
  }
}

// A click (not a drag) on the view picks a point when a stack is shown.
let pressed = null;
function onPointerDown(e) { pressed = e.button === 0 ? [e.clientX, e.clientY] : null; }
function onPointerUp(e) {
  if (!pressed || !state.manifest || !state.manifest.stack || brush.enabled) return;
  const moved = Math.hypot(e.clientX - pressed[0], e.clientY - pressed[1]);
  pressed = null;
  if (moved > 4) return;
  const k = pickPoint(e.clientX, e.clientY);
  if (k === null) { status('no point under the click'); return; }
  showSeries(k);
}

async function applyColoring() {
  const mode = $('colorBy').value;
  if (mode === '__stack') { showStack('colour by'); return; }
  if (mode === '__labels') colorByLabels();
  else if (mode === '__normals') await colorByNormals();
  else if (mode === '__height') colorByHeight();
  else await colorByAttribute(mode);
  colorAttribute().needsUpdate = true;
  await nextFrame();
}

// The first frame's colouring (the stack's goes through colorByStack directly: no timing entry).
async function firstColoring() {
  if ($('colorBy').value === '__stack') {
    colorAttribute().needsUpdate = true;
    await nextFrame();
  } else {
    await applyColoring();
  }
}

// --- planes: labels from the server, latest request wins -------------------------------------
let pendingQuery = null;
let running = false;

function describe(query) {
  if ('min_persistence' in query) return `components with persistence ≥ ${query.min_persistence}`;
  if ('level' in query) {
    const t = state.manifest.planes.scales[query.level];
    return `segmentation at scale t = ${t.toPrecision(4)} (level ${query.level})`;
  }
  if (query.components === 'body') return `${state.selection.length} selected components`;
  return `selected components: ${query.components || 'none'}`;
}

// Asks the server for the labels of `query` and shows them; `what` names the timing entry;
// `body` (uint32 component ids) goes with components=body.
function showLabels(query, what, body = null) {
  pendingQuery = { query, what, body, start: performance.now() };
  if (!running) drainQueries();
}

async function drainQueries() {
  running = true;
  state.busy++;
  try {
    while (pendingQuery) {
      const { query, what, body, start } = pendingQuery;
      pendingQuery = null;
      const labels = new Int32Array(body
        ? await postBytes('/api/planes/labels', query, body)
        : await getBytes('/api/planes/labels', query));
      state.labels = labels;
      state.labelsQuery = query;
      state.labelsBody = body;
      $('colorBy').value = '__labels';
      colorByLabels();
      colorAttribute().needsUpdate = true;
      await nextFrame();
      let labelled = 0;
      const ids = new Set();
      for (const l of labels) if (l >= 0) { labelled++; ids.add(l); }
      $('showing').textContent = `${describe(query)}: ${ids.size} components, ${labelled} points`;
      state.timings.push({ what, ms: performance.now() - start });
    }
  } catch (e) {
    fail(e);
  } finally {
    running = false;
    state.busy--;
  }
}

function setSelection(ids) {
  state.selection = [...new Set(ids)];
  diagram.selected = new Set(state.selection);
  diagram.draw();
  const body = $('selectionTable').tBodies[0];
  body.textContent = '';
  for (const id of state.selection.slice(0, 200)) {
    const c = state.components[id];
    const row = body.insertRow();
    for (const v of [c.id, c.birth_level, c.death_level, c.persistence, c.area.toPrecision(3),
      `${c.nx.toFixed(2)} ${c.ny.toFixed(2)} ${c.nz.toFixed(2)} | ${c.offset.toPrecision(4)}`]) {
      row.insertCell().textContent = v;
    }
  }
  // A long selection goes in the body: a URL holds a few thousand characters at most.
  if (state.selection.length > 400) showLabels({ components: 'body' }, 'selection', Uint32Array.from(state.selection));
  else showLabels({ components: state.selection.join(',') }, 'selection');
}

// --- brush: screen-space stroke -> the visible points under it -> rankByBrush on the server ---
// Sec. 2.4.3: the brush selects what is under the stroke on the visible surface. The drawn points'
// view-space depths are rendered to an offscreen target (a depth pass: each pixel keeps its
// front-most point's depth, 24 bits over [near, far]); a point under the stroke is kept only if
// its depth is within brushTolerance of the front-most depth at its own pixel, so a wall seen from
// outside selects that wall and not the one behind it.
const brush = new BrushStroke(view, () => Number($('brushRadius').value));
const DEPTH_LEVELS = 16777215;  // 2^24 - 1
const depthMaterial = new THREE.ShaderMaterial({
  uniforms: { size: { value: 1 }, near: { value: 0.01 }, far: { value: 1000 } },
  vertexShader: `
    uniform float size;
    varying float vDepth;
    void main() {
      vec4 mv = modelViewMatrix * vec4(position, 1.0);
      vDepth = -mv.z;
      gl_Position = projectionMatrix * mv;
      gl_PointSize = size;
    }`,
  fragmentShader: `
    uniform float near, far;
    varying float vDepth;
    void main() {
      float v = floor(clamp((vDepth - near) / (far - near), 0.0, 1.0) * ${DEPTH_LEVELS}.0 + 0.5);
      float r = floor(v / 65536.0);
      float g = floor((v - r * 65536.0) / 256.0);
      float b = v - r * 65536.0 - g * 256.0;
      gl_FragColor = vec4(r / 255.0, g / 255.0, b / 255.0, 1.0);
    }`,
});
let depthTarget = null;

// The front-most view-space depth at each pixel (w x h, row 0 at the top; NaN where no point is
// drawn) of the points as drawn now (same point size, in CSS pixels).
function frontDepths(w, h) {
  if (!depthTarget || depthTarget.width !== w || depthTarget.height !== h) {
    if (depthTarget) depthTarget.dispose();
    depthTarget = new THREE.WebGLRenderTarget(w, h, { depthBuffer: true, generateMipmaps: false });
  }
  points.updateMatrixWorld();
  const pick = new THREE.Points(points.geometry, depthMaterial);
  pick.matrixAutoUpdate = false;
  pick.matrix.copy(points.matrixWorld);
  pick.frustumCulled = false;
  const pickScene = new THREE.Scene();
  pickScene.add(pick);
  depthMaterial.uniforms.size.value = points.material.size;
  depthMaterial.uniforms.near.value = camera.near;
  depthMaterial.uniforms.far.value = camera.far;
  const clear = renderer.getClearColor(new THREE.Color()), clearAlpha = renderer.getClearAlpha();
  const index = points.geometry.getIndex();
  if (index) points.geometry.setIndex(null);
  renderer.setRenderTarget(depthTarget);
  renderer.setClearColor(0x000000, 0);
  renderer.clear(true, true, false);
  renderer.render(pickScene, camera);
  renderer.setRenderTarget(null);
  renderer.setClearColor(clear, clearAlpha);
  if (index) points.geometry.setIndex(index);
  const rgba = new Uint8Array(4 * w * h);
  renderer.readRenderTargetPixels(depthTarget, 0, 0, w, h, rgba);
  const out = new Float32Array(w * h);
  const scale = (camera.far - camera.near) / DEPTH_LEVELS;
  for (let y = 0; y < h; ++y) {
    const row = (h - 1 - y) * w;  // GL rows start at the bottom
    for (let x = 0; x < w; ++x) {
      const q = 4 * (row + x);
      out[y * w + x] = rgba[q + 3] === 0 ? NaN
        : camera.near + ((rgba[q] * 65536 + rgba[q + 1] * 256 + rgba[q + 2]) * scale);
    }
  }
  return out;
}

// How far behind the front-most depth near its pixel a point may lie and still count as visible.
// That depth is the nearest within gap + size / 2 pixels (a drawn point covers size x size
// pixels), so on an oblique surface the point's own neighbours lie nearer by that many pixels'
// worth of depth times the surface's slope (world size of a pixel at depth d: 2 d tan(fov/2) / h);
// slopes up to 4 (surfaces 14 degrees from the line of sight) are allowed, plus two steps of the
// depth encoding.
function brushTolerance(depth, h, gap) {
  const pixel = 2 * depth * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) / h;
  return 4 * (gap + Math.max(1, points.material.size)) * pixel + 2 * (camera.far - camera.near) / DEPTH_LEVELS;
}

// The gaps between drawn points on screen: twice the median distance (pixels) from a point under
// the stroke to the nearest other one (at most 16). Between the sprites of a sparse cloud the
// surface behind shows through; the front depth is the nearest within that many pixels, so that a
// surface hides what lies behind it, holes between its points included. The median is taken over
// at most 2,000 of the points (evenly spread in the list, itself in the server's coarse-to-fine
// order), each searched ring by ring of pixels around it: a dense stroke (a million-point cloud
// puts thousands of points in a few pixels) costs no more than a sparse one.
const GAP_LIMIT = 16, GAP_QUERIES = 2000;
function screenGap(xs, ys) {
  const n = xs.length;
  if (n < 2) return 0;
  const grid = new Map();  // pixel -> the points in it
  for (let i = 0; i < n; ++i) {
    const key = (ys[i] | 0) * 65536 + (xs[i] | 0);
    const list = grid.get(key);
    if (list) list.push(i); else grid.set(key, [i]);
  }
  const queries = Math.min(n, GAP_QUERIES), nearest = new Float32Array(queries);
  for (let q = 0; q < queries; ++q) {
    const i = Math.floor(q * n / queries), px = xs[i] | 0, py = ys[i] | 0;
    let best = GAP_LIMIT;
    const visit = (x, y) => {
      for (const j of grid.get(y * 65536 + x) || []) {
        if (j !== i) best = Math.min(best, Math.hypot(xs[j] - xs[i], ys[j] - ys[i]));
      }
    };
    // Ring r holds the pixels r steps away: none of their points is nearer than r - 1.
    for (let r = 0; r <= GAP_LIMIT && r - 1 < best; ++r) {
      if (r === 0) { visit(px, py); continue; }
      for (let d = -r; d <= r; ++d) {
        visit(px + d, py - r); visit(px + d, py + r);
        if (d > -r && d < r) { visit(px - r, py + d); visit(px + r, py + d); }
      }
    }
    nearest[q] = best;
  }
  nearest.sort();
  return Math.min(GAP_LIMIT, Math.ceil(2 * nearest[queries >> 1]));
}

// View-space depth of displayed point k (for the end-to-end test's reference).
function viewDepth(k) {
  points.updateMatrixWorld();
  const p = state.positions;
  return -new THREE.Vector3(p[3 * k], p[3 * k + 1], p[3 * k + 2]).applyMatrix4(points.matrixWorld).applyMatrix4(camera.matrixWorldInverse).z;
}
state.viewDepth = viewDepth;

// The cloud's own indices of the visible points under the stroke, and (`underStroke`, display
// indices) every drawn point under it whatever its depth.
function brushedIndices() {
  const w = view.clientWidth, h = view.clientHeight;
  const mask = brush.mask(w, h);
  points.updateMatrixWorld();
  const mv = new THREE.Matrix4().multiplyMatrices(camera.matrixWorldInverse, points.matrixWorld).elements;
  const e = new THREE.Matrix4()
    .multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse)
    .multiply(points.matrixWorld).elements;
  const p = state.positions, underStroke = [], xs = [], ys = [], depths = [];
  for (let i = 0; i < state.count; ++i) {
    const x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
    const cw = e[3] * x + e[7] * y + e[11] * z + e[15];
    if (cw <= 0) continue;
    const sx = ((e[0] * x + e[4] * y + e[8] * z + e[12]) / cw * 0.5 + 0.5) * w;
    const sy = (0.5 - (e[1] * x + e[5] * y + e[9] * z + e[13]) / cw * 0.5) * h;
    if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
    if (!mask[(sy | 0) * w + (sx | 0)]) continue;
    underStroke.push(i);
    xs.push(sx);
    ys.push(sy);
    depths.push(-(mv[2] * x + mv[6] * y + mv[10] * z + mv[14]));
  }
  if (underStroke.length === 0) return { indices: new Uint32Array(0), underStroke };
  const front = frontDepths(w, h);
  // Two passes: the gaps of all the points under the stroke (surfaces behind interleave with the
  // front one's, so they look denser than it is), then those of the points found visible.
  let gap = screenGap(xs, ys), visible = [];
  for (let pass = 0; pass < 2; ++pass) {
    const nearby = new Map();  // pixel -> the nearest depth within `gap` pixels
    visible = [];
    for (let c = 0; c < underStroke.length; ++c) {
      const px = xs[c] | 0, py = ys[c] | 0, pixel = py * w + px;
      let f = nearby.get(pixel);
      if (f === undefined) {
        f = Infinity;
        for (let y = Math.max(0, py - gap); y <= Math.min(h - 1, py + gap); ++y) {
          for (let x = Math.max(0, px - gap); x <= Math.min(w - 1, px + gap); ++x) {
            const d = front[y * w + x];
            if (d < f) f = d;  // NaN (nothing drawn) never is
          }
        }
        nearby.set(pixel, f);
      }
      if (depths[c] <= f + brushTolerance(depths[c], h, gap)) visible.push(c);
    }
    if (pass === 0) gap = Math.max(gap, screenGap(visible.map((c) => xs[c]), visible.map((c) => ys[c])));
  }
  const out = visible.map((c) => state.indices[underStroke[c]]);  // the cloud's own indices
  state.brushGap = gap;
  return { indices: Uint32Array.from(out), underStroke };
}

async function onBrushStroke() {
  const start = performance.now();
  const { indices, underStroke } = brushedIndices();
  const selectMs = performance.now() - start;  // the points under the stroke and the depth test
  brush.clear();
  if (indices.length === 0) { status('brush: no point under the stroke'); return; }
  state.busy++;
  try {
    const { matches } = await post('/api/planes/brush', {}, indices);
    state.lastBrush = { indices, matches, underStroke, selectMs, rankMs: performance.now() - start - selectMs };
    if (matches.length === 0) { status(`brush: ${indices.length} points, no component holds them`); return; }
    status(`brush: ${indices.length} points, ${matches.length} components; best ${matches[0].component} ` +
      `(score ${matches[0].score.toPrecision(3)}, overlap ${matches[0].overlap.toPrecision(3)})`);
    setSelection([matches[0].component]);  // as `segment --brush`: the best-ranked component
  } catch (e) {
    fail(e);
  } finally {
    state.busy--;
  }
}

async function onSimilar() {
  if (state.selection.length === 0) { status('similar: select a component first (diagram or brush)'); return; }
  const query = state.selection[0];
  const useBrush = $('domain').value === 'brush';
  if (useBrush && !state.lastBrush) { status('similar: brush a region first, or search the whole cloud'); return; }
  state.busy++;
  const start = performance.now();
  try {
    const { components } = useBrush
      ? await post('/api/planes/similar', { component: query }, state.lastBrush.indices)
      : await post('/api/planes/similar', { component: query, domain: 'all' }, new Uint8Array(0));
    state.lastSimilar = { query, domain: useBrush ? 'brush' : 'all', components, ms: performance.now() - start };
    status(`similar to ${query}: ${components.length} components`);
    setSelection(components);
  } catch (e) {
    fail(e);
  } finally {
    state.busy--;
  }
}

async function onExport(format) {
  if (!state.labelsQuery) { status('export: nothing shown yet'); return; }
  state.busy++;
  try {
    const result = await post('/api/planes/export', { ...state.labelsQuery, format }, state.labelsBody || new Uint8Array(0));
    state.lastExport = { ...result, query: state.labelsQuery, format };
    $('exported').textContent = `written: ${result.path} (${result.labelled} of ${result.point_count} points labelled)`;
  } catch (e) {
    fail(e);
  } finally {
    state.busy--;
  }
}

// --- start-up ----------------------------------------------------------------------------------
let diagram = null;

async function loadPlanes() {
  const p = state.manifest.planes;
  $('planesPanel').classList.remove('hidden');
  const fields = p.component_fields;
  const raw = new Float64Array(await getBytes('/api/planes/components'));
  for (let k = 0; k < p.component_count; ++k) {
    const c = {};
    fields.forEach((f, j) => { c[f] = raw[k * fields.length + j]; });
    state.components.push(c);
  }
  diagram = new PersistenceDiagram($('diagram'), state.components, p.scales, (id, add) =>
    setSelection(add ? [...state.selection, id] : [id]));
  state.diagram = diagram;
  const pers = $('persistence'), scale = $('scale');
  pers.max = String(p.max_persistence);
  pers.value = String(Math.round(p.max_persistence / 2));
  scale.max = String(Math.max(0, p.scales.length - 1));
  scale.value = String(Math.floor(p.scales.length / 2));
  const showPersistence = () => {
    $('persistenceValue').textContent = pers.value;
    diagram.minPersistence = Number(pers.value);
    diagram.draw();
  };
  const showScale = () => { $('scaleValue').textContent = `t = ${p.scales[Number(scale.value)].toPrecision(3)}`; };
  showPersistence();
  showScale();
  pers.addEventListener('input', () => {
    showPersistence();
    showLabels({ min_persistence: pers.value }, 'persistence slider');
  });
  scale.addEventListener('input', () => { showScale(); showLabels({ level: scale.value }, 'scale slider'); });
  $('brush').addEventListener('click', () => {
    const on = !brush.enabled;
    brush.enabled = on;
    controls.enabled = !on;
    $('brush').classList.toggle('on', on);
    view.classList.toggle('brushing', on);
  });
  brush.onStroke = onBrushStroke;
  $('brushRadius').addEventListener('input', () => { $('brushRadiusValue').textContent = `${$('brushRadius').value} px`; });
  $('similar').addEventListener('click', onSimilar);
  $('exportPly').addEventListener('click', () => onExport('ply'));
  $('exportCsv').addEventListener('click', () => onExport('csv'));
  diagram.draw();
}

function fillColorChoices() {
  const select = $('colorBy');
  const add = (value, text) => { const o = document.createElement('option'); o.value = value; o.textContent = text; select.append(o); };
  if (state.manifest.planes) add('__labels', 'plane components');
  if (state.manifest.stack) add('__stack', 'stack quantity (scale slider)');
  if (state.manifest.cloud.has_normals) add('__normals', 'normals (as RGB)');
  add('__height', 'height');
  for (const a of state.manifest.cloud.attributes) add(a.name, a.name);
  select.addEventListener('change', () => applyColoring().catch(fail));
}

// --- lines and stack panels ----------------------------------------------------------------------
async function colorLinesBy(name) {
  const range = await colorLines(lines, state.manifest.lines, name);
  state.linesColorBy = name;
  $('linesBar').classList.toggle('hidden', !range);
  $('linesBarName').textContent = range ? name : `${name} (one colour per id)`;
  $('linesBarMin').textContent = range ? range[0].toPrecision(4) : '';
  $('linesBarMax').textContent = range ? range[1].toPrecision(4) : '';
  requestRender();
}

function setupLines() {
  const m = state.manifest.lines;
  $('linesPanel').classList.remove('hidden');
  $('showLines').classList.remove('hidden');
  $('showLinesLabel').classList.remove('hidden');
  $('linesInfo').textContent = `${m.line_count.toLocaleString()} lines, ${state.linesSegments.toLocaleString()} segments, ${m.vertex_count.toLocaleString()} vertices`;
  const select = $('linesColorBy');
  for (const a of m.attributes) { const o = document.createElement('option'); o.value = a.name; o.textContent = a.name; select.append(o); }
  const names = m.attributes.map((a) => a.name);
  select.value = names.includes('scale') ? 'scale' : names[0];
  select.addEventListener('change', () => colorLinesBy(select.value).catch(fail));
  drawColorBar($('linesBar'));
}

function setupStack() {
  const s = state.manifest.stack;
  $('stackPanel').classList.remove('hidden');
  const quantity = $('stackQuantity');
  for (const q of s.quantities) { const o = document.createElement('option'); o.value = q.name; o.textContent = q.name; o.title = q.description; quantity.append(o); }
  quantity.value = 'curv_mean';
  const scale = $('stackScale');
  scale.max = String(Math.max(0, s.scale_count - 1));
  scale.value = String(Math.floor(s.scale_count / 2));
  const showScale = () => { $('stackScaleValue').textContent = `t = ${s.scales[Number(scale.value)].toPrecision(3)}`; };
  showScale();
  scale.addEventListener('input', () => { showScale(); showStack('stack scale slider'); });
  quantity.addEventListener('change', () => showStack('stack quantity'));
  $('stackRange').addEventListener('change', () => showStack('stack range'));
  seriesPlot = new SeriesPlot($('series'));
  seriesPlot.scales = s.scales;
  state.seriesPlot = seriesPlot;
  const mg = new THREE.BufferGeometry();
  mg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3), 3));
  // A child of the points: state.positions are already in their (centred) frame.
  marker = new THREE.Points(mg, new THREE.PointsMaterial({ size: 12, color: 0xffcc33, sizeAttenuation: false, depthTest: false }));
  marker.renderOrder = 1;
  marker.visible = false;
  marker.frustumCulled = false;
  points.add(marker);
  renderer.domElement.addEventListener('pointerdown', onPointerDown);
  renderer.domElement.addEventListener('pointerup', onPointerUp);
}

async function start() {
  const t0 = performance.now();
  state.manifest = await getJson('/api/manifest');
  const cloud = state.manifest.cloud;
  state.count = cloud.display_count;
  $('source').textContent = `${state.manifest.source.path}\n${cloud.point_count.toLocaleString()} points` +
    (state.count < cloud.point_count ? `, ${state.count.toLocaleString()} drawn, spread evenly (--point-budget)` : '');
  state.indices = new Uint32Array(await getBytes('/api/cloud/indices'));
  status('loading positions…');
  state.positions = new Float32Array(await getBytes('/api/cloud/positions', {}, (got, total) => progress(total ? got / total : 0)));
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(state.positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(3 * state.count), 3, true));
  const [lo, hi] = cloud.bounds;
  geometry.translate(-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -(lo[2] + hi[2]) / 2);
  geometry.boundingSphere = new THREE.Sphere(new THREE.Vector3(), 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
  const material = new THREE.PointsMaterial({ size: Number($('pointSize').value), vertexColors: true, sizeAttenuation: false });
  points = new THREE.Points(geometry, material);
  state.pointsObject = points;
  upGroup.add(points);
  upGroup.rotation.copy(UP.z);
  if (state.manifest.lines) {
    status('loading lines…');
    const loaded = await loadLines(state.manifest.lines);
    lines = loaded.lines;
    lines.geometry.translate(-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -(lo[2] + hi[2]) / 2);
    upGroup.add(lines);
    state.linesSegments = lines.geometry.getIndex().count / 2;
    state.linesObject = lines;
    setupLines();
    await colorLinesBy($('linesColorBy').value);
    if (state.manifest.source.kind === 'lines') $('showPoints').checked = false;
    points.visible = $('showPoints').checked;
  }
  if (state.manifest.stack) setupStack();
  fillColorChoices();
  resize();
  resetView();
  if (state.manifest.stack) {
    $('colorBy').value = '__stack';
    await colorByStack();
  } else if (state.manifest.planes) {
    const query = { min_persistence: String(Math.round(state.manifest.planes.max_persistence / 2)) };
    const labels = new Int32Array(await getBytes('/api/planes/labels', query));
    state.labels = labels;
    state.labelsQuery = query;
    $('colorBy').value = '__labels';
  } else {
    $('colorBy').value = cloud.attributes.length ? cloud.attributes[0].name : cloud.has_normals ? '__normals' : '__height';
  }
  await firstColoring();
  state.firstFrameMs = performance.now();
  state.firstFrameSincePageStart = performance.now() - t0;
  progress(1);
  $('loading').classList.add('hidden');
  status(`first frame after ${(state.firstFrameMs / 1000).toFixed(2)} s`);
  if (state.manifest.planes) await loadPlanes();
  if (state.labelsQuery) $('showing').textContent = describe(state.labelsQuery);
  state.ready = true;
}

$('pointSize').addEventListener('input', () => {
  $('pointSizeValue').textContent = $('pointSize').value;
  if (points) { points.material.size = Number($('pointSize').value); requestRender(); }
});
$('upAxis').addEventListener('change', () => {
  upGroup.rotation.copy(UP[$('upAxis').value]);
  if ($('colorBy').value === '__height') applyColoring().catch(fail);
  resetView();
});
$('resetView').addEventListener('click', resetView);
$('showPoints').addEventListener('change', () => { if (points) { points.visible = $('showPoints').checked; requestRender(); } });
$('showLines').addEventListener('change', () => { if (lines) { lines.visible = $('showLines').checked; requestRender(); } });
window.addEventListener('resize', resize);
drawColorBar($('colorbar'));
start().catch((e) => { fail(e); $('loading').textContent = `error: ${state.error}`; });
