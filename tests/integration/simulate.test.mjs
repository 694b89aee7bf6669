// `scanplan simulate`: the closed loop without DDS writes coverage.csv, a top view per step and a
// JSON summary (DESIGN.md "CLI").
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, existsSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { requireEnv } from '../support/stack.mjs';

test('simulate on the tree-row world', { timeout: 120000 }, () => {
  const out = mkdtempSync(join(tmpdir(), 'scanplan-sim-'));
  try {
    const run = spawnSync(requireEnv('SCANPLAN_CLI'), ['simulate', '--world',
      join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/tree_row.json'), '--policy', 'paper',
      '--alpha', '0.5', '--max-scans', '4', '--seed', '3', '--out', out], { encoding: 'utf8' });
    assert.equal(run.status, 0, run.stderr);
    const summary = JSON.parse(run.stdout);
    assert.equal(summary.world, 'tree_row');
    const n = summary.scans.length;
    assert.ok(n >= 2 && n <= 4, JSON.stringify(summary));
    // The robot reports drifting odometry (the world file has no pose_noise) and the pose graph
    // is on; its edges are listed with their error against the truth.
    assert.equal(summary.odometry, 'drift');
    assert.equal(summary.graph, 'on');
    assert.ok(summary.edges.length >= n - 1, 'an odometry edge between consecutive scans at least');
    for (const e of summary.edges) {
      assert.ok(['odometry', 'map', 'map-confirmed', 'pair-search', 'rematch'].includes(e.origin), e.origin);
      assert.ok(e.error_m >= 0 && e.whitened >= 0 && e.from >= 1 && e.to <= n, JSON.stringify(e));
    }
    // Each scan: reported, matched (by matching alone), joined (after the graph that step),
    // placed (the graph's at the end) and true pose in the map frame, and the match (none for
    // the first, which defines the map frame; the placed error is measured against it).
    const pose = (p) => ['x', 'y', 'z', 'yaw_deg'].every((k) => Number.isFinite(p[k]));
    summary.scans.forEach((s, i) => {
      assert.equal(s.scan, i + 1);
      assert.ok(pose(s.reported) && pose(s.matched) && pose(s.joined) && pose(s.placed) &&
        pose(s.true), JSON.stringify(s));
      assert.ok(s.matched_error_m >= 0 && s.joined_error_m >= 0);
      assert.ok(s.graph.pairs_matched <= s.graph.pairs_tried);
      assert.ok(s.placed_error_m >= 0 && s.placed_error_deg >= 0);
      if (i === 0) {
        assert.equal(s.match, null);
        assert.equal(s.placed_error_m, 0);
        assert.ok(Math.abs(s.true.x - s.placed.x) < 1e-9, 'the first scan defines the map frame');
      } else {
        assert.equal(typeof s.match.applied, 'boolean');
        assert.equal(typeof s.match.converged, 'boolean');
        assert.equal(typeof s.match.reason, 'string');
        // Refused: x, y and yaw where matching started (the robot's last anchored scan moved
        // by its odometry since), z set on the map's ground (within 1 m).
        if (!s.match.applied) {
          for (const k of ['x', 'y', 'yaw_deg']) assert.equal(s.matched[k], s.match.prior[k], k);
          assert.ok(Math.abs(s.matched.z - s.match.prior.z) <= 1.0, JSON.stringify(s));
        }
        // What the plan that sent the robot there forecast of the match.
        // On drifting odometry (the world's), with the drive's reach of the matcher's search.
        assert.ok(s.forecast === null || (s.forecast.overlap_share >= 0 &&
          s.forecast.overlap_share <= 1 && s.forecast.factor > 0 && s.forecast.factor <= 1 &&
          s.forecast.reach > 0 && s.forecast.reach <= 1),
        JSON.stringify(s.forecast));
      }
    });
    assert.equal(summary.accuracy.matches_tried, n - 1);
    assert.ok(summary.accuracy.matches_applied <= n - 1);
    const rows = readFileSync(join(out, 'coverage.csv'), 'utf8').trim().split('\n');
    assert.equal(rows[0],
      'scan,x,y,detected_m2,completed_m2,coverage_pct,path_m,plan_ms,placed_error_m,placed_error_deg,' +
      'matched_error_m,matched_error_deg');
    assert.equal(rows.length, n + 1);
    const cov = rows.slice(1).map((r) => r.split(',').map(Number));
    for (let i = 1; i < cov.length; i++) {
      assert.ok(cov[i][3] >= cov[i - 1][3], 'the detected area never shrinks');
      assert.ok(cov[i][6] > cov[i - 1][6], 'the robot drove between scans');
    }
    // Trees alone seldom fix a pose: scans the map cannot place wait outside it (the pose graph
    // keeps them out of the MLS map), so coverage may stay at the first scan's.
    assert.ok(cov.at(-1)[5] >= cov[0][5] && cov[0][5] > 40, `coverage ${cov.at(-1)[5]} %`);
    assert.ok(Math.abs(summary.coverage_pct - cov.at(-1)[5]) < 0.01);
    cov.forEach((row, i) => {
      assert.ok(Math.abs(row[8] - summary.scans[i].joined_error_m) < 1e-3, 'csv and summary agree');
      assert.ok(Math.abs(row[10] - summary.scans[i].matched_error_m) < 1e-3, 'csv and summary agree');
    });
    for (let i = 1; i <= n; i++) {
      assert.ok(existsSync(join(out, `step_${String(i).padStart(2, '0')}.png`)));
    }
    const bad = spawnSync(requireEnv('SCANPLAN_CLI'), ['simulate', '--world',
      join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/tree_row.json'), '--policy', 'teleport',
      '--out', out], { encoding: 'utf8' });
    assert.notEqual(bad.status, 0);
    assert.match(bad.stderr, /--policy must be paper, exhaustive, travel, nearest-frontier or random/);
  } finally {
    rmSync(out, { recursive: true, force: true });
  }
});
