// Browser end-to-end test of the operator page (issue 8) against a real server and simulated robot,
// at the 1366×768 of a field laptop: the map arrives as per-scan chunks, a candidate shows in the
// list and on the top view, a custom point is proposed from the top view, an approval (confirmed) drives the robot and the scan that follows
// grows the map through a WebSocket chunk (no full map.drc), the coverage chart and the decision
// log follow; a lost connection shows the banner and resumes with map.drc?since=<last scan held>.
// Screenshots: $SCREENSHOT_DIR (build/screenshots under ctest).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { requestScan, requireEnv, scanAndWait, startStack, worldVariant, scratchDir } from '../support/stack.mjs';
import {
  canvasCoverage,
  dataset,
  frames,
  openPage,
  overflowing,
  screenshot,
  waitForData,
  withBrowser,
} from '../support/browser.mjs';

let stack;
before(async () => {
  // No pose noise: the robot scans exactly where it was sent, so the test checks positions.
  const { file } = worldVariant(scratchDir('scanplan-page-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file, timeScale: 600 });
  await scanAndWait(stack, 1);
});
after(async () => stack && (await stack.stop()));

const WebSocket = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'))('ws');

const session = async () => (await stack.api('GET', '/api/v1/session')).json();
const fullMapFetches = (requests) => requests.filter((r) => r.path === '/api/v1/map.drc' && !new URLSearchParams(r.search).has('since'));

test('operator page: map, candidates, approval, growth by WebSocket chunk, reconnection', { timeout: 120000 }, async (t) => {
  await withBrowser(async (context) => {
    const { page, problems, requests } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    const first = await session();

    // 1. The map of scan 1 is drawn, the role is known, the layout fits the screen.
    await waitForData(page, 'the first scan drawn', (n) => Number(document.body.dataset.points) >= n && document.body.dataset.ws === 'open', first.points);
    await waitForData(page, 'candidates', () => Number(document.body.dataset.candidates) >= 1);
    let ds = await dataset(page);
    assert.equal(ds.state, 'live');
    assert.equal(ds.role, 'operator');
    assert.equal(ds.chunks, '1');
    assert.equal(ds.error, '');
    await frames(page);
    const pix = await canvasCoverage(page);
    t.diagnostic(`3-D canvas ${pix.width}x${pix.height}: ${(pix.fraction * 100).toFixed(2)}% non-background`);
    assert.ok(pix.fraction > 0.005, `the 3-D view looks blank (${pix.fraction})`);
    assert.deepEqual(await overflowing(page), [], 'every panel fits in 1366×768');

    // 2. Candidates: in the list and on the top view; a click on the top view selects one.
    const rows = await page.locator('#cand-list .cand-row').count();
    assert.ok(rows >= 1, 'candidate rows');
    if (rows >= 2) await page.locator('#cand-list .cand-row').nth(1).click();
    const target = await page.evaluate(() => {
      const tv = window.scanplan.topView;
      const c = tv.candidates.find((k) => k.rank === 1);
      const s = tv.screenOf(c.x, c.y);
      const r = tv.canvas.getBoundingClientRect();
      return { id: c.id, x: c.x, y: c.y, travel: c.travel_m, f: c.f, px: r.left + s.x, py: r.top + s.y, inside: s.x > 0 && s.y > 0 && s.x < r.width && s.y < r.height };
    });
    assert.ok(target.inside, 'the best candidate is inside the top view');
    await page.mouse.click(target.px, target.py);
    await frames(page);
    assert.equal(await page.evaluate(() => window.scanplan.candidates.selected), target.id, 'top-view click selects the candidate');
    const onTop = await page.evaluate(({ px, py }) => {
      const tv = window.scanplan.topView;
      const r = tv.canvas.getBoundingClientRect();
      const k = tv.dpr;
      const d = tv.ctx.getImageData(Math.round((px - r.left + 7) * k), Math.round((py - r.top) * k), 1, 1).data;
      return [d[0], d[1], d[2]];
    }, target);
    assert.deepEqual(onTop, [0x39, 0xc5, 0xf3], 'the selected candidate is drawn on the top view');
    const detail = await page.locator('#cand-detail').innerText();
    // Plain words with units first, the paper's score as a detail.
    assert.match(detail, /new ground\s+≈ [\d,]+ m²/);
    assert.match(detail, /never scanned\s+[\d,]+ m²/);
    assert.match(detail, /now coarse\s+[\d,]+ m²/);
    assert.match(detail, /drive\s+[\d.]+ m/);
    assert.match(detail, /position\s+-?[\d.]+, -?[\d.]+, -?[\d.]+ m/);
    assert.match(detail, /score F\s+[\d,]+ m²/);
    // The row warns (⚠) exactly when the planner forecasts the scan there may not match.
    const firstRow = await page.locator('#cand-list .cand-row').first().innerText();
    assert.match(firstRow, /≈ [\d,]+ m²\s+(⚠ )?new ground · F [\d,]+\s+[\d.]+ m/);
    const firstDoubtful = await page.evaluate(() => {
      const r = window.scanplan.candidates.list[0].registrability;
      return !!r && r.factor < 1;
    });
    assert.equal(firstRow.includes('⚠'), firstDoubtful, 'the warning follows the forecast');
    // The planner's forecast of matching a scan there (matching is on).
    assert.match(detail, /overlap\s+[\d,]+ m² of the map in view/);
    assert.match(detail, /matching\s+(only )?\d+ % (of the scan )?on the trusted map/);
    t.diagnostic(`shot: ${await screenshot(page, 'operator_page.png')}`);

    // 3. A click on the top view proposes the operator's own point: refused where the robot cannot
    // stand (the server's reason is shown), added as a custom candidate where it can.
    const clickMap = async (x, y) => {
      const p = await page.evaluate(([mx, my]) => {
        const tv = window.scanplan.topView;
        const s = tv.screenOf(mx, my);
        const r = tv.canvas.getBoundingClientRect();
        return { x: r.left + s.x, y: r.top + s.y };
      }, [x, y]);
      await page.mouse.click(p.x, p.y);
    };
    await clickMap(-17.4, 8.6); // on a 1 m crate
    await page.click('#goal-propose');
    await waitForData(page, 'the refusal', () => /not possible/.test(document.getElementById('goal-msg').textContent));
    assert.match(await page.locator('#goal-msg').innerText(), /not in the movable region/);
    await clickMap(-9.3, -6.2); // open ground near the robot
    assert.match(await page.locator('#goal-where').innerText(), /\(-9\.\d, -6\.\d\)/);
    await page.click('#goal-propose');
    await waitForData(page, 'the custom candidate', () => !!document.querySelector('#cand-list .cand-row .rank.custom'));
    // The list shows the new row as soon as the plan comes; the detail follows the selection.
    await waitForData(page, 'the custom candidate selected', () => /custom point/.test(document.getElementById('cand-detail').textContent));
    assert.match(await page.locator('#cand-detail').innerText(), /custom point/);
    assert.ok(await page.locator('#goal-bar').isHidden(), 'the proposed point is taken over by the candidate');
    t.diagnostic(`shot: ${await screenshot(page, 'custom_goal.png')}`);
    // Reject the custom point, with a reason, after the confirmation.
    await page.click('#reject');
    await page.waitForSelector('#confirm[open]');
    assert.ok(await page.locator('#confirm-reason').isVisible(), 'a rejection asks for the reason');
    await page.fill('#confirm-reason', 'rubble on the way');
    await page.click('#confirm-ok');
    await waitForData(page, 'the custom point rejected', () => document.querySelector('#cand-list .cand-row .rank.custom')?.closest('.cand-row')?.dataset.state === 'rejected');
    await waitForData(page, 'the rejection in the log', () => /rejected #\d+: rubble on the way/.test(document.getElementById('log').textContent));
    await page.locator(`#cand-list .cand-row[data-id="${target.id}"]`).click(); // back to the planner's best
    assert.equal(await page.evaluate(() => window.scanplan.candidates.selected), target.id);

    // 4. Approve, with a confirmation naming the drive; then the robot moves and scan 2 arrives.
    // What the mission panel is told on the way is recorded.
    await page.evaluate(() => {
      const m = window.scanplan.mission;
      window.seen = { robot: [], progress: [] };
      for (const [name, key, field] of [['onRobotStatus', 'robot', 'state'], ['onScanProgress', 'progress', 'fraction']]) {
        const original = m[name].bind(m);
        m[name] = (e) => {
          window.seen[key].push(e[field]);
          original(e);
        };
      }
    });
    await page.click('#approve');
    await page.waitForSelector('#confirm[open]');
    assert.match(await page.locator('#confirm-body').innerText(), /will drive .* m to/);
    await page.fill('#confirm-by', 'Test Operator');
    t.diagnostic(`shot: ${await screenshot(page, 'approve_confirm.png')}`);
    await page.click('#confirm-ok');
    await waitForData(page, 'scan 2 drawn from a WebSocket chunk', () => document.body.dataset.scans === '2' && document.body.dataset.chunks === '2', null, 45000);
    const second = await session();
    assert.equal(second.scans, 2);
    assert.ok(Math.hypot(second.last_scan.pose.x - target.x, second.last_scan.pose.y - target.y) < 0.01, 'scanned where approved');
    await waitForData(page, 'every point of both scans', (n) => Number(document.body.dataset.points) === n, second.points);
    const stats = await page.evaluate(() => window.scanplan.chunks.stats);
    assert.ok(stats.wsChunks >= 1, `scan 2 came over the WebSocket: ${JSON.stringify(stats)}`);
    assert.deepEqual(fullMapFetches(requests), [], 'the page never downloads the whole map.drc');
    assert.ok(!requests.some((r) => r.path === '/api/v1/map.drc' && /until=2/.test(r.search)), 'scan 2 was not fetched over REST');

    await waitForData(page, 'two points in the coverage chart', () => document.getElementById('chart').dataset.points === '2');
    await waitForData(page, 'the approval in the log', () => /approved/.test(document.getElementById('log').textContent));
    assert.match(await page.locator('#log').innerText(), /Test Operator/);
    assert.match(await page.locator('#scan-progress-text').innerText(), /scan 2/);
    const seen = await page.evaluate(() => window.seen);
    t.diagnostic(`robot states ${seen.robot.join(' ')}; scan fractions ${seen.progress.map((f) => f.toFixed(2)).join(' ')}`);
    assert.ok(seen.robot.includes('moving') && seen.robot.includes('arrived'), `the move's states: ${seen.robot}`);
    assert.ok(seen.progress.some((f) => f > 0 && f < 1) && seen.progress.includes(1), `scan progress: ${seen.progress}`);
    assert.equal(await page.locator('#scan-progress').getAttribute('data-fraction'), '1.000');
    await waitForData(page, 'the match result of scan 2', () => /scan 2 matched/.test(document.getElementById('match-result').textContent));
    assert.match(await page.locator('#match-result').innerText(), /score [\d.]+, RMSE [\d.]+ m, shift [\d.]+ m/);
    assert.match(await page.locator('#log').innerText(), /robot1 arrived at #/);
    await frames(page);
    t.diagnostic(`shot: ${await screenshot(page, 'operator_after_move.png')}`);

    // 5. The link goes down: the banner shows; a scan made meanwhile comes with since=2 once it is back.
    await context.setOffline(true);
    await page.evaluate(() => window.scanplan.events.drop('test: link down'));
    await waitForData(page, 'the connection-lost banner', () => document.body.dataset.banner === 'lost' && !document.getElementById('banner').hidden);
    assert.match(await page.locator('#banner').innerText(), /Connection to the server lost/);
    await frames(page);
    t.diagnostic(`shot: ${await screenshot(page, 'connection_lost.png')}`);
    const before = requests.length;
    // The server counts a scan in the session before it has sent the scan's chunk; the link
    // comes back only after the scan's last event (map_updated), so that the page cannot get
    // the chunk over its new socket and the REST resume is what is tested.
    const ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
    await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
    let processed = false;
    ws.on('message', (data, isBinary) => {
      const e = isBinary ? null : JSON.parse(data.toString());
      if (e?.type === 'map_updated' && e.scan === 3) processed = true;
    });
    await requestScan(stack);
    await stack.waitFor('scan 3 processed', async () => processed || undefined);
    ws.close();
    const third = await session();
    assert.equal(third.scans, 3);
    ds = await dataset(page);
    assert.equal(ds.chunks, '2', 'nothing arrives while the link is down');
    await context.setOffline(false);
    await page.evaluate(() => window.scanplan.events.retryNow());
    await waitForData(page, 'the map resumed with scan 3', (n) => document.body.dataset.ws === 'open' && document.body.dataset.chunks === '3' && Number(document.body.dataset.points) === n, third.points, 30000);
    await waitForData(page, 'the banner to say it reconnected', () => document.body.dataset.banner !== 'lost');
    const resumed = requests.slice(before).filter((r) => r.path === '/api/v1/map.drc');
    assert.deepEqual(resumed.map((r) => r.search), ['?since=2&until=3'], 'only the missed scan is downloaded');
    assert.deepEqual(fullMapFetches(requests), []);
    assert.equal(await page.evaluate(() => window.scanplan.view.chunkCount), 3);

    // 6. A bad scan taken out of the map and put back (issue 16): from a point of scan 2 clicked
    // in the view (the button that click shows), confirmed with a reason; the map is rebuilt
    // without it, the page drops its points and lists it; "Put back" brings it back.
    await page.evaluate(() => {
      const b = document.getElementById('exclude-scan');
      b.dataset.scan = '2';
      b.textContent = 'Take scan 2 out of the map…';
      b.hidden = false;
    });
    await page.click('#exclude-scan');
    await page.fill('#confirm-reason', 'ghost walls from a wrong match');
    await page.click('#confirm-ok');
    await waitForData(page, 'scan 2 out of the view', () => document.body.dataset.chunks === '2' &&
      document.querySelector('#excluded-scans .excluded-scan[data-scan="2"]') !== null, null, 30000);
    assert.match(await page.locator('#excluded-scans').innerText(), /scan 2 .*ghost walls from a wrong match/s);
    assert.equal((await session()).scans, 2);
    await screenshot(page, 'operator_page_scan_excluded.png');
    await page.click('#excluded-scans .excluded-scan[data-scan="2"] button');
    await page.click('#confirm-ok');
    await waitForData(page, 'scan 2 back in the view', () => document.body.dataset.chunks === '3' &&
      document.getElementById('excluded-scans').hidden, null, 30000);
    assert.match(await page.locator('#log').innerText(), /took scan 2 out of the map: ghost walls/);

    assert.deepEqual(problems.foreignRequests, [], 'every asset comes from our server');
    assert.deepEqual(problems.pageErrors, [], 'uncaught page errors');
    assert.deepEqual(problems.consoleErrors.filter((m) => !/ERR_INTERNET_DISCONNECTED|Failed to load resource|WebSocket/.test(m)), [], 'console errors');
  });
});
