// From the end of a scan to its new candidates visible in the operator's page (issue 18's target,
// issue 19's path): a real bridge (the campus, time scale 600), server and Debian's Chromium at
// 1366×768. For each scan: `done` = the scan_progress "done" event's server time (the bridge's last
// word on the scan, on the same machine), `server` = the plan_done event's server time (the
// baseline: the candidates exist on the server), `page` = the animation frame in which the page's
// candidate list first shows the plan made after that scan (and the scan is drawn). The top
// candidate is approved over REST each time (not clicked: the click's own delay is not the path).
// Stage by stage (medians, from the server's event times and the page's clock): the scan's way in
// (done → scan_received: DDS transfer, the PLY synced), matching (→ match_done), the map, regions,
// layers and plan (→ plan_done; of which the planner's own plan_ms), the page (→ candidates
// shown), and the scan's chunk drawn in the 3-D view (plan_done → drawn); beside them the
// server's own account of each scan (map_updated's stages_ms: match, graph, map, thin, plan,
// layers). Prints one JSON line. Usage: tests/bench/scan_to_page.sh [SCANS] [ROBOTS]; with
// SCANPLAN_BENCH_SERVER_LOG=FILE the server's log is kept there.
import { readFileSync, writeFileSync } from 'node:fs';
import { requestScan, scratchDir, startStack, worldVariant } from '../support/stack.mjs';
import { openPage, withBrowser } from '../support/browser.mjs';

