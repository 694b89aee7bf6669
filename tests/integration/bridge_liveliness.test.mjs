// A bridge that vanishes mid-scan (SIGKILL: no goodbye on DDS) is noticed through its
// liveliness lease within seconds: the operator gets robot_lost and scan_failed, the session shows
// the robot disconnected, nothing half-received reaches the map, and an approved move is freed.
// A new bridge with the same robot id brings the robot back, and scans and moves work again. A
// bridge stopped cleanly says goodbye and is reported as shut down.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { startStack, requestScan, scanAndWait, requireEnv } from '../support/stack.mjs';

const webRequire = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'));
const WebSocket = webRequire('ws');

// The bridge's DDS liveliness lease (msgs dds_participant.hpp kBridgeLivelinessLease).
const LEASE_MS = 2000;
const LOST_REASON = 'bridge lost during the scan';

let stack;
let ws;
let bridge;  // the bridge serving robot1 now
const events = [];
before(async () => {
  // 10 simulated seconds per second: the one-minute scan takes about 6 s, with progress.
  stack = await startStack({ timeScale: 10 });
  bridge = stack.bridge;
  ws = new WebSocket(`${stack.url.replace('http', 'ws')}/api/v1/events?token=${stack.viewerToken}`);
  await new Promise((resolve, reject) => { ws.on('open', resolve); ws.on('error', reject); });
  ws.on('message', (data, isBinary) => {
    if (!isBinary) events.push({ ...JSON.parse(data.toString()), receivedAt: Date.now() });
  });
});
after(async () => {
  ws?.close();
  if (stack) await stack.stop();
});

const session = async () => (await stack.api('GET', '/api/v1/session')).json();
const event = (what, pred, timeoutMs = 30000) =>
  stack.waitFor(what, async () => events.find(pred), timeoutMs);

// The session's event log (session.sqlite), read beside the running server (WAL allows it).
function loggedKinds() {
  const sqlite = process.env.SCANPLAN_SQLITE3;
  if (!sqlite) return null;
  const out = execFileSync(sqlite, ['-readonly', '-json', join(stack.dir, 'session', 'session.sqlite'),
    'SELECT kind, json FROM events ORDER BY id'], { encoding: 'utf8' });
  return out.trim() ? JSON.parse(out) : [];
}

async function killBridgeAndMeasure() {
  const killedAt = Date.now();
  bridge.kill('SIGKILL');
  const lost = await event('robot_lost', (e) => e.type === 'robot_lost' && e.receivedAt >= killedAt, 15000);
  return { lost, detectedMs: lost.receivedAt - killedAt };
}

test('a bridge killed mid-scan is lost, its scan fails, and nothing reaches the map', async (t) => {
  await stack.waitFor('robot1 in the session', async () => (await session()).robots.robot1);
  assert.equal((await session()).robots.robot1.connected, true);
  assert.equal((await session()).robots.robot1.lost_at, null);

  const command = await requestScan(stack);
  await event('the scan running', (e) => e.type === 'scan_progress' && e.command_id === command &&
    e.state === 'scanning' && e.fraction >= 0.1);

  const { lost, detectedMs } = await killBridgeAndMeasure();
  t.diagnostic(`SIGKILL noticed after ${detectedMs} ms (lease ${LEASE_MS} ms)`);
  assert.ok(detectedMs < LEASE_MS + 3000, `lost after ${detectedMs} ms`);
  assert.equal(lost.robot, 'robot1');
  assert.match(lost.reason, /liveliness/);

  const failed = await event('scan_failed', (e) => e.type === 'scan_failed', 5000);
  assert.equal(failed.robot, 'robot1');
  assert.equal(failed.command_id, command);
  assert.equal(failed.reason, LOST_REASON);
  assert.ok(failed.fraction >= 0.1 && failed.fraction < 1, `failed at ${failed.fraction}`);

  const s = await session();
  const robot = s.robots.robot1;
  assert.equal(robot.connected, false);
  assert.match(robot.lost_at, /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$/);
  assert.equal(robot.lost_reason, lost.reason);
  assert.equal(robot.scan.state, 'failed');
  assert.equal(robot.scan.message, LOST_REASON);
  // DDS keeps the dead bridge matched until its participant lease ends; it must not count.
  assert.equal(s.bridges, 0);
  assert.equal((await (await stack.api('GET', '/api/v1/health', { auth: null })).json()).bridges, 0);

  const toLost = await stack.api('POST', '/api/v1/scan?robot=robot1');
  assert.equal(toLost.status, 503);
  assert.match((await toLost.json()).error.message, /robot 'robot1' is not connected/);
  assert.equal((await stack.api('POST', '/api/v1/scan')).status, 503);

  // Long enough for any straggling part to have been stored, were it accepted.
  await new Promise((r) => setTimeout(r, 3000));
  const scans = await (await stack.api('GET', '/api/v1/scans')).json();
  assert.deepEqual(scans, { scans: [], pending: 0, excluded: [], not_in_map: [] });
  assert.equal((await session()).scans, 0);
  assert.ok(!events.some((e) => e.type === 'scan_received'), 'no scan was received');

  const kinds = loggedKinds();
  if (kinds === null) {
    t.diagnostic('sqlite3 not found: the event log is not checked');
  } else {
    const lostRow = kinds.find((k) => k.kind === 'robot_lost');
    assert.ok(lostRow, JSON.stringify(kinds));
    assert.equal(JSON.parse(lostRow.json).robot, 'robot1');
    const failedRow = kinds.find((k) => k.kind === 'scan_failed');
    assert.equal(JSON.parse(failedRow.json).reason, LOST_REASON);
  }
});

