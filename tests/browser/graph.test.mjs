// Browser test of the state-machine graph on a real recording (a `shoal run` folder's page):
//
//   node tests/browser/graph.test.mjs --page <view.html> [--shot <png>]
//
// Checks that the graph draws the selected agent's species from its RON data (priority rows,
// transitions seen in the run as edges), that the highlighted node is the agent's behavior in
// every frame as the replay moves (through at least two different behaviors), and that a click
// on a node shows where the behavior is written (file:line:col) and its `when` text.

import { check, finish, launch, open, fileUrl } from './harness.mjs';

const args = {};
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.page) {
  console.error('usage: graph.test.mjs --page <view.html> [--shot <png>]');
  process.exit(2);
}

let session = null;
try {
  session = await launch();
  const { page, errors } = await open(session.context, fileUrl(args.page), 'replay');
  // An agent whose behavior changes during the run, and the frames where it does.
  const pick = await page.evaluate(() => {
    const s = window.shoal;
    const seen = new Map();
    let n = 0;
    for (let i = 0; ; i++) {
      const k = s.setFrame(i);
      if (k !== i) break;
      n = i + 1;
      for (const id of s.ids()) {
        const b = s.behaviorOf(id);
        if (!seen.has(id)) seen.set(id, new Set());
        seen.get(id).add(b);
      }
    }
    let best = null;
    for (const [id, set] of seen) if (!best || set.size > best[1]) best = [id, set.size];
    s.setFrame(0);
    return { frames: n, id: best ? best[0] : null, kinds: best ? best[1] : 0 };
  });
  check(pick.id !== null && pick.kinds >= 2, `an agent changes behavior (agent ${pick.id}, ${pick.kinds} behaviors over ${pick.frames} frames)`);
  await page.evaluate((id) => window.shoal.select(id), pick.id);
  const nextPaint = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  await nextPaint();
  const g0 = await page.evaluate(() => window.shoal.graph());
  check(g0.nodes.length >= 2, `graph drawn for the agent's species: ${g0.nodes.join(', ')}`);
  check(await page.locator('[data-testid=graph-svg] .graph-node').count() === g0.nodes.length, 'one SVG node per behavior');
  const edges = await page.locator('[data-testid=graph-svg] path.graph-edge').count();
  check(g0.edges.length > 0 && edges > 0, `transitions of the run drawn as edges (${edges} drawn, ${g0.edges.length} counted)`);
  const levels = await page.locator('[data-testid=graph-svg] text.graph-level').allTextContents();
  check(levels.length >= 1 && levels.every((t) => /^P\d+$/.test(t)), `priority rows: ${levels.join(' ')}`);

  // The highlight follows the agent through the replay, frame by frame.
  let agree = 0, shown = 0;
  const currents = new Set();
  const stride = Math.max(1, Math.floor(pick.frames / 60));
  for (let i = 0; i < pick.frames; i += stride) {
    await page.evaluate((k) => window.shoal.setFrame(k), i);
    await nextPaint();
    const [g, b] = await page.evaluate((id) => [window.shoal.graph(), window.shoal.behaviorOf(id)], pick.id);
    if (b === null) continue;
    shown++;
    if (g.current === b) agree++;
    currents.add(g.current);
    const hl = await page.locator('[data-testid=graph-svg] .graph-node.current').getAttribute('data-behavior').catch(() => null);
    if (hl !== b) { check(false, `frame ${i}: highlighted node ${hl}, agent's behavior ${b}`); break; }
  }
  check(shown > 0 && agree === shown, `highlight matches the agent's behavior in ${agree}/${shown} frames`);
  check(currents.size >= 2, `the highlight moved across behaviors: ${[...currents].join(', ')}`);
  // Playing: still in step after a moment of playback.
  await page.evaluate(() => { window.shoal.setFrame(0); window.shoal.play(4); });
  await page.waitForTimeout(800);
  await nextPaint();
  const [gp, bp] = await page.evaluate((id) => [window.shoal.graph(), window.shoal.behaviorOf(id)], pick.id);
  check(bp === null || gp.current === bp, `during playback the highlight is the agent's behavior (${gp.current} / ${bp})`);

  // A click on a node shows its source location and condition.
  const node = g0.nodes[0];
  await page.locator(`[data-testid=graph-svg] .graph-node[data-behavior="${node}"]`).click();
  const info = await page.locator('[data-testid=graph-info]').textContent();
  check(/\.ron:\d+:\d+/.test(info) && info.includes(node), `click shows where "${node}" is written: ${info.split('\n').slice(0, 2).join(' · ')}`);
  check(/when: |priority/.test(info), 'and its priority and conditions');
  if (args.shot) {
    await page.locator('[data-testid=graph-box]').screenshot({ path: args.shot });
  }
  check(errors.length === 0, `no page errors${errors.length ? ': ' + errors.join('; ') : ''}`);
} catch (e) {
  check(false, 'graph test threw: ' + (e && e.stack ? e.stack : e));
} finally {
  await finish(session);
}
