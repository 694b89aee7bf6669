// Exports for other teams (issue 18, DESIGN.md "REST"): the registered map as binary PLY and as
// LAS 1.4, the poses as CSV and the annotations as GeoJSON, read back here by readers written
// from the formats' specifications (not the server's code).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { requireEnv, runCli, scanAndWait, startStack, worldVariant, scratchDir } from '../support/stack.mjs';

let stack;
before(async () => {
  const { file } = worldVariant(scratchDir('scanplan-exports-'), 'yard.json', {
    pose_noise: { model: 'absolute', xy_sigma_m: 0, z_sigma_m: 0, yaw_sigma_deg: 0 },
  });
  stack = await startStack({ world: file });
});
after(async () => stack && (await stack.stop()));

const get = (path, auth) => stack.api('GET', `/api/v1/export/${path}`, { auth });

// A binary little-endian PLY's vertices: the header's properties in order, then fixed records.
function readPly(buf) {
  const end = buf.indexOf('end_header\n');
  assert.ok(end > 0, 'a PLY header');
  const lines = buf.subarray(0, end).toString('latin1').split('\n');
  assert.equal(lines[0], 'ply');
  assert.equal(lines[1], 'format binary_little_endian 1.0');
  const sizes = { float: 4, uchar: 1, uint: 4 };
  const props = [];
  let count = 0;
  for (const l of lines) {
    const f = l.split(' ');
    if (f[0] === 'element') count = Number(f[2]);
    if (f[0] === 'property') props.push({ type: f[1], name: f[2] });
  }
  const stride = props.reduce((s, p) => s + sizes[p.type], 0);
  const body = buf.subarray(end + 'end_header\n'.length);
  assert.equal(body.length, count * stride, 'the body holds exactly the declared vertices');
  const vertex = (i) => {
    const v = {};
    let o = i * stride;
    for (const p of props) {
      v[p.name] = p.type === 'float' ? body.readFloatLE(o) : p.type === 'uchar' ? body.readUInt8(o) : body.readUInt32LE(o);
      o += sizes[p.type];
    }
    return v;
  };
  return { count, props: props.map((p) => `${p.type} ${p.name}`), vertex };
}

// LAS 1.4 (ASPRS R15): the public header block's fields at their offsets, and format 7 records.
function readLas(buf) {
  const h = {
    signature: buf.toString('latin1', 0, 4),
    version: [buf.readUInt8(24), buf.readUInt8(25)],
    headerSize: buf.readUInt16LE(94),
    pointOffset: buf.readUInt32LE(96),
    vlrs: buf.readUInt32LE(100),
    format: buf.readUInt8(104),
    recordLength: buf.readUInt16LE(105),
    legacyCount: buf.readUInt32LE(107),
    scale: [131, 139, 147].map((o) => buf.readDoubleLE(o)),
    offset: [155, 163, 171].map((o) => buf.readDoubleLE(o)),
    max: [179, 195, 211].map((o) => buf.readDoubleLE(o)),
    min: [187, 203, 219].map((o) => buf.readDoubleLE(o)),
    count: Number(buf.readBigUInt64LE(247)),
    firstReturns: Number(buf.readBigUInt64LE(255)),
  };
  const point = (i) => {
    const o = h.pointOffset + i * h.recordLength;
    const xyz = [0, 4, 8].map((k, a) => buf.readInt32LE(o + k) * h.scale[a] + h.offset[a]);
    return {
      xyz,
      returns: buf.readUInt8(o + 14),
      source: buf.readUInt16LE(o + 20),
      rgb: [30, 32, 34].map((k) => buf.readUInt16LE(o + k)),
    };
  };
  return { h, point, bytes: buf.length };
}

test('no map to export before the first scan; unknown exports are named', async () => {
  const r = await get('map.ply');
  assert.equal(r.status, 409);
  assert.equal((await r.json()).error.code, 'no_map');
  const u = await get('map.xyz');
  assert.equal(u.status, 404);
  assert.match((await u.json()).error.message, /map\.ply, map\.las, poses\.csv and annotations\.geojson/);
  assert.equal((await get('poses.csv', null)).status, 401);
});

