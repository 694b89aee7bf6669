// Two simulated robots (two bridges, robot1 and robot2) on one DDS domain and one server: one
// map from both, one plan per robot with no two robots sent to the same spot, each robot's move
// approved on its own, and each robot's plan and goal on its own ROS 2-namespaced topics.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startStack, worldVariant, scratchDir } from '../support/stack.mjs';
import { startListener } from '../support/dds_listener.mjs';

// robot1 starts at the yard's start (-15, -8); robot2 in the south-east corner, across the yard.
const ROBOT2_START = [22, -16, 90];
const KEEP_APART_M = 10; // PlannerConfig::claim_separation_m

let stack;
let listener;
before(async () => {
  const { file } = worldVariant(scratchDir('scanplan-robots-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  // Slow enough (a 30 m drive takes 3 s) that robot1 is still driving when robot2 is approved.
  stack = await startStack({ world: file, timeScale: 20 });
  stack.startBridge(['--robot-id', 'robot2', '--start', ROBOT2_START.join(',')]);
  await stack.waitFor('both bridges on DDS', async () => {
    const h = await (await stack.api('GET', '/api/v1/health', { auth: null })).json();
    return h.bridges === 2;
  }, 20000);
  listener = await startListener('SCANPLAN_ROS_WIRE_LISTENER', { robots: ['robot1', 'robot2'] });
});
after(async () => {
  await listener?.stop().catch(() => {});
  if (stack) await stack.stop();
});

const candidates = async (query = '') => (await stack.api('GET', `/api/v1/candidates${query}`)).json();
const session = async () => (await stack.api('GET', '/api/v1/session')).json();
const scans = async () => (await (await stack.api('GET', '/api/v1/scans')).json()).scans;
const dist = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);

test('one scan command reaches both robots and both scans join one map', async () => {
  const r = await stack.api('POST', '/api/v1/scan');
  assert.equal(r.status, 202);
  assert.equal((await r.json()).robot, '*');
  await stack.waitFor('a scan from each robot', async () => ((await session()).scans >= 2 ? true : undefined));
  const list = await scans();
  assert.deepEqual(list.map((s) => s.robot).sort(), ['robot1', 'robot2']);
  const by = Object.fromEntries(list.map((s) => [s.robot, s]));
  assert.ok(dist(by.robot1.placed, { x: -15, y: -8 }) < 0.01, JSON.stringify(by.robot1.placed));
  assert.ok(dist(by.robot2.placed, { x: ROBOT2_START[0], y: ROBOT2_START[1] }) < 0.01, JSON.stringify(by.robot2.placed));
});

test('each robot gets a plan of its own, and the second keeps away from the first one\'s choice', async () => {
  const answer = await stack.waitFor('a plan for each robot after scan 2', async () => {
    const c = await candidates();
    return c.plans.length === 2 && c.plans.every((p) => p.based_on_scan === 2) ? c : undefined;
  });
  assert.deepEqual(answer.plans.map((p) => p.robot).sort(), ['robot1', 'robot2']);
  // The robots were decided one after another: the one decided second keeps all its candidates
  // away from the first one's best point.
  const [first, second] = answer.plans;
  assert.equal(answer.plan.id, first.id);
  const bestOf = (robot) => answer.candidates.find((c) => c.robot === robot && c.rank === 1);
  const apart = (from, to) => answer.candidates.filter((c) => c.robot === from).every((c) => dist(c, bestOf(to)) >= KEEP_APART_M);
  assert.ok(bestOf('robot1') && bestOf('robot2'), JSON.stringify(answer.candidates));
  assert.ok(dist(bestOf('robot1'), bestOf('robot2')) >= KEEP_APART_M, 'the two best points are apart');
  assert.ok(apart('robot1', 'robot2') || apart('robot2', 'robot1'), JSON.stringify(answer.candidates));
  for (const c of answer.candidates) assert.equal(c.plan, c.robot === first.robot ? first.id : second.id);
  // ?robot= narrows the answer to one robot's plan.
  const only2 = await candidates('?robot=robot2');
  assert.deepEqual(only2.plans.map((p) => p.robot), ['robot2']);
  assert.ok(only2.candidates.every((c) => c.robot === 'robot2'));
  assert.equal((await candidates('?robot=robot9')).plan, null);

  // Each robot's plan on its own latched topic, in the order and positions of the REST answer.
  for (const p of answer.plans) {
    const own = answer.candidates.filter((c) => c.robot === p.robot);
    const sample = await listener.waitFor(`rt/${p.robot}/scanplan/candidates`, (l) =>
      l.topic === `rt/${p.robot}/scanplan/candidates` && l.poses.length === own.length &&
      l.poses.every((q, i) => Math.abs(q.x - own[i].x) < 1e-6 && Math.abs(q.y - own[i].y) < 1e-6));
    assert.equal(sample.frame_id, 'map');
  }
});

test('each robot\'s move is approved on its own, and never to where the other is going', async () => {
  const answer = await candidates();
  const c1 = answer.candidates.find((c) => c.robot === 'robot1' && c.rank === 1);
  const approved = await stack.api('POST', `/api/v1/candidates/${c1.id}/approve`, { body: JSON.stringify({ by: 'Ann' }) });
  assert.equal(approved.status, 200, await approved.clone().text());
  assert.equal((await approved.json()).robot, 'robot1');

  // robot2 may not be sent to robot1's goal, even by hand (the yard is one open floor, so the
  // point itself is a valid custom goal for robot2).
  const goal = await stack.api('POST', '/api/v1/goals', { body: JSON.stringify({ x: c1.x, y: c1.y, robot: 'robot2' }) });
  assert.equal(goal.status, 201, await goal.clone().text());
  const custom = await goal.json();
  assert.equal(custom.robot, 'robot2');
  const refused = await stack.api('POST', `/api/v1/candidates/${custom.id}/approve`);
  assert.equal(refused.status, 409);
  assert.match((await refused.json()).error.message, /robot1.*already going/);
  const unknown = await stack.api('POST', '/api/v1/goals', { body: JSON.stringify({ x: 0, y: 0, robot: 'robot9' }) });
  assert.equal(unknown.status, 400);
  assert.equal((await unknown.json()).error.code, 'unknown_robot');

  // robot1 drives; robot2 is still free to be sent elsewhere.
  const c2 = (await candidates('?robot=robot2')).candidates.find((c) => c.state === 'proposed' && dist(c, c1) >= KEEP_APART_M);
  assert.ok(c2, 'robot2 has a candidate away from robot1\'s goal');
  const second = await stack.api('POST', `/api/v1/candidates/${c2.id}/approve`, { body: JSON.stringify({ by: 'Ann' }) });
  assert.equal(second.status, 200, await second.clone().text());
  assert.equal((await second.json()).robot, 'robot2');

  // Both arrive and scan there (the server asks for each scan on arrival).
  await stack.waitFor('a scan at each approved point', async () => ((await session()).scans >= 4 ? true : undefined), 90000);
  const list = await scans();
  const last1 = list.filter((s) => s.robot === 'robot1').at(-1);
  const last2 = list.filter((s) => s.robot === 'robot2').at(-1);
  assert.ok(dist(last1.placed, c1) < 0.01, `robot1 scanned at ${JSON.stringify(last1.placed)}`);
  assert.ok(dist(last2.placed, c2) < 0.01, `robot2 scanned at ${JSON.stringify(last2.placed)}`);

  // Each goal went out on the robot's own topic (and the newest on the shared one).
  for (const [robot, c] of [['robot1', c1], ['robot2', c2]]) {
    await listener.waitFor(`rt/${robot}/scanplan/goal`, (l) =>
      l.topic === `rt/${robot}/scanplan/goal` && Math.abs(l.pose.x - c.x) < 1e-6 && Math.abs(l.pose.y - c.y) < 1e-6);
  }
  const decisions = (await (await stack.api('GET', '/api/v1/decisions?limit=50')).json()).decisions;
  const approvals = decisions.filter((d) => d.kind === 'approve');
  assert.deepEqual(approvals.map((d) => d.robot), ['robot1', 'robot2']);
  assert.ok(approvals.every((d) => d.by === 'operator Ann'));
});
