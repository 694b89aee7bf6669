// Builds the operator page into dist/: index.html, app.js + app.css (esbuild bundle),
// map_chunks_worker.js (the map decoder worker) and
// draco/ (three's Draco decoder, loaded by the worker at run time). No network, no CDN.
// Usage: node build.mjs [--dev]   (--dev: unminified with source maps)
import { build } from 'esbuild';
import { copyFile, mkdir, readFile, rm, writeFile } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, 'dist');
const dev = process.argv.includes('--dev');
const t0 = performance.now();

await rm(dist, { recursive: true, force: true });
await mkdir(join(dist, 'draco'), { recursive: true });

const common = {
  absWorkingDir: here,
  outdir: dist,
  bundle: true,
  platform: 'browser',
  target: ['es2022', 'chrome100', 'firefox100', 'safari16'],
  minify: !dev,
  sourcemap: dev ? 'linked' : false,
  legalComments: 'eof',
  charset: 'utf8',
  logLevel: 'warning',
  metafile: true,
};
// The page (an ES module) and the map decoder worker (a classic worker: it importScripts the
// Draco decoder from draco/ beside it, as DRACOLoader's worker does).
const [page, worker] = await Promise.all([
  build({ ...common, entryPoints: { app: 'src/main.js' }, format: 'esm' }),
  build({ ...common, entryPoints: { map_chunks_worker: 'src/map_chunks_worker.js' }, format: 'iife' }),
]);
const result = { metafile: { outputs: { ...page.metafile.outputs, ...worker.metafile.outputs } } };

// The decoder files DRACOLoader fetches from setDecoderPath('draco/') (not the gltf/ variant).
const dracoSrc = join(here, 'node_modules/three/examples/jsm/libs/draco');
for (const f of ['draco_decoder.wasm', 'draco_wasm_wrapper.js', 'draco_decoder.js']) {
  await copyFile(join(dracoSrc, f), join(dist, 'draco', f));
}

await writeFile(join(dist, 'index.html'), await readFile(join(here, 'index.html')));

const outputs = Object.entries(result.metafile.outputs)
  .map(([f, o]) => `${f.replace(/^.*dist\//, 'dist/')} ${(o.bytes / 1024).toFixed(0)} KiB`)
  .join(', ');
console.log(`built ${outputs} + dist/draco/ in ${Math.round(performance.now() - t0)} ms`);
