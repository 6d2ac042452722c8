// Browser test of the live page against a stand-in for `shoal watch` on 127.0.0.1:
//
//   node tests/browser/live.test.mjs <live.html>
//
// The stand-in serves the page, the `/stream` event source (world, frame, diagnostics, reload),
// `/control` and `/agent/<id>` as docs/viewer.md describes, and records what the page asked for.

import fs from 'node:fs';
import http from 'node:http';
import { check, finish, launch, nonBackground, open, shot, visible } from './harness.mjs';

const file = process.argv[2];
if (!file) {
  console.error('usage: live.test.mjs <live.html>');
  process.exit(2);
}
const html = fs.readFileSync(file);

const WORLD = {
  bounds: { min: [-30, -10, -30], max: [30, 10, 30] },
  obstacles: [{ id: 0, shape: 'sphere', center: [0, 0, 0], radius: 4, removed_tick: null }],
  species: [
    { name: 'reef_fish', color: '#e0a030', length: 1.0, behaviors: ['wander', 'eat', 'escape'] },
    { name: 'shark', color: '#708090', length: 3.0, behaviors: ['patrol', 'hunt'] },
  ],
  terrain: null,
  plans: [],
};
const AGENTS = 40;

// Agents on a ring, spread out so any one can be clicked; they turn slowly with the tick.
function frame(tick) {
  const f = { tick, time: tick * 0.05, ids: [], species: [], behavior: [], pos: [], fwd: [], speed: [], stack_depth: [], hunger: [], libido: [], fear: [], food: [1, -5, 1, -3, -5, 4] };
  for (let i = 0; i < AGENTS; i++) {
    const a = (i / AGENTS) * Math.PI * 2 + tick * 0.01, r = 22;
    const s = i % 5 === 0 ? 1 : 0;
    f.ids.push(i + 1); f.species.push(s); f.behavior.push(s ? (tick + i) % 2 : (tick + i) % 3);
    f.pos.push(r * Math.cos(a), (i % 4) - 2, r * Math.sin(a));
    f.fwd.push(-Math.sin(a), 0, Math.cos(a));
    f.speed.push(1.5); f.stack_depth.push(1); f.hunger.push(0.4); f.libido.push(0.2); f.fear.push(0.1);
  }
  return f;
}

