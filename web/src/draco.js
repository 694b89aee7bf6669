// Draco point-cloud decoding with three's DRACOLoader (decoder files served from ./draco/).
import { LinearSRGBColorSpace } from 'three';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { colorsToLinear } from './view.js';

const DECODER_PATH = 'draco/';

let loader = null;

function getLoader() {
  if (!loader) {
    loader = new DRACOLoader();
    loader.setDecoderPath(DECODER_PATH);
    loader.setWorkerLimit(1);
    loader.preload();
  }
  return loader;
}

/** Starts fetching the decoder early so the first map appears sooner. */
export function preloadDecoder() {
  try {
    getLoader();
  } catch {
    /* reported when a decode is attempted */
  }
}

/**
 * Decodes a Draco point cloud (POSITION float, COLOR uint8 normalized) into a BufferGeometry
 * with linear-space float colours. The buffer is transferred to the decoder worker.
 * @param {ArrayBuffer} buffer
 * @returns {Promise<import('three').BufferGeometry>}
 */
export function decodePointCloud(buffer) {
  const l = getLoader();
  return new Promise((resolve, reject) => {
    const fail = (err) => {
      // The decoder worker rejects with its message object {type: 'error', error: text}:
      // the data was bad, the decoder is fine. Anything else may be a failed decoder download,
      // which leaves DRACOLoader's init promise rejected for good: start over with a fresh loader.
      const fromWorker = err && typeof err === 'object' && err.type === 'error' && 'error' in err;
      if (fromWorker) err = new Error(String(err.error));
      else if (loader === l) {
        loader = null;
        try {
          l.dispose();
        } catch {
          /* ignore */
        }
      }
      const msg = err && err.message ? err.message : String(err);
      reject(new Error(`map decoding failed: ${msg.replace(/^THREE\.DRACOLoader: /, '')}`));
    };
    let p;
    try {
      // Colours are decoded without three's per-vertex sRGB conversion; colorsToLinear does it with a LUT.
      p = l.decodeDracoFile(buffer, (geometry) => {
        try {
          const pos = geometry.getAttribute('position');
          if (!pos || pos.count === 0) throw new Error('no POSITION attribute');
          const col = geometry.getAttribute('color');
          if (col) {
            const usable = !col.isInterleavedBufferAttribute && col.array instanceof Float32Array && col.itemSize === 3;
            if (usable) colorsToLinear(col.array);
            else geometry.deleteAttribute('color'); // not RGB: draw the points in one colour
          }
          resolve(geometry);
        } catch (e) {
          geometry.dispose();
          fail(e);
        }
      }, null, null, LinearSRGBColorSpace, fail);
    } catch (e) {
      fail(e);
      return;
    }
    if (p && typeof p.catch === 'function') p.catch(fail);
  });
}
