// Runs one of the stand-alone DDS listeners (tests/integration/*_listener.cpp) on the test's
// domain and collects the JSON lines it prints, one a sample.
import { spawn } from 'node:child_process';
import { createInterface } from 'node:readline';
import { loopbackDds, requireEnv } from './stack.mjs';

export async function startListener(envName, { seconds = 200, robots = [] } = {}) {
  const child = spawn(requireEnv(envName),
    ['--domain', requireEnv('SCANPLAN_TEST_DOMAIN'), '--seconds', String(seconds),
     ...(robots.length ? ['--robots', robots.join(',')] : [])],
    { env: { ...process.env, CYCLONEDDS_URI: loopbackDds }, stdio: ['ignore', 'pipe', 'pipe'] });
  const lines = [];
  let stderr = '';
  child.stderr.on('data', (c) => { stderr += c.toString(); });
  createInterface({ input: child.stdout }).on('line', (l) => lines.push(JSON.parse(l)));
  const exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal })));
  const listener = {
    lines,
    // Samples of `topic` so far, oldest first.
    of: (topic) => lines.filter((l) => l.topic === topic),
    // Resolves with the first line for which fn(line, index) is true.
    async waitFor(what, fn, timeoutMs = 60000) {
      const deadline = Date.now() + timeoutMs;
      for (;;) {
        const found = lines.find(fn);
        if (found) return found;
        if (child.exitCode !== null) throw new Error(`${envName} exited (${child.exitCode}) before ${what}: ${stderr}`);
        if (Date.now() > deadline) {
          throw new Error(`timed out waiting for ${what}; the listener saw:\n` +
            lines.map((l) => JSON.stringify(l).slice(0, 300)).join('\n') + `\n${stderr}`);
        }
        await new Promise((r) => setTimeout(r, 50));
      }
    },
    async stop() {
      if (child.exitCode === null && child.signalCode === null) child.kill('SIGTERM');
      const r = await exited;
      if (r.code !== 0) throw new Error(`${envName} ended with ${JSON.stringify(r)}: ${stderr}`);
    },
  };
  await listener.waitFor('the listener to be ready', (l) => l.ready === true, 15000);
  return listener;
}
