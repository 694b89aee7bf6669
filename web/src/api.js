// Access token handling and the JSON/binary REST client of the operator page.
// Every API call carries `Authorization: Bearer <token>`; errors come back as ApiError
// with a message meant for the operator (shown in the status bar).

const TOKEN_KEY = 'scanplan.token';

function storage() {
  try {
    return window.sessionStorage;
  } catch {
    return null; // storage disabled (e.g. opaque origin): keep the token in memory only
  }
}

let memoryToken = '';

/**
 * Reads the token from `?token=T` or `#token=T`, remembers it in sessionStorage and removes it
 * from the address bar (so it does not end up in bookmarks or screenshots). Falls back to the
 * stored token when the URL has none.
 */
export function initToken(win = window) {
  const url = new URL(win.location.href);
  const hash = new URLSearchParams(url.hash.replace(/^#/, ''));
  const fromUrl = url.searchParams.get('token') || hash.get('token') || '';
  const store = storage();
  if (fromUrl) {
    memoryToken = fromUrl;
    try {
      store?.setItem(TOKEN_KEY, fromUrl);
    } catch {
      /* quota or disabled storage: memory copy is enough */
    }
    url.searchParams.delete('token');
    hash.delete('token');
    const h = hash.toString();
    url.hash = h ? `#${h}` : '';
    try {
      win.history.replaceState(win.history.state, '', url.toString());
    } catch {
      /* ignore: cosmetic only */
    }
  } else {
    memoryToken = store?.getItem(TOKEN_KEY) || '';
  }
  return memoryToken;
}

export function getToken() {
  return memoryToken;
}

export class ApiError extends Error {
  /**
   * @param {string} message text for the operator
   * @param {{status?: number, code?: string, auth?: boolean, network?: boolean}} info
   */
  constructor(message, info = {}) {
    super(message);
    this.name = 'ApiError';
    this.status = info.status ?? 0;
    this.code = info.code ?? '';
    this.auth = !!info.auth;
    this.network = !!info.network;
    this.detail = info.detail ?? ''; // the server's own message, for the operator

  }
}

async function errorFromResponse(res, path) {
  if (res.status === 401) {
    return new ApiError('token missing or wrong', { status: res.status, code: 'unauthorized', auth: true });
  }
  let code = '';
  let message = '';
  try {
    const text = await res.text();
    try {
      const body = JSON.parse(text);
      if (body && typeof body === 'object' && body.error) {
        code = String(body.error.code ?? '');
        message = String(body.error.message ?? '');
      }
    } catch {
      message = text.slice(0, 200);
    }
  } catch {
    /* body unreadable */
  }
  if (res.status === 403) {
    const detail = message || 'this action needs an operator token';
    return new ApiError(detail, { status: 403, code: code || 'forbidden', detail });
  }
  const detail = message || res.statusText || 'request failed';
  return new ApiError(`${path}: ${res.status} ${detail}${code ? ` (${code})` : ''}`, { status: res.status, code, detail: message });
}

/**
 * fetch() with the bearer token, a timeout and operator-readable errors.
 * @returns {Promise<Response>} a response with a 2xx status
 */
export async function apiFetch(path, { timeoutMs = 15000, method = 'GET', headers = {}, body } = {}) {
  const ctrl = new AbortController();
  const timer = setTimeout(() => ctrl.abort(), timeoutMs);
  const h = new Headers(headers);
  if (memoryToken) h.set('Authorization', `Bearer ${memoryToken}`);
  let res;
  try {
    res = await fetch(path, { method, headers: h, body, signal: ctrl.signal, cache: 'no-store' });
  } catch {
    clearTimeout(timer);
    const why = ctrl.signal.aborted ? `timed out after ${Math.round(timeoutMs / 1000)} s` : 'server unreachable';
    throw new ApiError(`${path}: ${why}`, { network: true });
  }
  if (!res.ok) {
    clearTimeout(timer);
    throw await errorFromResponse(res, path);
  }
  // Keep the timeout armed while the caller reads the body; clear it once it is read.
  res.done = () => clearTimeout(timer);
  return res;
}

export async function getJson(path, opts) {
  const res = await apiFetch(path, opts);
  try {
    const text = await res.text();
    try {
      return JSON.parse(text);
    } catch {
      throw new ApiError(`${path}: answer is not JSON`, { status: res.status });
    }
  } finally {
    res.done();
  }
}

/** @returns {Promise<ArrayBuffer|null>} null for an empty body (204, no scans yet) */
export async function getBinary(path, opts) {
  const res = await apiFetch(path, opts);
  try {
    if (res.status === 204) return null;
    const buf = await res.arrayBuffer();
    return buf.byteLength ? buf : null;
  } catch (e) {
    if (e instanceof ApiError) throw e;
    throw new ApiError(`${path}: download interrupted`, { network: true });
  } finally {
    res.done();
  }
}

/**
 * Like getBinary, with the response headers.
 * @returns {Promise<{body: ArrayBuffer|null, headers: Headers, status: number}>}
 */
export async function getBinaryWithHeaders(path, opts) {
  const res = await apiFetch(path, opts);
  try {
    if (res.status === 204) return { body: null, headers: res.headers, status: 204 };
    const buf = await res.arrayBuffer();
    return { body: buf.byteLength ? buf : null, headers: res.headers, status: res.status };
  } catch (e) {
    if (e instanceof ApiError) throw e;
    throw new ApiError(`${path}: download interrupted`, { network: true });
  } finally {
    res.done();
  }
}

/**
 * Sends JSON with `method` (POST by default) and returns the JSON answer (null for an empty one).
 * Errors carry the server's message, e.g. why a goal was refused.
 */
export async function sendJson(path, body, { method = 'POST', timeoutMs = 15000 } = {}) {
  const res = await apiFetch(path, {
    method,
    timeoutMs,
    headers: { 'Content-Type': 'application/json' },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  try {
    const text = await res.text();
    if (!text) return null;
    try {
      return JSON.parse(text);
    } catch {
      throw new ApiError(`${path}: answer is not JSON`, { status: res.status });
    }
  } finally {
    res.done();
  }
}
