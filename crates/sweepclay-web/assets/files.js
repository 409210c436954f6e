// Files in and out (docs/MODELER.md, "Files"): the design saved and opened
// as JSON, a vessel mesh sent to the server to be fitted
// (docs/MESHES.md), an SVG or CSV path imported through a preview that
// thins dense shapes, and the server's G-code and STL downloaded.

import { segDist } from './editor.js';
import { edit, setDesign, state } from './store.js';
import { setVerdict, showError, showNote } from './status.js';
import { download, postDesign } from './io.js';
import { setClosed } from './shapes.js';
import { editors } from './editors-panel.js';
import { keptPrinters, withMyPrinter } from './printer-dialog.js';

/**
 * The printer an opened design prints on: the file's own only when it
 * names one the user has (a preset, or a printer kept in this browser),
 * and then the note says so; else the printer in use stays (an opened
 * mesh names none). Returns the design and what to say, if anything.
 */
function onMyPrinter(d, name) {
  const p = d.printer;
  const pname = typeof p === 'string' ? p : p && p.name;
  const presets = (state.meta?.presets || []).map((x) => x.name);
  const kept = keptPrinters().find((k) => k.printer.name === pname);
  if (typeof p === 'string' && presets.includes(p)) return [d, `${name} names the printer ${p}: now printing on it.`];
  if (kept) {
    d.printer = { ...kept.printer };
    return [d, `${name} names your printer ${pname}: now printing on it.`];
  }
  const mine = state.design?.printer;
  const mineName = typeof mine === 'string' ? mine : mine?.name;
  const said = pname && pname !== mineName ? `${name} names a printer you do not have (${pname}): kept yours, ${mineName || 'generic'}.` : null;
  return [withMyPrinter(d), said];
}

const $ = (id) => document.getElementById(id);


/**
 * The design's name as a file name: Unicode kept, only what no file
 * system takes (/ \ : * ? " < > |, control characters) replaced, and
 * dots and spaces at the ends dropped.
 */
