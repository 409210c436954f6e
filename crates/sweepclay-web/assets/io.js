// The page's ways out to the server and the disk: a design posted to an
// API route, and a file handed to the browser to save.

/** POSTs a design (JSON text) to an API route. */
export function postDesign(route, json) {
  return fetch(route, { method: 'POST', headers: { 'content-type': 'application/json' }, body: json });
}

/** Saves `blob` as `name` through the browser's download. */
export function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}
