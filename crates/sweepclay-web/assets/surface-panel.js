// The Surface panel (docs/MODELER.md): the twist slider and the textures,
// each with sliders in plain words; a picture texture takes any picture the
// browser reads. It reads the design from the store and changes it through
// `edit`; every new design refreshes it.

import { showError } from './status.js';
import { edit, state, subscribe } from './store.js';

const $ = (id) => document.getElementById(id);

// Each texture's sliders: [key, words, min, max, step, unit, kinds].
const TEXTURE_FIELDS = [
  ['amplitude', 'depth', -4, 4, 0.1, 'mm', ['ripple', 'flute', 'spiral', 'image']],
  ['period', 'a ring every', 4, 60, 0.5, 'mm', ['ripple']],
  ['count', 'ribs', 1, 60, 1, '', ['flute', 'spiral']],
  ['pitch', 'ribs move on one over', 10, 400, 5, 'mm of height', ['spiral']],
  ['fade_in', 'fade in above the foot', 0, 40, 1, 'mm', ['ripple', 'flute', 'spiral', 'image']],
  ['fade_out', 'fade out below the lip', 0, 40, 1, 'mm', ['ripple', 'flute', 'spiral', 'image']],
  ['phase_deg', 'start the wave at', -180, 180, 5, '°', ['ripple', 'flute', 'spiral']],
];
const TEXTURE_NAMES = { ripple: 'rings (ripple)', flute: 'ribs (flutes)', spiral: 'spiral ribs', image: 'your picture' };

/** A picture for a new image texture: a band of diamonds, 48 × 24. */
function defaultPicture() {
  const c = document.createElement('canvas');
  c.width = 48;
  c.height = 24;
  const g = c.getContext('2d');
  g.fillStyle = '#282828';
  g.fillRect(0, 0, 48, 24);
  g.fillStyle = '#fff';
  for (let x = 0; x < 48; x += 12) {
    g.beginPath();
    g.moveTo(x + 6, 3);
    g.lineTo(x + 11, 12);
    g.lineTo(x + 6, 21);
    g.lineTo(x + 1, 12);
    g.fill();
  }
  return c.toDataURL('image/png').split(',')[1];
}

/** Any picture the browser reads, as a greyscale-able PNG at most 256 px across (base64). */
function pictureAsPng(file) {
  return new Promise((resolve, reject) => {
    if (file.size > 8 << 20) {
      reject(new Error(`${file.name} is ${(file.size / 1048576).toFixed(1)} MB; at most 8 MB`));
      return;
    }
    const url = URL.createObjectURL(file);
    const img = new Image();
    img.onload = () => {
      const k = Math.min(1, 256 / img.naturalWidth, 256 / img.naturalHeight);
      const c = document.createElement('canvas');
      c.width = Math.max(1, Math.round(img.naturalWidth * k));
      c.height = Math.max(1, Math.round(img.naturalHeight * k));
      c.getContext('2d').drawImage(img, 0, 0, c.width, c.height);
      URL.revokeObjectURL(url);
      resolve(c.toDataURL('image/png').split(',')[1]);
    };
    img.onerror = () => {
      URL.revokeObjectURL(url);
      reject(new Error(`${file.name} is not a picture this browser can read`));
    };
    img.src = url;
  });
}

function newTexture(kind, d) {
  const closed = !!d.trajectory.closed;
  if (kind === 'ripple') return { kind, amplitude: 1, period: 10, fade_in: 5, fade_out: 5 };
  if (kind === 'flute') return { kind, amplitude: 1, count: 12, fade_in: 5, fade_out: 5 };
  if (kind === 'spiral') return { kind, amplitude: 1, count: closed ? 8 : 6, pitch: 80, fade_in: 5, fade_out: 5 };
  return { kind, amplitude: 1, png_base64: defaultPicture(), fade_in: 5, fade_out: 5 };
}

