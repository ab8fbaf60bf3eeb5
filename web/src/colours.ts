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

/** A distinct, stable colour per id: hues spread by the golden angle. */
export function idColour(id: number): string {
  const hue = (id * 137.508) % 360;
  return `hsl(${hue.toFixed(1)}, 62%, 58%)`;
}

export function patchColour(patch: Patch, mode: ColourMode): string {
  return mode === 'class' ? CLASS_COLOURS[patch.label] : idColour(patch.id);
}
