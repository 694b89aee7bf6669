// The terminal operator (`scanplan status|candidates|approve|reject|watch`) against a real
// server and simulated bridge: what it prints, what it exits with, and that watch follows the
// event stream through a server restart.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { createServer } from 'node:net';
import { join } from 'node:path';
import { startStack, requestScan, requireEnv, loopbackDds } from '../support/stack.mjs';

const cli = requireEnv('SCANPLAN_CLI');
let stack, watch, restarted;

// Runs `scanplan args…` to completion: { code, stdout, stderr }.
function run(args, env = {}) {
  return new Promise((resolve) => {
    const child = spawn(cli, args, { env: { ...process.env, ...env }, stdio: ['ignore', 'pipe', 'pipe'] });
    let stdout = '', stderr = '';
    child.stdout.on('data', (d) => { stdout += d; });
    child.stderr.on('data', (d) => { stderr += d; });
    child.on('exit', (code) => resolve({ code, stdout, stderr }));
  });
}

// `scanplan watch --json` in the background, its stdout as parsed lines.
function startWatch(url, token) {
  const child = spawn(cli, ['watch', '--json', '--server', url, '--token', token, '--max-backoff', '1'],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  child.events = [];
  child.stderrText = '';
  let partial = '';
  child.stdout.on('data', (d) => {
    partial += d;
    const lines = partial.split('\n');
    partial = lines.pop();
    for (const l of lines) if (l.trim()) child.events.push(JSON.parse(l));
  });
  child.stderr.on('data', (d) => { child.stderrText += d; });
  child.exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal })));
  return child;
}

async function until(what, fn, timeoutMs = 60000) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const v = await fn().catch(() => undefined);
    if (v) return v;
    if (Date.now() > deadline) {
      throw new Error(`timed out waiting for ${what}\n--- watch stderr\n${watch?.stderrText}\n--- watch events\n` +
        (watch?.events ?? []).map((e) => JSON.stringify(e)).join('\n').slice(-4000));
    }
    await new Promise((r) => setTimeout(r, 100));
  }
}

const seen = (pred) => async () => watch.events.find(pred);

