// Shared by the browser tests: launching Debian Chromium headless with WebGL, screenshots decoded
// to pixels, and check bookkeeping.

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

export const failures = [];
export function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (!ok) failures.push(what);
  return ok;
}

// Minimal PNG decoder (8-bit, non-interlaced; what Chromium screenshots are) → RGBA.
export function decodePng(buf) {
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

export function nonBackground(img) {
  let n = 0;
  for (let i = 0; i < img.rgba.length; i += 4) {
    if (Math.abs(img.rgba[i] - BACKGROUND[0]) + Math.abs(img.rgba[i + 1] - BACKGROUND[1]) + Math.abs(img.rgba[i + 2] - BACKGROUND[2]) > 18) n++;
  }
  return n;
}

export function differing(a, b) {
  if (a.width !== b.width || a.height !== b.height) return a.width * a.height;
  let n = 0;
  for (let i = 0; i < a.rgba.length; i += 4) {
    if (Math.abs(a.rgba[i] - b.rgba[i]) + Math.abs(a.rgba[i + 1] - b.rgba[i + 1]) + Math.abs(a.rgba[i + 2] - b.rgba[i + 2]) > 30) n++;
  }
  return n;
}

// The canvas as decoded pixels, after the last change was composited.
export async function shot(page) {
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
export async function launch() {
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

// Opens `url` and waits until the viewer is ready (or reports an error); `label` names it in checks.
export async function open(context, url, label) {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  const t0 = Date.now();
  await page.goto(url, { waitUntil: 'load', timeout: 120000 });
  await page.waitForFunction(() => window.shoal && (window.shoal.ready || window.shoal.error), null, { timeout: 120000 });
  const loadMs = Date.now() - t0;
  const error = await page.evaluate(() => window.shoal.error);
  check(!error, `${label}: viewer started${error ? ': ' + error : ''}`);
  return { page, errors, loadMs };
}

// Whether the element with `data-testid=testid` is shown.
export async function visible(page, testid) {
  return page.locator(`[data-testid=${testid}]`).isVisible();
}


// Closes the browser, prints the failed checks and sets the exit code.
export async function finish(session) {
  if (session) {
    await session.context.close().catch(() => {});
    fs.rmSync(session.profile, { recursive: true, force: true });
  }
  if (failures.length) {
    console.error(`\n${failures.length} check(s) failed:\n  - ` + failures.join('\n  - '));
    process.exitCode = 1;
  } else {
    console.log('all browser checks passed');
  }
}

export const fileUrl = (file) => pathToFileURL(file).href;
