// End-to-end test of `scalespace view` in Debian's Chromium (headless, driven by playwright-core):
// a generated `planes` result is opened, the persistence and scale sliders are moved with the
// keyboard, a region is brushed with the mouse (and a wall hiding other faces: the depth test), a
// dot of the persistence diagram is clicked, a similarity search is run and the result exported;
// every point set the page shows is compared with `scalespace segment` on the same input (same
// plane_id per point), the export with segment's file byte for byte.
//   node view_e2e.mjs CLI WORKDIR [--points N] [--screenshots DIR] [--measure | --cloud-only]
//                     [--point-budget N]
// Exit 0: passed; 1: a check failed; 77: skipped (what is missing is printed).
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { checks, chromiumOrSkip, commandLine, launchChromium, openViewer, runner } from './e2e_common.mjs';

const { cli, work, rest, option } = commandLine();
const pointCount = Number(option('--points', '20000'));
const screenshots = option('--screenshots', null);
const measureOnly = rest.includes('--measure') || rest.includes('--cloud-only');
const cloudOnly = rest.includes('--cloud-only');  // view the generated cloud itself (no planes)

const chromium = chromiumOrSkip(cli);

const { check, finish } = checks();
const run = runner(cli);

// plane_id column of a CSV written by `segment -o X.csv` (header names the columns).
function planeIds(file) {
  const lines = fs.readFileSync(file, 'utf8').trim().split('\n');
  const column = lines[0].split(',').indexOf('plane_id');
  return Int32Array.from(lines.slice(1), (l) => Number(l.split(',')[column]));
}
function sameLabels(a, b) {
  if (a.length !== b.length) return `lengths ${a.length} and ${b.length}`;
  let differ = 0;
  for (let i = 0; i < a.length; ++i) differ += a[i] !== b[i];
  return differ === 0 ? '' : `${differ} points differ`;
}

// Resident memory (MB) of this run's Chromium processes: the renderer (the tab) and the GPU
// process (SwiftShader's WebGL buffers live there), found under the browser process, which is the
// one started with our --user-data-dir.
function chromiumMemory(profile) {
  const rows = execFileSync('ps', ['-eo', 'pid=,ppid=,rss=,args='], { encoding: 'utf8' }).trim().split('\n')
    .map((l) => l.trim().match(/^(\d+)\s+(\d+)\s+(\d+)\s+(.*)$/)).filter(Boolean)
    .map((m) => ({ pid: +m[1], ppid: +m[2], rss: +m[3], args: m[4] }));
  const root = rows.find((r) => r.args.includes(`--user-data-dir=${profile}`) && !r.args.includes('--type='));
  if (!root) return {};
  const tree = new Set([root.pid]);
  for (let grown = true; grown;) {
    grown = false;
    for (const r of rows) if (tree.has(r.ppid) && !tree.has(r.pid)) { tree.add(r.pid); grown = true; }
  }
  const mb = (f) => Math.round(rows.filter((r) => tree.has(r.pid) && f(r)).reduce((a, r) => a + r.rss, 0) / 1024);
  return {
    rendererRssMB: mb((r) => r.args.includes('--type=renderer')),
    gpuRssMB: mb((r) => r.args.includes('--type=gpu-process')),
    chromiumRssMB: mb(() => true),
  };
}

fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(path.join(work, 'exports'), { recursive: true });
const cloud = path.join(work, 'house.ply');
const planes = path.join(work, 'house.planes');
run('generate', 'house', '-n', String(pointCount), '--noise', '0.001', '--seed', '3', '-o', cloud, '-q');
const tPlanes = performance.now();
if (!cloudOnly) run('planes', cloud, '-o', planes, '--scales', measureOnly ? '30' : '16', '-q');
const planesSeconds = (performance.now() - tPlanes) / 1000;

const t0 = performance.now();
const budget = option('--point-budget', null);  // passed on to `view`
const server = spawn(cli, ['view', cloudOnly ? cloud : planes, '--no-browser', '--export-dir', path.join(work, 'exports'), '-q',
  ...(budget ? ['--point-budget', budget] : [])],
  { stdio: ['ignore', 'pipe', 'inherit'] });
