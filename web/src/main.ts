// The dashboard: wires loading, the 3D view, the table and the summary together.

import './style.css';
import { fileKind, loadBinaryFile, loadFile, loadInitial, watchDrops, type Loaded } from './load';
import type { PlaneClass, PlanesExport } from './planes';
import { PlanesView, type Hit } from './scene';
import { PatchTable } from './table';
import { renderSummary } from './summary';
import { heightRange, type ColourMode } from './colours';
import { blockHeights, parseBlocks, parseVoxels, type BlockSet, type VoxelSet } from './blocks';
import { Measure } from './measure';
import { HeightCut } from './height_cut';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

const viewEl = $<HTMLDivElement>('view');
const stage = $<HTMLDivElement>('stage');
const message = $<HTMLDivElement>('message');
const side = $<HTMLElement>('side');
const filterInput = $<HTMLInputElement>('filter');
const colourSelect = $<HTMLSelectElement>('colour-mode');
const pickInfo = $<HTMLDivElement>('pick-info');
const layerPatches = $<HTMLInputElement>('layer-patches');
const layerBlocks = $<HTMLInputElement>('layer-blocks');
const layerVoxels = $<HTMLInputElement>('layer-voxels');

let data: PlanesExport | null = null;
let blocks: BlockSet | null = null;
let voxels: VoxelSet | null = null;
let origin = '';
let selected: number | null = null;
let shownClasses: Set<PlaneClass> | null = null;
let view: PlanesView | null = null;
let viewFailed = false;

const table = new PatchTable($<HTMLTableElement>('patches'), (id) => select(id === selected ? null : id, 'table'));
const measure = new Measure($<HTMLButtonElement>('measure'), $('measure-info'), (points) => view?.setMarkers(points));
const cut = new HeightCut((bottom, top) => view?.setCut(bottom, top));

function setState(state: 'loading' | 'empty' | 'ready' | 'error'): void {
  document.body.dataset.state = state;
  side.hidden = state !== 'ready';
  // Shown before the view frames the map: the tool bar takes height from the view.
  $('tools').hidden = state !== 'ready' || viewFailed;
  $('view-hint').hidden = state !== 'ready' || view === null;
}

function showMessage(text: string, kind: 'error' | 'warning'): void {
  message.textContent = text;
  message.className = kind;
  message.hidden = false;
}

function clearMessage(): void {
  message.hidden = true;
  message.textContent = '';
}

function fail(e: unknown): void {
  showMessage(e instanceof Error ? e.message : String(e), 'error');
  data = null;
  blocks = null;
  voxels = null;
  select(null, 'table');
  measure.toggle(false);
  view?.show(emptyExport());
  $('origin').textContent = '';
  $('map-name').textContent = '';
  setState('error');
}

/** Nothing to draw: the view stays, blank, behind the drop zone. */
function emptyExport(): PlanesExport {
  return {
    schema: 'mlmap.planes/1', map: { source: '', cell_size: 1, cells: 0, blocks: 0, bounds: { min: [0, 0, 0], max: [0, 0, 0] } },
    parameters: {}, detection: {}, timings: { direction_vectors_s: 0, detection_s: 0, total_s: 0 }, planes: [],
  };
}

function ensureView(): PlanesView | null {
  if (view || viewFailed) return view;
  try {
    view = new PlanesView(stage, onViewClick);
  } catch (e) {
    viewFailed = true;
    showMessage(`The 3D view is unavailable (WebGL could not start: ${e instanceof Error ? e.message : e}). The table and summary still work.`, 'warning');
  }
  return view;
}

function onViewClick(hit: Hit | null): void {
  if (measure.active) {
    if (hit) measure.add(hit.point);
    return;
  }
  select(hit?.id ?? null, 'view');
}

