// What the operator page needs from the server beyond the planner's loop: the operator's own scan
// point (POST /api/v1/goals, checked against the movable region and approved like a candidate),
// the record of decisions (GET /api/v1/decisions), where the top-view layers lie in the map, the
// caller's role, each scan's areas for the coverage chart, and map.drc?since=&until= for one scan.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { scanAndWait, startStack, worldVariant, scratchDir } from '../support/stack.mjs';

let stack;
before(async () => {
  const { file } = worldVariant(scratchDir('scanplan-goals-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
});
after(async () => stack && (await stack.stop()));

const json = async (r) => ({ status: r.status, body: await r.json() });
const goal = (body, auth) => stack.api('POST', '/api/v1/goals', { body: JSON.stringify(body), auth }).then(json);

test('no goal before there is a map', async () => {
  const r = await goal({ x: -10, y: -8 });
  assert.equal(r.status, 409);
  assert.equal(r.body.error.code, 'no_map');
  const s = await json(await stack.api('GET', '/api/v1/session'));
  assert.equal(s.body.role, 'operator');
  assert.equal(s.body.layers, undefined, 'no layers before the first scan');
  assert.equal((await json(await stack.api('GET', '/api/v1/session', { auth: stack.viewerToken }))).body.role, 'viewer');
});

test('a custom goal is checked against the movable region, proposed, approved and scanned', async () => {
  await scanAndWait(stack, 1);
  await stack.waitFor('the first plan', async () => (await json(await stack.api('GET', '/api/v1/candidates'))).body.plan);

  // Refusals name the reason; nothing is added to the plan.
  const refusals = [
    [{ y: 1 }, 'bad_request', /'x' is required/],
    [{ x: 'a', y: 1 }, 'bad_request', /'x' is required: a finite number/],
    [{ x: 1, y: 1, z: 0 }, 'bad_request', /unknown field 'z'/],
    [{ x: -10, y: -8, robot: 'robot9' }, 'unknown_robot', /robot9' has no plan/],
    [{ x: 150, y: 150 }, 'outside_target', /outside the target region/],
    [{ x: 14, y: 6 }, 'no_data', /not been scanned/], // inside the building
    [{ x: -17.4, y: 8.6 }, 'not_movable', /not in the movable region/], // on the 1 m crate
  ];
  for (const [body, code, message] of refusals) {
    const r = await goal(body);
    assert.equal(r.status, 400, JSON.stringify(body));
    assert.equal(r.body.error.code, code, JSON.stringify(r.body));
    assert.match(r.body.error.message, message);
  }
  const bad = await stack.api('POST', '/api/v1/goals', { body: 'x=1' });
  assert.equal(bad.status, 400);
  assert.equal((await goal({ x: -10, y: -8 }, stack.viewerToken)).status, 403);
  const plan = (await json(await stack.api('GET', '/api/v1/candidates'))).body;
  assert.ok(plan.candidates.every((c) => !c.custom), 'refused goals leave the plan alone');

  // A movable spot becomes a custom candidate with F, gains and the drive there.
  const r = await goal({ x: -4.2, y: -4.7, by: 'Alice' });
  assert.equal(r.status, 201, JSON.stringify(r.body));
  const c = r.body;
  assert.equal(c.custom, true);
  assert.equal(c.rank, 0);
  assert.equal(c.state, 'proposed');
  assert.deepEqual([c.x, c.y], [-4.5, -4.5], 'the centre of the cell');
  assert.ok(c.f > 0 && c.gain_unscanned_m2 >= 0 && c.gain_low_res_m2 >= 0, JSON.stringify(c));
  assert.ok(c.travel_m > 9 && c.travel_m < 16, `drive ${c.travel_m} m`);
  assert.deepEqual(c.path[c.path.length - 1], [-4.5, -4.5]);
  const listed = (await json(await stack.api('GET', '/api/v1/candidates'))).body.candidates.find((k) => k.id === c.id);
  assert.deepEqual(listed, c);

  // It is approved like the planner's candidates; the robot drives there and scans.
  const approved = await stack.api('POST', `/api/v1/candidates/${c.id}/approve`, { body: '{"by":"Alice"}' });
  assert.equal(approved.status, 200, await approved.clone().text());
  const s = await stack.waitFor('scan 2 at the goal', async () => {
    const b = (await json(await stack.api('GET', '/api/v1/session'))).body;
    return b.scans >= 2 ? b : undefined;
  });
  assert.ok(Math.hypot(s.last_scan.pose.x + 4.5, s.last_scan.pose.y + 4.5) < 0.01, JSON.stringify(s.last_scan.pose));

  // The record: who proposed, who approved, what the robot did.
  const log = (await json(await stack.api('GET', '/api/v1/decisions', { auth: stack.viewerToken }))).body.decisions;
  const kinds = log.map((e) => e.kind);
  for (const k of ['goal', 'approve', 'arrived', 'scan_requested']) assert.ok(kinds.includes(k), `${k} in ${kinds}`);
  const g = log.find((e) => e.kind === 'goal');
  assert.equal(g.by, 'operator Alice');
  assert.equal(g.candidate, c.id);
  assert.match(g.at, /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$/);
  assert.ok(log.every((e, i) => i === 0 || e.id > log[i - 1].id), 'oldest first');
  const last = (await json(await stack.api('GET', '/api/v1/decisions?limit=1'))).body.decisions;
  assert.equal(last.length, 1);
  assert.equal(last[0].id, log[log.length - 1].id, 'limit keeps the newest');
  assert.equal((await stack.api('GET', '/api/v1/decisions?limit=0')).status, 400);
});

test('layers say where they lie in the map', async () => {
  const s = (await json(await stack.api('GET', '/api/v1/session'))).body;
  const L = s.layers;
  assert.ok(L, 'session.layers');
  assert.equal(L.px_per_m, 4);
  assert.equal(L.width, (L.max[0] - L.min[0]) * L.px_per_m);
  assert.equal(L.height, (L.max[1] - L.min[1]) * L.px_per_m);
  // The default target region is a 200 m square around the first scan point (-15, -8).
  assert.ok(L.min[0] <= -115 && L.max[0] >= 84 && L.min[1] <= -108 && L.max[1] >= 91, JSON.stringify(L));
  for (const name of ['regions', 'elevation', 'movable']) {
    const r = await stack.api('GET', `/api/v1/layers/${name}.png`);
    assert.equal(r.status, 200);
    const bounds = r.headers.get('x-scanplan-layer-bounds').split(',').map(Number);
    assert.deepEqual(bounds, [...L.min, ...L.max]);
    const png = Buffer.from(await r.arrayBuffer());
    assert.equal(png.readUInt32BE(16), L.width, `${name} width`);
    assert.equal(png.readUInt32BE(20), L.height, `${name} height`);
  }
});

test('each scan has its areas; map.drc?since&until serves one scan', async () => {
  const scans = (await json(await stack.api('GET', '/api/v1/scans'))).body.scans;
  assert.equal(scans.length, 2);
  for (const s of scans) {
    assert.ok(s.areas && s.areas.completed_m2 > 0 && s.areas.unscanned_m2 > 0, JSON.stringify(s.areas));
  }
  assert.ok(scans[1].areas.completed_m2 > scans[0].areas.completed_m2, 'the second scan completes more');
  const one = await stack.api('GET', '/api/v1/map.drc?since=1&until=2');
  assert.equal(one.status, 200);
  assert.equal(one.headers.get('x-scanplan-last-scan'), '2');
  const same = await stack.api('GET', '/api/v1/map.drc?since=1');
  assert.deepEqual(Buffer.from(await one.arrayBuffer()), Buffer.from(await same.arrayBuffer()), 'the cached chunk of scan 2');
  const first = await stack.api('GET', '/api/v1/map.drc?until=1');
  assert.equal(first.status, 200);
  assert.equal(first.headers.get('x-scanplan-last-scan'), '1');
  const none = await stack.api('GET', '/api/v1/map.drc?since=1&until=1');
  assert.equal(none.status, 204);
  assert.equal((await stack.api('GET', '/api/v1/map.drc?since=2&until=1')).status, 400);
  assert.equal((await stack.api('GET', '/api/v1/map.drc?until=x')).status, 400);
});
