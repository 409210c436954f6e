// The slice fetched and its answer read into typed arrays, with the
// triangles and smooth normals of its surface: done in the slice worker
// (slice-worker.js) off the main thread, and on the page only where
// workers are not available.

/**
 * Triangles between adjacent transition curves, always advancing along the
 * curve whose next sample is lower (as mesh::surface_triangles in Rust).
 * `cols` is [first, count, first, count, …]; round a vessel's loop
 * (`closed`) the last curve is joined to the first, or the seam shows
 * as a slit.
 */
export function zip(P, cols, closed = false) {
  const m = cols.length / 2;
  const pairs = [];
  for (let c = 0; c + 1 < m; c++) pairs.push([c, c + 1]);
  if (closed && m > 2) pairs.push([m - 1, 0]);
  let total = 0;
  for (const [a, b] of pairs) total += cols[2 * a + 1] + cols[2 * b + 1] - 2;
  const T = new Uint32Array(3 * total);
  let t = 0;
  for (const [a, b] of pairs) {
    let i = cols[2 * a];
    let j = cols[2 * b];
    const ae = i + cols[2 * a + 1];
    const be = j + cols[2 * b + 1];
    while (i + 1 < ae || j + 1 < be) {
      const advanceA = i + 1 >= ae ? false : j + 1 >= be ? true : P[3 * i + 5] <= P[3 * j + 5];
      T[t++] = i;
      T[t++] = j;
      if (advanceA) T[t++] = ++i;
      else T[t++] = ++j;
    }
  }
  return T;
}

/** Smooth vertex normals: each vertex the sum of its triangles' normals. */
export function normals(P, T) {
  const N = new Float32Array(P.length);
  for (let t = 0; t < T.length; t += 3) {
    const [a, b, c] = [T[t] * 3, T[t + 1] * 3, T[t + 2] * 3];
    const u0 = P[b] - P[a], u1 = P[b + 1] - P[a + 1], u2 = P[b + 2] - P[a + 2];
    const v0 = P[c] - P[a], v1 = P[c + 1] - P[a + 1], v2 = P[c + 2] - P[a + 2];
    const x = u1 * v2 - u2 * v1;
    const y = u2 * v0 - u0 * v2;
    const z = u0 * v1 - u1 * v0;
    for (const i of [a, b, c]) {
      N[i] += x;
      N[i + 1] += y;
      N[i + 2] += z;
    }
  }
  return N;
}

/** Reads the binary slice answer (SliceView::to_binary): typed arrays, no parsing. */
export function decode(buf) {
  const dv = new DataView(buf);
  const magic = String.fromCharCode(...new Uint8Array(buf, 0, 4));
  if (magic !== 'SWCL') throw new Error('unexpected answer from /api/slice');
  const jsonLen = dv.getUint32(4, true);
  const head = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 8, jsonLen)));
  let o = 8 + jsonLen;
  const next = (Type) => {
    const n = dv.getUint32(o, true);
    const a = new Type(buf, o + 4, n);
    o += 4 + 4 * n;
    return a;
  };
  const positions = next(Float32Array);
  const columns = next(Uint32Array);
  const moved = next(Uint32Array);
  const order = next(Uint32Array);
  const width = next(Float32Array);
  const pass = next(Uint32Array);
  const top = next(Uint32Array);
  const beads = {
    overlap: next(Float32Array),
    overhang_deg: next(Float32Array),
    layer_height: next(Float32Array),
    clearance: next(Float32Array),
  };
  const kept = next(Float32Array);
  const path = { order, width, pass, top, beads, texture_kept: kept.length ? kept : null };
  return { ...head, surface: { positions, columns, moved, curves: head.curves }, path };
}

/**
 * Slices a design (JSON text) on the server and reads the answer:
 * `{ ok, body, timing, transfer }` (`transfer`: the buffers a worker may
 * hand over without copying), `{ ok: false, body }` for a refusal, or
 * `{ ok: false, failed }` when the server did not answer. Run in the slice
 * worker, and on the page only where workers are not available.
 */
export async function fetchSlice(design) {
  const t0 = performance.now();
  try {
    const r = await fetch('/api/slice?format=binary', { method: 'POST', headers: { 'content-type': 'application/json' }, body: design });
    const headers = performance.now() - t0;
    if (!r.ok) return { ok: false, body: await r.json() };
    const buf = await r.arrayBuffer();
    const request = performance.now() - t0;
    const body = decode(buf);
    const triangles = zip(body.surface.positions, body.surface.columns, !!body.stats?.vessel);
    body.surface.triangles = triangles;
    body.surface.normals = normals(body.surface.positions, triangles);
    const timing = { headers_ms: headers, request_ms: request, worker_ms: performance.now() - t0 };
    return { ok: true, body, timing, transfer: [buf, triangles.buffer, body.surface.normals.buffer] };
  } catch (e) {
    return { ok: false, failed: String(e.message || e) };
  }
}