test('the map, the poses and the annotations read back as their formats say', async () => {
  await scanAndWait(stack, 1);
  const note = await stack.api('POST', '/api/v1/annotations',
    { body: JSON.stringify({ kind: 'victim', x: -12.5, y: 3.25, z: 0.4, text: 'two adults, "responsive"', by: 'Ann' }) });
  assert.equal(note.status, 201);

  // Every export is readable with a viewer's token: other teams get read-only links.
  const plyRes = await get('map.ply', stack.viewerToken);
  assert.equal(plyRes.status, 200);
  assert.match(plyRes.headers.get('content-disposition'), /scanplan-map\.ply/);
  const ply = readPly(Buffer.from(await plyRes.arrayBuffer()));
  assert.deepEqual(ply.props, ['float x', 'float y', 'float z', 'uchar red', 'uchar green', 'uchar blue', 'uint scan_id']);
  const session = await (await stack.api('GET', '/api/v1/session')).json();
  assert.ok(ply.count > 10000, `${ply.count} points`);
  assert.equal(ply.count, session.points, 'every point the map holds, once');

  const las = readLas(Buffer.from(await (await get('map.las')).arrayBuffer()));
  assert.equal(las.h.signature, 'LASF');
  assert.deepEqual(las.h.version, [1, 4]);
  assert.equal(las.h.headerSize, 375);
  assert.equal(las.h.pointOffset, 375);
  assert.equal(las.h.vlrs, 0);
  assert.equal(las.h.format, 7);
  assert.equal(las.h.recordLength, 36);
  assert.equal(las.h.legacyCount, 0, 'format 7 keeps the legacy count at zero');
  assert.equal(las.h.count, ply.count);
  assert.equal(las.h.firstReturns, ply.count);
  assert.equal(las.bytes, 375 + 36 * ply.count);
  assert.deepEqual(las.h.scale, [0.001, 0.001, 0.001]);
  // Point by point against the PLY: the same place to a millimetre, colour × 257, the scan id.
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < ply.count; i += 97) {
    const v = ply.vertex(i), p = las.point(i);
    [v.x, v.y, v.z].forEach((c, a) => {
      assert.ok(Math.abs(p.xyz[a] - c) <= 0.0006, `point ${i} axis ${a}: ${p.xyz[a]} against ${c}`);
      lo[a] = Math.min(lo[a], c);
      hi[a] = Math.max(hi[a], c);
    });
    assert.deepEqual(p.rgb, [v.red * 257, v.green * 257, v.blue * 257]);
    assert.equal(p.source, 1);
    assert.equal(v.scan_id, 1);
    assert.equal(p.returns, 0x11);
  }
  for (let a = 0; a < 3; a++) {
    assert.ok(las.h.min[a] <= lo[a] + 1e-3 && las.h.max[a] >= hi[a] - 1e-3, `bounds on axis ${a}`);
  }
  // The yard is (−30..30) × (−20..20), and with exact poses the map frame is the world's.
  assert.ok(las.h.min[0] >= -30.5 && las.h.max[0] <= 30.5, JSON.stringify(las.h));
  assert.ok(las.h.min[1] >= -20.5 && las.h.max[1] <= 20.5, JSON.stringify(las.h));

  const csv = (await (await get('poses.csv')).text()).trim().split('\n');
  assert.equal(csv[0], 'scan,robot,x,y,z,roll_deg,pitch_deg,yaw_deg,received_at');
  assert.equal(csv.length, 2);
  const row = csv[1].split(',');
  assert.equal(row[0], '1');
  assert.equal(row[1], 'robot1');
  assert.ok(row.slice(2, 8).every((v) => Number.isFinite(Number(v))), csv[1]);
  assert.match(row[8], /^\d{4}-\d\d-\d\dT/);

  const geo = await (await get('annotations.geojson')).json();
  assert.equal(geo.type, 'FeatureCollection');
  assert.match(geo.scanplan_frame, /not longitude and latitude/);
  assert.equal(geo.features.length, 1);
  const f = geo.features[0];
  assert.deepEqual(f.geometry, { type: 'Point', coordinates: [-12.5, 3.25, 0.4] });
  assert.equal(f.properties.kind, 'victim');
  assert.equal(f.properties.text, 'two adults, "responsive"');
  assert.equal(f.properties.by, 'operator Ann');
});

test('the terminal operator saves an export to a file', async () => {
  const out = join(scratchDir('scanplan-export-cli-'), 'poses.csv');
  const run = (args) => runCli(stack, args, stack.viewerToken);
  const r = await run(['export', 'poses.csv', '--out', out]);
  assert.equal(r.code, 0, r.stderr);
  assert.match(r.stderr, /wrote .*poses\.csv \(\d+ bytes\)/);
  assert.equal(readFileSync(out, 'utf8'), await (await get('poses.csv')).text());
  const bad = await run(['export', 'map.xyz']);
  assert.notEqual(bad.code, 0);
});

