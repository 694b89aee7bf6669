// The walking skeleton end to end: a simulated scanner on DDS, the server, one scan, the map
// fetched over HTTP and decoded with Draco's own decoder (the one the browser uses).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { startStack, scanAndWait, worldVariant, requireEnv, scratchDir } from '../support/stack.mjs';

const webRequire = createRequire(join(requireEnv('SCANPLAN_SOURCE_DIR'), 'web', 'package.json'));
const draco3d = webRequire('draco3d');

async function decodeDraco(bytes) {
  const m = await draco3d.createDecoderModule({});
  const decoder = new m.Decoder();
  const buffer = new m.DecoderBuffer();
  buffer.Init(new Int8Array(bytes), bytes.byteLength);
  assert.equal(decoder.GetEncodedGeometryType(buffer), m.POINT_CLOUD);
  const pc = new m.PointCloud();
  const status = decoder.DecodeBufferToPointCloud(buffer, pc);
  assert.ok(status.ok(), status.error_msg());
  const n = pc.num_points();
  const read = (type, make) => {
    const attr = decoder.GetAttribute(pc, decoder.GetAttributeId(pc, type));
    const arr = make();
    decoder.GetAttributeFloatForAllPoints(pc, attr, arr);
    return { attr, arr };
  };
  const pos = read(m.POSITION, () => new m.DracoFloat32Array());
  const positions = new Float32Array(n * 3);
  for (let i = 0; i < n * 3; i++) positions[i] = pos.arr.GetValue(i);
  const colorAttr = decoder.GetAttribute(pc, decoder.GetAttributeId(pc, m.COLOR));
  const colorNormalized = colorAttr.normalized();
  const colorType = colorAttr.data_type();
  m.destroy(pos.arr); m.destroy(pc); m.destroy(buffer); m.destroy(decoder);
  return { n, positions, colorNormalized, colorType, uint8: m.DT_UINT8 };
}

let stack;
before(async () => {
  const dir = scratchDir('scanplan-world-');
  // Exact reported poses, so the map's bounds are the yard's walls to within the range noise.
  const { file } = worldVariant(dir, 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
});
after(async () => {
  if (stack) {
    const exits = await stack.stop();
    for (const e of exits) assert.equal(e.code, 0, 'processes stop cleanly on SIGTERM');
  }
});

test('API answers with JSON errors and enforces tokens', async () => {
  const health = await stack.api('GET', '/api/v1/health', { auth: null });
  assert.equal(health.status, 200);
  const noToken = await stack.api('GET', '/api/v1/session', { auth: null });
  assert.equal(noToken.status, 401);
  assert.equal((await noToken.json()).error.code, 'unauthorized');
  const viewerScan = await stack.api('POST', '/api/v1/scan', { auth: stack.viewerToken });
  assert.equal(viewerScan.status, 403);
  assert.equal((await stack.api('GET', '/api/v1/session', { auth: stack.viewerToken })).status, 200);
  const missing = await stack.api('GET', '/api/v1/nothing-here');
  assert.equal(missing.status, 404);
  assert.ok((await missing.json()).error.message);
  const wrongMethod = await stack.api('DELETE', '/api/v1/session');
  assert.equal(wrongMethod.status, 405);
  assert.equal((await stack.api('GET', '/api/v1/map.drc')).status, 204, 'empty map before a scan');
});

test('a scan command brings a whole scan into the Draco map', async () => {
  const session = await scanAndWait(stack, 1);
  assert.equal(session.robots.robot1.scan.state, 'done');
  assert.equal(session.robots.robot1.scan.fraction, 1);
  // 720 stage angles × 361 beams; about half look at the sky of the open yard.
  assert.ok(session.points > 100000 && session.points < 259920, `points: ${session.points}`);
  assert.equal(session.last_scan.points, session.points);

  const res = await stack.api('GET', '/api/v1/map.drc');
  assert.equal(res.status, 200);
  assert.equal(res.headers.get('content-type'), 'application/octet-stream');
  const bytes = await res.arrayBuffer();
  // Raw float xyz + rgb8 is 15 bytes a point; Draco must do much better.
  assert.ok(bytes.byteLength < session.points * 6, `map.drc is ${bytes.byteLength} bytes`);
  const map = await decodeDraco(bytes);
  assert.equal(map.n, session.points);
  assert.ok(map.colorNormalized, 'colours are marked normalized for three.js');
  assert.equal(map.colorType, map.uint8);

  const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < map.n; i++) {
    for (let a = 0; a < 3; a++) {
      const v = map.positions[3 * i + a];
      if (v < min[a]) min[a] = v;
      if (v > max[a]) max[a] = v;
    }
  }
  // The yard's walls stand inside ±30 m × ±20 m; the building's roof edge is 12.5 m high.
  // 14-bit quantisation over ~60 m is 4 mm, the range noise 1 cm (σ): 0.1 m covers both.
  const expectMin = [-30, -20, 0], expectMax = [30, 20, 12.5];
  for (let a = 0; a < 3; a++) {
    assert.ok(Math.abs(min[a] - expectMin[a]) < 0.1, `min[${a}] = ${min[a]}`);
    assert.ok(Math.abs(max[a] - expectMax[a]) < 0.1, `max[${a}] = ${max[a]}`);
  }
});

test('top-view layers come from the MLS map', async () => {
  for (const name of ['regions', 'elevation', 'movable']) {
    const res = await stack.api('GET', `/api/v1/layers/${name}.png`);
    assert.equal(res.status, 200, name);
    assert.equal(res.headers.get('content-type'), 'image/png');
    const bytes = new Uint8Array(await res.arrayBuffer());
    assert.deepEqual([...bytes.subarray(1, 4)].map((c) => String.fromCharCode(c)).join(''), 'PNG');
    // The default target region is 200 m square at 4 px a cell.
    const width = new DataView(bytes.buffer).getUint32(16);
    assert.ok(width >= 800 && width <= 808, `${name}.png is ${width} px wide`);
    // The elevation colours' scale in metres: the yard's ground (0) up to the roof edge (12.5 m).
    const range = res.headers.get('x-scanplan-layer-range');
    if (name !== 'elevation') assert.equal(range, null, name);
    else {
      const [lo, hi] = range.split(',').map(Number);
      assert.ok(Math.abs(lo) < 0.3 && hi > 10 && hi < 13, `elevation range ${range}`);
    }
  }
  const unknown = await stack.api('GET', '/api/v1/layers/heat.png');
  assert.equal(unknown.status, 404);
  assert.match((await unknown.json()).error.message, /regions, elevation and movable/);
  const { areas } = await (await stack.api('GET', '/api/v1/session')).json();
  // From one scan in the 60 m × 40 m yard: up to 20 m around the scanner is scan-completed.
  assert.ok(areas.completed_m2 > 600 && areas.completed_m2 <= Math.PI * 400, JSON.stringify(areas));
  assert.ok(areas.movable_m2 > 800, JSON.stringify(areas));
});
