// Colours of the classes and of patch ids, shared by the 3D view, the table and the summary.

import type { Patch, PlaneClass } from './planes';

export type ColourMode = 'class' | 'id' | 'height';

/** Blocks on no plane, in the class and id modes. */
export const UNLABELLED_COLOUR = '#6f7683';

export const CLASS_COLOURS: Record<PlaneClass, string> = {
  floor: '#4f8fd8',
  ceiling: '#c9ccd6',
  wall: '#e8a04a',
  table: '#5cc27a',
  step: '#b57bdc',
  other: '#8a8f99',
};

/**
 * A distinct, stable colour per id, the same as the voxels of `mlmap export --octovis`
 * (io::planeColour): hues spread by the golden ratio, brightness alternating with the id.
 */
export function idColour(id: number): string {
  if (id <= 0) return 'rgb(150, 150, 150)';
  const hue = (0.1 + id * 0.6180339887498949) % 1;
  const value = id % 2 === 0 ? 0.8 : 0.95;
  const saturation = 0.7;
  const sector = hue * 6;
  const whole = Math.floor(sector) % 6;
  const fraction = sector - Math.floor(sector);
  const p = value * (1 - saturation);
  const q = value * (1 - saturation * fraction);
  const t = value * (1 - saturation * (1 - fraction));
  const [r, g, b] = [
    [value, t, p],
    [q, value, p],
    [p, value, t],
    [p, q, value],
    [t, p, value],
    [value, p, q],
  ][whole];
  const byte = (channel: number) => Math.round(channel * 255);
  return `rgb(${byte(r)}, ${byte(g)}, ${byte(b)})`;
}

/** The z range the height colours span; set by the page from the map's bounds. */
export const heightRange = { min: 0, max: 3 };

// Blue (low) through cyan, green and yellow to red (high): neighbouring storeys differ in hue.
const RAMP: [number, number, number][] = [[0.19, 0.33, 0.85], [0.16, 0.72, 0.85], [0.3, 0.78, 0.36], [0.96, 0.84, 0.25], [0.9, 0.3, 0.22]];

/** The height colour of z as r, g, b in 0..1. */
export function heightRgb(z: number, out: [number, number, number] = [0, 0, 0]): [number, number, number] {
  const span = heightRange.max - heightRange.min;
  const t = Math.min(1, Math.max(0, span > 0 ? (z - heightRange.min) / span : 0.5)) * (RAMP.length - 1);
  const k = Math.min(RAMP.length - 2, Math.floor(t));
  const f = t - k;
  for (let c = 0; c < 3; c++) out[c] = RAMP[k][c] + (RAMP[k + 1][c] - RAMP[k][c]) * f;
  return out;
}

export function heightColour(z: number): string {
  const [r, g, b] = heightRgb(z).map((c) => Math.round(c * 255));
  return `rgb(${r}, ${g}, ${b})`;
}

export function patchColour(patch: Patch, mode: ColourMode): string {
  if (mode === 'height') return heightColour(patch.centroid[2]);
  return mode === 'class' ? CLASS_COLOURS[patch.label] : idColour(patch.id);
}
