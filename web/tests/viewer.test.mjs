// End-to-end test of the dashboard as the map's viewer, on a real `mlmap export --dashboard`
// (scripts/lab-export.sh: the coarse lab, built and labelled by the CLI), opened from disk
// (file://) at 800 and 1600 px: the blocks layer, the height cut, the views, the measure, the
// PNG and CSV exports and the layout. Screenshots go to test-output/viewer-*.png.
import { test, before, after, afterEach } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFile, mkdir, mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { launchChromium, serveDir } from '../scripts/browser.mjs';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const output = path.join(web, 'test-output');
const WIDTHS = [800, 1600];

let browser, server, exportDir, site, planes, blockCount, voxelCount, pageErrors;

/** blocks.bin's header and kind column, read as the format says (include/mlmap/io/dashboard_blocks.hpp). */
function readBlocksHeader(bytes) {
  assert.equal(bytes.subarray(0, 8).toString('latin1'), 'MLBLOCKS');
  const count = bytes.readUInt32LE(12);
  assert.equal(bytes.length, 24 + 21 * count);
  return { count, cellSize: bytes.readDoubleLE(16) };
}

before(async () => {
  assert.ok(existsSync(path.join(web, 'dist', 'index.html')), 'dist/index.html is missing: run npm run build first');
  exportDir = await mkdtemp(path.join(tmpdir(), 'mlmap-web-export-'));
  execFileSync('bash', [path.join(web, 'scripts', 'lab-export.sh'), exportDir], { stdio: 'inherit' });
  planes = JSON.parse(await readFile(path.join(exportDir, 'planes.json'), 'utf8'));
  const header = readBlocksHeader(await readFile(path.join(exportDir, 'blocks.bin')));
  blockCount = header.count;
  assert.equal(header.cellSize, planes.map.cell_size);
  assert.equal(blockCount, planes.map.blocks);
  const voxelBytes = await readFile(path.join(exportDir, 'voxels.bin'));
  assert.equal(voxelBytes.subarray(0, 8).toString('latin1'), 'MLVOXELS');
  voxelCount = voxelBytes.readUInt32LE(12);
  assert.ok(voxelCount > 0);
  site = await mkdtemp(path.join(tmpdir(), 'mlmap-web-viewer-'));
  for (const f of ['index.html', 'planes.json', 'blocks.bin']) await copyFile(path.join(exportDir, f), path.join(site, f));
  const damaged = await readFile(path.join(exportDir, 'blocks.bin'));
  await writeFile(path.join(site, 'cut-short.bin'), damaged.subarray(0, damaged.length - 5));
  await mkdir(output, { recursive: true });
  server = await serveDir(site);
  browser = await launchChromium();
});

after(async () => {
  await browser?.context.close();
  await server?.close();
  if (browser) await rm(browser.userDataDir, { recursive: true, force: true });
  for (const dir of [exportDir, site]) if (dir) await rm(dir, { recursive: true, force: true });
});

// A failed test leaves its page open: close it, so it takes no CPU from the next.
afterEach(async () => {
  for (const page of browser?.context.pages() ?? []) await page.close();
});

async function open(url, width) {
  const page = await browser.context.newPage();
  await page.setViewportSize({ width, height: 900 });
  pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => ['ready', 'empty', 'error'].includes(document.body.dataset.state));
  return page;
}

const openExport = (width) => open(pathToFileURL(path.join(exportDir, 'index.html')).href, width);
const state = (page) => page.evaluate(() => window.mlmapDashboard.state());
const stageCentre = async (page) => {
  const box = await page.locator('#stage').boundingBox();
  return { x: box.x + box.width / 2, y: box.y + box.height / 2, box };
};
const probe = (page, x, y) => page.evaluate(([x, y]) => window.mlmapDashboard.probe(x, y), [x, y]);
const camera = (page) => page.evaluate(() => window.mlmapDashboard.camera());
/** What an n × n grid of probes over the 3D view hits, in one round trip. */
const probeGrid = (page, n) => page.evaluate((n) => {
  const box = document.getElementById('stage').getBoundingClientRect();
  const hits = [];
  for (let a = 1; a < n; a++) {
    for (let b = 1; b < n; b++) {
      const hit = window.mlmapDashboard.probe(box.left + (box.width * a) / n, box.top + (box.height * b) / n);
      if (hit) hits.push(hit);
    }
  }
  return hits;
}, n);

