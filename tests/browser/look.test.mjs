// How the replay page looks, checked on pixels in headless Debian Chromium.
//
//   node tests/browser/look.test.mjs --page <view.html> [--page <view.html> …] [--shots <dir>]
//                                    [--fps <view.html>]
//
// --page: per recording: each species drawn alone has its look's color and a silhouette of its
//         shape family (two species of different shapes differ in silhouette; two of the same
//         shape differ in color or size); pixels inside each obstacle's projected disk are the
//         rock's color, not what lies behind it; the camera's eye is above the ground; behavior
//         colors within a species are distinct; the legend fits the view in both color modes;
//         playback blends between recorded frames and a pause shows the recorded frame.
// --shots: also saves a screenshot of each page (and of the behavior mode) there.
// --fps:  prints the frame rate of continuous playback (page size, agents, frames); no threshold.
// Exits non-zero and prints each failed check on failure.

import fs from 'node:fs';
import path from 'node:path';
import { check, fileUrl, finish, launch, open, shot } from './harness.mjs';

function parseArgs(argv) {
  const out = { page: [], shots: null, fps: null };
  for (let i = 0; i < argv.length; i++) {
    const key = argv[i].replace(/^--/, '');
    if (!(key in out) || i + 1 >= argv.length) {
      console.error('usage: look.test.mjs --page <view.html> [--page …] [--shots <dir>] [--fps <view.html>]');
      process.exit(2);
    }
    const v = path.resolve(argv[++i]);
    if (key === 'page') out.page.push(v); else out[key] = v;
  }
  return out;
}

const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

// Intersection over union of two silhouette grids ('0'/'1' strings).
function iou(a, b) {
  let both = 0, either = 0;
  for (let i = 0; i < a.length; i++) {
    if (a[i] === '1' && b[i] === '1') both++;
    if (a[i] === '1' || b[i] === '1') either++;
  }
  return either ? both / either : 1;
}

