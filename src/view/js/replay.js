// shoal viewer, replay.js: The replay source: frames decoded from the page's embedded recording.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- replay source

  function decodeColumn(node) {
    const bin = atob(node.textContent);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    node.textContent = '';
    switch (node.dataset.kind) {
      case 'f32': return new Float32Array(bytes.buffer);
      case 'u32': return new Uint32Array(bytes.buffer);
      case 'u16': return new Uint16Array(bytes.buffer);
      default: return bytes;
    }
  }

  function replaySource() {
    const meta = JSON.parse($('shoal-meta').textContent);
    const cols = {};
    for (const node of document.querySelectorAll('script.shoal-col')) cols[node.dataset.name] = decodeColumn(node);
    const fr = meta.frames;
    const strings = meta.history.strings;
    const unorm = { hunger: true, libido: true, fear: true, swim_phase: true };
    let index = 0, playing = false, speed = 1, clockTime = 0;

    function makeFrame(i) {
      const a = fr.offset[i], b = fr.offset[i + 1], fa = fr.food_offset[i], fb = fr.food_offset[i + 1];
      const sub = (name, k) => cols[name].subarray(a * k, b * k);
      return {
        index: i, tick: fr.tick[i], time: fr.time[i], n: b - a,
        ids: sub('id', 1), species: sub('species', 1), behavior: sub('behavior', 1),
        pos: sub('pos', 3), fwd: sub('fwd', 3), speed: sub('speed', 1), stack_depth: sub('stack_depth', 1),
        hunger: sub('hunger', 1), libido: sub('libido', 1), fear: sub('fear', 1),
        swim_phase: sub('swim_phase', 1), tail_bend: sub('tail_bend', 1),
        food: cols.food.subarray(fa * 3, fb * 3), unorm,
      };
    }

    // Index range of agent `id` in the (agent, tick)-sorted history columns.
    function historyRange(id) {
      const ag = cols.h_agent;
      let lo = 0, hi = ag.length;
      while (lo < hi) { const m = (lo + hi) >> 1; if (ag[m] < id) lo = m + 1; else hi = m; }
      let end = lo;
      while (end < ag.length && ag[end] === id) end++;
      return [lo, end];
    }

    const src = {
      meta,
      start() {
        const r = meta.run;
        $('run-info').textContent = (r.scenario || 'run') + ' · seed ' + r.seed + ' · dt ' + r.dt + ' s · '
          + r.ticks + ' ticks · recorded every ' + r.record_interval + ' · ' + fr.count + ' frames';
        $('banner').classList.toggle('hidden', !meta.incomplete);
        if (meta.notes.length) { $('notes').textContent = meta.notes.join(' · '); $('notes').classList.remove('hidden'); }
        const evs = [];
        for (const e of meta.script_errors) evs.push([e.tick, 'script error: ' + e.text]);
        for (const e of meta.reloads) evs.push([e.tick, 'reload: ' + e.text]);
        for (const e of meta.named_events || []) evs.push([e.tick, 'event: ' + e.text]);
        evs.sort((x, y) => x[0] - y[0]);
        if (evs.length) {
          $('events-box').classList.remove('hidden');
          $('events-summary').textContent = 'Events (' + Object.entries(meta.event_counts).map(([k, v]) => k + ' ' + v).join(', ') + ')';
          for (const [t, text] of evs) $('events').append(el('li', null, 't' + t + ' ' + text));
        }
        setTables(meta.species, meta.behaviors);
        setWorld(meta.world);
        health.build(meta.health);
        const scrub = $('scrub');
        scrub.max = String(Math.max(0, fr.count - 1));
        src.setFrame(0);
      },
      setFrame(i) {
        if (!fr.count) return 0;
        index = Math.max(0, Math.min(fr.count - 1, i | 0));
        clockTime = fr.time[index];
        applyFrame(makeFrame(index));
        return index;
      },
      frameIndex() { return index; },
      // Index of the recorded frame nearest to `tick` (the earlier one on a tie).
      frameOfTick(tick) {
        const t = fr.tick;
        let lo = 0, hi = fr.count;
        while (lo < hi) { const m = (lo + hi) >> 1; if (t[m] < tick) lo = m + 1; else hi = m; }
        if (lo >= fr.count) return Math.max(0, fr.count - 1);
        return lo > 0 && tick - t[lo - 1] <= t[lo] - tick ? lo - 1 : lo;
      },
      onFrameShown(f) {
        $('scrub').value = String(f.index);
        $('clock').textContent = 'tick ' + f.tick + ' · t = ' + f.time.toFixed(2) + ' s · frame ' + (f.index + 1) + '/' + fr.count;
      },
      setPlaying(p) {
        if (p && index >= fr.count - 1) src.setFrame(0);
        playing = p;
        if (!p) setBlend(null, 0);
        $('play').textContent = p ? '❚❚' : '▶';
      },
      playing() { return playing; },
      setSpeed(v) { speed = v; },
      step(k) { src.setPlaying(false); src.setFrame(index + k); },
      // Advances playback by `dt` seconds of wall time.
      advance(dt) {
        if (!playing || fr.count < 2) return;
        clockTime += dt * speed;
        let j = index;
        while (j + 1 < fr.count && fr.time[j + 1] <= clockTime) j++;
        if (j !== index) src.setFrame(j);
        clockTime = Math.max(clockTime, fr.time[index]);
        if (index >= fr.count - 1) src.setPlaying(false);
        else {
          // Between two recorded frames: draw the blend (the panel keeps the recorded one).
          const span = fr.time[index + 1] - fr.time[index];
          setBlend(makeFrame(index + 1), span > 0 ? Math.min(1, (clockTime - fr.time[index]) / span) : 0);
        }
      },
      decisions(id, tick) {
        const [a, b] = historyRange(id);
        const out = [];
        for (let k = a; k < b && cols.h_tick[k] <= tick; k++) {
          out.push({
            tick: cols.h_tick[k], from: strings[cols.h_from[k]], to: strings[cols.h_to[k]],
            cause: strings[cols.h_cause[k]], condition: strings[cols.h_cond[k]], stack: strings[cols.h_stack[k]],
          });
        }
        return out;
      },
      agentStatus(id, present) {
        const d = meta.deaths[String(id)];
        const tick = state.frame ? state.frame.tick : 0;
        if (d && tick >= d[0]) return 'died at tick ' + d[0] + (d[1] ? ' (' + d[1] + ')' : '');
        return present ? '' : 'not present at tick ' + tick;
      },
      inspect() { return Promise.resolve(null); },
      control() {},
    };
    return src;
  }
