// Browser test of the explanation of the selected agent, on a real recording made with explain on.
//
//   node tests/browser/explain.test.mjs --page <view.html> [--walker <view.html>] [--shots <dir>]
//
// Selects an agent that has a target (through window.shoal.selectAgentAt at its screen position)
// and checks that the annotation overlay draws its target line and its perception volume (pixels
// of the overlay canvas along the projected line and circle), that the toggle clears them, and
// that the panel shows time in behavior in seconds, the steering term, decision times in seconds
// and the clauses of a decision. --walker: a species without drives or a swimming body (squad
// members) shows neither in the panel. With --shots, writes screenshots for docs/viewer.md there.
// Exits non-zero and prints each failed check on failure.

import fs from 'node:fs';
import path from 'node:path';
import { check, fileUrl, finish, launch, open } from './harness.mjs';

function parseArgs(argv) {
  const out = { page: null, walker: null, shots: null };
  for (let i = 0; i < argv.length; i++) {
    const key = argv[i].replace(/^--/, '');
    if (!(key in out) || i + 1 >= argv.length) {
      console.error('usage: explain.test.mjs --page <view.html> [--shots <dir>]');
      process.exit(2);
    }
    out[key] = path.resolve(argv[++i]);
  }
  return out;
}

// The overlay's pixels around client point (x, y): the largest alpha in a 3×3 box and its color.
async function overlayAt(page, pts) {
  return page.evaluate((pts) => {
    const o = document.getElementById('annot');
    const r = o.getBoundingClientRect(), dpr = o.width / Math.max(1, r.width);
    const g = o.getContext('2d');
    return pts.map(([x, y]) => {
      let best = [0, 0, 0, 0];
      for (let dy = -1; dy <= 1; dy++) {
        for (let dx = -1; dx <= 1; dx++) {
          const px = Math.round((x - r.left) * dpr) + dx, py = Math.round((y - r.top) * dpr) + dy;
          if (px < 0 || py < 0 || px >= o.width || py >= o.height) continue;
          const d = g.getImageData(px, py, 1, 1).data;
          if (d[3] > best[3]) best = [d[0], d[1], d[2], d[3]];
        }
      }
      return best;
    });
  }, pts);
}

