// The slice request, off the page's main thread (docs/MODELER.md, "Input
// that never lags"): fetches /api/slice in its binary form, wraps it in
// typed arrays and makes the surface's triangles and normals, then hands
// them over without copying. The page's input handlers never wait for it.

import { fetchSlice } from './mesh.js';

self.onmessage = async (e) => {
  const { id, design } = e.data;
  const { transfer, ...res } = await fetchSlice(design);
  self.postMessage({ id, ...res }, transfer || []);
};
