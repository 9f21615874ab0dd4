// The polylines of a `lines` result (/api/lines/*) as one THREE.LineSegments: positions relative to
// the cloud's origin (as the points), one segment per edge of the file, coloured per vertex.
import * as THREE from 'three';
import { getBytes } from './api.js';
import { labelColors, scalarColors } from './colors.js';

// Columns that are ids (one colour each) rather than scalars.
const ID_COLUMNS = new Set(['line_index', 'line_id', 'curve_id']);

export async function loadLines(manifest) {
  const positions = new Float32Array(await getBytes('/api/lines/positions'));
  const segments = new Uint32Array(await getBytes('/api/lines/segments'));
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(positions.length), 3, true));
  geometry.setIndex(new THREE.BufferAttribute(segments, 1));
  const material = new THREE.LineBasicMaterial({ vertexColors: true });
  const lines = new THREE.LineSegments(geometry, material);
  lines.frustumCulled = false;
  return { lines, segmentCount: segments.length / 2, vertexCount: manifest.vertex_count };
}

// Colours the lines by the vertex attribute `name`; returns [lo, hi] for a scalar, null for ids.
export async function colorLines(lines, manifest, name) {
  const a = manifest.attributes.find((x) => x.name === name);
  const values = new Float32Array(await getBytes('/api/lines/attribute', { name }));
  const colors = lines.geometry.getAttribute('color');
  let range = null;
  if (ID_COLUMNS.has(name)) {
    labelColors(Int32Array.from(values), colors.array);
  } else {
    range = a.p98 > a.p02 ? [a.p02, a.p98] : [a.min, a.max];
    scalarColors(values, range[0], range[1], colors.array);
  }
  colors.needsUpdate = true;
  return range;
}
