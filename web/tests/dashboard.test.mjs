// End-to-end test of the built dashboard (dist/index.html) in headless Debian chromium.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdir, mkdtemp, readFile, writeFile, copyFile, rm } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { closeChromium, launchChromium, serveDir, planesJs, waitDrawn } from '../scripts/browser.mjs';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const dist = path.join(web, 'dist', 'index.html');
const fixtures = path.join(web, 'tests', 'fixtures');
const output = path.join(web, 'test-output');
const labText = await readFile(path.join(fixtures, 'lab.planes.json'), 'utf8');
const lab = JSON.parse(labText);

let browser, server, site, pageErrors;

before(async () => {
  assert.ok(existsSync(dist), 'dist/index.html is missing: run npm run build first');
  // The served site: the bare page, the fixtures, and a copy of the page with planes.js beside it.
  site = await mkdtemp(path.join(tmpdir(), 'mlmap-web-site-'));
  await copyFile(dist, path.join(site, 'index.html'));
  await mkdir(path.join(site, 'fixtures'));
  for (const f of ['lab.planes.json', 'broken.json', 'wrong-schema.json', 'bad-field.json']) {
    await copyFile(path.join(fixtures, f), path.join(site, 'fixtures', f));
  }
  await mkdir(path.join(site, 'with-data'));
  await copyFile(dist, path.join(site, 'with-data', 'index.html'));
  await writeFile(path.join(site, 'with-data', 'planes.js'), planesJs(labText));
  await mkdir(output, { recursive: true });
  server = await serveDir(site);
  browser = await launchChromium();
});

after(async () => {
  await closeChromium(browser);
  await server?.close();
  if (site) await rm(site, { recursive: true, force: true });
});

async function open(url) {
  const page = await browser.context.newPage();
  pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => ['ready', 'empty', 'error'].includes(document.body.dataset.state));
  return page;
}

const state = (page) => page.evaluate(() => window.mlmapDashboard.state());
const visibleRows = (page) => page.locator('#patches tbody tr:not([hidden])');

async function expectLab(page) {
  assert.equal(await page.getAttribute('body', 'data-state'), 'ready');
  assert.equal(await page.locator('#patches tbody tr').count(), lab.planes.length);
  assert.equal(await visibleRows(page).count(), lab.planes.length);
  const ids = await page.$$eval('#patches tbody tr', (rows) => rows.map((r) => Number(r.dataset.id)).sort((a, b) => a - b));
  assert.deepEqual(ids, lab.planes.map((p) => p.id).sort((a, b) => a - b));
  assert.ok(await page.locator('#message').isHidden());
  assert.deepEqual(pageErrors, []);
}

test('the lab JSON given by ?src= fills the table, the summary and the 3D view', async () => {
  const page = await open(`${server.url}/index.html?src=fixtures/lab.planes.json`);
  await expectLab(page);
  const s = await state(page);
  assert.equal(s.webgl, true, 'WebGL started');
  assert.equal(s.patches, lab.planes.length);
  const summary = await page.textContent('#summary');
  assert.match(summary, new RegExp(`all\\s*${lab.planes.length}`));
  assert.match(summary, /cell size\s*0\.05 m/);
  assert.ok(summary.includes(lab.map.source));
  await page.close();
});

test('headers sort and the filters hide rows', async () => {
  const page = await open(`${server.url}/index.html?src=fixtures/lab.planes.json`);
  await page.click('#patches th[data-key="id"]');
  const first = () => page.$eval('#patches tbody tr', (r) => Number(r.dataset.id));
  assert.equal(await first(), Math.min(...lab.planes.map((p) => p.id)));
  await page.click('#patches th[data-key="id"]');
  assert.equal(await first(), Math.max(...lab.planes.map((p) => p.id)));
  await page.click('#patches th[data-key="area"]');
  assert.equal(await first(), lab.planes.reduce((a, b) => (b.area > a.area ? b : a)).id);

  const walls = lab.planes.filter((p) => p.label === 'wall').length;
  assert.ok(walls > 0);
  await page.fill('#filter', 'wall');
  assert.equal(await visibleRows(page).count(), walls);
  await page.fill('#filter', '');
  await page.uncheck('#summary input[data-class="wall"]');
  assert.equal(await visibleRows(page).count(), lab.planes.length - walls);
  assert.equal(await page.locator('#patches tbody tr[data-class="wall"]:not([hidden])').count(), 0);
  await page.close();
});

test('a click on a row highlights its patch in 3D', async () => {
  const page = await open(`${server.url}/index.html?src=fixtures/lab.planes.json`);
  const row = page.locator('#patches tbody tr').nth(2);
  const id = Number(await row.getAttribute('data-id'));
  await row.click();
  assert.match(await row.getAttribute('class'), /\bselected\b/);
  assert.equal(await page.locator('#patches tbody tr.selected').count(), 1);
  assert.equal(await page.getAttribute('#view', 'data-selected-id'), String(id));
  assert.equal(await page.getAttribute('#view', 'data-highlighted-id'), String(id));
  assert.equal((await state(page)).highlighted, id);
  assert.ok((await page.textContent('#pick-info')).startsWith(`#${id} `));
  await waitDrawn(page);
  await page.screenshot({ path: path.join(output, 'dashboard-selected.png') });
  await row.click(); // a second click lets go
  assert.equal((await state(page)).highlighted, null);
  assert.equal(await page.locator('#patches tbody tr.selected').count(), 0);
  await page.close();
});

