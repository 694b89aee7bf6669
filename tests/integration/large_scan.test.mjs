// A scan larger than the 300k points DESIGN.md promises must cross DDS whole: a closed room
// where every beam returns, at a finer angular step than the default.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { startStack, scanAndWait, scratchDir } from '../support/stack.mjs';

const wall = [120, 120, 120];
const room = {
  name: 'closed-room',
  bounds: { min: [-6, -6], max: [6, 6] },
  ground: { z: 0 },
  objects: [
    { type: 'box', min: [-6, -6, 0], max: [6, -5, 4], color: wall },
    { type: 'box', min: [-6, 5, 0], max: [6, 6, 4], color: wall },
    { type: 'box', min: [-6, -5, 0], max: [-5, 5, 4], color: wall },
    { type: 'box', min: [5, -5, 0], max: [6, 5, 4], color: wall },
    { type: 'box', min: [-6, -6, 4], max: [6, 6, 4.5], color: [200, 60, 60] },
  ],
  start: [0.3, -0.2, 10],
  scanner: { vertical_step_deg: 0.4, rotation_step_deg: 0.4 },
  pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
};
// 180° / 0.4° + 1 beams per fan, 360° / 0.4° stage angles; none can miss inside the room.
const expected = (180 / 0.4 + 1) * (360 / 0.4);

let stack;
after(async () => stack && (await stack.stop()));

test(`a ${expected}-point scan arrives whole`, async () => {
  const dir = scratchDir('scanplan-room-');
  const file = join(dir, 'room.json');
  writeFileSync(file, JSON.stringify(room));
  stack = await startStack({ world: file });
  const session = await scanAndWait(stack, 1);
  assert.ok(expected > 300000);
  assert.equal(session.points, expected);
  assert.equal(session.robots.robot1.scan.message, `${expected} points`);
});
