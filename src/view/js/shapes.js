// shoal viewer, shapes.js: The body meshes of the shape families (fish, shark, jelly, walker,
// custom outline) and the solid obstacle meshes. Pure geometry: no GL calls.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- body meshes

  // A body mesh is in body lengths: +z is the nose (the heading), +y up, +x the body's right;
  // the body spans z in [-0.5, 0.5] (a walker stands on y = 0 and is 1 tall). Each vertex is
  // position 3, normal 3, flex 1 (how far the tail bend moves it sideways).
  const BODY_FLOATS = 7;

  function meshBuilder() {
    const v = [], idx = [];
    const b = {
      vert(p, n, flex) {
        const l = Math.hypot(n[0], n[1], n[2]) || 1;
        v.push(p[0], p[1], p[2], n[0] / l, n[1] / l, n[2] / l, flex || 0);
        return v.length / BODY_FLOATS - 1;
      },
      tri(a, c, d) { idx.push(a, c, d); },
      // A flat double-sided polygon (fan from the first point).
      flat(pts, n, flexOf) {
        for (const side of [1, -1]) {
          const nn = [n[0] * side, n[1] * side, n[2] * side];
          const base = pts.map((p) => b.vert(p, nn, flexOf ? flexOf(p) : 0));
          for (let k = 1; k + 1 < base.length; k++) {
            if (side > 0) b.tri(base[0], base[k], base[k + 1]); else b.tri(base[0], base[k + 1], base[k]);
          }
        }
      },
      // A body of revolution about z: `profile` is [z, rx, ry] rings from nose to tail.
      lathe(profile, seg, flexOf, yOff) {
        const rings = profile.map(([z, rx, ry]) => {
          const ring = [];
          for (let s = 0; s < seg; s++) {
            const a = (s / seg) * Math.PI * 2, cx = Math.cos(a), cy = Math.sin(a);
            const p = [cx * rx, cy * ry + (yOff || 0), z];
            ring.push(b.vert(p, [cx * (ry || 0.01), cy * (rx || 0.01), 0.15 * Math.sign(z)], flexOf ? flexOf(z) : 0));
          }
          return ring;
        });
        for (let r = 0; r + 1 < rings.length; r++) {
          for (let s = 0; s < seg; s++) {
            const a = rings[r][s], c = rings[r][(s + 1) % seg], d = rings[r + 1][s], e = rings[r + 1][(s + 1) % seg];
            b.tri(a, d, c); b.tri(c, d, e);
          }
        }
      },
      // An axis-aligned box between `mn` and `mx`, flat-shaded.
      box(mn, mx, flex) {
        const faces = [
          [[1, 0, 0], [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]]],
          [[-1, 0, 0], [[0, 0, 1], [0, 1, 1], [0, 1, 0], [0, 0, 0]]],
          [[0, 1, 0], [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]]],
          [[0, -1, 0], [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]],
          [[0, 0, 1], [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]],
          [[0, 0, -1], [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]]],
        ];
        for (const [n, corners] of faces) {
          const q = corners.map((c) => b.vert([c[0] ? mx[0] : mn[0], c[1] ? mx[1] : mn[1], c[2] ? mx[2] : mn[2]], n, flex));
          b.tri(q[0], q[1], q[2]); b.tri(q[0], q[2], q[3]);
        }
      },
      done() { return { v: new Float32Array(v), i: new Uint16Array(idx) }; },
    };
    return b;
  }

  // Tail flex: nothing ahead of the middle, growing towards the tail.
  const tailFlex = (z) => Math.max(0, -z - 0.05) * 1.6;

  const bodyMeshes = {
    fish() {
      const b = meshBuilder();
      b.lathe([[0.5, 0, 0], [0.42, 0.05, 0.08], [0.25, 0.09, 0.17], [0.02, 0.1, 0.2], [-0.2, 0.07, 0.13],
        [-0.34, 0.03, 0.05], [-0.38, 0.015, 0.025]], 8, tailFlex);
      b.flat([[0, 0, -0.36], [0, 0.2, -0.52], [0, 0.05, -0.44], [0, -0.05, -0.44], [0, -0.2, -0.52]], [1, 0, 0], (p) => tailFlex(p[2]));
      b.flat([[0, 0.17, 0.15], [0, 0.3, -0.02], [0, 0.15, -0.12]], [1, 0, 0]);
      return b.done();
    },
    shark() {
      const b = meshBuilder();
      b.lathe([[0.5, 0, 0], [0.44, 0.04, 0.035], [0.3, 0.085, 0.08], [0.08, 0.1, 0.095], [-0.15, 0.065, 0.065],
        [-0.33, 0.025, 0.025], [-0.38, 0.012, 0.012]], 8, tailFlex);
      b.flat([[0, 0.08, 0.12], [0, 0.27, -0.05], [0, 0.07, -0.07]], [1, 0, 0]);
      b.flat([[0, 0, -0.36], [0, 0.24, -0.55], [0, 0.03, -0.43], [0, -0.12, -0.48]], [1, 0, 0], (p) => tailFlex(p[2]));
      for (const s of [1, -1]) b.flat([[s * 0.08, -0.04, 0.18], [s * 0.3, -0.1, 0.0], [s * 0.08, -0.04, 0.04]], [0, 1, 0]);
      return b.done();
    },
    jelly() {
      const b = meshBuilder();
      // Bell around the heading axis: the dome leads, the rim trails.
      b.lathe([[0.5, 0, 0], [0.45, 0.22, 0.22], [0.33, 0.38, 0.38], [0.15, 0.46, 0.46], [0.05, 0.44, 0.44],
        [0.1, 0.3, 0.3], [0.14, 0, 0]], 10);
      for (let k = 0; k < 6; k++) {
        const a = (k / 6) * Math.PI * 2, cx = Math.cos(a) * 0.25, cy = Math.sin(a) * 0.25;
        const tx = -Math.sin(a) * 0.04, ty = Math.cos(a) * 0.04;
        b.flat([[cx - tx, cy - ty, 0.08], [cx + tx, cy + ty, 0.08], [cx * 0.6, cy * 0.6, -0.5]], [Math.cos(a), Math.sin(a), 0], (p) => Math.max(0, -p[2]) * 0.6);
      }
      return b.done();
    },
    walker() {
      const b = meshBuilder();
      b.box([-0.09, 0, -0.05], [-0.015, 0.46, 0.05]); // legs
      b.box([0.015, 0, -0.05], [0.09, 0.46, 0.05]);
      b.box([-0.13, 0.45, -0.07], [0.13, 0.8, 0.07]); // torso
      b.box([-0.18, 0.46, -0.04], [-0.13, 0.78, 0.04]); // arms
      b.box([0.13, 0.46, -0.04], [0.18, 0.78, 0.04]);
      b.box([-0.065, 0.82, -0.065], [0.065, 0.97, 0.07]); // head
      b.box([-0.04, 0.86, 0.07], [0.04, 0.9, 0.11]); // nose: which way it faces
      b.box([0.1, 0.6, 0.04], [0.14, 0.65, 0.4]); // carried pole
      return b.done();
    },
    // A slab cut from the side-view outline `pts` ([along, up] in body lengths, nose at +along).
    custom(pts) {
      const b = meshBuilder();
      let lo = Infinity, hi = -Infinity;
      for (const p of pts) { lo = Math.min(lo, p[0]); hi = Math.max(hi, p[0]); }
      const span = hi - lo || 1, mid = (hi + lo) / 2, half = 0.06;
      const P = pts.map((p) => [(p[0] - mid) / span, p[1] / span]);
      const cz = P.reduce((s, p) => s + p[0], 0) / P.length, cy = P.reduce((s, p) => s + p[1], 0) / P.length;
      for (const side of [1, -1]) {
        const c = b.vert([side * half, cy, cz], [side, 0, 0], tailFlex(cz));
        const ring = P.map((p) => b.vert([side * half, p[1], p[0]], [side, 0, 0], tailFlex(p[0])));
        for (let k = 0; k < ring.length; k++) {
          const a = ring[k], d = ring[(k + 1) % ring.length];
          if (side > 0) b.tri(c, a, d); else b.tri(c, d, a);
        }
      }
      for (let k = 0; k < P.length; k++) {
        const p = P[k], q = P[(k + 1) % P.length];
        const n = [0, -(q[0] - p[0]), q[1] - p[1]];
        const e = [[half, p[1], p[0]], [half, q[1], q[0]], [-half, q[1], q[0]], [-half, p[1], p[0]]]
          .map((x) => b.vert(x, n, tailFlex(x[2])));
        b.tri(e[0], e[1], e[2]); b.tri(e[0], e[2], e[3]);
      }
      return b.done();
    },
  };

  // The mesh of a species' look (cached by shape and outline).
  const bodyMeshCache = new Map();
  function bodyMesh(look) {
    const shape = look && bodyMeshes[look.shape] ? look.shape : 'fish';
    const key = shape === 'custom' ? 'custom:' + JSON.stringify(look.outline || []) : shape;
    if (!bodyMeshCache.has(key)) {
      const outline = look && look.outline && look.outline.length >= 3 ? look.outline : null;
      bodyMeshCache.set(key, shape === 'custom' ? (outline ? bodyMeshes.custom(outline) : bodyMeshes.fish()) : bodyMeshes[shape]());
    }
    return { key, mesh: bodyMeshCache.get(key), upright: shape === 'walker' };
  }

  // ---------------------------------------------------------------- solid meshes (world units)

  // Triangles with position 3, normal 3, color 3 per vertex, pushed into a plain array.
  const solid = {
    tri(out, a, b, c, n, col) {
      for (const p of [a, b, c]) out.push(p[0], p[1], p[2], n[0], n[1], n[2], col[0], col[1], col[2]);
    },
    sphere(out, ctr, r, col) {
      const lat = 14, lon = 22;
      const P = (i, j) => {
        const t = (i / lat) * Math.PI, f = (j / lon) * Math.PI * 2;
        return [Math.sin(t) * Math.cos(f), Math.cos(t), Math.sin(t) * Math.sin(f)];
      };
      const push = (n) => out.push(ctr[0] + n[0] * r, ctr[1] + n[1] * r, ctr[2] + n[2] * r, n[0], n[1], n[2], col[0], col[1], col[2]);
      for (let i = 0; i < lat; i++) {
        for (let j = 0; j < lon; j++) {
          const a = P(i, j), b = P(i + 1, j), c = P(i, j + 1), d = P(i + 1, j + 1);
          push(a); push(b); push(c); push(c); push(b); push(d);
        }
      }
    },
    box(out, mn, mx, col) {
      const C = (x, y, z) => [x ? mx[0] : mn[0], y ? mx[1] : mn[1], z ? mx[2] : mn[2]];
      const quad = (a, b, c, d, n) => { solid.tri(out, a, b, c, n, col); solid.tri(out, a, c, d, n, col); };
      quad(C(1, 0, 0), C(1, 1, 0), C(1, 1, 1), C(1, 0, 1), [1, 0, 0]);
      quad(C(0, 0, 1), C(0, 1, 1), C(0, 1, 0), C(0, 0, 0), [-1, 0, 0]);
      quad(C(0, 1, 0), C(0, 1, 1), C(1, 1, 1), C(1, 1, 0), [0, 1, 0]);
      quad(C(0, 0, 0), C(1, 0, 0), C(1, 0, 1), C(0, 0, 1), [0, -1, 0]);
      quad(C(0, 0, 1), C(1, 0, 1), C(1, 1, 1), C(0, 1, 1), [0, 0, 1]);
      quad(C(0, 0, 0), C(0, 1, 0), C(1, 1, 0), C(1, 0, 0), [0, 0, -1]);
    },
    cylinder(out, base, r, h, col) {
      const n = 24, y0 = base[1], y1 = base[1] + h;
      for (let k = 0; k < n; k++) {
        const a0 = (k / n) * Math.PI * 2, a1 = ((k + 1) / n) * Math.PI * 2;
        const p = (a, y) => [base[0] + Math.cos(a) * r, y, base[2] + Math.sin(a) * r];
        const nm = [Math.cos((a0 + a1) / 2), 0, Math.sin((a0 + a1) / 2)];
        solid.tri(out, p(a0, y0), p(a0, y1), p(a1, y1), nm, col);
        solid.tri(out, p(a0, y0), p(a1, y1), p(a1, y0), nm, col);
        solid.tri(out, [base[0], y1, base[2]], p(a1, y1), p(a0, y1), [0, 1, 0], col);
      }
    },
  };