export function buildSurface() {
  const twist = $('twist');
  twist.addEventListener('input', () => { $('twist-val').value = `${twist.value}°`; });
  twist.addEventListener('change', () => edit((d) => {
    const v = Number(twist.value);
    if (v) d.twist_deg = v;
    else delete d.twist_deg;
  }, true));
  $('tex-add').addEventListener('change', () => {
    const kind = $('tex-add').value;
    $('tex-add').value = '';
    if (kind) edit((d) => { d.texture = [...(d.texture || []), newTexture(kind, d)]; }, true);
  });
}

/** The texture panel for the design: rebuilt when its entries change kind or number. */
function fillSurface() {
  const d = state.design;
  const twist = d.twist_deg || 0;
  if (document.activeElement !== $('twist')) {
    $('twist').value = String(twist);
    $('twist-val').value = `${twist}°`;
  }
  const tex = d.texture || [];
  const shape = tex.map((t) => t.kind).join(',');
  const list = $('tex-list');
  if (list.dataset.shape !== shape) {
    list.dataset.shape = shape;
    list.innerHTML = '';
    tex.forEach((t, k) => list.appendChild(textureBox(t, k)));
  }
  tex.forEach((t, k) => {
    for (const [key, , , , , unit] of TEXTURE_FIELDS) {
      const inp = $(`tex-${key}-${k}`);
      if (!inp || document.activeElement === inp) continue;
      const v = t[key] ?? 0;
      inp.value = String(v);
      inp.nextElementSibling.value = `${v}${unit ? ` ${unit}` : ''}`;
    }
  });
}

function textureBox(t, k) {
  const box = document.createElement('fieldset');
  box.className = 'texture';
  box.id = `tex-${k}`;
  const legend = document.createElement('legend');
  legend.textContent = `${TEXTURE_NAMES[t.kind] || t.kind} `;
  const del = document.createElement('button');
  del.type = 'button';
  del.id = `tex-del-${k}`;
  del.textContent = '×';
  del.title = 'Remove this texture';
  del.addEventListener('click', () => edit((d) => {
    d.texture.splice(k, 1);
    if (!d.texture.length) delete d.texture;
  }, true));
  legend.appendChild(del);
  box.appendChild(legend);
  for (const [key, words, min, max, step, unit, kinds] of TEXTURE_FIELDS) {
    if (!kinds.includes(t.kind)) continue;
    const l = document.createElement('label');
    l.className = 'row';
    l.append(`${words} `);
    const inp = document.createElement('input');
    inp.type = 'range';
    inp.id = `tex-${key}-${k}`;
    Object.assign(inp, { min, max, step });
    const out = document.createElement('output');
    inp.addEventListener('input', () => { out.value = `${inp.value}${unit ? ` ${unit}` : ''}`; });
    inp.addEventListener('change', () => edit((d) => {
      const v = Number(inp.value);
      if ((key.startsWith('fade') || key === 'phase_deg') && !v) delete d.texture[k][key];
      else d.texture[k][key] = v;
    }, true));
    l.append(inp, out);
    box.appendChild(l);
  }
  if (t.kind === 'image') {
    const l = document.createElement('label');
    l.className = 'row';
    l.title = 'A picture wrapped round the wall: light pushes the wall out, dark in (any format the browser reads; kept as a PNG at most 256 px across)';
    l.append('picture ');
    const f = document.createElement('input');
    f.type = 'file';
    f.accept = 'image/*';
    f.id = `tex-file-${k}`;
    f.addEventListener('change', async () => {
      const file = f.files[0];
      if (!file) return;
      try {
        const png = await pictureAsPng(file);
        edit((d) => { d.texture[k].png_base64 = png; delete d.texture[k].path; }, true);
      } catch (e) {
        showError(`texture[${k}]: ${e.message}`, `texture[${k}]`);
      }
    });
    l.appendChild(f);
    box.appendChild(l);
  }
  return box;
}

subscribe(() => fillSurface());
