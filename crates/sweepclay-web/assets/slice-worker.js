// The slice request, off the page's main thread (docs/MODELER.md, "Input
// that never lags"): fetches /api/slice in its binary form, wraps it in
// typed arrays and makes the surface's triangles and normals, then hands
// them over without copying. The page's input handlers never wait for it.

import { decode, normals, zip } from './mesh.js';

self.onmessage = async (e) => {
  const { id, design } = e.data;
  const t0 = performance.now();
  try {
    const r = await fetch('/api/slice?format=binary', { method: 'POST', headers: { 'content-type': 'application/json' }, body: design });
    const headers = performance.now() - t0;
    if (!r.ok) {
      self.postMessage({ id, ok: false, body: await r.json() });
      return;
    }
    const buf = await r.arrayBuffer();
    const request = performance.now() - t0;
    const data = decode(buf);
    const triangles = zip(data.surface.positions, data.surface.columns);
    data.surface.triangles = triangles;
    data.surface.normals = normals(data.surface.positions, triangles);
    const timing = { headers_ms: headers, request_ms: request, worker_ms: performance.now() - t0 };
    self.postMessage({ id, ok: true, body: data, timing }, [buf, triangles.buffer, data.surface.normals.buffer]);
  } catch (err) {
    self.postMessage({ id, ok: false, failed: String(err.message || err) });
  }
};
