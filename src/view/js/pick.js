// shoal viewer, pick.js: Projection and picking: which agent is under the cursor.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
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
