// Colours of the classes and of patch ids, shared by the 3D view, the table and the summary.

import type { Patch, PlaneClass } from './planes';

export type ColourMode = 'class' | 'id';

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

export function patchColour(patch: Patch, mode: ColourMode): string {
  return mode === 'class' ? CLASS_COLOURS[patch.label] : idColour(patch.id);
}
