// Browser end-to-end test of the operator page's map view.
//
// Under ctest (make test) it starts its own bridge + server and takes one scan; the page must
// then show every point of the map. Against an already running server instead:
//   SCANPLAN_URL        e.g. http://127.0.0.1:8080
//   SCANPLAN_TOKEN      a viewer or operator token
//   SCANPLAN_MIN_POINTS points the map must show (default 1000)
//   SCREENSHOT_DIR      where map_view.png is written (default: the OS temp dir)
//   CHROMIUM            browser binary (default /usr/bin/chromium)
// Run: node --test tests/browser/   (playwright-core comes from web/node_modules: `npm ci` in web/ first)
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startStack, scanAndWait } from '../support/stack.mjs';
import { canvasCoverage, frames } from '../support/browser.mjs';

const require = createRequire(new URL('../../web/package.json', import.meta.url));

let BASE = (process.env.SCANPLAN_URL || '').replace(/\/+$/, '');
let TOKEN = process.env.SCANPLAN_TOKEN || '';
let MIN_POINTS = Number(process.env.SCANPLAN_MIN_POINTS || 1000);
const SHOT_DIR = process.env.SCREENSHOT_DIR || tmpdir();
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const WAIT_MS = 60000;

const CHROMIUM_ARGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  // WebGL without a GPU: Chromium is phasing out the implicit SwiftShader fallback; allow it explicitly.
  '--enable-unsafe-swiftshader',
];

let stack;
before(async () => {
  if (BASE) return;
  stack = await startStack();
  const session = await scanAndWait(stack, 1);
  BASE = stack.url;
  TOKEN = stack.token;
  MIN_POINTS = session.points;
});
after(async () => {
  if (stack) await stack.stop();
});

async function withPage(fn) {
  const { chromium } = require('playwright-core');
  const profile = mkdtempSync(join(tmpdir(), 'scanplan-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport: { width: 1366, height: 768 },
    deviceScaleFactor: 1,
    timeout: 30000,
  });
  try {
    const page = context.pages()[0] ?? (await context.newPage());
    return await fn(page);
  } finally {
    await context.close().catch(() => {});
    rmSync(profile, { recursive: true, force: true });
  }
}

test('map view shows the coloured point cloud', { timeout: 150000 }, async (t) => {
  await withPage(async (page) => {
    const pageErrors = [];
    const consoleErrors = [];
    page.on('pageerror', (e) => pageErrors.push(String(e && e.stack ? e.stack : e)));
    page.on('console', (m) => {
      if (m.type() === 'error') consoleErrors.push(m.text());
    });

    const res = await page.goto(`${BASE}/?token=${encodeURIComponent(TOKEN)}`, { waitUntil: 'load', timeout: 30000 });
    assert.ok(res && res.ok(), `page load failed: HTTP ${res && res.status()}`);

    // The token must not stay in the address bar, but must be kept for the session.
    assert.ok(!page.url().includes('token='), `token left in the URL: ${page.url()}`);
    assert.equal(await page.evaluate(() => sessionStorage.getItem('scanplan.token')), TOKEN);

    try {
      // Done when enough points are drawn; a rejected token cannot get better, so stop waiting then.
      await page.waitForFunction(
        (min) => Number(document.body.dataset.points || 0) >= min || document.body.dataset.error === 'token missing or wrong',
        MIN_POINTS,
        { timeout: WAIT_MS, polling: 250 },
      );
      const err = await page.evaluate(() => document.body.dataset.error);
      if (err) throw new Error(err);
    } catch (e) {
      const ds = await page.evaluate(() => ({ ...document.body.dataset, status: document.getElementById('status-message')?.textContent }));
      await page.screenshot({ path: join(SHOT_DIR, 'map_view.png') }).catch(() => {});
      throw new Error(`map view did not reach ${MIN_POINTS} points (${e.message.split('\n')[0]}): ${JSON.stringify(ds)}; page errors: ${pageErrors.join(' | ')}; console errors: ${consoleErrors.join(' | ')}`);
    }

    const ds = await page.evaluate(() => ({ ...document.body.dataset }));
    assert.equal(ds.state, 'live', `state: ${JSON.stringify(ds)}`);
    assert.ok(Number(ds.scans) >= 1, `scans: ${ds.scans}`);
    assert.equal(ds.error || '', '', `error shown: ${ds.error}`);

    // Let a frame or two render after the geometry arrived.
    await frames(page);

    const pix = await canvasCoverage(page);
    assert.ok(!pix.error, pix.error);
    t.diagnostic(`canvas ${pix.width}x${pix.height}: ${(pix.fraction * 100).toFixed(2)}% non-background pixels, ${pix.colours} colour bins, background rgb(${pix.bg})`);
    assert.ok(pix.width >= 300 && pix.height >= 200, `canvas too small: ${pix.width}x${pix.height}`);
    assert.ok(pix.fraction > 0.005, `canvas looks blank: only ${(pix.fraction * 100).toFixed(3)}% of pixels differ from the background`);

    mkdirSync(SHOT_DIR, { recursive: true });
    await page.screenshot({ path: join(SHOT_DIR, 'map_view.png') });

    assert.deepEqual(pageErrors, [], `uncaught page errors: ${pageErrors.join(' | ')}`);
  });
});
