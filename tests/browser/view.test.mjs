// Browser test of the shoal replay page in headless Debian Chromium.
//
//   node tests/browser/view.test.mjs --page <view.html> [--smoke <view.html>] [--perf <view.html>]
//
// --page:  renders agents, scrubbing changes the picture, clicking an agent opens its panel,
//          Esc closes it, color mode changes the picture, play advances.
// --smoke: loads without script errors, draws something, shows the incomplete-run banner.
// --perf:  prints load time and frame rate while playing (no pass/fail threshold).
// Exits non-zero and prints each failed check on failure.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import zlib from 'node:zlib';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const CHROMIUM = process.env.SHOAL_CHROMIUM || '/usr/bin/chromium';
const BASE_ARGS = [
  '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
];
const SWIFTSHADER_ARGS = ['--use-angle=swiftshader', '--enable-unsafe-swiftshader'];
// The page's clear color (#0b1a2a).
const BACKGROUND = [11, 26, 42];

const failures = [];
function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (!ok) failures.push(what);
  return ok;
}

function parseArgs(argv) {
  const out = { page: null, smoke: null, perf: null };
  for (let i = 0; i < argv.length; i++) {
    const key = argv[i].replace(/^--/, '');
    if (!(key in out) || i + 1 >= argv.length) {
      console.error('usage: view.test.mjs --page <view.html> [--smoke <view.html>] [--perf <view.html>]');
      process.exit(2);
    }
    out[key] = path.resolve(argv[++i]);
  }
  return out;
}

// Minimal PNG decoder (8-bit, non-interlaced; what Chromium screenshots are) → RGBA.
function decodePng(buf) {
  let pos = 8, width = 0, height = 0, depth = 0, type = 0, interlace = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos), kind = buf.toString('ascii', pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (kind === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      depth = data[8]; type = data[9]; interlace = data[12];
    } else if (kind === 'IDAT') idat.push(data);
    else if (kind === 'IEND') break;
    pos += 12 + len;
  }
  const bpp = { 0: 1, 2: 3, 4: 2, 6: 4 }[type];
  if (depth !== 8 || interlace || !bpp) throw new Error(`unsupported PNG (depth ${depth}, type ${type})`);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * bpp, rgba = Buffer.alloc(width * height * 4);
  let prev = Buffer.alloc(stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const cur = Buffer.alloc(stride);
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? cur[x - bpp] : 0, b = prev[x], c = x >= bpp ? prev[x - bpp] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      cur[x] = v & 255;
    }
    for (let x = 0; x < width; x++) {
      const o = (y * width + x) * 4, s = x * bpp;
      if (bpp >= 3) { rgba[o] = cur[s]; rgba[o + 1] = cur[s + 1]; rgba[o + 2] = cur[s + 2]; } else { rgba[o] = rgba[o + 1] = rgba[o + 2] = cur[s]; }
      rgba[o + 3] = 255;
    }
    prev = cur;
  }
  return { width, height, rgba };
}

function nonBackground(img) {
  let n = 0;
  for (let i = 0; i < img.rgba.length; i += 4) {
    if (Math.abs(img.rgba[i] - BACKGROUND[0]) + Math.abs(img.rgba[i + 1] - BACKGROUND[1]) + Math.abs(img.rgba[i + 2] - BACKGROUND[2]) > 18) n++;
  }
  return n;
}

function differing(a, b) {
  if (a.width !== b.width || a.height !== b.height) return a.width * a.height;
  let n = 0;
  for (let i = 0; i < a.rgba.length; i += 4) {
    if (Math.abs(a.rgba[i] - b.rgba[i]) + Math.abs(a.rgba[i + 1] - b.rgba[i + 1]) + Math.abs(a.rgba[i + 2] - b.rgba[i + 2]) > 30) n++;
  }
  return n;
}

async function shot(page) {
  // Two animation frames so the last state change is composited.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  return decodePng(await page.locator('[data-testid=canvas]').screenshot());
}

async function webglWorks(context) {
  const page = await context.newPage();
  try {
    return await page.evaluate(() => {
      const c = document.createElement('canvas');
      return !!(c.getContext('webgl2') || c.getContext('webgl'));
    });
  } finally {
    await page.close();
  }
}

// A headless Chromium with WebGL, from a fresh profile; software GL flags only when needed.
async function launch() {
  for (const extra of [[], SWIFTSHADER_ARGS]) {
    const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'shoal-chromium-'));
    const context = await chromium.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      headless: true,
      args: [...BASE_ARGS, ...extra],
      viewport: { width: 1280, height: 800 },
      deviceScaleFactor: 1,
    });
    if (await webglWorks(context)) {
      console.log('chromium ' + context.browser()?.version?.() + ' WebGL ok' + (extra.length ? ' (' + extra.join(' ') + ')' : ''));
      return { context, profile };
    }
    await context.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  throw new Error('WebGL is not available in headless Chromium, even with SwiftShader');
}

async function open(context, file) {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  const t0 = Date.now();
  await page.goto(pathToFileURL(file).href, { waitUntil: 'load', timeout: 120000 });
  await page.waitForFunction(() => window.shoal && (window.shoal.ready || window.shoal.error), null, { timeout: 120000 });
  const loadMs = Date.now() - t0;
  const error = await page.evaluate(() => window.shoal.error);
  check(!error, `${path.basename(path.dirname(file))}: viewer started${error ? ': ' + error : ''}`);
  return { page, errors, loadMs };
}

async function visible(page, testid) {
  return page.locator(`[data-testid=${testid}]`).isVisible();
}

async function testPage(context, file) {
  const { page, errors } = await open(context, file);
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
  check(bars === 3, `histogram has a bar per species (${bars})`);

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
  const { page, errors } = await open(context, file);
  const drawn = nonBackground(await shot(page));
  check(drawn > 500, `terrain run rendered: ${drawn} non-background pixels`);
  check(await visible(page, 'incomplete-banner'), 'incomplete run shows its banner');
  await page.evaluate(() => window.shoal.setFrame(1e9));
  check(errors.length === 0, 'no script errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await page.close();
}

async function measurePerf(context, file) {
  const { page, loadMs } = await open(context, file);
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
if (!args.page && !args.smoke && !args.perf) parseArgs(['--help']);
let session = null;
try {
  session = await launch();
  if (args.page) await testPage(session.context, args.page);
  if (args.smoke) await testSmoke(session.context, args.smoke);
  if (args.perf) await measurePerf(session.context, args.perf);
} catch (e) {
  check(false, 'browser test crashed: ' + (e && e.stack ? e.stack : e));
} finally {
  if (session) {
    await session.context.close().catch(() => {});
    fs.rmSync(session.profile, { recursive: true, force: true });
  }
}
if (failures.length) {
  console.error(`\n${failures.length} check(s) failed:\n  - ` + failures.join('\n  - '));
  process.exit(1);
}
console.log('all browser checks passed');