process.on('exit', () => server.kill('SIGTERM'));  // whatever happens below, the server stops
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/scalespace view: (http:\/\/127\.0\.0\.1:\d+\/\?token=[0-9a-f]{32})/);
    if (m) resolve(m[1]);
  });
  server.on('exit', (code) => reject(new Error(`scalespace view exited (${code}) before printing its URL`)));
  const timer = setTimeout(() => reject(new Error('no URL from scalespace view within 60 s')), 60000);
  server.stdout.on('data', () => { if (/token=[0-9a-f]{32}/.test(out)) clearTimeout(timer); });
});
const tUrl = performance.now() - t0;

const { browser, userDataDir } = await launchChromium(chromium, work);
const results = { points: pointCount, planesSeconds: Number(planesSeconds.toFixed(1)) };
try {
  const page = browser.pages()[0] || await browser.newPage();
  const { errors, outside } = await openViewer(page, url);
  results.urlMs = Math.round(tUrl);
  results.firstFrameMs = Math.round(await page.evaluate(() => window.scalespace.firstFrameMs));
  results.commandToFirstFrameMs = Math.round(performance.now() - t0 - (await page.evaluate(() => performance.now() - window.scalespace.firstFrameMs)));
  check(!(await page.evaluate(() => window.scalespace.error)), 'the page loaded without an error');
  const manifest = await page.evaluate(() => window.scalespace.manifest);
  const idle = () => page.waitForFunction(() => window.scalespace.busy === 0, null, { timeout: 60000 });
  const labels = async () => Int32Array.from(await page.evaluate(() => Array.from(window.scalespace.labels)));
  // The page's arrays follow its drawn points (/api/cloud/indices, coarse to fine); a whole-cloud
  // array (segment's plane_id, in input order) is compared at the same points.
  const drawn = await page.evaluate(() => Array.from(window.scalespace.indices));
  const drawnOrder = (whole) => Int32Array.from(drawn, (i) => whole[i]);
  const shot = async (name) => { if (screenshots) await page.screenshot({ path: path.join(screenshots, name) }); };

  if (cloudOnly) {
    // Point size and colour changes: the cloud-only measurements.
    const t1 = await page.evaluate(async () => {
      const s = performance.now();
      const select = document.getElementById('colorBy');
      select.value = '__height';
      select.dispatchEvent(new Event('change'));
      await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
      return performance.now() - s;
    });
    results.recolorMs = Math.round(t1);
    results.displayCount = manifest.cloud.display_count;
  }
  // Persistence slider: a few key presses down from its start, then the labels against segment.
  if (!cloudOnly) await page.focus('#persistence');
  const before = await page.evaluate(() => window.scalespace.timings.length);
  for (let k = 0; k < 3 && !cloudOnly; ++k) { await page.keyboard.press('ArrowLeft'); await idle(); }
  if (!cloudOnly) {
  const persistence = Number(await page.inputValue('#persistence'));
  await page.waitForFunction((p) => window.scalespace.labelsQuery && window.scalespace.labelsQuery.min_persistence === String(p) && window.scalespace.busy === 0, persistence);
  if (!measureOnly) {
    run('segment', planes, '--min-persistence', String(persistence), '-o', path.join(work, 'pers.csv'), '-q');
    const d = sameLabels(await labels(), drawnOrder(planeIds(path.join(work, 'pers.csv'))));
    check(!d, `persistence slider at ${persistence}: same labels as segment --min-persistence ${persistence} ${d}`);
  }
  await shot('viewer_persistence.png');

  // Scale slider.
  await page.focus('#scale');
  for (let k = 0; k < 3; ++k) { await page.keyboard.press('ArrowLeft'); await idle(); }
  const level = Number(await page.inputValue('#scale'));
  await page.waitForFunction((l) => window.scalespace.labelsQuery && window.scalespace.labelsQuery.level === String(l) && window.scalespace.busy === 0, level);
  const t = manifest.planes.scales[level];
  if (!measureOnly) {
    run('segment', planes, '--scale', String(t), '-o', path.join(work, 'scale.csv'), '-q');
    const d = sameLabels(await labels(), drawnOrder(planeIds(path.join(work, 'scale.csv'))));
    check(!d, `scale slider at level ${level} (t = ${t}): same labels as segment --scale ${t} ${d}`);
  }
  await shot('viewer_scale.png');
  const timings = await page.evaluate((n) => window.scalespace.timings.slice(n), before);
  results.sliderMs = timings.map((x) => Math.round(x.ms));
  }

  if (!measureOnly) {
    // Diagram: click the dot of the most persistent component; it becomes the selection.
    await page.focus('#persistence');
    await page.keyboard.press('Home');
    await idle();
    const comps = await page.evaluate(() => window.scalespace.components);
    const top = comps.reduce((a, b) => (b.persistence > a.persistence ? b : a));
    const box = await page.locator('#diagram').boundingBox();
    const dot = await page.evaluate((c) => window.scalespace.diagram.position(c), top);
    const canvasSize = await page.evaluate(() => [document.getElementById('diagram').width, document.getElementById('diagram').height]);
    await page.mouse.click(box.x + dot[0] * box.width / canvasSize[0], box.y + dot[1] * box.height / canvasSize[1]);
    await page.waitForFunction(() => window.scalespace.labelsQuery && 'components' in window.scalespace.labelsQuery && window.scalespace.busy === 0);
    const picked = await page.evaluate(() => window.scalespace.selection);
    check(picked.length === 1 && comps[picked[0]].persistence === top.persistence,
      `diagram click selects a component of the largest persistence ${top.persistence} (got ${picked})`);

    // Brush: a stroke across the middle of the view.
    await page.click('#brush');
    const view = await page.locator('#view').boundingBox();
    const cx = view.x + view.width / 2, cy = view.y + view.height / 2;
    await page.mouse.move(cx - 60, cy - 10);
    await page.mouse.down();
    for (let k = 0; k <= 12; ++k) await page.mouse.move(cx - 60 + 10 * k, cy - 10 + 2 * k);
    await page.mouse.up();
    await page.waitForFunction(() => window.scalespace.lastBrush && window.scalespace.busy === 0, null, { timeout: 60000 });
    await page.click('#brush');
    const brushed = await page.evaluate(() => Array.from(window.scalespace.lastBrush.indices));
    const matches = await page.evaluate(() => window.scalespace.lastBrush.matches);
    check(brushed.length > 0 && matches.length > 0, `brush: ${brushed.length} points, ${matches.length} components`);
    fs.writeFileSync(path.join(work, 'brush.txt'), brushed.join('\n'));
    const ranking = run('segment', planes, '--brush', path.join(work, 'brush.txt'), '-o', path.join(work, 'brush.csv'))
      .trim().split('\n').slice(1).map((l) => Number(l.split(',')[0]));
    check(JSON.stringify(ranking) === JSON.stringify(matches.map((m) => m.component)),
      `brush ranking equals segment --brush's (${ranking.slice(0, 5)}...)`);
    const db = sameLabels(await labels(), drawnOrder(planeIds(path.join(work, 'brush.csv'))));
    check(!db, `brush: the best component's points equal segment --brush's ${db}`);
    await shot('viewer_brush.png');

    // Similarity search from the brushed component, in the whole cloud.
    await page.click('#similar');
    await page.waitForFunction(() => window.scalespace.lastSimilar && window.scalespace.busy === 0);
    const similar = await page.evaluate(() => window.scalespace.lastSimilar);
    fs.writeFileSync(path.join(work, 'all.txt'), Array.from({ length: pointCount }, (_, i) => i).join('\n'));
    run('segment', planes, '--similar', String(similar.query), '--within', path.join(work, 'all.txt'), '-o', path.join(work, 'similar.csv'), '-q');
    const ds = sameLabels(await labels(), drawnOrder(planeIds(path.join(work, 'similar.csv'))));
    check(!ds, `similar to ${similar.query}: ${similar.components.length} components, same points as segment --similar ${ds}`);
    await shot('viewer_similar.png');

    // Export of what is shown (the similar components): byte for byte segment's file.
    await page.click('#exportCsv');
    await page.waitForFunction(() => window.scalespace.lastExport && window.scalespace.busy === 0);
    const exported = await page.evaluate(() => window.scalespace.lastExport.path);
    check(path.dirname(exported) === path.join(work, 'exports'), `export written to the export folder: ${exported}`);
    check(fs.readFileSync(exported).equals(fs.readFileSync(path.join(work, 'similar.csv'))),
      'the exported CSV is byte for byte segment --similar\'s');
  }
  if (!measureOnly) {
    // Brush depth test (Sec. 2.4.3: the components under the stroke, on the visible surface). A
    // place is chosen where one face of the house (gt_face) covers a 40 x 40 pixel cell entirely
    // and another face lies behind it (a wall seen from outside, the opposite wall behind): a
    // stroke there must select the front face's points under the stroke and none of the hidden
    // face's, which the stroke's screen footprint covers too.
    const plan = await page.evaluate(async () => {
      const s = window.scalespace, token = new URLSearchParams(location.search).get('token');
      const face = new Float32Array(await (await fetch(`/api/cloud/attribute?name=gt_face&token=${token}`)).arrayBuffer());
      s.gtFace = face;
      const canvas = document.querySelector('#view canvas').getBoundingClientRect();
      const [lo, hi] = s.manifest.cloud.bounds;
      const radius = 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
      const C = 40, B = 8;  // cell and block sizes (pixels)
      const cells = new Map();
      for (let k = 0; k < s.count; ++k) {
        const [x, y] = s.screenPosition(k);
        const cx = Math.floor((x - canvas.left) / C), cy = Math.floor((y - canvas.top) / C);
        if (cx < 1 || cy < 1 || (cx + 2) * C > canvas.width || (cy + 2) * C > canvas.height) continue;
        const key = cy * 10000 + cx;
        if (!cells.has(key)) cells.set(key, { cx, cy, pts: [] });
        cells.get(key).pts.push([k, x - canvas.left, y - canvas.top, s.viewDepth(k), face[k]]);
      }
      let best = null;
      for (const cell of cells.values()) {
        // Front face: the nearest point's; it must be the front-most in every 8 x 8 block.
        const front = cell.pts.reduce((a, b) => (b[3] < a[3] ? b : a))[4];
        const blocks = new Map();
        for (const q of cell.pts) {
          const b = Math.floor((q[2] - cell.cx * C) / B) * 100 + Math.floor((q[1] - cell.cy * C) / B);
          if (!blocks.has(b) || blocks.get(b)[3] > q[3]) blocks.set(b, q);
        }
        if (blocks.size < (C / B) ** 2) continue;
        if ([...blocks.values()].some((q) => q[4] !== front)) continue;
        const frontMax = Math.max(...cell.pts.filter((q) => q[4] === front).map((q) => q[3]));
        const hidden = cell.pts.filter((q) => q[4] !== front && q[3] > frontMax + 0.05 * radius);
        if (!best || hidden.length > best.hidden) best = { x: canvas.left + (cell.cx + 0.5) * C, y: canvas.top + (cell.cy + 0.5) * C, front, hidden: hidden.length, radius };
      }
      return best;
    });
    check(plan && plan.hidden >= 20, `depth test: a place where gt_face ${plan && plan.front} hides ${plan && plan.hidden} points of other faces`);
    if (plan) {
      await page.evaluate(() => { window.scalespace.lastBrush = null; });
      await page.click('#brush');
      await page.mouse.move(plan.x - 4, plan.y);
      await page.mouse.down();
      for (let k = 0; k <= 4; ++k) await page.mouse.move(plan.x - 4 + 2 * k, plan.y);
      await page.mouse.up();
      await page.waitForFunction(() => window.scalespace.lastBrush && window.scalespace.busy === 0, null, { timeout: 60000 });
      await page.click('#brush');
      const r = await page.evaluate(async (plan) => {
        const s = window.scalespace, token = new URLSearchParams(location.search).get('token');
        const drawnAt = new Map(Array.from(s.indices, (i, k) => [i, k]));  // cloud index -> drawn
        const selected = new Set(Array.from(s.lastBrush.indices, (i) => drawnAt.get(i)));
        const under = s.lastBrush.underStroke;
        const frontMax = Math.max(...under.filter((k) => s.gtFace[k] === plan.front).map((k) => s.viewDepth(k)));
        const isHidden = (k) => s.gtFace[k] !== plan.front && s.viewDepth(k) > frontMax + 0.05 * plan.radius;
        const out = {
          selectMs: Math.round(s.lastBrush.selectMs), rankMs: Math.round(s.lastBrush.rankMs), gap: s.brushGap,
          under: under.length, selected: selected.size,
          frontUnder: under.filter((k) => s.gtFace[k] === plan.front).length,
          frontSelected: under.filter((k) => s.gtFace[k] === plan.front && selected.has(k)).length,
          hiddenUnder: under.filter(isHidden).length,
          hiddenSelected: under.filter((k) => isHidden(k) && selected.has(k)).length,
          hiddenFaces: [...new Set(under.filter(isHidden).map((k) => s.gtFace[k]))],
          components: [],
        };
        // The share of each ranked component's points on the hidden faces, for the page's ranking
        // and for the one of every point under the stroke (no depth test).
        const share = async (matches) => {
          const list = [];
          for (const m of matches) {
            const labels = new Int32Array(await (await fetch(`/api/planes/labels?components=${m.component}&token=${token}`)).arrayBuffer());
            let all = 0, hidden = 0;
            labels.forEach((l, k) => { if (l >= 0) { all++; hidden += out.hiddenFaces.includes(s.gtFace[k]); } });
            list.push({ component: m.component, hidden: Number((hidden / Math.max(1, all)).toFixed(3)), front: labels.some((l, k) => l >= 0 && s.gtFace[k] === plan.front) });
          }
          return list;
        };
        out.components = await share(s.lastBrush.matches);
        const everything = Uint32Array.from(under, (k) => s.indices[k]);
        const noDepth = await (await fetch(`/api/planes/brush?token=${token}`, { method: 'POST', body: everything })).json();
        out.withoutDepthTest = await share(noDepth.matches);
        return out;
      }, plan);
      console.log(`     depth test: ${JSON.stringify(r)}`);
      check(r.hiddenUnder >= 20, `depth test: the stroke covers ${r.hiddenUnder} points of hidden faces ${r.hiddenFaces} on screen`);
      check(r.hiddenSelected === 0, `depth test: none of them is selected (${r.hiddenSelected})`);
      check(r.frontSelected >= 0.9 * r.frontUnder && r.frontSelected > 0,
        `depth test: the front face ${plan.front}'s points under the stroke are selected (${r.frontSelected} of ${r.frontUnder})`);
      check(r.components.length > 0 && r.components[0].front && r.components[0].hidden < 0.5,
        `depth test: the best component lies on the front face (${JSON.stringify(r.components[0])})`);
      check(r.components.every((c) => c.hidden < 1),
        `depth test: no ranked component lies entirely on the hidden faces (${JSON.stringify(r.components)})`);
      check(r.withoutDepthTest.some((c) => c.hidden === 1),
        `depth test: without it, the stroke would rank components lying entirely on hidden faces (${JSON.stringify(r.withoutDepthTest.filter((c) => c.hidden === 1))})`);
      await shot('viewer_brush_depth.png');
    }
  }
  if (!measureOnly) {
    // Colour by an attribute: the colour bar names it with its range.
    await page.selectOption('#colorBy', 'gt_face');
    await page.waitForFunction(() => document.getElementById('barName').textContent.startsWith('gt_face'));
    check(true, 'colour by the attribute gt_face, with its colour bar');
    await page.selectOption('#upAxis', 'z');
    await shot('viewer_attribute.png');
  }
  if (measureOnly) {
    // Orbiting: 20 mouse moves with the left button, each waited until two frames are drawn; the
    // mean time per frame (headless Chromium's frames come at most every 16.7 ms).
    const view = await page.locator('#view').boundingBox();
    const x0 = view.x + view.width / 2, y0 = view.y + view.height / 2;
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    const start = performance.now();
    for (let k = 1; k <= 20; ++k) {
      await page.mouse.move(x0 + 8 * k, y0 + 2 * k);
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    }
    await page.mouse.up();
    results.orbitFrameMs = Math.round((performance.now() - start) / 40);
  }
  results.jsHeapMB = await page.evaluate(() => (performance.memory ? Math.round(performance.memory.usedJSHeapSize / 2 ** 20) : null));
  Object.assign(results, chromiumMemory(userDataDir));
  check(errors.length === 0, `no page error ${errors.join('; ')}`);
  check(outside.length === 0, `no request left the local server ${outside.join(' ')}`);
} finally {
  await browser.close();
  server.kill('SIGTERM');
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
finish(results, 'view end-to-end');
