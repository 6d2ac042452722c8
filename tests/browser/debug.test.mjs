// Browser test of live debugging against `shoal watch` itself (started paused):
//
//   node tests/browser/debug.test.mjs --url http://127.0.0.1:PORT/ --dart-line N [--shots DIR]
//
// The fish species has `dart` (priority 2, `when: Chance(..)`) over `wander`; its script throws
// in `oops()` after some decision passes. Checks: the graph is drawn from the species' RON data
// with the source line of `dart`; bad breakpoints get a 400 with a reason; a breakpoint "any fish
// enters dart" set from the page pauses the run at the tick of the transition (the page's frame,
// the hook and `/control` agree, and the run stays there), the triggering agent is selected and
// its graph node highlighted; step advances exactly one tick; after the breakpoints are removed
// and the run is stepped on, the script error shows in the page within 1 s of its tick, naming
// agent, species, function and file:line:col.

import { check, finish, launch, open } from './harness.mjs';

const args = {};
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.url || !args['dart-line']) {
  console.error('usage: debug.test.mjs --url <url> --dart-line <n> [--shots <dir>]');
  process.exit(2);
}

let session = null;
try {
  session = await launch();
  const { page, errors } = await open(session.context, args.url, 'shoal watch --paused');
  const control = () => page.evaluate(() => fetch('/control').then((r) => r.json()));
  const post = (body) => page.evaluate((b) => fetch('/control', { method: 'POST', body: b })
    .then((r) => r.json().then((j) => ({ status: r.status, body: j }))), body);

  // The graph, from the RON data.
  await page.waitForFunction(() => window.shoal.graph().nodes.length >= 2, null, { timeout: 10000 }).catch(() => {});
  const g = await page.evaluate(() => window.shoal.graph());
  check(g.nodes.includes('dart') && g.nodes.includes('wander'), `graph nodes: ${g.nodes.join(', ')}`);
  await page.locator('[data-testid=graph-svg] .graph-node[data-behavior="dart"]').click();
  const info = await page.locator('[data-testid=graph-info]').textContent();
  check(info.includes(`fish.ron:${args['dart-line']}:`) && info.includes('when: '), `node click shows the source: ${info.split('\n').slice(0, 3).join(' · ')}`);

  // Hostile breakpoint bodies: 400 with a reason.
  for (const [body, says] of [
    ['{"cmd":"break"}', 'on'],
    ['{"cmd":"break","on":"enter"}', 'behavior'],
    ['{"cmd":"break","on":"enter","behavior":"dart","agent":"x"}', 'agent'],
    ['{"cmd":"break","on":"explode","behavior":"dart"}', 'unknown'],
    ['not json', 'JSON'],
  ]) {
    const r = await post(body);
    check(r.status === 400 && String(r.body.error || '').includes(says), `${body} → ${r.status} ${r.body.error}`);
  }

  // A breakpoint from the page's form: any fish entering dart.
  await page.locator('[data-testid=break-on]').selectOption('enter');
  await page.locator('[data-testid=break-behavior]').fill('dart');
  await page.locator('[data-testid=break-who]').fill('fish');
  await page.locator('[data-testid=break-add]').click();
  await page.waitForFunction(() => document.querySelectorAll('[data-testid=break-list] li').length === 1, null, { timeout: 5000 }).catch(() => {});
  const st0 = await control();
  check(st0.breakpoints.length === 1 && st0.breakpoints[0].text === 'any fish: enters dart', `/control lists it: ${JSON.stringify(st0.breakpoints)}`);
  // (The page does not know the session started paused: resume through the endpoint.)
  await post('{"cmd":"resume"}');
  await page.waitForFunction(() => window.shoal.breakHit(), null, { timeout: 20000 }).catch(() => {});
  const hit = await page.evaluate(() => window.shoal.breakHit());
  check(!!hit && hit.reason.includes('entered dart'), `breakpoint hit: ${hit && hit.reason}`);
  if (hit) {
    await page.waitForTimeout(600);
    const st = await control();
    const frameTick = await page.evaluate(() => window.shoal.frameTick());
    check(st.paused && st.hit && st.hit.tick === hit.tick, `/control: paused at tick ${st.tick}, hit at ${st.hit && st.hit.tick}`);
    check(st.tick === hit.tick && frameTick === hit.tick, `the run stopped at the breakpoint's tick (${hit.tick}; status ${st.tick}, page frame ${frameTick})`);
    const clock = await page.locator('[data-testid=clock]').textContent();
    check(clock.includes('tick ' + hit.tick), `the page's clock says so: ${clock}`);
    await page.waitForFunction((id) => window.shoal.selected() === id && window.shoal.graph().current, hit.agent, { timeout: 3000 }).catch(() => {});
    const sel = await page.evaluate(() => [window.shoal.selected(), window.shoal.graph().current, window.shoal.behaviorOf(window.shoal.selected())]);
    check(sel[0] === hit.agent && sel[1] === 'dart' && sel[2] === 'dart', `agent ${sel[0]} selected, graph highlights ${sel[1]} (frame: ${sel[2]})`);
    if (args.shots) await page.screenshot({ path: args.shots + '/viewer-breakpoint.png' });
    // Step: exactly one tick (a second hit in that tick is at that tick too).
    await page.locator('[data-testid=step]').click();
    await page.waitForFunction((t) => window.shoal.frameTick() === t + 1, hit.tick, { timeout: 5000 }).catch(() => {});
    const st2 = await control();
    check(st2.tick === hit.tick + 1 && st2.paused, `step: tick ${hit.tick} → ${st2.tick}, still paused`);
  }
  const rm = await post('{"cmd":"unbreak"}');
  check(rm.status === 200 && (await control()).breakpoints.length === 0, 'unbreak removes them');

  // Step on until the script fails; the error shows within 1 s of the step that ran its tick.
  const err = await page.evaluate(async () => {
    const s = window.shoal, box = document.querySelector('[data-testid=script-errors]');
    const shown = () => !box.classList.contains('hidden');
    const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
    if (shown()) return { early: true };
    for (let k = 0; k < 400; k++) {
      const before = s.frameTick(), t0 = performance.now();
      await fetch('/control', { method: 'POST', body: '{"cmd":"step"}' });
      while (performance.now() - t0 < 3000) {
        if (shown()) return { ms: performance.now() - t0, steps: k + 1, tick: s.frameTick(), text: box.textContent };
        if (s.frameTick() > before) break;
        await sleep(5);
      }
    }
    return { never: true };
  });
  check(!err.early && !err.never, `a script error shows while stepping (${JSON.stringify(err).slice(0, 80)})`);
  if (err.ms !== undefined) {
    check(err.ms < 1000, `the script error shows ${err.ms.toFixed(0)} ms after the tick that raised it`);
    check(/agent \d+ \(fish\) in oops\(\)/.test(err.text) && /fish\.rhai:\d+:\d+/.test(err.text), `it names agent, species, function and place: ${err.text.slice(0, 160)}`);
    const listed = await page.evaluate(() => window.shoal.scriptErrors());
    check(listed.length >= 1 && listed[0].function === 'oops', 'the hook lists it');
    if (args.shots) await page.screenshot({ path: args.shots + '/viewer-script-error.png' });
  }
  // The hostile bodies above were answered 400 on purpose; anything else is a page error.
  const unexpected = errors.filter((e) => !e.includes('status of 400'));
  check(unexpected.length === 0, `no page errors${unexpected.length ? ': ' + unexpected.join('; ') : ''}`);
} catch (e) {
  check(false, 'debug test threw: ' + (e && e.stack ? e.stack : e));
} finally {
  await finish(session);
}
