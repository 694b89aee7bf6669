// The page follows the pose graph (issue 17): four recorded campus scans posted on drifting
// odometry; the graph corrects the map (map_corrected), and the page says so in its log, draws
// exactly the scans in the map (a scan waiting outside it is not drawn) and fetches a corrected
// scan's chunk again.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { createRequire } from 'node:module';
import { startStack, requireEnv } from '../support/stack.mjs';
import { dataset, openPage, waitForData, withBrowser } from '../support/browser.mjs';

const script = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/replays/campus/campus.replay.json');
const uploads = JSON.parse(readFileSync(script, 'utf8')).steps
  .filter((s) => s.request.method === 'POST' && s.expect?.status === 201)
  .map((s) => ({ path: s.request.path, body: readFileSync(join(dirname(script), s.request.body_file)) }));

const WebSocket = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'))('ws');

let stack;
after(async () => stack && (await stack.stop()));

test('the page draws the map as the graph has it and says when it was corrected', { timeout: 180000 }, async () => {
  stack = await startStack({ bridge: false, odometry: 'drift' });
  await withBrowser(async (context) => {
    const { page, problems, requests } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await waitForData(page, 'the page live', () => document.body.dataset.ws === 'open');
    const ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
    await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
    const corrections = [];
    let lastScan = 0;
    let settled = false; // the last scan's map_updated, its last event: every other came before
    ws.on('message', (data, isBinary) => {
      if (isBinary) return;
      const e = JSON.parse(data.toString());
      if (e.type === 'map_corrected') corrections.push(e);
      if (e.type === 'map_updated') lastScan = e.scan;
      if (e.type === 'map_updated' && lastScan === uploads.length) settled = true;
    });
    for (const u of uploads) {
      const r = await stack.api('POST', u.path, { body: u.body });
      assert.equal(r.status, 201, await r.text());
    }
    const scans = await stack.waitFor('the four scans processed', async () => {
      const a = await (await stack.api('GET', '/api/v1/scans')).json();
      return a.scans.length === 4 && a.pending === 0 ? a.scans : undefined;
    }, 120000);
    const inMap = scans.filter((s) => s.in_map).map((s) => s.id);
    // A scan outside the map says why; one in it says nothing.
    for (const s of scans) {
      if (s.in_map) assert.equal(s.outside, null, `scan ${s.id}`);
      else assert.ok(typeof s.outside === 'string' && s.outside.length > 0, `scan ${s.id}: ${s.outside}`);
    }
    await stack.waitFor('the last scan\'s events', async () => settled || undefined, 30000);
    assert.ok(corrections.length >= 1, 'the graph corrected the map');
    // The page had every correction the server made, and then holds each scan in the map where
    // the server has it now.
    await waitForData(page, `all ${corrections.length} corrections in the log`,
      (n) => [...document.querySelectorAll('#log li')].filter((li) => li.textContent.includes('map corrected')).length === n,
      corrections.length);
    await waitForData(page, `the ${inMap.length} scans in the map drawn where they are, and no other`,
      (n) => document.body.dataset.chunks === String(n) && document.body.dataset.mapCurrent === 'true', inMap.length, 60000);
    // The page's match history tells the operator why a scan waits outside the map.
    const history = await page.locator('#match-result').getAttribute('title');
    for (const s of scans.filter((x) => !x.in_map)) {
      assert.ok(history.includes(`scan ${s.id}: waiting outside the map (not drawn): ${s.outside}`), history);
    }
    const said = await page.locator('#log li', { hasText: 'map corrected' }).first().textContent();
    assert.match(said, /map corrected: scans? [0-9]/);
    // The chunks came over the WebSocket as the scans joined; a scan the graph moved or tied in
    // later was fetched (again) over REST, where it now is.
    ws.close();
    const fetched = new Set(requests.filter((r) => r.path === '/api/v1/map.drc')
      .map((r) => Number(new URLSearchParams(r.search).get('until'))));
    for (const id of new Set(corrections.flatMap((c) => [...c.scans, ...c.joined]))) {
      if (inMap.includes(id)) assert.ok(fetched.has(id), `scan ${id}, corrected, fetched where it now is`);
    }
    const ds = await dataset(page);
    assert.equal(ds.error, '');
    assert.deepEqual(problems.pageErrors, []);
    assert.deepEqual(problems.consoleErrors, []);
  });
});
