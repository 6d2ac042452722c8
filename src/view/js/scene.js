// shoal viewer, scene.js: Shared scene state: the world, the current frame (blended while
// playing), the selection; the seabed, obstacles and instance buffers built from them.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- shared scene state

  const state = {
    world: null,
    species: [], // [{name, rgb, length, behaviors, look}]
    behaviorRgb: [], // behaviorRgb[species][global behavior index]: see `legend.assignColors`
    next: null, // while playing: the recorded frame after `frame`, blended in by `alpha`
    alpha: 0,
    fitted: false,
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

  // A species' look: the one its file gives (in `world.json`), or a fish in its color.
  function lookOf(s) {
    const l = s.look || {};
    return {
      shape: l.shape || 'fish', outline: l.outline || [],
      length: l.length > 0 ? l.length : (s.length > 0 ? s.length : 1),
      color: l.color || s.color, behavior_colors: l.behavior_colors || {},
    };
  }

  function setTables(species, behaviors) {
    state.species = species.map((s) => {
      const look = lookOf(s);
      return { name: s.name, rgb: hexToRgb(look.color), length: look.length, behaviors: s.behaviors || [], look };
    });
    state.behaviors = behaviors.slice();
    legend.assignColors();
    legend.build();
    histogram.build();
  }

  // Height of terrain `t` under (x, z), bilinear between cell centers.
  function terrainHeight(t, x, z) {
    const fc = Math.max(0, Math.min(t.cols - 1.001, (x - t.origin[0]) / t.cell - 0.5));
    const fr = Math.max(0, Math.min(t.rows - 1.001, (z - t.origin[1]) / t.cell - 0.5));
    const c = Math.floor(fc), r = Math.floor(fr), u = fc - c, v = fr - r;
    const H = (cc, rr) => t.heights[Math.min(t.rows - 1, rr) * t.cols + Math.min(t.cols - 1, cc)];
    return (H(c, r) * (1 - u) + H(c + 1, r) * u) * (1 - v) + (H(c, r + 1) * (1 - u) + H(c + 1, r + 1) * u) * v;
  }

  function setWorld(world) {
    state.world = world;
    camera.fit(world.bounds);
    state.fitted = false;
    renderer.setTerrain(world.terrain);
    const t = world.terrain, b = world.bounds;
    if (t && t.cols >= 2 && t.rows >= 2 && t.heights && t.heights.length === t.cols * t.rows) {
      camera.ground = (x, z) => terrainHeight(t, x, z);
      renderer.setGround(null);
    } else {
      camera.ground = () => b.min[1];
      const cx = (b.min[0] + b.max[0]) / 2, cz = (b.min[2] + b.max[2]) / 2;
      const grid = Math.pow(10, Math.max(0, Math.round(Math.log10(camera.scale / 5))));
      renderer.setGround(b.min[1], cx, cz, camera.scale * 12, grid);
    }
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
    const out = [], rocks = [];
    geom.box(out, w.bounds.min, w.bounds.max, [0.25, 0.38, 0.48]);
    for (const o of present) {
      if (o.shape === 'sphere') solid.sphere(rocks, o.center, o.radius, ROCK_COLOR);
      else if (o.shape === 'box') solid.box(rocks, o.min, o.max, ROCK_COLOR);
      else if (o.shape === 'cylinder') solid.cylinder(rocks, o.base, o.radius, o.height, ROCK_COLOR);
    }
    renderer.setSolids(new Float32Array(rocks));
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

  // Writes the agents of the shown frame into the instance buffer, grouped by species (one draw
  // call each). While playing, positions, headings and tail bends are blended towards the same
  // agent (matched by id) in `state.next`; paused or stepped, the recorded frame is drawn as is.
  function fillInstances() {
    const f = state.frame;
    if (!f || !renderer.ok) return;
    const n = f.n, sp = state.species, ns = Math.max(1, sp.length);
    if (state.instances.length < n * AGENT_FLOATS) state.instances = new Float32Array(Math.ceil(n * 1.25) * AGENT_FLOATS + AGENT_FLOATS);
    const d = state.instances, bySpecies = state.colorMode === 'species';
    const grey = [0.7, 0.7, 0.7];
    // Rows per species, then each species' first row in the buffer.
    const start = new Uint32Array(ns + 1);
    for (let i = 0; i < n; i++) start[Math.min(f.species[i], ns - 1) + 1]++;
    for (let s = 0; s < ns; s++) start[s + 1] += start[s];
    const at = start.slice(0, ns);
    const nx = state.next && state.alpha > 0 ? state.next : null, a = state.alpha;
    let j = 0;
    for (let i = 0; i < n; i++) {
      const si = Math.min(f.species[i], ns - 1), s = sp[si];
      const o = at[si]++ * AGENT_FLOATS;
      const c = bySpecies ? (s ? s.rgb : grey) : behaviorRgb(si, f.behavior[i]);
      let px = f.pos[3 * i], py = f.pos[3 * i + 1], pz = f.pos[3 * i + 2];
      let fx = f.fwd[3 * i], fy = f.fwd[3 * i + 1], fz = f.fwd[3 * i + 2];
      let bend = f.tail_bend ? f.tail_bend[i] : 0;
      if (nx) {
        const id = f.ids[i];
        while (j < nx.n && nx.ids[j] < id) j++;
        if (j < nx.n && nx.ids[j] === id) {
          px += (nx.pos[3 * j] - px) * a; py += (nx.pos[3 * j + 1] - py) * a; pz += (nx.pos[3 * j + 2] - pz) * a;
          fx += (nx.fwd[3 * j] - fx) * a; fy += (nx.fwd[3 * j + 1] - fy) * a; fz += (nx.fwd[3 * j + 2] - fz) * a;
          if (nx.tail_bend) bend += (nx.tail_bend[j] - bend) * a;
        }
      }
      d[o] = px; d[o + 1] = py; d[o + 2] = pz;
      d[o + 3] = fx; d[o + 4] = fy; d[o + 5] = fz;
      d[o + 6] = c[0]; d[o + 7] = c[1]; d[o + 8] = c[2];
      d[o + 9] = s ? s.length : 1;
      d[o + 10] = bend;
    }
    const groups = [];
    for (let s = 0; s < ns; s++) groups.push({ look: sp[s] ? sp[s].look : null, start: start[s], count: start[s + 1] - start[s] });
    renderer.setAgents(d, n, groups);
    const food = f.food || [];
    const fp = new Float32Array((food.length / 3) * 6);
    for (let i = 0, k = 0; i < food.length; i += 3, k += 6) {
      fp[k] = food[i]; fp[k + 1] = food[i + 1]; fp[k + 2] = food[i + 2];
      fp[k + 3] = 0.55; fp[k + 4] = 0.92; fp[k + 5] = 0.35;
    }
    renderer.fill(renderer.foodPoints, fp, renderer.gl.DYNAMIC_DRAW);
  }

  // Blends the shown frame towards `next` by `alpha` in [0, 1) (null: the recorded frame).
  function setBlend(next, alpha) {
    if (!next && !state.next) return;
    state.next = next;
    state.alpha = next ? alpha : 0;
    fillInstances();
    state.dirty = true;
  }

  // Shows `frame` everywhere: agents, food, obstacles, histogram, panel, clock.
  function applyFrame(frame) {
    state.frame = frame;
    state.next = null;
    state.alpha = 0;
    state.applied++;
    if (!state.fitted && frame.n) {
      camera.fitPoints(frame.pos);
      state.fitted = true;
    }
    rebuildStatic(frame.tick);
    fillInstances();
    histogram.update(frame);
    panel.update();
    source.onFrameShown(frame);
    state.dirty = true;
  }
