// Scans fed through POST /api/v1/scans and annotations are on disk once acknowledged: a server
// killed with SIGKILL restarts from its session directory with every scan, pose, annotation and
// the same map, and publishes the annotations on DDS again for subscribers that join later.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startStack, requireEnv } from '../support/stack.mjs';
import { startListener } from '../support/dds_listener.mjs';

const cli = requireEnv('SCANPLAN_CLI');
const world = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/yard.json');
const poses = [[-15, -8, 0, 0], [5, -14, 0, 90], [-20, 12, 0, -45]];
let dir, files, stack;

before(() => {
  dir = mkdtempSync(join(tmpdir(), 'scanplan-recovery-'));
  files = poses.map(([x, y, z, yaw], i) => {
    const out = join(dir, `s${i}.ply`);
    execFileSync(cli, ['scan', '--world', world, '--at', `${x},${y},${z},${yaw}`, '--out', out,
      '--seed', String(i + 1)], { stdio: ['ignore', 'ignore', 'ignore'] });
    return out;
  });
});
after(async () => {
  if (stack) await stack.stop();
  rmSync(dir, { recursive: true, force: true });
});

const post = (s, i) => {
  const [x, y, z, yaw] = poses[i];
  return s.api('POST', `/api/v1/scans?x=${x}&y=${y}&z=${z}&yaw_deg=${yaw}`, { body: readFileSync(files[i]) });
};

