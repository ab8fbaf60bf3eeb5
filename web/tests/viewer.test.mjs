// End-to-end test of the dashboard as the map's viewer, on a real `mlmap export --dashboard`
// (scripts/lab-export.sh: the coarse lab, built and labelled by the CLI), opened from disk
// (file://) at 800 and 1600 px: the blocks layer, the height cut, the views, the measure, the
// PNG and CSV exports and the layout. Screenshots go to test-output/viewer-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFile, mkdir, mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { closeChromium, launchChromium, serveDir, waitDrawn } from '../scripts/browser.mjs';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const output = path.join(web, 'test-output');
const WIDTHS = [800, 1600];

let browser, server, exportDir, site, planes, blockCount, voxelCount, pageErrors, blocks;

/** blocks.bin's header and kind column, read as the format says (include/mlmap/io/dashboard_blocks.hpp). */
function readBlocksHeader(bytes) {
  assert.equal(bytes.subarray(0, 8).toString('latin1'), 'MLBLOCKS');
  const count = bytes.readUInt32LE(12);
  assert.equal(bytes.length, 24 + 21 * count);
  return { count, cellSize: bytes.readDoubleLE(16) };
}

/** Every block of blocks.bin, with the box the page draws for it (horizontal: a slab a quarter cell thick). */
function readBlocks(bytes) {
  const { count, cellSize } = readBlocksHeader(bytes);
  const column = (k, read) => Array.from({ length: count }, (_, b) => read(24 + 4 * (k * count + b)));
  const j = column(0, (o) => bytes.readInt32LE(o)), i = column(1, (o) => bytes.readInt32LE(o));
  const top = column(2, (o) => bytes.readFloatLE(o)), depth = column(3, (o) => bytes.readFloatLE(o));
  const plane = column(4, (o) => bytes.readInt32LE(o));
  return Array.from({ length: count }, (_, b) => {
    const vertical = bytes[24 + 20 * count + b] === 1 && depth[b] > 0;
    const bottom = top[b] - (vertical ? depth[b] : 0.25 * cellSize);
    return { plane: plane[b], vertical, top: top[b], min: [j[b] * cellSize, i[b] * cellSize, bottom], max: [(j[b] + 1) * cellSize, (i[b] + 1) * cellSize, top[b]] };
  });
}

/** The blocks whose box holds the point (within 0.1 mm). */
const blocksAt = (p) => blocks.filter((b) => [0, 1, 2].every((a) => p[a] >= b.min[a] - 1e-4 && p[a] <= b.max[a] + 1e-4));

before(async () => {
  assert.ok(existsSync(path.join(web, 'dist', 'index.html')), 'dist/index.html is missing: run npm run build first');
  exportDir = await mkdtemp(path.join(tmpdir(), 'mlmap-web-export-'));
  execFileSync('bash', [path.join(web, 'scripts', 'lab-export.sh'), exportDir], { stdio: 'inherit' });
  planes = JSON.parse(await readFile(path.join(exportDir, 'planes.json'), 'utf8'));
  const blockBytes = await readFile(path.join(exportDir, 'blocks.bin'));
  const header = readBlocksHeader(blockBytes);
  blocks = readBlocks(blockBytes);
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
  await closeChromium(browser);
  await server?.close();
  for (const dir of [exportDir, site]) if (dir) await rm(dir, { recursive: true, force: true });
});

