#!/usr/bin/env node
// Renders the built dashboard (dist/index.html) with a planes JSON, or with the export
// directory of `mlmap export --dashboard DIR` (its planes.js, blocks.js and voxels.js), and saves
// a screenshot once the 3D view has drawn everything.
// Usage: node scripts/screenshot.mjs PLANES.json|DIR OUT.png [WIDTHxHEIGHT] [class|id|height] [reset|top|side]
// (colour by id gives the colours of `mlmap export --octovis`)
// Needs `npm run build` first and /usr/bin/chromium (or CHROMIUM=path).
import { copyFile, mkdir, mkdtemp, readFile, rm, stat, writeFile } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { closeChromium, launchChromium, planesJs, waitDrawn } from './browser.mjs';

const [input, out, size = '1600x1000', colourMode = 'class', view = 'reset'] = process.argv.slice(2);
if (!input || !out || !['reset', 'top', 'side'].includes(view)) {
  console.error('usage: node scripts/screenshot.mjs PLANES.json|DIR OUT.png [WIDTHxHEIGHT] [class|id|height] [reset|top|side]');
  process.exit(2);
}
const [width, height] = size.split('x').map(Number);
const dist = path.join(path.dirname(fileURLToPath(import.meta.url)), '..', 'dist', 'index.html');
if (!existsSync(dist)) {
  console.error(`${dist} is missing: run npm run build in web/ first`);
  process.exit(1);
}

const dir = await mkdtemp(path.join(tmpdir(), 'mlmap-web-shot-'));
const browser = await launchChromium();
try {
  // The page as `mlmap export --dashboard` lays it out: index.html with planes.js beside it.
  await copyFile(dist, path.join(dir, 'index.html'));
  if ((await stat(input)).isDirectory()) {
    // An export directory: its data files beside this build of the page.
    for (const f of ['planes.js', 'blocks.js', 'voxels.js']) {
      if (existsSync(path.join(input, f))) await copyFile(path.join(input, f), path.join(dir, f));
    }
  } else {
    await writeFile(path.join(dir, 'planes.js'), planesJs(await readFile(input, 'utf8')));
  }
  const page = await browser.context.newPage();
  await page.setViewportSize({ width, height });
  await page.goto(pathToFileURL(path.join(dir, 'index.html')).href);
  await page.waitForFunction(() => ['ready', 'error'].includes(document.body.dataset.state));
  if ((await page.getAttribute('body', 'data-state')) !== 'ready') {
    throw new Error(`the dashboard did not load ${input}: ${await page.textContent('#message')}`);
  }
  await page.selectOption('#colour-mode', colourMode);
  if (view !== 'reset') await page.click(`#view-${view}`);
  await waitDrawn(page);
  await mkdir(path.dirname(path.resolve(out)), { recursive: true });
  await page.screenshot({ path: out });
  console.log(`wrote ${out}`);
} finally {
  await closeChromium(browser);
  await rm(dir, { recursive: true, force: true });
}