test('bad uploads are refused with the right status and nothing is stored', async () => {
  stack = await startStack({ bridge: false, dir: join(dir, 'run1') });
  const missing = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0', { body: readFileSync(files[0]) });
  assert.equal(missing.status, 400);
  assert.match((await missing.json()).error.message, /yaw_deg/);
  const nan = await stack.api('POST', '/api/v1/scans?x=NaN&y=0&z=0&yaw_deg=0', { body: readFileSync(files[0]) });
  assert.equal(nan.status, 400);
  const garbage = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0&yaw_deg=0', { body: 'ply\nformat ascii 1.0\nelement vertex 99999999\n' });
  assert.equal(garbage.status, 400);
  assert.equal((await garbage.json()).error.code, 'bad_scan');
  // Nothing but the scanner's own mount (within 0.3 m of the laser, 1 m above the scan's
  // origin): no point is the scene.
  const mountOnly = 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n' +
    'property float z\nend_header\n0.1 0 1\n0 0.2 0.9\n';
  const mount = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0&yaw_deg=0', { body: mountOnly });
  assert.equal(mount.status, 422);
  const mountError = (await mount.json()).error;
  assert.equal(mountError.code, 'too_few_points');
  assert.match(mountError.message, /2 on the scanner's mount/);
  const viewer = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0&yaw_deg=0', { auth: stack.viewerToken, body: readFileSync(files[0]) });
  assert.equal(viewer.status, 403);
  assert.equal((await (await stack.api('GET', '/api/v1/scans/1')).json()).error.code, 'not_found');
  assert.equal((await stack.api('GET', '/api/v1/scans/abc')).status, 400);
  assert.deepEqual((await (await stack.api('GET', '/api/v1/scans')).json()).scans, []);
});

test('acknowledged scans survive SIGKILL', async () => {
  for (let i = 0; i < poses.length; i++) {
    const r = await post(stack, i);
    assert.equal(r.status, 201);
    const body = await r.json();
    assert.equal(body.id, i + 1);
    assert.deepEqual(body.estimated, { x: poses[i][0], y: poses[i][1], z: poses[i][2], yaw_deg: poses[i][3] });
  }
  const before = await stack.waitFor('three scans in the map', async () => {
    const s = await (await stack.api('GET', '/api/v1/session')).json();
    return s.scans === 3 ? s : undefined;
  });
  const mapBefore = Buffer.from(await (await stack.api('GET', '/api/v1/map.drc')).arrayBuffer());
  // Each scan after the first carries its match outcome, stored with it.
  const listBefore = (await (await stack.api('GET', '/api/v1/scans')).json()).scans;
  assert.equal(listBefore[0].match, null, 'the first scan defines the map frame');
  for (const s of listBefore.slice(1)) {
    assert.equal(s.match.method, 'search-gicp');
    assert.equal(typeof s.match.applied, 'boolean');
    assert.equal(s.match.reason === '', s.match.applied, 'a reason exactly when not applied');
    // How firmly the matched surfaces fixed the pose (an applied match passed the check on it).
    assert.equal(typeof s.match.weakest_constraint, 'number');
    if (s.match.applied) assert.ok(s.match.weakest_constraint >= 0.01, `${s.match.weakest_constraint}`);
  }
  // Annotations: one withdrawn, and one acknowledged just before the kill.
  const annotate = async (body) => {
    const r = await stack.api('POST', '/api/v1/annotations', { body: JSON.stringify(body) });
    assert.equal(r.status, 201);
    return r.json();
  };
  const hazard = await annotate({ kind: 'hazard', x: -12, y: 3, z: 0, text: 'leaning wall' });
  assert.equal((await stack.api('DELETE', `/api/v1/annotations/${hazard.id}`)).status, 200);
  const victim = await annotate({ kind: 'victim', x: 4.5, y: -9.25, z: 0.3, text: 'child, calling out', by: 'Ann' });
  const tokens = { operator: stack.token, viewer: stack.viewerToken };
  const sessionDir = stack.dir;
  await stack.stop({ keepDir: true, signal: 'SIGKILL' });

  stack = await startStack({ bridge: false, dir: sessionDir, tokens });
  // Never an empty session while it comes back (issue 16): until all three scans are in, the
  // session says it is rebuilding and how far it is.
  const polls = [];
  const after = await stack.waitFor('the map rebuilt from disk', async () => {
    const s = await (await stack.api('GET', '/api/v1/session')).json();
    polls.push({ scans: s.scans, rebuilding: s.rebuilding });
    return s.scans === 3 && s.rebuilding === null ? s : undefined;
  });
  for (const p of polls.filter((x) => x.scans < 3)) {
    assert.equal(p.rebuilding?.total, 3, `rebuilding said while ${p.scans} of 3 were back`);
    assert.ok(p.rebuilding.done <= 3);
  }
  assert.equal(after.points, before.points);
  assert.deepEqual(after.bounds, before.bounds);
  const list = (await (await stack.api('GET', '/api/v1/scans')).json()).scans;
  assert.deepEqual(list.map((s) => s.id), [1, 2, 3]);
  assert.deepEqual(list[1].estimated, { x: 5, y: -14, z: 0, yaw_deg: 90 });
  assert.deepEqual(list.map((s) => s.match), listBefore.map((s) => s.match), 'the match outcomes are back');
  const mapAfter = Buffer.from(await (await stack.api('GET', '/api/v1/map.drc')).arrayBuffer());
  assert.ok(mapAfter.equals(mapBefore), 'the page gets the same map after the restart');
  const next = await post(stack, 0);
  assert.equal((await next.json()).id, 4, 'ids continue after the restart');

  const annotations = (await (await stack.api('GET', '/api/v1/annotations')).json()).annotations;
  assert.deepEqual(annotations, [victim], 'the acknowledged annotation is back, the deleted one is not');
  const listener = await startListener('SCANPLAN_ANNOTATION_LISTENER');
  try {
    const sample = await listener.waitFor('the annotation on DDS after the restart', (l) => l.id === victim.id);
    assert.deepEqual([sample.kind, sample.x, sample.y, sample.z, sample.text, sample.author],
      ['victim', 4.5, -9.25, 0.3, 'child, calling out', 'operator Ann']);
    assert.ok(!listener.lines.some((l) => l.id === hazard.id), 'the deleted annotation is not republished');
  } finally {
    await listener.stop();
  }
  const more = await stack.api('POST', '/api/v1/annotations', { body: '{"kind":"blocked","x":0,"y":0,"z":0}' });
  assert.equal((await more.json()).id, victim.id + 1, 'annotation ids continue after the restart');
});
