// The 3D preview: the corrected surface (lit, translucent, moved samples in
// orange), the toolpath as one line or as beads of their true width and
// height, coloured by stability (the least room of overlap, overhang, layer
// height and the extruder body's clearance, docs/ALGORITHMS.md §11), one of
// those four, bead width, pass or stage; the worst bead marked, the
// returning turns' top-edge beads as dots, the bed and the printer's build
// volume, with what lies outside it in red. WebGL 2, drawn on demand;
// orbit, pan and zoom with mouse, touch or pen.

const VS_LIT = `#version 300 es
in vec3 pos; in vec3 nrm; in vec3 col;
uniform mat4 mvp; out vec3 v_col; out vec3 v_n;
void main() { gl_Position = mvp * vec4(pos, 1.0); v_col = col; v_n = nrm; }`;
const FS_LIT = `#version 300 es
precision mediump float;
in vec3 v_col; in vec3 v_n; uniform float alpha; out vec4 o;
void main() {
  vec3 n = normalize(v_n);
  float l = 0.45 + 0.55 * abs(dot(n, normalize(vec3(0.4, -0.5, 0.75))));
  o = vec4(v_col * l, alpha);
}`;
const VS_FLAT = `#version 300 es
in vec3 pos; in vec3 col;
uniform mat4 mvp; uniform float size; out vec3 v_col;
void main() { gl_Position = mvp * vec4(pos, 1.0); gl_PointSize = size; v_col = col; }`;
const FS_FLAT = `#version 300 es
precision mediump float;
in vec3 v_col; out vec4 o;
void main() { o = vec4(v_col, 1.0); }`;

/** The shortest time between two drawings of the edited curves over the
 * 3D view while they change (ms; docs/MODELER.md, "Speed budget"). */
const OVERLAY_MS = 66;

const CLAY = [0.83, 0.62, 0.48];
const MOVED = [1.0, 0.5, 0.0];
// Outside the printer is violet: red is kept for a bead at a limit.
const OUTSIDE = [0.56, 0.27, 0.88];
const WORST = [0.55, 0.0, 0.35];

/** Red → yellow → green for a margin m ∈ [0, 1] (0: at the limit). */
export function margin(m) {
  m = Math.min(1, Math.max(0, m));
  return hsl(m * 120, 0.75, 0.42);
}

/**
 * The room each bead has, 0 (at or past a limit) to 1 (plenty), by each
 * of the four figures of the bead map, and the least of them.
 */
export function margins(beads, i, p, all = {}) {
  const ov = (beads.overlap[i] - 0.5) / Math.max(1e-6, p.overlap - 0.5);
  const oh = 1 - beads.overhang_deg[i] / p.max_overhang_deg;
  const h = beads.layer_height[i];
  // A layer thinner than the minimum is a bead pressed onto the one below
  // (a spiral's first turn, a rim's taper): supported, but worth seeing,
  // so it goes no lower than half; one thicker than the maximum falls off.
  const lh = h < p.layer_height * 0.95 ? 0.5 + 0.5 * (h / (p.layer_height * 0.95)) : h > p.max_layer_height * 1.05 ? (p.max_layer_height * 1.05) / h : 1;
  const cl = beads.clearance[i] / p.nozzle_height;
  // Filled in place: the page asks for every bead of the path at once.
  all.overlap = Math.min(1, Math.max(0, ov));
  all.overhang = Math.min(1, Math.max(0, oh));
  all.layer = Math.min(1, Math.max(0, lh));
  all.clearance = Math.min(1, Math.max(0, cl));
  all.stability = Math.min(all.overlap, all.overhang, all.layer, all.clearance);
  // What a change of the design can improve: a thin layer is a spiral's
  // start or a rim's taper, made so on purpose, and never the worst bead.
  all.fixable = Math.min(all.overlap, all.overhang, all.clearance, h > p.max_layer_height * 1.05 ? all.layer : 1);
  return all;
}

/** Blue → cyan → green → yellow → red for f ∈ [0, 1]. */
export function ramp(f) {
  f = Math.min(1, Math.max(0, f));
  const h = (1 - f) * 240;
  return hsl(h, 0.8, 0.45);
}

