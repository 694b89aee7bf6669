// The operator's loop over REST: a scan, candidates from the planner, an approval that moves
// the simulated robot over DDS, and the scan that follows its arrival. Nothing moves without
// the approval, and viewers cannot decide.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startStack, scanAndWait, worldVariant, scratchDir } from '../support/stack.mjs';

let stack;
before(async () => {
  const { file } = worldVariant(scratchDir('scanplan-approval-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
});
after(async () => stack && (await stack.stop()));

const candidates = async () => (await stack.api('GET', '/api/v1/candidates')).json();

test('candidates follow the first scan and only an operator decides', async () => {
  assert.deepEqual((await candidates()).candidates, []);
  await scanAndWait(stack, 1);
  const plan = await stack.waitFor('candidates', async () => {
    const c = await candidates();
    return c.candidates.length > 0 ? c : undefined;
  });
  assert.equal(plan.plan.based_on_scan, 1);
  for (const c of plan.candidates) {
    assert.equal(c.state, 'proposed');
    assert.ok(c.f > 0 && c.gain_unscanned_m2 >= 0 && c.gain_low_res_m2 >= 0, JSON.stringify(c));
    assert.ok(c.x > -30 && c.x < 30 && c.y > -20 && c.y < 20, 'inside the yard');
  }
  const id = plan.candidates[0].id;
  const viewer = await stack.api('POST', `/api/v1/candidates/${id}/approve`, { auth: stack.viewerToken });
  assert.equal(viewer.status, 403);
  assert.equal((await stack.api('POST', '/api/v1/candidates/999999/approve')).status, 404);
  assert.equal((await stack.api('POST', '/api/v1/candidates/abc/approve')).status, 400);
  const session = await (await stack.api('GET', '/api/v1/session')).json();
  assert.equal(session.robots.robot1.state, 'idle', 'nothing moved before an approval');
});

test('an approval drives the robot there and a scan follows its arrival', async () => {
  const plan = await candidates();
  const [first, second] = plan.candidates;
  if (second) {
    const rejected = await stack.api('POST', `/api/v1/candidates/${second.id}/reject`, {
      body: JSON.stringify({ by: 'Alice', reason: 'rubble' }),
    });
    assert.equal(rejected.status, 200);
  }
  const approved = await stack.api('POST', `/api/v1/candidates/${first.id}/approve`, {
    body: JSON.stringify({ by: 'Alice' }),
  });
  assert.equal(approved.status, 200, await approved.clone().text());
  const move = await approved.json();
  assert.equal(move.by, 'operator Alice');
  assert.equal((await stack.api('POST', `/api/v1/candidates/${first.id}/approve`)).status, 409);

  const session = await scanAndWaitWithoutAsking(2);
  const p = session.last_scan.pose;
  assert.ok(Math.hypot(p.x - first.x, p.y - first.y) < 0.01, `scanned at ${JSON.stringify(p)}`);
  // The scan keeps where it was taken for: a scan the map cannot place is claimed there.
  const scans = (await (await stack.api('GET', '/api/v1/scans')).json()).scans;
  assert.equal(scans[0].goal, null, 'the first scan was not sent for');
  const sentFor = scans.find((s) => s.id === 2).goal;
  assert.deepEqual([sentFor.x, sentFor.y, sentFor.z], [first.x, first.y, first.z]);
  const after = await stack.waitFor('a new plan', async () => {
    const c = await candidates();
    return c.plan.based_on_scan === 2 ? c : undefined;
  });
  assert.ok(after.plan.id > plan.plan.id);
});

// The second scan is asked for by the server itself when the robot arrives.
async function scanAndWaitWithoutAsking(count) {
  return stack.waitFor(`scan ${count} after the approved move`, async () => {
    const s = await (await stack.api('GET', '/api/v1/session')).json();
    return s.scans >= count ? s : undefined;
  }, 60000);
}
