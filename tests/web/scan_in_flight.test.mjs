// The page's hold while the server works on a scan (web/src/scan_in_flight.js): busy from the
// first scan received to the plan or map update that settles the last, and never for longer than its cap.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { setTimeout as sleep } from 'node:timers/promises';
import { ScanInFlight } from '../../web/src/scan_in_flight.js';

function recorder(maxMs) {
  const calls = [];
  const f = new ScanInFlight({ onBusy: () => calls.push('busy'), onIdle: () => calls.push('idle'), maxMs });
  return { f, calls };
}

test('busy from the first scan received until every scan in flight is settled', () => {
  const { f, calls } = recorder(60000);
  f.received(3);
  f.received(4);
  f.received(4); // the same scan told twice is one scan
  assert.deepEqual(calls, ['busy']);
  f.settled(3);
  assert.equal(f.busy, true);
  f.settled(4);
  assert.equal(f.busy, false);
  assert.deepEqual(calls, ['busy', 'idle']);
});

test('a plan based on a later scan settles the earlier ones too', () => {
  const { f, calls } = recorder(60000);
  f.received(7);
  f.received(8);
  f.settled(8);
  assert.deepEqual(calls, ['busy', 'idle']);
  f.settled(9); // nothing in flight: no second idle
  assert.deepEqual(calls, ['busy', 'idle']);
});

test('words without a scan id change nothing', () => {
  const { f, calls } = recorder(60000);
  f.received(undefined);
  assert.equal(f.busy, false);
  f.received(2);
  f.settled(undefined);
  f.settled(1);
  assert.equal(f.busy, true);
  f.clear();
  assert.deepEqual(calls, ['busy', 'idle']);
});

test('a hold ends after maxMs from its first scan, whatever arrives meanwhile', async () => {
  const { f, calls } = recorder(60);
  f.received(1);
  await sleep(40);
  f.received(2); // a second robot's scan does not make the hold longer
  await sleep(40);
  assert.equal(f.busy, false);
  assert.deepEqual(calls, ['busy', 'idle']);
  f.settled(2); // its word, late, changes nothing
  f.received(3); // the next scan holds anew
  assert.deepEqual(calls, ['busy', 'idle', 'busy']);
  f.settled(3);
  assert.deepEqual(calls, ['busy', 'idle', 'busy', 'idle']);
});
