// Browser test of `shoal watch` itself: the real server, the real simulation, real file edits.
//
//   node tests/browser/watch.test.mjs --url http://127.0.0.1:PORT/ --species <fish.ron> --agents N
//
// Checks that the page connects and shows the agents moving, that a broken edit of the species
// file brings up the error overlay (with the file:line:col of the problem) and that fixing it
// hides the overlay, then pause, step, the behavior histogram and clicking an agent.

import fs from 'node:fs';
import { check, differing, finish, launch, nonBackground, open, shot, visible } from './harness.mjs';

function parseArgs(argv) {
  const out = { url: null, species: null, agents: null };
  for (let i = 0; i < argv.length; i += 2) {
    const key = argv[i].replace(/^--/, '');
    if (!(key in out) || i + 1 >= argv.length) {
      console.error('usage: watch.test.mjs --url <url> --species <species.ron> --agents <n>');
      process.exit(2);
    }
    out[key] = argv[i + 1];
  }
  if (!out.url || !out.species || !out.agents) parseArgs(['--help']);
  return out;
}

const args = parseArgs(process.argv.slice(2));
const original = fs.readFileSync(args.species, 'utf8');
const clockTick = (text) => Number((/tick (\d+)/.exec(text || '') || [])[1]);

let session = null;
try {
  session = await launch();
  const { page, errors } = await open(session.context, args.url, 'shoal watch');
  const count = await page.evaluate(() => window.shoal.agentCount());
  check(count === Number(args.agents), `live view shows ${count} agents (expected ${args.agents})`);
  check(nonBackground(await shot(page)) > 300, 'agents rendered');

  // Agents move: the clock advances and the picture changes.
  const clock = page.locator('[data-testid=clock]');
  const t0 = clockTick(await clock.textContent());
  const before = await shot(page);
  await page.waitForTimeout(1500);
  const t1 = clockTick(await clock.textContent());
  const after = await shot(page);
  check(t1 > t0 + 5, `the clock advances (tick ${t0} → ${t1})`);
  const moved = differing(before, after);
  check(moved > 50, `agents move on screen (${moved} pixels changed)`);

  // A broken edit: the overlay appears with the diagnostic, the run goes on.
  const broken = original.replace('Above(Drive(Hunger), 0.95)', 'Abov(Drive(Hunger), 0.95)');
  const lineNo = broken.slice(0, broken.indexOf('Abov(')).split('\n').length;
  const tBreak = Date.now();
  fs.writeFileSync(args.species, broken);
  const overlay = page.locator('[data-testid=diagnostics]');
  await overlay.waitFor({ state: 'visible', timeout: 10000 }).catch(() => {});
  check(await visible(page, 'diagnostics'), `error overlay shown ${Date.now() - tBreak} ms after the broken save`);
  const text = (await overlay.textContent()) || '';
  check(text.includes(`fish.ron:${lineNo}:`) && text.includes('Abov'), `overlay names the file, line and problem: ${text.split('\n')[0]}`);
  check(text.includes('when: Abov(Drive(Hunger), 0.95),'), 'overlay shows the offending line');
  const tb = clockTick(await clock.textContent());
  await page.waitForTimeout(600);
  check(clockTick(await clock.textContent()) > tb, 'the last good version keeps running');

  // The fix: the overlay goes away and a reload is announced.
  const tFix = Date.now();
  fs.writeFileSync(args.species, original.replace(/0\.95/g, '0.5'));
  await overlay.waitFor({ state: 'hidden', timeout: 10000 }).catch(() => {});
  check(!(await visible(page, 'diagnostics')), `error overlay hidden ${Date.now() - tFix} ms after the fix`);
  const toast = page.locator('[data-testid=toast]');
  await toast.waitFor({ state: 'visible', timeout: 5000 }).catch(() => {});
  const toastText = (await toast.textContent()) || '';
  check(/version 1/.test(toastText), `reload toast: ${toastText}`);

  // Pause and step one tick.
  await page.waitForTimeout(700);
  await page.click('[data-testid=play]');
  await page.waitForTimeout(500);
  const p0 = clockTick(await clock.textContent());
  await page.waitForTimeout(600);
  const p1 = clockTick(await clock.textContent());
  check(p0 === p1, `paused: the clock stays at tick ${p0} (${p1})`);
  await page.click('[data-testid=step]');
  await page.waitForFunction((t) => /tick (\d+)/.exec(document.querySelector('[data-testid=clock]').textContent)?.[1] === String(t + 1), p1, { timeout: 5000 }).catch(() => {});
  check(clockTick(await clock.textContent()) === p1 + 1, `step advances exactly one tick (${p1} → ${clockTick(await clock.textContent())})`);

  // Behaviors per species over time.
  check(await page.locator('[data-testid=histogram] canvas.strip').count() === 1, 'behavior strip chart for the species');

  // Click a fish that switched from wandering to grazing after the fix: its panel lists the
  // decision. Which fish did, and when, depends on the tick the paused run reached (wall-clock
  // timing), so the server's answer picks it; the panel must then show what the server says.
  const ids = await page.evaluate(() => window.shoal.ids());
  let grazer = null;
  for (const id of ids) {
    const info = await (await fetch(new URL('/agent/' + id, args.url))).json();
    const last = info.decisions[info.decisions.length - 1];
    const switched = last && last.from === 'wander' && last.to === 'graze';
    if (info.behavior === 'graze' && info.stack.includes('wander') && switched) { grazer = id; break; }
  }
  check(grazer !== null, `a fish that switched from wandering to grazing exists (${grazer})`);
  if (grazer !== null) {
    const pos = await page.evaluate((id) => window.shoal.screenPosOf(id), grazer);
    await page.mouse.click(pos.x, pos.y);
    await page.locator('[data-testid=agent-panel]').waitFor({ state: 'visible', timeout: 5000 }).catch(() => {});
    check(await visible(page, 'agent-panel'), 'clicking an agent opens its panel');
    const picked = await page.evaluate(() => window.shoal.selected());
    check(picked === grazer, `the clicked agent is selected (${picked})`);
    await page.waitForFunction(() => document.querySelector('[data-testid=panel-behavior]').textContent === 'graze', null, { timeout: 5000 }).catch(() => {});
    check((await page.locator('[data-testid=panel-behavior]').textContent()) === 'graze', 'panel shows the current behavior');
    // The panel fills its fields as the agent's details arrive: wait for the stack as for the behavior.
    await page.waitForFunction(() => (document.querySelector('#panel-stack')?.textContent ?? '').includes('wander'), null, { timeout: 5000 }).catch(() => {});
    check((await page.locator('#panel-stack').textContent()).includes('wander'), 'panel shows the stack');
    const history = (await page.locator('[data-testid=panel-history] li').first().textContent()) || '';
    check(history.includes('wander → graze') && history.includes('hunger > 0.5'), `panel lists the decision and its cause (${history})`);
    const drives = await page.locator('[data-testid=panel-drives]').textContent();
    check(/hunger/.test(drives), 'panel shows the drives');
  }
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
} catch (e) {
  check(false, 'watch browser test crashed: ' + (e && e.stack ? e.stack : e));
} finally {
  fs.writeFileSync(args.species, original);
  await finish(session);
}