function hsl(h, s, l) {
  const k = (n) => (n + h / 30) % 12;
  const a = s * Math.min(l, 1 - l);
  const f = (n) => l - a * Math.max(-1, Math.min(k(n) - 3, Math.min(9 - k(n), 1)));
  return [f(0), f(8), f(4)];
}

import { afterPaint, onFrame } from './frame.js';

export class View3D {
  /**
   * @param {HTMLCanvasElement} canvas the WebGL view
   * @param {HTMLCanvasElement} overlay a 2D canvas over it for the
   *   edited curves, so that a drag never redraws the 3D scene
   */
  constructor(canvas, overlay) {
    this.canvas = canvas;
    this.overlay = overlay;
    // Smoothed edges cost a software GPU (SwiftShader, llvmpipe) most of
    // a frame: there they are off (docs/MODELER.md).
    const gl = canvas.getContext('webgl2', { antialias: !softwareGL() });
    if (!gl) throw new Error('this browser has no WebGL 2: the 3D preview is off');
    this.gl = gl;
    this.lit = program(gl, VS_LIT, FS_LIT);
    this.flat = program(gl, VS_FLAT, FS_FLAT);
    this.yaw = -0.6;
    this.pitch = 0.45;
    this.dist = 300;
    this.target = [0, 0, 30];
    this.showSurface = true;
    this.showPath = true;
    this.trueWidth = false;
    this.colourBy = 'stability';
    this.data = null;
    this.pointers = new Map();
    canvas.addEventListener('pointerdown', (e) => this.down(e));
    canvas.addEventListener('pointermove', (e) => this.move(e));
    canvas.addEventListener('pointerup', (e) => this.up(e));
    canvas.addEventListener('pointercancel', (e) => this.up(e));
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.dist *= Math.exp(e.deltaY * 0.0015);
      this.redraw();
    }, { passive: false });
    // Drawn in the next frame (see editor.js: no resizing inside the
    // observer's callback).
    new ResizeObserver(() => requestAnimationFrame(() => this.redraw())).observe(canvas);
  }

  /** New slicing result; `params` gives the width range for colours. */
  update(data, params, fit) {
    this.data = data;
    this.lines = null;
    this.params = params;
    const P = data.surface.positions;
    const n = P.length / 3;
    // The triangles and their smooth normals come made (mesh.js, in the
    // slice worker, off the main thread).
    const T = data.surface.triangles;
    const N = data.surface.normals;
    const C = new Float32Array(P.length);
    for (let i = 0; i < n; i++) C.set(CLAY, 3 * i);
    for (const i of data.surface.moved) C.set(MOVED, 3 * i);
    this.replace('surface', this.mesh(this.lit, { pos: P, nrm: N, col: C }, T));
    // The path: positions in print order.
    const order = data.path.order;
    const PP = new Float32Array(order.length * 3);
    order.forEach((s, i) => PP.set(P.subarray(3 * s, 3 * s + 3), 3 * i));
    this.pathPositions = PP;
    // Top-edge beads and the start/end marks.
    const marks = [];
    const mcol = [];
    for (const i of data.path.top) {
      marks.push(...PP.subarray(3 * i, 3 * i + 3));
      mcol.push(0.1, 0.1, 0.1);
    }
    this.topCount = data.path.top.length;
    marks.push(...PP.subarray(0, 3), ...PP.subarray(PP.length - 3));
    mcol.push(0.1, 0.6, 0.2, 0.8, 0.1, 0.1);
    this.replace('marks', this.mesh(this.flat, { pos: new Float32Array(marks), col: new Float32Array(mcol) }));
    // The bed: a 10 mm grid under the bounding box.
    const [lo, hi] = [data.stats.bounds_mm[0], data.stats.bounds_mm[1]];
    const o = data.origin || [0, 0];
    const x0 = Math.floor((lo[0] - o[0]) / 10) * 10 - 10, x1 = Math.ceil((hi[0] - o[0]) / 10) * 10 + 10;
    const y0 = Math.floor((lo[1] - o[1]) / 10) * 10 - 10, y1 = Math.ceil((hi[1] - o[1]) / 10) * 10 + 10;
    const g = [];
    for (let x = x0; x <= x1; x += 10) g.push(x, y0, 0, x, y1, 0);
    for (let y = y0; y <= y1; y += 10) g.push(x0, y, 0, x1, y, 0);
    const gc = new Array(g.length).fill(0.82);
    // The build volume, in the design's coordinates (the bed's less the
    // origin): a box, or a cylinder for a round bed.
    const pr = data.printer;
    if (pr) {
      const b0 = [pr.bed_min[0] - o[0], pr.bed_min[1] - o[1], 0];
      const b1 = [b0[0] + pr.build_volume[0], b0[1] + pr.build_volume[1], pr.build_volume[2]];
      const edges = [];
      if (pr.bed_diameter) {
        const c = [(b0[0] + b1[0]) / 2, (b0[1] + b1[1]) / 2];
        const r = pr.bed_diameter / 2;
        for (let k = 0; k < 64; k++) {
          const [a, b] = [(k / 64) * 2 * Math.PI, ((k + 1) / 64) * 2 * Math.PI];
          for (const z of [0, b1[2]]) edges.push(c[0] + r * Math.cos(a), c[1] + r * Math.sin(a), z, c[0] + r * Math.cos(b), c[1] + r * Math.sin(b), z);
          if (k % 16 === 0) edges.push(c[0] + r * Math.cos(a), c[1] + r * Math.sin(a), 0, c[0] + r * Math.cos(a), c[1] + r * Math.sin(a), b1[2]);
        }
      } else {
        const X = [b0[0], b1[0]], Y = [b0[1], b1[1]], Z = [0, b1[2]];
        for (const y of Y) for (const z of Z) edges.push(X[0], y, z, X[1], y, z);
        for (const x of X) for (const z of Z) edges.push(x, Y[0], z, x, Y[1], z);
        for (const x of X) for (const y of Y) edges.push(x, y, Z[0], x, y, Z[1]);
      }
      g.push(...edges);
      for (let k = 0; k < edges.length; k += 3) gc.push(0.45, 0.55, 0.7);
      this.volume = { b0, b1, round: pr.bed_diameter ? [(b0[0] + b1[0]) / 2, (b0[1] + b1[1]) / 2, pr.bed_diameter / 2] : null };
    } else {
      this.volume = null;
    }
    this.replace('bed', this.mesh(this.flat, { pos: new Float32Array(g), col: new Float32Array(gc) }));
    const old = this.box;
    this.box = [[x0, y0, 0], [x1, y1, hi[2]]];
    const grew = !old || this.box[0].some((v, k) => v < old[0][k]) || this.box[1].some((v, k) => v > old[1][k]);
    // Coloured once the build volume is known (what lies outside is violet).
    this.recolour();
    // A print that grew out of sight (a top pulled up past the view) is
    // framed again: nothing of it may be off-screen.
    if (fit || (grew && !this.inView())) this.fit();
    // Drawn with the next frame: never waiting here for the GPU.
    this.redraw();
  }

  /**
   * The edited curves (pairs of points), drawn over the last slice until
   * the next one arrives; `since` is the edit's time, for the speed
   * budget's immediate preview (docs/MODELER.md).
   */
  showCurves(lines, since) {
    // Drawn on the overlay at the frame, never in an input handler: a
    // drag's many moves make one drawing a frame (docs/MODELER.md). And
    // at most every OVERLAY_MS: the whole overlay redrawn and composited
    // each frame held the frames 33–50 ms apart where the editor alone
    // paints every 17 ms, and the finger's curve is the editor's.
    this.curvesSince = this.curvesSince ?? since ?? null;
    this.nextLines = lines;
    if (this.overlayTimer) return;
    const draw = () => {
      this.overlayTimer = 0;
      onFrame('view3d-curves', () => {
        this.overlayAt = performance.now();
        const l = this.nextLines;
        this.lines = typeof l === 'function' ? l() : l;
        this.drawOverlay();
        this.timeCurves();
      });
    };
    const wait = OVERLAY_MS - (performance.now() - this.overlayAt);
    if (wait <= 0) draw();
    else this.overlayTimer = setTimeout(draw, wait);
  }

  /**
   * The edited curves on the 2D canvas over the view, projected as the
   * 3D view is seen: drawn by the CPU in a fraction of a 3D frame.
   */
  drawOverlay() {
    const o = this.overlay;
    const [w, h, dpr] = fitCanvas(o);
    const c = o.getContext('2d', { willReadFrequently: true });
    c.clearRect(0, 0, w, h);
    const L = this.lines;
    if (!L || !L.length || !this.data) return;
    const m = this.matrix(w / h);
    const at = (p) => {
      const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
      const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
      const q = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
      return q > 1e-6 ? [((x / q + 1) / 2) * w, ((1 - y / q) / 2) * h] : null;
    };
    c.strokeStyle = 'rgb(26, 51, 191)';
    c.lineWidth = 1.5 * dpr;
    c.beginPath();
    for (let i = 0; i + 1 < L.length; i += 2) {
      const [a, b] = [at(L[i]), at(L[i + 1])];
      if (!a || !b) continue;
      c.moveTo(a[0], a[1]);
      c.lineTo(b[0], b[1]);
    }
    c.stroke();
  }

  /** From the edit to the painted frame with its curves (the speed budget). */
  timeCurves() {
    if (this.curvesSince == null) return;
    const since = this.curvesSince;
    this.curvesSince = null;
    afterPaint((t) => {
      this.curveTimes.push(t - since);
      if (this.curveTimes.length > 200) this.curveTimes.shift();
    });
  }

  /** Beads drawn as boxes of their width and height, or as a line. */
  setTrueWidth(on) {
    this.trueWidth = on;
    this.recolour();
  }

  /** Whether a point (design coordinates) lies outside the build volume. */
  outside(P, i) {
    const v = this.volume;
    if (!v) return false;
    const [x, y, z] = [P[3 * i], P[3 * i + 1], P[3 * i + 2]];
    if (v.round && Math.hypot(x - v.round[0], y - v.round[1]) > v.round[2]) return true;
    return x < v.b0[0] || y < v.b0[1] || x > v.b1[0] || y > v.b1[1] || z > v.b1[2];
  }

  recolour() {
    const d = this.data;
    if (!d) return;
    const n = d.path.order.length;
    const C = new Float32Array(3 * n);
    const K = d.plan.passes;
    const lower = d.plan.lower_passes;
    const p = this.params;
    const [w0, w1] = [p.width_min, p.width_max];
    const top = new Set(d.path.top);
    const beads = d.path.beads;
    const PP = this.pathPositions;
    // The bead with the least room, for the mark and the legend.
    let worst = -1;
    let worstM = 2;
    this.outsideCount = 0;
    const scratch = {};
    for (let i = 0; i < n; i++) {
      let c;
      const m = beads ? margins(beads, i, p, scratch) : null;
      if (m && m.fixable < worstM) {
        worstM = m.fixable;
        worst = i;
      }
      if (this.colourBy === 'pass') c = ramp((d.path.pass[i] - 1) / Math.max(1, K - 1));
      else if (this.colourBy === 'stage') c = top.has(i) ? [0.1, 0.1, 0.1] : d.path.pass[i] > lower ? [0.93, 0.45, 0.1] : [0.15, 0.4, 0.8];
      else if (this.colourBy === 'texture') c = d.path.texture_kept ? margin(d.path.texture_kept[i]) : [0.6, 0.6, 0.6];
      else if (this.colourBy === 'width' || !m) c = ramp((d.path.width[i] - w0) / Math.max(1e-6, w1 - w0));
      else c = margin(m[this.colourBy]);
      if (this.outside(PP, i)) {
        c = OUTSIDE;
        this.outsideCount++;
      }
      C.set(c, 3 * i);
    }
    this.worst = worst >= 0 ? { i: worst, m: margins(beads, worst, p) } : null;
    this.pathColours = C;
    this.replace('path', this.mesh(this.flat, { pos: PP, col: C }));
    if (this.trueWidth) this.replace('tubesMesh', this.tubes(C));
    if (this.worst) {
      const w = PP.subarray(3 * worst, 3 * worst + 3);
      this.replace('worstMark', this.mesh(this.flat, { pos: new Float32Array(w), col: new Float32Array(WORST) }));
    }
    this.redraw();
  }

  /**
   * Each bead as a box of its width and layer height (top and both sides,
   * flat-shaded), ending at the nozzle's height: the clay as it will lie.
   */
  tubes(C) {
    const d = this.data;
    const PP = this.pathPositions;
    const n = d.path.order.length;
    const pos = new Float32Array(n * 18 * 3);
    const nrm = new Float32Array(n * 18 * 3);
    const col = new Float32Array(n * 18 * 3);
    let v = 0;
    const put = (p, q, c) => {
      pos.set(p, 3 * v);
      nrm.set(q, 3 * v);
      col.set(c, 3 * v);
      v++;
    };
    for (let i = 1; i < n; i++) {
      const a = PP.subarray(3 * (i - 1), 3 * i);
      const b = PP.subarray(3 * i, 3 * i + 3);
      let [dx, dy] = [b[0] - a[0], b[1] - a[1]];
      const l = Math.hypot(dx, dy);
      if (l < 1e-6) continue;
      [dx, dy] = [dx / l, dy / l];
      const w = d.path.width[i] / 2;
      const h = Math.max(0.1, d.path.beads ? d.path.beads.layer_height[i] : 1);
      const s = [-dy * w, dx * w];
      const c = C.subarray(3 * i, 3 * i + 3);
      const corner = (p, side, up) => [p[0] + side * s[0], p[1] + side * s[1], p[2] - (up ? 0 : h)];
      const quad = (p0, p1, p2, p3, q) => {
        for (const p of [p0, p1, p2, p0, p2, p3]) put(p, q, c);
      };
      quad(corner(a, -1, true), corner(a, 1, true), corner(b, 1, true), corner(b, -1, true), [0, 0, 1]);
      quad(corner(a, 1, true), corner(a, 1, false), corner(b, 1, false), corner(b, 1, true), [s[0], s[1], 0]);
      quad(corner(a, -1, false), corner(a, -1, true), corner(b, -1, true), corner(b, -1, false), [-s[0], -s[1], 0]);
    }
    return this.mesh(this.lit, { pos: pos.subarray(0, 3 * v), nrm: nrm.subarray(0, 3 * v), col: col.subarray(0, 3 * v) });
  }

  /**
   * What the worst bead a change can improve lacks, in words, and what to
   * change (docs/MODELER.md): for the legend.
   */
  worstWords() {
    const w = this.worst;
    if (!w) return '';
    const b = this.data.path.beads;
    const p = this.params;
    const i = w.i;
    const zi = this.pathPositions[3 * i + 2];
    const z = zi.toFixed(1);
    const m = w.m;
    const k = ['overlap', 'overhang', 'clearance', 'layer'].sort((x, y) => m[x] - m[y])[0];
    const what = {
      overlap: `overlap ${(100 * b.overlap[i]).toFixed(0)} %`,
      overhang: `overhang ${b.overhang_deg[i].toFixed(0)}° of ${p.max_overhang_deg}°`,
      layer: `layer ${b.layer_height[i].toFixed(2)} mm`,
      clearance: `body clearance ${b.clearance[i].toFixed(1)} mm`,
    }[k];
    let advice = '';
    // Advice only where the room is short (under a quarter), and only
    // where following it changes the verdict: a print that passes needs
    // none (a straight cylinder's foot was told to pull its wall in).
    const fails = this.data.verdict && this.data.verdict.printable === false;
    if (m[k] < 0.25 && fails) {
      if (k === 'overhang' || k === 'overlap') {
        const by = this.pullIn(i);
        advice = by ? `: pull the wall in by about ${by} mm near z ${z} mm` : `: lean the wall less near z ${z} mm`;
      } else if (k === 'clearance') {
        advice = `: the wall leans in over clay there; lean it in less near z ${z} mm, or set a taller extruder body height if yours is`;
      } else {
        advice = `: bring the two profiles' heights closer, or allow a thicker max layer height`;
      }
    }
    return `least room: ${what} at z ${z} mm (◆)${advice}`;
  }

  /**
   * How far (mm, to half a mm) the wall must come in around bead `i` for
   * its overhang to keep a quarter of the limit as room: the excess lean
   * over the band of steep beads at its height, taken as a wedge.
   */
  pullIn(i) {
    const b = this.data.path.beads;
    const p = this.params;
    const PP = this.pathPositions;
    const target = 0.75 * p.max_overhang_deg;
    const lean = b.overhang_deg[i];
    if (!(lean > target)) return 0;
    const gap = 3 * p.max_layer_height;
    const zs = [];
    for (let j = 0; j < b.overhang_deg.length; j++) if (b.overhang_deg[j] > target) zs.push(PP[3 * j + 2]);
    zs.sort((x, y) => x - y);
    const z = PP[3 * i + 2];
    let k = zs.findIndex((v) => v >= z - 1e-6);
    if (k < 0) k = zs.length - 1;
    let [lo, hi] = [k, k];
    while (lo > 0 && zs[lo] - zs[lo - 1] < gap) lo--;
    while (hi + 1 < zs.length && zs[hi + 1] - zs[hi] < gap) hi++;
    const band = Math.max(zs[hi] - zs[lo], b.layer_height[i]);
    const rad = Math.PI / 180;
    const mm = (band * (Math.tan(lean * rad) - Math.tan(target * rad))) / 2;
    return Math.max(0.5, Math.round(mm * 2) / 2);
  }

  /**
   * The colours' legend, and the marks every colouring shares: the black
   * beads of the rim and the top edge, the start and end, the samples a
   * correction moved (orange on the surface).
   */
  legend() {
    const main = this.colourLegend();
    if (!main) return main;
    const keys = [];
    if (this.topCount) keys.push(`<b>● ${this.data.stats.vessel ? 'rim and top-edge beads' : 'top-edge beads'}</b>`);
    keys.push('<b style="color:#1a9933">●</b> start · <b style="color:#cc1a1a">●</b> end');
    if (this.data.surface.moved.length) keys.push('<b style="color:#ff8000">■</b> surface moved by a correction');
    return `${main} · ${keys.join(' · ')}`;
  }

  colourLegend() {
    const p = this.params;
    if (!p || !this.data) return '';
    const out = this.outsideCount ? ` · <b style="color:#8f45e0">■ ${this.outsideCount} points outside the printer</b>` : '';
    const worst = this.data.path.beads ? ` · ${this.worstWords()}` : '';
    const m = `<i style="background:${grad(margin)}"></i>`;
    if (this.colourBy === 'stability') return `at a limit ${m} plenty of room${worst}${out}`;
    if (this.colourBy === 'overlap') return `overlap 50 % ${m} ${Math.round(100 * p.overlap)} %+${worst}${out}`;
    if (this.colourBy === 'overhang') return `overhang ${p.max_overhang_deg}° ${m} 0°${worst}${out}`;
    if (this.colourBy === 'layer') return `layer height outside ${p.layer_height}–${p.max_layer_height} mm ${m} within${worst}${out}`;
    if (this.colourBy === 'clearance') return `body clearance 0 ${m} ${p.nozzle_height} mm${worst}${out}`;
    if (this.colourBy === 'texture') {
      return this.data.path.texture_kept
        ? `texture reduced to nothing ${m} kept whole (where the clay would not hold it: Corrections says why)${out}`
        : `no texture${out}`;
    }
    if (this.colourBy === 'pass') return `pass 1 <i style="background:${grad()}"></i> ${this.data.plan.passes}${out}`;
    if (this.colourBy === 'stage') {
      return this.data.plan.stages === 2
        ? '<b style="color:#2666cc">lower stage</b> · <b style="color:#ed731a">upper stage</b>'
        : '<b style="color:#2666cc">one stage</b>';
    }
    return `width ${p.width_min} mm <i style="background:${grad()}"></i> ${p.width_max} mm${out}`;
  }

  /** Swaps in a new mesh and frees the GPU buffers of the old one. */
  replace(name, m) {
    const old = this[name];
    if (old) {
      for (const b of old.bufs) this.gl.deleteBuffer(b);
      this.gl.deleteVertexArray(old.vao);
    }
    this[name] = m;
  }

  mesh(prog, attrs, index) {
    const gl = this.gl;
    const bufs = [];
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    for (const [name, data] of Object.entries(attrs)) {
      const loc = gl.getAttribLocation(prog, name);
      if (loc < 0) continue;
      const buf = gl.createBuffer();
      bufs.push(buf);
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    }
    let count = attrs.pos.length / 3;
    if (index) {
      const ib = gl.createBuffer();
      bufs.push(ib);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, index, gl.STATIC_DRAW);
      count = index.length;
    }
    gl.bindVertexArray(null);
    return { vao, bufs, count, indexed: !!index };
  }

  /** Whether every corner of the print's box is on the canvas. */
  inView() {
    if (!this.box) return true;
    const c = this.canvas;
    const m = this.matrix(Math.max(1, c.clientWidth) / Math.max(1, c.clientHeight));
    const [lo, hi] = this.box;
    for (const x of [lo[0], hi[0]]) {
      for (const y of [lo[1], hi[1]]) {
        for (const z of [lo[2], hi[2]]) {
          const w = m[3] * x + m[7] * y + m[11] * z + m[15];
          if (w <= 1e-6) return false;
          const px = (m[0] * x + m[4] * y + m[8] * z + m[12]) / w;
          const py = (m[1] * x + m[5] * y + m[9] * z + m[13]) / w;
          if (Math.abs(px) > 1 || Math.abs(py) > 1) return false;
        }
      }
    }
    return true;
  }

  fit() {
    if (!this.box) return;
    const [lo, hi] = this.box;
    this.target = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] / 2];
    const r = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2]) / 2;
    // A tall narrow canvas (a phone) sees less across than up and down.
    const c = this.canvas;
    const aspect = Math.min(1, Math.max(1, c.clientWidth) / Math.max(1, c.clientHeight));
    this.dist = (r / (Math.tan(Math.PI / 8) * aspect)) * 1.1;
    this.redraw();
  }

  redraw() {
    onFrame('view3d-draw', () => this.draw());
  }

  draw() {
    const gl = this.gl;
    const [w, h, dpr] = fitCanvas(this.canvas);
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.957, 0.945, 0.925, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!this.data) return;
    const mvp = this.matrix(w / h);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.flat);
    gl.uniformMatrix4fv(gl.getUniformLocation(this.flat, 'mvp'), false, mvp);
    gl.uniform1f(gl.getUniformLocation(this.flat, 'size'), 5 * dpr);
    this.drawMesh(this.bed, gl.LINES);
    if (this.showPath) {
      if (!this.trueWidth) this.drawMesh(this.path, gl.LINE_STRIP);
      this.drawMesh(this.marks, gl.POINTS);
      gl.uniform1f(gl.getUniformLocation(this.flat, 'size'), 14 * dpr);
      this.drawMesh(this.worstMark, gl.POINTS);
    }
    if (this.showPath && this.trueWidth) {
      gl.useProgram(this.lit);
      gl.uniformMatrix4fv(gl.getUniformLocation(this.lit, 'mvp'), false, mvp);
      gl.uniform1f(gl.getUniformLocation(this.lit, 'alpha'), 1.0);
      this.drawMesh(this.tubesMesh, gl.TRIANGLES);
    }
    if (this.showSurface) {
      gl.useProgram(this.lit);
      gl.uniformMatrix4fv(gl.getUniformLocation(this.lit, 'mvp'), false, mvp);
      gl.uniform1f(gl.getUniformLocation(this.lit, 'alpha'), this.showPath ? 0.45 : 1.0);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(!this.showPath);
      this.drawMesh(this.surface, gl.TRIANGLES);
      gl.depthMask(true);
      gl.disable(gl.BLEND);
    }
    this.drawOverlay();
  }

  /** Times from edits to their curves on screen (ms), newest last. */
  curveTimes = [];
  overlayAt = -Infinity;
  overlayTimer = 0;

  drawMesh(m, mode) {
    if (!m) return;
    const gl = this.gl;
    gl.bindVertexArray(m.vao);
    if (m.indexed) gl.drawElements(mode, m.count, gl.UNSIGNED_INT, 0);
    else gl.drawArrays(mode, 0, m.count);
    gl.bindVertexArray(null);
  }

  matrix(aspect) {
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    const eye = [
      this.target[0] + this.dist * cp * Math.cos(this.yaw),
      this.target[1] + this.dist * cp * Math.sin(this.yaw),
      this.target[2] + this.dist * sp,
    ];
    const view = lookAt(eye, this.target, [0, 0, 1]);
    const proj = perspective(Math.PI / 4, aspect, Math.max(0.5, this.dist / 100), this.dist * 10 + 1000);
    return mul(proj, view);
  }

  /** Unit vectors of the screen's right and up directions in the world. */
  screenAxes() {
    const right = [-Math.sin(this.yaw), Math.cos(this.yaw), 0];
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    const fwd = [-cp * Math.cos(this.yaw), -cp * Math.sin(this.yaw), -sp];
    const up = cross(right, fwd);
    return [right, up];
  }

  down(e) {
    this.canvas.setPointerCapture(e.pointerId);
    this.pointers.set(e.pointerId, [e.clientX, e.clientY]);
    this.mode = e.button === 2 || e.shiftKey ? 'pan' : 'orbit';
  }

  move(e) {
    const last = this.pointers.get(e.pointerId);
    if (!last) return;
    const now = [e.clientX, e.clientY];
    if (this.pointers.size === 2) {
      const [a, b] = [...this.pointers.values()];
      const other = a === last ? b : a;
      const before = Math.hypot(last[0] - other[0], last[1] - other[1]);
      const after = Math.hypot(now[0] - other[0], now[1] - other[1]);
      if (before > 0 && after > 0) this.dist *= before / after;
      // Two fingers moving together pan: their midpoint moves by half of
      // this finger's move (a pinch alone leaves it in place).
      const k = this.dist / this.canvas.clientHeight;
      const [r, u] = this.screenAxes();
      const [mx, my] = [(now[0] - last[0]) / 2, (now[1] - last[1]) / 2];
      for (let i = 0; i < 3; i++) this.target[i] += (-mx * r[i] + my * u[i]) * k;
    } else {
      const dx = now[0] - last[0];
      const dy = now[1] - last[1];
      if (this.mode === 'pan') {
        const k = this.dist / this.canvas.clientHeight;
        const [r, u] = this.screenAxes();
        for (let i = 0; i < 3; i++) this.target[i] += (-dx * r[i] + dy * u[i]) * k;
      } else {
        this.yaw -= dx * 0.008;
        this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + dy * 0.008));
      }
    }
    this.pointers.set(e.pointerId, now);
    this.redraw();
  }

  up(e) {
    this.pointers.delete(e.pointerId);
  }
}

