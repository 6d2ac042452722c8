// Browser test of the shoal replay page in headless Debian Chromium.
//
//   node tests/browser/view.test.mjs --page <view.html> [--smoke <view.html>] [--perf <view.html>]
//
// --page:  renders agents, scrubbing changes the picture, clicking an agent opens its panel,
//          Esc closes it, color mode changes the picture, play advances.
// --smoke: loads without script errors, draws something, shows the incomplete-run banner.
// --perf:  prints load time and frame rate while playing (no pass/fail threshold).
// --health: the run-health section lists figures and warnings; clicking the warning for tick 131,
//          agent 7 moves the timeline to the nearest recorded frame (tick 130) and opens agent 7.
// --no-health: a run without health.json says it has no report.
// Exits non-zero and prints each failed check on failure.

import fs from 'node:fs';
import path from 'node:path';
import { check, differing, fileUrl, finish, launch, nonBackground, open, shot, visible } from './harness.mjs';

function parseArgs(argv) {
  const out = { page: null, smoke: null, perf: null, health: null, 'no-health': null };
  for (let i = 0; i < argv.length; i++) {
    const key = argv[i].replace(/^--/, '');
    if (!(key in out) || i + 1 >= argv.length) {
      console.error('usage: view.test.mjs --page <view.html> [--smoke <view.html>] [--perf <view.html>] [--health <view.html>] [--no-health <view.html>]');
      process.exit(2);
    }
    out[key] = path.resolve(argv[++i]);
  }
  return out;
}

async function testPage(context, file) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const frames = await page.evaluate(() => Number(document.querySelector('[data-testid=scrub]').max) + 1);
  check(frames > 2, `timeline has ${frames} frames`);
  await page.evaluate(() => window.shoal.setFrame(0));
  const n0 = await page.evaluate(() => window.shoal.agentCount());
  check(n0 > 0, `frame 0 has ${n0} agents`);

  const first = await shot(page);
  const drawn = nonBackground(first);
  check(drawn > 500, `agents rendered: ${drawn} non-background pixels (want > 500)`);

  // Scrub through the slider as a person would: set its value and fire `input`.
  const mid = Math.floor(frames / 2);
  const clockBefore = await page.locator('[data-testid=clock]').textContent();
  await page.$eval('[data-testid=scrub]', (s, v) => {
    s.value = String(v);
    s.dispatchEvent(new Event('input', { bubbles: true }));
  }, mid);
  check((await page.evaluate(() => window.shoal.frameIndex())) === mid, `scrubbing moved to frame ${mid}`);
  const clockAfter = await page.locator('[data-testid=clock]').textContent();
  check(clockBefore !== clockAfter, `clock label changed (${clockAfter})`);
  const second = await shot(page);
  const changed = differing(first, second);
  check(changed > 300, `scrubbing changed the picture: ${changed} pixels differ (want > 300)`);

  // Click an agent with no other agent within 14 px, so the expected pick is unambiguous.
  const target = await page.evaluate(() => {
    const s = window.shoal, pts = s.ids().map((id) => [id, s.screenPosOf(id)]).filter(([, p]) => p);
    const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    for (const [id, p] of pts) {
      if (p.x < r.left + 20 || p.x > r.right - 20 || p.y < r.top + 20 || p.y > r.bottom - 20) continue;
      if (pts.every(([o, q]) => o === id || Math.hypot(q.x - p.x, q.y - p.y) > 14)) return { id, ...p };
    }
    return null;
  });
  if (check(target !== null, 'found an isolated agent on screen to click')) {
    check(!(await visible(page, 'agent-panel')), 'panel hidden before the click');
    await page.mouse.click(target.x, target.y);
    await page.locator('[data-testid=agent-panel]').waitFor({ state: 'visible', timeout: 5000 }).catch(() => {});
    check(await visible(page, 'agent-panel'), `clicking agent ${target.id} at (${target.x.toFixed(0)}, ${target.y.toFixed(0)}) shows the panel`);
    const shownId = (await page.locator('[data-testid=panel-id]').textContent()).trim();
    check(shownId === String(target.id), `panel shows id ${target.id} (got "${shownId}")`);
    check((await page.evaluate(() => window.shoal.selected())) === target.id, 'selected() returns the clicked id');
    const species = (await page.locator('[data-testid=panel-species]').textContent()).trim();
    check(species.length > 0 && species !== '–', `panel shows species "${species}"`);
    const history = await page.locator('[data-testid=panel-history] li').count();
    check(history > 0, `panel lists ${history} decisions`);
    await page.keyboard.press('Escape');
    check(!(await visible(page, 'agent-panel')), 'Esc closes the panel');
    check((await page.evaluate(() => window.shoal.selected())) === null, 'Esc clears the selection');
  }

  const bySpecies = await shot(page);
  await page.selectOption('[data-testid=color-mode]', 'behavior');
  const byBehavior = await shot(page);
  check(differing(bySpecies, byBehavior) > 100, 'coloring by behavior changes the picture');
  const legend = await page.locator('[data-testid=legend] div').count();
  check(legend > 3, `legend lists ${legend} behaviors`);
  const bars = await page.locator('[data-testid=histogram] .hrow').count();
  const nSpecies = await page.evaluate(() => window.shoal.speciesCount());
  check(nSpecies > 0 && bars === nSpecies, `histogram has a bar per species (${bars} of ${nSpecies})`);

  await page.evaluate(() => window.shoal.setFrame(0));
  await page.click('[data-testid=play]');
  await page.waitForTimeout(700);
  const playedTo = await page.evaluate(() => window.shoal.frameIndex());
  check(playedTo > 0, `play advances the timeline (frame ${playedTo})`);
  check(!(await visible(page, 'incomplete-banner')), 'no incomplete banner on a complete run');
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
}

