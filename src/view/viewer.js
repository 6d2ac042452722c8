// shoal viewer: one renderer, picking, agent panel and histogram shared by two data sources,
// a recorded run embedded in the page (replay) and the `/stream` of `shoal watch` (live).
// The data format is described in docs/viewer.md.
(function () {
  'use strict';

  const LIVE = window.SHOAL_LIVE === true;
  const $ = (id) => document.getElementById(id);

  // ---------------------------------------------------------------- small helpers

  function hexToRgb(hex) {
    const m = /^#?([0-9a-f]{6})$/i.exec(String(hex || '').trim());
    if (!m) return [0.75, 0.75, 0.75];
    const n = parseInt(m[1], 16);
    return [((n >> 16) & 255) / 255, ((n >> 8) & 255) / 255, (n & 255) / 255];
  }

  function hslToRgb(h, s, l) {
    const k = (n) => (n + h / 30) % 12;
    const a = s * Math.min(l, 1 - l);
    const f = (n) => l - a * Math.max(-1, Math.min(k(n) - 3, Math.min(9 - k(n), 1)));
    return [f(0), f(8), f(4)];
  }

  // Distinct colors for behaviors, by index (golden-angle hues).
  const behaviorColorCache = [];
  function behaviorColor(i) {
    if (!behaviorColorCache[i]) {
      behaviorColorCache[i] = hslToRgb((i * 137.508 + 20) % 360, 0.7, i % 2 ? 0.62 : 0.52);
    }
    return behaviorColorCache[i];
  }

  function cssColor(rgb) {
    return 'rgb(' + rgb.map((v) => Math.round(v * 255)).join(',') + ')';
  }

  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    if (attrs) for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function fmt(v, digits) {
    return v === null || v === undefined || Number.isNaN(v) ? '–' : Number(v).toFixed(digits);
  }

  // ---------------------------------------------------------------- matrices (column-major)

  const M4 = {
    perspective(fovy, aspect, near, far) {
      const f = 1 / Math.tan(fovy / 2);
      const m = new Float32Array(16);
      m[0] = f / aspect; m[5] = f;
      m[10] = (far + near) / (near - far); m[11] = -1;
      m[14] = (2 * far * near) / (near - far);
      return m;
    },
    lookAt(eye, c, up) {
      let zx = eye[0] - c[0], zy = eye[1] - c[1], zz = eye[2] - c[2];
      let l = Math.hypot(zx, zy, zz) || 1; zx /= l; zy /= l; zz /= l;
      let xx = up[1] * zz - up[2] * zy, xy = up[2] * zx - up[0] * zz, xz = up[0] * zy - up[1] * zx;
      l = Math.hypot(xx, xy, xz) || 1; xx /= l; xy /= l; xz /= l;
      const yx = zy * xz - zz * xy, yy = zz * xx - zx * xz, yz = zx * xy - zy * xx;
      return new Float32Array([
        xx, yx, zx, 0, xy, yy, zy, 0, xz, yz, zz, 0,
        -(xx * eye[0] + xy * eye[1] + xz * eye[2]),
        -(yx * eye[0] + yy * eye[1] + yz * eye[2]),
        -(zx * eye[0] + zy * eye[1] + zz * eye[2]), 1,
      ]);
    },
    mul(a, b) {
      const o = new Float32Array(16);
      for (let c = 0; c < 4; c++) {
        for (let r = 0; r < 4; r++) {
          o[c * 4 + r] = a[r] * b[c * 4] + a[4 + r] * b[c * 4 + 1] + a[8 + r] * b[c * 4 + 2] + a[12 + r] * b[c * 4 + 3];
        }
      }
      return o;
    },
  };

  // ---------------------------------------------------------------- camera

  // Orbits `target` (world up is +Y); distances scale with the world's size.
  const camera = {
    target: [0, 0, 0], yaw: 0.7, pitch: 0.55, dist: 100, fovy: Math.PI / 4, scale: 100,
    eye() {
      const cp = Math.cos(this.pitch);
      return [
        this.target[0] + this.dist * cp * Math.sin(this.yaw),
        this.target[1] + this.dist * Math.sin(this.pitch),
        this.target[2] + this.dist * cp * Math.cos(this.yaw),
      ];
    },
    fit(bounds) {
      const mn = bounds.min, mx = bounds.max;
      this.target = [(mn[0] + mx[0]) / 2, (mn[1] + mx[1]) / 2, (mn[2] + mx[2]) / 2];
      const r = Math.max(1, Math.hypot(mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]) / 2);
      this.scale = r;
      this.dist = r / Math.sin(this.fovy / 2) * 0.95;
    },
    orbit(dx, dy) {
      this.yaw -= dx * 0.006;
      this.pitch = Math.max(-1.45, Math.min(1.45, this.pitch + dy * 0.006));
    },
    pan(dx, dy, heightPx) {
      const e = this.eye();
      let fx = this.target[0] - e[0], fy = this.target[1] - e[1], fz = this.target[2] - e[2];
      const fl = Math.hypot(fx, fy, fz) || 1; fx /= fl; fy /= fl; fz /= fl;
      // right = forward x up(+Y); camera up = right x forward
      let rx = -fz, rz = fx; const rl = Math.hypot(rx, rz) || 1; rx /= rl; rz /= rl;
      const ux = -rz * fy, uy = rz * fx - rx * fz, uz = rx * fy;
      const k = (2 * this.dist * Math.tan(this.fovy / 2)) / Math.max(1, heightPx);
      this.target[0] += (-dx * rx + dy * ux) * k;
      this.target[1] += dy * uy * k;
      this.target[2] += (-dx * rz + dy * uz) * k;
    },
    zoom(factor) {
      this.dist = Math.max(this.scale * 0.01, Math.min(this.scale * 20, this.dist * factor));
    },
    viewProj(aspect) {
      const near = Math.max(0.01, this.dist * 0.01);
      const far = this.dist + this.scale * 6;
      return M4.mul(M4.perspective(this.fovy, aspect, near, far), M4.lookAt(this.eye(), this.target, [0, 1, 0]));
    },
  };

  // ---------------------------------------------------------------- renderer

  // Agents are point sprites, one vertex each: the vertex shader projects the body axis to find the
  // on-screen heading and foreshortening; the fragment shader cuts a fish silhouette (body + bent
  // tail) out of the square. One draw call per frame whatever the agent count, and cheap even on
  // software GL, where instancing is slow.
  const AGENT_VS = `
attribute vec3 iPos; attribute vec3 iFwd; attribute vec3 iColor; attribute float iLen; attribute float iBend;
uniform mat4 uViewProj; uniform vec2 uViewport; uniform float uProjF; uniform float uMinPx; uniform float uMaxPx;
varying vec3 vColor; varying vec2 vDir; varying float vAspect; varying float vBend;
vec2 toPx(vec4 c) { return c.xy / max(c.w, 1e-4) * 0.5 * uViewport; }
void main() {
  vec4 c = uViewProj * vec4(iPos, 1.0);
  gl_Position = c;
  vec3 f = iFwd; float fl = length(f);
  f = fl > 1e-6 ? f / fl : vec3(1.0, 0.0, 0.0);
  vec2 d = toPx(uViewProj * vec4(iPos + f * (0.5 * iLen), 1.0)) - toPx(uViewProj * vec4(iPos - f * (0.5 * iLen), 1.0));
  float onScreen = length(d);
  // side-on length in pixels at this depth
  float full = iLen * uProjF * 0.5 * uViewport.y / max(c.w, 1e-4);
  float size = clamp(full, uMinPx, uMaxPx);
  gl_PointSize = size;
  vDir = onScreen > 1e-3 ? d / onScreen : vec2(1.0, 0.0);
  vAspect = clamp(onScreen / max(full, 1e-3), 0.3, 1.0);
  vColor = iColor;
  vBend = iBend;
}`;
  const AGENT_FS = `
precision mediump float;
varying vec3 vColor; varying vec2 vDir; varying float vAspect; varying float vBend;
void main() {
  vec2 p = gl_PointCoord - 0.5;
  p.y = -p.y;
  // u along the body (nose +0.5), v to the fish's left on screen
  float u = dot(p, vDir) / vAspect;
  float v = dot(p, vec2(-vDir.y, vDir.x));
  float w = mix(0.2, 0.13, vAspect);
  float e = ((u - 0.08) * (u - 0.08)) / (0.38 * 0.38) + (v * v) / (w * w);
  float shade;
  if (e <= 1.0) {
    shade = e > 0.72 ? 0.6 : 1.0 - 0.3 * e;
  } else {
    float back = -0.2 - u;
    float vt = v + sin(vBend) * back;
    if (back < 0.0 || u < -0.5 || abs(vt) > 0.02 + back * 0.5) discard;
    shade = 0.75;
  }
  gl_FragColor = vec4(vColor * shade, 1.0);
}`;
  const COLOR_FS = `
precision mediump float; varying vec3 vColor;
void main() { gl_FragColor = vec4(vColor, 1.0); }`;
  const LINE_VS = `
attribute vec3 aPos; attribute vec3 aColor; uniform mat4 uViewProj; uniform float uPointSize;
varying vec3 vColor;
void main() { gl_Position = uViewProj * vec4(aPos, 1.0); gl_PointSize = uPointSize; vColor = aColor; }`;
  const POINT_FS = `
precision mediump float; varying vec3 vColor;
void main() { vec2 d = gl_PointCoord - 0.5; if (dot(d, d) > 0.25) discard; gl_FragColor = vec4(vColor, 1.0); }`;
  const MESH_VS = `
attribute vec3 aPos; attribute vec3 aNormal; attribute vec3 aColor; uniform mat4 uViewProj;
varying vec3 vColor; varying vec3 vNormal;
void main() { gl_Position = uViewProj * vec4(aPos, 1.0); vColor = aColor; vNormal = aNormal; }`;
  const MESH_FS = `
precision mediump float; varying vec3 vColor; varying vec3 vNormal;
void main() {
  float l = max(dot(normalize(vNormal), normalize(vec3(0.4, 1.0, 0.3))), 0.0);
  gl_FragColor = vec4(vColor * (0.35 + 0.65 * l), 1.0);
}`;

  const AGENT_FLOATS = 11; // pos 3, fwd 3, color 3, length 1, bend 1

  const renderer = {
    gl: null, ok: false, progs: {}, maxPointPx: 64,
    agentCount: 0, agentBuf: null,
    staticLines: null, staticPoints: null, foodPoints: null, selLines: null, terrain: null,
    init(canvas) {
      const opts = { antialias: false, alpha: false, preserveDrawingBuffer: false };
      let gl = canvas.getContext('webgl2', opts);
      const gl2 = !!gl;
      if (!gl) gl = canvas.getContext('webgl', opts) || canvas.getContext('experimental-webgl', opts);
      if (!gl) throw new Error('WebGL is not available in this browser');
      this.gl = gl;
      this.uintIndices = gl2 || !!gl.getExtension('OES_element_index_uint');
      this.maxPointPx = Math.min(512, gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE)[1] || 64);
      this.progs.agent = this.program(AGENT_VS, AGENT_FS);
      this.progs.line = this.program(LINE_VS, COLOR_FS);
      this.progs.point = this.program(LINE_VS, POINT_FS);
      this.progs.mesh = this.program(MESH_VS, MESH_FS);
      this.agentBuf = gl.createBuffer();
      this.staticLines = this.vertexSet();
      this.staticPoints = this.vertexSet();
      this.foodPoints = this.vertexSet();
      this.selLines = this.vertexSet();
      gl.enable(gl.DEPTH_TEST);
      gl.clearColor(0.043, 0.102, 0.165, 1);
      this.ok = true;
    },
    program(vs, fs) {
      const gl = this.gl;
      const compile = (type, src) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(s));
        return s;
      };
      const p = gl.createProgram();
      gl.attachShader(p, compile(gl.VERTEX_SHADER, vs));
      gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fs));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('program: ' + gl.getProgramInfoLog(p));
      const info = { p, a: {}, u: {} };
      const na = gl.getProgramParameter(p, gl.ACTIVE_ATTRIBUTES);
      for (let i = 0; i < na; i++) { const n = gl.getActiveAttrib(p, i).name; info.a[n] = gl.getAttribLocation(p, n); }
      const nu = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
      for (let i = 0; i < nu; i++) { const n = gl.getActiveUniform(p, i).name; info.u[n] = gl.getUniformLocation(p, n); }
      return info;
    },
    // A buffer of interleaved position + color vertices (6 floats each).
    vertexSet() {
      return { buf: this.gl.createBuffer(), count: 0 };
    },
    fill(set, data, usage) {
      const gl = this.gl;
      gl.bindBuffer(gl.ARRAY_BUFFER, set.buf);
      gl.bufferData(gl.ARRAY_BUFFER, data, usage || gl.STATIC_DRAW);
      set.count = data.length / 6;
    },
    setTerrain(t) {
      const gl = this.gl;
      this.terrain = null;
      if (!t || !t.cols || !t.rows || t.cols < 2 || t.rows < 2) return;
      const { cols, rows, cell } = t;
      const h = t.heights, blocked = t.blocked || [];
      let lo = Infinity, hi = -Infinity;
      for (let i = 0; i < h.length; i++) { if (h[i] < lo) lo = h[i]; if (h[i] > hi) hi = h[i]; }
      const span = hi > lo ? hi - lo : 1;
      const v = new Float32Array(cols * rows * 9);
      const H = (c, r) => h[Math.max(0, Math.min(rows - 1, r)) * cols + Math.max(0, Math.min(cols - 1, c))];
      for (let r = 0; r < rows; r++) {
        for (let c = 0; c < cols; c++) {
          const i = r * cols + c, o = i * 9;
          v[o] = t.origin[0] + (c + 0.5) * cell; v[o + 1] = h[i]; v[o + 2] = t.origin[1] + (r + 0.5) * cell;
          const nx = H(c - 1, r) - H(c + 1, r), nz = H(c, r - 1) - H(c, r + 1), ny = 2 * cell;
          const nl = Math.hypot(nx, ny, nz);
          v[o + 3] = nx / nl; v[o + 4] = ny / nl; v[o + 5] = nz / nl;
          const k = (h[i] - lo) / span;
          // deep teal → sand → pale, tinted red where blocked
          let col = k < 0.5
            ? [0.10 + 0.5 * k, 0.28 + 0.5 * k, 0.30 + 0.1 * k]
            : [0.35 + 0.6 * (k - 0.5), 0.53 + 0.4 * (k - 0.5), 0.35 + 0.5 * (k - 0.5)];
          if (blocked[i]) col = [0.55 + 0.3 * col[0], 0.15 + 0.2 * col[1], 0.15 + 0.2 * col[2]];
          v[o + 6] = col[0]; v[o + 7] = col[1]; v[o + 8] = col[2];
        }
      }
      const quads = (cols - 1) * (rows - 1);
      const idx = new Uint32Array(quads * 6);
      let q = 0;
      for (let r = 0; r + 1 < rows; r++) {
        for (let c = 0; c + 1 < cols; c++) {
          const a = r * cols + c, b = a + 1, d = a + cols, e = d + 1;
          idx[q++] = a; idx[q++] = d; idx[q++] = b; idx[q++] = b; idx[q++] = d; idx[q++] = e;
        }
      }
      const buf = gl.createBuffer();
      this.terrain = { buf, count: idx.length, ibuf: null };
      if (this.uintIndices) {
        gl.bindBuffer(gl.ARRAY_BUFFER, buf);
        gl.bufferData(gl.ARRAY_BUFFER, v, gl.STATIC_DRAW);
        this.terrain.ibuf = gl.createBuffer();
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.terrain.ibuf);
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
      } else {
        const flat = new Float32Array(idx.length * 9);
        for (let i = 0; i < idx.length; i++) flat.set(v.subarray(idx[i] * 9, idx[i] * 9 + 9), i * 9);
        gl.bindBuffer(gl.ARRAY_BUFFER, buf);
        gl.bufferData(gl.ARRAY_BUFFER, flat, gl.STATIC_DRAW);
      }
    },
    setAgents(data, count) {
      const gl = this.gl;
      gl.bindBuffer(gl.ARRAY_BUFFER, this.agentBuf);
      gl.bufferData(gl.ARRAY_BUFFER, data.subarray(0, count * AGENT_FLOATS), gl.DYNAMIC_DRAW);
      this.agentCount = count;
    },
    attrib(prog, name, size, stride, offset) {
      const gl = this.gl, loc = prog.a[name];
      if (loc === undefined || loc < 0) return;
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, size, gl.FLOAT, false, stride * 4, offset * 4);
      this.usedAttribs.push(loc);
    },
    releaseAttribs() {
      for (const loc of this.usedAttribs) this.gl.disableVertexAttribArray(loc);
      this.usedAttribs = [];
    },
    usedAttribs: [],
    drawSet(set, mode, prog, vp, pointSize) {
      if (!set.count) return;
      const gl = this.gl;
      gl.useProgram(prog.p);
      gl.uniformMatrix4fv(prog.u.uViewProj, false, vp);
      if (prog.u.uPointSize) gl.uniform1f(prog.u.uPointSize, pointSize || 1);
      gl.bindBuffer(gl.ARRAY_BUFFER, set.buf);
      this.attrib(prog, 'aPos', 3, 6, 0);
      this.attrib(prog, 'aColor', 3, 6, 3);
      gl.drawArrays(mode, 0, set.count);
      this.releaseAttribs();
    },
    draw(vp, widthPx, heightPx, dpr) {
      const gl = this.gl;
      gl.viewport(0, 0, widthPx, heightPx);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      if (this.terrain) {
        const p = this.progs.mesh;
        gl.useProgram(p.p);
        gl.uniformMatrix4fv(p.u.uViewProj, false, vp);
        gl.bindBuffer(gl.ARRAY_BUFFER, this.terrain.buf);
        this.attrib(p, 'aPos', 3, 9, 0);
        this.attrib(p, 'aNormal', 3, 9, 3);
        this.attrib(p, 'aColor', 3, 9, 6);
        if (this.terrain.ibuf) {
          gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.terrain.ibuf);
          gl.drawElements(gl.TRIANGLES, this.terrain.count, gl.UNSIGNED_INT, 0);
        } else {
          gl.drawArrays(gl.TRIANGLES, 0, this.terrain.count);
        }
        this.releaseAttribs();
      }
      this.drawSet(this.staticLines, gl.LINES, this.progs.line, vp);
      this.drawSet(this.staticPoints, gl.POINTS, this.progs.point, vp, 5 * dpr);
      this.drawSet(this.foodPoints, gl.POINTS, this.progs.point, vp, 4 * dpr);
      if (this.agentCount) {
        // One draw call for every agent of the frame.
        const p = this.progs.agent;
        gl.useProgram(p.p);
        gl.uniformMatrix4fv(p.u.uViewProj, false, vp);
        gl.uniform2f(p.u.uViewport, widthPx, heightPx);
        gl.uniform1f(p.u.uProjF, vp.projF);
        gl.uniform1f(p.u.uMinPx, 8 * dpr);
        gl.uniform1f(p.u.uMaxPx, this.maxPointPx);
        gl.bindBuffer(gl.ARRAY_BUFFER, this.agentBuf);
        this.attrib(p, 'iPos', 3, AGENT_FLOATS, 0);
        this.attrib(p, 'iFwd', 3, AGENT_FLOATS, 3);
        this.attrib(p, 'iColor', 3, AGENT_FLOATS, 6);
        this.attrib(p, 'iLen', 1, AGENT_FLOATS, 9);
        this.attrib(p, 'iBend', 1, AGENT_FLOATS, 10);
        gl.drawArrays(gl.POINTS, 0, this.agentCount);
        this.releaseAttribs();
      }
      gl.disable(gl.DEPTH_TEST);
      this.drawSet(this.selLines, gl.LINES, this.progs.line, vp);
      gl.enable(gl.DEPTH_TEST);
    },
  };

  // Line geometry builders: push position + color pairs into a plain array.
  const geom = {
    seg(out, a, b, c) { out.push(a[0], a[1], a[2], c[0], c[1], c[2], b[0], b[1], b[2], c[0], c[1], c[2]); },
    box(out, mn, mx, c) {
      const p = (i) => [i & 1 ? mx[0] : mn[0], i & 2 ? mx[1] : mn[1], i & 4 ? mx[2] : mn[2]];
      for (let i = 0; i < 8; i++) for (const bit of [1, 2, 4]) if (!(i & bit)) geom.seg(out, p(i), p(i | bit), c);
    },
    circle(out, ctr, r, axis, c, n) {
      n = n || 40;
      const pt = (k) => {
        const a = (k / n) * Math.PI * 2, u = Math.cos(a) * r, v = Math.sin(a) * r;
        if (axis === 0) return [ctr[0], ctr[1] + u, ctr[2] + v];
        if (axis === 1) return [ctr[0] + u, ctr[1], ctr[2] + v];
        return [ctr[0] + u, ctr[1] + v, ctr[2]];
      };
      for (let k = 0; k < n; k++) geom.seg(out, pt(k), pt(k + 1), c);
    },
    sphere(out, ctr, r, c) {
      geom.circle(out, ctr, r, 0, c); geom.circle(out, ctr, r, 1, c); geom.circle(out, ctr, r, 2, c);
      for (const f of [-0.6, 0.6]) geom.circle(out, [ctr[0], ctr[1] + f * r, ctr[2]], r * 0.8, 1, c);
    },
    cylinder(out, base, r, h, c) {
      const top = [base[0], base[1] + h, base[2]];
      geom.circle(out, base, r, 1, c); geom.circle(out, top, r, 1, c);
      for (let k = 0; k < 8; k++) {
        const a = (k / 8) * Math.PI * 2, dx = Math.cos(a) * r, dz = Math.sin(a) * r;
        geom.seg(out, [base[0] + dx, base[1], base[2] + dz], [top[0] + dx, top[1], top[2] + dz], c);
      }
    },
    cross(out, p, s, c) {
      geom.seg(out, [p[0] - s, p[1], p[2]], [p[0] + s, p[1], p[2]], c);
      geom.seg(out, [p[0], p[1] - s, p[2]], [p[0], p[1] + s, p[2]], c);
      geom.seg(out, [p[0], p[1], p[2] - s], [p[0], p[1], p[2] + s], c);
    },
  };

  // ---------------------------------------------------------------- shared scene state

  const state = {
    world: null,
    species: [], // [{name, rgb, length}]
    behaviors: [], // global behavior names
    frame: null, // the frame shown: see `makeFrame` / live `toFrame`
    colorMode: 'species',
    selected: null, // agent id
    follow: false,
    obstacleKey: '',
    instances: new Float32Array(0),
    dirty: true,
    renders: 0,
    applied: 0,
  };

  function setTables(species, behaviors) {
    state.species = species.map((s) => ({
      name: s.name, rgb: hexToRgb(s.color), length: s.length > 0 ? s.length : 1, behaviors: s.behaviors || [],
    }));
    state.behaviors = behaviors.slice();
    legend.build();
    histogram.build();
  }

  function setWorld(world) {
    state.world = world;
    camera.fit(world.bounds);
    renderer.setTerrain(world.terrain);
    state.obstacleKey = null;
    rebuildStatic(state.frame ? state.frame.tick : 0);
    const pts = [];
    for (const plan of world.plans || []) {
      for (const slots of plan.slots || []) for (const s of slots) pts.push(s[0], s[1], s[2], 0.4, 0.85, 0.95);
    }
    renderer.fill(renderer.staticPoints, new Float32Array(pts));
    state.dirty = true;
  }

  // Bounds, obstacles present at `tick`, plans.
  function rebuildStatic(tick) {
    const w = state.world;
    if (!w) return;
    const present = (w.obstacles || []).filter((o) => o.removed_tick === null || o.removed_tick === undefined || tick < o.removed_tick);
    const key = present.map((o) => o.id).join(',');
    if (key === state.obstacleKey) return;
    state.obstacleKey = key;
    const out = [];
    geom.box(out, w.bounds.min, w.bounds.max, [0.35, 0.48, 0.6]);
    for (const o of present) {
      if (o.shape === 'sphere') geom.sphere(out, o.center, o.radius, [0.85, 0.55, 0.45]);
      else if (o.shape === 'box') geom.box(out, o.min, o.max, [0.85, 0.55, 0.45]);
      else if (o.shape === 'cylinder') geom.cylinder(out, o.base, o.radius, o.height, [0.85, 0.55, 0.45]);
    }
    const s = camera.scale * 0.01;
    for (const plan of w.plans || []) {
      const path = plan.path || [];
      for (let i = 0; i + 1 < path.length; i++) geom.seg(out, path[i], path[i + 1], [1.0, 0.62, 0.2]);
      for (const k of plan.key_points || []) geom.cross(out, k, s * 1.5, [1, 1, 1]);
      for (const t of plan.transitions || []) geom.cross(out, t.at, s * 2.5, [0.95, 0.35, 0.85]);
    }
    renderer.fill(renderer.staticLines, new Float32Array(out));
    state.dirty = true;
  }

  // Value of per-agent field `name` at row `i` of `frame` (bytes hold [0, 1] as 0..255).
  function fval(frame, name, i) {
    const a = frame[name];
    if (!a || i >= a.length) return null;
    return frame.unorm && frame.unorm[name] ? a[i] / 255 : a[i];
  }

  function indexOfId(frame, id) {
    if (!frame || id === null) return -1;
    const ids = frame.ids;
    let lo = 0, hi = frame.n - 1;
    while (lo <= hi) { // ids ascend within a frame
      const mid = (lo + hi) >> 1;
      if (ids[mid] === id) return mid;
      if (ids[mid] < id) lo = mid + 1; else hi = mid - 1;
    }
    for (let i = 0; i < frame.n; i++) if (ids[i] === id) return i;
    return -1;
  }

  function fillInstances() {
    const f = state.frame;
    if (!f || !renderer.ok) return;
    const n = f.n;
    if (state.instances.length < n * AGENT_FLOATS) state.instances = new Float32Array(Math.ceil(n * 1.25) * AGENT_FLOATS + AGENT_FLOATS);
    const d = state.instances, sp = state.species, bySpecies = state.colorMode === 'species';
    const grey = [0.7, 0.7, 0.7];
    for (let i = 0, o = 0; i < n; i++, o += AGENT_FLOATS) {
      const s = sp[f.species[i]];
      const c = bySpecies ? (s ? s.rgb : grey) : behaviorColor(f.behavior[i]);
      d[o] = f.pos[3 * i]; d[o + 1] = f.pos[3 * i + 1]; d[o + 2] = f.pos[3 * i + 2];
      d[o + 3] = f.fwd[3 * i]; d[o + 4] = f.fwd[3 * i + 1]; d[o + 5] = f.fwd[3 * i + 2];
      d[o + 6] = c[0]; d[o + 7] = c[1]; d[o + 8] = c[2];
      d[o + 9] = s ? s.length : 1;
      d[o + 10] = f.tail_bend ? f.tail_bend[i] : 0;
    }
    renderer.setAgents(d, n);
    const food = f.food || [];
    const fp = new Float32Array((food.length / 3) * 6);
    for (let i = 0, j = 0; i < food.length; i += 3, j += 6) {
      fp[j] = food[i]; fp[j + 1] = food[i + 1]; fp[j + 2] = food[i + 2];
      fp[j + 3] = 0.55; fp[j + 4] = 0.92; fp[j + 5] = 0.35;
    }
    renderer.fill(renderer.foodPoints, fp, renderer.gl.DYNAMIC_DRAW);
  }

  // Shows `frame` everywhere: agents, food, obstacles, histogram, panel, clock.
  function applyFrame(frame) {
    state.frame = frame;
    state.applied++;
    rebuildStatic(frame.tick);
    fillInstances();
    histogram.update(frame);
    panel.update();
    source.onFrameShown(frame);
    state.dirty = true;
  }

  // ---------------------------------------------------------------- view / picking

  const canvas = $('gl');
  let viewProj = null;

  function resize() {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; state.dirty = true; }
  }

  function computeViewProj() {
    const aspect = canvas.width / Math.max(1, canvas.height);
    viewProj = camera.viewProj(aspect);
    viewProj.projF = 1 / Math.tan(camera.fovy / 2);
    return viewProj;
  }

  function followSelected() {
    if (!state.follow || !state.frame) return;
    const i = indexOfId(state.frame, state.selected);
    if (i < 0) return;
    const p = state.frame.pos, t = camera.target;
    const dx = p[3 * i] - t[0], dy = p[3 * i + 1] - t[1], dz = p[3 * i + 2] - t[2];
    if (Math.hypot(dx, dy, dz) < camera.scale * 1e-4) return;
    t[0] += dx * 0.2; t[1] += dy * 0.2; t[2] += dz * 0.2;
    state.dirty = true;
  }

  function render() {
    if (!renderer.ok) return;
    resize();
    const vp = computeViewProj();
    const sel = [];
    const f = state.frame;
    const i = indexOfId(f, state.selected);
    if (i >= 0) {
      const p = [f.pos[3 * i], f.pos[3 * i + 1], f.pos[3 * i + 2]];
      const w = vp[3] * p[0] + vp[7] * p[1] + vp[11] * p[2] + vp[15];
      const s = state.species[f.species[i]];
      const dpr = window.devicePixelRatio || 1;
      const r = Math.max((s ? s.length : 1) * 0.8, 12 * dpr * Math.max(w, 0) * 2 / (canvas.height * vp.projF));
      geom.box(sel, [p[0] - r, p[1] - r, p[2] - r], [p[0] + r, p[1] + r, p[2] + r], [1, 1, 0.3]);
    }
    renderer.fill(renderer.selLines, new Float32Array(sel), renderer.gl.DYNAMIC_DRAW);
    renderer.draw(vp, canvas.width, canvas.height, window.devicePixelRatio || 1);
    state.renders++;
  }

  // Client (CSS pixel) position of row `i` of the shown frame, or null when behind the camera.
  function screenPosOfRow(i, vp, rect) {
    const p = state.frame.pos, x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
    const cw = vp[3] * x + vp[7] * y + vp[11] * z + vp[15];
    if (cw <= 1e-6) return null;
    const cx = (vp[0] * x + vp[4] * y + vp[8] * z + vp[12]) / cw;
    const cy = (vp[1] * x + vp[5] * y + vp[9] * z + vp[13]) / cw;
    if (cx < -1 || cx > 1 || cy < -1 || cy > 1) return null;
    return { x: rect.left + (cx * 0.5 + 0.5) * rect.width, y: rect.top + (0.5 - cy * 0.5) * rect.height };
  }

  // Nearest agent to client point (x, y) within a few pixels, or null.
  function pickAt(x, y) {
    const f = state.frame;
    if (!f || !f.n) return null;
    resize();
    const vp = computeViewProj(), rect = canvas.getBoundingClientRect();
    let best = null, bestD = 10 * 10;
    for (let i = 0; i < f.n; i++) {
      const s = screenPosOfRow(i, vp, rect);
      if (!s) continue;
      const d = (s.x - x) * (s.x - x) + (s.y - y) * (s.y - y);
      if (d < bestD) { bestD = d; best = f.ids[i]; }
    }
    return best;
  }

  function select(id) {
    state.selected = id;
    state.follow = id !== null;
    panel.open(id);
    state.dirty = true;
  }

  // ---------------------------------------------------------------- legend

  const legend = {
    build() {
      const box = $('legend');
      box.textContent = '';
      const items = state.colorMode === 'species'
        ? state.species.map((s) => [s.name, s.rgb])
        : state.behaviors.map((b, i) => [b, behaviorColor(i)]);
      for (const [name, rgb] of items) {
        const row = el('div');
        const sw = el('span', { class: 'swatch' });
        sw.style.background = cssColor(rgb);
        row.append(sw, el('span', null, name));
        box.append(row);
      }
    },
  };

  // ---------------------------------------------------------------- histogram

  // Per species: a stacked bar of current behavior shares; live adds a rolling strip chart.
  const histogram = {
    rows: [],
    build() {
      const box = $('histogram');
      box.textContent = '';
      this.rows = state.species.map((s) => {
        const row = el('div', { class: 'hrow' });
        const name = el('div', { class: 'name' });
        const label = el('span', null, s.name), count = el('span', { class: 'muted' }, '');
        name.append(label, count);
        const bar = el('div', { class: 'hbar' });
        row.append(name, bar);
        let strip = null;
        if (LIVE) {
          strip = el('canvas', { class: 'strip', width: '280', height: '36' });
          row.append(strip);
        }
        box.append(row);
        return { bar, count, segs: [], strip };
      });
    },
    update(frame) {
      const ns = state.species.length, nb = Math.max(1, state.behaviors.length);
      const counts = new Uint32Array(ns * nb), totals = new Uint32Array(ns);
      for (let i = 0; i < frame.n; i++) {
        const s = frame.species[i], b = frame.behavior[i];
        if (s < ns && b < nb) { counts[s * nb + b]++; totals[s]++; }
      }
      for (let s = 0; s < ns && s < this.rows.length; s++) {
        const row = this.rows[s];
        row.count.textContent = String(totals[s]);
        for (let b = 0; b < nb; b++) {
          const c = counts[s * nb + b];
          let seg = row.segs[b];
          if (!seg && c) {
            seg = row.segs[b] = el('div');
            seg.style.background = cssColor(behaviorColor(b));
            seg.title = state.behaviors[b];
            row.bar.append(seg);
          }
          if (seg) {
            const pct = totals[s] ? (100 * c) / totals[s] : 0;
            seg.style.width = pct + '%';
            seg.title = state.behaviors[b] + ': ' + c + ' (' + pct.toFixed(0) + '%)';
          }
        }
        if (row.strip) this.stripColumn(row.strip, counts, s * nb, nb, totals[s]);
      }
    },
    // Scrolls the strip one pixel left and draws the newest shares at the right edge.
    stripColumn(cv, counts, base, nb, total) {
      const ctx = cv.getContext('2d'), w = cv.width, h = cv.height;
      ctx.drawImage(cv, -1, 0);
      ctx.fillStyle = '#1d3a56';
      ctx.fillRect(w - 1, 0, 1, h);
      if (!total) return;
      let y = h;
      for (let b = 0; b < nb; b++) {
        const c = counts[base + b];
        if (!c) continue;
        const hh = (c / total) * h;
        ctx.fillStyle = cssColor(behaviorColor(b));
        ctx.fillRect(w - 1, y - hh, 1, hh);
        y -= hh;
      }
    },
  };

  // ---------------------------------------------------------------- agent panel

  const panel = {
    live: null, // last /agent/<id> answer (live only)
    timer: null,
    open(id) {
      $('panel').classList.toggle('hidden', id === null);
      this.live = null;
      if (this.timer) { clearInterval(this.timer); this.timer = null; }
      if (id !== null && LIVE) {
        const poll = () => source.inspect(id).then((j) => { if (state.selected === id) { this.live = j; this.update(); } });
        poll();
        this.timer = setInterval(poll, 500);
      }
      this.update();
    },
    close() { select(null); },
    drive(name, v) {
      const row = el('div', { class: 'drive' });
      const bar = el('div', { class: 'bar' }), fill = el('div');
      const colors = { hunger: '#e0a030', libido: '#e06090', fear: '#6090e0' };
      fill.style.background = colors[name] || '#9fb3c8';
      fill.style.width = (v === null ? 0 : Math.max(0, Math.min(1, v)) * 100) + '%';
      bar.append(fill);
      row.append(el('span', null, name), bar, el('span', null, fmt(v, 2)));
      return row;
    },
    update() {
      const id = state.selected;
      if (id === null) return;
      const f = state.frame;
      const i = indexOfId(f, id);
      const lv = this.live;
      $('panel-id').textContent = String(id);
      const sp = i >= 0 ? state.species[f.species[i]] : null;
      $('panel-species').textContent = lv && lv.species !== undefined ? lv.species : sp ? sp.name : '–';
      $('panel-behavior').textContent = lv && lv.behavior !== undefined ? lv.behavior
        : i >= 0 ? state.behaviors[f.behavior[i]] || '?' : '–';
      $('panel-depth').textContent = lv && lv.stack ? String(lv.stack.length) : i >= 0 ? String(fval(f, 'stack_depth', i)) : '–';
      $('panel-speed').textContent = i >= 0 ? fmt(fval(f, 'speed', i), 2) : '–';
      const phase = i >= 0 ? fval(f, 'swim_phase', i) : null, bend = i >= 0 ? fval(f, 'tail_bend', i) : null;
      $('panel-anim').textContent = phase === null && bend === null ? '–'
        : 'swim phase ' + fmt(phase, 2) + ', tail bend ' + fmt(bend, 3) + ' rad';
      $('panel-status').textContent = source.agentStatus(id, i >= 0);
      const drives = $('panel-drives');
      drives.textContent = '';
      for (const name of ['hunger', 'libido', 'fear']) {
        const v = lv && lv.drives && lv.drives[name] !== undefined ? lv.drives[name] : i >= 0 ? fval(f, name, i) : null;
        drives.append(this.drive(name, v));
      }
      const decisions = lv ? lv.decisions || [] : source.decisions(id, f ? f.tick : 0);
      const stack = lv && lv.stack ? lv.stack.join(' > ') : decisions.length ? decisions[decisions.length - 1].stack : '';
      $('panel-stack').textContent = stack || '–';
      const memBox = $('panel-memory-box');
      memBox.classList.toggle('hidden', !(lv && lv.memory));
      if (lv && lv.memory) $('panel-memory').textContent = JSON.stringify(lv.memory, null, 2);
      const list = $('panel-history');
      list.textContent = '';
      const shown = decisions.slice(-200).reverse();
      for (const d of shown) {
        const li = el('li');
        li.append(el('b', null, 't' + d.tick + ' '), el('span', null, (d.from || '∅') + ' → ' + (d.to || '∅') + ' '),
          el('span', { class: 'muted' }, '(' + d.cause + ')'));
        if (d.condition) li.append(el('div', { class: 'cond' }, d.condition));
        list.append(li);
      }
      if (!shown.length) list.append(el('li', { class: 'muted' }, 'no decisions yet'));
    },
  };

  // ---------------------------------------------------------------- run health

  // The run's health report (replay: `health.json`; live: streamed about once a second):
  // per-species figures against their bounds, and the warnings; clicking a warning seeks to its
  // tick (replay) and opens its agent.
  const health = {
    format(kind, v) {
      if (v === null || v === undefined) return '–';
      if (kind === 'share') return (v * 100).toFixed(1) + '%';
      if (kind === 'ratio') return v.toFixed(1) + '×';
      if (kind === 'rate') return v.toFixed(2);
      return String(Math.round(v));
    },
    build(h) {
      const box = $('health-box');
      box.classList.remove('hidden');
      const body = $('health');
      body.textContent = '';
      if (!h) {
        body.append(el('div', { class: 'muted', 'data-testid': 'health-none' }, 'no health report for this run'));
        return;
      }
      const n = h.warnings.length;
      // Live figures restart with each version swapped in.
      const since = h.since_tick ? ' (since tick ' + h.since_tick + ')' : '';
      $('health-title').textContent = 'Run health' + since + (n ? ' · ' + n + (n === 1 ? ' warning' : ' warnings') : '');
      const wrap = el('div', { class: 'health-table' });
      const table = el('table', { 'data-testid': 'health-table' });
      const head = el('tr');
      head.append(el('th', null, ''), el('th', { class: 'bound', title: 'bound' }, 'bound'));
      for (const sp of h.species) {
        const th = el('th', { title: sp.name + ' (' + sp.agents + ' agents)' });
        const info = state.species.find((x) => x.name === sp.name);
        if (info) th.style.borderBottomColor = cssColor(info.rgb);
        // Long names may wrap after an underscore.
        sp.name.split('_').forEach((part, k, all) => {
          th.append(document.createTextNode(part + (k < all.length - 1 ? '_' : '')));
          if (k < all.length - 1) th.append(el('wbr'));
        });
        head.append(th);
      }
      table.append(head);
      h.columns.forEach((c, k) => {
        const tr = el('tr');
        tr.append(el('th', { class: 'fig' }, c.label),
          el('td', { class: 'bound' }, c.bound === null ? '' : '≤' + this.format(c.kind, c.bound)));
        for (const sp of h.species) {
          const over = sp.over[k];
          const td = el('td', over ? { class: 'over', title: c.label + ' past its bound' } : null,
            this.format(c.kind, sp.values[k]) + (over ? '!' : ''));
          tr.append(td);
        }
        table.append(tr);
      });
      wrap.append(table);
      body.append(wrap);
      const list = el('ol', { id: 'health-warnings', 'data-testid': 'health-warnings' });
      for (const w of h.warnings) {
        const li = el('li', { 'data-testid': 'health-warning' });
        if (w.tick !== null) li.dataset.tick = String(w.tick);
        if (w.agent !== null) li.dataset.agent = String(w.agent);
        li.append(el('span', null, w.message));
        const where = [];
        if (w.tick !== null) where.push('t' + w.tick);
        if (w.agent !== null) where.push('#' + w.agent);
        if (where.length) {
          li.append(el('span', { class: 'muted where' }, ' ' + where.join(' · ')));
          li.classList.add('jump');
          li.title = 'show ' + (w.agent !== null ? 'agent ' + w.agent + ' ' : '') + (w.tick !== null ? 'at tick ' + w.tick : '');
          li.addEventListener('click', () => this.jump(w));
        }
        list.append(li);
      }
      if (!n) list.append(el('li', { class: 'muted' }, 'no warnings: every figure within its bound'));
      body.append(list);
    },
    jump(w) {
      // Live, the past is gone: the agent is opened where it is now.
      if (!LIVE) {
        source.setPlaying(false);
        if (w.tick !== null) source.setFrame(source.frameOfTick(w.tick));
      }
      if (w.agent !== null) select(w.agent);
      state.dirty = true;
    },
  };

  // ---------------------------------------------------------------- replay source

  function decodeColumn(node) {
    const bin = atob(node.textContent);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    node.textContent = '';
    switch (node.dataset.kind) {
      case 'f32': return new Float32Array(bytes.buffer);
      case 'u32': return new Uint32Array(bytes.buffer);
      case 'u16': return new Uint16Array(bytes.buffer);
      default: return bytes;
    }
  }

  function replaySource() {
    const meta = JSON.parse($('shoal-meta').textContent);
    const cols = {};
    for (const node of document.querySelectorAll('script.shoal-col')) cols[node.dataset.name] = decodeColumn(node);
    const fr = meta.frames;
    const strings = meta.history.strings;
    const unorm = { hunger: true, libido: true, fear: true, swim_phase: true };
    let index = 0, playing = false, speed = 1, clockTime = 0;

    function makeFrame(i) {
      const a = fr.offset[i], b = fr.offset[i + 1], fa = fr.food_offset[i], fb = fr.food_offset[i + 1];
      const sub = (name, k) => cols[name].subarray(a * k, b * k);
      return {
        index: i, tick: fr.tick[i], time: fr.time[i], n: b - a,
        ids: sub('id', 1), species: sub('species', 1), behavior: sub('behavior', 1),
        pos: sub('pos', 3), fwd: sub('fwd', 3), speed: sub('speed', 1), stack_depth: sub('stack_depth', 1),
        hunger: sub('hunger', 1), libido: sub('libido', 1), fear: sub('fear', 1),
        swim_phase: sub('swim_phase', 1), tail_bend: sub('tail_bend', 1),
        food: cols.food.subarray(fa * 3, fb * 3), unorm,
      };
    }

    // Index range of agent `id` in the (agent, tick)-sorted history columns.
    function historyRange(id) {
      const ag = cols.h_agent;
      let lo = 0, hi = ag.length;
      while (lo < hi) { const m = (lo + hi) >> 1; if (ag[m] < id) lo = m + 1; else hi = m; }
      let end = lo;
      while (end < ag.length && ag[end] === id) end++;
      return [lo, end];
    }

    const src = {
      meta,
      start() {
        const r = meta.run;
        $('run-info').textContent = (r.scenario || 'run') + ' · seed ' + r.seed + ' · dt ' + r.dt + ' s · '
          + r.ticks + ' ticks · recorded every ' + r.record_interval + ' · ' + fr.count + ' frames';
        $('banner').classList.toggle('hidden', !meta.incomplete);
        if (meta.notes.length) { $('notes').textContent = meta.notes.join(' · '); $('notes').classList.remove('hidden'); }
        const evs = [];
        for (const e of meta.script_errors) evs.push([e.tick, 'script error: ' + e.text]);
        for (const e of meta.reloads) evs.push([e.tick, 'reload: ' + e.text]);
        evs.sort((x, y) => x[0] - y[0]);
        if (evs.length) {
          $('events-box').classList.remove('hidden');
          $('events-summary').textContent = 'Events (' + Object.entries(meta.event_counts).map(([k, v]) => k + ' ' + v).join(', ') + ')';
          for (const [t, text] of evs) $('events').append(el('li', null, 't' + t + ' ' + text));
        }
        setTables(meta.species, meta.behaviors);
        setWorld(meta.world);
        health.build(meta.health);
        const scrub = $('scrub');
        scrub.max = String(Math.max(0, fr.count - 1));
        src.setFrame(0);
      },
      setFrame(i) {
        if (!fr.count) return 0;
        index = Math.max(0, Math.min(fr.count - 1, i | 0));
        clockTime = fr.time[index];
        applyFrame(makeFrame(index));
        return index;
      },
      frameIndex() { return index; },
      // Index of the recorded frame nearest to `tick` (the earlier one on a tie).
      frameOfTick(tick) {
        const t = fr.tick;
        let lo = 0, hi = fr.count;
        while (lo < hi) { const m = (lo + hi) >> 1; if (t[m] < tick) lo = m + 1; else hi = m; }
        if (lo >= fr.count) return Math.max(0, fr.count - 1);
        return lo > 0 && tick - t[lo - 1] <= t[lo] - tick ? lo - 1 : lo;
      },
      onFrameShown(f) {
        $('scrub').value = String(f.index);
        $('clock').textContent = 'tick ' + f.tick + ' · t = ' + f.time.toFixed(2) + ' s · frame ' + (f.index + 1) + '/' + fr.count;
      },
      setPlaying(p) {
        if (p && index >= fr.count - 1) src.setFrame(0);
        playing = p;
        $('play').textContent = p ? '❚❚' : '▶';
      },
      playing() { return playing; },
      setSpeed(v) { speed = v; },
      step(k) { src.setPlaying(false); src.setFrame(index + k); },
      // Advances playback by `dt` seconds of wall time.
      advance(dt) {
        if (!playing || fr.count < 2) return;
        clockTime += dt * speed;
        let j = index;
        while (j + 1 < fr.count && fr.time[j + 1] <= clockTime) j++;
        if (j !== index) src.setFrame(j);
        clockTime = Math.max(clockTime, fr.time[index]);
        if (index >= fr.count - 1) src.setPlaying(false);
      },
      decisions(id, tick) {
        const [a, b] = historyRange(id);
        const out = [];
        for (let k = a; k < b && cols.h_tick[k] <= tick; k++) {
          out.push({
            tick: cols.h_tick[k], from: strings[cols.h_from[k]], to: strings[cols.h_to[k]],
            cause: strings[cols.h_cause[k]], condition: strings[cols.h_cond[k]], stack: strings[cols.h_stack[k]],
          });
        }
        return out;
      },
      agentStatus(id, present) {
        const d = meta.deaths[String(id)];
        const tick = state.frame ? state.frame.tick : 0;
        if (d && tick >= d[0]) return 'died at tick ' + d[0] + (d[1] ? ' (' + d[1] + ')' : '');
        return present ? '' : 'not present at tick ' + tick;
      },
      inspect() { return Promise.resolve(null); },
      control() {},
    };
    return src;
  }

  // ---------------------------------------------------------------- live source

  function liveSource() {
    let frames = 0, playing = true, lastTick = null;
    // behaviorMap[s][j] = global index of world.species[s].behaviors[j]
    let behaviorMap = [];

    function tablesFromWorld(world) {
      const names = [], index = new Map();
      behaviorMap = (world.species || []).map((s) => (s.behaviors || []).map((b) => {
        if (!index.has(b)) { index.set(b, names.length); names.push(b); }
        return index.get(b);
      }));
      names.push('?');
      setTables(world.species || [], names);
    }

    function toFrame(j) {
      const n = j.ids.length;
      const beh = new Uint16Array(n), unknown = state.behaviors.length - 1;
      for (let i = 0; i < n; i++) {
        const m = behaviorMap[j.species[i]];
        const g = m ? m[j.behavior[i]] : undefined;
        beh[i] = g === undefined ? unknown : g;
      }
      const f32 = (a, k) => (a && a.length === n * k ? Float32Array.from(a) : new Float32Array(n * k));
      return {
        index: frames, tick: j.tick, time: j.time, n,
        ids: Uint32Array.from(j.ids), species: Uint8Array.from(j.species), behavior: beh,
        pos: f32(j.pos, 3), fwd: f32(j.fwd, 3), speed: f32(j.speed, 1), stack_depth: f32(j.stack_depth, 1),
        hunger: f32(j.hunger, 1), libido: f32(j.libido, 1), fear: f32(j.fear, 1),
        swim_phase: j.swim_phase ? f32(j.swim_phase, 1) : null, tail_bend: j.tail_bend ? f32(j.tail_bend, 1) : null,
        food: j.food ? Float32Array.from(j.food) : new Float32Array(0),
      };
    }

    const status = (text) => { $('live-status').textContent = text; };
    const post = (body) => fetch('/control', { method: 'POST', body: JSON.stringify(body) }).catch(() => {});

    const src = {
      start() {
        $('run-info').textContent = 'live';
        $('scrub').classList.add('hidden');
        $('step').classList.remove('hidden');
        $('play').textContent = '❚❚';
        $('histogram-title').textContent = 'Behaviors over time';
        const es = new EventSource('/stream');
        es.onopen = () => status('connected');
        es.onerror = () => status('disconnected, retrying…');
        es.addEventListener('world', (e) => {
          const world = JSON.parse(e.data);
          tablesFromWorld(world);
          setWorld(world);
          if (state.frame) applyFrame(state.frame);
        });
        es.addEventListener('frame', (e) => {
          if (!state.world) return;
          const f = toFrame(JSON.parse(e.data));
          frames++;
          lastTick = f.tick;
          applyFrame(f);
          markReady();
        });
        es.addEventListener('diagnostics', (e) => {
          const lines = JSON.parse(e.data);
          const box = $('diagnostics');
          box.textContent = Array.isArray(lines) ? lines.join('\n') : String(lines);
          box.classList.toggle('hidden', !(Array.isArray(lines) && lines.length));
        });
        es.addEventListener('health', (e) => {
          try { health.build(JSON.parse(e.data)); } catch (_) { /* a bad message leaves the last figures */ }
        });
        es.addEventListener('reload', (e) => {
          let msg = 'reloaded';
          try { msg = JSON.parse(e.data).message || msg; } catch (_) { /* keep default */ }
          toast(msg);
        });
      },
      setFrame() { return frames - 1; },
      frameIndex() { return frames - 1; },
      onFrameShown(f) {
        $('clock').textContent = 'tick ' + f.tick + ' · t = ' + Number(f.time).toFixed(2) + ' s · ' + f.n + ' agents';
        status('live · tick ' + lastTick);
      },
      setPlaying(p) { playing = p; $('play').textContent = p ? '❚❚' : '▶'; post({ cmd: p ? 'resume' : 'pause' }); },
      playing() { return playing; },
      setSpeed(v) { post({ cmd: 'speed', value: v }); },
      step() { src.setPlaying(false); post({ cmd: 'step' }); },
      advance() {},
      decisions() { return []; },
      agentStatus(id, present) { return present ? '' : 'not in the latest frame'; },
      inspect(id) {
        return fetch('/agent/' + id).then((r) => (r.ok ? r.json() : null)).catch(() => null);
      },
    };
    return src;
  }

  let toastTimer = null;
  function toast(text) {
    const t = $('toast');
    t.textContent = text;
    t.classList.remove('hidden');
    clearTimeout(toastTimer);
    toastTimer = setTimeout(() => t.classList.add('hidden'), 2500);
  }

  // ---------------------------------------------------------------- input and loop

  let source = null;

  function bindInput() {
    let drag = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, sx: e.clientX, sy: e.clientY, pan: e.button === 2 || e.shiftKey, moved: false, button: e.button };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (Math.abs(e.clientX - drag.sx) + Math.abs(e.clientY - drag.sy) > 4) drag.moved = true;
      if (!drag.moved) return;
      if (drag.pan) { camera.pan(dx, dy, canvas.clientHeight); state.follow = false; } else camera.orbit(dx, dy);
      state.dirty = true;
    });
    canvas.addEventListener('pointerup', (e) => {
      if (drag && !drag.moved && drag.button === 0) {
        const id = pickAt(e.clientX, e.clientY);
        if (id !== null) select(id);
      }
      drag = null;
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      camera.zoom(Math.exp(e.deltaY * 0.0015));
      state.dirty = true;
    }, { passive: false });
    $('scrub').addEventListener('input', (e) => { source.setPlaying(false); source.setFrame(Number(e.target.value)); });
    $('play').addEventListener('click', () => source.setPlaying(!source.playing()));
    $('step').addEventListener('click', () => source.step(1));
    $('speed').addEventListener('change', (e) => source.setSpeed(Number(e.target.value)));
    $('color-mode').addEventListener('change', (e) => {
      state.colorMode = e.target.value;
      legend.build();
      fillInstances();
      state.dirty = true;
    });
    $('panel-close').addEventListener('click', () => panel.close());
    window.addEventListener('keydown', (e) => {
      if (e.target && (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT') && e.key !== 'Escape') return;
      if (e.key === 'Escape') panel.close();
      else if (e.key === ' ') { e.preventDefault(); source.setPlaying(!source.playing()); } else if (e.key === 'ArrowRight') source.step(1);
      else if (e.key === 'ArrowLeft' && !LIVE) source.step(-1);
      else if (e.key === 'c') { const m = $('color-mode'); m.value = m.value === 'species' ? 'behavior' : 'species'; m.dispatchEvent(new Event('change')); }
    });
    window.addEventListener('resize', () => { state.dirty = true; });
  }

  let last = performance.now();
  function loop(now) {
    const dt = Math.min(0.25, (now - last) / 1000);
    last = now;
    source.advance(dt);
    followSelected();
    if (state.dirty) { state.dirty = false; render(); }
    requestAnimationFrame(loop);
  }

  // ---------------------------------------------------------------- test hook

  const hook = {
    ready: false,
    error: null,
    frameIndex: () => source.frameIndex(),
    setFrame: (i) => { const k = source.setFrame(i); render(); state.dirty = false; return k; },
    agentCount: () => (state.frame ? state.frame.n : 0),
    selectAgentAt: (x, y) => { const id = pickAt(x, y); if (id !== null) select(id); return id; },
    selected: () => state.selected,
    screenPosOf: (id) => {
      const i = indexOfId(state.frame, id);
      if (i < 0) return null;
      resize();
      return screenPosOfRow(i, computeViewProj(), canvas.getBoundingClientRect());
    },
    ids: () => (state.frame ? Array.from(state.frame.ids) : []),
    speciesCount: () => (state.world && state.world.species ? state.world.species.length : 0),
    stats: () => ({ renders: state.renders, frames: state.applied }),
    play: (speed) => { if (speed) source.setSpeed(speed); source.setPlaying(true); },
  };
  window.shoal = hook;

  function markReady() {
    if (hook.ready) return;
    render();
    state.dirty = false;
    $('loading').classList.add('hidden');
    hook.ready = true;
  }

  function fail(err) {
    hook.error = String(err && err.message ? err.message : err);
    const box = $('diagnostics');
    box.textContent = 'viewer error: ' + hook.error;
    box.classList.remove('hidden');
    $('loading').classList.add('hidden');
  }

  function boot() {
    try {
      renderer.init(canvas);
      source = LIVE ? liveSource() : replaySource();
      bindInput();
      source.start();
      if (!LIVE) markReady();
      requestAnimationFrame(loop);
    } catch (err) {
      fail(err);
    }
  }

  // Let the page paint its frame (and "loading…") before decoding a large payload.
  setTimeout(boot, 0);
})();