/** Sizes a canvas's pixels to its box on screen: `[width, height, dpr]`. */
function fitCanvas(c) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(c.clientWidth * dpr));
  const h = Math.max(1, Math.round(c.clientHeight * dpr));
  if (c.width !== w || c.height !== h) {
    c.width = w;
    c.height = h;
  }
  return [w, h, dpr];
}

/** Whether WebGL here is drawn by the CPU (no GPU, or a blocked one). */
function softwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : '';
    gl?.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|software|softpipe/i.test(name);
  } catch (e) {
    return false;
  }
}

function grad(f0 = ramp) {
  return `linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map((f) => {
    const [r, g, b] = f0(f).map((v) => Math.round(v * 255));
    return `rgb(${r},${g},${b})`;
  }).join(',')})`;
}

function program(gl, vs, fs) {
  const p = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}

function norm(v) {
  const l = Math.hypot(...v) || 1;
  return v.map((x) => x / l);
}

// Column-major 4×4 matrices, as WebGL expects.
function lookAt(eye, at, up) {
  const z = norm(eye.map((e, i) => e - at[i]));
  const x = norm(cross(up, z));
  const y = cross(z, x);
  const d = (v) => -(v[0] * eye[0] + v[1] * eye[1] + v[2] * eye[2]);
  return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, d(x), d(y), d(z), 1]);
}

function perspective(fov, aspect, near, far) {
  const f = 1 / Math.tan(fov / 2);
  const nf = 1 / (near - far);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
}

function mul(a, b) {
  const o = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
  }
  return o;
}
