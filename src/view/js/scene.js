// shoal viewer, scene.js: Shared scene state: the world, the current frame, the selection.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
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