async function testSmoke(context, file) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const drawn = nonBackground(await shot(page));
  check(drawn > 500, `terrain run rendered: ${drawn} non-background pixels`);
  check(await visible(page, 'incomplete-banner'), 'incomplete run shows its banner');
  await page.evaluate(() => window.shoal.setFrame(1e9));
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
}

async function testHealth(context, file) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  check(await visible(page, 'health'), 'run-health section shown');
  const table = await page.locator('[data-testid=health-table] tr').count();
  check(table === 10, `health table has a header and 9 figure rows (${table} rows)`);
  const over = await page.locator('[data-testid=health-table] td.over').allTextContents();
  check(over.length === 1 && over[0].endsWith('!'), `one figure marked past its bound: ${JSON.stringify(over)}`);
  const items = page.locator('[data-testid=health-warning]');
  const n = await items.count();
  check(n === 1, `one warning listed (${n})`);
  const warning = items.first();
  const text = (await warning.textContent()) || '';
  check(text.includes('reef_fish') && text.includes('pitch limit'), `warning names species and figure: "${text}"`);
  await page.evaluate(() => window.shoal.setFrame(0));
  check(!(await visible(page, 'agent-panel')), 'panel hidden before clicking the warning');
  await warning.click();
  await page.locator('[data-testid=agent-panel]').waitFor({ state: 'visible', timeout: 5000 }).catch(() => {});
  const frame = await page.evaluate(() => window.shoal.frameIndex());
  check(frame === 65, `clicking the warning moved to frame 65, tick 130 (frame ${frame})`);
  const scrub = await page.$eval('[data-testid=scrub]', (s) => Number(s.value));
  check(scrub === 65, `scrub bar at frame 65 (${scrub})`);
  const clock = (await page.locator('[data-testid=clock]').textContent()) || '';
  check(clock.startsWith('tick 130 '), `clock shows tick 130 ("${clock}")`);
  check(await visible(page, 'agent-panel'), 'clicking the warning opens the agent panel');
  const shownId = (await page.locator('[data-testid=panel-id]').textContent()).trim();
  check(shownId === '7', `panel shows agent 7 (got "${shownId}")`);
  check((await page.evaluate(() => window.shoal.selected())) === 7, 'selected() is the warning\'s agent');
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
}

async function testNoHealth(context, file) {
  const { page, errors } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  check(await visible(page, 'health-none'), 'a run without health.json says it has no report');
  check((await page.locator('[data-testid=health-warning]').count()) === 0, 'no warnings listed');
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
}

async function measurePerf(context, file) {
  const { page, loadMs } = await open(context, fileUrl(file), path.basename(path.dirname(file)));
  const agents = await page.evaluate(() => window.shoal.agentCount());
  // Each animation frame shows the next recorded frame (new agent data uploaded and drawn), so the
  // rAF rate is the frame rate of continuous playback.
  const result = await page.evaluate(() => new Promise((resolve) => {
    const s = window.shoal, count = Number(document.querySelector('[data-testid=scrub]').max) + 1;
    const t0 = performance.now();
    let n = 0, worst = 0, prev = t0;
    const step = (now) => {
      worst = Math.max(worst, now - prev);
      prev = now;
      s.setFrame(++n % count);
      if (now - t0 < 5000) requestAnimationFrame(step);
      else resolve({ fps: n / ((now - t0) / 1000), worst });
    };
    requestAnimationFrame(step);
  }));
  const mb = fs.statSync(file).size / 1e6;
  console.log(`perf: ${agents} agents, page ${mb.toFixed(1)} MB, load+decode ${loadMs} ms; ` +
    `a new frame every animation frame: ${result.fps.toFixed(1)} fps, worst gap ${result.worst.toFixed(0)} ms`);
  await page.close();
}

const args = parseArgs(process.argv.slice(2));
if (!args.page && !args.smoke && !args.perf && !args.health && !args['no-health']) parseArgs(['--help']);
let session = null;
try {
  session = await launch();
  if (args.page) await testPage(session.context, args.page);
  if (args.smoke) await testSmoke(session.context, args.smoke);
  if (args.perf) await measurePerf(session.context, args.perf);
  if (args.health) await testHealth(session.context, args.health);
  if (args['no-health']) await testNoHealth(session.context, args['no-health']);
} catch (e) {
  check(false, 'browser test crashed: ' + (e && e.stack ? e.stack : e));
} finally {
  await finish(session);
}