async function freePort() {
  return new Promise((resolve) => {
    const s = createServer();
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

before(async () => { stack = await startStack(); });
after(async () => {
  if (watch && watch.exitCode === null) watch.kill('SIGKILL');
  if (restarted && restarted.exitCode === null) restarted.kill('SIGTERM');
  if (stack) await stack.stop();
});

test('status before any scan, from the token in $SCANPLAN_TOKEN', async () => {
  const r = await run(['status', '--server', stack.url], { SCANPLAN_TOKEN: stack.viewerToken });
  assert.equal(r.code, 0, r.stderr);
  assert.match(r.stdout, /^scans\s+0 scans, 0 points in the map$/m);
  assert.match(r.stdout, /^connection\s+1 robot bridge connected/m);
  assert.match(r.stdout, /^last scan\s+none yet/m);
  const j = await run(['status', '--json', '--server', stack.url, '--token', stack.viewerToken]);
  assert.equal(j.code, 0, j.stderr);
  assert.equal(JSON.parse(j.stdout).scans, 0);
});

test('watch prints the events of a scan; candidates agree with the REST API', async () => {
  watch = startWatch(stack.url, stack.viewerToken);
  await until('watch to connect', seen((e) => e.type === 'connection' && e.state === 'connected'));
  await requestScan(stack);
  for (const type of ['scan_progress', 'scan_received', 'map_updated', 'plan_done']) {
    await until(type, seen((e) => e.type === type));
  }
  assert.ok(watch.events.some((e) => e.type === 'scan_progress' && e.state === 'done' && e.fraction === 1));
  assert.ok(watch.events.some((e) => e.type === 'map_chunk' && e.scan === 1 && e.bytes > 0), 'map chunk summarised');

  const rest = await (await stack.api('GET', '/api/v1/candidates')).json();
  assert.ok(rest.candidates.length > 0);
  const r = await run(['candidates', '--json', '--server', stack.url, '--token', stack.viewerToken]);
  assert.equal(r.code, 0, r.stderr);
  assert.deepEqual(JSON.parse(r.stdout), rest);

  const text = await run(['candidates', '--server', stack.url, '--token', stack.viewerToken]);
  assert.equal(text.code, 0, text.stderr);
  assert.match(text.stdout, /^rank\s+id\s+state\s+x m\s+y m\s+F\s+gain U m2\s+gain M m2\s+travel m\s+match$/m);
  const first = rest.candidates[0];
  assert.match(text.stdout, new RegExp(`^\\s+1\\s+${first.id}\\s+proposed\\s`, 'm'));
  const view = text.stdout.split('\n').filter((l) => /^\|.*\|$/.test(l));
  assert.ok(view.length >= 5, 'a framed top view');
  assert.ok(view.some((l) => l.includes('1')), 'candidate 1 on the map');
  assert.ok(view.some((l) => l.includes('R')), 'the robot on the map');
  assert.ok(view.some((l) => l.includes('#')), 'scan-completed area on the map');
});

test('a viewer cannot approve, an unknown candidate is 404, an operator sends the robot', async () => {
  const { candidates } = await (await stack.api('GET', '/api/v1/candidates')).json();
  const id = String(candidates[0].id);
  const viewer = await run(['approve', id, '--yes', '--server', stack.url, '--token', stack.viewerToken]);
  assert.equal(viewer.code, 4, viewer.stderr);
  assert.match(viewer.stderr, /cannot approve candidate \d+ \(HTTP 403\): this action needs an operator token; yours is a viewer's/);

  const unknown = await run(['approve', '999999', '--yes', '--server', stack.url, '--token', stack.token]);
  assert.equal(unknown.code, 5, unknown.stderr);
  assert.match(unknown.stderr, /\(HTTP 404\): no candidate 999999 in the current plan/);

  const ok = await run(['approve', id, '--yes', '--by', 'Tess', '--server', stack.url, '--token', stack.token]);
  assert.equal(ok.code, 0, ok.stderr);
  assert.match(ok.stdout, new RegExp(`^approved candidate ${id} by operator Tess: robot1 drives to`));

  const again = await run(['approve', id, '--yes', '--server', stack.url, '--token', stack.token]);
  assert.equal(again.code, 6, 'a candidate already moving is a conflict');

  await until('the approval on the event stream', seen((e) => e.type === 'mission' && e.kind === 'approve' && String(e.candidate) === id));
  await until('the robot moving', seen((e) => e.type === 'robot_status' && e.state === 'moving'));
  await until('the second scan in the map', seen((e) => e.type === 'map_updated' && e.scan === 2));
  await until('a plan after the second scan', seen((e) => e.type === 'plan_done' && e.based_on_scan === 2));
});

test('a wrong token and an unreachable server give their exit codes and say what to do', async () => {
  const wrong = await run(['status', '--server', stack.url, '--token', 'not-the-token']);
  assert.equal(wrong.code, 3);
  assert.match(wrong.stderr, /the server refused the token \(HTTP 401\)/);
  const wrongWatch = await run(['watch', '--server', stack.url, '--token', 'not-the-token']);
  assert.equal(wrongWatch.code, 3);
  assert.match(wrongWatch.stderr, /the server refused the token/);
  const none = await run(['candidates', '--server', stack.url], { SCANPLAN_TOKEN: '' });
  assert.equal(none.code, 3);
  assert.match(none.stderr, /no token/);

  const port = await freePort();
  const down = await run(['status', '--server', `http://127.0.0.1:${port}`, '--token', 'x']);
  assert.equal(down.code, 2);
  assert.equal(down.stderr.trim(),
    `scanplan status: cannot reach http://127.0.0.1:${port}: connection refused — is scanplan-server running?`);
  const downWatch = await run(['watch', '--server', `http://127.0.0.1:${port}`, '--token', 'x']);
  assert.equal(downWatch.code, 2);
});

test('watch reports a killed server and reconnects when it is back on the same port', async () => {
  const port = new URL(stack.url).port;
  const before = watch.events.length;
  stack.server.kill('SIGKILL');
  await stack.server.exited;
  await until('the lost connection', async () =>
    watch.events.slice(before).find((e) => e.type === 'connection' && e.state === 'lost'));
  await until('a failed retry', async () =>
    watch.events.slice(before).find((e) => e.type === 'connection' && e.state === 'retrying' &&
      /connection refused/.test(e.message)));
  assert.equal(watch.exitCode, null, 'watch keeps running');

  restarted = spawn(requireEnv('SCANPLAN_SERVER'),
    ['--session', join(stack.dir, 'session'), '--listen', `127.0.0.1:${port}`,
     '--domain', requireEnv('SCANPLAN_TEST_DOMAIN'), '--web', requireEnv('SCANPLAN_WEB_DIR')],
    { env: { ...process.env, CYCLONEDDS_URI: loopbackDds, SCANPLAN_OPERATOR_TOKEN: stack.token,
             SCANPLAN_VIEWER_TOKEN: stack.viewerToken },
      stdio: ['ignore', 'ignore', 'ignore'] });
  const reconnected = await until('the reconnection', async () =>
    watch.events.slice(before).find((e) => e.type === 'connection' && e.state === 'connected'));
  assert.match(reconnected.message, /reconnected to http:\/\/127\.0\.0\.1:\d+ after/);

  // It is really following the new server: a scan there shows up.
  await until('the bridge on the new server', async () =>
    (await (await fetch(`${stack.url}/api/v1/health`)).json()).bridges >= 1);
  const after = watch.events.length;
  const r = await fetch(`${stack.url}/api/v1/scan`, { method: 'POST', headers: { Authorization: `Bearer ${stack.token}` } });
  assert.equal(r.status, 202);
  await until('a scan after the reconnection', async () =>
    watch.events.slice(after).find((e) => e.type === 'map_updated'));

  watch.kill('SIGINT');
  const { code } = await watch.exited;
  assert.equal(code, 0, 'Ctrl-C ends watch cleanly');
  assert.ok(watch.events.at(-1).type === 'connection' && watch.events.at(-1).state === 'closed');
});
