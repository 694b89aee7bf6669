// Issue 16's load target: with HOSTILE connections open against the server (a quarter each of
// unauthenticated 200 MB uploads, authenticated uploads trickling below the minimum rate,
// clients pipelining map.drc without reading, and event WebSockets that never read, spread over
// three client addresses of the loopback net), a normal client (its own address) keeps getting
// GET /api/v1/session answered quickly, and the server's memory stays bounded. The same client
// against the quiet server first, in the same run. Scans are posted during the attack so the
// event sockets have chunks to fall behind on. Prints one JSON line. Run with
// tests/bench/hostile_bench.sh.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import http from 'node:http';
import { connect } from 'node:net';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startStack, requireEnv } from '../support/stack.mjs';

const hostile = Number(process.argv[2] ?? 600);
const src = requireEnv('SCANPLAN_SOURCE_DIR');
const cli = requireEnv('SCANPLAN_CLI');
const work = mkdtempSync(join(tmpdir(), 'scanplan-hostile-'));
const world = join(src, 'samples/worlds/yard.json');
const poses = [[-15, -8, 0, 0], [5, -14, 0, 90], [-20, 12, 0, -45], [10, 10, 0, 180]];
const scans = poses.map(([x, y, z, yaw], i) => {
  const out = join(work, `s${i}.ply`);
  execFileSync(cli, ['scan', '--world', world, '--at', `${x},${y},${z},${yaw}`, '--out', out, '--seed', String(i + 1)],
    { stdio: ['ignore', 'ignore', 'ignore'] });
  return readFileSync(out);
});

const stack = await startStack({ bridge: false, dir: join(work, 'stack') });
const { hostname, port } = new URL(stack.url);
const post = (i) => stack.api('POST', `/api/v1/scans?x=${poses[i][0]}&y=${poses[i][1]}&z=0&yaw_deg=${poses[i][3]}`, { body: scans[i] });
for (let i = 0; i < 2; i++) await post(i);
await stack.waitFor('two scans in the map', async () => {
  const s = await (await stack.api('GET', '/api/v1/session')).json();
  return s.scans === 2 ? s : undefined;
});
const mapBytes = (await (await stack.api('GET', '/api/v1/map.drc')).arrayBuffer()).byteLength;

function memory() {
  const status = readFileSync(`/proc/${stack.server.pid}/status`, 'utf8');
  const field = (name) => Number(status.match(new RegExp(`${name}:\\s+(\\d+)`))[1]) / 1024;
  return { rss: field('VmRSS'), hwm: field('VmHWM') };
}

// The normal client: keep-alive, from 127.0.0.2.
const agent = new http.Agent({ keepAlive: true, maxSockets: 1, localAddress: '127.0.0.2' });
function get(path) {
  return new Promise((resolve) => {
    const started = process.hrtime.bigint();
    const req = http.request({ host: hostname, port, path, agent, headers: { Authorization: `Bearer ${stack.token}` } }, (res) => {
      res.resume();
      res.on('end', () => resolve({ status: res.statusCode, ms: Number(process.hrtime.bigint() - started) / 1e6 }));
    });
    req.on('error', () => resolve({ status: 0, ms: Number(process.hrtime.bigint() - started) / 1e6 }));
    req.end();
  });
}
async function measure(n) {
  const ms = [];
  let failed = 0;
  for (let i = 0; i < n; i++) {
    const r = await get('/api/v1/session');
    if (r.status === 200) ms.push(r.ms);
    else failed++;
    await new Promise((r2) => setTimeout(r2, 10));
  }
  ms.sort((a, b) => a - b);
  return { median: ms[Math.floor(ms.length / 2)] ?? null, p95: ms[Math.floor(ms.length * 0.95)] ?? null, failed };
}

const quiet = await measure(200);

// The attack. Each kind opens its connections from one of three addresses, round robin.
const sockets = [];
const answered = { refused_401: 0, timed_out_408: 0, over_limit_503: 0 };
function open(i, first, then) {
  const s = connect({ host: hostname, port: Number(port), localAddress: `127.0.0.${3 + (i % 3)}` });
  s.on('error', () => {});
  s.on('data', (c) => {
    const t = c.toString('latin1', 0, 16);
    if (t.startsWith('HTTP/1.1 401')) answered.refused_401++;
    else if (t.startsWith('HTTP/1.1 408')) answered.timed_out_408++;
    else if (t.startsWith('HTTP/1.1 503')) answered.over_limit_503++;
  });
  s.on('connect', () => {
    s.write(first);
    if (then) then(s);
  });
  sockets.push(s);
  return s;
}
const kinds = [
  // An upload without a valid token announcing 200 MB, sending on.
  (i) => open(i, 'POST /api/v1/scans?x=0&y=0&z=0&yaw_deg=0 HTTP/1.1\r\nHost: h\r\nContent-Length: 200000000\r\n\r\n',
    (s) => { s.timer = setInterval(() => s.write(Buffer.alloc(16384)), 200); }),
  // An operator's upload trickling 100 bytes a second.
  (i) => open(i, `PUT /api/v1/params HTTP/1.1\r\nHost: h\r\nAuthorization: Bearer ${stack.token}\r\nContent-Length: 100000000\r\n\r\n`,
    (s) => { s.timer = setInterval(() => s.write('x'.repeat(100)), 1000); }),
  // Thirty-two map requests pipelined, never read.
  (i) => open(i, `GET /api/v1/map.drc HTTP/1.1\r\nHost: h\r\nAuthorization: Bearer ${stack.token}\r\n\r\n`.repeat(32),
    (s) => s.pause()),
  // An event WebSocket that never reads.
  (i) => open(i, `GET /api/v1/events?token=${stack.viewerToken} HTTP/1.1\r\nHost: ${hostname}:${port}\r\nUpgrade: websocket\r\n` +
    'Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n', (s) => s.pause()),
];
for (let i = 0; i < hostile; i++) kinds[i % kinds.length](i);
await new Promise((r) => setTimeout(r, 2000));
// New scans while under attack: events and map chunks for the sockets that never read.
const posted = [];
for (let i = 2; i < poses.length; i++) posted.push((await post(i)).status);
const underAttack = await measure(200);
await new Promise((r) => setTimeout(r, 12000)); // past the trickling uploads' grace period
const later = await measure(100);
const mem = memory();
const sessionAfter = await (await stack.api('GET', '/api/v1/session')).json();

for (const s of sockets) {
  clearInterval(s.timer);
  s.destroy();
}
agent.destroy();
await stack.stop();
rmSync(work, { recursive: true, force: true });
console.log(JSON.stringify({
  bench: 'hostile_clients',
  hostile_connections: hostile,
  map_drc_bytes: mapBytes,
  quiet_median_ms: quiet.median,
  quiet_p95_ms: quiet.p95,
  under_attack_median_ms: underAttack.median,
  under_attack_p95_ms: underAttack.p95,
  under_attack_failed: underAttack.failed,
  after_grace_median_ms: later.median,
  after_grace_failed: later.failed,
  scans_posted_under_attack: posted,
  scans_in_map: sessionAfter.scans,
  answered,
  rss_mb: Math.round(mem.rss),
  rss_mb_peak: Math.round(mem.hwm),
}));
