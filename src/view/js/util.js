// shoal viewer, util.js: Small helpers, matrices and the orbit camera; opens the page's one function scope.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
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

  // The behavior palette: 16 colors told apart at a glance (hue, then lightness), no two alike.
  // A behavior's color is picked by a hash of its name, so `escape` is the same red in every
  // scenario; see `legend.js` for how collisions within a species are resolved.
  // Any two are at least 98 apart in 0–255 RGB, and all are light enough for the dark page.
  const PALETTE = [
    '#e6194b', '#00ffff', '#60ff00', '#fffac8', '#ff00ff', '#4363d8', '#ffe119', '#00a000',
    '#80ff80', '#808000', '#ff7f7f', '#7fbfff', '#911eb4', '#ff6000', '#a9a9a9', '#3cb44b',
  ].map(hexToRgb);

  function nameHash(s) {
    let h = 2166136261;
    for (let i = 0; i < s.length; i++) { h ^= s.charCodeAt(i); h = Math.imul(h, 16777619); }
    return h >>> 0;
  }

  // Colors for behaviors by global index, for callers without a species (golden-angle hues).
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
  // `ground(x, z)` is the height of the seabed or terrain under a point (null: none); the eye is
  // never put below it, so orbiting or following never ends inside a ridge.
  const camera = {
    target: [0, 0, 0], yaw: 0.7, pitch: 0.45, dist: 100, fovy: Math.PI / 4, scale: 100, ground: null,
    eye() {
      const cp = Math.cos(this.pitch);
      const e = [
        this.target[0] + this.dist * cp * Math.sin(this.yaw),
        this.target[1] + this.dist * Math.sin(this.pitch),
        this.target[2] + this.dist * cp * Math.cos(this.yaw),
      ];
      if (this.ground) {
        const g = this.ground(e[0], e[2]);
        const clear = Math.max(0.5, this.dist * 0.05);
        if (g !== null && e[1] < g + clear) e[1] = g + clear;
      }
      return e;
    },
    // Frames the agents at `pos` (x, y, z triples): centered, the farthest within the view.
    fitPoints(pos) {
      const n = pos.length / 3;
      if (!n) return;
      const mn = [Infinity, Infinity, Infinity], mx = [-Infinity, -Infinity, -Infinity];
      for (let i = 0; i < n; i++) {
        for (let k = 0; k < 3; k++) {
          const v = pos[3 * i + k];
          if (v < mn[k]) mn[k] = v;
          if (v > mx[k]) mx[k] = v;
        }
      }
      this.target = [(mn[0] + mx[0]) / 2, (mn[1] + mx[1]) / 2, (mn[2] + mx[2]) / 2];
      const r = Math.max(this.scale * 0.03, 2, Math.hypot(mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]) / 2);
      this.dist = Math.min(this.scale * 20, (r / Math.sin(this.fovy / 2)) * 1.05);
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
      const eye = this.eye();
      const m = M4.mul(M4.perspective(this.fovy, aspect, near, far), M4.lookAt(eye, this.target, [0, 1, 0]));
      m.eye = eye;
      // Fog starts a little beyond the target and thickens over a few world sizes.
      m.fog = [this.dist * 0.9, this.dist + this.scale * 5];
      return m;
    },
  };
