// Where a planes export comes from: ?src=URL, window.MLMAP_PLANES (set by planes.js beside the
// page, as `mlmap export --dashboard DIR` writes it), a file picker or a file dropped on the page.
// The blocks likewise: ?blocks=URL, window.MLMAP_BLOCKS (blocks.js, base64) or a picked blocks.bin;
// and the voxels: ?voxels=URL, window.MLMAP_VOXELS (voxels.js) or a picked voxels.bin.

import { parsePlanes, validatePlanes, PlanesError, type PlanesExport } from './planes';
import { base64ToBuffer, parseBlocks, parseVoxels, type BlockSet, type VoxelSet } from './blocks';

export interface Loaded {
  data: PlanesExport;
  /** what the data came from, for the title bar: a URL, a file name or "planes.js" */
  origin: string;
  blocks?: BlockSet;
  voxels?: VoxelSet;
  /** why the blocks or voxels beside the planes could not be read; the planes are shown without them */
  blocksError?: string;
}

declare global {
  interface Window {
    MLMAP_PLANES?: unknown;
    MLMAP_BLOCKS?: unknown;
    MLMAP_VOXELS?: unknown;
  }
}

function reason(e: unknown): string {
  if (e instanceof PlanesError) return e.message;
  return e instanceof Error ? e.message : String(e);
}

/** Reads a File (from the picker or a drop). */
export async function loadFile(file: File): Promise<Loaded> {
  let text: string;
  try {
    text = await file.text();
  } catch (e) {
    throw new PlanesError(`Could not read ${file.name}: ${reason(e)}`);
  }
  try {
    return { data: parsePlanes(text), origin: file.name };
  } catch (e) {
    throw new PlanesError(`Could not load ${file.name}: ${reason(e)}`);
  }
}

/** Fetches a URL (the ?src= parameter). */
export async function loadUrl(url: string): Promise<Loaded> {
  let text: string;
  try {
    const response = await fetch(url);
    if (!response.ok) throw new Error(`HTTP ${response.status} ${response.statusText}`.trim());
    text = await response.text();
  } catch (e) {
    const hint = location.protocol === 'file:'
      ? ' (pages opened from disk cannot fetch files; put planes.js beside the page or use a static server)'
      : '';
    throw new PlanesError(`Could not fetch ${url}: ${reason(e)}${hint}`);
  }
  try {
    return { data: parsePlanes(text), origin: url };
  } catch (e) {
    throw new PlanesError(`Could not load ${url}: ${reason(e)}`);
  }
}

/** Reads a blocks.bin or voxels.bin File; throws PlanesError naming it. */
export async function loadBinaryFile<T>(file: File, parse: (buffer: ArrayBuffer) => T): Promise<T> {
  try {
    return parse(await file.arrayBuffer());
  } catch (e) {
    throw new PlanesError(`Could not load ${file.name}: ${reason(e)}`);
  }
}

/** What a picked file holds, told by its first bytes (a planes JSON starts with text). */
export async function fileKind(file: File): Promise<'planes' | 'blocks' | 'voxels'> {
  const head = String.fromCharCode(...new Uint8Array(await file.slice(0, 8).arrayBuffer()));
  if (head === 'MLBLOCKS' || (file.name.endsWith('.bin') && head !== 'MLVOXELS')) return 'blocks';
  return head === 'MLVOXELS' ? 'voxels' : 'planes';
}

async function fetchBinary<T>(url: string, what: string, parse: (buffer: ArrayBuffer) => T): Promise<T> {
  try {
    const response = await fetch(url);
    if (!response.ok) throw new Error(`HTTP ${response.status} ${response.statusText}`.trim());
    return parse(await response.arrayBuffer());
  } catch (e) {
    throw new PlanesError(`Could not load the ${what} ${url}: ${reason(e)}`);
  }
}

function embedded<T>(value: unknown, file: string, parse: (buffer: ArrayBuffer) => T): T | undefined {
  if (value === undefined) return undefined;
  if (typeof value !== 'string') throw new PlanesError(`Could not load ${file}: it does not hold a base64 string`);
  try {
    return parse(base64ToBuffer(value));
  } catch (e) {
    throw new PlanesError(`Could not load ${file}: ${reason(e)}`);
  }
}

/** The export that planes.js put on window, if any, with the blocks of blocks.js. */
export function loadEmbedded(): Loaded | null {
  if (window.MLMAP_PLANES === undefined) return null;
  let loaded: Loaded;
  try {
    loaded = { data: validatePlanes(window.MLMAP_PLANES), origin: 'planes.js' };
  } catch (e) {
    throw new PlanesError(`Could not load planes.js: ${reason(e)}`);
  }
  try {
    loaded.blocks = embedded(window.MLMAP_BLOCKS, 'blocks.js', parseBlocks);
    loaded.voxels = embedded(window.MLMAP_VOXELS, 'voxels.js', parseVoxels);
  } catch (e) {
    loaded.blocksError = reason(e);
  }
  return loaded;
}

/** What to show at start-up: ?src=URL (and ?blocks=URL) first, then planes.js, else nothing (the picker). */
export async function loadInitial(): Promise<Loaded | null> {
  const params = new URLSearchParams(location.search);
  const src = params.get('src');
  if (!src) return loadEmbedded();
  const loaded = await loadUrl(src);
  const blocks = params.get('blocks');
  const voxels = params.get('voxels');
  try {
    if (blocks) loaded.blocks = await fetchBinary(blocks, 'blocks', parseBlocks);
    if (voxels) loaded.voxels = await fetchBinary(voxels, 'voxels', parseVoxels);
  } catch (e) {
    loaded.blocksError = reason(e);
  }
  return loaded;
}

/** Calls onFiles for files dropped anywhere on the page; marks the body while dragging. */
export function watchDrops(onFiles: (files: File[]) => void): void {
  let depth = 0;
  const hasFiles = (e: DragEvent) => Array.from(e.dataTransfer?.types ?? []).includes('Files');
  window.addEventListener('dragenter', (e) => {
    if (!hasFiles(e)) return;
    e.preventDefault();
    depth++;
    document.body.classList.add('dragging');
  });
  window.addEventListener('dragover', (e) => {
    if (!hasFiles(e)) return;
    e.preventDefault();
    if (e.dataTransfer) e.dataTransfer.dropEffect = 'copy';
  });
  window.addEventListener('dragleave', () => {
    depth = Math.max(0, depth - 1);
    if (depth === 0) document.body.classList.remove('dragging');
  });
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    depth = 0;
    document.body.classList.remove('dragging');
    const files = Array.from(e.dataTransfer?.files ?? []);
    if (files.length) onFiles(files);
  });
}
