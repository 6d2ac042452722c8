// shoal viewer, panel.js: The agent panel: what the selected agent is doing and why.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- agent panel

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
      const phase = i >= 0 ? fval(f, 'swim_phase', i) : null, bend = i >= 0 ? fval(f, 'tail_bend', i) : null;
      $('panel-anim').textContent = phase === null && bend === null ? '–'
        : 'swim phase ' + fmt(phase, 2) + ', tail bend ' + fmt(bend, 3) + ' rad';
      $('panel-status').textContent = source.agentStatus(id, i >= 0);
      const drives = $('panel-drives');
      drives.textContent = '';
      for (const name of ['hunger', 'libido', 'fear']) {
        const v = lv && lv.drives && lv.drives[name] !== undefined ? lv.drives[name] : i >= 0 ? fval(f, name, i) : null;
        drives.append(this.drive(name, v));
      }
      const decisions = lv ? lv.decisions || [] : source.decisions(id, f ? f.tick : 0);
      const stack = lv && lv.stack ? lv.stack.join(' > ') : decisions.length ? decisions[decisions.length - 1].stack : '';
      $('panel-stack').textContent = stack || '–';
      const memBox = $('panel-memory-box');
      memBox.classList.toggle('hidden', !(lv && lv.memory));
      if (lv && lv.memory) $('panel-memory').textContent = JSON.stringify(lv.memory, null, 2);
      const list = $('panel-history');
      list.textContent = '';
      const shown = decisions.slice(-200).reverse();
      for (const d of shown) {
        const li = el('li');
        li.append(el('b', null, 't' + d.tick + ' '), el('span', null, (d.from || '∅') + ' → ' + (d.to || '∅') + ' '),
          el('span', { class: 'muted' }, '(' + d.cause + ')'));
        if (d.condition) li.append(el('div', { class: 'cond' }, d.condition));
        list.append(li);
      }
      if (!shown.length) list.append(el('li', { class: 'muted' }, 'no decisions yet'));
    },
  };