function show(loaded: Loaded): void {
  clearMessage();
  if (loaded.blocksError) showMessage(`${loaded.blocksError}. The planes are shown without the blocks.`, 'warning');
  data = loaded.data;
  blocks = loaded.blocks ?? null;
  voxels = loaded.voxels ?? null;
  origin = loaded.origin;
  if (blocks && Math.abs(blocks.cellSize - data.map.cell_size) > 1e-9) {
    showMessage(`The blocks (cell size ${blocks.cellSize} m) are not of this map (cell size ${data.map.cell_size} m): shown without them.`, 'warning');
    blocks = null;
  }
  selected = null;
  shownClasses = null;
  filterInput.value = '';
  measure.toggle(false);
  // The map's own name: the file the export was made from, else where the data came from.
  const name = data.map.source || loaded.origin;
  $('map-name').textContent = name;
  const blockCount = blocks ? ` · ${blocks.count.toLocaleString('en')} blocks` : '';
  const voxelCount = voxels ? ` · ${voxels.count.toLocaleString('en')} voxels` : '';
  $('origin').textContent = `${loaded.origin} · ${data.planes.length} patches${blockCount}${voxelCount}`;
  document.title = `mlmap · ${name}`;
  const { min, max } = data.map.bounds;
  const heights = blocks && blocks.count > 0 ? blockHeights(blocks) : { min: min[2], max: max[2] };
  heightRange.min = Math.min(min[2], heights.min);
  heightRange.max = Math.max(max[2], heights.max);
  setState('ready'); // first, so the view has its final width when it frames the map
  renderSummary($('summary'), data, (classes) => { shownClasses = classes; applyFilter(); });
  table.setData(data.planes);
  table.setColourMode(colourSelect.value as ColourMode);
  const v = ensureView();
  v?.show(data, blocks, voxels);
  v?.setColourMode(colourSelect.value as ColourMode);
  $('layers').hidden = !blocks && !voxels;
  layerBlocks.parentElement!.hidden = !blocks;
  layerVoxels.parentElement!.hidden = !voxels;
  // With blocks, the blocks are the map and the patch polygons would lie on them: blocks first;
  // the voxels, which lie on the blocks as well, only when there are no blocks.
  layerBlocks.checked = true;
  layerVoxels.checked = !blocks;
  layerPatches.checked = !blocks && !voxels;
  applyLayers();
  const ceilings = data.planes.filter((p) => p.label === 'ceiling').map((p) => p.centroid[2]);
  cut.reset(heightRange.min, heightRange.max, data.map.cell_size, ceilings.length ? Math.min(...ceilings) : null);
  // Blocks and voxels are opaque: seen from above, a building is its ceiling. Start without it.
  if ((blocks || voxels) && ceilings.length) cut.cutCeiling();
  setState('ready');
  applyFilter();
  select(null, 'table');
}

function applyLayers(): void {
  view?.setLayers({ patches: layerPatches.checked, blocks: layerBlocks.checked, voxels: layerVoxels.checked });
}

function applyFilter(): void {
  if (!data) return;
  const words = filterInput.value.trim().toLowerCase().split(/\s+/).filter(Boolean);
  const ids = new Set<number>();
  for (const p of data.planes) {
    if (shownClasses && !shownClasses.has(p.label)) continue;
    const text = `#${p.id} ${p.label} ${p.cityjson_type ?? ''}`.toLowerCase();
    if (words.every((w) => text.includes(w))) ids.add(p.id);
  }
  table.setVisible(ids);
  view?.setVisible(ids);
  $('count').textContent = `${ids.size} of ${data.planes.length} shown`;
  if (selected !== null && !ids.has(selected)) select(null, 'table');
}

function select(id: number | null, from: 'table' | 'view'): void {
  selected = id;
  table.select(id, from === 'view');
  view?.select(id);
  viewEl.dataset.selectedId = id === null ? '' : String(id);
  viewEl.dataset.highlightedId = String(view?.highlightedId() ?? '');
  const patch = id === null ? undefined : data?.planes.find((p) => p.id === id);
  pickInfo.hidden = !patch;
  if (patch) {
    pickInfo.textContent = `#${patch.id} ${patch.label} · ${patch.area.toFixed(2)} m² · height ${patch.centroid[2].toFixed(2)} m · ` +
      `${patch.blocks} blocks · RMS ${(patch.rms * 100).toFixed(1)} cm`;
  }
}

