// The dashboard: wires loading, the 3D view, the table and the summary together.

import './style.css';
import { loadFile, loadInitial, watchDrops, type Loaded } from './load';
import type { PlaneClass, PlanesExport } from './planes';
import { PlanesView } from './scene';
import { PatchTable } from './table';
import { renderSummary } from './summary';
import type { ColourMode } from './colours';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

const viewEl = $<HTMLDivElement>('view');
const message = $<HTMLDivElement>('message');
const side = $<HTMLElement>('side');
const filterInput = $<HTMLInputElement>('filter');
const colourSelect = $<HTMLSelectElement>('colour-mode');
const pickInfo = $<HTMLDivElement>('pick-info');

let data: PlanesExport | null = null;
let selected: number | null = null;
let shownClasses: Set<PlaneClass> | null = null;
let view: PlanesView | null = null;
let viewFailed = false;

const table = new PatchTable($<HTMLTableElement>('patches'), (id) => select(id === selected ? null : id, 'table'));

function setState(state: 'loading' | 'empty' | 'ready' | 'error'): void {
  document.body.dataset.state = state;
  side.hidden = state !== 'ready';
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
  select(null, 'table');
  view?.show(emptyExport());
  $('origin').textContent = '';
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
    view = new PlanesView(viewEl, (id) => select(id, 'view'));
  } catch (e) {
    viewFailed = true;
    showMessage(`The 3D view is unavailable (WebGL could not start: ${e instanceof Error ? e.message : e}). The table and summary still work.`, 'warning');
  }
  return view;
}

function show(loaded: Loaded): void {
  clearMessage();
  data = loaded.data;
  selected = null;
  shownClasses = null;
  filterInput.value = '';
  $('origin').textContent = `${loaded.origin} · ${data.planes.length} patches`;
  document.title = `mlmap planes · ${loaded.origin}`;
  setState('ready'); // first, so the view has its final width when it frames the map
  renderSummary($('summary'), data, (classes) => { shownClasses = classes; applyFilter(); });
  table.setData(data.planes);
  table.setColourMode(colourSelect.value as ColourMode);
  const v = ensureView();
  v?.show(data);
  v?.setColourMode(colourSelect.value as ColourMode);
  setState('ready');
  applyFilter();
  select(null, 'table');
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

async function openFile(file: File): Promise<void> {
  try {
    show(await loadFile(file));
  } catch (e) {
    fail(e);
  }
}

for (const id of ['file-input', 'file-input-empty']) {
  const input = $<HTMLInputElement>(id);
  input.addEventListener('change', () => {
    const file = input.files?.[0];
    input.value = '';
    if (file) void openFile(file);
  });
}
watchDrops((file) => void openFile(file));
filterInput.addEventListener('input', applyFilter);
colourSelect.addEventListener('change', () => {
  const mode = colourSelect.value as ColourMode;
  table.setColourMode(mode);
  view?.setColourMode(mode);
});
window.addEventListener('keydown', (e) => {
  if (e.key === 'Escape' && selected !== null) select(null, 'table');
});

// A hook for tests and for the curious: the state the page shows and the 3D view's picking.
declare global {
  interface Window {
    mlmapDashboard?: unknown;
  }
}
window.mlmapDashboard = {
  state: () => ({ state: document.body.dataset.state, patches: data?.planes.length ?? 0, selected, highlighted: view?.highlightedId() ?? null, webgl: view !== null }),
  pickAt: (x: number, y: number) => view?.pickAt(x, y) ?? null,
  project: (point: [number, number, number]) => view?.project(point) ?? null,
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
