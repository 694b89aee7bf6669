// A whole mission from the page (issue 18's target): the campus set up as `make demo` does (the
// world's bounds as the area, drifting odometry), the operator approves the top candidate each
// time until the page says the mission is complete or 40 scans are in, never needing a point of
// their own and never refused by the robot; then the exports and the report are downloaded from
// the page and checked against each other and the session. Screenshot: whole_mission.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { requestScan, startStack, worldVariant, scratchDir } from '../support/stack.mjs';
import { frames, openPage, screenshot, waitForData, withBrowser } from '../support/browser.mjs';

const MAX_SCANS = 40;
let stack;
let world;
before(async () => {
  ({ file: world } = worldVariant(scratchDir('scanplan-mission-'), 'campus.json', {}));
  stack = await startStack({ world });
  const { bounds } = JSON.parse(readFileSync(world, 'utf8'));
  const target = [bounds.min, [bounds.max[0], bounds.min[1]], bounds.max, [bounds.min[0], bounds.max[1]]];
  const r = await stack.api('PUT', '/api/v1/params', { body: JSON.stringify({ target, by: 'make demo (the world\'s bounds)' }) });
  assert.equal(r.status, 200, await r.text());
  await requestScan(stack);
});
after(async () => stack && (await stack.stop()));

const api = async (path) => (await stack.api('GET', path)).json();

test(`a whole campus mission: the top candidate approved until complete or ${MAX_SCANS} scans`, { timeout: 900000 }, async (t) => {
  await withBrowser(async (context) => {
    const { page, problems } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    // Chromium draws on its software renderer here, on the 2 cores the server also needs: the
    // smallest point budget keeps it from starving the mission (issue 19 adapts it by itself).
    await page.selectOption('#budget', '1000000');
    let scans = 0;
    let state = '';
    for (;;) {
      // The newest scan in, its plan in the page, the robot idle.
      const s = await stack.waitFor('the scan in the session', async () => {
        const session = await api('/api/v1/session');
        return session.scans > scans && session.last_scan ? session : undefined;
      }, 120000);
      scans = s.scans;
      const last = s.last_scan.id;
      await waitForData(page, `the plan after scan ${last}`, (id) => {
        const { candidates, mission } = window.scanplan;
        const robot = mission.robots.robot1;
        return candidates.plan?.based_on_scan === id && robot?.state !== 'scanning' && robot?.state !== 'moving' &&
          document.getElementById('mission-progress').dataset.state !== '' && document.body.dataset.scans === String(id);
      }, last, 60000);
      state = await page.locator('#mission-progress').getAttribute('data-state');
      if (state === 'complete' || scans >= MAX_SCANS) break;
      const row = page.locator('#cand-list .cand-row[data-state="proposed"]').first();
      assert.ok(await row.count(), `a candidate to approve after scan ${last}`);
      await row.click();
      await page.click('#approve');
      await page.waitForSelector('#confirm[open]');
      await page.click('#confirm-ok');
      await waitForData(page, 'the move under way', () => !document.querySelector('#confirm[open]'));
    }
    t.diagnostic(`${scans} scans, mission ${state}: ${await page.locator('#mission-progress').innerText()}`);

    const decisions = (await api('/api/v1/decisions?limit=1000')).decisions;
    const kinds = (k) => decisions.filter((d) => d.kind === k);
    assert.deepEqual(kinds('refused'), [], 'the robot refused nothing');
    assert.deepEqual(kinds('goal'), [], 'no point of the operator\'s own was needed');
    assert.equal(kinds('approve').length, scans - 1, 'each scan after the first came from an approved candidate');
    const session = await api('/api/v1/session');
    assert.ok(session.mission.coverage_pct >= (state === 'complete' ? 85 : 70), `coverage ${session.mission.coverage_pct} %`);

    // The exports, saved from the page's menu.
    const save = async (name) => {
      const [download] = await Promise.all([page.waitForEvent('download'), page.selectOption('#export-select', name)]);
      await page.waitForFunction(() => document.getElementById('export-msg').dataset.state === 'saved', null, { timeout: 120000 });
      return readFileSync(await download.path());
    };
    const ply = await save('map.ply');
    const header = ply.subarray(0, ply.indexOf('end_header\n') + 11).toString('latin1');
    const vertices = Number(header.match(/element vertex (\d+)/)[1]);
    assert.match(header, /^ply\nformat binary_little_endian 1\.0\n/);
    assert.equal(ply.length, header.length + vertices * (12 + 3 + 4), 'x y z float, rgb uchar, scan_id uint per point');
    const las = await save('map.las');
    assert.equal(las.subarray(0, 4).toString('latin1'), 'LASF');
    assert.deepEqual([las[24], las[25]], [1, 4], 'LAS 1.4');
    assert.equal(Number(las.readBigUInt64LE(247)), vertices, 'the LAS holds the same points as the PLY');
    const inMap = (await api('/api/v1/scans')).scans.filter((x) => x.in_map !== false);
    assert.equal(vertices, inMap.reduce((n, x) => n + x.points, 0), 'every point of every scan in the map');
    const csv = (await save('poses.csv')).toString('utf8').trim().split('\n');
    assert.equal(csv.length, 1 + inMap.length, 'a header and a row per scan in the map');
    t.diagnostic(`${inMap.length} of ${scans} scans in the map, ${vertices} points`);
    const geo = JSON.parse((await save('annotations.geojson')).toString('utf8'));
    assert.equal(geo.type, 'FeatureCollection');
    const report = (await save('report.html')).toString('utf8');
    assert.match(report, /^<!doctype html>/i);
    assert.match(report, new RegExp(`${scans} scans`));
    assert.match(report, /<img [^>]*src="data:image\/png;base64,/, 'the top view inside the page');
    assert.doesNotMatch(report, /<script|src="http/i, 'self-contained');

    await frames(page);
    t.diagnostic(`shot: ${await screenshot(page, 'whole_mission.png')}`);
    assert.deepEqual(problems, { pageErrors: [], consoleErrors: [], foreignRequests: [] });
  });
});
