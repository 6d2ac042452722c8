// shoal viewer, render.js: The WebGL renderer: instanced body meshes, seabed or terrain, solid
// obstacles, fog, food, bounds.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- renderer

  // Far agents (and all of them without instancing) are point sprites, one vertex each: the
  // vertex shader projects the body axis to find the on-screen heading and foreshortening; the
  // fragment shader cuts the silhouette of the shape family out of the square. Software GL draws
  // these far faster than instanced meshes (its instancing costs much per instance), so only
  // agents near the eye get a mesh (`drawAgents`). With 10,000 agents most of a frame is spent
  // filling these squares, so each shape family has its own program (no branch on the shape per
  // pixel) and everything constant over a sprite (its axes, its tail's bend, its width) is worked
  // out once per vertex.
  const SPRITE_SHAPES = { fish: 0, custom: 0, shark: 1, jelly: 2, walker: 3 };
  const spriteVs = (shape) => `
#define SHAPE ${shape}
attribute vec3 iPos; attribute vec3 iFwd; attribute vec3 iColor; attribute float iLen; attribute float iBend;
uniform mat4 uViewProj; uniform vec2 uViewport; uniform float uProjF; uniform float uMinPx; uniform float uMaxPx;
varying vec3 vColor; varying vec2 vU; varying vec2 vV; varying float vBend; varying float vInvW2;
vec2 toPx(vec4 c) { return c.xy / max(c.w, 1e-4) * 0.5 * uViewport; }
void main() {
#if SHAPE == 3
  // A walker stands on its position: the sprite is centered half its height up.
  vec3 center = iPos + vec3(0.0, 0.5 * iLen, 0.0);
#else
  vec3 center = iPos;
#endif
  vec4 c = uViewProj * vec4(center, 1.0);
  gl_Position = c;
  vec3 f = iFwd; float fl = length(f);
  f = fl > 1e-6 ? f / fl : vec3(1.0, 0.0, 0.0);
  vec2 d = toPx(uViewProj * vec4(center + f * (0.5 * iLen), 1.0)) - toPx(uViewProj * vec4(center - f * (0.5 * iLen), 1.0));
  float onScreen = length(d);
  // side-on length in pixels at this depth
  float full = iLen * uProjF * 0.5 * uViewport.y / max(c.w, 1e-4);
  gl_PointSize = clamp(full, uMinPx, uMaxPx);
  vec2 dir = onScreen > 1e-3 ? d / onScreen : vec2(1.0, 0.0);
  float aspect = clamp(onScreen / max(full, 1e-3), 0.3, 1.0);
  // The sprite's axes in point coordinates (y down): u along the body, nose at +0.5, shortened
  // by the foreshortening; v to the body's left on screen.
  vU = vec2(dir.x, -dir.y) / aspect;
  vV = vec2(-dir.y, -dir.x);
  float w = mix(0.2, 0.13, aspect) * (SHAPE == 1 ? 0.7 : 1.0);
  vInvW2 = 1.0 / (w * w);
  vBend = sin(iBend);
  vColor = iColor;
}`;
  const spriteFs = (shape) => `
#define SHAPE ${shape}
precision mediump float;
varying vec3 vColor; varying vec2 vU; varying vec2 vV; varying float vBend; varying float vInvW2;
void main() {
  vec2 p = gl_PointCoord - 0.5;
  float shade;
#if SHAPE == 3
  // walker: upright on screen, head, body, legs
  p.y = -p.y;
  float head = length(p - vec2(0.0, 0.38)) / 0.09;
  if (head <= 1.0) shade = 1.0 - 0.2 * head;
  else if (abs(p.x) < 0.13 && p.y > -0.05 && p.y < 0.3) shade = 0.9;
  else if (abs(abs(p.x) - 0.06) < 0.04 && p.y >= -0.5 && p.y <= -0.05) shade = 0.7;
  else discard;
#else
  float u = dot(p, vU);
  float v = dot(p, vV);
#if SHAPE == 2
  // jelly: a round bell leading, tentacles trailing
  float e = length(vec2(u - 0.2, v)) / 0.28;
  if (e <= 1.0) shade = e > 0.75 ? 0.65 : 1.0 - 0.25 * e;
  else if (u < 0.0 && u > -0.5 && abs(fract((v + 0.2) * 10.0) - 0.5) < 0.18 && abs(v) < 0.18) shade = 0.6;
  else discard;
#else
  // fish and shark: an ellipse body and a tail bent by the swim phase
  float du = u - 0.08;
  float e = du * du * 6.925 + v * v * vInvW2;
  if (e <= 1.0) {
    shade = e > 0.72 ? 0.6 : 1.0 - 0.3 * e;
  } else {
    float back = -0.2 - u;
    if (back < 0.0 || u < -0.5 || abs(v + vBend * back) > 0.02 + back * ${shape === 1 ? '0.7' : '0.5'}) discard;
    shade = 0.75;
  }
#endif
#endif
  gl_FragColor = vec4(vColor * shade, 1.0);
}`;
  // Instanced body meshes: one draw call per species, the mesh turned to the heading and scaled
  // to the look's length, never smaller than `uMinPx` on screen. Lit by a sun from above plus
  // ambient light, fogged with distance like the rest of the scene.
  const BODY_VS = `
attribute vec3 aPos; attribute vec3 aNormal; attribute float aFlex;
attribute vec3 iPos; attribute vec3 iFwd; attribute vec3 iColor; attribute float iLen; attribute float iBend;
uniform mat4 uViewProj; uniform float uPxPerUnit; uniform float uMinPx; uniform float uUpright; uniform vec3 uEye;
varying vec3 vColor; varying vec3 vNormal; varying float vDist;
void main() {
  vec3 f = iFwd;
  if (uUpright > 0.5) f.y = 0.0;
  float fl = length(f);
  f = fl > 1e-6 ? f / fl : vec3(0.0, 0.0, 1.0);
  vec3 up0 = abs(f.y) > 0.98 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 r = normalize(cross(up0, f));
  vec3 u = cross(f, r);
  float w = (uViewProj * vec4(iPos, 1.0)).w;
  float size = max(iLen, uMinPx * max(w, 1e-3) / uPxPerUnit);
  vec3 p = aPos;
  p.x += sin(iBend) * aFlex * 0.35;
  vec3 world = iPos + (r * p.x + u * p.y + f * p.z) * size;
  gl_Position = uViewProj * vec4(world, 1.0);
  vNormal = r * aNormal.x + u * aNormal.y + f * aNormal.z;
  vColor = iColor;
  vDist = distance(world, uEye);
}`;
  const LIT = `
uniform vec3 uFogColor; uniform vec2 uFog; uniform float uAlpha;
vec3 lit(vec3 c, vec3 n) {
  // The sun above the default eye's shoulder, so faces turned to the viewer are lit.
  float d = dot(normalize(n), normalize(vec3(0.45, 1.0, 0.55)));
  return c * (0.5 + 0.55 * max(d, 0.0) + 0.1 * max(-d, 0.0));
}
vec4 fogged(vec3 c, float dist) {
  float k = clamp((dist - uFog.x) / max(uFog.y - uFog.x, 1e-3), 0.0, 1.0);
  return vec4(mix(c, uFogColor, k), uAlpha);
}`;
  const BODY_FS = `
precision mediump float; varying vec3 vColor; varying vec3 vNormal; varying float vDist;` + LIT + `
void main() { gl_FragColor = fogged(lit(vColor, vNormal), vDist); }`;
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
attribute vec3 aPos; attribute vec3 aNormal; attribute vec3 aColor; uniform mat4 uViewProj; uniform vec3 uEye;
varying vec3 vColor; varying vec3 vNormal; varying float vDist;
void main() { gl_Position = uViewProj * vec4(aPos, 1.0); vColor = aColor; vNormal = aNormal; vDist = distance(aPos, uEye); }`;
  const MESH_FS = `
