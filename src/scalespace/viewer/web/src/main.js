// The page of `scalespace view`: draws what the server computes. Every query of Sec. 2.4
// (persistence threshold, scale, brush, similarity) runs in the library on the server; the page
// only turns the answers (per-point labels, rankings) into colours, the diagram and the table.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { getBytes, getJson, post, postBytes } from './api.js';
import { drawColorBar, labelColors, scalarColors } from './colors.js';
import { PersistenceDiagram } from './diagram.js';
import { BrushStroke } from './brush.js';

const $ = (id) => document.getElementById(id);

// Everything the page knows; the end-to-end test (tests/viewer) reads it as window.scalespace.
const state = {
  manifest: null, step: 1, count: 0, positions: null, labels: null, labelsQuery: null,
  components: [], selection: [], lastBrush: null, lastSimilar: null, lastExport: null,
  timings: [], firstFrameMs: null, busy: 0, error: null,
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

// While the view is dragged, every k-th point only (at most INTERACTIVE_POINTS): a frame of a
// million points takes 0.4 s in software WebGL (no GPU), a quarter of them a quarter of that. The
// whole cloud is drawn again when the drag ends.
const INTERACTIVE_POINTS = 250000;
let interactionIndex = null;
controls.addEventListener('start', () => {
  if (!points || state.count <= INTERACTIVE_POINTS) return;
  if (!interactionIndex) {
    const k = Math.ceil(state.count / INTERACTIVE_POINTS);
    interactionIndex = new THREE.BufferAttribute(new Uint32Array(Math.ceil(state.count / k)).map((_, i) => i * k), 1);
  }
  points.geometry.setIndex(interactionIndex);
});
controls.addEventListener('end', () => {
  if (!points || !points.geometry.getIndex()) return;
  points.geometry.setIndex(null);
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

async function applyColoring() {
  const mode = $('colorBy').value;
  if (mode === '__labels') colorByLabels();
  else if (mode === '__normals') await colorByNormals();
  else if (mode === '__height') colorByHeight();
  else await colorByAttribute(mode);
  colorAttribute().needsUpdate = true;
  await nextFrame();
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

// --- brush: screen-space stroke -> the cloud's point indices -> rankByBrush on the server ------
const brush = new BrushStroke(view, () => Number($('brushRadius').value));

function brushedIndices() {
  const w = view.clientWidth, h = view.clientHeight;
  const mask = brush.mask(w, h);
  points.updateMatrixWorld();
  const e = new THREE.Matrix4()
    .multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse)
    .multiply(points.matrixWorld).elements;
  const p = state.positions, out = [];
  for (let i = 0; i < state.count; ++i) {
    const x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
    const cw = e[3] * x + e[7] * y + e[11] * z + e[15];
    if (cw <= 0) continue;
    const sx = ((e[0] * x + e[4] * y + e[8] * z + e[12]) / cw * 0.5 + 0.5) * w;
    const sy = (0.5 - (e[1] * x + e[5] * y + e[9] * z + e[13]) / cw * 0.5) * h;
    if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
    if (mask[(sy | 0) * w + (sx | 0)]) out.push(i * state.step);  // the cloud's own index
  }
  return Uint32Array.from(out);
}

async function onBrushStroke() {
  const indices = brushedIndices();
  brush.clear();
  if (indices.length === 0) { status('brush: no point under the stroke'); return; }
  state.busy++;
  try {
    const { matches } = await post('/api/planes/brush', {}, indices);
    state.lastBrush = { indices, matches };
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
  if (state.manifest.cloud.has_normals) add('__normals', 'normals (as RGB)');
  add('__height', 'height');
  for (const a of state.manifest.cloud.attributes) add(a.name, a.name);
  select.addEventListener('change', () => applyColoring().catch(fail));
}

async function start() {
  const t0 = performance.now();
  state.manifest = await getJson('/api/manifest');
  const cloud = state.manifest.cloud;
  state.step = cloud.display_step;
  state.count = cloud.display_count;
  $('source').textContent = `${state.manifest.source.path}\n${cloud.point_count.toLocaleString()} points` +
    (state.step > 1 ? `, every ${state.step}th drawn (${state.count.toLocaleString()}; --point-budget)` : '');
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
  upGroup.add(points);
  upGroup.rotation.copy(UP.z);
  fillColorChoices();
  resize();
  resetView();
  if (state.manifest.planes) {
    const query = { min_persistence: String(Math.round(state.manifest.planes.max_persistence / 2)) };
    const labels = new Int32Array(await getBytes('/api/planes/labels', query));
    state.labels = labels;
    state.labelsQuery = query;
    $('colorBy').value = '__labels';
  } else {
    $('colorBy').value = cloud.attributes.length ? cloud.attributes[0].name : cloud.has_normals ? '__normals' : '__height';
  }
  await applyColoring();
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
window.addEventListener('resize', resize);
drawColorBar($('colorbar'));
start().catch((e) => { fail(e); $('loading').textContent = `error: ${state.error}`; });
