// The operator's area (issue 18): the target region and no-go zones set with PUT /api/v1/params
// keep the planner's candidates, the operator's own goals and the drives out of the zones, and a
// server restarted on the session plans with them as before.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { runCli, scanAndWait, startStack, worldVariant, scratchDir } from '../support/stack.mjs';

// Runs `scanplan args…` against the stack: { code, stdout, stderr }.
const cli = (args, token) => runCli(stack, args, token);

let stack;
before(async () => {
  const { file } = worldVariant(scratchDir('scanplan-area-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
});
after(async () => stack && (await stack.stop()));

const json = async (r) => ({ status: r.status, body: await r.json() });
const put = (body, auth) => stack.api('PUT', '/api/v1/params', { body: JSON.stringify(body), auth }).then(json);

// The yard is (−30..30) × (−20..20); the robot starts at (−15, −8). The zone takes the yard's
// east part, from x = −8 on.
const target = [[-30, -20], [30, -20], [30, 20], [-30, 20]];
const zone = [[-8, -20], [30, -20], [30, 20], [-8, 20]];

test('bad zones are refused with what is wrong, and nothing changes', async () => {
  const before = (await json(await stack.api('GET', '/api/v1/params'))).body;
  assert.deepEqual(before.no_go, []);
  const refusals = [
    [{ no_go: zone }, /no-go zone 1 must be \[\[x, y\], \.\.\.\]/],
    [{ no_go: { a: 1 } }, /'no_go' must be a list of at most 100 polygons/],
    [{ no_go: [[[0, 0], [1, 1]]] }, /no-go zone 1 is not a region the planner can take/],
    [{ no_go: [zone, [[0, 0], [1, 0], ['x', 1]]] }, /no-go zone 2 must be/],
  ];
  for (const [body, message] of refusals) {
    const r = await put(body);
    assert.equal(r.status, 400, JSON.stringify(body));
    assert.match(r.body.error.message, message);
  }
  assert.equal((await put({ no_go: [zone] }, stack.viewerToken)).status, 403);
  assert.deepEqual((await json(await stack.api('GET', '/api/v1/params'))).body, before);
});

test('no candidate, goal or drive in a no-go zone, and a restart keeps the area', async () => {
  const set = await put({ target, no_go: [zone], by: 'Ann' });
  assert.equal(set.status, 200, JSON.stringify(set.body));
  assert.deepEqual(set.body.target, target);
  assert.deepEqual(set.body.no_go, [zone]);

  await scanAndWait(stack, 1);
  const plan = await stack.waitFor('the first plan', async () => {
    const b = (await json(await stack.api('GET', '/api/v1/candidates'))).body;
    return b.plan && b.candidates.length ? b : undefined;
  });
  for (const c of plan.candidates) {
    assert.ok(c.x < -8, `candidate ${c.id} at (${c.x}, ${c.y}) lies in the zone`);
    assert.ok(c.path.every(([x]) => x < -8), `candidate ${c.id}'s drive crosses the zone`);
  }
  // The operator's own point in the zone is refused; one outside it is taken.
  const inZone = await json(await stack.api('POST', '/api/v1/goals', { body: JSON.stringify({ x: -4.2, y: -4.7 }) }));
  assert.equal(inZone.status, 400, JSON.stringify(inZone.body));
  assert.equal(inZone.body.error.code, 'no_go');
  assert.match(inZone.body.error.message, /\(-4\.2, -4\.7\) lies in a no-go zone/);

  // The change is in the decision log, with who made it.
  const log = (await json(await stack.api('GET', '/api/v1/decisions'))).body;
  const entry = (log.decisions ?? log).find((d) => d.kind === 'params');
  assert.ok(entry, JSON.stringify(log).slice(0, 400));

  // The mission's progress; the operator finishes it (a viewer may not).
  const running = (await json(await stack.api('GET', '/api/v1/session'))).body.mission;
  assert.equal(running.state, 'running', JSON.stringify(running));
  assert.ok(running.coverage_pct > 0 && running.best_gain_m2 > running.threshold_m2, JSON.stringify(running));
  assert.equal((await stack.api('POST', '/api/v1/mission/finish', { auth: stack.viewerToken })).status, 403);
  const fin = await json(await stack.api('POST', '/api/v1/mission/finish', { body: JSON.stringify({ by: 'Ann', reason: 'crew leaves' }) }));
  assert.equal(fin.status, 200, JSON.stringify(fin.body));
  assert.equal(fin.body.state, 'finished');
  assert.equal(fin.body.finished_by, 'operator Ann');

  const tokens = { operator: stack.token, viewer: stack.viewerToken };
  const dir = stack.dir;
  await stack.stop({ keepDir: true, signal: 'SIGKILL' });
  stack = await startStack({ bridge: false, dir, tokens });
  const after = (await json(await stack.api('GET', '/api/v1/session'))).body.mission;
  assert.equal(after.state, 'finished', 'a restart keeps the operator\'s finish');
  const again = await json(await stack.api('POST', '/api/v1/mission/resume'));
  assert.equal(again.body.state, 'running');
  const resumed = (await json(await stack.api('GET', '/api/v1/params'))).body;
  assert.deepEqual(resumed.target, target);
  assert.deepEqual(resumed.no_go, [zone]);
  const replanned = await stack.waitFor('the plan after the restart', async () => {
    const b = (await json(await stack.api('GET', '/api/v1/candidates'))).body;
    return b.plan && b.candidates.length ? b : undefined;
  });
  assert.ok(replanned.candidates.every((c) => c.x < -8), JSON.stringify(replanned.candidates.map((c) => [c.x, c.y])));
});

test('the terminal operator reads and sets the area', async () => {
  const shown = await cli(['area']);
  assert.equal(shown.code, 0, shown.stderr);
  assert.match(shown.stdout, /target area \(4 corners, m\): \(-30\.0, -20\.0\) \(30\.0, -20\.0\)/);
  assert.match(shown.stdout, /no-go zone 1: \(-8\.0, -20\.0\)/);

  const set = await cli(['area', '--no-go', '-30,-20 -25,-20 -25,-15', '--no-go', '20,10;25,10;25,15', '--by', 'Bo']);
  assert.equal(set.code, 0, set.stderr);
  assert.match(set.stdout, /no-go zone 2: \(20\.0, 10\.0\) \(25\.0, 10\.0\) \(25\.0, 15\.0\)/);
  const params = (await json(await stack.api('GET', '/api/v1/params'))).body;
  assert.equal(params.no_go.length, 2);

  const cleared = await cli(['area', '--clear-no-go', '--json']);
  assert.equal(cleared.code, 0, cleared.stderr);
  assert.deepEqual(JSON.parse(cleared.stdout).no_go, []);

  const bad = await cli(['area', '--target', '0,0 1,1']);
  assert.equal(bad.code, 9);
  assert.match(bad.stderr, /--target needs at least three corners/);
  const viewer = await cli(['area', '--clear-no-go'], stack.viewerToken);
  assert.equal(viewer.code, 4, viewer.stderr);
});