precision mediump float; varying vec3 vColor; varying vec3 vNormal; varying float vDist;` + LIT + `
void main() { gl_FragColor = fogged(lit(vColor, vNormal), vDist); }`;
  // The seabed: a wide plane under the world, sand with ripples and a faint 10 m grid for scale.
  // The plane is cut into many cells so that the distance to the eye (fog, and the fading of the
  // ripples) can be taken per vertex rather than per pixel, which software GL pays for on most of
  // the screen every frame.
  const GROUND_VS = `
attribute vec3 aPos; uniform mat4 uViewProj; uniform vec3 uEye; uniform vec2 uFog;
varying vec2 vXZ; varying float vNear; varying float vFogK;
void main() {
  gl_Position = uViewProj * vec4(aPos, 1.0);
  vXZ = aPos.xz;
  float dist = distance(aPos, uEye);
  vNear = 1.0 - clamp(dist / uFog.y, 0.0, 1.0);
  vFogK = clamp((dist - uFog.x) / max(uFog.y - uFog.x, 1e-3), 0.0, 1.0);
}`;
  const GROUND_FS = `
precision highp float; varying vec2 vXZ; varying float vNear; varying float vFogK;
uniform float uGrid; uniform vec3 uFogColor; uniform float uAlpha;
void main() {
  vec2 q = vXZ;
  // Ripples and grid fade out with distance, where they would only shimmer.
  float ripple = sin(q.x * 0.6 + 2.0 * sin(q.y * 0.25)) * sin(q.y * 0.45 + 1.5 * sin(q.x * 0.15));
  vec3 c = vec3(0.38, 0.36, 0.29) * (0.95 + 0.05 * ripple * vNear);
  vec2 g = abs(fract(q / uGrid + 0.5) - 0.5) * uGrid;
  float line = 1.0 - smoothstep(0.0, uGrid * 0.012, min(g.x, g.y));
  c = mix(c, vec3(0.30, 0.36, 0.34), line * 0.6 * vNear);
  // lit()'s factor for an upward normal: 0.5 + 0.55 * dot(up, sun) = 0.9483.
  c *= 0.9483;
  gl_FragColor = vec4(mix(c, uFogColor, vFogK), uAlpha);
}`;

  // The page's deep-water background (#0b1a2a): what the fog fades to.
  const FOG_COLOR = [0.043, 0.102, 0.165];
  const ROCK_COLOR = [0.50, 0.64, 0.60];
  const ROCK_ALPHA = 0.86;

  const AGENT_FLOATS = 11; // pos 3, fwd 3, color 3, length 1, bend 1
  // On-screen lengths (CSS px): every body is drawn at least MIN_PX long; from MESH_PX on, as a mesh.
  const MIN_PX = 12, MESH_PX = 30;

  const renderer = {
    gl: null, ok: false, progs: {}, maxPointPx: 64, inst: null,
    agentCount: 0, agentData: null, agentBuf: null, meshBuf: null, meshRows: null, spriteRows: null,
    groups: [], bodies: new Map(),
    staticLines: null, staticPoints: null, foodPoints: null, selLines: null, terrain: null,
    solids: null, ground: null, fog: [0, 1], grid: 10,
    init(canvas) {
      const opts = { antialias: false, alpha: false, preserveDrawingBuffer: false };
      let gl = canvas.getContext('webgl2', opts);
      const gl2 = !!gl;
      if (!gl) gl = canvas.getContext('webgl', opts) || canvas.getContext('experimental-webgl', opts);
      if (!gl) throw new Error('WebGL is not available in this browser');
      this.gl = gl;
      this.uintIndices = gl2 || !!gl.getExtension('OES_element_index_uint');
      // Instanced drawing: WebGL2, or WebGL1's ANGLE_instanced_arrays; without it, point sprites.
      if (gl2) {
        this.inst = { divisor: (l, d) => gl.vertexAttribDivisor(l, d), draw: (m, n, t, o, k) => gl.drawElementsInstanced(m, n, t, o, k) };
      } else {
        const ext = gl.getExtension('ANGLE_instanced_arrays');
        if (ext) this.inst = { divisor: (l, d) => ext.vertexAttribDivisorANGLE(l, d), draw: (m, n, t, o, k) => ext.drawElementsInstancedANGLE(m, n, t, o, k) };
      }
      this.maxPointPx = Math.min(512, gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE)[1] || 64);
      this.progs.sprite = [0, 1, 2, 3].map((k) => this.program(spriteVs(k), spriteFs(k)));
      if (this.inst) this.progs.body = this.program(BODY_VS, BODY_FS);
      this.progs.line = this.program(LINE_VS, COLOR_FS);
      this.progs.point = this.program(LINE_VS, POINT_FS);
      this.progs.mesh = this.program(MESH_VS, MESH_FS);
      this.progs.ground = this.program(GROUND_VS, GROUND_FS);
      this.agentBuf = gl.createBuffer();
      this.meshBuf = gl.createBuffer();
      this.staticLines = this.vertexSet();
      this.staticPoints = this.vertexSet();
      this.foodPoints = this.vertexSet();
      this.selLines = this.vertexSet();
      this.solids = { buf: gl.createBuffer(), count: 0 };
      gl.enable(gl.DEPTH_TEST);
      gl.clearColor(FOG_COLOR[0], FOG_COLOR[1], FOG_COLOR[2], 1);
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
    // Solid obstacles: triangles of position, normal, color (9 floats a vertex).
    setSolids(data) {
      const gl = this.gl;
      gl.bindBuffer(gl.ARRAY_BUFFER, this.solids.buf);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      this.solids.count = data.length / 9;
    },
    // The seabed plane at height `y`, reaching `reach` around (cx, cz); null for none.
    setGround(y, cx, cz, reach, grid) {
      const gl = this.gl;
      if (y === null) { this.ground = null; return; }
      // CELLS × CELLS squares, two triangles each.
      const CELLS = 48, step = (2 * reach) / CELLS, v = [];
      for (let i = 0; i < CELLS; i++) {
        for (let j = 0; j < CELLS; j++) {
          const x0 = cx - reach + i * step, z0 = cz - reach + j * step, x1 = x0 + step, z1 = z0 + step;
          v.push(x0, y, z0, x1, y, z0, x1, y, z1, x0, y, z0, x1, y, z1, x0, y, z1);
        }
      }
      const buf = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(v), gl.STATIC_DRAW);
      this.ground = { buf, count: v.length / 3 };
      this.grid = grid;
    },
    // The GL buffers of the body mesh of a look, made once per shape.
    body(look) {
      const bm = bodyMesh(look);
      if (!this.bodies.has(bm.key)) {
        const gl = this.gl, vbuf = gl.createBuffer(), ibuf = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, vbuf);
        gl.bufferData(gl.ARRAY_BUFFER, bm.mesh.v, gl.STATIC_DRAW);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibuf);
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, bm.mesh.i, gl.STATIC_DRAW);
        this.bodies.set(bm.key, { vbuf, ibuf, count: bm.mesh.i.length, upright: bm.upright });
      }
      return this.bodies.get(bm.key);
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
          // low meadow green → dry grass → pale rock, tinted red where blocked
          let col = k < 0.5
            ? [0.22 + 0.3 * k, 0.38 + 0.2 * k, 0.20 + 0.05 * k]
            : [0.37 + 0.5 * (k - 0.5), 0.48 + 0.3 * (k - 0.5), 0.26 + 0.5 * (k - 0.5)];
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
    // `groups`: [{look, start, count}] ranges of `data` rows drawn with one look each.
    // (Uploaded at draw time, split by distance from the eye.)
    setAgents(data, count, groups) {
      this.agentData = data;
      this.agentCount = count;
      this.groups = groups || [{ look: null, start: 0, count }];
    },
    attrib(prog, name, size, stride, offset, divisor) {
      const gl = this.gl, loc = prog.a[name];
      if (loc === undefined || loc < 0) return;
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, size, gl.FLOAT, false, stride * 4, offset * 4);
      if (divisor) { this.inst.divisor(loc, 1); this.divided.push(loc); }
      this.usedAttribs.push(loc);
    },
    releaseAttribs() {
      for (const loc of this.divided) this.inst.divisor(loc, 0);
      for (const loc of this.usedAttribs) this.gl.disableVertexAttribArray(loc);
      this.usedAttribs = [];
      this.divided = [];
    },
    usedAttribs: [],
    divided: [],
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
    // Uniforms every lit program shares: eye, fog, opacity.
    litUniforms(p, vp, alpha) {
      const gl = this.gl;
      gl.useProgram(p.p);
      gl.uniformMatrix4fv(p.u.uViewProj, false, vp);
      if (p.u.uEye) gl.uniform3fv(p.u.uEye, vp.eye);
      if (p.u.uFogColor) gl.uniform3fv(p.u.uFogColor, FOG_COLOR);
      const fog = vp.fog || this.fog;
      if (p.u.uFog) gl.uniform2f(p.u.uFog, fog[0], fog[1]);
      if (p.u.uAlpha) gl.uniform1f(p.u.uAlpha, alpha);
    },
    // Splits the agents by on-screen length: meshes for those at least `MESH_PX` long (and in
    // front of the eye), sprites for the rest; each kept grouped by species.
    splitByDistance(vp, heightPx, dpr) {
      const d = this.agentData, k = vp.projF * 0.5 * heightPx, lod = MESH_PX * dpr;
      const need = this.agentCount * AGENT_FLOATS;
      if (!this.meshRows || this.meshRows.length < need) {
        this.meshRows = new Float32Array(need + AGENT_FLOATS);
        this.spriteRows = new Float32Array(need + AGENT_FLOATS);
      }
      const mesh = [], sprite = [];
      let nm = 0, ns = 0;
      for (const g of this.groups) {
        const m0 = nm, s0 = ns;
        for (let r = g.start; r < g.start + g.count; r++) {
          const o = r * AGENT_FLOATS;
          const w = vp[3] * d[o] + vp[7] * d[o + 1] + vp[11] * d[o + 2] + vp[15];
          let out, at;
          if (this.inst && w > 0 && (d[o + 9] * k) / w >= lod) { out = this.meshRows; at = nm++ * AGENT_FLOATS; } else { out = this.spriteRows; at = ns++ * AGENT_FLOATS; }
          for (let j = 0; j < AGENT_FLOATS; j++) out[at + j] = d[o + j];
        }
        mesh.push({ look: g.look, start: m0, count: nm - m0 });
        sprite.push({ look: g.look, start: s0, count: ns - s0 });
      }
      return { mesh, sprite, nm, ns };
    },
    drawAgents(vp, widthPx, heightPx, dpr) {
      const gl = this.gl;
      const split = this.splitByDistance(vp, heightPx, dpr);
      if (split.ns) {
        gl.bindBuffer(gl.ARRAY_BUFFER, this.agentBuf);
        gl.bufferData(gl.ARRAY_BUFFER, this.spriteRows.subarray(0, split.ns * AGENT_FLOATS), gl.STREAM_DRAW);
        for (const g of split.sprite) {
          if (!g.count) continue;
          const p = this.progs.sprite[SPRITE_SHAPES[g.look ? g.look.shape : 'fish'] || 0];
          gl.useProgram(p.p);
          gl.uniformMatrix4fv(p.u.uViewProj, false, vp);
          gl.uniform2f(p.u.uViewport, widthPx, heightPx);
          gl.uniform1f(p.u.uProjF, vp.projF);
          gl.uniform1f(p.u.uMinPx, MIN_PX * dpr);
          gl.uniform1f(p.u.uMaxPx, this.maxPointPx);
          const o = g.start * AGENT_FLOATS;
          this.attrib(p, 'iPos', 3, AGENT_FLOATS, o);
          this.attrib(p, 'iFwd', 3, AGENT_FLOATS, o + 3);
          this.attrib(p, 'iColor', 3, AGENT_FLOATS, o + 6);
          this.attrib(p, 'iLen', 1, AGENT_FLOATS, o + 9);
          this.attrib(p, 'iBend', 1, AGENT_FLOATS, o + 10);
          gl.drawArrays(gl.POINTS, 0, g.count);
          this.releaseAttribs();
        }
      }
      if (!split.nm) return;
      const p = this.progs.body;
      this.litUniforms(p, vp, 1);
      gl.uniform1f(p.u.uPxPerUnit, vp.projF * 0.5 * heightPx);
      gl.uniform1f(p.u.uMinPx, MIN_PX * dpr);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.meshBuf);
      gl.bufferData(gl.ARRAY_BUFFER, this.meshRows.subarray(0, split.nm * AGENT_FLOATS), gl.STREAM_DRAW);
      for (const g of split.mesh) {
        if (!g.count) continue;
        const body = this.body(g.look);
        gl.uniform1f(p.u.uUpright, body.upright ? 1 : 0);
        gl.bindBuffer(gl.ARRAY_BUFFER, body.vbuf);
        this.attrib(p, 'aPos', 3, BODY_FLOATS, 0);
        this.attrib(p, 'aNormal', 3, BODY_FLOATS, 3);
        this.attrib(p, 'aFlex', 1, BODY_FLOATS, 6);
        gl.bindBuffer(gl.ARRAY_BUFFER, this.meshBuf);
        const o = g.start * AGENT_FLOATS;
        this.attrib(p, 'iPos', 3, AGENT_FLOATS, o, 1);
        this.attrib(p, 'iFwd', 3, AGENT_FLOATS, o + 3, 1);
        this.attrib(p, 'iColor', 3, AGENT_FLOATS, o + 6, 1);
        this.attrib(p, 'iLen', 1, AGENT_FLOATS, o + 9, 1);
        this.attrib(p, 'iBend', 1, AGENT_FLOATS, o + 10, 1);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, body.ibuf);
        this.inst.draw(gl.TRIANGLES, body.count, gl.UNSIGNED_SHORT, 0, g.count);
        this.releaseAttribs();
      }
    },
    draw(vp, widthPx, heightPx, dpr) {
      const gl = this.gl;
      gl.viewport(0, 0, widthPx, heightPx);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      if (this.ground && !this.terrain) {
        const p = this.progs.ground;
        this.litUniforms(p, vp, 1);
        gl.uniform1f(p.u.uGrid, this.grid);
        gl.bindBuffer(gl.ARRAY_BUFFER, this.ground.buf);
        this.attrib(p, 'aPos', 3, 3, 0);
        gl.drawArrays(gl.TRIANGLES, 0, this.ground.count);
        this.releaseAttribs();
      }
      if (this.terrain) {
        const p = this.progs.mesh;
        this.litUniforms(p, vp, 1);
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
      if (this.agentCount) this.drawAgents(vp, widthPx, heightPx, dpr);
      if (this.solids.count) {
        // Rocks last, slightly transparent: a fish behind or inside one still shows through.
        const p = this.progs.mesh;
        this.litUniforms(p, vp, ROCK_ALPHA);
        gl.enable(gl.BLEND);
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
        gl.depthMask(false);
        gl.bindBuffer(gl.ARRAY_BUFFER, this.solids.buf);
        this.attrib(p, 'aPos', 3, 9, 0);
        this.attrib(p, 'aNormal', 3, 9, 3);
        this.attrib(p, 'aColor', 3, 9, 6);
        gl.drawArrays(gl.TRIANGLES, 0, this.solids.count);
        this.releaseAttribs();
        gl.depthMask(true);
        gl.disable(gl.BLEND);
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
