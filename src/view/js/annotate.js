// shoal viewer, annotate.js: Annotations of the selected agent on a 2D overlay above the 3D view
// (OpenSteer style): its perception volume, what it perceives, its target with a line and the
// distance, the steering vector with the term that won, avoid pressures, a pursuit's intercept
// point and its path. Toggled with the "explain" button or the `a` key. Reads the explained
// frame (`explainedFrame`, panel.js) and the shown frame; draws nothing into the GL canvas.
// The files of js/ are parts of one function scope, joined in the order view/mod.rs lists them.
  // ---------------------------------------------------------------- annotations

  const annotate = {
    on: true,
    overlay: null,
    ctx: null,
    drawnFor: '',
    // Positions of the selected agent by tick, as frames were shown (its path).
    path: new Map(),
    pathOf: null,
    // What the last draw put on the overlay, in CSS pixels of the overlay (for tests).
    last: null,
    init() {
      if (this.overlay) return;
      const o = document.createElement('canvas');
      o.id = 'annot';
      o.setAttribute('data-testid', 'annotations');
      o.style.cssText = 'position:absolute;inset:0;width:100%;height:100%;pointer-events:none;z-index:2';
      canvas.after(o);
      this.overlay = o;
      this.ctx = o.getContext('2d');
      const b = el('button', { id: 'annot-toggle', type: 'button', title: 'Explain the selected agent (a)', 'data-testid': 'annot-toggle' }, 'explain');
      b.classList.toggle('active', this.on);
      b.addEventListener('click', () => this.toggle());
      const bar = $('topbar');
      if (bar) bar.append(b);
      window.addEventListener('keydown', (e) => {
        if (e.target && (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT')) return;
        if (e.key === 'a') this.toggle();
      });
      const tick = () => { this.maybeDraw(); requestAnimationFrame(tick); };
      requestAnimationFrame(tick);
    },
    toggle(v) {
      this.on = v === undefined ? !this.on : !!v;
      const b = $('annot-toggle');
      if (b) b.classList.toggle('active', this.on);
      this.drawnFor = '';
      this.maybeDraw();
      return this.on;
    },
    maybeDraw() {
      const f = state.frame;
      const key = [this.on, state.selected, state.renders, f ? f.tick : -1, panel.live ? panel.live.tick : -1].join(',');
      if (key === this.drawnFor) return;
      this.drawnFor = key;
      this.draw();
    },
    // Client point of world point `p` on the overlay (CSS px), or null behind the camera.
    project(p, vp, w, h) {
      const cw = vp[3] * p[0] + vp[7] * p[1] + vp[11] * p[2] + vp[15];
      if (cw <= 1e-6) return null;
      const cx = (vp[0] * p[0] + vp[4] * p[1] + vp[8] * p[2] + vp[12]) / cw;
      const cy = (vp[1] * p[0] + vp[5] * p[1] + vp[9] * p[2] + vp[13]) / cw;
      return { x: (cx * 0.5 + 0.5) * w, y: (0.5 - cy * 0.5) * h, w: cw };
    },
    draw() {
      const o = this.overlay;
      if (!o) return;
      const dpr = window.devicePixelRatio || 1;
      const w = o.clientWidth, h = o.clientHeight;
      if (o.width !== Math.round(w * dpr) || o.height !== Math.round(h * dpr)) { o.width = Math.round(w * dpr); o.height = Math.round(h * dpr); }
      const g = this.ctx;
      g.setTransform(1, 0, 0, 1, 0, 0);
      g.clearRect(0, 0, o.width, o.height);
      this.last = null;
      const f = state.frame, id = state.selected;
      if (id === null || !f) return;
      const i = indexOfId(f, id);
      if (i < 0) return;
      const p = [f.pos[3 * i], f.pos[3 * i + 1], f.pos[3 * i + 2]];
      if (this.pathOf !== id) { this.path = new Map(); this.pathOf = id; }
      this.path.set(f.tick, p);
      if (!this.on) return;
      g.setTransform(dpr, 0, 0, dpr, 0, 0);
      const vp = computeViewProj();
      const at = this.project(p, vp, w, h);
      if (!at) return;
      const drawn = { origin: at };
      const ef = explainedFrame(id, f.tick);
      const line = (a, b, color, width, dash) => {
        g.strokeStyle = color; g.lineWidth = width; g.setLineDash(dash || []);
        g.beginPath(); g.moveTo(a.x, a.y); g.lineTo(b.x, b.y); g.stroke();
        g.setLineDash([]);
      };
      const label = (text, x, y, color) => {
        g.font = '12px sans-serif';
        const m = g.measureText(text).width;
        g.fillStyle = 'rgba(8,20,32,0.75)'; g.fillRect(x + 4, y - 13, m + 6, 16);
        g.fillStyle = color; g.fillText(text, x + 7, y);
      };
      // Its path: where it was on the frames shown so far, up to now.
      const ticks = [...this.path.keys()].filter((t) => t <= f.tick).sort((a, b) => a - b).slice(-200);
      if (ticks.length > 1) {
        g.strokeStyle = 'rgba(255,255,255,0.45)'; g.lineWidth = 1.5; g.beginPath();
        let started = false;
        for (const t of ticks) {
          const s = this.project(this.path.get(t), vp, w, h);
          if (!s) { started = false; continue; }
          if (started) g.lineTo(s.x, s.y); else { g.moveTo(s.x, s.y); started = true; }
        }
        g.stroke();
      }
      if (!ef) {
        label(LIVE ? 'waiting for the explanation…' : 'no explanation recorded (shoal run --explain)', at.x + 8, at.y - 8, '#c8d4e0');
        this.last = drawn;
        return;
      }
      // Perception volume: the vision sphere's outline, its horizontal circle and the cone (the
      // smell sphere for a species that does not see).
      const R = ef.vision ? ef.vision.radius || ef.vision.smell || 0 : 0;
      if (R > 0) {
        const rpx = R * vp.projF * (h / 2) / at.w;
        g.strokeStyle = 'rgba(120,200,255,0.85)'; g.lineWidth = 1.5;
        g.beginPath(); g.arc(at.x, at.y, rpx, 0, 2 * Math.PI); g.stroke();
        drawn.circle = { x: at.x, y: at.y, r: rpx };
        g.strokeStyle = 'rgba(120,200,255,0.4)'; g.lineWidth = 1; g.beginPath();
        for (let k = 0; k <= 48; k++) {
          const a = (k / 48) * 2 * Math.PI;
          const s = this.project([p[0] + R * Math.cos(a), p[1], p[2] + R * Math.sin(a)], vp, w, h);
          if (!s) continue;
          if (k === 0) g.moveTo(s.x, s.y); else g.lineTo(s.x, s.y);
        }
        g.stroke();
        const half = ef.vision.half_angle;
        if (half < 3.1) {
          const fx = f.fwd[3 * i], fz = f.fwd[3 * i + 2];
          for (const sgn of [-1, 1]) {
            const c = Math.cos(sgn * half), s = Math.sin(sgn * half);
            const d = [fx * c - fz * s, 0, fx * s + fz * c];
            const n = Math.hypot(d[0], d[2]) || 1;
            const e = this.project([p[0] + R * d[0] / n, p[1], p[2] + R * d[2] / n], vp, w, h);
            if (e) line(at, e, 'rgba(120,200,255,0.6)', 1, [4, 3]);
          }
        }
      }
      // What it perceives.
      const colors = { Kin: '#7fd0a0', Mate: '#e06090', Food: '#f0d060', Predator: '#ff6050', Prey: '#ffa040', Obstacle: '#b0b0c0', Other: '#9fb3c8' };
      for (const q of ef.percepts || []) {
        const s = this.project(q.pos, vp, w, h);
        if (s) line(at, s, colors[q.c] || '#9fb3c8', 0.75, [2, 3]);
      }
      // Its target, with the distance.
      if (ef.target && ef.target.pos) {
        const s = this.project(ef.target.pos, vp, w, h);
        if (s) {
          line(at, s, '#ffe040', 2.5);
          g.fillStyle = '#ffe040'; g.beginPath(); g.arc(s.x, s.y, 4, 0, 2 * Math.PI); g.fill();
          label(ef.target.kind + ' ' + (ef.target.id !== null && ef.target.id !== undefined ? ef.target.id + ' ' : '') + fmt(ef.target.dist, 1) + ' m',
            (at.x + s.x) / 2, (at.y + s.y) / 2, '#ffe040');
          drawn.target = { x1: at.x, y1: at.y, x2: s.x, y2: s.y };
        }
      }
      // A pursuit's predicted intercept point.
      if (ef.intercept) {
        const s = this.project(ef.intercept, vp, w, h);
        if (s) {
          g.strokeStyle = '#ff60ff'; g.lineWidth = 2; g.beginPath();
          g.moveTo(s.x - 5, s.y - 5); g.lineTo(s.x + 5, s.y + 5); g.moveTo(s.x - 5, s.y + 5); g.lineTo(s.x + 5, s.y - 5); g.stroke();
          line(at, s, 'rgba(255,96,255,0.6)', 1, [5, 4]);
          drawn.intercept = s;
        }
      }
      // The steering vector (1 s of the desired velocity), labelled with the term that won.
      if (ef.steer) {
        const e = this.project([p[0] + ef.steer[0], p[1] + ef.steer[1], p[2] + ef.steer[2]], vp, w, h);
        if (e) {
          line(at, e, '#60ff90', 2);
          const a = Math.atan2(e.y - at.y, e.x - at.x);
          g.fillStyle = '#60ff90'; g.beginPath(); g.moveTo(e.x, e.y);
          g.lineTo(e.x - 9 * Math.cos(a - 0.4), e.y - 9 * Math.sin(a - 0.4));
          g.lineTo(e.x - 9 * Math.cos(a + 0.4), e.y - 9 * Math.sin(a + 0.4)); g.fill();
          label(ef.term || '', e.x, e.y, '#60ff90');
          drawn.steer = { x1: at.x, y1: at.y, x2: e.x, y2: e.y };
        }
      }
      // Avoid pressures: four bars around the agent, red past the threshold where they act.
      const pr = ef.pressures;
      if (pr) {
        const bar = (v, dx, dy) => {
          const len = Math.min(40, 40 * v);
          if (len <= 0.5) return;
          g.strokeStyle = v > pr.threshold ? '#ff5040' : 'rgba(255,160,64,0.8)'; g.lineWidth = 4;
          g.beginPath(); g.moveTo(at.x + dx * 10, at.y + dy * 10); g.lineTo(at.x + dx * (10 + len), at.y + dy * (10 + len)); g.stroke();
        };
        bar(pr.left, -1, 0); bar(pr.right, 1, 0); bar(pr.up, 0, -1); bar(pr.down, 0, 1);
      }
      this.last = drawn;
    },
  };

  // Set up before the page boots (the GL canvas and the top bar are already in the page).
  setTimeout(() => {
    annotate.init();
    if (window.shoal) {
      window.shoal.annotate = (v) => annotate.toggle(v);
      window.shoal.annotations = () => { annotate.drawnFor = ''; annotate.maybeDraw(); return annotate.last; };
      window.shoal.explainedFrame = () => (state.frame && state.selected !== null ? explainedFrame(state.selected, state.frame.tick) : null);
    }
  }, 0);
