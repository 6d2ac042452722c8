// shoal viewer, legend.js: The behavior palette, the legend and the labelled behaviors histogram.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- legend

  // Color of global behavior `b` for an agent of species `s`.
  function behaviorRgb(s, b) {
    const row = state.behaviorRgb[s];
    return (row && row[b]) || behaviorColor(b);
  }

  const legend = {
    // Gives every behavior a palette color: the slot its name hashes to, or the next one far
    // enough (in RGB) from the colors this species already uses. Species are taken in order and
    // a name keeps the slot it first got where it can, so a behavior shared by species looks the
    // same in each; a species' `behavior_colors` win over the palette (and are avoided by it).
    assignColors() {
      const byName = new Map(), index = new Map(state.behaviors.map((b, i) => [b, i]));
      const far = (c, used) => used.reduce((m, u) => Math.min(m, 255 * Math.hypot(c[0] - u[0], c[1] - u[1], c[2] - u[2])), Infinity);
      state.behaviorRgb = state.species.map((sp) => {
        const row = [], own = sp.look ? sp.look.behavior_colors || {} : {};
        const used = sp.behaviors.filter((n) => own[n]).map((n) => hexToRgb(own[n]));
        for (const name of sp.behaviors) {
          const b = index.get(name);
          if (b === undefined) continue;
          if (own[name]) { row[b] = hexToRgb(own[name]); continue; }
          const pref = byName.has(name) ? byName.get(name) : nameHash(name) % PALETTE.length;
          let slot = pref, best = -1;
          for (let k = 0; k < PALETTE.length; k++) {
            const cand = (pref + k) % PALETTE.length, d = far(PALETTE[cand], used);
            if (d >= 70) { slot = cand; break; }
            if (d > best) { best = d; slot = cand; }
          }
          if (!byName.has(name)) byName.set(name, slot);
          used.push(PALETTE[slot]);
          row[b] = PALETTE[slot];
        }
        return row;
      });
    },
    build() {
      const box = $('legend');
      box.textContent = '';
      const swatchRow = (name, rgb, cls) => {
        const row = el('div', cls ? { class: cls } : null);
        const sw = el('span', { class: 'swatch' });
        sw.style.background = cssColor(rgb);
        row.append(sw, el('span', null, name));
        return row;
      };
      if (state.colorMode === 'species') {
        for (const s of state.species) box.append(swatchRow(s.name + ' · ' + s.look.shape, s.rgb));
        return;
      }
      // Behavior mode: one group per species, its behaviors in priority order of the file.
      state.species.forEach((s, si) => {
        const group = el('div', { class: 'lgroup' });
        group.append(el('div', { class: 'lhead' }, s.name));
        for (const name of s.behaviors) {
          const b = state.behaviors.indexOf(name);
          if (b >= 0) group.append(swatchRow(name, behaviorRgb(si, b), 'litem'));
        }
        box.append(group);
      });
    },
  };

  // ---------------------------------------------------------------- histogram

  // Per species: a stacked bar of current behavior shares; live adds a rolling strip chart.
  const histogram = {
    rows: [],
    build() {
      const box = $('histogram');
      box.textContent = '';
      this.rows = state.species.map((s) => {
        const row = el('div', { class: 'hrow' });
        const name = el('div', { class: 'name' });
        const label = el('span', null, s.name), count = el('span', { class: 'muted' }, '');
        name.append(label, count);
        const bar = el('div', { class: 'hbar' });
        const key = el('div', { class: 'hkey' });
        row.append(name, bar, key);
        let strip = null;
        if (LIVE) {
          strip = el('canvas', { class: 'strip', width: '280', height: '36' });
          row.append(strip);
        }
        box.append(row);
        return { bar, count, segs: [], keys: [], key, strip };
      });
    },
    update(frame) {
      const ns = state.species.length, nb = Math.max(1, state.behaviors.length);
      const counts = new Uint32Array(ns * nb), totals = new Uint32Array(ns);
      for (let i = 0; i < frame.n; i++) {
        const s = frame.species[i], b = frame.behavior[i];
        if (s < ns && b < nb) { counts[s * nb + b]++; totals[s]++; }
      }
      for (let s = 0; s < ns && s < this.rows.length; s++) {
        const row = this.rows[s];
        row.count.textContent = String(totals[s]);
        for (let b = 0; b < nb; b++) {
          const c = counts[s * nb + b];
          let seg = row.segs[b];
          if (!seg && c) {
            const rgb = behaviorRgb(s, b);
            seg = row.segs[b] = el('div');
            seg.style.background = cssColor(rgb);
            seg.title = state.behaviors[b];
            row.bar.append(seg);
            // The label under the bar: swatch, name, count.
            const k = row.keys[b] = el('span', { class: 'hlabel' });
            const sw = el('span', { class: 'swatch' });
            sw.style.background = cssColor(rgb);
            k.append(sw, el('span', null, ''));
            row.key.append(k);
          }
          if (seg) {
            const pct = totals[s] ? (100 * c) / totals[s] : 0;
            seg.style.width = pct + '%';
            seg.title = state.behaviors[b] + ': ' + c + ' (' + pct.toFixed(0) + '%)';
            row.keys[b].lastChild.textContent = state.behaviors[b] + ' ' + c;
            row.keys[b].classList.toggle('zero', !c);
          }
        }
        if (row.strip) this.stripColumn(row.strip, counts, s * nb, nb, totals[s], s);
      }
    },
    // Scrolls the strip one pixel left and draws the newest shares at the right edge.
    stripColumn(cv, counts, base, nb, total, s) {
      const ctx = cv.getContext('2d'), w = cv.width, h = cv.height;
      ctx.drawImage(cv, -1, 0);
      ctx.fillStyle = '#1d3a56';
      ctx.fillRect(w - 1, 0, 1, h);
      if (!total) return;
      let y = h;
      for (let b = 0; b < nb; b++) {
        const c = counts[base + b];
        if (!c) continue;
        const hh = (c / total) * h;
        ctx.fillStyle = cssColor(behaviorRgb(s, b));
        ctx.fillRect(w - 1, y - hh, 1, hh);
        y -= hh;
      }
    },
  };