function baseName() {
  const n = (state.design.name || '').replace(/[/\\:*?"<>|\u0000-\u001f]+/g, '_').replace(/^[\s.]+|[\s.]+$/g, '');
  return n || 'sweepclay';
}

export async function downloadFrom(route, ext, button) {
  button.disabled = true;
  const label = button.textContent;
  button.textContent = 'working…';
  try {
    const r = await postDesign(route, JSON.stringify(state.design));
    if (!r.ok) {
      const body = await r.json();
      if (body.failures) setVerdict({ printable: false, failures: body.failures, locations: body.locations || [] });
      showError(`No ${ext.toUpperCase()} file: ${body.error}`, body.key);
      return;
    }
    download(await r.blob(), `${baseName()}.${ext}`);
  } catch (e) {
    showError(`the server did not answer: ${e.message || e}`);
  } finally {
    button.disabled = false;
    button.textContent = label;
  }
}

function readFile(input) {
  return new Promise((resolve, reject) => {
    const f = input.files[0];
    input.value = '';
    if (!f) return;
    const r = new FileReader();
    r.onload = () => resolve({ name: f.name, text: String(r.result) });
    r.onerror = () => reject(r.error);
    r.readAsText(f);
  });
}

$('save').addEventListener('click', () => {
  download(new Blob([JSON.stringify(state.design, null, 1) + '\n'], { type: 'application/json' }), `${baseName()}.json`);
});
$('open').addEventListener('click', () => $('open-file').click());
$('open-file').addEventListener('change', async () => {
  const file = $('open-file').files[0];
  if (file && /\.(stl|obj)$/i.test(file.name)) {
    $('open-file').value = '';
    openMesh(file);
    return;
  }
  const { name, text } = await readFile($('open-file'));
  let d;
  try {
    d = JSON.parse(text);
  } catch (e) {
    showError(`${name}: not JSON: ${e.message}`);
    return;
  }
  if (typeof d !== 'object' || !d || !d.profile_start || !d.trajectory) {
    showError(`${name}: not a sweepclay design (it needs profile_start and trajectory)`);
    return;
  }
  const [mine, said] = onMyPrinter(d, name);
  setDesign(mine, { fit: true });
  if (said) showNote(said);
});
/**
 * A vessel mesh: the server cuts it into sections and fits it by a
 * design (docs/MESHES.md), which opens as any design does; the note
 * says how close the fit is, or the error why there is none.
 */
async function openMesh(file) {
  showNote(`${file.name}: cutting and fitting the mesh…`);
  let r;
  try {
    r = await fetch(`/api/mesh?name=${encodeURIComponent(file.name)}`, {
      method: 'POST', headers: { 'content-type': 'application/octet-stream' }, body: await file.arrayBuffer(),
    });
  } catch (e) {
    showError(`${file.name}: the server could not be reached (${e.message})`);
    return;
  }
  const body = await r.json();
  if (!r.ok) {
    $('status').querySelector('.note')?.remove();
    showError(`${file.name}: ${body.error}`);
    return;
  }
  // A mesh names no printer: the one in use stays.
  setDesign(withMyPrinter(body.design), { fit: true });
  const kind = body.kind === 'shell' ? 'a wall with its thickness, its outside kept' : 'a solid, its outside kept';
  const units = body.note ? `; ${body.note}` : '';
  // A twist and ribs found in the mesh are the design's own twist and
  // texture (docs/MESHES.md, "Twist", "Ribs").
  const ribs = (body.design.texture || [])
    .map((t) => `, ${t.count} ${t.kind === 'spiral' ? 'spiral ribs' : 'flutes'} ${t.amplitude} mm deep`).join('');
  const twist = (body.design.twist_deg ? `, twisted ${body.design.twist_deg}°` : '') + ribs;
  if (body.sweep) {
    // No sweep within the tolerance: the design is the closest sweep and
    // a relief, and prints as the mesh is (docs/MESHES.md).
    const [x, y, z] = body.sweep.at.map((v) => v.toFixed(1));
    showNote(`${file.name}: ${body.triangles} triangles (${kind}), printed as the mesh is (within ${body.deviation_mm.toFixed(2)} mm). It could not be made an editable sweep: the closest one${twist} differs from it by ${body.sweep.deviation_mm.toFixed(2)} mm at (${x}, ${y}, ${z}) mm, so the rest rides on it as a relief; editing the curves reshapes the sweep under it${units}`);
    return;
  }
  showNote(`${file.name}: ${body.triangles} triangles (${kind}), now an editable design${twist} within ${body.deviation_mm.toFixed(2)} mm of the mesh${units}`);
}

$('import').addEventListener('click', () => $('import-file').click());
$('import-file').addEventListener('change', async () => {
  const { name, text } = await readFile($('import-file'));
  const format = /\.svg$/i.test(name) || text.trimStart().startsWith('<') ? 'svg' : 'csv';
  const r = await fetch(`/api/import/${format}`, {
    method: 'POST', headers: { 'content-type': 'application/octet-stream' }, body: text,
  });
  const body = await r.json();
  if (!r.ok) {
    showError(`${name}: ${body.error}`);
    return;
  }
  openImport(name, body);
});

/**
 * Ramer–Douglas–Peucker: the fewest of `pts` that keep the polyline within
 * `tol` of itself (a loop is split at its farthest point first).
 */
function simplify(pts, tol, closed) {
  if (pts.length < 3) return pts.slice();
  const keep = new Uint8Array(pts.length);
  const run = (i, j) => {
    const stack = [[i, j]];
    while (stack.length) {
      const [a, b] = stack.pop();
      let far = -1;
      let fd = tol;
      for (let k = a + 1; k < b; k++) {
        const d = segDist(pts[a], pts[b % pts.length], pts[k]);
        if (d > fd) {
          fd = d;
          far = k;
        }
      }
      if (far >= 0) {
        keep[far] = 1;
        stack.push([a, far], [far, b]);
      }
    }
  };
  keep[0] = 1;
  if (closed) {
    // The point farthest from the first splits the loop in two.
    let far = 1;
    for (let k = 1; k < pts.length; k++) {
      if ((pts[k][0] - pts[0][0]) ** 2 + (pts[k][1] - pts[0][1]) ** 2 > (pts[far][0] - pts[0][0]) ** 2 + (pts[far][1] - pts[0][1]) ** 2) far = k;
    }
    keep[far] = 1;
    run(0, far);
    run(far, pts.length);
  } else {
    keep[pts.length - 1] = 1;
    run(0, pts.length - 1);
  }
  return pts.filter((_, k) => keep[k]);
}

/** Shows an import before it replaces the path: which shape, how dense. */
function openImport(name, body) {
  const shapes = body.shapes;
  const pick = $('im-pick');
  pick.innerHTML = '';
  shapes.forEach((sh, i) => {
    const o = document.createElement('option');
    o.value = i;
    o.textContent = `${i + 1}: ${sh.label} (${sh.points.length} points${sh.closed ? ', closed' : ''})`;
    pick.appendChild(o);
  });
  $('im-pick-row').hidden = shapes.length < 2;
  // Dense shapes become editable points by default: the picked one's
  // density decides, not the first's.
  const denseDefault = () => { $('im-simplify').checked = shapes[Number(pick.value) || 0].points.length > 150; };
  denseDefault();
  const chosen = () => {
    const sh = shapes[Number(pick.value) || 0];
    const tol = parseFloat($('im-tol').value);
    const pts = $('im-simplify').checked && tol > 0 ? simplify(sh.points, tol, sh.closed) : sh.points;
    return { sh, pts, tol };
  };
  const draw = () => {
    const { sh, pts, tol } = chosen();
    $('im-count').textContent = $('im-simplify').checked ? `${sh.points.length} → ${pts.length} points (within ${tol} mm)` : `${sh.points.length} points`;
    const left = (body.skipped || []).length ? ` ${body.skipped.join('; ')}.` : '';
    $('im-what').textContent = `${name}: ${shapes.length} shape${shapes.length > 1 ? 's' : ''}; the path is replaced only when you press “Use this path”.${left}`;
    drawImport($('im-preview'), sh.points, pts, sh.closed);
  };
  pick.onchange = () => { denseDefault(); draw(); };
  $('im-simplify').onchange = draw;
  $('im-tol').oninput = draw;
  draw();
  const dlg = $('import-dialog');
  dlg.onclose = () => {
    if (dlg.returnValue !== 'use') return;
    const { sh, pts } = chosen();
    useImport(name, { ...sh, points: pts });
  };
  dlg.returnValue = '';
  dlg.showModal();
}

/** The imported curve (grey) and the points that will be kept (blue). */
function drawImport(canvas, all, kept, closed) {
  const c = canvas.getContext('2d');
  const [w, h] = [canvas.width, canvas.height];
  c.clearRect(0, 0, w, h);
  const xs = all.map((p) => p[0]);
  const ys = all.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const k = Math.min((w - 20) / Math.max(1e-6, x1 - x0), (h - 20) / Math.max(1e-6, y1 - y0));
  const at = (p) => [10 + (p[0] - x0) * k + (w - 20 - (x1 - x0) * k) / 2, h - 10 - (p[1] - y0) * k - (h - 20 - (y1 - y0) * k) / 2];
  const line = (pts, colour, width) => {
    c.beginPath();
    pts.forEach((p, i) => (i ? c.lineTo(...at(p)) : c.moveTo(...at(p))));
    if (closed) c.closePath();
    c.strokeStyle = colour;
    c.lineWidth = width;
    c.stroke();
  };
  line(all, '#bbb', 4);
  line(kept, '#b5653a', 1.5);
  if (kept.length <= 400) {
    c.fillStyle = '#1d5fbf';
    for (const p of kept) {
      const [x, y] = at(p);
      c.fillRect(x - 2, y - 2, 4, 4);
    }
  }
}

function useImport(name, body) {
  edit((d) => {
    d.trajectory = body.closed ? { points: body.points, closed: true } : { points: body.points };
    if (body.offset === 'normal') d.trajectory.offset = 'normal';
    setClosed(d, body.closed, state.meta?.presets);
  }, true);
  // The note of the last import, or none: an earlier import's stays no
  // longer.
  if (body.note) showNote(`${name}: ${body.note}`);
  else $('status').querySelector('.note')?.remove();
  editors[2].fitted = false;
  editors[2].fit();
  editors[2].refresh();
}