test('the mission report is one printable page with the map, the marks, the scans and the decisions', async () => {
  const set = await stack.api('PUT', '/api/v1/params', { body: JSON.stringify({ no_go: [[[20, 10], [25, 10], [25, 15]]], by: 'Ann' }) });
  assert.equal(set.status, 200);
  const r = await stack.api('GET', '/api/v1/report.html', { auth: stack.viewerToken });
  assert.equal(r.status, 200);
  assert.match(r.headers.get('content-type'), /^text\/html/);
  const html = await r.text();
  assert.match(html, /^<!DOCTYPE html>/);
  // Self-contained: the map is inline, nothing is fetched from anywhere.
  assert.match(html, /<img alt="top view of the map" src="data:image\/png;base64,[A-Za-z0-9+/]{1000,}={0,2}">/);
  assert.doesNotMatch(html, /(src|href)="(https?:)?\/\//);
  assert.doesNotMatch(html, /<script/);
  // The mark, numbered on the map and in the table, with its coordinates, text, author and time.
  assert.match(html, /<span class="mark" style="left:[\d.]+%;top:[\d.]+%;background:#d62728" title="victim">1<\/span>/);
  assert.match(html, /<td>1<\/td><td class="kind-victim">victim<\/td><td>-12\.50, 3\.25, 0\.40<\/td><td>two adults, &quot;responsive&quot;<\/td><td>operator Ann<\/td><td>\d{4}-/);
  // The scan with its pose and what matching did; the coverage; the decisions.
  assert.match(html, /<tr><td>1<\/td><td>robot1<\/td><td>\d{4}-[^<]+<\/td><td>-15\.00, -8\.00, [-\d.]+, 0\.0<\/td><td>\d+<\/td><td>the reference \(first scan\)<\/td><\/tr>/);
  assert.match(html, /<h2>Coverage<\/h2><p>Now: [\d.]+ % of the target region scan-completed/);
  assert.match(html, /<svg class="chart"[^>]*>[\s\S]*<title>scan 1: [\d.]+ % completed<\/title>/);
  assert.match(html, /params · by operator Ann/);
  assert.match(html, /1 no-go zones · 1 marks/);
});

test('the terminal operator proposes a point, marks the map and takes a scan out and back', async () => {
  const run = (args, token) => runCli(stack, args, token);
  const mark = await run(['annotate', 'hazard', '5', '-10', '--text', 'leaning wall', '--by', 'Bo']);
  assert.equal(mark.code, 0, mark.stderr);
  assert.match(mark.stdout, /^hazard #\d+ at \(5\.0, -10\.0\), z 0\.0 m by operator Bo: leaning wall$/m);
  const bad = await run(['annotate', 'note', '1', '1']);
  assert.equal(bad.code, 9, 'a note needs its text: the server says so');
  assert.match(bad.stderr, /text/);

  const goal = await run(['propose', '-4.2', '-4.7', '--by', 'Bo']);
  assert.equal(goal.code, 0, goal.stderr);
  assert.match(goal.stdout, /proposed for robot1; send it there with: scanplan approve \d+/);
  const inside = await run(['propose', '14', '6']);
  assert.equal(inside.code, 9);
  assert.match(inside.stderr, /not been scanned/);

  const only = await run(['exclude-scan', '1']);
  assert.equal(only.code, 6, 'the only scan stays: the server refuses (409)');
  assert.match(only.stderr, /scan 1 is the only one in the map/);
  const scan = await run(['scan', '--robot', 'robot1']);
  assert.equal(scan.code, 0, scan.stderr);
  assert.match(scan.stdout, /^scan requested from robot1 \(command \d+\); follow it with scanplan watch$/m);
  const offline = await run(['scan', '--world', join(requireEnv('SCANPLAN_SOURCE_DIR'), 'samples/worlds/yard.json')]);
  assert.notEqual(offline.code, 0, 'a simulated scan still needs --at and --out');
  assert.match(offline.stderr, /--at/);

  await stack.waitFor('scan 2 in the session', async () =>
    ((await (await stack.api('GET', '/api/v1/session')).json()).scans >= 2) || undefined);
  await stack.waitFor('scan 2 in the map', async () => {
    const s = await (await stack.api('GET', '/api/v1/scans/2')).json();
    return s.in_map !== false && s.id === 2 ? s : undefined;
  });
  const out = await run(['exclude-scan', '2', '--reason', 'drifted', '--by', 'Bo']);
  assert.equal(out.code, 0, out.stderr);
  assert.match(out.stdout, /scan 2 is out of the map/);
  const back = await run(['exclude-scan', '2', '--restore']);
  assert.equal(back.code, 0, back.stderr);
  assert.match(back.stdout, /scan 2 is back in the map/);
  assert.equal((await run(['exclude-scan', '2'], stack.viewerToken)).code, 4);
});
