// The viewer's endpoints (src/scalespace/viewer/*Layer.hpp). Every request carries the token the
// page was opened with; binary answers are little-endian arrays read straight into typed arrays.
const token = new URLSearchParams(location.search).get('token') || '';

function url(path, params = {}) {
  const q = new URLSearchParams({ ...params, token });
  return `${path}?${q}`;
}

async function check(response) {
  if (!response.ok) throw new Error(`${response.status}: ${(await response.text()).trim()}`);
  return response;
}

export async function getJson(path, params) {
  return (await check(await fetch(url(path, params)))).json();
}

// Reads the body chunk by chunk so that `onProgress(bytesSoFar, total)` can drive a progress bar.
export async function getBytes(path, params, onProgress) {
  const response = await check(await fetch(url(path, params)));
  const total = Number(response.headers.get('Content-Length')) || 0;
  if (!response.body || !onProgress) return response.arrayBuffer();
  const reader = response.body.getReader();
  const out = new Uint8Array(total);
  const chunks = [];
  let received = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    if (received + value.length <= total) out.set(value, received);
    else chunks.push(value);
    received += value.length;
    onProgress(received, total);
  }
  if (received === total) return out.buffer;
  // No or wrong Content-Length: put the pieces together.
  const all = new Uint8Array(received);
  let at = 0;
  for (const c of [out.subarray(0, Math.min(total, received)), ...chunks]) { all.set(c, at); at += c.length; }
  return all.buffer;
}

export async function post(path, params, body) {
  const response = await check(await fetch(url(path, params), {
    method: 'POST', body, headers: { 'Content-Type': 'application/octet-stream' },
  }));
  return response.json();
}

// POST with a binary body, binary answer (labels of a selection too long for a URL).
export async function postBytes(path, params, body) {
  const response = await check(await fetch(url(path, params), {
    method: 'POST', body, headers: { 'Content-Type': 'application/octet-stream' },
  }));
  return response.arrayBuffer();
}
