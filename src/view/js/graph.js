// shoal viewer, graph.js: The state machine drawn: each species' behaviors from its RON file.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- state-machine graph

  // Generated from `world.species[s].behavior_info` (priority level, interrupt flag, condition
  // texts, source location) and the transitions seen in the run (replay: every transition of
  // events.jsonl; live: behavior changes between the frames received), never edited by hand.
  // Follows the selected agent: its current behavior is highlighted and its stack numbered.
  const SVG_NS = 'http://www.w3.org/2000/svg';
  const graph = {
    species: -1, // species index drawn
    nodes: [], // [{name, x, y, w, h, g: <g>, info}]
    current: null, // highlighted behavior name
    stack: [], // the selected agent's stack, bottom first
    seenWorld: null,
    seenFrame: null,
    seenSelected: undefined,
    pinned: false, // the species was chosen in the select: do not follow the selection
    liveEdges: new Map(), // live: "s\tfrom\tto" -> count
    liveLast: new Map(), // live: agent id -> [species, behavior name]
    stackAsked: 0,

    // Transition counts of species `s` as [[from, to, n]].
    edgesOf(s) {
      const name = state.species[s] && state.species[s].name;
      const out = [];
      if (!LIVE && source && source.meta) {
        for (const [sp, from, to, n] of source.meta.transition_counts || []) if (sp === name) out.push([from, to, n]);
      } else {
        for (const [k, n] of this.liveEdges) {
          const [sp, from, to] = k.split('\t');
          if (Number(sp) === s) out.push([from, to, n]);
        }
      }
      return out;
    },

    // Counts live transitions from one frame to the next (frames may skip ticks: a change
    // through a short-lived behavior shows as one edge).
    countLive(f) {
      for (let i = 0; i < f.n; i++) {
        const id = f.ids[i], s = f.species[i], b = state.behaviors[f.behavior[i]];
        const last = this.liveLast.get(id);
        if (last && last[0] === s && last[1] !== b) {
          const k = s + '\t' + last[1] + '\t' + b;
          this.liveEdges.set(k, (this.liveEdges.get(k) || 0) + 1);
        }
        this.liveLast.set(id, [s, b]);
      }
    },

    fillSelect() {
      const sel = $('graph-species');
      sel.textContent = '';
      state.species.forEach((s, i) => sel.append(el('option', { value: String(i) }, s.name)));
      sel.value = String(Math.max(0, this.species));
    },

    // Lays out species `s`: one row per priority level (1 at the top), nodes spread along it.
    build(s) {
      this.species = s;
      const box = $('graph');
      box.textContent = '';
      this.nodes = [];
      const world = state.world && state.world.species ? state.world.species[s] : null;
      if (!world) return;
      const names = world.behaviors || [];
      const info = world.behavior_info || [];
      const levels = [...new Set(names.map((_, j) => (info[j] ? info[j].priority : 1)))].sort((a, b) => a - b);
      const W = 280, rowH = 46, nodeH = 22, padL = 26;
      const H = Math.max(1, levels.length) * rowH + 8;
      const svg = document.createElementNS(SVG_NS, 'svg');
      const attr = (e, a) => { for (const k in a) e.setAttribute(k, a[k]); return e; };
      const mk = (tag, a) => attr(document.createElementNS(SVG_NS, tag), a);
      attr(svg, { viewBox: '0 0 ' + W + ' ' + H, width: String(W), height: String(H), 'data-testid': 'graph-svg' });
      const defs = mk('defs', {});
      const marker = mk('marker', { id: 'graph-arrow', viewBox: '0 0 8 8', refX: '7', refY: '4', markerWidth: '7', markerHeight: '7', markerUnits: 'userSpaceOnUse', orient: 'auto-start-reverse' });
      marker.append(mk('path', { d: 'M0,0 L8,4 L0,8 z', fill: '#9fb3c8' }));
      defs.append(marker);
      svg.append(defs);
      const edgeLayer = mk('g', { class: 'graph-edges' });
      svg.append(edgeLayer);
      levels.forEach((p, r) => {
        const y = 6 + r * rowH + nodeH / 2 + 8;
        const label = mk('text', { x: '2', y: String(y + 4), class: 'graph-level' });
        label.textContent = 'P' + p;
        svg.append(label);
        // The behaviors of the species' list on this level; a composed one is drawn as a
        // dashed box named after it, holding its parts (labelled by their own names: `bite` for
        // `eat/bite`), so the slots are shared out by leaf count.
        const top = names.map((n, j) => [n, j]).filter(([, j]) => !(info[j] && info[j].parent) && (info[j] ? info[j].priority : 1) === p);
        const leavesOf = (n) => names.map((m, j) => [m, j]).filter(([m, j]) => m.startsWith(n + '/') && !(info[j] && info[j].kind && info[j].kind !== 'leaf'));
        const units = top.map(([n, j]) => (info[j] && info[j].kind && info[j].kind !== 'leaf') ? Math.max(1, leavesOf(n).length) : 1);
        const unit = (W - padL - 4) / Math.max(1, units.reduce((a, b) => a + b, 0));
        let left = padL;
        const node = (n, j, x0, slot, label) => {
          const w = Math.min(slot - 6, Math.max(40, label.length * 6.2 + 12));
          const x = x0 + (slot - w) / 2;
          const g = mk('g', { class: 'graph-node', 'data-behavior': n, tabindex: '0' });
          const bi = info[j] || {};
          const rect = mk('rect', { x: String(x), y: String(y - nodeH / 2), width: String(w), height: String(nodeH), rx: '5' });
          if (bi.initial) rect.classList.add('initial');
          if (bi.equal_may_interrupt === false) rect.classList.add('no-equal-interrupt');
          const t = mk('text', { x: String(x + w / 2), y: String(y + 4), 'text-anchor': 'middle' });
          t.textContent = label.length * 6.2 + 12 > w ? label.slice(0, Math.max(3, Math.floor((w - 12) / 6.2))) + '…' : label;
          const badge = mk('text', { x: String(x + w - 3), y: String(y - nodeH / 2 + 8), 'text-anchor': 'end', class: 'graph-stack' });
          const title = mk('title', {});
          title.textContent = n + ' · P' + (bi.priority || '?') + (bi.source ? ' · ' + bi.source : '');
          g.append(title, rect, t, badge);
          g.addEventListener('click', () => this.show(n));
          svg.append(g);
          this.nodes.push({ name: n, x, y, w, h: nodeH, g, badge, info: bi });
        };
        top.forEach(([n, j], k) => {
          const slot = units[k] * unit;
          const bi = info[j] || {};
          if (bi.kind && bi.kind !== 'leaf') {
            const box = mk('g', { class: 'graph-group', 'data-behavior': n });
            const frame = mk('rect', { x: String(left + 1), y: String(y - nodeH / 2 - 11), width: String(slot - 2), height: String(nodeH + 14), rx: '6' });
            const name = mk('text', { x: String(left + 5), y: String(y - nodeH / 2 - 2), class: 'graph-group-name' });
            name.textContent = n + (bi.kind === 'sequence' ? ' →' : bi.kind === 'fallback' ? ' ?' : '');
            const title = mk('title', {});
            title.textContent = n + ' (' + bi.kind + ') · P' + (bi.priority || '?') + (bi.source ? ' · ' + bi.source : '');
            box.append(title, frame, name);
            box.addEventListener('click', () => this.show(n));
            svg.append(box);
            this.nodes.push({ name: n, x: left, y, w: slot, h: nodeH, g: box, badge: name, info: bi, group: true });
            const parts = leavesOf(n);
            const ps = slot / Math.max(1, parts.length);
            parts.forEach(([m, pj], q) => node(m, pj, left + q * ps, ps, m.slice(n.length + 1)));
          } else {
            node(n, j, left, slot, n);
          }
          left += slot;
        });
      });
      // Edges: transitions seen, width by count (log scale), curved so both directions show.
      const at = new Map(this.nodes.map((n) => [n.name, n]));
      const edges = this.edgesOf(s);
      const max = Math.max(1, ...edges.map((e) => e[2]));
      for (const [from, to, n] of edges) {
        const a = at.get(from), b = at.get(to);
        if (!a || !b || a === b) continue;
        const x1 = a.x + a.w / 2, y1 = a.y, x2 = b.x + b.w / 2, y2 = b.y;
        const dx = x2 - x1, dy = y2 - y1, len = Math.hypot(dx, dy) || 1;
        const mx = (x1 + x2) / 2 - (dy / len) * 14, my = (y1 + y2) / 2 + (dx / len) * 14;
        // End at the target's border, not its centre.
        const ex = x2 - (dx / len) * (b.h / 2 + 2), ey = y2 - (dy / len) * (b.h / 2 + 2);
        const path = mk('path', {
          d: 'M' + x1 + ',' + y1 + ' Q' + mx + ',' + my + ' ' + ex + ',' + ey,
          class: 'graph-edge', 'marker-end': 'url(#graph-arrow)',
          'stroke-width': String(0.8 + 3.2 * Math.log1p(n) / Math.log1p(max)),
          'data-from': from, 'data-to': to, 'data-count': String(n),
        });
        const title = mk('title', {});
        title.textContent = from + ' → ' + to + ': ' + n;
        path.append(title);
        edgeLayer.append(path);
      }
      box.append(svg);
      this.current = null;
      this.paint();
    },

    // The behavior's place in the RON file and its conditions, under the graph.
    show(name) {
      const n = this.nodes.find((x) => x.name === name);
      if (!n) return;
      const i = n.info;
      const lines = [name + ' · priority ' + (i.priority || '?') + (i.initial ? ' · initial' : '')
        + (i.equal_may_interrupt === false ? ' · equal levels may not interrupt' : '')];
      if (i.source) lines.push(i.source);
      if (i.when) lines.push('when: ' + i.when);
      if (i.done) lines.push('done: ' + i.done);
      const box = $('graph-info');
      box.textContent = lines.join('\n');
      box.classList.remove('hidden');
    },

    // Highlights the current behavior and numbers the stack.
    paint() {
      for (const n of this.nodes) {
        if (n.group) {
          // A composed behavior is current while one of its parts is.
          n.g.classList.toggle('current', !!this.current && this.current.startsWith(n.name + '/'));
          continue;
        }
        n.g.classList.toggle('current', n.name === this.current);
        const k = this.stack.indexOf(n.name);
        n.g.classList.toggle('stacked', k >= 0 && n.name !== this.current);
        n.badge.textContent = k >= 0 && this.stack.length > 1 ? String(k + 1) : '';
      }
      $('graph-stack').textContent = this.stack.length ? 'stack: ' + this.stack.join(' > ') : '';
    },

    // Called every animation frame: cheap unless the world, frame or selection changed.
    follow() {
      if (!state.world || !state.frame) return;
      const worldChanged = state.world !== this.seenWorld;
      const frameChanged = state.frame !== this.seenFrame;
      const selChanged = state.selected !== this.seenSelected;
      if (!worldChanged && !frameChanged && !selChanged) return;
      this.seenWorld = state.world;
      this.seenFrame = state.frame;
      this.seenSelected = state.selected;
      if (LIVE && frameChanged) this.countLive(state.frame);
      $('graph-box').classList.remove('hidden');
      const f = state.frame;
      const i = state.selected === null ? -1 : indexOfId(f, state.selected);
      let s = this.species < 0 ? 0 : this.species;
      if (i >= 0 && !this.pinned) s = f.species[i];
      if (worldChanged) this.fillSelect();
      if (worldChanged || s !== this.species || (LIVE && frameChanged && state.applied % 20 === 0)) {
        this.build(s);
        $('graph-species').value = String(s);
      }
      const cur = i >= 0 && f.species[i] === this.species ? state.behaviors[f.behavior[i]] : null;
      this.current = cur;
      this.stack = cur ? this.stackOf(state.selected, f, cur) : [];
      this.paint();
    },

    // The selected agent's stack: replay reads its decision history; live asks the server now
    // and then (the frame carries the depth only).
    stackOf(id, f, cur) {
      if (!LIVE) {
        const d = source.decisions(id, f.tick);
        const last = d.length ? d[d.length - 1].stack : '';
        // The recorded stack holds the behaviors under the current one.
        const st = last ? last.split(' > ') : [];
        if (st[st.length - 1] !== cur) st.push(cur);
        return st;
      }
      const now = performance.now();
      if (now - this.stackAsked > 1000) {
        this.stackAsked = now;
        source.inspect(id).then((info) => {
          if (!info || state.selected !== id || !Array.isArray(info.stack)) return;
          // The stack under the current behavior, then the current one.
          const st = info.stack.slice();
          if (info.behavior && st[st.length - 1] !== info.behavior) st.push(info.behavior);
          this.stack = st;
          this.paint();
        });
      }
      return this.stack.length && this.stack[this.stack.length - 1] === cur ? this.stack : [cur];
    },

    snapshot() {
      return {
        species: this.species,
        current: this.current,
        stack: this.stack.slice(),
        nodes: this.nodes.filter((n) => !n.group).map((n) => n.name),
        groups: this.nodes.filter((n) => n.group).map((n) => n.name),
        edges: this.nodes.length ? this.edgesOf(this.species) : [],
        info: $('graph-info').textContent,
      };
    },
  };

  $('graph-species').addEventListener('change', (e) => {
    graph.pinned = true;
    graph.build(Number(e.target.value));
    graph.seenFrame = null;
  });

  // Called by the page's animation loop (main.js) right after the frame advances, so the
  // highlight is never a frame behind the agents.
  function followGraph() {
    try { graph.follow(); } catch (err) { /* the graph must never stop the page */ }
  }
