// shoal viewer, legend.js: The legend and the behaviors histogram.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- legend

  const legend = {
    build() {
      const box = $('legend');
      box.textContent = '';
      const items = state.colorMode === 'species'
        ? state.species.map((s) => [s.name, s.rgb])
        : state.behaviors.map((b, i) => [b, behaviorColor(i)]);
      for (const [name, rgb] of items) {
        const row = el('div');
        const sw = el('span', { class: 'swatch' });
        sw.style.background = cssColor(rgb);
        row.append(sw, el('span', null, name));
        box.append(row);
      }
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
        row.append(name, bar);
        let strip = null;
        if (LIVE) {
          strip = el('canvas', { class: 'strip', width: '280', height: '36' });
          row.append(strip);
        }
        box.append(row);
        return { bar, count, segs: [], strip };
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
            seg = row.segs[b] = el('div');
            seg.style.background = cssColor(behaviorColor(b));
            seg.title = state.behaviors[b];
            row.bar.append(seg);
          }
          if (seg) {
            const pct = totals[s] ? (100 * c) / totals[s] : 0;
            seg.style.width = pct + '%';
            seg.title = state.behaviors[b] + ': ' + c + ' (' + pct.toFixed(0) + '%)';
          }
        }
        if (row.strip) this.stripColumn(row.strip, counts, s * nb, nb, totals[s]);
      }
    },
    // Scrolls the strip one pixel left and draws the newest shares at the right edge.
    stripColumn(cv, counts, base, nb, total) {
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
        ctx.fillStyle = cssColor(behaviorColor(b));
        ctx.fillRect(w - 1, y - hh, 1, hh);
        y -= hh;
      }
    },
  };
