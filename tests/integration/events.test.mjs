// GET /api/v1/events: the WebSocket a browser keeps open. A scan produces progress, reception,
// map and plan events in text frames, and the scan's own points as a binary Draco chunk
// ([u8 op][u32 id][u64 ns][payload]); map.drc?since=ID serves the same new points over REST.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { startStack, scanAndWait, requireEnv } from '../support/stack.mjs';

const webRequire = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'));
const WebSocket = webRequire('ws');
const draco3d = webRequire('draco3d');

async function drcPoints(bytes) {
  const m = await draco3d.createDecoderModule({});
  const decoder = new m.Decoder();
  const buffer = new m.DecoderBuffer();
  buffer.Init(new Int8Array(bytes), bytes.byteLength);
  const pc = new m.PointCloud();
  assert.ok(decoder.DecodeBufferToPointCloud(buffer, pc).ok());
  const n = pc.num_points();
  m.destroy(pc); m.destroy(buffer); m.destroy(decoder);
  return n;
}

let stack;
before(async () => { stack = await startStack(); });
after(async () => stack && (await stack.stop()));

test('a token is required', async () => {
  const ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events`);
  const status = await new Promise((resolve) => {
    ws.on('unexpected-response', (_req, res) => resolve(res.statusCode));
    ws.on('open', () => resolve('open'));
  });
  assert.equal(status, 401);
});

test('a scan arrives as events and a binary map chunk', async () => {
  const ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
  await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
  const events = [];
  const chunks = [];
  ws.on('message', (data, isBinary) => {
    if (isBinary) chunks.push(Buffer.from(data));
    else events.push(JSON.parse(data.toString()));
  });
  const session = await scanAndWait(stack, 1);
  await stack.waitFor('plan_done, the chunk and map_updated', async () =>
    events.some((e) => e.type === 'plan_done') && chunks.length > 0 && events.some((e) => e.type === 'map_updated'), 30000);
  ws.close();

  const types = new Set(events.map((e) => e.type));
  for (const t of ['scan_progress', 'scan_received', 'map_updated', 'plan_done']) assert.ok(types.has(t), t);
  const done = events.find((e) => e.type === 'scan_progress' && e.state === 'done');
  assert.equal(done.fraction, 1);
  const updated = events.find((e) => e.type === 'map_updated');
  assert.equal(updated.scan, 1);
  // Where the server's time went: every stage is a duration, and the plan is the planner's.
  for (const stage of ['match', 'graph', 'map', 'thin', 'plan', 'layers']) {
    assert.ok(updated.stages_ms[stage] >= 0 && updated.stages_ms[stage] < 60000, `${stage}: ${updated.stages_ms[stage]}`);
  }
  assert.ok(updated.stages_ms.plan >= events.find((e) => e.type === 'plan_done').plan_ms);

  const chunk = chunks[0];
  assert.equal(chunk.readUInt8(0), 1, 'op 1: map chunk');
  assert.equal(chunk.readUInt32LE(1), 1, 'scan id');
  const sentNs = chunk.readBigUInt64LE(5);
  assert.ok(Number(sentNs / 1000000n) > Date.now() - 60000, 'send time in ns since the epoch');
  assert.equal(await drcPoints(chunk.subarray(13)), session.points);
});

test('map.drc?since=ID sends only what is new', async () => {
  await scanAndWait(stack, 2);
  const all = await stack.api('GET', '/api/v1/map.drc');
  assert.equal(all.headers.get('x-scanplan-last-scan'), '2');
  const total = await drcPoints(await all.arrayBuffer());
  const first = await drcPoints(await (await stack.api('GET', '/api/v1/map.drc?since=0')).arrayBuffer());
  assert.equal(first, total);
  const scans = (await (await stack.api('GET', '/api/v1/scans')).json()).scans;
  const onlySecond = await stack.api('GET', '/api/v1/map.drc?since=1');
  assert.equal(await drcPoints(await onlySecond.arrayBuffer()), scans[1].points);
  const nothing = await stack.api('GET', '/api/v1/map.drc?since=2');
  assert.equal(nothing.status, 204);
  assert.equal((await stack.api('GET', '/api/v1/map.drc?since=-3')).status, 400);
});