async function testPage(context, file, shots) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const frames = await page.evaluate(() => Number(document.querySelector('[data-testid=scrub]').max) + 1);
  // A late frame: agents have made decisions and have targets by then.
  const frame = Math.max(0, frames - 2);
  await page.evaluate((i) => window.shoal.setFrame(i), frame);
  // Select, through the picking hook, an isolated agent on screen whose explained frame names a
  // target with a position on screen.
  const chosen = await page.evaluate(() => {
    const s = window.shoal, r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    const pts = s.ids().map((id) => [id, s.screenPosOf(id)]).filter(([, p]) => p);
    const inside = (p) => p.x > r.left + 40 && p.x < r.right - 40 && p.y > r.top + 40 && p.y < r.bottom - 40;
    let fallback = null;
    for (const [id, p] of pts) {
      if (!inside(p) || !pts.every(([o, q]) => o === id || Math.hypot(q.x - p.x, q.y - p.y) > 12)) continue;
      const got = s.selectAgentAt(p.x, p.y);
      if (got !== id) continue;
      const ef = s.explainedFrame();
      const a = s.annotations();
      if (ef && ef.target && ef.target.pos && a && a.target && a.circle) {
        const len = Math.hypot(a.target.x2 - a.target.x1, a.target.y2 - a.target.y1);
        if (len > 30) return { id, tick: ef.tick, term: ef.term, target: ef.target, a };
        if (!fallback) fallback = { id, tick: ef.tick, term: ef.term, target: ef.target, a };
      }
    }
    if (fallback) s.selectAgentAt(fallback.a.origin.x + r.left, fallback.a.origin.y + r.top);
    return fallback;
  });
  if (!check(chosen !== null, 'selected an agent on screen whose explanation names a target')) {
    await page.close();
    return;
  }
  console.log(`agent ${chosen.id}: ${chosen.term} → ${chosen.target.kind} ${chosen.target.id} at ${chosen.target.dist} m`);
  check((await page.evaluate(() => window.shoal.selected())) === chosen.id, `agent ${chosen.id} is selected`);
  // The camera follows the selected agent: let it settle before reading pixels.
  await page.waitForTimeout(2000);
  const a = await page.evaluate(() => window.shoal.annotations());
  const rect = await page.evaluate(() => {
    const r = document.getElementById('annot').getBoundingClientRect();
    return { left: r.left, top: r.top, width: r.width, height: r.height };
  });
  const client = (x, y) => [x + rect.left, y + rect.top];
  // Along the target line (away from its ends and the distance label at its middle).
  const t = a.target;
  const along = [0.12, 0.25, 0.35, 0.65, 0.8]
    .map((k) => [t.x1 + k * (t.x2 - t.x1), t.y1 + k * (t.y2 - t.y1)])
    .filter(([x, y]) => x > 2 && y > 2 && x < rect.width - 2 && y < rect.height - 2)
    .map(([x, y]) => client(x, y));
  const onLine = await overlayAt(page, along);
  const drawnOnLine = onLine.filter((p) => p[3] > 0).length;
  const yellow = onLine.filter((p) => p[3] > 0 && p[0] > 180 && p[1] > 160 && p[2] < 140).length;
  check(along.length >= 3 && drawnOnLine === along.length, `target line drawn: ${drawnOnLine}/${along.length} overlay pixels along it are painted`);
  check(yellow >= 3, `target line is the target color at ${yellow}/${along.length} points`);
  // Around the perception circle, where it is inside the view.
  const c = a.circle;
  const round = [];
  for (let k = 0; k < 24; k++) {
    const ang = (k / 24) * 2 * Math.PI, x = c.x + c.r * Math.cos(ang), y = c.y + c.r * Math.sin(ang);
    if (x > 2 && y > 2 && x < rect.width - 2 && y < rect.height - 2) round.push(client(x, y));
  }
  const onCircle = await overlayAt(page, round);
  const drawnOnCircle = onCircle.filter((p) => p[3] > 0).length;
  check(round.length >= 6 && drawnOnCircle >= 0.8 * round.length,
    `perception volume drawn: ${drawnOnCircle}/${round.length} overlay pixels on its projected circle (radius ${c.r.toFixed(0)} px)`);
  // Inside the circle but off every line, the overlay is clear: it is a drawing, not a fill.
  const blank = await overlayAt(page, [client(c.x + 0.5 * c.r * Math.cos(2.2), c.y + 0.5 * c.r * Math.sin(2.2))]);
  console.log(`overlay inside the circle: alpha ${blank[0][3]}`);

  // The panel.
  const tib = (await page.locator('[data-testid=panel-time-in-behavior]').textContent()).trim();
  check(/^\d+\.\d\d s$/.test(tib), `panel shows time in behavior in seconds ("${tib}")`);
  const term = (await page.locator('[data-testid=panel-term]').textContent()).trim();
  check(term.length > 0 && term === chosen.term, `panel shows the steering term in control ("${term}")`);
  const target = (await page.locator('[data-testid=panel-target]').textContent()).trim();
  check(/ m$/.test(target), `panel shows the target and its distance ("${target}")`);
  const history = await page.locator('[data-testid=panel-history] li > b').allTextContents();
  check(history.length > 0 && history.every((h) => /^\d+\.\d\d s $/.test(h)), `decision times in seconds (${history.slice(0, 3).join('|')})`);
  const contacts = (await page.locator('[data-testid=panel-contacts]').textContent()).trim();
  check(/^meals \d+ · catches \d+/.test(contacts), `panel shows meals and catches ("${contacts}")`);
  if (shots) {
    fs.mkdirSync(shots, { recursive: true });
    await page.screenshot({ path: path.join(shots, 'explain-annotations.png') });
  }

  // Clauses of a decision: some agent on this frame has an explained decision in its history.
  const withClauses = await page.evaluate(() => {
    const s = window.shoal, r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    for (const id of s.ids()) {
      const p = s.screenPosOf(id);
      if (!p || s.selectAgentAt(p.x, p.y) !== id) continue;
      const box = document.querySelector('[data-testid=decision-clauses]');
      if (box) {
        box.open = true;
        const items = box.querySelectorAll('.clauses li');
        return { id, items: items.length, text: items.length ? items[0].textContent : '' };
      }
    }
    return null;
  });
  check(withClauses !== null && withClauses.items > 0,
    `an agent's decision lists its clauses with values (${withClauses ? 'agent ' + withClauses.id + ': ' + withClauses.text : 'none'})`);
  if (shots && withClauses) await page.locator('[data-testid=agent-panel]').screenshot({ path: path.join(shots, 'explain-panel.png') });

  // The toggle clears the overlay.
  await page.evaluate((id) => {
    const s = window.shoal, p = s.screenPosOf(id);
    if (p) s.selectAgentAt(p.x, p.y);
  }, chosen.id);
  await page.evaluate(() => window.shoal.annotate(false));
  await page.evaluate(() => window.shoal.annotations());
  const off = await overlayAt(page, along);
  check(off.every((p) => p[3] === 0), 'turning annotations off clears the target line');
  await page.evaluate(() => window.shoal.annotate(true));
  check(errors.length === 0, `no script errors${errors.length ? ': ' + errors.join('; ') : ''}`);
  await page.close();
}

async function testWalker(context, file) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const r = await page.evaluate(() => {
    const h = window.shoal;
    h.setFrame(Math.min(20, Number(document.querySelector('[data-testid=scrub]').max)));
    for (const id of h.ids()) {
      const p = h.screenPosOf(id);
      if (p && h.selectAgentAt(p.x, p.y) === id) break;
    }
    return {
      selected: h.selected(),
      anim: !document.getElementById('panel-anim').classList.contains('hidden'),
      drives: document.getElementById('panel-drives').children.length,
      term: (document.querySelector('[data-testid=panel-term]') || {}).textContent || '',
    };
  });
  check(r.selected !== null, `walker: selected agent ${r.selected}`);
  check(!r.anim && r.drives === 0, `walker: no swim phase or tail bend (${r.anim ? 'shown' : 'hidden'}), no drives (${r.drives} rows)`);
  check(r.term.length > 0, `walker: steering term "${r.term}"`);
  check(errors.length === 0, `walker: no script errors${errors.length ? ': ' + errors.join('; ') : ''}`);
  await page.close();
}

const args = parseArgs(process.argv.slice(2));
if (!args.page) {
  console.error('usage: explain.test.mjs --page <view.html> [--shots <dir>]');
  process.exit(2);
}
const session = await launch();
try {
  await testPage(session.context, args.page, args.shots);
  if (args.walker) await testWalker(session.context, args.walker);
} catch (err) {
  check(false, 'test threw: ' + (err && err.stack ? err.stack : err));
} finally {
  await finish(session);
}
