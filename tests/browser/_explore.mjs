// scratch: screenshots at several sizes (not a test; deleted before commit)
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { requestScan, startStack, worldVariant, scanAndWait } from '../support/stack.mjs';
import { openPage, waitForData, withBrowser, frames, overflowing } from '../support/browser.mjs';
const { file } = worldVariant(mkdtempSync(join(tmpdir(), 'x-')), 'campus.json', {});
const stack = await startStack({ world: file, timeScale: 600 });
stack.startBridge(['--robot-id', 'robot2', '--start', '40,20,90']);
await stack.waitFor('both', async () => (await (await stack.api('GET', '/api/v1/health', { auth: null })).json()).bridges === 2 || undefined, 20000);
await requestScan(stack);
await stack.waitFor('plans', async () => { const c = await (await stack.api('GET', '/api/v1/candidates')).json(); return c.plans.length === 2 || undefined; }, 60000);
for (const [w, h, name, touch] of [[1366, 768, 'laptop', false], [1024, 768, 'small', false], [768, 1024, 'tablet', true], [390, 844, 'phone', true]]) {
  await withBrowser(async (context) => {
    const { page } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await page.setViewportSize({ width: w, height: h });
    await waitForData(page, 'drawn', () => Number(document.body.dataset.chunks) >= 1);
    await new Promise((r) => setTimeout(r, 1500));
    await frames(page);
    await page.screenshot({ path: `/tmp/shots/${name}.png` });
    console.log(name, JSON.stringify(await overflowing(page)));
  });
}
console.log(stack.url, stack.token);
await stack.stop();
