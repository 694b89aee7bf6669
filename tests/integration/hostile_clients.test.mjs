// Issue 16: what a broken client or a careless script sends must not stop the operators, and
// nothing the server acknowledged may be lost. One real server on an ephemeral port; each case
// checks the answer and that the map, the plan and the session are as they should be after it.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { connect } from 'node:net';
import { existsSync, mkdtempSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createRequire } from 'node:module';
import { startStack, requireEnv } from '../support/stack.mjs';

const WebSocket = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'))('ws');

// A 20 m room seen from its middle: walls 3 m high and the floor, in the robot frame (the
// ground at z = 0), with any extra vertices appended.
function roomPly(extra = [], count = 4000) {
  const lines = [];
  let seed = 7;
  const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
  for (let i = 0; i < count; i++) {
    const u = -10 + 20 * rand();
    if (i % 2 === 0) {
      const side = [[u, -10], [u, 10], [-10, u], [10, u]][i % 8 / 2];
      lines.push(`${side[0]} ${side[1]} ${3 * rand()}`);
    } else {
      lines.push(`${u} ${-10 + 20 * rand()} 0`);
    }
  }
  for (const p of extra) lines.push(p.join(' '));
  return 'ply\nformat ascii 1.0\nelement vertex ' + lines.length +
    '\nproperty float x\nproperty float y\nproperty float z\nend_header\n' + lines.join('\n') + '\n';
}

let dir, stack;
const session = async () => (await stack.api('GET', '/api/v1/session')).json();
const errorOf = async (r) => (await r.json()).error;

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'scanplan-hostile-'));
  stack = await startStack({ bridge: false, dir: join(dir, 'run') });
});
after(async () => {
  if (stack) await stack.stop({ keepDir: true });
  rmSync(dir, { recursive: true, force: true });
});

