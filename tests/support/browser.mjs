// Debian chromium driven by playwright-core, for the operator page's browser tests.
// playwright-core comes from web/node_modules (`npm ci` in web/ first).
import { createRequire } from 'node:module';
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const require = createRequire(new URL('../../web/package.json', import.meta.url));

export const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
export const SHOT_DIR = process.env.SCREENSHOT_DIR || tmpdir();
export const VIEWPORT = { width: 1366, height: 768 }; // a field laptop

export const CHROMIUM_ARGS = [
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

/**
 * A fresh browser profile; `fn(context)`; everything is closed and removed afterwards.
 * `viewport` (default the field laptop's) and `touch` (a touch screen: taps, pinches, coarse
 * pointer) choose the device.
 */
export async function withBrowser(fn, { viewport = VIEWPORT, touch = false } = {}) {
  const { chromium } = require('playwright-core');
  const profile = mkdtempSync(join(tmpdir(), 'scanplan-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport,
    deviceScaleFactor: 1,
    hasTouch: touch,
    isMobile: false,
    timeout: 30000,
  });
  try {
    return await fn(context);
  } finally {
    await context.close().catch(() => {});
    rmSync(profile, { recursive: true, force: true });
  }
}

/**
 * A page with its problems collected: uncaught errors, console errors (except the 404 of a
 * probed endpoint, which the page handles), requests to anywhere but our server, and every API
 * request made.
 */
export async function openPage(context, url) {
  const page = await context.newPage();
  const problems = { pageErrors: [], consoleErrors: [], foreignRequests: [] };
  const requests = [];
  const origin = new URL(url).origin;
  page.on('pageerror', (e) => problems.pageErrors.push(String(e && e.stack ? e.stack : e)));
  page.on('console', (m) => {
    if (m.type() === 'error' && !/status of 404/.test(m.text())) problems.consoleErrors.push(m.text());
  });
  page.on('request', (r) => {
    const u = new URL(r.url());
    // Everything must come from our server: the page works with no internet.
    if (!['data:', 'blob:'].includes(u.protocol) && u.origin !== origin) problems.foreignRequests.push(r.url());
    if (u.pathname.startsWith('/api/')) requests.push({ method: r.method(), path: u.pathname, search: u.search });
  });
  const res = await page.goto(url, { waitUntil: 'load', timeout: 30000 });
  if (!res || !res.ok()) throw new Error(`page load failed: HTTP ${res && res.status()}`);
  return { page, problems, requests };
}

export async function screenshot(page, name) {
  mkdirSync(SHOT_DIR, { recursive: true });
  const path = join(SHOT_DIR, name);
  await page.screenshot({ path });
  return path;
}

/** The page's test state (document.body.dataset) and what the status line says. */
export function dataset(page) {
  return page.evaluate(() => ({ ...document.body.dataset, status: document.getElementById('status-message')?.textContent }));
}

/** Waits for fn(dataset) on the page; on timeout the error names the dataset it last saw. */
export async function waitForData(page, what, predicate, arg, timeout = 30000) {
  try {
    await page.waitForFunction(predicate, arg, { timeout, polling: 200 });
  } catch (e) {
    throw new Error(`timed out waiting for ${what}: ${JSON.stringify(await dataset(page))}`);
  }
}

/**
 * Share of the map canvas's pixels that differ from its background (the most frequent colour),
 * and how many coarse colours (3 bits a channel) those pixels take.
 */
export function canvasCoverage(page) {
  return page.evaluate(() => {
    const src = document.querySelector('#view canvas');
    if (!src) return { error: 'no canvas' };
    const c = document.createElement('canvas');
    c.width = src.width;
    c.height = src.height;
    const ctx = c.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(src, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const hist = new Map();
    for (let i = 0; i < d.length; i += 4) {
      const k = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      hist.set(k, (hist.get(k) || 0) + 1);
    }
    let bg = 0;
    let best = -1;
    for (const [k, n] of hist) if (n > best) [bg, best] = [k, n];
    const br = bg >> 16, bgG = (bg >> 8) & 255, bb = bg & 255;
    let differ = 0;
    const hues = new Set();
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - br) + Math.abs(d[i + 1] - bgG) + Math.abs(d[i + 2] - bb) > 24) {
        differ++;
        hues.add(((d[i] >> 5) << 6) | ((d[i + 1] >> 5) << 3) | (d[i + 2] >> 5));
      }
    }
    return { width: c.width, height: c.height, fraction: differ / (c.width * c.height), colours: hues.size, bg: [br, bgG, bb] };
  });
}

/** Two animation frames, so what changed is drawn. */
export function frames(page) {
  return page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
}

/** Layout problems at the current viewport: elements of the page that overflow the window. */
export function overflowing(page) {
  return page.evaluate(() => {
    const out = [];
    const W = window.innerWidth;
    const H = window.innerHeight;
    for (const sel of ['#topbar', '#view-pane', '#side', '#top-panel', '#side-tabs', '#bottom', '#mission-panel', '#chart-panel', '#log-panel']) {
      const el = document.querySelector(sel);
      if (!el) continue;
      const r = el.getBoundingClientRect();
      if (r.right > W + 0.5 || r.bottom > H + 0.5 || r.width < 1 || r.height < 1) out.push(`${sel} ${JSON.stringify(r)}`);
    }
    if (document.documentElement.scrollWidth > W || document.documentElement.scrollHeight > H) out.push('the page scrolls');
    return out;
  });
}
