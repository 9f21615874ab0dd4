// End-to-end test of `scalespace view` on a scale stack and on polylines, in Debian's Chromium
// (headless, driven by playwright-core):
//  - a generated stack (`scalespace scales`) is opened; the scale slider is moved with the keyboard
//    and the quantity changed; every value the page colours by is compared with `scalespace export
//    --scale J` (the stack reader's values, as CSV) and the colours with the colour bar's ends; a
//    point is clicked and its series compared with `scalespace export --point I`;
//  - polylines (`scalespace lines`) are opened over their cloud (`view CLOUD --lines LINES.ply`)
//    and alone (`view LINES.ply`): the page draws as many segments as the file has edges.
//   node view_stack_e2e.mjs CLI WORKDIR [--points N] [--scales M] [--screenshots DIR] [--measure]
// Screenshots (viewer_stack.png, viewer_lines.png, viewer_lines_alone.png) go to WORKDIR unless
// --screenshots names another folder.
// Exit 0: passed; 1: a check failed; 77: skipped (what is missing is printed).
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { checks, chromiumOrSkip, commandLine, launchChromium, openViewer, runner } from './e2e_common.mjs';

const { cli, work, rest, option } = commandLine();
const measure = rest.includes('--measure');
const pointCount = Number(option('--points', measure ? '200000' : '20000'));
const scaleCount = Number(option('--scales', measure ? '20' : '12'));
const screenshots = option('--screenshots', work);  // default: beside the test's files

const chromium = chromiumOrSkip(cli);

const { check, finish } = checks();
const run = runner(cli);

// Columns of a CSV written by `scalespace export` (header names them), as numbers.
function csvColumns(text) {
  const lines = text.trim().split('\n');
  const names = lines[0].split(',');
  const columns = Object.fromEntries(names.map((n) => [n, new Float64Array(lines.length - 1)]));
  for (let r = 1; r < lines.length; ++r) {
    const cells = lines[r].split(',');
    names.forEach((n, c) => { columns[n][r - 1] = Number(cells[c]); });
  }
  return columns;
}
// Float32 values served against the CSV's (printed from the same float32 with 9+ digits).
// With `indices` (the page's drawn points, /api/cloud/indices), served[k] is the value of point
// indices[k].
function sameFloat32(served, expected, indices = null) {
  const n = indices ? indices.length : expected.length;
  if (served.length !== n) return `lengths ${served.length} and ${n}`;
  let differ = 0;
  for (let k = 0; k < n; ++k) {
    const e = expected[indices ? indices[k] : k];
    differ += served[k] !== Math.fround(e) && !(Number.isNaN(served[k]) && Number.isNaN(e));
  }
  return differ === 0 ? '' : `${differ} values differ`;
}
// The edge count in a PLY header.
function plyEdgeCount(file) {
  const head = fs.readFileSync(file).subarray(0, 4096).toString('latin1');
  const m = head.match(/\nelement edge (\d+)\s*\n/);
  return m ? Number(m[1]) : -1;
}

// Starts `scalespace view ARGS`, resolves with its URL; the server is stopped on exit.
const servers = [];
async function startView(args) {
  const server = spawn(cli, ['view', ...args, '--no-browser', '-q'], { stdio: ['ignore', 'pipe', 'inherit'] });
  servers.push(server);
  return new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error('no URL from scalespace view within 60 s')), 60000);
    server.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/scalespace view: (http:\/\/127\.0\.0\.1:\d+\/\?token=[0-9a-f]{32})/);
      if (m) { clearTimeout(timer); resolve(m[1]); }
    });
    server.on('exit', (code) => reject(new Error(`scalespace view exited (${code}) before printing its URL`)));
  });
}
process.on('exit', () => { for (const s of servers) s.kill('SIGTERM'); });

fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const cloud = path.join(work, 'house.ply');
const stack = path.join(work, 'house.stack');
run('generate', 'house', '-n', String(pointCount), '--noise', '0.001', '--seed', '3', '-o', cloud, '-q');
run('scales', cloud, '-o', stack, '--scales', String(scaleCount), '-q');
const torus = path.join(work, 'torus.ply');
const linesFile = path.join(work, 'torus_lines.ply');
if (!measure) {
  run('generate', 'torus', '-n', '20000', '--noise', '0.0001', '--seed', '1', '-o', torus, '-q');
  run('lines', torus, '-o', linesFile, '--scales', '3', '--beta', '3', '-q');  // sparse seeds: a legible picture
}

