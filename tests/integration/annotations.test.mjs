// Annotations (victim, hazard, blocked, note): validated on POST with 400s that name the field,
// operator-only to change, stored, announced on the WebSocket and published on DDS
// (scanplan_Annotation, transient-local: a late joiner gets the live ones, not deleted ones).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { startStack, requireEnv } from '../support/stack.mjs';
import { startListener } from '../support/dds_listener.mjs';

const webRequire = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'));
const WebSocket = webRequire('ws');
const LISTENER = 'SCANPLAN_ANNOTATION_LISTENER';

let stack, ws, early;
const events = [];
before(async () => {
  stack = await startStack({ bridge: false });
  ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
  await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
  ws.on('message', (data, isBinary) => { if (!isBinary) events.push(JSON.parse(data.toString())); });
  early = await startListener(LISTENER);
});
after(async () => {
  ws?.close();
  await early?.stop().catch(() => {});
  if (stack) await stack.stop();
});

const post = (body, auth) => stack.api('POST', '/api/v1/annotations', {
  auth, body: typeof body === 'string' ? body : JSON.stringify(body),
});
const list = async () => (await (await stack.api('GET', '/api/v1/annotations', { auth: stack.viewerToken })).json()).annotations;

async function refused(body, status, pattern) {
  const r = await post(body);
  assert.equal(r.status, status, `${JSON.stringify(body)} → ${status}`);
  const { error } = await r.json();
  if (status === 400) assert.equal(error.code, 'bad_request');
  assert.match(error.message, pattern, JSON.stringify(body));
}

test('bad annotations are refused naming the field, and nothing is stored', async () => {
  const ok = { kind: 'hazard', x: 1, y: 2, z: 0 };
  await refused({ ...ok, kind: 'rubble' }, 400, /'kind'.*victim.*hazard.*blocked.*note/);
  await refused({ x: 1, y: 2, z: 0 }, 400, /'kind'/);
  await refused({ ...ok, kind: 7 }, 400, /'kind'/);
  await refused({ kind: 'hazard', y: 2, z: 0 }, 400, /'x' is required/);
  await refused({ ...ok, y: '2' }, 400, /'y' must be a finite number/);
  await refused({ ...ok, z: null }, 400, /'z' must be a finite number/);
  await refused({ ...ok, x: 1e7 }, 400, /'x'/);
  await refused('{"kind":"hazard","x":1e999,"y":2,"z":0}', 400, /not valid JSON.*overflow/);
  await refused({ ...ok, text: 'a'.repeat(1001) }, 400, /'text' is too long: 1001 bytes, at most 1000/);
  await refused({ ...ok, text: 5 }, 400, /'text' must be a string/);
  await refused({ kind: 'note', x: 1, y: 2, z: 0 }, 400, /'text' is required for a note/);
  await refused({ ...ok, colour: 'red' }, 400, /unknown field 'colour'/);
  await refused({ ...ok, by: '' }, 400, /'by'/);
  await refused('[1, 2]', 400, /JSON object/);
  await refused('{"kind": "hazard", "x": 1', 400, /not valid JSON/);
  await refused('', 400, /not valid JSON/);
  const viewer = await post(ok, stack.viewerToken);
  assert.equal(viewer.status, 403);
  const anonymous = await post(ok, null);
  assert.equal(anonymous.status, 401);
  assert.equal((await stack.api('GET', '/api/v1/annotations', { auth: null })).status, 401);
  assert.deepEqual(await list(), []);
  assert.equal(early.of('scanplan_Annotation').length, 0, 'nothing refused was published');
  // The server is still answering.
  assert.equal((await stack.api('GET', '/api/v1/health', { auth: null })).status, 200);
});

test('an annotation is stored, announced on the WebSocket and published on DDS', async () => {
  const text = 'two adults, one trapped under the stairs — responsive';
  const r = await post({ kind: 'victim', x: 12.5, y: -3.25, z: 0.4, text, by: 'Ann' });
  assert.equal(r.status, 201);
  const a = await r.json();
  assert.equal(a.id, 1);
  assert.equal(a.kind, 'victim');
  assert.deepEqual([a.x, a.y, a.z], [12.5, -3.25, 0.4]);
  assert.equal(a.text, text);
  assert.equal(a.author, 'operator Ann', 'recorded as decisions are');
  assert.ok(Math.abs(Date.parse(a.created_at) - Date.now()) < 60000, a.created_at);
  assert.deepEqual(await list(), [a], 'a viewer reads it back');

  const event = await stack.waitFor('the annotation event', async () => events.find((e) => e.type === 'annotation'), 10000);
  assert.deepEqual({ ...event, type: undefined, at: undefined }, { ...a, type: undefined, at: undefined });

  const sample = await early.waitFor('the DDS sample', (l) => l.topic === 'scanplan_Annotation' && l.id === a.id);
  assert.equal(sample.kind, 'victim');
  assert.deepEqual([sample.x, sample.y, sample.z], [12.5, -3.25, 0.4]);
  assert.equal(sample.text, text);
  assert.equal(sample.author, 'operator Ann');
  assert.equal(Math.floor(Number(BigInt(sample.stamp_ns) / 1000000n) / 1000), Math.floor(Date.parse(a.created_at) / 1000),
    'stamped when it was made');

  const hazard = await (await post({ kind: 'hazard', x: 3, y: 4, z: 0 })).json();
  assert.equal(hazard.id, 2);
  assert.equal(hazard.author, 'operator');
  assert.equal(hazard.text, '');
});

test('a deletion is announced, disposed on DDS and not given to late joiners', async () => {
  assert.equal((await stack.api('DELETE', '/api/v1/annotations/2', { auth: stack.viewerToken })).status, 403);
  assert.equal((await stack.api('DELETE', '/api/v1/annotations/abc')).status, 400);
  assert.equal((await stack.api('DELETE', '/api/v1/annotations/99')).status, 404);
  const r = await stack.api('DELETE', '/api/v1/annotations/2', { body: JSON.stringify({ by: 'Bob' }) });
  assert.equal(r.status, 200);
  assert.deepEqual(await r.json(), { id: 2, deleted: true, by: 'operator Bob' });
  assert.equal((await stack.api('DELETE', '/api/v1/annotations/2')).status, 404, 'already deleted');
  assert.deepEqual((await list()).map((a) => a.id), [1]);
  await stack.waitFor('the deletion event', async () =>
    events.find((e) => e.type === 'annotation_deleted' && e.id === 2 && e.by === 'operator Bob'), 10000);
  await early.waitFor('the disposal', (l) => l.disposed === 2);

  const late = await startListener(LISTENER);
  try {
    await late.waitFor('annotation 1', (l) => l.id === 1);
    // Give a deleted annotation time to show up if it were (wrongly) still kept for late joiners.
    await new Promise((res) => setTimeout(res, 1000));
    // It may be told that 2 was disposed (the writer may still hold the disposal for it), but
    // it is never given annotation 2 itself.
    const samples = late.of('scanplan_Annotation');
    assert.deepEqual(samples.filter((l) => l.disposed === undefined).map((l) => l.id), [1]);
    assert.ok(samples.every((l) => l.disposed === undefined || l.disposed === 2), JSON.stringify(samples));
  } finally {
    await late.stop();
  }
  const third = await (await post({ kind: 'blocked', x: 0, y: 0, z: 0 })).json();
  assert.equal(third.id, 3, 'ids are not reused');
});
