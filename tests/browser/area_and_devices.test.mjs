// The operator's area drawn on the top view (issue 18, part 1) and the page on smaller devices
// (part 9): at 1024×768 with a mouse a no-go zone is drawn over the best candidate and saved, the
// server re-plans around it and logs who set it; on an upright tablet (768×1024, touch) every
// panel fits, a tap on the top view selects a candidate and a two-finger pinch zooms it.
// Screenshots: $SCREENSHOT_DIR/area_1024x768.png, tablet_768x1024.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startOneScanReplay } from '../support/stack.mjs';
import { frames, openPage, overflowing, screenshot, waitForData, withBrowser } from '../support/browser.mjs';

let stack;
before(async () => {
  stack = await startOneScanReplay();
});
after(async () => stack && (await stack.stop()));

const inside = ([x, y], poly) => {
  let c = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const [xi, yi] = poly[i];
    const [xj, yj] = poly[j];
    if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) c = !c;
  }
  return c;
};

test('1024×768: a no-go zone drawn over the best candidate moves the plan away from it', { timeout: 120000 }, async (t) => {
  await withBrowser(async (context) => {
    const { page, problems } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await waitForData(page, 'candidates', () => Number(document.body.dataset.candidates) >= 2);
    assert.deepEqual(await overflowing(page), [], 'every panel fits in 1024×768');
    const before = await (await stack.api('GET', '/api/v1/candidates')).json();
    const best = before.candidates.find((c) => c.rank === 1);

    // A 6 m square around the best candidate, corner by corner, closed by clicking the first.
    await page.click('#area-edit');
    await page.click('#area-zone');
    const box = await page.locator('#top-canvas').boundingBox();
    const zone = [[-3, -3], [3, -3], [3, 3], [-3, 3]].map(([dx, dy]) => [best.x + dx, best.y + dy]);
    // Zoomed in enough that the corners are well apart on screen.
    await page.evaluate(({ x, y }) => {
      const tv = window.scanplan.topView;
      tv.cx = x;
      tv.cy = y;
      tv.scale = 12;
      tv.userMoved = true;
      tv.redraw();
    }, best);
    for (const [x, y] of [...zone, zone[0]]) {
      const s = await page.evaluate(([mx, my]) => window.scanplan.topView.screenOf(mx, my), [x, y]);
      await page.mouse.click(box.x + s.x, box.y + s.y);
    }
    assert.match(await page.locator('#area-zones').innerText(), /no-go 1 · 3\d(\.\d)? m²/);
    const planBefore = before.plan.id;
    await page.click('#area-save');
    await waitForData(page, 'saved', () => /^Saved/.test(document.getElementById('area-msg').textContent));
    assert.match(await page.locator('#area-msg').innerText(), /1 no-go zone/);

    const params = await (await stack.api('GET', '/api/v1/params')).json();
    assert.equal(params.no_go.length, 1);
    for (const [k, [x, y]] of params.no_go[0].entries()) {
      assert.ok(Math.hypot(x - zone[k][0], y - zone[k][1]) < 0.5, `corner ${k} (${x}, ${y}) where it was clicked (${zone[k]})`);
    }
    const replanned = await stack.waitFor('the plan made with the zone', async () => {
      const c = await (await stack.api('GET', '/api/v1/candidates')).json();
      return c.plan.id !== planBefore ? c : undefined;
    });
    const proposed = replanned.candidates.filter((c) => c.plan === replanned.plan.id);
    assert.ok(proposed.length >= 1, 'still candidates outside the zone');
    for (const c of proposed) assert.ok(!inside([c.x, c.y], params.no_go[0]), `candidate ${c.id} (${c.x}, ${c.y}) is in the zone`);
    const decisions = (await (await stack.api('GET', '/api/v1/decisions')).json()).decisions;
    assert.ok(decisions.some((d) => d.kind === 'params' && d.params.no_go.length === 1), 'the change is in the decision log');
    // The saved zone stays drawn after editing; the page shows it to a late joiner too.
    await waitForData(page, 'the zone drawn', () => window.scanplan.area.shapes().noGo.length === 1 && !window.scanplan.area.editing);

    // Units where numbers are shown: the cursor's position and the elevation colours.
    const c = await page.evaluate(([mx, my]) => window.scanplan.topView.screenOf(mx, my), [best.x, best.y]);
    await page.mouse.move(box.x + c.x, box.y + c.y);
    assert.match(await page.locator('#top-coords').innerText(), /^x -?\d+\.\d m\s+y -?\d+\.\d m$/);
    await page.selectOption('#layer-select', 'elevation');
    await waitForData(page, 'elevation legend in metres', () => /-?\d+\.\d m → \d+\.\d m/.test(document.getElementById('top-legend').textContent));
    await frames(page);
    t.diagnostic(`shot: ${await screenshot(page, 'area_1024x768.png')}`);
    assert.deepEqual(problems, { pageErrors: [], consoleErrors: [], foreignRequests: [] });
  }, { viewport: { width: 1024, height: 768 } });
});

test('tablet 768×1024, touch: every panel fits, a tap selects a candidate, a pinch zooms the top view', { timeout: 120000 }, async (t) => {
  await withBrowser(async (context) => {
    const { page, problems } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await waitForData(page, 'candidates and the map', () => Number(document.body.dataset.candidates) >= 2 && document.body.dataset.chunks === '1');
    await frames(page);
    assert.deepEqual(await overflowing(page), [], 'every panel fits in 768×1024');
    assert.equal(await page.evaluate(() => window.matchMedia('(pointer: coarse)').matches), true, 'a touch screen');
    // Finger-sized buttons.
    const approve = await page.locator('#approve').boundingBox();
    assert.ok(approve.height >= 34, `approve is ${approve.height} px high`);

    // A tap on the second candidate's circle selects it.
    const box = await page.locator('#top-canvas').boundingBox();
    const target = await page.evaluate(() => {
      const c = window.scanplan.topView.candidates.find((k) => k.rank === 2);
      return { id: c.id, ...window.scanplan.topView.screenOf(c.x, c.y) };
    });
    await page.touchscreen.tap(box.x + target.x, box.y + target.y);
    await waitForData(page, 'the tapped candidate selected', (id) => window.scanplan.candidates.selected === id, target.id);

    // Two fingers spreading apart zoom in about their midpoint.
    const scale0 = await page.evaluate(() => window.scanplan.topView.scale);
    const cdp = await context.newCDPSession(page);
    const mx = box.x + box.width / 2;
    const my = box.y + box.height / 2;
    const fingers = (d) => [{ x: mx - d, y: my, id: 0 }, { x: mx + d, y: my, id: 1 }];
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: fingers(20) });
    for (const d of [30, 40, 50, 60]) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: fingers(d) });
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
    const scale1 = await page.evaluate(() => window.scanplan.topView.scale);
    assert.ok(scale1 / scale0 > 2.5 && scale1 / scale0 < 3.5, `pinch 40 → 120 px zoomed ×${(scale1 / scale0).toFixed(2)}`);
    assert.equal(await page.locator('#goal-bar').isVisible(), false, 'a pinch is not a tap: no point picked');
    await frames(page);
    t.diagnostic(`shot: ${await screenshot(page, 'tablet_768x1024.png')}`);
    assert.deepEqual(problems, { pageErrors: [], consoleErrors: [], foreignRequests: [] });
  }, { viewport: { width: 768, height: 1024 }, touch: true });
});
