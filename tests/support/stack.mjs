// Starts a real scanplan-bridge + scanplan-server pair for a process-level test: DDS on
// loopback in the test's own domain, HTTP on an ephemeral port, a session in a temp directory.
import { execFileSync, spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { randomBytes } from 'node:crypto';

const env = process.env;

export const loopbackDds =
  '<CycloneDDS><Domain Id="any"><General><Interfaces>' +
  '<NetworkInterface address="127.0.0.1" multicast="true"/>' +
  '</Interfaces></General></Domain></CycloneDDS>';

export function requireEnv(name) {
  const v = env[name];
  if (!v) throw new Error(`${name} is not set: run this test through ctest (make test)`);
  return v;
}

// A temporary directory that is removed when the test process exits, however it ends.
const scratch = [];
process.on('exit', () => {
  for (const dir of scratch) rmSync(dir, { recursive: true, force: true });
});
export function scratchDir(prefix) {
  const dir = mkdtempSync(join(tmpdir(), prefix));
  scratch.push(dir);
  return dir;
}

// A copy of a sample world with overrides, e.g. exact poses for a test that checks geometry.
export function worldVariant(dir, sampleName, overrides) {
  const src = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples', 'worlds', sampleName);
  const world = { ...JSON.parse(readFileSync(src, 'utf8')), ...overrides };
  const file = join(dir, sampleName);
  writeFileSync(file, JSON.stringify(world));
  return { file, world };
}

function startProcess(cmd, args, extraEnv, name) {
  const child = spawn(cmd, args, {
    env: { ...env, CYCLONEDDS_URI: loopbackDds, ...extraEnv },
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  child.log = '';
  const keep = (chunk) => {
    child.log += chunk.toString();
    if (child.log.length > 200_000) child.log = child.log.slice(-100_000);
  };
  child.stdout.on('data', keep);
  child.stderr.on('data', keep);
  child.exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal })));
  child.label = name;
  return child;
}

async function waitFor(what, fn, timeoutMs, procs = []) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    for (const p of procs) {
      if (p.exitCode !== null) throw new Error(`${p.label} exited (${p.exitCode}) while waiting for ${what}:\n${p.log}`);
    }
    const v = await fn().catch(() => undefined);
    if (v) return v;
    if (Date.now() > deadline) {
      throw new Error(`timed out waiting for ${what}\n` + procs.map((p) => `--- ${p.label}\n${p.log}`).join('\n'));
    }
    await new Promise((r) => setTimeout(r, 100));
  }
}

// The server's --odometry for a world file's pose_noise: exact when an absolute model has no
// noise at all.
export function odometryOf(worldFile) {
  const noise = JSON.parse(readFileSync(worldFile, 'utf8')).pose_noise ?? {};
  if (noise.model !== 'absolute') return 'drift';
  const exact = ['xy_sigma_m', 'z_sigma_m', 'yaw_sigma_deg'].every((k) => noise[k] === 0);
  return exact ? 'exact' : 'absolute';
}