// Cosine of the angle between two colors: 1 when one is the other lit more or less.
function hueMatch(a, b) {
  const n = Math.hypot(...a) * Math.hypot(...b);
  return n ? (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / n : 0;
}

async function testPage(context, file, shots) {
  const label = path.basename(path.dirname(file));
  const { page, errors } = await open(context, fileUrl(file), label);
  const frames = await page.evaluate(() => Number(document.querySelector('[data-testid=scrub]').max) + 1);
  await page.evaluate((i) => window.shoal.setFrame(i), Math.floor(frames / 2));

  // Each species alone, side-on.
  const looks = await page.evaluate(() => window.shoalView.looks());
  const portraits = [];
  for (let s = 0; s < looks.length; s++) {
    const p = await page.evaluate((k) => window.shoalView.portrait(k, 0.5), s);
    portraits.push(p);
    if (!check(p && p.pixels > 2000, `${label}: ${looks[s].name} (${looks[s].shape}) drawn alone covers ${p ? p.pixels : 0} pixels (want > 2000)`)) continue;
    const m = hueMatch(p.color, p.expected);
    check(m > 0.97, `${label}: ${looks[s].name} is drawn in its look's color ${looks[s].color} (mean [${p.color.map((v) => v.toFixed(0))}], match ${m.toFixed(3)})`);
  }
  for (let a = 0; a < looks.length; a++) {
    for (let b = a + 1; b < looks.length; b++) {
      const pa = portraits[a], pb = portraits[b];
      if (!pa || !pb || !pa.grid || !pb.grid) continue;
      const overlap = iou(pa.grid, pb.grid);
      const what = `${looks[a].name} (${pa.shape}) and ${looks[b].name} (${pb.shape})`;
      if (pa.shape !== pb.shape) {
        check(overlap < 0.8 || Math.abs(Math.log(pa.aspect / pb.aspect)) > 0.3,
          `${label}: ${what} have different silhouettes (overlap ${overlap.toFixed(2)}, aspect ${pa.aspect.toFixed(2)} vs ${pb.aspect.toFixed(2)})`);
      } else {
        const sizes = Math.abs(Math.log(looks[a].length / looks[b].length));
        check(dist(pa.expected, pb.expected) > 40 || sizes > 0.2,
          `${label}: ${what} share a shape and differ in color or size`);
      }
    }
  }

  // Obstacles are solid: inside each one's projected disk, the rock's color.
  await page.evaluate(() => window.shoalView.refit());
  const obstacles = await page.evaluate(() => window.shoalView.obstacles());
  const rect = await page.evaluate(() => { const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect(); return { l: r.left, t: r.top, r: r.right, b: r.bottom }; });
  let seen = 0;
  for (const o of obstacles) {
    if (o.eyeInside || o.r < 8 || o.x - o.r < rect.l || o.x + o.r > rect.r || o.y - o.r < rect.t || o.y + o.r > rect.b) continue;
    seen++;
    const pts = [];
    for (let k = 0; k < 12; k++) {
      const a = (k / 12) * Math.PI * 2, rr = o.r * (k % 2 ? 0.45 : 0.2);
      pts.push([o.x + Math.cos(a) * rr, o.y + Math.sin(a) * rr]);
    }
    pts.push([o.x, o.y]);
    const px = await page.evaluate((p) => window.shoalView.pixelsAt(p), pts);
    let rocky = 0, odd = '';
    for (let k = 0; k < pts.length; k++) {
      const c = px.withRocks[k], behind = px.without[k];
      if (!c || !behind) continue;
      if (!odd) odd = ` (e.g. [${c}] over [${behind}], rock [${px.rock.map(Math.round)}])`;
      // The rock's stone, lit more or less: its hue, and not what is drawn without it.
      if (hueMatch(c, px.rock) > 0.97 && dist(c, px.background) > 40 && dist(c, behind) > 15) rocky++;
    }
    check(rocky >= pts.length * 0.8, `${label}: obstacle ${o.id} (${o.shape}, ${o.r.toFixed(0)} px) is solid: ${rocky}/${pts.length} pixels inside its disk are rock${rocky < pts.length ? odd : ''}`);
  }
  if (obstacles.length) check(seen > 0, `${label}: at least one of ${obstacles.length} obstacles is fully in view (${seen})`);

  // The camera is above the ground.
  const cam = await page.evaluate(() => window.shoalView.camera());
  check(cam.ground === null || cam.eye[1] > cam.ground, `${label}: the camera's eye (y ${cam.eye[1].toFixed(1)}) is above the ground (${cam.ground === null ? 'none' : cam.ground.toFixed(1)})`);

  // Behavior colors: distinct within each species.
  for (const sp of await page.evaluate(() => window.shoalView.behaviorColors())) {
    let worst = Infinity, pair = '';
    for (let a = 0; a < sp.behaviors.length; a++) {
      for (let b = a + 1; b < sp.behaviors.length; b++) {
        const d = dist(sp.behaviors[a][1], sp.behaviors[b][1]);
        if (d < worst) { worst = d; pair = sp.behaviors[a][0] + '/' + sp.behaviors[b][0]; }
      }
    }
    if (sp.behaviors.length > 1) check(worst > 60, `${label}: ${sp.name}'s ${sp.behaviors.length} behavior colors are distinct (closest ${pair}: ${worst.toFixed(0)})`);
  }

  // The legend fits the view in both color modes.
  for (const mode of ['species', 'behavior']) {
    await page.selectOption('[data-testid=color-mode]', mode);
    const fit = await page.evaluate(() => {
      const l = document.querySelector('[data-testid=legend]'), st = document.getElementById('stage');
      const a = l.getBoundingClientRect(), b = st.getBoundingClientRect();
      return { inside: a.left >= b.left && a.right <= b.right + 0.5 && a.top >= b.top && a.bottom <= b.bottom + 0.5, scrolls: (l.scrollHeight <= l.clientHeight + 1 || getComputedStyle(l).overflowY === 'auto') && l.scrollWidth <= l.clientWidth + 1, rows: l.querySelectorAll('.swatch').length };
    });
    check(fit.inside && fit.scrolls && fit.rows > 0, `${label}: the ${mode} legend (${fit.rows} rows) fits the view`);
    if (shots) {
      const name = label.replace(/[^a-z0-9_-]/gi, '_') + (mode === 'species' ? '' : '-behavior') + '.png';
      await page.evaluate(() => window.shoalView.refit());
      await shot(page);
      await page.screenshot({ path: path.join(shots, name) });
    }
  }
  await page.selectOption('[data-testid=color-mode]', 'species');

  // Playback is blended between recorded frames; a pause shows the recorded frame.
  if (frames > 2) {
    await page.evaluate(() => window.shoal.setFrame(0));
    const seen = await page.evaluate(() => new Promise((resolve) => {
      window.shoal.play(0.5);
      let best = 0, n = 0;
      const look = () => {
        const b = window.shoalView.blend();
        if (b.blended && b.alpha > 0 && b.alpha < 1) best = Math.max(best, Math.min(b.alpha, 1 - b.alpha));
        if (++n < 40) requestAnimationFrame(look); else resolve(best);
      };
      requestAnimationFrame(look);
    }));
    check(seen > 0.05, `${label}: playing draws agents between recorded frames (blend up to ${seen.toFixed(2)} of the way)`);
    await page.keyboard.press(' ');
    const paused = await page.evaluate(() => window.shoalView.blend());
    check(!paused.blended && paused.alpha === 0, `${label}: paused, the recorded frame is drawn as is`);
  }
  check(errors.length === 0, `${label}: no script errors${errors.length ? ': ' + errors.join(' | ') : ''}`);
  await page.close();
}

async function measureFps(context, file) {
  const { page, loadMs } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const agents = await page.evaluate(() => window.shoal.agentCount());
  const frames = await page.evaluate(() => Number(document.querySelector('[data-testid=scrub]').max) + 1);
  // Plays at the recording's own speed (each animation frame draws a blend of two recorded
  // frames, and a new recorded frame is uploaded every few); counts the drawn frames.
  const r = await page.evaluate(() => new Promise((resolve) => {
    window.shoal.setFrame(0);
    const s0 = window.shoal.stats(), t0 = performance.now();
    let worst = 0, prev = t0;
    window.shoal.play(1);
    const tick = (now) => {
      worst = Math.max(worst, now - prev);
      prev = now;
      if (now - t0 < 8000) requestAnimationFrame(tick);
      else {
        const s1 = window.shoal.stats();
        resolve({ fps: (s1.renders - s0.renders) / ((now - t0) / 1000), recorded: s1.frames - s0.frames, worst });
      }
    };
    requestAnimationFrame(tick);
  }));
  const mb = fs.statSync(file).size / 1e6;
  console.log(`fps: ${agents} agents × ${frames} frames, page ${mb.toFixed(1)} MB, load+decode ${loadMs} ms; ` +
    `playing: ${r.fps.toFixed(1)} drawn frames/s (${r.recorded} recorded frames shown in 8 s), worst gap ${r.worst.toFixed(0)} ms`);
  await page.close();
}

const args = parseArgs(process.argv.slice(2));
if (!args.page.length && !args.fps) parseArgs(['--help']);
if (args.shots) fs.mkdirSync(args.shots, { recursive: true });
let session = null;
try {
  session = await launch();
  for (const p of args.page) await testPage(session.context, p, args.shots);
  if (args.fps) await measureFps(session.context, args.fps);
} catch (e) {
  check(false, 'browser test crashed: ' + (e && e.stack ? e.stack : e));
} finally {
  await finish(session);
}