test('absurd but finite poses are refused by name and nothing is stored', async () => {
  const cases = [
    ['x=1e7&y=0&z=0&yaw_deg=0', /pose's x is 1e\+07 m/],
    ['x=1e308&y=0&z=0&yaw_deg=0', /pose's x is 1e\+308/],
    ['x=0&y=-2e5&z=0&yaw_deg=0', /pose's y/],
    ['x=0&y=0&z=0&yaw_deg=10000', /pose's yaw is 10000°/],
    ['x=0x1p3&y=0&z=0&yaw_deg=0', /'x' must be a finite decimal number/],
    ['x=inf&y=0&z=0&yaw_deg=0', /'x' must be a finite decimal number/],
    ['x=1e400&y=0&z=0&yaw_deg=0', /'x' must be a finite decimal number/],
    ['x=1&y=0&z=0&yaw_deg=0&robot=a%0Ab', /'robot' must be 1 to 64 characters/],
  ];
  for (const [query, message] of cases) {
    const r = await stack.api('POST', `/api/v1/scans?${query}`, { body: roomPly() });
    assert.equal(r.status, 400, query);
    assert.match((await errorOf(r)).message, message, query);
  }
  assert.deepEqual((await (await stack.api('GET', '/api/v1/scans')).json()).scans, []);
});

test('points beyond any scanner\'s reach are dropped and counted, and the scan joins the map', async () => {
  const r = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0&yaw_deg=0',
    { body: roomPly([[1e30, 0, 0], [0, -1e30, 1], [0, 0, 5000]]) });
  assert.equal(r.status, 201);
  const scan = await r.json();
  assert.deepEqual(scan.dropped, { non_finite: 0, out_of_range: 3, mount: 0, saturated: 0 });
  assert.equal(scan.points, 4000);
  const s = await stack.waitFor('the scan in the map', async () => {
    const j = await session();
    return j.scans === 1 && j.areas.movable_m2 > 0 ? j : undefined;
  });
  for (const v of [...s.bounds.min, ...s.bounds.max]) assert.ok(Math.abs(v) < 20, `bounds ${JSON.stringify(s.bounds)}`);
  const plan = await (await stack.api('GET', '/api/v1/candidates')).json();
  assert.ok(plan.candidates.length > 0, 'the planner still has somewhere to go');
});

test('a scan with too few measurements is refused with 422', async () => {
  const tiny = await stack.api('POST', '/api/v1/scans?x=1&y=0&z=0&yaw_deg=0', { body: roomPly([], 50) });
  assert.equal(tiny.status, 422);
  const e = await errorOf(tiny);
  assert.equal(e.code, 'too_few_points');
  assert.match(e.message, /50 of the scan's points are measurements, at least 100/);
  const far = await stack.api('POST', '/api/v1/scans?x=1&y=0&z=0&yaw_deg=0',
    { body: roomPly(Array.from({ length: 200 }, (_, i) => [1e20, i, 0]), 0) });
  assert.equal(far.status, 422);
  assert.match((await errorOf(far)).message, /200 beyond 1000 m/);
  assert.equal((await session()).scans, 1);
});

test('text fields are checked and capped', async () => {
  const reject = (body) => stack.api('POST', '/api/v1/candidates/1/reject', { body: JSON.stringify(body) });
  let r = await reject({ reason: 'x'.repeat(5_000_000) });
  assert.equal(r.status, 400);
  assert.match((await errorOf(r)).message, /'reason' is too long: 5000000 bytes/);
  r = await reject({ reason: 'stairs\u001b[2J' });
  assert.equal(r.status, 400);
  r = await reject({ by: 'Ann\nEve' });
  assert.equal(r.status, 400);
  assert.match((await errorOf(r)).message, /'by' must be one line/);
  r = await stack.api('POST', '/api/v1/goals', { body: JSON.stringify({ x: 1, y: 1, robot: 'r\n1' }) });
  assert.equal(r.status, 400);
  r = await stack.api('GET', '/api/v1/candidates?robot=' + encodeURIComponent('a b'));
  assert.equal(r.status, 400);
  r = await stack.api('POST', '/api/v1/annotations',
    { body: JSON.stringify({ kind: 'note', x: 1, y: 1, z: 0, text: 'bell\u0007' }) });
  assert.equal(r.status, 400);
  r = await stack.api('POST', '/api/v1/annotations',
    { body: JSON.stringify({ kind: 'note', x: 1, y: 1, z: 0, text: 'two adults,\nstairs blocked' }) });
  assert.equal(r.status, 201);
});

test('a target region of 1e9 m is refused and changes nothing; later changes and scans work', async () => {
  const put = (body) => stack.api('PUT', '/api/v1/params', { body: JSON.stringify(body) });
  const before = await (await stack.api('GET', '/api/v1/params')).json();
  for (const target of [[[0, 0], [1e9, 0], [1e9, 1e9]], [[0, 0], [5000, 0], [5000, 10]],
    [[0, 0], [1, 0]], [[0, 0], ['a', 0], [1, 1]]]) {
    const r = await put({ alpha: 0.2, target });
    assert.equal(r.status, 400, JSON.stringify(target));
  }
  assert.deepEqual(await (await stack.api('GET', '/api/v1/params')).json(), before, 'a refused PUT changes nothing');
  const ok = await put({ target: [[-40, -40], [40, -40], [40, 40], [-40, 40]] });
  assert.equal(ok.status, 200);
  const r = await stack.api('POST', '/api/v1/scans?x=5&y=0&z=0&yaw_deg=0', { body: roomPly() });
  assert.equal(r.status, 201);
  await stack.waitFor('the second scan in the map', async () => ((await session()).scans === 2 ? true : undefined));
});

// Sends `text` on a raw TCP connection and resolves with everything the server sent back
// before it closed (or `waitMs` passed), and whether it closed.
function raw(text, { waitMs = 3000, keepSending } = {}) {
  const { hostname, port } = new URL(stack.url);
  return new Promise((resolve) => {
    const socket = connect(Number(port), hostname);
    let got = '';
    let timer;
    const done = (closed) => {
      clearTimeout(timer);
      clearInterval(socket.trickle);
      socket.destroy();
      resolve({ got, closed });
    };
    socket.on('data', (c) => { got += c.toString('latin1'); });
    socket.on('close', () => done(true));
    socket.on('error', () => done(true));
    socket.on('connect', () => {
      socket.write(text);
      if (keepSending) socket.trickle = setInterval(() => socket.write(keepSending), 50);
    });
    timer = setTimeout(() => done(false), waitMs);
  });
}

test('no token, no work: an upload is refused before its body is read', async () => {
  const started = Date.now();
  const refused = await raw('POST /api/v1/scans?x=0&y=0&z=0&yaw_deg=0 HTTP/1.1\r\nHost: h\r\n' +
    'Content-Length: 200000000\r\nExpect: 100-continue\r\n\r\n');
  assert.match(refused.got, /^HTTP\/1\.1 401 /);
  assert.doesNotMatch(refused.got, /100 Continue/);
  assert.ok(refused.closed);
  assert.ok(Date.now() - started < 2000);
  // Many at once, sending on: each is answered and let go, and the operators are still served.
  const flood = Array.from({ length: 150 }, () => raw('PUT /api/v1/params HTTP/1.1\r\nHost: h\r\n' +
    'Authorization: Bearer wrong\r\nContent-Length: 200000000\r\n\r\n', { keepSending: 'x'.repeat(4096), waitMs: 5000 }));
  for (let i = 0; i < 20; i++) assert.equal((await stack.api('GET', '/api/v1/session')).status, 200);
  for (const r of await Promise.all(flood)) assert.match(r.got, /^HTTP\/1\.1 401 /);
  const viewer = await stack.api('POST', '/api/v1/scans?x=0&y=0&z=0&yaw_deg=0', { auth: stack.viewerToken, body: roomPly() });
  assert.equal(viewer.status, 403);
  const { url } = stack;
  const lower = await fetch(url + '/api/v1/session', { headers: { Authorization: `bearer  ${stack.token}` } });
  assert.equal(lower.status, 200, 'the Bearer scheme is case-insensitive');
  assert.equal((await lower.json()).role, 'operator');
});

test('the page carries its security headers; the events socket checks Origin', async () => {
  const page = await fetch(stack.url + '/');
  assert.equal(page.status, 200);
  assert.match(page.headers.get('content-security-policy'), /default-src 'self'.*frame-ancestors 'none'/);
  assert.equal(page.headers.get('x-frame-options'), 'DENY');
  assert.equal(page.headers.get('referrer-policy'), 'no-referrer');
  const { host } = new URL(stack.url);
  const upgrade = (origin) => raw(`GET /api/v1/events?token=${stack.token} HTTP/1.1\r\nHost: ${host}\r\n` +
    'Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n' +
    `Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n${origin ? `Origin: ${origin}\r\n` : ''}\r\n`, { waitMs: 1000 });
  assert.match((await upgrade('http://evil.example')).got, /^HTTP\/1\.1 403 .*forbidden_origin/s);
  assert.match((await upgrade(`http://${host}`)).got, /^HTTP\/1\.1 101 /);
  assert.match((await upgrade(null)).got, /^HTTP\/1\.1 101 /, 'a client that is not a browser sends no Origin');
});

test('a request line with an absolute URI is served (RFC 9112 §3.2.2)', async () => {
  const r = await raw(`GET ${stack.url}/api/v1/health HTTP/1.1\r\nHost: elsewhere\r\nConnection: close\r\n\r\n`);
  assert.match(r.got, /^HTTP\/1\.1 200 /);
  assert.match(r.got, /"status":"ok"/);
});

// Runs the server binary on `sessionDir` and returns its exit code and output.
function runServer(sessionDir) {
  return new Promise((resolve) => {
    const p = spawn(requireEnv('SCANPLAN_SERVER'),
      ['--session', sessionDir, '--listen', '127.0.0.1:0', '--domain', requireEnv('SCANPLAN_TEST_DOMAIN'),
        '--web', requireEnv('SCANPLAN_WEB_DIR')],
      { env: { ...process.env, SCANPLAN_OPERATOR_TOKEN: 'x'.repeat(32) }, stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    p.stdout.on('data', (c) => { out += c; });
    p.stderr.on('data', (c) => { out += c; });
    const timer = setTimeout(() => p.kill('SIGKILL'), 15000);
    p.on('exit', (code) => { clearTimeout(timer); resolve({ code, out }); });
  });
}

test('uploads from several clients at once, with hundreds of event sockets, half never reading', async () => {
  const base = stack.url.replace('http', 'ws') + `/api/v1/events?token=${stack.viewerToken}`;
  const opened = (ws) => new Promise((resolve) => { ws.on('open', resolve); ws.on('error', resolve); });
  const sockets = Array.from({ length: 200 }, () => new WebSocket(base));
  await Promise.all(sockets.map(opened));
  // Half of them stop reading: the server's queue for them fills with the scans' map chunks.
  for (const ws of sockets.slice(0, 100)) ws._socket?.pause();
  const listener = sockets[150];
  const received = [];
  listener.on('message', (data, binary) => { if (!binary) received.push(JSON.parse(data.toString()).type); });
  const before = (await session()).scans;
  const uploads = await Promise.all(Array.from({ length: 8 }, (_, i) =>
    stack.api('POST', `/api/v1/scans?x=${(i % 4) - 2}&y=${i % 2}&z=0&yaw_deg=${i * 10}`, { body: roomPly() })));
  assert.deepEqual(uploads.map((r) => r.status), Array(8).fill(201));
  await stack.waitFor('every upload in the map', async () => ((await session()).scans === before + 8 ? true : undefined));
  await stack.waitFor('a reading socket told of each', async () =>
    (received.filter((t) => t === 'map_updated').length >= 8 ? true : undefined), 20000);
  assert.equal((await stack.api('GET', '/api/v1/health')).status, 200);
  for (const ws of sockets) ws.terminate();
  // Back to two scans for the cases below: the eight go out of the map again.
  for (let id = before + 1; id <= before + 8; id++) {
    assert.equal((await stack.api('DELETE', `/api/v1/scans/${id}`)).status, 200);
  }
  await stack.waitFor('the eight out of the map', async () => ((await session()).scans === before ? true : undefined));
});

test('a second server on the same session is refused', async () => {
  const second = await runServer(join(stack.dir, 'session'));
  assert.notEqual(second.code, 0);
  assert.match(second.out, /is open in another process \(pid \d+\)/);
  assert.equal((await session()).scans, 2, 'the first server is untouched');
});

test('the operator takes a scan out of the map and puts it back, and it is recorded', async () => {
  const del = (id, body) => stack.api('DELETE', `/api/v1/scans/${id}`, body && { body: JSON.stringify(body) });
  const viewer = await stack.api('DELETE', '/api/v1/scans/2', { auth: stack.viewerToken });
  assert.equal(viewer.status, 403);
  assert.equal((await del(99)).status, 404);
  let r = await del(2, { by: 'Ann', reason: 'ghost walls\nfrom a wrong match' });
  assert.equal(r.status, 200);
  const out = await r.json();
  assert.equal(out.excluded.by, 'operator Ann');
  assert.equal(out.excluded.reason, 'ghost walls\nfrom a wrong match');
  r = await del(2);
  assert.equal(r.status, 409);
  assert.equal((await errorOf(r)).code, 'already_excluded');
  r = await del(1);
  assert.equal(r.status, 409, 'the last scan in the map stays');
  assert.equal((await errorOf(r)).code, 'last_scan');
  const s = await stack.waitFor('the map without scan 2', async () => {
    const j = await session();
    return j.scans === 1 && j.rebuilding === null ? j : undefined;
  });
  assert.ok(s.points > 0);
  const list = await (await stack.api('GET', '/api/v1/scans')).json();
  assert.deepEqual(list.scans.map((x) => x.id), [1]);
  assert.ok(list.excluded.some((x) => x.id === 2));
  assert.equal((await stack.api('GET', '/api/v1/scans/2')).status, 200);
  r = await stack.api('POST', '/api/v1/scans/2/restore', { body: JSON.stringify({ by: 'Eve' }) });
  assert.equal(r.status, 200);
  assert.equal((await r.json()).excluded, null);
  await stack.waitFor('scan 2 back in the map', async () => ((await session()).scans === 2 ? true : undefined));
  assert.equal((await stack.api('POST', '/api/v1/scans/2/restore')).status, 409);
  // Out again, to be found out after the restart below.
  assert.equal((await del(2, { reason: 'kept out' })).status, 200);
  await stack.waitFor('scan 2 out again', async () => ((await session()).scans === 1 ? true : undefined));
});

test('after a restart a lost scan file is reported, not silently missing', async () => {
  await stack.stop({ keepDir: true });
  const scans = join(stack.dir, 'session', 'scans');
  rmSync(join(scans, 'scan_000001.ply'));
  // Scan 2's file as a session from before points were checked may hold it: a point at 1e30.
  writeFileSync(join(scans, 'scan_000002.ply'), roomPly([[1e30, 0, 0]]));
  stack = await startStack({ bridge: false, dir: stack.dir });
  const s = await stack.waitFor('the session rebuilt', async () => {
    const j = await session();
    return j.rebuilding === null ? j : undefined;
  });
  assert.equal(s.scans, 0, 'scan 1 is lost, scan 2 is kept out');
  assert.equal(s.scans_not_in_map.length, 1);
  assert.equal(s.scans_not_in_map[0].id, 1);
  assert.match(s.scans_not_in_map[0].reason, /scan_000001\.ply/);
  const list = await (await stack.api('GET', '/api/v1/scans')).json();
  assert.deepEqual(list.not_in_map.map((x) => x.id), [1]);
  assert.equal(list.excluded.find((x) => x.id === 2).excluded.reason, 'kept out');
  // Put back after the restart: read from its file.
  assert.equal((await stack.api('POST', '/api/v1/scans/2/restore')).status, 200);
  const back = await stack.waitFor('scan 2 back from its file', async () => {
    const j = await session();
    return j.scans === 1 ? j : undefined;
  });
  for (const v of [...back.bounds.min, ...back.bounds.max]) {
    assert.ok(Math.abs(v) < 30, `the point at 1e30 stays out: bounds ${JSON.stringify(back.bounds)}`);
  }
});

test('scan files without their database are refused, not emptied', async () => {
  await stack.stop({ keepDir: true });
  const sessionDir = join(stack.dir, 'session');
  for (const f of ['session.sqlite', 'session.sqlite-wal', 'session.sqlite-shm']) {
    rmSync(join(sessionDir, f), { force: true });
  }
  const r = await runServer(sessionDir);
  assert.notEqual(r.code, 0);
  assert.match(r.out, /holds 9 scan files .* but no session\.sqlite/);
  const left = readdirSync(join(sessionDir, 'scans')).filter((f) => f.endsWith('.ply'));
  assert.equal(left.length, 9, 'every scan file is still there');
  assert.ok(!existsSync(join(sessionDir, 'session.sqlite')));
  stack = undefined;
});

test('a full disk refuses new scans with 503 and loses none it acknowledged', async () => {
  // A file-size limit of 400 kB (RLIMIT_FSIZE: no root needed) stands for a full disk: the
  // session's database and scan files cannot grow past it.
  const dir2 = mkdtempSync(join(tmpdir(), 'scanplan-full-'));
  const sessionDir = join(dir2, 'session');
  const token = 'f'.repeat(32);
  const start = (limitKb) => {
    const p = spawn('sh', ['-c', `${limitKb ? `ulimit -f ${limitKb}; ` : ''}exec "$0" "$@"`,
      requireEnv('SCANPLAN_SERVER'), '--session', sessionDir, '--listen', '127.0.0.1:0',
      '--domain', requireEnv('SCANPLAN_TEST_DOMAIN'), '--web', requireEnv('SCANPLAN_WEB_DIR')],
    { env: { ...process.env, SCANPLAN_OPERATOR_TOKEN: token }, stdio: ['ignore', 'pipe', 'pipe'] });
    p.log = '';
    p.stdout.on('data', (c) => { p.log += c; });
    p.stderr.on('data', (c) => { p.log += c; });
    p.exited = new Promise((resolve) => p.on('exit', resolve));
    return p;
  };
  const urlOf = async (p) => {
    for (let i = 0; i < 150; i++) {
      const m = p.log.match(/listening on (http:\/\/[0-9.:]+)\//);
      if (m) return m[1];
      await new Promise((r) => setTimeout(r, 100));
    }
    throw new Error(`the server did not start:\n${p.log}`);
  };
  const call = (url, method, path, body) =>
    fetch(url + path, { method, headers: { Authorization: `Bearer ${token}` }, body });
  let server = start(400);
  try {
    let url = await urlOf(server);
    let acknowledged = 0;
    let refused;
    for (let i = 0; i < 40 && !refused; i++) {
      const r = await call(url, 'POST', `/api/v1/scans?x=${i % 5}&y=0&z=0&yaw_deg=0`, roomPly());
      if (r.status === 201) acknowledged++;
      else refused = { status: r.status, error: (await r.json()).error };
    }
    assert.ok(refused, 'the limit was reached');
    assert.ok(acknowledged >= 1);
    assert.equal(refused.status, 503);
    assert.equal(refused.error.code, 'storage_failed');
    // Still serving, and every acknowledged scan joins the map.
    let s;
    for (let i = 0; i < 300; i++) {
      s = await (await call(url, 'GET', '/api/v1/session')).json();
      if (s.scans === acknowledged) break;
      await new Promise((r) => setTimeout(r, 100));
    }
    assert.equal(s.scans, acknowledged);
    // Before the limit refused a scan, it refused matches' poses: those scans stayed in the map,
    // and the session says why, with the database's own reason.
    assert.match(s.storage_failure?.message ?? '', /could not be recorded in the session: .*(full|disk|large)/i);
    assert.equal((await call(url, 'GET', '/api/v1/health')).status, 200);
    server.kill('SIGTERM');
    await server.exited;
    // With room again, a restart brings back every scan that was acknowledged, and no other.
    server = start(0);
    url = await urlOf(server);
    let back;
    // The restart rebuilds the map from every scan: seconds alone, more beside other tests.
    for (let i = 0; i < 600; i++) {
      back = await (await call(url, 'GET', '/api/v1/session')).json();
      if (back.rebuilding === null && back.scans === acknowledged) break;
      await new Promise((r) => setTimeout(r, 100));
    }
    assert.equal(back.scans, acknowledged);
    assert.deepEqual(back.scans_not_in_map, []);
    assert.ok(!readdirSync(join(sessionDir, 'scans')).some((f) => f.endsWith('.part')), 'no half-written file');
  } finally {
    server.kill('SIGKILL');
    await server.exited;
    rmSync(dir2, { recursive: true, force: true });
  }
});
