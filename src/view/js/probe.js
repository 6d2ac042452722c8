// shoal viewer, probe.js: `window.shoalView`, what the page drew read back as pixels: one species'
// body alone (its silhouette and color), what lies under an obstacle, the playback blend, the
// behavior colors. Used by the browser tests and for the documentation's screenshots.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- pixel probes

  // Canvas pixels (rows bottom-up), read right after drawing: the drawing buffer is not kept.
  function readCanvas() {
    const gl = renderer.gl, w = canvas.width, h = canvas.height, px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    return { w, h, px };
  }

  // Draws with some layers hidden and the camera set by `pose`, reads the pixels, restores all.
  function drawAside(hide, pose) {
    const r = renderer, cam = camera;
    const saved = {
      target: cam.target.slice(), yaw: cam.yaw, pitch: cam.pitch, dist: cam.dist, ground: cam.ground,
      gr: r.ground, terrain: r.terrain, solids: r.solids.count, lines: r.staticLines.count,
      points: r.staticPoints.count, food: r.foodPoints.count, sel: r.selLines.count, agents: r.agentCount,
    };
    if (hide.agents) r.agentCount = 0;
    if (hide.scenery) {
      r.ground = null; r.terrain = null; r.staticLines.count = 0; r.staticPoints.count = 0; r.foodPoints.count = 0;
    }
    if (hide.scenery || hide.rocks) r.solids.count = 0;
    r.selLines.count = 0;
    if (pose) pose(cam);
    resize();
    r.draw(computeViewProj(), canvas.width, canvas.height, window.devicePixelRatio || 1);
    const img = readCanvas();
    Object.assign(cam, { target: saved.target, yaw: saved.yaw, pitch: saved.pitch, dist: saved.dist, ground: saved.ground });
    Object.assign(r, { ground: saved.gr, terrain: saved.terrain });
    r.solids.count = saved.solids; r.staticLines.count = saved.lines; r.staticPoints.count = saved.points;
    r.foodPoints.count = saved.food; r.selLines.count = saved.sel; r.agentCount = saved.agents;
    return img;
  }

  // Client point → canvas pixel index in an image read by `readCanvas`.
  function pixelIndex(img, x, y) {
    const rect = canvas.getBoundingClientRect();
    const cx = Math.round(((x - rect.left) / rect.width) * img.w), cy = Math.round(((y - rect.top) / rect.height) * img.h);
    if (cx < 0 || cy < 0 || cx >= img.w || cy >= img.h) return -1;
    return ((img.h - 1 - cy) * img.w + cx) * 4;
  }

  const probe = {
    // Species `s` drawn alone, side-on, `frac` of the view's height long, heading +z (a jelly's
    // bell up): its silhouette on a 32 × 16 grid over its bounding box, the box's aspect, the
    // mean color of its pixels (0–255) and the look's color.
    portrait(s, frac) {
      const sp = state.species[s];
      if (!sp || !renderer.ok) return null;
      const len = sp.length, up = sp.look.shape === 'jelly';
      const row = new Float32Array([0, 0, 0, 0, up ? 1 : 0, up ? 0 : 1, sp.rgb[0], sp.rgb[1], sp.rgb[2], len, 0]);
      renderer.setAgents(row, 1, [{ look: sp.look, start: 0, count: 1 }]);
      const img = drawAside({ scenery: true }, (cam) => {
        cam.ground = null; cam.yaw = Math.PI / 2; cam.pitch = 0.0;
        cam.target = [0, sp.look.shape === 'walker' ? 0.5 * len : 0, 0];
        cam.dist = len / ((frac || 0.5) * 2 * Math.tan(cam.fovy / 2));
      });
      fillInstances();
      state.dirty = true;
      const bg = FOG_COLOR.map((v) => v * 255), { w, h, px } = img;
      const on = (i) => Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 24;
      let x0 = w, x1 = -1, y0 = h, y1 = -1, n = 0;
      const sum = [0, 0, 0];
      for (let y = 0; y < h; y++) {
        for (let x = 0; x < w; x++) {
          const i = (y * w + x) * 4;
          if (!on(i)) continue;
          n++; sum[0] += px[i]; sum[1] += px[i + 1]; sum[2] += px[i + 2];
          if (x < x0) x0 = x; if (x > x1) x1 = x; if (y < y0) y0 = y; if (y > y1) y1 = y;
        }
      }
      if (!n) return { pixels: 0 };
      const GW = 32, GH = 16, grid = new Array(GW * GH).fill(0), count = new Array(GW * GH).fill(0);
      for (let y = y0; y <= y1; y++) {
        for (let x = x0; x <= x1; x++) {
          const g = Math.min(GH - 1, Math.floor(((y - y0) / (y1 - y0 + 1)) * GH)) * GW + Math.min(GW - 1, Math.floor(((x - x0) / (x1 - x0 + 1)) * GW));
          count[g]++;
          if (on((y * w + x) * 4)) grid[g]++;
        }
      }
      return {
        pixels: n, aspect: (x1 - x0 + 1) / (y1 - y0 + 1),
        grid: grid.map((v, g) => (v * 2 > count[g] ? '1' : '0')).join(''),
        color: sum.map((v) => v / n), expected: sp.rgb.map((v) => v * 255), shape: sp.look.shape,
      };
    },
    // Obstacles present now, with their projected centers and radii in client pixels.
    obstacles() {
      const w = state.world;
      if (!w) return [];
      resize();
      const vp = computeViewProj(), rect = canvas.getBoundingClientRect();
      const out = [];
      for (const o of w.obstacles || []) {
        const tick = state.frame ? state.frame.tick : 0;
        if (o.removed_tick !== null && o.removed_tick !== undefined && tick >= o.removed_tick) continue;
        let c, r;
        if (o.shape === 'sphere') { c = o.center; r = o.radius; } else if (o.shape === 'box') {
          c = [0, 1, 2].map((k) => (o.min[k] + o.max[k]) / 2);
          r = Math.min(...[0, 1, 2].map((k) => (o.max[k] - o.min[k]) / 2));
        } else { c = [o.base[0], o.base[1] + o.height / 2, o.base[2]]; r = Math.min(o.radius, o.height / 2); }
        const cw = vp[3] * c[0] + vp[7] * c[1] + vp[11] * c[2] + vp[15];
        if (cw <= 1e-6) continue;
        const cx = (vp[0] * c[0] + vp[4] * c[1] + vp[8] * c[2] + vp[12]) / cw;
        const cy = (vp[1] * c[0] + vp[5] * c[1] + vp[9] * c[2] + vp[13]) / cw;
        out.push({
          id: o.id, shape: o.shape, x: rect.left + (cx * 0.5 + 0.5) * rect.width, y: rect.top + (0.5 - cy * 0.5) * rect.height,
          r: (r * vp.projF * 0.5 * rect.height) / cw, eyeInside: Math.hypot(...vp.eye.map((e, k) => e - c[k])) < r,
        });
      }
      return out;
    },
    // Colors (0–255) at client points, drawn with and without the obstacles (agents hidden: a
    // fish in front of a rock is not the rock).
    pixelsAt(points) {
      const get = (img) => points.map(([x, y]) => { const i = pixelIndex(img, x, y); return i < 0 ? null : [img.px[i], img.px[i + 1], img.px[i + 2]]; });
      const withRocks = get(drawAside({ agents: true }));
      const without = get(drawAside({ agents: true, rocks: true }));
      state.dirty = true;
      return { withRocks, without, rock: ROCK_COLOR.map((v) => v * 255), background: FOG_COLOR.map((v) => v * 255) };
    },
    // The playback blend now: how far towards the next recorded frame agents are drawn.
    blend: () => ({ alpha: state.alpha, blended: !!state.next }),
    // Per species, its behaviors and their colors (0–255).
    behaviorColors: () => state.species.map((sp, s) => ({
      name: sp.name,
      behaviors: sp.behaviors.map((b) => [b, behaviorRgb(s, state.behaviors.indexOf(b)).map((v) => Math.round(v * 255))]),
    })),
    looks: () => state.species.map((sp) => ({ name: sp.name, ...sp.look })),
    camera: () => ({ eye: camera.eye(), target: camera.target.slice(), ground: camera.ground ? camera.ground(...[camera.eye()[0], camera.eye()[2]]) : null }),
    // Moves the camera (for screenshots): any of yaw, pitch, dist, target.
    setCamera(c) { Object.assign(camera, c); state.dirty = true; },
    // Points the camera at agent `id` from `dist` world units (for close-ups); false if absent.
    focus(id, dist) {
      const i = indexOfId(state.frame, id);
      if (i < 0) return false;
      const p = state.frame.pos;
      camera.target = [p[3 * i], p[3 * i + 1], p[3 * i + 2]];
      if (dist) camera.dist = dist;
      state.dirty = true;
      return true;
    },
    // Ids of the agents of species `s` in the shown frame.
    idsOf(s) {
      const f = state.frame, out = [];
      for (let i = 0; f && i < f.n; i++) if (f.species[i] === s) out.push(f.ids[i]);
      return out;
    },
    // The agents' bounding box is fitted again, as on load.
    refit() { if (state.frame) camera.fitPoints(state.frame.pos); state.dirty = true; },
  };
  window.shoalView = probe;