test('a new bridge with the same robot id brings the robot back and scans again', async () => {
  const since = Date.now();
  bridge = stack.startBridge();
  const back = await event('robot_back', (e) => e.type === 'robot_back' && e.receivedAt >= since, 20000);
  assert.equal(back.robot, 'robot1');
  const robot = (await session()).robots.robot1;
  assert.equal(robot.connected, true);
  assert.equal(robot.lost_at, null);

  const s = await scanAndWait(stack, 1);
  assert.equal(s.scans, 1);
  assert.equal(s.last_scan.robot, 'robot1');
  const kinds = loggedKinds();
  if (kinds !== null) assert.ok(kinds.some((k) => k.kind === 'robot_back'), JSON.stringify(kinds));
});

test('a move cut short by a lost bridge is freed and can be approved again', async (t) => {
  const plan = await stack.waitFor('candidates', async () => {
    const c = await (await stack.api('GET', '/api/v1/candidates')).json();
    return c.candidates.length > 0 && c.plan.based_on_scan === 1 ? c : undefined;
  });
  // The farthest candidate: the drive there lasts longest.
  const target = plan.candidates.reduce((a, b) => (b.travel_m > a.travel_m ? b : a));
  const since = Date.now();
  const approved = await stack.api('POST', `/api/v1/candidates/${target.id}/approve`);
  assert.equal(approved.status, 200, await approved.clone().text());
  const move = await approved.json();
  await event('the robot moving', (e) => e.type === 'robot_status' && e.command_id === move.command_id &&
    e.state === 'moving');
  const { detectedMs } = await killBridgeAndMeasure();
  t.diagnostic(`SIGKILL during a move noticed after ${detectedMs} ms`);
  const interrupted = await event('the move interrupted', (e) => e.type === 'mission' &&
    e.kind === 'interrupted' && e.receivedAt >= since, 5000);
  assert.equal(interrupted.candidate, target.id);
  assert.ok(!events.some((e) => e.type === 'mission' && e.kind === 'arrived' && e.receivedAt >= since),
    'the robot did not arrive');
  const after = await (await stack.api('GET', '/api/v1/candidates')).json();
  const c = after.candidates.find((x) => x.id === target.id);
  assert.equal(c.state, 'interrupted');
  assert.match(c.note, /interrupted/);
  const whileLost = await stack.api('POST', `/api/v1/candidates/${target.id}/approve`);
  assert.equal(whileLost.status, 503);

  const backSince = Date.now();
  bridge = stack.startBridge();
  await event('robot_back', (e) => e.type === 'robot_back' && e.receivedAt >= backSince, 20000);
  const again = await stack.api('POST', `/api/v1/candidates/${target.id}/approve`);
  assert.equal(again.status, 200, await again.clone().text());
  // The arrival asks for the scan itself: the mission is not stuck waiting on the dead bridge.
  const s = await stack.waitFor('scan 2 after the approved move', async () => {
    const x = await session();
    return x.scans >= 2 ? x : undefined;
  }, 90000);
  assert.ok(Math.hypot(s.last_scan.pose.x - target.x, s.last_scan.pose.y - target.y) < 5,
    `scanned near the goal: ${JSON.stringify(s.last_scan.pose)}`);
});

test('a bridge that shuts down says goodbye and is lost at once, without a scan to fail', async () => {
  const since = Date.now();
  bridge.kill('SIGTERM');
  // Not stack.waitFor: that fails as soon as a watched process exits, as this one will.
  let lost;
  for (const deadline = Date.now() + 10000; !lost && Date.now() < deadline;) {
    await new Promise((r) => setTimeout(r, 50));
    lost = events.find((e) => e.type === 'robot_lost' && e.receivedAt >= since);
  }
  assert.ok(lost, 'robot_lost after SIGTERM');
  assert.equal((await bridge.exited).code, 0, 'the bridge stopped cleanly');
  assert.equal(lost.reason, 'the bridge shut down');
  assert.ok(lost.receivedAt - since < 1500, `lost after ${lost.receivedAt - since} ms`);
  const offline = events.find((e) => e.type === 'robot_status' && e.state === 'offline' && e.receivedAt >= since);
  assert.ok(offline && events.indexOf(offline) < events.indexOf(lost), 'the goodbye came first');
  await new Promise((r) => setTimeout(r, 500));
  assert.ok(!events.some((e) => e.type === 'scan_failed' && e.receivedAt >= since), 'no scan was running');
  const robot = (await session()).robots.robot1;
  assert.equal(robot.connected, false);
  assert.equal(robot.state, 'offline');
});
