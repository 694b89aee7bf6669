// Web Worker: decodes the map's Draco chunks off the main thread (a classic worker, built to
// dist/map_chunks_worker.js; the decoder comes from draco/ beside it, as DRACOLoader's does).
//
// In:  {type: 'decode', key, buffer: ArrayBuffer}            (buffer transferred)
// Out: {type: 'decoded', key, count, positions: Float32Array, colors: Uint8Array | null,
//       min: [x, y, z], max: [x, y, z]}                        (arrays transferred)
//      {type: 'error', key, message}
//
// The points are put in a random order (seeded by the key, so the same chunk always comes out
// the same): every prefix of the arrays is then an even sample of the whole chunk, and the view's
// level of detail is a draw range, with nothing re-uploaded to the GPU.
/* global DracoDecoderModule */

const base = new URL('./draco/', self.location.href).href;
let modulePromise = null;

function loadDecoder() {
  if (modulePromise) return modulePromise;
  modulePromise = (async () => {
    if (typeof WebAssembly === 'object') {
      importScripts(`${base}draco_wasm_wrapper.js`);
      const res = await fetch(`${base}draco_decoder.wasm`);
      if (!res.ok) throw new Error(`draco_decoder.wasm: HTTP ${res.status}`);
      const wasmBinary = await res.arrayBuffer();
      return new Promise((resolve) => {
        // The module is promise-like: wrap it so resolve() does not try to adopt it.
        DracoDecoderModule({ wasmBinary, onModuleLoaded: (draco) => resolve({ draco }) });
      });
    }
    importScripts(`${base}draco_decoder.js`);
    return new Promise((resolve) => {
      DracoDecoderModule({ onModuleLoaded: (draco) => resolve({ draco }) });
    });
  })();
  // A failed download is not permanent: the next chunk tries again.
  modulePromise.catch(() => {
    modulePromise = null;
  });
  return modulePromise;
}

function readAttribute(draco, decoder, pc, attribute, TypedArray, dracoType, count) {
  const comps = attribute.num_components();
  const bytes = count * comps * TypedArray.BYTES_PER_ELEMENT;
  const ptr = draco._malloc(bytes);
  try {
    if (!decoder.GetAttributeDataArrayForAllPoints(pc, attribute, dracoType, bytes, ptr)) {
      throw new Error('attribute data could not be read');
    }
    return { comps, data: new TypedArray(draco.HEAPF32.buffer, ptr, count * comps).slice() };
  } finally {
    draco._free(ptr);
  }
}

function hashKey(key) {
  let h = 2166136261;
  const s = String(key);
  for (let i = 0; i < s.length; i++) {
    h ^= s.charCodeAt(i);
    h = Math.imul(h, 16777619);
  }
  return h >>> 0 || 1;
}

function decode(draco, buffer, key) {
  const array = new Int8Array(buffer);
  const decoder = new draco.Decoder();
  let pc = null;
  try {
    if (decoder.GetEncodedGeometryType(array) !== draco.POINT_CLOUD) throw new Error('not a Draco point cloud');
    pc = new draco.PointCloud();
    const status = decoder.DecodeArrayToPointCloud(array, array.byteLength, pc);
    if (!status.ok() || pc.ptr === 0) throw new Error(`decoding failed: ${status.error_msg()}`);
    const count = pc.num_points();
    const posId = decoder.GetAttributeId(pc, draco.POSITION);
    if (posId < 0 || count === 0) throw new Error('no POSITION attribute');
    const pos = readAttribute(draco, decoder, pc, decoder.GetAttribute(pc, posId), Float32Array, draco.DT_FLOAT32, count);
    if (pos.comps !== 3) throw new Error(`POSITION has ${pos.comps} components, expected 3`);
    let col = null;
    const colId = decoder.GetAttributeId(pc, draco.COLOR);
    if (colId >= 0) {
      const c = readAttribute(draco, decoder, pc, decoder.GetAttribute(pc, colId), Uint8Array, draco.DT_UINT8, count);
      if (c.comps >= 3) col = c;
    }
    return shuffle(pos.data, col, count, hashKey(key));
  } finally {
    if (pc) draco.destroy(pc);
    draco.destroy(decoder);
  }
}

// Fisher-Yates with xorshift32; RGB(A) colours become tight RGB. Also finds the bounds.
function shuffle(src, col, count, seed) {
  const positions = new Float32Array(count * 3);
  const colors = col ? new Uint8Array(count * 3) : null;
  const order = new Uint32Array(count);
  for (let i = 0; i < count; i++) order[i] = i;
  let s = seed;
  for (let i = count - 1; i > 0; i--) {
    s ^= s << 13;
    s ^= s >>> 17;
    s ^= s << 5;
    const j = (s >>> 0) % (i + 1);
    const t = order[i];
    order[i] = order[j];
    order[j] = t;
  }
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  const cc = col ? col.comps : 0;
  let n = 0;
  for (let i = 0; i < count; i++) {
    const k = order[i];
    const x = src[3 * k], y = src[3 * k + 1], z = src[3 * k + 2];
    if (!Number.isFinite(x) || !Number.isFinite(y) || !Number.isFinite(z)) continue;
    positions[3 * n] = x;
    positions[3 * n + 1] = y;
    positions[3 * n + 2] = z;
    if (x < min[0]) min[0] = x;
    if (y < min[1]) min[1] = y;
    if (z < min[2]) min[2] = z;
    if (x > max[0]) max[0] = x;
    if (y > max[1]) max[1] = y;
    if (z > max[2]) max[2] = z;
    if (colors) {
      colors[3 * n] = col.data[cc * k];
      colors[3 * n + 1] = col.data[cc * k + 1];
      colors[3 * n + 2] = col.data[cc * k + 2];
    }
    n++;
  }
  return {
    count: n,
    positions: n === count ? positions : positions.slice(0, 3 * n),
    colors: colors && n !== count ? colors.slice(0, 3 * n) : colors,
    min,
    max,
  };
}

self.onmessage = async (e) => {
  const { type, key, buffer } = e.data || {};
  if (type !== 'decode') return;
  try {
    const { draco } = await loadDecoder();
    const r = decode(draco, buffer, key);
    const transfer = [r.positions.buffer];
    if (r.colors) transfer.push(r.colors.buffer);
    self.postMessage({ type: 'decoded', key, ...r }, transfer);
  } catch (err) {
    self.postMessage({ type: 'error', key, message: String(err && err.message ? err.message : err) });
  }
};