const controls = [], inspected = [], clients = [];
let tick = 0, paused = false;
function send(event, data, to) {
  for (const res of to ? [to] : clients) res.write(`event: ${event}\ndata: ${JSON.stringify(data)}\n\n`);
}
const server = http.createServer((req, res) => {
  if (req.method === 'GET' && req.url === '/') {
    res.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8' });
    res.end(html);
  } else if (req.method === 'GET' && req.url === '/stream') {
    res.writeHead(200, { 'Content-Type': 'text/event-stream', 'Cache-Control': 'no-cache', Connection: 'keep-alive' });
    clients.push(res);
    req.on('close', () => clients.splice(clients.indexOf(res), 1));
    send('world', WORLD, res);
    send('frame', frame(tick), res);
  } else if (req.method === 'POST' && req.url === '/control') {
    let body = '';
    req.on('data', (c) => { body += c; });
    req.on('end', () => {
      const cmd = JSON.parse(body);
      controls.push(cmd);
      if (cmd.cmd === 'pause') paused = true;
      if (cmd.cmd === 'resume') paused = false;
      if (cmd.cmd === 'step') send('frame', frame(++tick));
      res.writeHead(200, { 'Content-Type': 'application/json' });
      res.end('{"ok":true}');
    });
  } else if (req.method === 'GET' && req.url.startsWith('/agent/')) {
    const id = Number(req.url.slice('/agent/'.length));
    inspected.push(id);
    res.writeHead(200, { 'Content-Type': 'application/json' });
    res.end(JSON.stringify({
      id, species: 'reef_fish', behavior: 'eat', stack: ['wander', 'eat'],
      drives: { hunger: 0.8, libido: 0.1, fear: 0.05 }, memory: { last_food: [1, -5, 1] },
      decisions: [{ tick: 12, from: 'wander', to: 'eat', cause: 'activated', condition: 'hunger > 0.6 and sees food' }],
    }));
  } else {
    res.writeHead(404);
    res.end();
  }
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}`;
// Bounded stream: at most 600 frames, 10 a second, while not paused.
const ticker = setInterval(() => { if (!paused && tick < 600) send('frame', frame(++tick)); }, 100);

const waitFor = async (pred, ms) => {
  const end = Date.now() + ms;
  while (Date.now() < end) { if (pred()) return true; await new Promise((r) => setTimeout(r, 50)); }
  return pred();
};

let session = null;
try {
  session = await launch();
  const { page, errors } = await open(session.context, base + '/', 'live');
  check((await page.evaluate(() => window.shoal.agentCount())) === AGENTS, `live frame shows ${AGENTS} agents`);
  check(nonBackground(await shot(page)) > 500, 'live agents rendered');
  check(await page.locator('[data-testid=histogram] canvas.strip').count() === 2, 'rolling strip chart per species');
  check(!(await visible(page, 'scrub')), 'no timeline slider in live mode');

  const lines = ['scripts/hunt.rhai:4:9: unknown variable `prey`', '4 | let x = prey;', '  |         ^'];
  send('diagnostics', lines);
  await page.locator('[data-testid=diagnostics]').waitFor({ state: 'visible', timeout: 3000 }).catch(() => {});
  check(await visible(page, 'diagnostics'), 'diagnostics overlay shown');
  const text = await page.locator('[data-testid=diagnostics]').textContent();
  check(text === lines.join('\n'), 'diagnostics text is verbatim');
  const font = await page.$eval('[data-testid=diagnostics]', (e) => getComputedStyle(e).fontFamily);
  check(/mono/i.test(font), `diagnostics in monospace (${font})`);
  send('diagnostics', []);
  await page.locator('[data-testid=diagnostics]').waitFor({ state: 'hidden', timeout: 3000 }).catch(() => {});
  check(!(await visible(page, 'diagnostics')), 'empty diagnostics hide the overlay');

  send('reload', { message: 'reloaded behaviors (version 3)' });
  await page.locator('[data-testid=toast]').waitFor({ state: 'visible', timeout: 3000 }).catch(() => {});
  check((await page.locator('[data-testid=toast]').textContent()) === 'reloaded behaviors (version 3)', 'reload shows a toast');

  await page.click('[data-testid=play]');
  check(await waitFor(() => controls.some((c) => c.cmd === 'pause'), 3000), 'pause button posts {cmd:"pause"}');
  await page.click('[data-testid=play]');
  check(await waitFor(() => controls.some((c) => c.cmd === 'resume'), 3000), 'play button posts {cmd:"resume"}');
  await page.selectOption('[data-testid=speed]', '2');
  check(await waitFor(() => controls.some((c) => c.cmd === 'speed' && c.value === 2), 3000), 'speed posts {cmd:"speed",value:2}');
  await page.click('[data-testid=step]');
  check(await waitFor(() => controls.some((c) => c.cmd === 'step'), 3000), 'step button posts {cmd:"step"}');
  check(paused, 'stepping pauses the run');
  const stepped = tick;
  await page.waitForFunction((t) => document.querySelector('[data-testid=clock]').textContent.startsWith('tick ' + t + ' '), stepped, { timeout: 3000 }).catch(() => {});
  check((await page.locator('[data-testid=clock]').textContent()).startsWith('tick ' + stepped + ' '), `clock shows the stepped tick ${stepped}`);

  const target = await page.evaluate(() => ({ id: 6, ...window.shoal.screenPosOf(6) }));
  await page.mouse.click(target.x, target.y);
  await page.locator('[data-testid=agent-panel]').waitFor({ state: 'visible', timeout: 3000 }).catch(() => {});
  check(await visible(page, 'agent-panel'), 'clicking a live agent shows the panel');
  check((await page.locator('[data-testid=panel-id]').textContent()) === '6', 'panel shows id 6');
  check(await waitFor(() => inspected.filter((i) => i === 6).length >= 3, 3000), 'panel polls /agent/6 every 500 ms');
  check((await page.locator('[data-testid=panel-behavior]').textContent()) === 'eat', 'panel shows the inspected behavior');
  const decision = await page.locator('[data-testid=panel-history] li').first().textContent();
  check(decision.includes('wander → eat') && decision.includes('hunger > 0.6 and sees food'), `panel lists the decision (${decision})`);
  await page.keyboard.press('Escape');
  check(!(await visible(page, 'agent-panel')), 'Esc closes the live panel');
  const polls = inspected.length;
  await page.waitForTimeout(1200);
  check(inspected.length === polls, 'polling stops once the panel is closed');
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
} catch (e) {
  check(false, 'live browser test crashed: ' + (e && e.stack ? e.stack : e));
} finally {
  clearInterval(ticker);
  for (const res of clients.splice(0)) res.end();
  server.close();
  await finish(session);
}