test('a click on a patch in 3D selects its row', async () => {
  const page = await open(`${server.url}/index.html?src=fixtures/lab.planes.json`);
  // A patch whose centroid is not hidden behind another one from this view.
  const target = await page.evaluate((planes) => {
    const d = window.mlmapDashboard;
    for (const p of [...planes].sort((a, b) => b.area - a.area)) {
      const at = d.project(p.centroid);
      if (d.pickAt(at.x, at.y) === p.id) return { id: p.id, ...at };
    }
    return null;
  }, lab.planes);
  assert.ok(target, 'some patch is visible at its centroid');
  await page.mouse.click(target.x, target.y);
  const row = page.locator(`#patches tbody tr[data-id="${target.id}"]`);
  assert.match(await row.getAttribute('class'), /\bselected\b/);
  assert.equal((await state(page)).highlighted, target.id);
  await page.close();
});

test('a damaged file, a file of another schema and a bad field each show a message', async () => {
  const page = await open(`${server.url}/index.html`);
  assert.equal(await page.getAttribute('body', 'data-state'), 'empty');
  assert.ok(await page.locator('.drop-zone').isVisible());
  await page.setInputFiles('#file-input-empty', path.join(fixtures, 'lab.planes.json'));
  await page.waitForFunction(() => document.body.dataset.state === 'ready');
  await expectLab(page);

  const cases = [
    ['broken.json', /Could not load broken\.json: The file is not valid JSON/],
    ['wrong-schema.json', /Could not load wrong-schema\.json: Not an mlmap planes export: schema is "mlmap\.info\/1", expected "mlmap\.planes\/1"/],
    ['bad-field.json', /planes\[0\]\.normal: expected an array of 3 numbers/],
  ];
  for (const [file, expected] of cases) {
    await page.setInputFiles('#file-input', path.join(fixtures, file));
    await page.waitForFunction(() => document.body.dataset.state === 'error');
    const message = page.locator('#message');
    assert.ok(await message.isVisible(), `${file}: message visible`);
    assert.match(await message.textContent(), expected);
    assert.ok(await page.locator('.drop-zone').isVisible(), `${file}: the drop zone is back`);
    assert.ok(await page.locator('#side').isHidden());
    assert.deepEqual(pageErrors, []);
    // Loading a good file clears the message.
    await page.setInputFiles('#file-input', path.join(fixtures, 'lab.planes.json'));
    await page.waitForFunction(() => document.body.dataset.state === 'ready');
    await expectLab(page);
  }
  await page.close();
});

test('?src= of a missing file shows a message', async () => {
  const page = await open(`${server.url}/index.html?src=fixtures/nothing.json`);
  assert.equal(await page.getAttribute('body', 'data-state'), 'error');
  assert.match(await page.textContent('#message'), /Could not fetch fixtures\/nothing\.json: HTTP 404/);
  await page.close();
});

test('a file dropped on the page is shown', async () => {
  const page = await open(`${server.url}/index.html`);
  await page.evaluate((text) => {
    const transfer = new DataTransfer();
    transfer.items.add(new File([text], 'dropped.planes.json', { type: 'application/json' }));
    for (const type of ['dragenter', 'dragover', 'drop']) {
      document.body.dispatchEvent(new DragEvent(type, { dataTransfer: transfer, bubbles: true, cancelable: true }));
    }
  }, labText);
  await page.waitForFunction(() => document.body.dataset.state === 'ready');
  await expectLab(page);
  assert.match(await page.textContent('#origin'), /dropped\.planes\.json/);
  await page.close();
});

test('served with planes.js beside it, the page shows that data', async () => {
  const page = await open(`${server.url}/with-data/`);
  await expectLab(page);
  assert.match(await page.textContent('#origin'), /planes\.js/);
  await page.close();
});

test('opened from disk (file://) with planes.js beside it, and without', async () => {
  const dir = await mkdtemp(path.join(tmpdir(), 'mlmap-web-file-'));
  try {
    await copyFile(dist, path.join(dir, 'index.html'));
    const url = pathToFileURL(path.join(dir, 'index.html')).href;
    let page = await open(url);
    assert.equal(await page.getAttribute('body', 'data-state'), 'empty', 'no planes.js: the picker');
    assert.ok(await page.locator('.drop-zone').isVisible());
    assert.deepEqual(pageErrors, []);
    await page.close();

    await writeFile(path.join(dir, 'planes.js'), planesJs(labText));
    page = await open(url);
    await expectLab(page);
    assert.equal((await state(page)).webgl, true);
    await page.waitForTimeout(300);
    await waitDrawn(page);
    await page.screenshot({ path: path.join(output, 'dashboard.png') });
    await page.close();
  } finally {
    await rm(dir, { recursive: true, force: true });
  }
});