async function open(url, width) {
  // A failed test leaves its page open: closed here, so it takes no CPU from the next. (Not in
  // an afterEach hook: node:test runs those after every subtest too, and the tools' subtests
  // share one page.)
  for (const page of browser.context.pages()) await page.close();
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
async function colourFraction(page, rgb, tolerance = 40) {
  await waitDrawn(page); // the picture is drawn over frames: wait for all of it
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

/** A screenshot of the page once the 3D view has drawn every box, into test-output/. */
async function shot(page, name) {
  await waitDrawn(page);
  await page.screenshot({ path: path.join(output, name) });
}

/** The 3D view's picture once every box is drawn, as a data URL. */
async function picture(page) {
  await waitDrawn(page);
  return page.evaluate(() => document.querySelector('#stage canvas').toDataURL());
}

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
    await shot(page, `viewer-blocks-${width}.png`);
    const filled = 1 - (await colourFraction(page, BACKGROUND, 12));
    assert.ok(filled > 0.1, `the blocks fill the view (${filled} of it)`);
    const byClass = await picture(page);
    await page.selectOption('#colour-mode', 'height');
    assert.notEqual(await picture(page), byClass);
    await shot(page, `viewer-height-${width}.png`);
    // A row's plane lights up its blocks (lit, so yellow of some brightness).
    const yellowBefore = await colourFraction(page, 'yellow');
    const floor = planes.planes.filter((p) => p.label === 'floor').sort((a, b) => b.blocks - a.blocks)[0];
    await page.click(`#patches tbody tr[data-id="${floor.id}"]`);
    assert.equal((await state(page)).highlighted, floor.id);
    const yellowAfter = await colourFraction(page, 'yellow');
    assert.ok(yellowAfter - yellowBefore > 0.02, `the floor's blocks are highlighted (${yellowBefore} → ${yellowAfter} of the pixels yellow)`);
    await shot(page, `viewer-selected-${width}.png`);
    // The patch layer can be shown over the blocks, and the blocks hidden.
    await page.uncheck('#layer-blocks');
    await page.check('#layer-patches');
    assert.equal((await probe(page, x, y))?.what ?? 'patch', 'patch');
    // The occupied voxels alone.
    await page.uncheck('#layer-patches');
    await page.check('#layer-voxels');
    assert.equal((await probe(page, x, y))?.what, 'voxel');
    await shot(page, `viewer-voxels-${width}.png`);
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
      await shot(page, `viewer-${width}.png`);
    });
    await t.test('a click on a block selects its plane; the block is one of blocks.bin', async () => {
      // Spots over the view where a labelled block is hit (not the floor: any plane but the largest).
      const spots = await page.evaluate(() => {
        const box = document.getElementById('stage').getBoundingClientRect();
        const found = [];
        for (let a = 1; a < 12; a++) for (let b = 1; b < 12; b++) {
          const x = box.left + (box.width * a) / 12, y = box.top + (box.height * b) / 12;
          const hit = window.mlmapDashboard.probe(x, y);
          if (hit?.what === 'block' && hit.id !== null) found.push({ x, y, hit });
        }
        return found;
      });
      assert.ok(spots.length >= 10, `${spots.length} spots hit a labelled block`);
      for (const { hit } of spots) {
        const holders = blocksAt(hit.point);
        assert.ok(holders.some((b) => b.plane === hit.id), `no block of plane ${hit.id} holds the picked point ${hit.point}`);
      }
      const wall = spots.find((s) => planes.planes.find((p) => p.id === s.hit.id)?.label === 'wall') ?? spots[0];
      const patch = planes.planes.find((p) => p.id === wall.hit.id);
      await page.mouse.click(wall.x, wall.y);
      assert.equal((await state(page)).selected, patch.id);
      assert.equal((await state(page)).highlighted, patch.id);
      assert.equal(await page.getAttribute('#patches tbody tr.selected', 'data-id'), String(patch.id));
      assert.equal(await page.textContent('#pick-info'), `#${patch.id} ${patch.label} · ${patch.area.toFixed(2)} m² · height ${patch.centroid[2].toFixed(2)} m · ` +
        `${patch.blocks} blocks · RMS ${(patch.rms * 100).toFixed(1)} cm`);
      await shot(page, `viewer-picked-${width}.png`);
      await page.keyboard.press('Escape');
      assert.equal((await state(page)).selected, null);
    });
    await t.test('a picture drawn over many frames is the picture drawn in one', async () => {
      await page.evaluate(() => window.mlmapDashboard.setFrameBudget(1e9));
      const whole = await picture(page);
      assert.equal((await page.evaluate(() => window.mlmapDashboard.drawing())).frames, 1);
      await page.evaluate(() => window.mlmapDashboard.setFrameBudget(1500));
      const pieces = await picture(page);
      const drawing = await page.evaluate(() => window.mlmapDashboard.drawing());
      assert.ok(drawing.frames >= Math.floor(blockCount / 1500), `${drawing.frames} frames for ${blockCount} blocks at 1500 a frame`);
      const differ = await page.evaluate(async ([a, b]) => {
        const pixels = async (url) => {
          const image = new Image();
          image.src = url;
          await image.decode();
          const c = document.createElement('canvas');
          c.width = image.width; c.height = image.height;
          const g = c.getContext('2d');
          g.drawImage(image, 0, 0);
          return g.getImageData(0, 0, c.width, c.height).data;
        };
        const [p, q] = [await pixels(a), await pixels(b)];
        let n = 0;
        for (let k = 0; k < p.length; k += 4) if (Math.abs(p[k] - q[k]) + Math.abs(p[k + 1] - q[k + 1]) + Math.abs(p[k + 2] - q[k + 2]) > 24) n++;
        return n / (p.length / 4);
      }, [whole, pieces]);
      // Only where two boxes meet at the same depth may the later-drawn one win another way.
      assert.ok(differ < 0.002, `${differ} of the pixels differ`);
      await page.evaluate(() => window.mlmapDashboard.setFrameBudget(null));
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
      await shot(page, `viewer-top-${width}.png`);
      await page.click('#view-side');
      c = await camera(page);
      assert.ok(Math.abs(c.position[2] - c.target[2]) < 0.03 * distance(c), 'level');
      assert.ok(c.position[1] < c.target[1], 'from the south');
      await shot(page, `viewer-side-${width}.png`);
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
      const ceilingIds = new Set(planes.planes.filter((p) => p.label === 'ceiling').map((p) => p.id));
      const uncut = await probeGrid(page, 20);
      assert.ok(uncut.filter((h) => ceilingIds.has(h.id)).length > 0.5 * uncut.length, 'from above, most probes hit the ceiling\'s blocks');
      // The ceiling as drawn from above: the colour at the middle of the view.
      await waitDrawn(page);
      const ceilingRgb = await page.evaluate(async () => {
        const canvas = document.querySelector('#stage canvas');
        const image = new Image();
        image.src = canvas.toDataURL('image/png');
        await image.decode();
        const c = document.createElement('canvas');
        c.width = canvas.width; c.height = canvas.height;
        const g = c.getContext('2d');
        g.drawImage(image, 0, 0);
        return [...g.getImageData(c.width >> 1, c.height >> 1, 1, 1).data.slice(0, 3)];
      });
      const ceilingDrawn = await colourFraction(page, ceilingRgb, 30);
      assert.ok(ceilingDrawn > 0.2, `the ceiling's blocks cover the view from above (${ceilingDrawn} of it, rgb ${ceilingRgb})`);
      await page.click('#cut-ceiling');
      const cut = (await state(page)).cut;
      assert.ok(cut.top !== null && cut.top < Math.min(...ceiling));
      const below = await probe(page, x, y);
      assert.ok(below && below.point[2] < cut.top + 1e-6, `under the cut, z ${below?.point[2]}`);
      const cutHits = await probeGrid(page, 20);
      assert.ok(cutHits.length > 0.5 * uncut.length, `under the cut the probes hit the rooms (${cutHits.length})`);
      assert.deepEqual(cutHits.filter((h) => ceilingIds.has(h.id)), [], 'no ceiling block is hit under the cut');
      // and none is drawn: the ceiling's colour is (almost) gone from the picture
      const ceilingLeft = await colourFraction(page, ceilingRgb, 30);
      assert.ok(ceilingLeft < 0.02, `the ceiling's blocks are not drawn (${ceilingLeft} of the view in its colour)`);
      assert.match(await page.textContent('#cut-text'), /… – \d+\.\d\d m/);
      await shot(page, `viewer-cut-${width}.png`);
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
      await shot(page, `viewer-slice-${width}.png`);
      // Without the cut, the same probes hit the ceiling and the floor too.
      await page.click('#cut-clear');
      const all = await probeGrid(page, 40);
      assert.ok(all.some((h) => h.point[2] > 1.0 + 1e-4) && all.length > hits.length);
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
      // Two floor blocks far apart, at known places: the middles of their tops, from blocks.bin.
      const floor = planes.planes.filter((p) => p.label === 'floor').sort((a, b) => b.blocks - a.blocks)[0];
      const floorBlocks = blocks.filter((b) => b.plane === floor.id && !b.vertical);
      const candidates = floorBlocks.filter((_, k) => k % Math.max(1, Math.floor(floorBlocks.length / 300)) === 0)
        .map((b) => [(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, b.top]);
      // Those seen from above (not under a table), where they land on the screen.
      const seen = await page.evaluate(([candidates, id]) => candidates.map((p) => {
        const s = window.mlmapDashboard.project(p);
        const hit = window.mlmapDashboard.probe(s.x, s.y);
        return hit && hit.id === id && Math.abs(hit.point[2] - p[2]) < 1e-3 ? { p, s } : null;
      }).filter(Boolean), [candidates, floor.id]);
      assert.ok(seen.length >= 10, `${seen.length} floor blocks seen from above`);
      let pair = [seen[0], seen[1]];
      for (const a of seen) for (const b of seen) if (Math.hypot(a.p[0] - b.p[0], a.p[1] - b.p[1]) > Math.hypot(pair[0].p[0] - pair[1].p[0], pair[0].p[1] - pair[1].p[1])) pair = [a, b];
      for (const { s } of pair) await page.mouse.click(s.x, s.y);
      const m = (await state(page)).measure;
      assert.equal(m.points.length, 2);
      const [p, q] = pair.map((e) => e.p);
      const known = Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      // A click lands within a pixel of the block's middle: a pixel is ~2 cm here.
      const pixel = await page.evaluate((p) => {
        const d = window.mlmapDashboard;
        const a = d.project(p), b = d.project([p[0] + 1, p[1], p[2]]);
        return 1 / Math.hypot(a.x - b.x, a.y - b.y);
      }, p);
      assert.ok(Math.abs(m.distance - known) < 2 * pixel, `measured ${m.distance} m, the blocks are ${known} m apart (a pixel is ${pixel} m)`);
      assert.ok(Math.abs(m.horizontal - Math.hypot(p[0] - q[0], p[1] - q[1])) < 2 * pixel);
      assert.ok(Math.abs(m.vertical - Math.abs(p[2] - q[2])) < 1e-3, `vertical ${m.vertical} m, the tops differ by ${Math.abs(p[2] - q[2])} m`);
      assert.ok(known > 3, `the blocks are ${known} m apart`);
      for (let k = 0; k < 2; k++) for (let a = 0; a < 3; a++) assert.ok(Math.abs(m.points[k][a] - pair[k].p[a]) < 2 * pixel);
      assert.match(await page.textContent('#measure-info'), new RegExp(`distance ${m.distance.toFixed(3)} m`));
      await shot(page, `viewer-measure-${width}.png`);
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
      assert.ok(size[0] >= 0.5 * width && size[1] >= 300, `the PNG is ${size[0]}×${size[1]}`);
      // It holds the map, not a blank canvas: most of it is blocks, not background.
      const filled = await page.evaluate(async ([base64, bg]) => {
        const image = new Image();
        image.src = `data:image/png;base64,${base64}`;
        await image.decode();
        const c = document.createElement('canvas');
        c.width = image.width; c.height = image.height;
        const g = c.getContext('2d');
        g.drawImage(image, 0, 0);
        const d = g.getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let k = 0; k < d.length; k += 4) if (Math.abs(d[k] - bg[0]) + Math.abs(d[k + 1] - bg[1]) + Math.abs(d[k + 2] - bg[2]) > 12) n++;
        return n / (d.length / 4);
      }, [bytes.toString('base64'), BACKGROUND]);
      assert.ok(filled > 0.1, `the PNG shows the map (${filled} of it not background)`);
  
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
      const fields = (p) => [p.id, p.label, p.cityjson_type ?? '', p.area, ...p.normal, p.centroid[2], p.offset, p.blocks, p.rms];
      for (const r of rows) {
        const p = walls.find((w) => w.id === Number(r[0]));
        assert.deepEqual(r.map((v, k) => (k === 1 || k === 2 ? v : Number(v))), fields(p));
      }
      // Without the filter: every patch, each row equal to the JSON's values.
      await page.fill('#filter', '');
      const [all] = await Promise.all([page.waitForEvent('download'), page.click('#save-csv')]);
      const allRows = (await readFile(await all.path(), 'utf8')).trim().split('\n').slice(1).map((l) => l.split(','));
      assert.equal(allRows.length, planes.planes.length);
      assert.deepEqual(allRows.map((r) => r.map((v, k) => (k === 1 || k === 2 ? v : Number(v)))).sort((a, b) => a[0] - b[0]),
        planes.planes.map(fields).sort((a, b) => a[0] - b[0]));
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
