// shoal viewer, live.js: The live source: frames from the `/stream` of `shoal watch`.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
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