const scans = Number(process.argv[2] || 15);
const robots = Number(process.argv[3] || 1);
const { file } = worldVariant(scratchDir('scanplan-latency-'), 'campus.json', {});
const { bounds } = JSON.parse(readFileSync(file, 'utf8'));
const stack = await startStack({ world: file });
const median = (v) => {
  const s = [...v].sort((a, b) => a - b);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : null;
};
try {
  for (let k = 2; k <= robots; k++) stack.startBridge(['--robot-id', `robot${k}`, '--start', `${80 + 12 * (k - 1)},45,0`]);
  await stack.waitFor('the bridges', async () => (await (await stack.api('GET', '/api/v1/health', { auth: null })).json()).bridges === robots || undefined, 20000);
  const target = [bounds.min, [bounds.max[0], bounds.min[1]], bounds.max, [bounds.min[0], bounds.max[1]]];
  await stack.api('PUT', '/api/v1/params', { body: JSON.stringify({ target }) });

  const result = await withBrowser(async (context) => {
    const { page } = await openPage(context, `${stack.url}/?token=${encodeURIComponent(stack.token)}`);
    await page.waitForFunction(() => document.body.dataset.ws === 'open', null, { timeout: 30000 });
    // In the page: the server times of each scan's end and plan, and the frame that shows it.
    await page.evaluate(() => {
      const log = { done: {}, plan: {}, shown: {}, received: {}, matched: {}, drawn: {}, inside: {} }; // by robot, or by scan
      window.__latency = log;
      const push = (k, robot, v) => (log[k][robot] ??= []).push(v);
      const { events, candidates } = window.scanplan;
      const inner = events.onEvent;
      events.onEvent = (e) => {
        if (e.type === 'scan_progress' && e.state === 'done') push('done', e.robot, Date.parse(e.at));
        if (e.type === 'plan_done') push('plan', e.robot, { at: Date.parse(e.at), scan: e.based_on_scan, ms: e.plan_ms });
        if (e.type === 'scan_received') push('received', e.robot, { at: Date.parse(e.at), scan: e.scan });
        if (e.type === 'match_done') log.matched[e.scan] = Date.parse(e.at);
        if (e.type === 'map_updated' && e.stages_ms) log.inside[e.scan] = e.stages_ms;
        inner(e);
      };
      const { view } = window.scanplan;
      const addChunk = view.addChunk.bind(view);
      view.addChunk = (c) => {
        log.drawn[c.id] ??= Date.now();
        return addChunk(c);
      };
      const seen = new Set();
      const frame = () => {
        for (const p of candidates.plans || []) {
          const key = `${p.robot}:${p.based_on_scan}`;
          const rows = document.querySelectorAll(`#cand-list .cand-row[data-robot="${p.robot}"], #cand-list .cand-row:not([data-robot])`).length;
          const drawn = Number(document.body.dataset.chunks) >= 1;
          if (!seen.has(key) && rows && drawn) {
            seen.add(key);
            push('shown', p.robot, { at: Date.now(), scan: p.based_on_scan });
          }
        }
        requestAnimationFrame(frame);
      };
      requestAnimationFrame(frame);
    });
    await requestScan(stack);
    let taken = robots;
    const lastPlanOf = {};
    while (taken < scans) {
      // Each robot whose newest plan came after its own latest scan goes to its top candidate.
      const c = await (await stack.api('GET', '/api/v1/candidates')).json();
      let sent = 0;
      for (const p of c.plans) {
        if (lastPlanOf[p.robot] === p.id || taken >= scans) continue;
        const top = c.candidates.find((x) => x.plan === p.id && x.state === 'proposed');
        const driving = c.candidates.some((x) => x.robot === p.robot && x.state === 'moving');
        if (!top || driving) continue;
        const r = await stack.api('POST', `/api/v1/candidates/${top.id}/approve`, { body: '{}' });
        if (r.status === 200) {
          lastPlanOf[p.robot] = p.id;
          taken += 1;
          sent += 1;
        }
      }
      if (!sent) await new Promise((r) => setTimeout(r, 100));
    }
    await stack.waitFor('the last scans in the page', async () => {
      const s = await (await stack.api('GET', '/api/v1/session')).json();
      if (s.scans < scans) return undefined;
      const shown = await page.evaluate(() => Object.values(window.__latency.shown).flat().length);
      return shown >= scans ? true : undefined;
    }, 180000);
    // At rest the view fills in the rest of the budget, pass by pass.
    const rest0 = Date.now();
    await page.waitForFunction(() => !window.scanplan.view.fill && !window.scanplan.view.dirty, null, { timeout: 60000, polling: 50 });
    const atRest = await page.evaluate(() => ({ held: window.scanplan.view.pointCount, drawn: window.scanplan.view.drawnCount, budget: window.scanplan.view.budget, points_per_ms: Math.round(window.scanplan.view.pointsPerMs ?? 0) }));
    atRest.fill_ms = Date.now() - rest0;
    return { ...(await page.evaluate(() => window.__latency)), atRest };
  });

  // The server's CPU time over the whole run (user + system, /proc/PID/stat fields 14 and 15).
  const stat = readFileSync(`/proc/${stack.server.pid}/stat`, 'utf8');
  const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
  const serverCpuS = (Number(fields[11]) + Number(fields[12])) / 100;
  // Pair each scan end with the first plan of that robot after it, and that plan's frame.
  const page = [];
  const server = [];
  const stages = { way_in: [], matching: [], map_and_plan: [], of_which_planner: [], page: [], chunk_drawn_after_plan: [] };
  // Inside the server, per scan (map_updated's stages_ms: match, graph, map, thin, plan, layers).
  const inside = {};
  for (const [robot, ends] of Object.entries(result.done)) {
    for (const done of ends) {
      const plan = (result.plan[robot] || []).find((p) => p.at >= done);
      if (!plan) continue;
      const shown = (result.shown[robot] || []).find((s) => s.scan === plan.scan);
      server.push(plan.at - done);
      if (shown) page.push(shown.at - done);
      const received = (result.received[robot] || []).find((r) => r.scan === plan.scan);
      const matched = result.matched[plan.scan];
      if (received) stages.way_in.push(received.at - done);
      if (received && matched) stages.matching.push(matched - received.at);
      if (matched) stages.map_and_plan.push(plan.at - matched);
      if (Number.isFinite(plan.ms)) stages.of_which_planner.push(plan.ms);
      if (shown) stages.page.push(shown.at - plan.at);
      if (result.drawn[plan.scan]) stages.chunk_drawn_after_plan.push(result.drawn[plan.scan] - plan.at);
      for (const [k, v] of Object.entries(result.inside[plan.scan] ?? {})) (inside[k] ??= []).push(v);
    }
  }
  console.log(JSON.stringify({
    bench: 'scan_to_page',
    robots,
    scans: page.length,
    page_ms_median: median(page),
    page_ms_max: Math.max(...page),
    server_ms_median: median(server),
    server_ms_max: Math.max(...server),
    page_minus_server_ms_median: median(page) - median(server),
    server_cpu_s: serverCpuS,
    stage_ms_median: Object.fromEntries(Object.entries(stages).map(([k, v]) => [k, median(v)])),
    server_stage_ms_median: Object.fromEntries(Object.entries(inside).map(([k, v]) => [k, median(v)])),
    page_ms: page.map(Math.round),
    at_rest: result.atRest,
  }));
} finally {
  await stack.stop();
  if (process.env.SCANPLAN_BENCH_SERVER_LOG) writeFileSync(process.env.SCANPLAN_BENCH_SERVER_LOG, stack.server.log);
}
