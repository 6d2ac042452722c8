// shoal viewer, live.js: The live source: frames from the `/stream` of `shoal watch`.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- live source

  function liveSource() {
    let frames = 0, playing = true, lastTick = null;
    // behaviorMap[s][j] = global index of world.species[s].behaviors[j]
    let behaviorMap = [];

    function tablesFromWorld(world) {
      // The behaviors-over-time strips survive a reload: each species' old strip is drawn into
      // its new one.
      const oldStrips = new Map();
      histogram.rows.forEach((r, i) => { if (r.strip && state.species[i]) oldStrips.set(state.species[i].name, r.strip); });
      const names = [], index = new Map();
      behaviorMap = (world.species || []).map((s) => (s.behaviors || []).map((b) => {
        if (!index.has(b)) { index.set(b, names.length); names.push(b); }
        return index.get(b);
      }));
      names.push('?');
      setTables(world.species || [], names);
      histogram.rows.forEach((r, i) => {
        const old = state.species[i] && oldStrips.get(state.species[i].name);
        if (r.strip && old) r.strip.getContext('2d').drawImage(old, 0, 0);
      });
      const dl = $('break-behaviors');
      dl.textContent = '';
      for (const b of new Set(names.slice(0, -1))) dl.append(el('option', { value: b }));
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
        es.addEventListener('script_error', (e) => {
          try { showScriptError(JSON.parse(e.data)); } catch (_) { /* a bad message is dropped */ }
        });
        es.addEventListener('breakpoint', (e) => {
          let hit = null;
          try { hit = JSON.parse(e.data); } catch (_) { /* treated as none */ }
          showHit(hit);
        });
        bindBreakpoints();
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
      // The server paused itself (a breakpoint): show it, send nothing.
      markPaused() { playing = false; $('play').textContent = '▶'; },
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

  // ---------------------------------------------------------------- live breakpoints and errors

  const breakState = { hit: null, errors: [], list: [] };

  // A runtime script error: listed in the red box over the view until dismissed.
  function showScriptError(f) {
    breakState.errors.push(f);
    const fn = f.function ? ' in ' + f.function + '()' : '';
    const first = String(f.message || '').split('\n');
    const text = 'tick ' + f.tick + ' · agent ' + f.agent + ' (' + f.species + ')' + fn + '\n' + first.join('\n');
    const list = $('script-error-list');
    list.append(el('li', { 'data-agent': String(f.agent) }, text));
    while (list.children.length > 5) list.firstChild.remove();
    $('script-errors').classList.remove('hidden');
  }

  function showHit(hit) {
    breakState.hit = hit;
    const box = $('break-hit');
    if (!hit) { box.classList.add('hidden'); return; }
    box.textContent = 'paused at tick ' + hit.tick + ': ' + hit.reason;
    box.classList.remove('hidden');
    $('break-box').classList.remove('hidden');
    if (source && source.playing()) source.markPaused();
    if (state.selected !== hit.agent) select(hit.agent);
  }

  function renderBreakList() {
    const ol = $('break-list');
    ol.textContent = '';
    for (const b of breakState.list) {
      const li = el('li', null, b.text);
      const rm = el('button', { type: 'button', title: 'Remove' }, '×');
      rm.addEventListener('click', () => {
        fetch('/control', { method: 'POST', body: JSON.stringify({ cmd: 'unbreak', id: b.id }) }).catch(() => {});
        breakState.list = breakState.list.filter((x) => x.id !== b.id);
        renderBreakList();
      });
      li.append(rm);
      ol.append(li);
    }
  }

  // The form: what to pause on, for which behavior, agent id or species (blank: any agent).
  function bindBreakpoints() {
    $('break-box').classList.remove('hidden');
    $('script-errors-close').addEventListener('click', () => {
      $('script-errors').classList.add('hidden');
      $('script-error-list').textContent = '';
    });
    $('break-add').addEventListener('click', () => {
      const body = { cmd: 'break', on: $('break-on').value };
      const beh = $('break-behavior').value.trim(), who = $('break-who').value.trim();
      if (body.on !== 'script_error') body.behavior = beh;
      if (/^\d+$/.test(who)) body.agent = Number(who); else if (who) body.species = who;
      fetch('/control', { method: 'POST', body: JSON.stringify(body) })
        .then((r) => r.json().then((j) => [r.ok, j]))
        .then(([ok, j]) => {
          if (!ok) { toast('breakpoint refused: ' + (j.error || '?')); return; }
          const who2 = body.agent !== undefined ? 'agent ' + body.agent : body.species ? 'any ' + body.species : 'any agent';
          const what = body.on === 'script_error' ? 'script error' : body.on === 'enter' ? 'enters ' + beh : beh + "'s " + body.on + ' fires';
          breakState.list.push({ id: j.id, text: who2 + ': ' + what });
          renderBreakList();
        })
        .catch(() => toast('breakpoint not sent'));
    });
  }

  let toastTimer = null;
  function toast(text) {
    const t = $('toast');
    t.textContent = text;
    t.classList.remove('hidden');
    clearTimeout(toastTimer);
    toastTimer = setTimeout(() => t.classList.add('hidden'), 2500);
  }