/** Pixels of the 3D view near an RGB colour (or, for rgb 'yellow', lit yellow ones), as a fraction. */
function colourFraction(page, rgb, tolerance = 40) {
  return page.evaluate(async ([rgb, tolerance]) => {
    const canvas = document.querySelector('#stage canvas');
    const image = new Image();
    image.src = canvas.toDataURL('image/png');
    await image.decode();
    const c = document.createElement('canvas');
    c.width = canvas.width; c.height = canvas.height;
    const g = c.getContext('2d');
    g.drawImage(image, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let near = 0;
    for (let k = 0; k < d.length; k += 4) {
      if (rgb === 'yellow' ? d[k] > 200 && d[k + 1] > 170 && d[k + 2] < 150 && d[k] - d[k + 2] > 100
        : Math.abs(d[k] - rgb[0]) + Math.abs(d[k + 1] - rgb[1]) + Math.abs(d[k + 2] - rgb[2]) <= tolerance) near++;
    }
    return near / (d.length / 4);
  }, [rgb, tolerance]);
}

const BACKGROUND = [0x1b, 0x20, 0x2a];

for (const width of WIDTHS) {
  test(`${width} px: the export opened from disk shows every block, under the map's own name`, async () => {
    const page = await openExport(width);
    assert.equal(await page.getAttribute('body', 'data-state'), 'ready', await page.textContent('#message'));
    const s = await state(page);
    assert.equal(s.webgl, true);
    assert.equal(s.blocks, blockCount);
    assert.equal(s.voxels, voxelCount);
    assert.match(await page.textContent('#origin'), new RegExp(`${blockCount.toLocaleString('en')} blocks · ${voxelCount.toLocaleString('en')} voxels`));
    assert.equal(s.patches, planes.planes.length);
    assert.equal(await page.textContent('#map-name'), 'lab.mlmap');
    assert.match(await page.title(), /lab\.mlmap/);
    assert.ok(!(await page.textContent('header h1')).includes('planes.js'));
    assert.ok(await page.isChecked('#layer-blocks'));
    assert.ok(!(await page.isChecked('#layer-patches')), 'with blocks, the patch polygons start hidden');
    assert.ok(!(await page.isChecked('#layer-voxels')), 'with blocks, the voxels start hidden');
    // Seen from above, a building is its ceiling: the page starts with it cut away.
    const ceilings = planes.planes.filter((p) => p.label === 'ceiling').map((p) => p.centroid[2]);
    assert.ok(s.cut.top !== null && s.cut.top < Math.min(...ceilings), JSON.stringify(s.cut));
    const { x, y } = await stageCentre(page);
    assert.equal((await probe(page, x, y))?.what, 'block');
    // The blocks cover much of the view; colour by height paints other pixels than by class.
    await page.screenshot({ path: path.join(output, `viewer-blocks-${width}.png`) });
    const filled = 1 - (await colourFraction(page, BACKGROUND, 12));
    assert.ok(filled > 0.1, `the blocks fill the view (${filled} of it)`);
    const byClass = await page.evaluate(() => document.querySelector('#stage canvas').toDataURL());
    await page.selectOption('#colour-mode', 'height');
    assert.notEqual(await page.evaluate(() => document.querySelector('#stage canvas').toDataURL()), byClass);
    await page.screenshot({ path: path.join(output, `viewer-height-${width}.png`) });
    // A row's plane lights up its blocks (lit, so yellow of some brightness).
    const yellowBefore = await colourFraction(page, 'yellow');
    const floor = planes.planes.filter((p) => p.label === 'floor').sort((a, b) => b.blocks - a.blocks)[0];
    await page.click(`#patches tbody tr[data-id="${floor.id}"]`);
    assert.equal((await state(page)).highlighted, floor.id);
    const yellowAfter = await colourFraction(page, 'yellow');
    assert.ok(yellowAfter - yellowBefore > 0.02, `the floor's blocks are highlighted (${yellowBefore} → ${yellowAfter} of the pixels yellow)`);
    await page.screenshot({ path: path.join(output, `viewer-selected-${width}.png`) });
    // The patch layer can be shown over the blocks, and the blocks hidden.
    await page.uncheck('#layer-blocks');
    await page.check('#layer-patches');
    assert.equal((await probe(page, x, y))?.what ?? 'patch', 'patch');
    // The occupied voxels alone.
    await page.uncheck('#layer-patches');
    await page.check('#layer-voxels');
    assert.equal((await probe(page, x, y))?.what, 'voxel');
    await page.screenshot({ path: path.join(output, `viewer-voxels-${width}.png`) });
    const voxelsFill = 1 - (await colourFraction(page, BACKGROUND, 12));
    assert.ok(voxelsFill > 0.1, `the voxels fill the view (${voxelsFill} of it)`);
    assert.deepEqual(pageErrors, []);
    await page.close();
  });

  // One page for the tools (a page load is slow in software WebGL): each step sets what it needs.
  test(`${width} px: the tools`, async (t) => {
    const page = await openExport(width);
    const first = await camera(page);
    await t.test('the layout keeps its columns and controls', async () => {
      const layout = await page.evaluate(() => {
        const rect = (el) => el.getBoundingClientRect();
        return {
          overflow: document.documentElement.scrollWidth - window.innerWidth,
          narrowestFact: Math.min(...[...document.querySelectorAll('#summary dd')].map((d) => rect(d).width)),
          tallestFact: Math.max(...[...document.querySelectorAll('#summary .map dd')].map((d) => rect(d).height)),
          tableHidden: document.querySelector('.table-wrap').scrollWidth - document.querySelector('.table-wrap').clientWidth,
          tools: [...document.querySelectorAll('#tools button, #tools input')].map((e) => { const r = rect(e); return [e.id, r.left, r.right, r.width]; }),
          stage: rect(document.getElementById('stage')),
          name: [document.getElementById('map-name').scrollWidth, document.getElementById('map-name').clientWidth],
        };
      });
      assert.ok(layout.overflow <= 0, `the page is ${layout.overflow} px wider than the window`);
      assert.ok(layout.narrowestFact >= 80, `a summary value is ${layout.narrowestFact} px wide`);
      assert.ok(layout.tallestFact <= 60, `a map fact is ${layout.tallestFact} px tall (wrapped letter by letter?)`);
      assert.ok(layout.tableHidden <= 1, `${layout.tableHidden} px of the table's columns are cut off`);
      for (const [id, left, right, w] of layout.tools) assert.ok(left >= 0 && right <= width && w > 0, `${id} is off screen`);
      assert.ok(layout.stage.width >= 0.5 * width && layout.stage.height >= 300, `the 3D view is ${layout.stage.width}×${layout.stage.height}`);
      assert.ok(layout.name[0] <= layout.name[1] + 1, 'the map name is shown whole');
      await page.screenshot({ path: path.join(output, `viewer-${width}.png`) });
    });
    await t.test('top, side and reset views', async () => {
      const distance = (c) => Math.hypot(...[0, 1, 2].map((k) => c.position[k] - c.target[k]));
      await page.click('#view-top');
      let c = await camera(page);
      assert.ok(Math.abs(c.position[0] - c.target[0]) < 1e-3 * distance(c) && Math.abs(c.position[1] - c.target[1]) < 1e-3 * distance(c));
      assert.ok(c.position[2] > c.target[2]);
      // North up: a point further north lands higher on the screen.
      const [south, north] = await page.evaluate((t) => [window.mlmapDashboard.project([t[0], t[1], t[2]]), window.mlmapDashboard.project([t[0], t[1] + 1, t[2]])], c.target);
      assert.ok(north.y < south.y - 5 && Math.abs(north.x - south.x) < 2);
      await page.screenshot({ path: path.join(output, `viewer-top-${width}.png`) });
      await page.click('#view-side');
      c = await camera(page);
      assert.ok(Math.abs(c.position[2] - c.target[2]) < 0.03 * distance(c), 'level');
      assert.ok(c.position[1] < c.target[1], 'from the south');
      await page.screenshot({ path: path.join(output, `viewer-side-${width}.png`) });
      await page.click('#view-reset');
      c = await camera(page);
      for (let k = 0; k < 3; k++) {
        assert.ok(Math.abs(c.position[k] - first.position[k]) < 1e-6 && Math.abs(c.target[k] - first.target[k]) < 1e-6);
      }
      assert.deepEqual(pageErrors, []);
    });
    await t.test('the height cut hides the ceiling and slices a storey', async () => {
      await page.click('#view-top');
      await page.click('#cut-clear');
      assert.deepEqual((await state(page)).cut, { bottom: null, top: null });
      const { x, y } = await stageCentre(page);
      const ceiling = planes.planes.filter((p) => p.label === 'ceiling').map((p) => p.centroid[2]);
      assert.ok(ceiling.length > 0);
      const fromAbove = await probe(page, x, y);
      assert.ok(fromAbove.point[2] > Math.min(...ceiling) - 0.2, `from above the ceiling is seen first (z ${fromAbove.point[2]})`);
      await page.click('#cut-ceiling');
      const cut = (await state(page)).cut;
      assert.ok(cut.top !== null && cut.top < Math.min(...ceiling));
      const below = await probe(page, x, y);
      assert.ok(below && below.point[2] < cut.top + 1e-6, `under the cut, z ${below?.point[2]}`);
      assert.match(await page.textContent('#cut-text'), /… – \d+\.\d\d m/);
      await page.screenshot({ path: path.join(output, `viewer-cut-${width}.png`) });
      // A slice from 0.5 m to 1.0 m: only what lies there is hit (the tables at 0.75 m).
      await page.evaluate(() => {
        const set = (id, v) => { const e = document.getElementById(id); e.value = String(v); e.dispatchEvent(new Event('input')); };
        set('cut-top', 1.0);
        set('cut-bottom', 0.5);
      });
      const slice = (await state(page)).cut;
      assert.ok(Math.abs(slice.bottom - 0.5) < 1e-9 && Math.abs(slice.top - 1) < 1e-9, JSON.stringify(slice));
      const hits = await probeGrid(page, 40);
      for (const hit of hits) assert.ok(hit.point[2] >= 0.5 - 1e-4 && hit.point[2] <= 1.0 + 1e-4, `hit at z ${hit.point[2]} outside the slice`);
      assert.ok(hits.length >= 10, `the slice holds something (${hits.length} hits)`);
      // Without the cut, the same probes hit the ceiling and the floor too.
      await page.click('#cut-clear');
      const all = await probeGrid(page, 40);
      assert.ok(all.some((h) => h.point[2] > 1.0 + 1e-4) && all.length > hits.length);
      await page.screenshot({ path: path.join(output, `viewer-slice-${width}.png`) });
      assert.deepEqual((await state(page)).cut, { bottom: null, top: null });
      assert.deepEqual(pageErrors, []);
    });
    await t.test('the distance between two picked points', async () => {
      await page.click('#view-top');
      await page.click('#cut-ceiling');
      await page.click('#measure');
      assert.equal(await page.getAttribute('#measure', 'aria-pressed'), 'true');
      assert.ok(await page.locator('#measure-info').isVisible());
      const { x, y } = await stageCentre(page);
      const spots = [[x - 120, y - 40], [x + 100, y + 60]];
      const hits = [];
      for (const [sx, sy] of spots) {
        hits.push(await probe(page, sx, sy));
        await page.mouse.click(sx, sy);
      }
      assert.ok(hits.every(Boolean), 'both spots hit the map');
      const m = (await state(page)).measure;
      assert.equal(m.points.length, 2);
      for (let k = 0; k < 2; k++) for (let a = 0; a < 3; a++) assert.ok(Math.abs(m.points[k][a] - hits[k].point[a]) < 1e-9);
      const [p, q] = hits.map((h) => h.point);
      const expected = Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      assert.ok(Math.abs(m.distance - expected) < 1e-9);
      assert.ok(Math.abs(m.horizontal - Math.hypot(p[0] - q[0], p[1] - q[1])) < 1e-9);
      // From straight above, the screen distance over the pixels per metre is the horizontal distance.
      const perMetre = await page.evaluate((p) => {
        const d = window.mlmapDashboard;
        const a = d.project(p), b = d.project([p[0] + 1, p[1], p[2]]);
        return Math.hypot(a.x - b.x, a.y - b.y);
      }, p);
      const onScreen = Math.hypot(spots[0][0] - spots[1][0], spots[0][1] - spots[1][1]) / perMetre;
      assert.ok(Math.abs(m.horizontal - onScreen) < 0.1 + 0.05 * onScreen, `${m.horizontal} m vs ${onScreen} m on screen`);
      assert.match(await page.textContent('#measure-info'), new RegExp(`distance ${m.distance.toFixed(3)} m`));
      await page.screenshot({ path: path.join(output, `viewer-measure-${width}.png`) });
      // While measuring, a click picks no patch; a third click starts a new pair; Esc stops.
      assert.equal((await state(page)).selected, null);
      await page.mouse.click(x, y);
      assert.equal((await state(page)).measure.points.length, 1);
      await page.keyboard.press('Escape');
      assert.equal(await page.getAttribute('#measure', 'aria-pressed'), 'false');
      assert.ok(await page.locator('#measure-info').isHidden());
      assert.deepEqual(pageErrors, []);
    });
    await t.test('the view saved as PNG, the table as CSV', async () => {
      const [png] = await Promise.all([page.waitForEvent('download'), page.click('#save-png')]);
      assert.equal(png.suggestedFilename(), 'lab-view.png');
      const bytes = await readFile(await png.path());
      assert.deepEqual([...bytes.subarray(0, 8)], [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
      const size = await page.evaluate(() => { const c = document.querySelector('#stage canvas'); return [c.width, c.height]; });
      assert.deepEqual([bytes.readUInt32BE(16), bytes.readUInt32BE(20)], size);
  
      const walls = planes.planes.filter((p) => p.label === 'wall');
      await page.fill('#filter', 'wall');
      const [csv] = await Promise.all([page.waitForEvent('download'), page.click('#save-csv')]);
      assert.equal(csv.suggestedFilename(), 'lab-patches.csv');
      const lines = (await readFile(await csv.path(), 'utf8')).trim().split('\n');
      assert.equal(lines[0], 'id,class,cityjson_type,area_m2,normal_x,normal_y,normal_z,height_m,offset_m,blocks,rms_m');
      assert.equal(lines.length, walls.length + 1);
      const rows = lines.slice(1).map((l) => l.split(','));
      // In the table's order (area, largest first), with the JSON's values.
      assert.deepEqual(rows.map((r) => Number(r[0])), [...walls].sort((a, b) => b.area - a.area || a.id - b.id).map((p) => p.id));
      for (const r of rows) {
        const p = walls.find((w) => w.id === Number(r[0]));
        assert.equal(r[1], 'wall');
        assert.equal(Number(r[3]), p.area);
        assert.equal(Number(r[7]), p.centroid[2]);
      }
      assert.deepEqual(pageErrors, []);
    });
    await page.close();
  });
}

test('blocks given by ?blocks= or picked with the JSON; a damaged blocks file leaves the planes shown', async () => {
  let page = await open(`${server.url}/index.html?src=planes.json&blocks=blocks.bin`, 1600);
  assert.equal((await state(page)).blocks, blockCount);
  assert.ok(await page.locator('#message').isHidden());
  await page.close();

  page = await open(`${server.url}/index.html?src=planes.json&blocks=cut-short.bin`, 1600);
  assert.equal(await page.getAttribute('body', 'data-state'), 'ready');
  assert.equal((await state(page)).blocks, 0);
  assert.match(await page.textContent('#message'), /Could not load the blocks cut-short\.bin: the header says \d+ blocks, which take \d+ bytes, but the file has \d+ \(cut short or damaged\?\)\. The planes are shown without the blocks\./);
  assert.equal((await state(page)).patches, planes.planes.length);
  // Picking the planes and the blocks together, then the blocks alone for the planes shown.
  await page.setInputFiles('#file-input', [path.join(exportDir, 'planes.json'), path.join(exportDir, 'blocks.bin')]);
  await page.waitForFunction((n) => window.mlmapDashboard.state().blocks === n, blockCount);
  assert.ok(await page.locator('#message').isHidden());
  await page.close();
});