export async function startStack({ world, replay, odometry: odometryArg, timeScale = 600, seed = 1, bridge: withBridge = true,
                                   dir = mkdtempSync(join(tmpdir(), 'scanplan-test-')), tokens } = {}) {
  const domain = requireEnv('SCANPLAN_TEST_DOMAIN');
  const token = tokens?.operator ?? randomBytes(16).toString('hex');
  const viewerToken = tokens?.viewer ?? randomBytes(16).toString('hex');
  const worldFile = world ?? join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/yard.json');
  // The server is told the robots' pose sensors, as an operator would configure it.
  const odometry = odometryArg ?? (replay ? 'absolute' : odometryOf(worldFile));

  const server = startProcess(
    requireEnv('SCANPLAN_SERVER'),
    ['--session', join(dir, 'session'), '--listen', '127.0.0.1:0', '--domain', domain,
     '--web', requireEnv('SCANPLAN_WEB_DIR'), '--odometry', odometry],
    { SCANPLAN_OPERATOR_TOKEN: token, SCANPLAN_VIEWER_TOKEN: viewerToken }, 'scanplan-server');
  const launchBridge = (extraArgs = []) => startProcess(
    requireEnv('SCANPLAN_BRIDGE'),
    [...(replay ? ['--replay', replay] : ['--world', worldFile]),
     '--domain', domain, '--time-scale', String(timeScale), '--seed', String(seed), ...extraArgs],
    {}, 'scanplan-bridge');
  const bridge = withBridge && launchBridge();
  const procs = withBridge ? [server, bridge] : [server];

  // A stack that fails to come up takes its processes down with it (a stray bridge would keep
  // node, and so the test, running until ctest's timeout).
  const url = await waitFor('the server to listen',
    async () => server.log.match(/listening on (http:\/\/[0-9.:]+)\//)?.[1], 15000, procs)
    .catch((e) => {
      for (const p of procs) if (p.exitCode === null && p.signalCode === null) p.kill('SIGKILL');
      throw e;
    });

  const api = async (method, path, { auth = token, body } = {}) => {
    const headers = auth ? { Authorization: `Bearer ${auth}` } : {};
    return fetch(url + path, { method, headers, body });
  };

  const stack = {
    url, token, viewerToken, dir, server, bridge, api,
    waitFor: (what, fn, timeoutMs = 60000) => waitFor(what, fn, timeoutMs, procs),
    // Another bridge on the same domain and world (e.g. one replacing a killed bridge); it is
    // watched and stopped with the stack. A process killed on purpose does not fail waitFor.
    startBridge(extraArgs = []) {
      const b = launchBridge(extraArgs);
      procs.push(b);
      return b;
    },
    async stop({ keepDir = false, signal = 'SIGTERM' } = {}) {
      for (const p of procs) if (p.exitCode === null && p.signalCode === null) p.kill(signal);
      const results = await Promise.all(procs.map((p) => p.exited));
      if (!keepDir) rmSync(dir, { recursive: true, force: true });
      return results;
    },
  };
  if (withBridge) {
    await stack.waitFor('the bridge to be matched on DDS', async () => {
      const h = await (await api('GET', '/api/v1/health', { auth: null })).json();
      return h.bridges >= 1;
    }, 20000);
  }
  return stack;
}

// Asks for one scan; returns the command id.
export async function requestScan(stack) {
  const r = await stack.api('POST', '/api/v1/scan');
  if (r.status !== 202) throw new Error(`POST /api/v1/scan answered ${r.status}: ${await r.text()}`);
  return (await r.json()).command_id;
}

// Asks for one scan and waits until the session holds `count` scans.
export async function scanAndWait(stack, count) {
  await requestScan(stack);
  return stack.waitFor(`scan ${count} in the session`, async () => {
    const s = await (await stack.api('GET', '/api/v1/session')).json();
    return s.scans >= count ? s : undefined;
  });
}

// A stack whose bridge replays one recorded yard scan taken at (−15, −8) (such a bridge cannot
// drive: it refuses every move), with that scan in the session and its plan made.
export async function startOneScanReplay() {
  const dir = scratchDir('scanplan-replay-');
  execFileSync(requireEnv('SCANPLAN_CLI'), ['scan', '--world', join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/yard.json'),
    '--at', '-15,-8,0,0', '--out', join(dir, 'scan0.ply'), '--seed', '1'], { stdio: 'ignore' });
  writeFileSync(join(dir, 'poses.csv'), 'file,x,y,z,yaw_deg\nscan0.ply,-15,-8,0,0\n');
  const stack = await startStack({ replay: dir });
  await scanAndWait(stack, 1);
  return stack;
}

// Runs `scanplan args…` against `stack` (its URL, the given token: the operator's by default)
// to completion: { code, stdout, stderr }.
export function runCli(stack, args, token = stack.token) {
  return new Promise((resolve) => {
    const child = spawn(requireEnv('SCANPLAN_CLI'), [...args, '--server', stack.url, '--token', token],
      { stdio: ['ignore', 'pipe', 'pipe'] });
    let stdout = '', stderr = '';
    child.stdout.on('data', (d) => { stdout += d; });
    child.stderr.on('data', (d) => { stderr += d; });
    child.on('exit', (code) => resolve({ code, stdout, stderr }));
  });
}
