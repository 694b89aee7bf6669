// Every REST replay script under samples/replays runs against a fresh server through
// `scanplan replay` (DESIGN.md "REST replay script") and must pass every step.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { readdirSync, statSync } from 'node:fs';
import { join } from 'node:path';
import { startStack, requireEnv } from '../support/stack.mjs';

const root = join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples', 'replays');
const scripts = readdirSync(root)
  .map((d) => join(root, d))
  .filter((d) => statSync(d).isDirectory())
  .flatMap((d) => readdirSync(d).filter((f) => f.endsWith('.replay.json')).map((f) => join(d, f)));

test('there are replay scripts', () => assert.ok(scripts.length > 0));

for (const script of scripts) {
  test(`replay ${script.slice(root.length + 1)}`, { timeout: 180000 }, async () => {
    // The scripts' reported poses are absolute fixes with bounded noise (σ 1 m, 5°), not odometry.
    const stack = await startStack({ bridge: false, odometry: 'absolute' });
    try {
      const run = spawnSync(requireEnv('SCANPLAN_CLI'),
        ['replay', script, '--server', stack.url, '--token', stack.token], { encoding: 'utf8' });
      assert.equal(run.status, 0, `replay failed:\n${run.stderr}\n${run.stdout}`);
      const summary = JSON.parse(run.stdout);
      assert.equal(summary.failed, 0);
      assert.ok(summary.passed > 5);
    } finally {
      await stack.stop();
    }
  });
}
