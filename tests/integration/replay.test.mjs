// Recorded scans played back by `scanplan-bridge --replay`: a folder made with `scanplan scan`
// (PLY + panorama) plus a broken file. Each scan command plays the next recording; the broken
// one is reported on the progress topic and the bridge keeps going.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { writeFileSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { startStack, scanAndWait, requestScan, requireEnv, runCli, scratchDir } from '../support/stack.mjs';

const cli = requireEnv('SCANPLAN_CLI');
const world = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/yard.json');
let dir, recorded, stack;

before(() => {
  dir = scratchDir('scanplan-replay-');
  recorded = [[-15, -8, 0, 0], [10, -15, 0, 90]].map(([x, y, z, yaw], i) => {
    const out = join(dir, `scan${i}.ply`);
    const json = execFileSync(cli, ['scan', '--world', world, '--at', `${x},${y},${z},${yaw}`,
      '--out', out, '--seed', String(i + 1), '--image', join(dir, `scan${i}.jpg`)],
      { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
    return JSON.parse(json);
  });
  writeFileSync(join(dir, 'broken.ply'), 'ply\nformat binary_little_endian 1.0\nelement vertex 5000\n');
  writeFileSync(join(dir, 'poses.csv'),
    'file,x,y,z,yaw_deg\nscan0.ply,-15,-8,0,0\nbroken.ply,0,0,0,0\nscan1.ply,10,-15,0,90\n');
});
after(async () => stack && (await stack.stop()));

test('scanplan scan writes the scan, its true pose and its panorama', () => {
  const [first] = recorded;
  assert.equal(first.world, 'yard');
  assert.deepEqual(first.true_pose, { x: -15, y: -8, z: 0, yaw_deg: 0 });
  assert.ok(first.points > 100000, `points: ${first.points}`);
  assert.ok(first.colored > first.points * 0.95, 'colourised from the panorama');
  const header = readFileSync(first.file).subarray(0, 600).toString('latin1');
  assert.match(header, /comment scanplan true_pose -15\.0+ -8\.0+ 0\.0+ 0\.0+/);
  assert.match(header, new RegExp(`element vertex ${first.points}\\n`));
});

test('each scan command plays the next recording, skipping a broken file with a reason', async () => {
  stack = await startStack({ replay: dir });
  let session = await scanAndWait(stack, 1);
  assert.equal(session.points, recorded[0].points, 'the first recording arrives whole');
  const p = session.last_scan.pose;
  assert.ok(Math.hypot(p.x + 15, p.y + 8, p.z) < 1e-9 && Math.abs(p.yaw_deg) < 1e-9, JSON.stringify(p));

  const broken = await requestScan(stack);
  const failed = await stack.waitFor('the broken recording to be reported', async () => {
    const s = await (await stack.api('GET', '/api/v1/session')).json();
    const scan = s.robots.robot1?.scan;
    return scan?.command_id === broken && scan.state === 'failed' ? scan : undefined;
  });
  assert.match(failed.message, /broken\.ply/);

  session = await scanAndWait(stack, 2);
  assert.equal(session.points, recorded[0].points + recorded[1].points);
  // Recorded at exact poses; matching against the first scan may only nudge it.
  const q = session.last_scan.pose;
  assert.ok(Math.hypot(q.x - 10, q.y + 15) < 0.05 && Math.abs(q.yaw_deg - 90) < 0.3, JSON.stringify(q));
  assert.equal(stack.bridge.exitCode, null, 'the bridge is still running');
});

test('approving a move the replaying robot cannot make fails with the robot\'s reason', async () => {
  const plan = await stack.waitFor('a plan', async () => {
    const b = await (await stack.api('GET', '/api/v1/candidates')).json();
    return b.candidates?.length ? b : undefined;
  });
  const id = String(plan.candidates[0].id);
  const result = await runCli(stack, ['approve', id, '--yes', '--wait', '20']);
  assert.match(result.stdout, new RegExp(`^approved candidate ${id}`));
  assert.equal(result.code, 10, result.stderr);
  assert.match(result.stderr, new RegExp(`robot1 refused to go to candidate ${id}: this robot replays a recording`));
});
