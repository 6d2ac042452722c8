// shoal viewer, main.js: Input, the animation loop and the test hook; closes the page's function scope.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
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
    followGraph();
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
    graph: () => graph.snapshot(),
    frameTick: () => (state.frame ? state.frame.tick : null),
    behaviorOf: (id) => {
      const i = state.frame ? indexOfId(state.frame, id) : -1;
      return i < 0 ? null : state.behaviors[state.frame.behavior[i]];
    },
    select: (id) => select(id),
    breakHit: () => breakState.hit,
    scriptErrors: () => breakState.errors.slice(),
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
