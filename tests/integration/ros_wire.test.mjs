// What a ROS 2 node sees: a plain Cyclone program built with only the ROS 2 types
// (ros_wire_listener) subscribes to the ROS-named topics of a running bridge + server and must
// get the bridge's scan and pose, and the server's thinned map, ranked candidates and approved
// goal, with the same content the REST API reports. A second listener joins late and must still
// be given the latest map, candidates and goal (transient-local).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startStack, scanAndWait, worldVariant } from '../support/stack.mjs';
import { startListener } from '../support/dds_listener.mjs';

const LISTENER = 'SCANPLAN_ROS_WIRE_LISTENER';
const FLOAT32 = 7;
let stack, early, worldDir;
const listeners = [];

before(async () => {
  // Exact reported poses, so the approved goal is reachable and the follow-up scan happens.
  worldDir = mkdtempSync(join(tmpdir(), 'scanplan-ros-wire-'));
  const { file } = worldVariant(worldDir, 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
  early = await startListener(LISTENER);
  listeners.push(early);
});
after(async () => {
  for (const l of listeners) await l.stop().catch(() => {});
  if (stack) await stack.stop();
  rmSync(worldDir, { recursive: true, force: true });
});

const get = async (path) => (await stack.api('GET', path)).json();
const last = (listener, topic) => listener.of(topic).at(-1);
const yawDeg = (p) => Math.atan2(2 * (p.qw * p.qz + p.qx * p.qy), 1 - 2 * (p.qy * p.qy + p.qz * p.qz)) * 180 / Math.PI;
const angleDiff = (a, b) => Math.abs(((a - b + 540) % 360) - 180);
// The heading the server gives a candidate: along the last leg of its path.
const approachYawDeg = (c) => {
  const n = c.path.length;
  if (n < 2) return 0;
  return Math.atan2(c.path[n - 1][1] - c.path[n - 2][1], c.path[n - 1][0] - c.path[n - 2][0]) * 180 / Math.PI;
};
const assertRecentStamp = (line) => {
  const ms = Number(BigInt(line.stamp_ns) / 1000000n);
  assert.ok(Math.abs(Date.now() - ms) < 120000, `${line.topic} stamped ${new Date(ms).toISOString()}: a real time`);
};

function assertXyzRgbCloud(m) {
  assert.ok(m.consistent, `${m.topic}: sizes and fields add up`);
  assert.deepEqual(m.fields.map((f) => f.name), ['x', 'y', 'z', 'rgb']);
  for (const f of m.fields) assert.equal(f.datatype, FLOAT32, `${f.name} is float32`);
  assert.equal(m.is_bigendian, false);
  assert.equal(m.height, 1);
  assert.equal(m.point_step, 16);
}

function assertMapMatchesSession(m, session) {
  assert.equal(m.frame_id, 'map');
  assertRecentStamp(m);
  assertXyzRgbCloud(m);
  assert.ok(m.points > 0, 'the map has points');
  assert.equal(m.finite, m.points);
  assert.ok(m.points < session.points, `thinned: ${m.points} of ${session.points} points`);
  assert.equal(m.colored, m.points, 'every map point carries a colour');
  for (let a = 0; a < 3; a++) {
    assert.ok(m.min[a] >= session.bounds.min[a] - 1e-4 && m.max[a] <= session.bounds.max[a] + 1e-4,
      `axis ${a}: map [${m.min[a]}, ${m.max[a]}] inside the session's [${session.bounds.min[a]}, ${session.bounds.max[a]}]`);
  }
}

function assertCandidatesMatch(line, rest) {
  assert.equal(line.frame_id, 'map');
  assertRecentStamp(line);
  assert.equal(line.poses.length, rest.candidates.length, 'one pose per candidate');
  rest.candidates.forEach((c, i) => {
    const p = line.poses[i];
    assert.equal(c.rank, i + 1, 'poses in rank order');
    assert.ok(Math.abs(p.x - c.x) < 1e-9 && Math.abs(p.y - c.y) < 1e-9 && Math.abs(p.z - c.z) < 1e-9,
      `candidate ${c.id}: pose (${p.x}, ${p.y}, ${p.z}) vs REST (${c.x}, ${c.y}, ${c.z})`);
    assert.ok(angleDiff(yawDeg(p), approachYawDeg(c)) < 1e-6, `candidate ${c.id} faces along its path`);
  });
}

test("the bridge's scan and pose reach a subscriber that knows only the ROS 2 types", async () => {
  await scanAndWait(stack, 1);
  const points = await early.waitFor('rt/scanner/points', (l) => l.topic === 'rt/scanner/points');
  const pose = await early.waitFor('rt/scanner/pose', (l) => l.topic === 'rt/scanner/pose');
  const [scan] = (await get('/api/v1/scans')).scans;

  assert.equal(points.frame_id, 'robot1/scanner', 'the robot id leads the frame');
  assertXyzRgbCloud(points);
  assert.equal(points.finite, scan.points, 'every point the server stored came over the wire');
  assert.equal(points.colored, 0, 'the laser alone sees no colour');
  assert.equal(points.stamp_ns, pose.stamp_ns, 'points and pose of one scan share a stamp');
  assertRecentStamp(points);

  assert.equal(pose.frame_id, 'robot1/map');
  assert.ok(Math.abs(pose.pose.x - scan.estimated.x) < 1e-9 && Math.abs(pose.pose.y - scan.estimated.y) < 1e-9 &&
    Math.abs(pose.pose.z - scan.estimated.z) < 1e-9, `pose ${JSON.stringify(pose.pose)} vs ${JSON.stringify(scan.estimated)}`);
  assert.ok(angleDiff(yawDeg(pose.pose), scan.estimated.yaw_deg) < 1e-6);
});

test('the thinned map and the ranked candidates, live and for a late joiner', async () => {
  const rest = await stack.waitFor('candidates for scan 1', async () => {
    const c = await get('/api/v1/candidates');
    return c.plan?.based_on_scan === 1 && c.candidates.length > 0 ? c : undefined;
  });
  const session = await get('/api/v1/session');
  await early.waitFor('the map', (l) => l.topic === 'rt/scanplan/map');
  await early.waitFor('the candidates', (l) => l.topic === 'rt/scanplan/candidates');
  assert.equal(early.of('rt/scanplan/map').length, 1, 'one map a scan');
  assertMapMatchesSession(last(early, 'rt/scanplan/map'), session);
  assertCandidatesMatch(last(early, 'rt/scanplan/candidates'), rest);

  const late = await startListener(LISTENER);
  listeners.push(late);
  const map = await late.waitFor('the latched map', (l) => l.topic === 'rt/scanplan/map');
  const poses = await late.waitFor('the latched candidates', (l) => l.topic === 'rt/scanplan/candidates');
  assert.deepEqual(map, last(early, 'rt/scanplan/map'), 'the late joiner gets the same map');
  assertCandidatesMatch(poses, rest);
  assert.equal(late.of('rt/scanplan/goal').length, 0, 'no goal before an approval');
  assert.equal(late.of('rt/scanner/points').length, 0, 'scans are not latched');
  await late.stop();
});

test('an approval publishes the goal; the scan that follows republishes map and candidates', async () => {
  const rest = await get('/api/v1/candidates');
  const chosen = rest.candidates[0];
  const approved = await stack.api('POST', `/api/v1/candidates/${chosen.id}/approve`);
  assert.equal(approved.status, 200, await approved.clone().text());
  const move = await approved.json();

  const goal = await early.waitFor('the goal', (l) => l.topic === 'rt/scanplan/goal');
  assert.equal(goal.frame_id, 'map');
  assertRecentStamp(goal);
  assert.ok(Math.abs(goal.pose.x - chosen.x) < 1e-9 && Math.abs(goal.pose.y - chosen.y) < 1e-9 &&
    Math.abs(goal.pose.z - chosen.z) < 1e-9, `goal ${JSON.stringify(goal.pose)} is candidate ${chosen.id}`);
  assert.ok(angleDiff(yawDeg(goal.pose), move.yaw_deg) < 1e-6, 'facing as the move command says');

  const late = await startListener(LISTENER);
  listeners.push(late);
  const lateGoal = await late.waitFor('the latched goal', (l) => l.topic === 'rt/scanplan/goal');
  assert.deepEqual(lateGoal.pose, goal.pose);
  await late.stop();

  // The robot arrives, the server asks for the scan, and the map and plan are published again.
  const next = await stack.waitFor('the plan after scan 2', async () => {
    const c = await get('/api/v1/candidates');
    return c.plan?.based_on_scan === 2 ? c : undefined;
  }, 90000);
  await early.waitFor('a second map', (l, i) => l.topic === 'rt/scanplan/map' && early.of('rt/scanplan/map').length >= 2);
  await early.waitFor('a second plan', (l) => l.topic === 'rt/scanplan/candidates' && early.of('rt/scanplan/candidates').length >= 2);
  const [first, second] = early.of('rt/scanplan/map');
  assert.ok(second.points > first.points, `the map grew: ${first.points} → ${second.points} points`);
  assertMapMatchesSession(second, await get('/api/v1/session'));
  assertCandidatesMatch(last(early, 'rt/scanplan/candidates'), next);
  assert.equal(early.of('rt/scanner/points').length, 2, 'the second scan went over the wire too');
});
