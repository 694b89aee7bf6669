// A robot that refuses every point (a bridge replaying a recording cannot drive): the operator
// approves the suggestions one after another from the page, each comes back refused with the
// robot's reason, and once none is left the page says so and points to the operator's own point.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startOneScanReplay, startStack } from '../support/stack.mjs';
import { openPage, screenshot, waitForData, withBrowser } from '../support/browser.mjs';

let stack;
before(async () => {
  stack = await startOneScanReplay();
});
after(async () => stack && (await stack.stop()));

test('every suggestion refused: the page says so and offers the operator\'s own point', { timeout: 90000 }, async (t) => {
  await withBrowser(async (context) => {
    const { page, problems } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await waitForData(page, 'candidates', () => Number(document.body.dataset.candidates) >= 1);
    const count = await page.locator('#cand-list .cand-row').count();
    assert.ok(count >= 2, `${count} candidates`);
    assert.equal(await page.locator('.all-refused').count(), 0, 'nothing refused yet');
    for (let k = 0; k < count; k++) {
      const row = page.locator('#cand-list .cand-row[data-state="proposed"]').first();
      const id = await row.getAttribute('data-id');
      await row.click();
      await page.locator('#approve').click();
      await page.waitForSelector('#confirm[open]');
      await page.locator('#confirm-ok').click();
      await page.waitForFunction((cid) => document.querySelector(`#cand-list .cand-row[data-id="${cid}"]`)?.dataset.state === 'refused', id, { timeout: 15000 })
        .catch(async (e) => {
          const server = await (await stack.api('GET', '/api/v1/candidates')).json();
          const states = await page.evaluate(() => [...document.querySelectorAll('#cand-list .cand-row')].map((r) => `${r.dataset.id}:${r.dataset.state}`));
          throw new Error(`candidate ${id} not shown refused: page ${states}, server ${server.candidates.map((c) => `${c.id}:${c.state}`)}, ${await page.locator('#cand-detail').innerText()} (${e.message})`);
        });
    }
    // The selected candidate's panel follows its state: not "on its way" once refused.
    assert.match(await page.locator('#cand-detail').innerText(), /refused by robot1: this robot replays a recording/);
    assert.doesNotMatch(await page.locator('#cand-detail').innerText(), /on its way/);
    assert.ok(await page.locator('.all-refused').isVisible(), 'the hint is in view, above the list');
    const text = await page.locator('.all-refused').innerText();
    assert.match(text, /robot1 refused every suggested point\. Click a spot on the top view to propose your own/);
    t.diagnostic(`shot: ${await screenshot(page, 'all-refused.png')}`);

    // The mission's progress line, and the operator finishing the mission from the page.
    assert.match(await page.locator('#mission-progress').innerText(), /\d+ % of the area scanned/);
    await page.click('#finish-mission');
    await page.waitForSelector('#confirm[open]');
    await page.fill('#confirm-reason', 'recording replayed');
    await page.click('#confirm-ok');
    await page.waitForFunction(() => document.getElementById('mission-progress').dataset.state === 'finished');
    assert.match(await page.locator('#mission-progress').innerText(), /^mission finished by operator/);
    assert.equal(await page.locator('#finish-mission').innerText(), 'Resume');
    await page.waitForFunction(() => /finished the mission: recording replayed/.test(document.getElementById('log').innerText));
    assert.deepEqual(problems.pageErrors, []);
  });
});

test('a restarted server still does not suggest the refused points', { timeout: 90000 }, async () => {
  const log = (await (await stack.api('GET', '/api/v1/decisions')).json()).decisions;
  const refused = log.filter((d) => d.kind === 'refused');
  assert.ok(refused.length >= 2, `${refused.length} refusals on record`);
  for (const d of refused) assert.ok(Number.isFinite(d.x) && Number.isFinite(d.y) && d.after_scan === 1, JSON.stringify(d));
  const tokens = { operator: stack.token, viewer: stack.viewerToken };
  const dir = stack.dir;
  await stack.stop({ keepDir: true, signal: 'SIGKILL' });
  stack = await startStack({ bridge: false, dir, tokens });
  const plan = await stack.waitFor('the plan after the restart', async () => {
    const b = await (await stack.api('GET', '/api/v1/candidates')).json();
    return b.plan ? b : undefined;
  });
  // Nothing within the planner's clearance (5 m) of a refused point: the same points would be
  // refused again. The scan they came after does not forget them as it reloads.
  for (const c of plan.candidates) {
    for (const d of refused) assert.ok(Math.hypot(c.x - d.x, c.y - d.y) >= 5 - 1e-6, `candidate ${c.id} (${c.x}, ${c.y}) near refused (${d.x}, ${d.y})`);
  }
});