// As view_e2e.mjs measures it: from the command to the first frame, Chromium's start included.
const t0 = performance.now();
const stackUrl = await startView([stack]);
const urlMs = Math.round(performance.now() - t0);

const { browser, userDataDir } = await launchChromium(chromium, work);
const results = { points: pointCount, scales: scaleCount };
const shot = async (page, name) => { if (screenshots) await page.screenshot({ path: path.join(screenshots, name) }); };

// Opens URL in a fresh tab and waits for the first frame; checks no request leaves the server.
async function openPage(url) {
  const page = await browser.newPage();
  const { errors, outside } = await openViewer(page, url);
  check(!(await page.evaluate(() => window.scalespace.error)), `the page loaded without an error ${await page.evaluate(() => window.scalespace.error || '')}`);
  const idle = () => page.waitForFunction(() => window.scalespace.busy === 0, null, { timeout: 60000 });
  const done = () => {
    check(errors.length === 0, `no page error ${errors.join('; ')}`);
    check(outside.length === 0, `no request left the local server ${outside.join(' ')}`);
  };
  return { page, idle, done };
}

try {
  // --- the stack -------------------------------------------------------------------------------
  results.urlMs = urlMs;
  const { page, idle, done } = await openPage(stackUrl);
  results.commandToFirstFrameMs = Math.round(performance.now() - t0 - (await page.evaluate(() => performance.now() - window.scalespace.firstFrameMs)));
  const manifest = await page.evaluate(() => window.scalespace.manifest);
  check(manifest.source.kind === 'stack' && manifest.stack.scale_count === scaleCount && manifest.stack.point_count === pointCount,
    `manifest: a stack of ${manifest.stack.point_count} points at ${manifest.stack.scale_count} scales`);
  const indices = await page.evaluate(() => Array.from(window.scalespace.indices));
  check(indices.length === manifest.cloud.display_count && new Set(indices).size === indices.length &&
    indices.every((i) => i < pointCount), `the page draws ${indices.length} distinct points of the cloud`);
  const served = async () => Float32Array.from(await page.evaluate(() => Array.from(window.scalespace.stackValues)));
  const exported = new Map();  // scale -> CSV columns of `export --scale`
  const exportScale = (j) => {
    if (!exported.has(j)) {
      const file = path.join(work, `scale${j}.csv`);
      run('export', stack, '--scale', String(j), '-o', file, '-q');
      exported.set(j, csvColumns(fs.readFileSync(file, 'utf8')));
    }
    return exported.get(j);
  };
  const checkShown = async (what) => {
    const q = await page.evaluate(() => window.scalespace.stackQuery);
    const d = sameFloat32(await served(), exportScale(Number(q.scale))[q.quantity], indices);
    check(!d, `${what}: ${q.quantity} at scale ${q.scale} equals export --scale ${q.scale}'s ${d}`);
    // Colours: a value at or below the colour bar's low end is viridis' first colour, at or above
    // its high end the last.
    const c = await page.evaluate(() => {
      const s = window.scalespace, [lo, hi] = s.stackRange.range;
      const col = s.pointsObject.geometry.getAttribute('color').array;
      let bad = 0, ends = 0;
      for (let i = 0; i < s.stackValues.length; ++i) {
        const v = s.stackValues[i];
        const expect = v <= lo ? [68, 1, 84] : v >= hi ? [253, 231, 37] : null;
        if (!expect) continue;
        ends++;
        if (col[3 * i] !== expect[0] || col[3 * i + 1] !== expect[1] || col[3 * i + 2] !== expect[2]) bad++;
      }
      return { bad, ends, bar: document.getElementById('barName').textContent };
    });
    check(c.bad === 0 && c.ends > 0 && c.bar.startsWith(q.quantity),
      `${what}: colours at the bar's ends (${c.ends} points) are viridis' ends, bar "${c.bar}" ${c.bad ? c.bad + ' wrong' : ''}`);
    return q;
  };
  await checkShown('first frame');

  // Scale slider: three steps down with the keyboard.
  await page.focus('#stackScale');
  const before = await page.evaluate(() => window.scalespace.timings.length);
  for (let k = 0; k < 3; ++k) { await page.keyboard.press('ArrowLeft'); await idle(); }
  const level = await page.inputValue('#stackScale');
  await page.waitForFunction((l) => window.scalespace.stackQuery.scale === l && window.scalespace.busy === 0, level);
  await checkShown('scale slider');
  // Quantity selector.
  await page.selectOption('#stackQuantity', 'curv_max');
  await page.waitForFunction(() => window.scalespace.stackQuery.quantity === 'curv_max' && window.scalespace.busy === 0);
  await checkShown('quantity selector');
  await page.selectOption('#stackQuantity', 'curv_mean');
  await page.waitForFunction(() => window.scalespace.stackQuery.quantity === 'curv_mean' && window.scalespace.busy === 0);
  results.sliderMs = (await page.evaluate((n) => window.scalespace.timings.slice(n), before))
    .filter((t) => t.what === 'stack scale slider').map((t) => Math.round(t.ms));

  // Click a point near the middle of the view: its series over the scales.
  const view = await page.locator('#view').boundingBox();
  const k = await page.evaluate(([cx, cy]) => {
    const s = window.scalespace;
    let best = -1, bestD = Infinity;
    for (let i = 0; i < s.count; i += 7) {
      const [x, y] = s.screenPosition(i);
      const d = Math.hypot(x - cx, y - cy);
      if (d < bestD) { bestD = d; best = i; }
    }
    return best;
  }, [view.x + view.width / 2, view.y + view.height / 2]);
  const [px, py] = await page.evaluate((i) => window.scalespace.screenPosition(i), k);
  const tClick = performance.now();
  await page.mouse.click(px, py);
  await page.waitForFunction(() => window.scalespace.series && window.scalespace.busy === 0, null, { timeout: 60000 });
  results.seriesMs = Math.round(performance.now() - tClick);
  const series = await page.evaluate(() => {
    const s = window.scalespace.series;
    return { point: s.point, length: s.length, values: Object.fromEntries(Object.entries(s.values).map(([n, v]) => [n, Array.from(v)])) };
  });
  check(series.length === scaleCount && series.values.curv_mean.length === scaleCount,
    `click at (${px.toFixed(0)}, ${py.toFixed(0)}) picks point ${series.point}: a series of ${series.length} scales`);
  const csv = csvColumns(run('export', stack, '--point', String(series.point), '-q'));
  for (const name of Object.keys(series.values)) {
    const d = sameFloat32(Float32Array.from(series.values[name]), csv[name]);
    check(!d, `series of point ${series.point}: ${name} equals export --point's ${d}`);
  }
  check(await page.evaluate(() => document.getElementById('seriesTitle').textContent.includes('scales')), 'the series plot is titled');
  await shot(page, 'viewer_stack.png');
  results.jsHeapMB = await page.evaluate(() => (performance.memory ? Math.round(performance.memory.usedJSHeapSize / 2 ** 20) : null));
  done();
  await page.close();

  // --- lines -----------------------------------------------------------------------------------
  if (!measure) {
    const edges = plyEdgeCount(linesFile);
    for (const args of [[torus, '--lines', linesFile], [linesFile]]) {
      const lv = await openPage(await startView(args));
      const m = await lv.page.evaluate(() => window.scalespace.manifest);
      const drawn = await lv.page.evaluate(() => window.scalespace.linesSegments);
      const inScene = await lv.page.evaluate(() => window.scalespace.linesObject.isLineSegments && window.scalespace.linesObject.geometry.getIndex().count / 2);
      check(edges > 0 && drawn === edges && inScene === edges && m.lines.segment_count === edges,
        `view ${args.map((a) => path.basename(a)).join(' ')}: ${drawn} segments drawn, the file has ${edges} edges`);
      check(await lv.page.evaluate(() => window.scalespace.linesColorBy === 'scale' && document.getElementById('linesBarName').textContent === 'scale'),
        'the lines are coloured by their scale, with its colour bar');
      if (args.length === 3) {
        // The cloud in muted colours (its normals) under the lines, for the screenshot.
        if (await lv.page.evaluate(() => window.scalespace.manifest.cloud.has_normals)) {
          await lv.page.selectOption('#colorBy', '__normals');
          await lv.idle();
        }
        await shot(lv.page, 'viewer_lines.png');
      } else {
        check(await lv.page.evaluate(() => !window.scalespace.pointsObject.visible), 'lines alone: the vertices are not drawn as points');
        await shot(lv.page, 'viewer_lines_alone.png');
      }
      lv.done();
      await lv.page.close();
    }
  }
} finally {
  await browser.close();
  for (const s of servers) s.kill('SIGTERM');
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
finish(results, 'view stack and lines end-to-end');
