// The server's map follows the pose graph (issue 17) and a restart resumes it: four recorded
// campus scans posted with drifting odometry; the graph ties scans in, moves or sets them aside
// (map_corrected on the WebSocket, each a pose revision in the session); a scan waiting
// outside the map is not in the map's points; after a restart every scan is back where the
// map had it, in the map or waiting as before.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { startStack, requireEnv } from '../support/stack.mjs';

const webRequire = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'));
const WebSocket = webRequire('ws');

const script = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/replays/campus/campus.replay.json');
// The script's scans that are stored (201), with the poses they are posted at.
const uploads = JSON.parse(readFileSync(script, 'utf8')).steps
  .filter((s) => s.request.method === 'POST' && s.expect?.status === 201)
  .map((s) => ({ path: s.request.path, body: readFileSync(join(dirname(script), s.request.body_file)) }));

let stack;
after(async () => stack && (await stack.stop()));

async function scansWhenIdle(s, count) {
  return s.waitFor(`${count} scans processed`, async () => {
    const a = await (await s.api('GET', '/api/v1/scans')).json();
    const session = await (await s.api('GET', '/api/v1/session')).json();
    return a.scans.length === count && a.pending === 0 && !session.rebuilding ? a : undefined;
  }, 120000);
}

test('corrections are announced and recorded, and a restart resumes them', { timeout: 300000 }, async () => {
  stack = await startStack({ bridge: false, odometry: 'drift' });
  const ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
  await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
  const events = [];
  ws.on('message', (data, isBinary) => { if (!isBinary) events.push(JSON.parse(data.toString())); });

  assert.equal(uploads.length, 4);
  for (const u of uploads) {
    const r = await stack.api('POST', u.path, { body: u.body });
    assert.equal(r.status, 201, await r.text());
  }
  const before = await scansWhenIdle(stack, 4);
  await stack.waitFor('the last map_updated', async () =>
    events.filter((e) => e.type === 'map_updated').length === 4, 30000);
  ws.close();

  const corrected = events.filter((e) => e.type === 'map_corrected');
  assert.ok(corrected.length >= 1, 'the graph changed the map after some scan');
  for (const c of corrected) {
    assert.ok(c.revision >= 1, `recorded as a pose revision: ${JSON.stringify(c)}`);
    assert.ok(c.scans.length + c.joined.length + c.left.length > 0);
  }
  // And in the mission's record, where a page that reloads reads its log back from.
  const { decisions } = await (await stack.api('GET', '/api/v1/decisions')).json();
  const recorded = decisions.filter((d) => d.kind === 'map_corrected');
  assert.deepEqual(recorded.map((d) => d.revision), corrected.map((c) => c.revision));
  assert.deepEqual(recorded.map((d) => d.joined), corrected.map((c) => c.joined));
  // map_updated and the scan list agree on which scans wait outside the map, and a waiting
  // scan's points are not in the map's.
  const waiting = before.scans.filter((s) => !s.in_map);
  const session = await (await stack.api('GET', '/api/v1/session')).json();
  const inMapPoints = before.scans.filter((s) => s.in_map).reduce((n, s) => n + s.points, 0);
  assert.equal(session.points, inMapPoints);
  assert.ok(before.scans[0].in_map, 'the first scan is the map frame');

  // A restart on the same session retraces the graph: every scan where it was.
  await stack.stop({ keepDir: true });
  stack = await startStack({ bridge: false, odometry: 'drift', dir: stack.dir,
                             tokens: { operator: stack.token, viewer: stack.viewerToken } });
  const again = await scansWhenIdle(stack, 4);
  for (const [k, s] of again.scans.entries()) {
    const b = before.scans[k];
    assert.equal(s.in_map, b.in_map, `scan ${s.id} in the map as before`);
    const moved = Math.hypot(s.placed.x - b.placed.x, s.placed.y - b.placed.y, s.placed.z - b.placed.z);
    assert.ok(moved < 0.02, `scan ${s.id} is ${moved.toFixed(3)} m from where it was before the restart`);
  }
  assert.deepEqual(again.scans.filter((s) => !s.in_map).map((s) => s.id), waiting.map((s) => s.id));
});
