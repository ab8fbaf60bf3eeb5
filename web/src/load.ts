// Where a planes export comes from: ?src=URL, window.MLMAP_PLANES (set by planes.js beside the
// page, as `mlmap export --dashboard DIR` writes it), a file picker or a file dropped on the page.

import { parsePlanes, validatePlanes, PlanesError, type PlanesExport } from './planes';

export interface Loaded {
  data: PlanesExport;
  /** what the data came from, for the title bar: a URL, a file name or "planes.js" */
  origin: string;
}

declare global {
  interface Window {
    MLMAP_PLANES?: unknown;
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

/** The export that planes.js put on window, if any. */
export function loadEmbedded(): Loaded | null {
  if (window.MLMAP_PLANES === undefined) return null;
  try {
    return { data: validatePlanes(window.MLMAP_PLANES), origin: 'planes.js' };
  } catch (e) {
    throw new PlanesError(`Could not load planes.js: ${reason(e)}`);
  }
}

/** What to show at start-up: ?src=URL first, then planes.js, else nothing (the picker). */
export async function loadInitial(): Promise<Loaded | null> {
  const src = new URLSearchParams(location.search).get('src');
  if (src) return loadUrl(src);
  return loadEmbedded();
}

/** Calls onFile for a file dropped anywhere on the page; marks the body while dragging. */
export function watchDrops(onFile: (file: File) => void): void {
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
    const file = e.dataTransfer?.files[0];
    if (file) onFile(file);
  });
}
