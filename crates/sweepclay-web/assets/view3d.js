// The 3D preview: the corrected surface (lit, translucent, moved samples in
// orange), the toolpath as one line coloured by bead width, pass or stage,
// the returning turns' top-edge beads as dots, and the bed. WebGL 2, drawn
// on demand; orbit, pan and zoom with mouse, touch or pen.

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

const CLAY = [0.83, 0.62, 0.48];
const MOVED = [1.0, 0.5, 0.0];

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

export class View3D {
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', { antialias: true });
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
    this.colourBy = 'width';
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
    new ResizeObserver(() => this.redraw()).observe(canvas);
  }

  /** New slicing result; `params` gives the width range for colours. */
  update(data, params, fit) {
    const gl = this.gl;
    this.data = data;
    this.params = params;
    const P = new Float32Array(data.surface.positions);
    const n = P.length / 3;
    // Smooth normals from the triangles.
    const N = new Float32Array(P.length);
    const T = zip(P, data.surface.columns);
    for (let t = 0; t < T.length; t += 3) {
      const [a, b, c] = [T[t] * 3, T[t + 1] * 3, T[t + 2] * 3];
      const u = [P[b] - P[a], P[b + 1] - P[a + 1], P[b + 2] - P[a + 2]];
      const v = [P[c] - P[a], P[c + 1] - P[a + 1], P[c + 2] - P[a + 2]];
      const x = u[1] * v[2] - u[2] * v[1];
      const y = u[2] * v[0] - u[0] * v[2];
      const z = u[0] * v[1] - u[1] * v[0];
      for (const i of [a, b, c]) {
        N[i] += x;
        N[i + 1] += y;
        N[i + 2] += z;
      }
    }
    const C = new Float32Array(P.length);
    for (let i = 0; i < n; i++) C.set(CLAY, 3 * i);
    for (const i of data.surface.moved) C.set(MOVED, 3 * i);
    this.replace('surface', this.mesh(this.lit, { pos: P, nrm: N, col: C }, T));
    // The path: positions in print order.
    const order = data.path.order;
    const PP = new Float32Array(order.length * 3);
    order.forEach((s, i) => PP.set(P.subarray(3 * s, 3 * s + 3), 3 * i));
    this.pathPositions = PP;
    this.recolour();
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
    this.replace('bed', this.mesh(this.flat, { pos: new Float32Array(g), col: new Float32Array(g.length).fill(0.82) }));
    this.box = [[x0, y0, 0], [x1, y1, hi[2]]];
    if (fit) this.fit();
    // Drawn now, not at the next frame, so the caller can time the update.
    this.draw();
    gl.finish();
  }

  recolour() {
    const d = this.data;
    if (!d) return;
    const n = d.path.order.length;
    const C = new Float32Array(3 * n);
    const K = d.plan.passes;
    const lower = d.plan.lower_passes;
    const [w0, w1] = [this.params.width_min, this.params.width_max];
    const top = new Set(d.path.top);
    for (let i = 0; i < n; i++) {
      let c;
      if (this.colourBy === 'pass') c = ramp((d.path.pass[i] - 1) / Math.max(1, K - 1));
      else if (this.colourBy === 'stage') c = top.has(i) ? [0.1, 0.1, 0.1] : d.path.pass[i] > lower ? [0.93, 0.45, 0.1] : [0.15, 0.4, 0.8];
      else c = ramp((d.path.width[i] - w0) / Math.max(1e-6, w1 - w0));
      C.set(c, 3 * i);
    }
    this.replace('path', this.mesh(this.flat, { pos: this.pathPositions, col: C }));
    this.redraw();
  }

  legend() {
    const p = this.params;
    if (!p || !this.data) return '';
    if (this.colourBy === 'pass') return `pass 1 <i style="background:${grad()}"></i> ${this.data.plan.passes}`;
    if (this.colourBy === 'stage') {
      return this.data.plan.stages === 2
        ? '<b style="color:#2666cc">lower stage</b> · <b style="color:#ed731a">upper stage</b> · <b>● top-edge beads (returning turns)</b>'
        : '<b style="color:#2666cc">one stage</b>';
    }
    return `width ${p.width_min} mm <i style="background:${grad()}"></i> ${p.width_max} mm`;
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

  fit() {
    if (!this.box) return;
    const [lo, hi] = this.box;
    this.target = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] / 2];
    const r = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2]) / 2;
    this.dist = r / Math.tan((Math.PI / 8)) * 1.1;
    this.redraw();
  }

  redraw() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.draw();
    });
  }

  draw() {
    const gl = this.gl;
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr));
    const h = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== w || c.height !== h) {
      c.width = w;
      c.height = h;
    }
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
      this.drawMesh(this.path, gl.LINE_STRIP);
      this.drawMesh(this.marks, gl.POINTS);
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
  }

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

/**
 * Triangles between adjacent transition curves, always advancing along the
 * curve whose next sample is lower (as mesh::surface_triangles in Rust).
 * `cols` is [first, count, first, count, …].
 */
export function zip(P, cols) {
  let total = 0;
  for (let c = 0; c + 3 < cols.length; c += 2) total += cols[c + 1] + cols[c + 3] - 2;
  const T = new Uint32Array(3 * total);
  let t = 0;
  for (let c = 0; c + 3 < cols.length; c += 2) {
    let i = cols[c];
    let j = cols[c + 2];
    const ae = i + cols[c + 1];
    const be = j + cols[c + 3];
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

function grad() {
  return `linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map((f) => {
    const [r, g, b] = ramp(f).map((v) => Math.round(v * 255));
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
