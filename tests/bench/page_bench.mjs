// The operator page with a 10 M-point map (issue 8): how long the 3-D view takes to draw a frame
// with the level of detail (default 4 M budget at rest, 35 % of it while the camera moves) against
// drawing every point (the baseline, budget above the points held), in the same run. A real
// server serves the page; the points are generated in the page (40 chunks of 250 000 points over
// a 200 m × 160 m campus, 0–15 m high, coloured) and handed to the view as the decoder worker
// hands it scans. Each frame is timed up to a pixel read back, so the time is that of the
// drawing, not of queueing it. The last row lets the page cap the moving frames by its measured
// drawing speed (100 ms a frame, issue 19) as it does for an operator. Prints one JSON line.
// Usage: tests/bench/page_bench.sh [MILLION_POINTS] [FRAMES]
import { startStack } from '../support/stack.mjs';
import { withBrowser } from '../support/browser.mjs';

const millions = Number(process.argv[2] || 10);
const frames = Number(process.argv[3] || 8);

const stack = await startStack({ bridge: false });
try {
  const result = await withBrowser(async (context) => {
    const page = await context.newPage();
    await page.goto(`${stack.url}/?token=${stack.token}`);
    await page.waitForFunction(() => document.body.dataset.state === 'live', null, { timeout: 30000 });
    const gpu = await page.evaluate(() => {
      const gl = window.scanplan.view.renderer.getContext();
      const ext = gl.getExtension('WEBGL_debug_renderer_info');
      return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    });
    const loaded = await page.evaluate(async (total) => {
      const { view } = window.scanplan;
      const per = 250_000;
      let seed = 1;
      const rand = () => ((seed = (seed * 1664525 + 1013904223) >>> 0) / 4294967296);
      const t0 = performance.now();
      for (let id = 1; id * per <= total; ++id) {
        const positions = new Float32Array(per * 3);
        const colors = new Uint8Array(per * 3);
        // Each scan covers a 60 m disc of the campus, as a scan does.
        const cx = 30 + rand() * 140, cy = 30 + rand() * 100;
        for (let i = 0; i < per; ++i) {
          const r = 60 * Math.sqrt(rand()), a = rand() * 2 * Math.PI;
          positions[3 * i] = cx + r * Math.cos(a);
          positions[3 * i + 1] = cy + r * Math.sin(a);
          positions[3 * i + 2] = rand() < 0.7 ? rand() * 0.3 : rand() * 15;
          colors[3 * i] = 60 + rand() * 150;
          colors[3 * i + 1] = 80 + rand() * 120;
          colors[3 * i + 2] = 60 + rand() * 100;
        }
        view.addChunk({ id, count: per, positions, colors, min: [cx - 60, cy - 60, 0], max: [cx + 60, cy + 60, 15] });
      }
      view.frame();
      return { held: view.pointCount, chunks: view.chunkCount, ms: performance.now() - t0 };
    }, millions * 1e6);

    const timeFrames = (config) => page.evaluate(async ({ budget, interacting, n, adaptive }) => {
      const { view } = window.scanplan;
      // The fixed rows draw what the budget says: the cap from the measured speed set aside.
      if (!adaptive) view.pointsPerMs = null;
      view.setBudget(budget);
      view._setInteracting(interacting);
      const gl = view.renderer.getContext();
      const pixel = new Uint8Array(4);
      // Reading a pixel back waits for the GPU process to finish the frame (gl.finish alone
      // returns at once in Chromium, whose GL runs in another process).
      const draw = () => {
        view.renderer.render(view.scene, view.camera);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      };
      draw(); // warm: shaders, uploads
      if (adaptive) {
        // The page's own loop measures the drawing speed while the camera moves, and caps the
        // frames to 100 ms of it: a dozen frames of orbiting, as a user dragging the view.
        for (let k = 0; k < 12; ++k) {
          const t0 = view.controls.target, p = view.camera.position;
          const dx = p.x - t0.x, dy = p.y - t0.y, c = Math.cos(0.02), s = Math.sin(0.02);
          p.set(t0.x + c * dx - s * dy, t0.y + s * dx + c * dy, p.z);
          view.camera.lookAt(t0);
          view.requestRender();
          await new Promise((r) => requestAnimationFrame(r));
        }
      }
      const times = [];
      for (let k = 0; k < n; ++k) {
        // Orbit a little each frame, as a user dragging the view.
        const t0 = view.controls.target, p = view.camera.position;
        const dx = p.x - t0.x, dy = p.y - t0.y, c = Math.cos(0.02), s = Math.sin(0.02);
        p.set(t0.x + c * dx - s * dy, t0.y + s * dx + c * dy, p.z);
        view.camera.lookAt(t0);
        const t = performance.now();
        draw();
        times.push(performance.now() - t);
      }
      const drawn = view.drawnCount;
      const pointsPerMs = view.pointsPerMs;
      view._setInteracting(false);
      times.sort((a, b) => a - b);
      const ms = times[Math.floor(times.length / 2)];
      return { drawn, ms_median: ms, ms_max: times[times.length - 1], fps: 1000 / ms, ...(adaptive ? { points_per_ms: Math.round(pointsPerMs) } : {}) };
    }, { ...config, n: frames });

    const all = await timeFrames({ budget: 64_000_000, interacting: false });
    const rest = await timeFrames({ budget: 4_000_000, interacting: false });
    const moving = await timeFrames({ budget: 4_000_000, interacting: true });
    const adaptive = await timeFrames({ budget: 4_000_000, interacting: true, adaptive: true });
    return { gpu, loaded, all, rest, moving, adaptive };
  });
  console.log(JSON.stringify({
    bench: 'page_10m_points',
    renderer: result.gpu,
    points_held: result.loaded.held,
    chunks: result.loaded.chunks,
    ms_load_into_view: result.loaded.ms,
    frames: frames,
    every_point: result.all,
    lod_at_rest: result.rest,
    lod_moving: result.moving,
    adaptive_moving: result.adaptive,
    speedup_moving_vs_every_point: result.all.ms_median / result.moving.ms_median,
  }));
} finally {
  await stack.stop();
}
