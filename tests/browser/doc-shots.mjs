// Writes the screenshots of docs/viewer.md from recorded pages (see the "Screenshots" section there).
//
//   node tests/browser/doc-shots.mjs <out dir> <reef view.html> <predator_attack view.html> <squad_march view.html>

import path from 'node:path';
import { fileUrl, finish, launch, open, shot } from './harness.mjs';

const [out, reef, predator, squad] = process.argv.slice(2);
if (!squad) {
  console.error('usage: doc-shots.mjs <out dir> <reef view.html> <predator_attack view.html> <squad_march view.html>');
  process.exit(2);
}

// Opens `file` at recorded frame `frame`, applies `setup` in the page, saves `name`.
async function take(session, file, name, frame, setup, arg) {
  const { page } = await open(session.context, fileUrl(file), name);
  await page.setViewportSize({ width: 1000, height: 620 });
  await page.evaluate((f) => window.shoal.setFrame(f), frame);
  await page.evaluate(() => window.shoalView.refit());
  if (setup) await page.evaluate(setup, arg);
  await shot(page);
  await page.screenshot({ path: path.join(out, name) });
  await page.close();
}

// A close-up of the middle agent of species `s`.
const closeUp = ([s, dist, yaw, pitch]) => {
  const ids = window.shoalView.idsOf(s);
  window.shoalView.focus(ids[Math.floor(ids.length / 2)], dist);
  window.shoalView.setCamera({ yaw, pitch });
};

const session = await launch();
try {
  await take(session, reef, 'viewer-reef.png', 25);
  await take(session, reef, 'viewer-closeup.png', 25, closeUp, [2, 14, 0.9, 0.3]);
  await take(session, reef, 'viewer-jelly.png', 25, closeUp, [3, 6, 0.9, 0.25]);
  await take(session, predator, 'viewer-behaviors.png', 50, () => {
    const m = document.querySelector('[data-testid=color-mode]');
    m.value = 'behavior';
    m.dispatchEvent(new Event('change'));
  });
  await take(session, squad, 'viewer-squad.png', 12, closeUp, [0, 9, 2.2, 0.35]);
} finally {
  await finish(session);
}