async function openFiles(files: File[]): Promise<void> {
  try {
    const kinds = await Promise.all(files.map(fileKind));
    const json = files.find((_, k) => kinds[k] === 'planes');
    const blocksFile = files.find((_, k) => kinds[k] === 'blocks');
    const voxelsFile = files.find((_, k) => kinds[k] === 'voxels');
    const newBlocks = blocksFile ? await loadBinaryFile(blocksFile, parseBlocks) : undefined;
    const newVoxels = voxelsFile ? await loadBinaryFile(voxelsFile, parseVoxels) : undefined;
    if (!json && data) {
      // Blocks or voxels alone: for the planes shown now.
      show({ data, origin, blocks: newBlocks ?? blocks ?? undefined, voxels: newVoxels ?? voxels ?? undefined });
      return;
    }
    if (!json) throw new Error(`${(blocksFile ?? voxelsFile)!.name} holds ${blocksFile ? 'blocks' : 'voxels'}: open the planes JSON with it`);
    const loaded = await loadFile(json);
    loaded.blocks = newBlocks;
    loaded.voxels = newVoxels;
    show(loaded);
  } catch (e) {
    fail(e);
  }
}

/** Offers a blob as a download. */
function download(blob: Blob, name: string): void {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
}

const baseName = () => ($('map-name').textContent || 'mlmap').replace(/\.[^.]*$/, '').replace(/[^\w.-]+/g, '_');

for (const id of ['file-input', 'file-input-empty']) {
  const input = $<HTMLInputElement>(id);
  input.addEventListener('change', () => {
    const files = Array.from(input.files ?? []);
    input.value = '';
    if (files.length) void openFiles(files);
  });
}
watchDrops((files) => void openFiles(files));
filterInput.addEventListener('input', applyFilter);
colourSelect.addEventListener('change', () => {
  const mode = colourSelect.value as ColourMode;
  table.setColourMode(mode);
  view?.setColourMode(mode);
});
layerPatches.addEventListener('change', applyLayers);
layerBlocks.addEventListener('change', applyLayers);
layerVoxels.addEventListener('change', applyLayers);
for (const which of ['top', 'side', 'reset'] as const) $(`view-${which}`).addEventListener('click', () => view?.view(which));
$('measure').addEventListener('click', () => measure.toggle());
$('save-png').addEventListener('click', () => { void view?.png().then((b) => download(b, `${baseName()}-view.png`)); });
$('save-csv').addEventListener('click', () => download(new Blob([table.csv()], { type: 'text/csv' }), `${baseName()}-patches.csv`));
window.addEventListener('keydown', (e) => {
  if (e.key !== 'Escape') return;
  if (measure.active) measure.toggle(false);
  else if (selected !== null) select(null, 'table');
});

// A hook for tests and for the curious: the state the page shows and the 3D view's picking.
declare global {
  interface Window {
    mlmapDashboard?: unknown;
  }
}
window.mlmapDashboard = {
  state: () => ({
    state: document.body.dataset.state, patches: data?.planes.length ?? 0, blocks: blocks?.count ?? 0, voxels: voxels?.count ?? 0, selected,
    highlighted: view?.highlightedId() ?? null, webgl: view !== null, software: view?.software ?? null, cut: cut.range(), measure: measure.state(),
  }),
  pickAt: (x: number, y: number) => view?.pickAt(x, y) ?? null,
  probe: (x: number, y: number) => view?.probe(x, y) ?? null,
  project: (point: [number, number, number]) => view?.project(point) ?? null,
  camera: () => view?.cameraState() ?? null,
  /** Resolves once the 3D view shows the page's state with every block drawn. */
  drawn: () => view?.whenDrawn() ?? Promise.resolve(),
  drawing: () => view?.drawing() ?? null,
  setFrameBudget: (boxes: number | null) => view?.setFrameBudget(boxes),
};

async function start(): Promise<void> {
  try {
    const loaded = await loadInitial();
    if (loaded) show(loaded);
    else setState('empty');
  } catch (e) {
    fail(e);
  }
}
void start();
