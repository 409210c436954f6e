// A 2D control-point editor on a canvas: grid, snapping, zoom and pan, and
// points that can be added, dragged and deleted with a mouse, a finger or a
// pen (pointer events). The caller says what the points mean through
// options: how to draw the curve, which moves are allowed, what happens on
// a change.

import { noteInput, onFrame } from './frame.js';

// How near a point the pointer must come to take it (px): a mouse is
// precise; a fingertip covers about 10 mm, so a touch reaches further.
const HIT_PX = { mouse: 9, pen: 14, touch: 24 };
let editorCount = 0;

export class CurveEditor {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {object} o
   *   get(): the points [[x, y], …] in model units
   *   set(points, final): a change (final = the end of a gesture: record it)
   *   curve(points): the polyline to draw through them
   *   constrain(i, p, points): the allowed position for point i near p
   *   pinned(i, points): the point can be neither moved nor deleted
   *   kept(i, points): the point can be moved but not deleted
   *   minPoints: fewest points allowed
   *   snap: grid step for snapping; grid: grid line spacing
   *   fixed: [xmin, ymin, xmax, ymax]: a fixed view (no zoom or pan)
   *   ground: draw the line y = 0
   *   centre: draw and drag the centre o (the trajectory's top view)
   *   ghost(): another curve to draw faintly, e.g. the other profile
   *   printed(): the curve as printed, where the corrections moved it
   *     (a polyline in model coordinates, or null): drawn dashed green
   *   label(p): text beside the selected point
   *   onSelect(editor, user): the selection changed (or its point moved);
   *     `user` false for a refresh from the model
   */
  constructor(canvas, o) {
    this.canvas = canvas;
    this.o = o;
    this.ox = 0;
    this.oy = 0;
    this.selected = -1;
    this.drag = null;
    this.snapOn = true;
    this.fitted = false;
    this.points = [];
    this.key = `editor-${editorCount++}`;
    // The last pointer's kind: a touch reaches further, and two taps are
    // never a double-click (docs/MODELER.md).
    this.pointerType = 'mouse';
    canvas.addEventListener('pointerdown', (e) => this.down(e));
    canvas.addEventListener('pointermove', (e) => this.move(e));
    canvas.addEventListener('pointerup', (e) => this.up(e));
    canvas.addEventListener('pointercancel', (e) => this.up(e));
    // A drag ends however the pointer lets go: released over another
    // element, or its capture taken away.
    canvas.addEventListener('lostpointercapture', (e) => this.up(e));
    canvas.addEventListener('dblclick', (e) => this.dbl(e));
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('wheel', (e) => this.wheel(e), { passive: false });
    canvas.addEventListener('keydown', (e) => {
      if ((e.key === 'Delete' || e.key === 'Backspace') && this.selected >= 0) {
        e.preventDefault();
        this.remove(this.selected);
      }
    });
    // Sized in the next frame, not in the observer's own callback: a
    // canvas resized there re-lays the page out within the observation,
    // which Chromium reports as an error ("ResizeObserver loop").
    new ResizeObserver(() => requestAnimationFrame(() => this.resize())).observe(canvas);
  }

  resize() {
    const r = this.canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.max(1, Math.round(r.width * dpr));
    this.canvas.height = Math.max(1, Math.round(r.height * dpr));
    this.w = r.width;
    this.h = r.height;
    if (this.o.fixed || !this.fitted) this.fit();
    this.draw();
  }

  /** Reads the points from the model and redraws. */
  refresh() {
    this.points = this.o.get().map((p) => p.slice());
    if (this.selected >= this.points.length) this.selected = -1;
    // A change typed elsewhere (a pot's base made 150 mm wide, its
    // height 260 mm) re-frames the view when the curve leaves it or
    // shrinks to a speck in it; never while a finger or the mouse drags.
    if (this.fitted && !this.drag && !this.o.fixed && this.points.length && this.w) {
      const s = this.points.map((p) => this.toScreen(p));
      const xs = s.map((p) => p[0]);
      const ys = s.map((p) => p[1]);
      const out = Math.min(...xs) < 0 || Math.max(...xs) > this.w || Math.min(...ys) < 0 || Math.max(...ys) > this.h;
      const speck = Math.max(...xs) - Math.min(...xs) < 0.1 * this.w && Math.max(...ys) - Math.min(...ys) < 0.1 * this.h;
      if (out || speck) {
        this.fit();
        this.look = null;
      }
    }
    // An editor whose curves did not change is not drawn again: a drag in
    // one editor repaints that one (and the other profile's ghost).
    const look = JSON.stringify([this.points, this.o.ghost?.(), this.o.printed?.(), this.selected, this.o.curve(this.points).length]);
    if (look !== this.look || !this.fitted) {
      this.look = look;
      onFrame(`${this.key}-draw`, () => this.draw());
    }
    this.told(false);
  }

  /** Tells `onSelect`; `user`: the user selected or moved a point here
   * (not a refresh from the model, which every editor gets). */
  told(user = true) {
    if (this.o.onSelect) this.o.onSelect(this, user);
  }

  /** Whether the selected point may be deleted. */
  canRemove(i = this.selected) {
    if (i < 0 || this.points.length <= (this.o.minPoints || 2)) return false;
    if (this.o.pinned && this.o.pinned(i, this.points)) return false;
    return !(this.o.kept && this.o.kept(i, this.points));
  }

  /** Moves the selected point to `p` (typed in), within the constraints. */
  moveSelected(p) {
    const i = this.selected;
    if (i < 0 || (this.o.pinned && this.o.pinned(i, this.points))) return false;
    const q = this.o.constrain ? this.o.constrain(i, p, this.points) : p;
    if (!q) return false;
    this.points[i] = q;
    this.changed(true);
    this.draw();
    this.told();
    return true;
  }

  /**
   * Adds a point halfway to the next one (before the last, halfway to the
   * one before), selected: the touch gesture for double-click.
   */
  addAfterSelected() {
    const n = this.points.length;
    let i = this.selected >= 0 ? this.selected : n - 2;
    if (i >= n - 1) i = n - 2;
    if (i < 0) return false;
    const [a, b] = [this.points[i], this.points[i + 1]];
    return this.insertAt(i + 1, [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]);
  }

  /**
   * Inserts a point near `m` as point `k` (where the constraints allow),
   * selected; false when they allow none.
   */
  insertAt(k, m) {
    const pts = this.points.slice();
    pts.splice(k, 0, m);
    const q = this.o.constrain ? this.o.constrain(k, m, pts) : m;
    if (!q) return false;
    pts[k] = q;
    this.points = pts;
    this.selected = k;
    this.changed(true);
    this.draw();
    this.told();
    return true;
  }

  /** Frames all points (and o, for the trajectory). */
  fit() {
    if (!this.w) return;
    let [x0, y0, x1, y1] = this.o.fixed || bounds(this.o.get(), this.o.centre || this.o.ground);
    const m = 28;
    const sx = (this.w - 2 * m) / Math.max(x1 - x0, 1e-6);
    const sy = (this.h - 2 * m) / Math.max(y1 - y0, 1e-6);
    // A fixed view fills the canvas; a free one keeps x and y at one scale.
    const k = Math.min(sx, sy);
    this.sx = this.o.fixed ? sx : k;
    this.sy = this.o.fixed ? sy : k;
    this.ox = m + (this.w - 2 * m - (x1 - x0) * this.sx) / 2 - x0 * this.sx;
    this.oy = this.h - m - (this.h - 2 * m - (y1 - y0) * this.sy) / 2 + y0 * this.sy;
    this.fitted = true;
  }

  toScreen([x, y]) {
    return [this.ox + x * this.sx, this.oy - y * this.sy];
  }

  toModel(px, py) {
    return [(px - this.ox) / this.sx, (this.oy - py) / this.sy];
  }

  local(e) {
    const r = this.canvas.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  hit(px, py) {
    let best = -1;
    let bd = HIT_PX[this.pointerType] ?? HIT_PX.mouse;
    this.points.forEach((p, i) => {
      const [sx, sy] = this.toScreen(p);
      const d = Math.hypot(sx - px, sy - py);
      if (d <= bd) {
        bd = d;
        best = i;
      }
    });
    return best;
  }

  snap(p) {
    const s = this.o.snap;
    if (!this.snapOn || !s) return p;
    return p.map((v) => Math.round(v / s) * s);
  }

  down(e) {
    this.pointerType = e.pointerType || 'mouse';
    this.canvas.focus();
    const [px, py] = this.local(e);
    this.canvas.setPointerCapture(e.pointerId);
    const i = this.hit(px, py);
    if (i >= 0 && e.button === 0) {
      this.selected = i;
      this.drag = { kind: 'point', i, moved: false };
    } else if (this.o.centre && e.button === 0 && this.nearCentre(px, py)) {
      this.drag = { kind: 'centre', last: this.toModel(px, py), moved: false };
    } else if (!this.o.fixed) {
      this.selected = i >= 0 ? i : -1;
      this.drag = { kind: 'pan', px, py, ox: this.ox, oy: this.oy };
    } else {
      this.selected = -1;
    }
    this.draw();
    this.told();
  }

  nearCentre(px, py) {
    const [sx, sy] = this.toScreen([0, 0]);
    return Math.hypot(sx - px, sy - py) <= (HIT_PX[this.pointerType] ?? HIT_PX.mouse) + 3;
  }

  move(e) {
    const [px, py] = this.local(e);
    let d = this.drag;
    if (d && e.buttons === 0 && e.pointerType === 'mouse') {
      // The button came up where this canvas did not hear it.
      this.up(e);
      d = null;
    }
    if (!d) {
      if (e.pointerType === 'mouse') {
        const over = this.hit(px, py) >= 0 || (this.o.centre && this.nearCentre(px, py));
        this.canvas.style.cursor = over ? 'grab' : this.o.fixed ? 'crosshair' : 'move';
      }
      return;
    }
    // Only the latest position counts, once a frame; the time is the
    // oldest event's, so the wait in the queue counts (docs/MODELER.md).
    this.latest = [px, py];
    noteInput(e);
    this.since = this.since ?? e.timeStamp;
    onFrame(this.key, () => this.apply());
  }

  /** Moves what is dragged to the latest pointer position. */
  apply() {
    const d = this.drag;
    const at = this.latest;
    this.latest = null;
    if (!d || !at) return;
    const [px, py] = at;
    if (d.kind === 'pan') {
      this.ox = d.ox + px - d.px;
      this.oy = d.oy + py - d.py;
      this.draw();
    } else if (d.kind === 'point') {
      if (this.o.pinned && this.o.pinned(d.i, this.points)) return;
      let p = this.snap(this.toModel(px, py));
      p = this.o.constrain ? this.o.constrain(d.i, p, this.points) : p;
      if (!p) return;
      this.points[d.i] = p;
      d.moved = true;
      this.changed(false);
      this.draw();
    } else if (d.kind === 'centre') {
      // Moving o moves the curve the other way: o stays the origin.
      const m = this.snap(this.toModel(px, py));
      const dx = m[0] - d.last[0];
      const dy = m[1] - d.last[1];
      if (dx === 0 && dy === 0) return;
      d.last = m;
      this.points = this.points.map(([x, y]) => [x - dx, y - dy]);
      this.ox += dx * this.sx;
      this.oy -= dy * this.sy;
      d.moved = true;
      this.changed(false);
      this.draw();
    }
  }

  up(e) {
    // A position not yet applied is applied before the gesture ends.
    if (this.latest) this.apply();
    const d = this.drag;
    this.drag = null;
    if (this.canvas.hasPointerCapture(e.pointerId)) this.canvas.releasePointerCapture(e.pointerId);
    if (d && d.moved) {
      this.changed(true);
      this.told();
    }
  }

  dbl(e) {
    // On a touch screen two quick taps on two points are not a request
    // to delete the second: the buttons below add and delete there.
    if (this.pointerType !== 'mouse') return;
    const [px, py] = this.local(e);
    const i = this.hit(px, py);
    if (i >= 0) {
      this.remove(i);
      return;
    }
    // Insert on the nearest segment of the control polygon.
    const m = this.snap(this.toModel(px, py));
    let best = 0;
    let bd = Infinity;
    for (let k = 0; k + 1 < this.points.length; k++) {
      const dist = segDist(this.toScreen(this.points[k]), this.toScreen(this.points[k + 1]), [px, py]);
      if (dist < bd) {
        bd = dist;
        best = k;
      }
    }
    this.insertAt(best + 1, m);
  }

  /** Hands a copy of the points to the model; `final` ends a gesture. */
  changed(final) {
    const since = this.since;
    this.since = null;
    this.o.set(this.points.map((q) => q.slice()), final, since);
  }

  remove(i) {
    if (!this.canRemove(i)) return;
    this.points.splice(i, 1);
    this.selected = -1;
    this.changed(true);
    this.draw();
    this.told();
  }

  wheel(e) {
    if (this.o.fixed) return;
    e.preventDefault();
    const [px, py] = this.local(e);
    const f = Math.exp(-e.deltaY * 0.0015);
    this.ox = px - (px - this.ox) * f;
    this.oy = py - (py - this.oy) * f;
    this.sx *= f;
    this.sy *= f;
    this.draw();
  }

  draw() {
    const c = this.ctx();
    if (!this.w) return;
    const dpr = this.canvas.width / this.w;
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    c.clearRect(0, 0, this.w, this.h);
    this.drawGrid(c);
    const ghost = this.o.ghost ? this.o.ghost() : null;
    if (ghost) this.polyline(c, this.o.curve(ghost), '#c9c2b8', 1.5, [4, 3]);
    // Control polygon, curve, points.
    this.polyline(c, this.points, '#bbb', 1, [3, 3]);
    this.polyline(c, this.o.curve(this.points), '#b5653a', 2.2);
    // The curve as printed over the drawn one: dashes where they agree,
    // a second line where the corrections moved it.
    const printed = this.o.printed ? this.o.printed() : null;
    if (printed && printed.length >= 2) {
      this.polyline(c, printed, '#1b7d3a', 2, [6, 4]);
      c.fillStyle = '#1b7d3a';
      c.font = '11px system-ui';
      c.fillText('- - as printed (corrected)', 6, 14);
    }
    const many = this.points.length > 150;
    this.points.forEach((p, i) => {
      // A dense import is drawn as its curve: dots would hide it.
      if (many && i !== this.selected) return;
      const [x, y] = this.toScreen(p);
      const pinned = this.o.pinned && this.o.pinned(i, this.points);
      c.beginPath();
      c.arc(x, y, i === this.selected ? 6 : many ? 2 : 4.5, 0, 2 * Math.PI);
      c.fillStyle = i === this.selected ? '#1d5fbf' : pinned ? '#888' : '#fff';
      c.fill();
      c.strokeStyle = '#1d5fbf';
      c.lineWidth = 1.5;
      if (!many || i === this.selected) c.stroke();
    });
    if (this.o.centre) {
      const [x, y] = this.toScreen([0, 0]);
      c.strokeStyle = '#b3261e';
      c.lineWidth = 2;
      c.beginPath();
      c.moveTo(x - 8, y);
      c.lineTo(x + 8, y);
      c.moveTo(x, y - 8);
      c.lineTo(x, y + 8);
      c.stroke();
      c.fillStyle = '#b3261e';
      c.font = '12px system-ui';
      c.fillText('o', x + 5, y - 5);
    }
    if (this.selected >= 0 && this.points[this.selected]) {
      const p = this.points[this.selected];
      const [x, y] = this.toScreen(p);
      c.fillStyle = '#1d5fbf';
      c.font = '11px system-ui';
      const text = this.o.label ? this.o.label(p) : `${fmt(p[0])}, ${fmt(p[1])}`;
      c.fillText(text, Math.min(x + 8, this.w - 90), Math.max(y - 8, 12));
    }
  }

  /**
   * The drawing context, kept in memory rather than on the GPU: small
   * canvases redrawn every frame cost far less so where the GPU is
   * software (docs/MODELER.md, measured there).
   */
  ctx() {
    this.context = this.context || this.canvas.getContext('2d', { willReadFrequently: true });
    return this.context;
  }

  drawGrid(c) {
    const step = this.o.grid || 10;
    const [x0, y1] = this.toModel(0, 0);
    const [x1, y0] = this.toModel(this.w, this.h);
    const pxStep = step * this.sx;
    const k = pxStep < 12 ? Math.ceil(12 / pxStep) : 1;
    const s = step * k;
    c.lineWidth = 1;
    c.font = '10px system-ui';
    c.fillStyle = '#999';
    for (let x = Math.ceil(x0 / s) * s; x <= x1; x += s) {
      const [sx] = this.toScreen([x, 0]);
      const major = Math.abs(Math.round(x / s) % 5) === 0;
      c.strokeStyle = major ? '#e3ded6' : '#f1eee9';
      c.beginPath();
      c.moveTo(sx, 0);
      c.lineTo(sx, this.h);
      c.stroke();
      if (major) c.fillText(fmt(x), sx + 2, this.h - 3);
    }
    for (let y = Math.ceil(y0 / s) * s; y <= y1; y += s) {
      const [, sy] = this.toScreen([0, y]);
      const major = Math.abs(Math.round(y / s) % 5) === 0;
      c.strokeStyle = major ? '#e3ded6' : '#f1eee9';
      c.beginPath();
      c.moveTo(0, sy);
      c.lineTo(this.w, sy);
      c.stroke();
      if (major) c.fillText(fmt(y), 2, sy - 2);
    }
    if (this.o.ground) {
      const [, gy] = this.toScreen([0, 0]);
      c.strokeStyle = '#6b5a48';
      c.lineWidth = 2;
      c.beginPath();
      c.moveTo(0, gy);
      c.lineTo(this.w, gy);
      c.stroke();
    }
  }

  polyline(c, pts, colour, width, dash = []) {
    if (!pts || pts.length < 2) return;
    c.strokeStyle = colour;
    c.lineWidth = width;
    c.setLineDash(dash);
    c.beginPath();
    pts.forEach((p, i) => {
      const [x, y] = this.toScreen(p);
      if (i === 0) c.moveTo(x, y);
      else c.lineTo(x, y);
    });
    c.stroke();
    c.setLineDash([]);
  }
}

function bounds(pts, withOrigin) {
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  const all = withOrigin ? pts.concat([[0, 0]]) : pts;
  for (const [x, y] of all) {
    x0 = Math.min(x0, x);
    y0 = Math.min(y0, y);
    x1 = Math.max(x1, x);
    y1 = Math.max(y1, y);
  }
  if (!isFinite(x0)) return [-10, -10, 10, 10];
  const pad = Math.max(x1 - x0, y1 - y0) * 0.12 + 5;
  return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
}

/** Distance from `p` to the segment from `a` to `b` (any units). */
export function segDist(a, b, p) {
  const dx = b[0] - a[0];
  const dy = b[1] - a[1];
  const l2 = dx * dx + dy * dy;
  const t = l2 > 0 ? Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2)) : 0;
  return Math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
}

/** A number with at most two decimals. */
export function fmt(v) {
  return String(Math.round(v * 100) / 100);
}
