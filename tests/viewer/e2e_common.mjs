// What the end-to-end tests of `scalespace view` share (view_e2e.mjs, view_stack_e2e.mjs): the
// command line, skipping (exit 77) when playwright-core, Chromium or the bundled page is missing,
// the check counter, and Chromium launched on a closed network with software WebGL.
import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..', '..', 'src', 'scalespace', 'viewer', 'web');
export const SKIP = 77;

// `node SCRIPT CLI WORKDIR [options]`: the CLI, the work folder, the options, option(name, fallback).
export function commandLine() {
  const [cli, work, ...rest] = process.argv.slice(2);
  const option = (name, fallback) => {
    const k = rest.indexOf(name);
    return k >= 0 ? rest[k + 1] : fallback;
  };
  return { cli, work, rest, option };
}

export const chromiumPath = process.env.SCALESPACE_CHROMIUM || '/usr/bin/chromium';

// playwright-core's chromium, or exit SKIP saying what is missing.
export function chromiumOrSkip(cli) {
  let chromium;
  try {
    ({ chromium } = createRequire(path.join(webDir, 'package.json'))('playwright-core'));
  } catch {
    console.log(`SKIP: playwright-core is not installed in ${webDir}/node_modules (run scripts/setup_web.sh)`);
    process.exit(SKIP);
  }
  if (!fs.existsSync(chromiumPath)) {
    console.log(`SKIP: no Chromium at ${chromiumPath} (Debian package chromium; scripts/setup.sh installs it)`);
    process.exit(SKIP);
  }
  if (!fs.existsSync(path.join(path.dirname(cli), 'viewer-page', 'app.js'))) {
    console.log('SKIP: the viewer page was not bundled (no node_modules at build time: run scripts/setup_web.sh, then rebuild)');
    process.exit(SKIP);
  }
  return chromium;
}

// check(ok, what) prints and counts; finish(results, what) prints the figures measured and exits
// 1 when a check failed, else 0 (now: a server's pipe would keep the event loop, and ctest,
// waiting).
export function checks() {
  let failed = 0;
  return {
    check(ok, what) {
      console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
      if (!ok) failed++;
    },
    finish(results, what) {
      console.log(`measured: ${JSON.stringify(results)}`);
      if (failed) {
        console.log(`${failed} check(s) failed`);
        process.exit(1);
      }
      console.log(`${what}: all checks passed`);
      process.exit(0);
    },
  };
}

// Runs the CLI with ARGS and returns its stdout.
export const runner = (cli) => (...args) =>
  execFileSync(cli, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 1 << 30 });

// A fresh profile in WORK each run (launchPersistentContext's folder is Chromium's --user-data-dir).
// A closed network: nothing that would try to reach the outside; software WebGL (no GPU here).
export async function launchChromium(chromium, work) {
  const userDataDir = fs.mkdtempSync(path.join(work, 'chromium-'));
  const browser = await chromium.launchPersistentContext(userDataDir, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 1400, height: 860 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  return { browser, userDataDir };
}

// Opens the viewer's URL in `page` and waits until it is ready (or failed); `errors` collects the
// page's exceptions and `outside` the requests that left the local server (there must be none).
export async function openViewer(page, url) {
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  const outside = [];
  page.on('request', (r) => { if (!r.url().startsWith(url.slice(0, url.indexOf('/?')))) outside.push(r.url()); });
  await page.goto(url);
  await page.waitForFunction(() => window.scalespace && (window.scalespace.ready || window.scalespace.error), null, { timeout: 120000 });
  return { errors, outside };
}
