// shoal viewer, health.js: The run-health table and its warnings.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- run health

  // The run's health report (replay: `health.json`; live: streamed about once a second):
  // per-species figures against their bounds, and the warnings; clicking a warning seeks to its
  // tick (replay) and opens its agent.
  const health = {
    format(kind, v) {
      if (v === null || v === undefined) return '–';
      if (kind === 'share') return (v * 100).toFixed(1) + '%';
      if (kind === 'ratio') return v.toFixed(1) + '×';
      if (kind === 'rate') return v.toFixed(2);
      return String(Math.round(v));
    },
    build(h) {
      const box = $('health-box');
      box.classList.remove('hidden');
      const body = $('health');
      body.textContent = '';
      if (!h) {
        body.append(el('div', { class: 'muted', 'data-testid': 'health-none' }, 'no health report for this run'));
        return;
      }
      const n = h.warnings.length;
      // Live figures restart with each version swapped in.
      const since = h.since_tick ? ' (since tick ' + h.since_tick + ')' : '';
      $('health-title').textContent = 'Run health' + since + (n ? ' · ' + n + (n === 1 ? ' warning' : ' warnings') : '');
      const wrap = el('div', { class: 'health-table' });
      const table = el('table', { 'data-testid': 'health-table' });
      const head = el('tr');
      head.append(el('th', null, ''), el('th', { class: 'bound', title: 'bound' }, 'bound'));
      for (const sp of h.species) {
        const th = el('th', { title: sp.name + ' (' + sp.agents + ' agents)' });
        const info = state.species.find((x) => x.name === sp.name);
        if (info) th.style.borderBottomColor = cssColor(info.rgb);
        // Long names may wrap after an underscore.
        sp.name.split('_').forEach((part, k, all) => {
          th.append(document.createTextNode(part + (k < all.length - 1 ? '_' : '')));
          if (k < all.length - 1) th.append(el('wbr'));
        });
        head.append(th);
      }
      table.append(head);
      const unjudged = [];
      h.columns.forEach((c, k) => {
        const tr = el('tr');
        tr.append(el('th', { class: 'fig' }, c.label),
          el('td', { class: 'bound' }, c.bound === null ? '' : '≤' + this.format(c.kind, c.bound)));
        for (const sp of h.species) {
          const over = sp.over[k];
          // Shown but not held to its bound (an upright body's pitch, too few episodes).
          const why = sp.unjudged ? sp.unjudged[k] : null;
          if (why) unjudged.push(sp.name + ' ' + c.label + ': ' + why);
          const attrs = over ? { class: 'over', title: c.label + ' past its bound' }
            : why ? { class: 'unjudged', title: 'not held to its bound: ' + why } : null;
          const td = el('td', attrs, this.format(c.kind, sp.values[k]) + (over ? '!' : why ? '*' : ''));
          tr.append(td);
        }
        table.append(tr);
      });
      wrap.append(table);
      body.append(wrap);
      const list = el('ol', { id: 'health-warnings', 'data-testid': 'health-warnings' });
      for (const w of h.warnings) {
        const li = el('li', { 'data-testid': 'health-warning' });
        if (w.tick !== null) li.dataset.tick = String(w.tick);
        if (w.agent !== null) li.dataset.agent = String(w.agent);
        li.append(el('span', null, w.message));
        const where = [];
        if (w.tick !== null) where.push('t' + w.tick);
        if (w.agent !== null) where.push('#' + w.agent);
        if (where.length) {
          li.append(el('span', { class: 'muted where' }, ' ' + where.join(' · ')));
          li.classList.add('jump');
          li.title = 'show ' + (w.agent !== null ? 'agent ' + w.agent + ' ' : '') + (w.tick !== null ? 'at tick ' + w.tick : '');
          li.addEventListener('click', () => this.jump(w));
        }
        list.append(li);
      }
      if (!n) list.append(el('li', { class: 'muted' }, 'no warnings: every judged figure within its bound'));
      body.append(list);
      if (unjudged.length) {
        body.append(el('p', { class: 'muted', 'data-testid': 'health-unjudged' },
          '* not held to its bound: ' + unjudged.join('; ')));
      }
    },
    jump(w) {
      // Live, the past is gone: the agent is opened where it is now.
      if (!LIVE) {
        source.setPlaying(false);
        if (w.tick !== null) source.setFrame(source.frameOfTick(w.tick));
      }
      if (w.agent !== null) select(w.agent);
      state.dirty = true;
    },
  };
