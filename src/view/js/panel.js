// shoal viewer, panel.js: The agent panel: what the selected agent is doing and why.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- agent panel

  // What the recording holds to explain agents (`explain.jsonl` grouped by agent, contacts from
  // `events.jsonl`), parsed on first use; null on the live page or an old page.
  let explainCache;
  function explainData() {
    if (explainCache !== undefined) return explainCache;
    const node = $('shoal-explain');
    try { explainCache = node ? JSON.parse(node.textContent) : null; } catch (e) { explainCache = null; }
    return explainCache;
  }

  // The explained frame of agent `id` at `tick` (the latest at or before it), or null.
  function explainedFrame(id, tick) {
    if (LIVE) return panel.live && panel.live.explain ? panel.live.explain : null;
    const ex = explainData();
    const list = ex && ex.frames[String(id)];
    if (!list || !list.length) return null;
    let lo = 0, hi = list.length;
    while (lo < hi) { const m = (lo + hi) >> 1; if (list[m].tick <= tick) lo = m + 1; else hi = m; }
    return lo > 0 ? list[lo - 1] : null;
  }

  // The explained decision of agent `id` made on `tick` towards behavior `to`, or null.
  function explainedDecision(id, tick, to) {
    const ex = LIVE ? null : explainData();
    const list = LIVE ? (panel.live && panel.live.explained_decisions) || [] : (ex && ex.decisions[String(id)]) || [];
    for (const d of list) if (d.tick === tick && (!to || d.to === to)) return d;
    return null;
  }

  // Seconds per tick: the run's dt (replay) or the live answer's.
  function tickSeconds() {
    if (source && source.meta && source.meta.run) return Number(source.meta.run.dt) || 0;
    return panel.live && panel.live.dt ? panel.live.dt : 0;
  }

  function secondsOf(tick) {
    const dt = tickSeconds();
    return dt ? (tick * dt).toFixed(2) + ' s' : 'tick ' + tick;
  }

  // One clause tree `{c, v, x, k}` as nested list items: ✓ held, ✗ did not; the value read.
  function clauseList(node) {
    const ul = el('ul', { class: 'clauses' });
    const add = (n, into) => {
      const li = el('li', { class: n.v ? 'held' : 'failed' });
      li.append(el('span', { class: 'mark' }, n.v ? '✓ ' : '✗ '), el('span', null, n.c + (n.x !== undefined && n.x !== null ? ' = ' + n.x : '')));
      if (n.script) li.append(el('span', { class: 'muted' }, ' (script)'));
      into.append(li);
      if (n.k && n.k.length) {
        const sub = el('ul', { class: 'clauses' });
        for (const k of n.k) add(k, sub);
        li.append(sub);
      }
    };
    add(node, ul);
    return ul;
  }

  function factRow(dl, name, value, testid) {
    dl.append(el('dt', null, name), el('dd', testid ? { 'data-testid': testid } : null, value));
  }

  const panel = {
    live: null, // last /agent/<id> answer (live only)
    timer: null,
    open(id) {
      $('panel').classList.toggle('hidden', id === null);
      this.live = null;
      if (this.timer) { clearInterval(this.timer); this.timer = null; }
      if (id !== null && LIVE) {
        const poll = () => source.inspect(id).then((j) => { if (state.selected === id) { this.live = j; this.update(); } });
        poll();
        this.timer = setInterval(poll, 500);
      }
      this.update();
    },
    close() { select(null); },
    drive(name, v) {
      const row = el('div', { class: 'drive' });
      const bar = el('div', { class: 'bar' }), fill = el('div');
      const colors = { hunger: '#e0a030', libido: '#e06090', fear: '#6090e0' };
      fill.style.background = colors[name] || '#9fb3c8';
      fill.style.width = (v === null ? 0 : Math.max(0, Math.min(1, v)) * 100) + '%';
      bar.append(fill);
      row.append(el('span', null, name), bar, el('span', null, fmt(v, 2)));
      return row;
    },
    update() {
      const id = state.selected;
      if (id === null) return;
      const f = state.frame;
      const i = indexOfId(f, id);
      const lv = this.live;
      $('panel-id').textContent = String(id);
      const sp = i >= 0 ? state.species[f.species[i]] : null;
      $('panel-species').textContent = lv && lv.species !== undefined ? lv.species : sp ? sp.name : '–';
      $('panel-behavior').textContent = lv && lv.behavior !== undefined ? lv.behavior
        : i >= 0 ? state.behaviors[f.behavior[i]] || '?' : '–';
      $('panel-depth').textContent = lv && lv.stack ? String(lv.stack.length) : i >= 0 ? String(fval(f, 'stack_depth', i)) : '–';
      $('panel-speed').textContent = i >= 0 ? fmt(fval(f, 'speed', i), 2) : '–';
      const ef = explainedFrame(id, f ? f.tick : 0);
      const phase = i >= 0 ? fval(f, 'swim_phase', i) : null, bend = i >= 0 ? fval(f, 'tail_bend', i) : null;
      // Fish-only fields: a body without a swimming cycle (walkers) shows no phase or bend.
      const animated = ef && ef.anim !== undefined ? ef.anim : (phase || 0) !== 0 || (bend || 0) !== 0;
      $('panel-anim').textContent = phase === null && bend === null ? '–'
        : 'swim phase ' + fmt(phase, 2) + ', tail bend ' + fmt(bend, 3) + ' rad';
      $('panel-anim').classList.toggle('hidden', !animated);
      $('panel-anim').previousElementSibling.classList.toggle('hidden', !animated);
      $('panel-status').textContent = source.agentStatus(id, i >= 0);
      const drives = $('panel-drives');
      drives.textContent = '';
      const dv = (name) => (lv && lv.drives && lv.drives[name] !== undefined ? lv.drives[name] : i >= 0 ? fval(f, name, i) : null);
      // Drives off (soldiers): no hunger, libido or fear to show.
      const hasDrives = ef && ef.drives !== undefined ? ef.drives : ['hunger', 'libido', 'fear'].some((n) => (dv(n) || 0) !== 0);
      if (hasDrives) for (const name of ['hunger', 'libido', 'fear']) drives.append(this.drive(name, dv(name)));
      this.explain(id, ef, f, decisionsOf(lv, id, f));
      const decisions = decisionsOf(lv, id, f);
      const stack = lv && lv.stack ? lv.stack.join(' > ') : decisions.length ? decisions[decisions.length - 1].stack : '';
      $('panel-stack').textContent = stack || '–';
      const memBox = $('panel-memory-box');
      const memory = lv && lv.memory ? lv.memory : ef ? ef.memory : null;
      memBox.classList.toggle('hidden', !memory);
      if (memory) $('panel-memory').textContent = Object.keys(memory).length ? JSON.stringify(memory, null, 2) : '(empty)';
      const list = $('panel-history');
      list.textContent = '';
      const shown = decisions.slice(-200).reverse();
      for (const d of shown) {
        const li = el('li');
        li.append(el('b', null, secondsOf(d.tick) + ' '), el('span', null, (d.from || '∅') + ' → ' + (d.to || '∅') + ' '),
          el('span', { class: 'muted' }, '(' + d.cause + ')'));
        if (d.condition) li.append(el('div', { class: 'cond' }, d.condition));
        const why = explainedDecision(id, d.tick, d.to);
        if (why) {
          const box = el('details', { class: 'why', 'data-testid': 'decision-clauses' });
          box.append(el('summary', null, 'clauses at the decision'), clauseList(why.clauses));
          if (why.why_not && why.why_not.length) {
            const wn = el('ul', { class: 'why-not' });
            for (const w of why.why_not) wn.append(el('li', null, 'not ' + w.b + ': ' + w.why));
            box.append(el('div', { class: 'muted' }, 'higher priorities that did not fire'), wn);
          }
          li.append(box);
        }
        list.append(li);
      }
      if (!shown.length) list.append(el('li', { class: 'muted' }, 'no decisions yet'));
    },
      // The explanation section: time in behavior, the steering term in control, target,
    // pressures, why not, script results, meals and catches.
    explain(id, ef, f, decisions) {
      let box = $('panel-explain');
      if (!box) {
        box = el('div', { id: 'panel-explain', 'data-testid': 'panel-explain' });
        $('panel-memory-box').after(box);
      }
      box.textContent = '';
      const dl = el('dl');
      const lv = this.live;
      let tib = null;
      if (lv && lv.time_in_behavior !== undefined) tib = lv.time_in_behavior;
      else if (ef && f && ef.tick === f.tick) tib = ef.time_in_behavior;
      else if (f && decisions.length && tickSeconds()) tib = (f.tick - decisions[decisions.length - 1].tick) * tickSeconds();
      else if (f && tickSeconds()) tib = f.tick * tickSeconds();
      factRow(dl, 'in behavior', tib === null ? '–' : fmt(tib, 2) + ' s', 'panel-time-in-behavior');
      if (ef) {
        factRow(dl, 'steering', ef.term || '–', 'panel-term');
        const t = ef.target;
        factRow(dl, 'target', t ? t.kind + (t.id !== null && t.id !== undefined ? ' ' + t.id : '') + (t.category ? ' (' + t.category + ')' : '')
          + ' at ' + fmt(t.dist, 2) + ' m' : 'none', 'panel-target');
        const sv = ef.steer || [0, 0, 0];
        factRow(dl, 'steer', fmt(Math.hypot(sv[0], sv[1], sv[2]), 2) + ' m/s');
        if (ef.intercept) factRow(dl, 'intercept', ef.intercept.map((v) => fmt(v, 1)).join(', '));
        const p = ef.pressures;
        if (p) factRow(dl, 'pressures', 'L ' + fmt(p.left, 2) + ' R ' + fmt(p.right, 2) + ' U ' + fmt(p.up, 2) + ' D ' + fmt(p.down, 2)
          + ' (acts above ' + fmt(p.threshold, 2) + ')');
        factRow(dl, 'perceives', String((ef.percepts || []).length));
        if (f && ef.tick !== f.tick) factRow(dl, 'explained at', secondsOf(ef.tick));
      } else if (!LIVE) {
        const ex = explainData();
        if (!ex || !ex.present) factRow(dl, 'explain', 'not recorded (shoal run --explain)');
      }
      box.append(dl);
      if (ef && ef.scripts && ef.scripts.length) {
        const ul = el('ul', { class: 'scripts', 'data-testid': 'panel-scripts' });
        for (const s of ef.scripts) ul.append(el('li', null, s.f + '() = ' + (s.v === null ? '–' : s.v)));
        box.append(el('div', { class: 'muted' }, 'script results'), ul);
      }
      if (ef && ef.why_not && ef.why_not.length) {
        const ul = el('ul', { class: 'why-not', 'data-testid': 'panel-why-not' });
        for (const w of ef.why_not) ul.append(el('li', null, w.b + ' (level ' + w.p + '): ' + w.why));
        box.append(el('div', { class: 'muted' }, 'why not a higher priority'), ul);
      }
      const ex = LIVE ? null : explainData();
      const contacts = (ex && ex.contacts[String(id)]) || (lv && lv.contacts) || [];
      const tick = f ? f.tick : Infinity;
      const seen = contacts.filter((c) => c[0] <= tick);
      const count = (k) => seen.filter((c) => c[1] === k).length;
      const line = 'meals ' + count('meal') + ' · catches ' + count('catch') + ' · matings ' + count('mating');
      const last = seen.slice(-3).map((c) => c[1] + ' ' + c[2] + ' at ' + secondsOf(c[0])).join(', ');
      box.append(el('div', { 'data-testid': 'panel-contacts' }, line + (last ? ' (last: ' + last + ')' : '')));
    },
  };

  function decisionsOf(lv, id, f) {
    return lv ? lv.decisions || [] : source.decisions(id, f ? f.tick : 0);
  }
