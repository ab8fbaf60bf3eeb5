// The blocks and voxels layers of the 3D view: every block (or voxel) as one instance of a
// unit box, moved and scaled in the vertex shader to its place. One draw call and 36 bytes a
// box on the GPU (centre, size, colour), so ~300k blocks stay interactive; a click is found by
// a ray-box test over the boxes' columns rather than three.js' per-instance raycast.

import * as THREE from 'three';
import type { BlockSet, VoxelSet } from './blocks';
import { CLASS_COLOURS, UNLABELLED_COLOUR, heightRgb, idColour, type ColourMode } from './colours';
import type { PlaneClass } from './planes';

// Horizontal blocks have no depth: drawn as slabs this fraction of a cell thick, top at h.
const SLAB_CELLS = 0.25;

/** Axis-aligned boxes, each on a plane (0 = none), as flat columns. */
export interface Boxes {
  count: number;
  centre: Float32Array; // x y z per box
  size: Float32Array; // x y z per box
  plane: Int32Array;
}

export function blockBoxes(set: BlockSet): Boxes {
  const n = set.count, s = set.cellSize;
  const centre = new Float32Array(3 * n), size = new Float32Array(3 * n);
  for (let k = 0; k < n; k++) {
    const vertical = set.kind[k] === 1 && set.depth[k] > 0;
    const height = vertical ? set.depth[k] : SLAB_CELLS * s;
    centre.set([(set.j[k] + 0.5) * s, (set.i[k] + 0.5) * s, set.top[k] - height / 2], 3 * k);
    size.set([s, s, height], 3 * k);
  }
  return { count: n, centre, size, plane: set.plane };
}

export function voxelBoxes(set: VoxelSet): Boxes {
  const n = set.count, s = set.voxelSize;
  const centre = new Float32Array(3 * n), size = new Float32Array(3 * n).fill(s);
  for (let k = 0; k < n; k++) centre.set([(set.x[k] + 0.5) * s, (set.y[k] + 0.5) * s, (set.z[k] + 0.5) * s], 3 * k);
  return { count: n, centre, size, plane: set.plane };
}

export interface BoxHit {
  box: number;
  plane: number;
  distance: number;
  point: THREE.Vector3;
}

export class BoxLayer {
  readonly mesh: THREE.Mesh<THREE.InstancedBufferGeometry, THREE.MeshLambertMaterial>;
  private readonly shownSize: Float32Array; // the box's size, or 0 0 0 while hidden
  private readonly sizeAttribute: THREE.InstancedBufferAttribute;
  private readonly colourAttribute: THREE.InstancedBufferAttribute;

  constructor(readonly boxes: Boxes, clipping: THREE.Plane[], name: string) {
    const n = boxes.count;
    this.shownSize = boxes.size.slice();
    const box = new THREE.BoxGeometry(1, 1, 1);
    const geometry = new THREE.InstancedBufferGeometry();
    geometry.setIndex(box.getIndex());
    geometry.setAttribute('position', box.getAttribute('position'));
    geometry.setAttribute('normal', box.getAttribute('normal'));
    geometry.setAttribute('boxCentre', new THREE.InstancedBufferAttribute(boxes.centre, 3));
    this.sizeAttribute = new THREE.InstancedBufferAttribute(this.shownSize, 3);
    geometry.setAttribute('boxSize', this.sizeAttribute);
    // Named "color" so the material's vertexColors reads it, once per instance.
    this.colourAttribute = new THREE.InstancedBufferAttribute(new Float32Array(3 * n), 3);
    geometry.setAttribute('color', this.colourAttribute);
    geometry.instanceCount = n;
    const material = new THREE.MeshLambertMaterial({ vertexColors: true, clippingPlanes: clipping });
    material.onBeforeCompile = (shader) => {
      shader.vertexShader = shader.vertexShader
        .replace('#include <common>', '#include <common>\nattribute vec3 boxCentre;\nattribute vec3 boxSize;')
        .replace('#include <begin_vertex>', 'vec3 transformed = position * boxSize + boxCentre;');
    };
    this.mesh = new THREE.Mesh(geometry, material);
    this.mesh.frustumCulled = false; // the geometry's bounds are the unit box's, not the boxes'
    this.mesh.name = name;
  }

  /** Colours every box by mode (height: of its top); the boxes of `highlighted` in the highlight colour. */
  recolour(mode: ColourMode, classOf: (plane: number) => PlaneClass | undefined, highlighted: number | null, highlight: THREE.Color): void {
    const { boxes } = this;
    const colours = this.colourAttribute.array as Float32Array;
    const byPlane = new Map<number, THREE.Color>();
    const unlabelled = new THREE.Color(UNLABELLED_COLOUR);
    const rgb: [number, number, number] = [0, 0, 0];
    for (let k = 0; k < boxes.count; k++) {
      const plane = boxes.plane[k];
      if (plane === highlighted && plane !== 0) {
        colours.set([highlight.r, highlight.g, highlight.b], 3 * k);
      } else if (mode === 'height') {
        colours.set(heightRgb(boxes.centre[3 * k + 2] + boxes.size[3 * k + 2] / 2, rgb), 3 * k);
      } else {
        let c = byPlane.get(plane);
        if (!c) {
          const cls = plane === 0 ? undefined : classOf(plane);
          c = plane === 0 ? unlabelled : new THREE.Color(mode === 'class' ? (cls ? CLASS_COLOURS[cls] : UNLABELLED_COLOUR) : idColour(plane));
          byPlane.set(plane, c);
        }
        colours.set([c.r, c.g, c.b], 3 * k);
      }
    }
    this.colourAttribute.needsUpdate = true;
  }

  /** Shows only the boxes whose plane passes `shown` (plane 0: on none). */
  setVisible(shown: (plane: number) => boolean): void {
    const { boxes } = this;
    for (let k = 0; k < boxes.count; k++) {
      if (shown(boxes.plane[k])) this.shownSize.set(boxes.size.subarray(3 * k, 3 * k + 3), 3 * k);
      else this.shownSize.fill(0, 3 * k, 3 * k + 3);
    }
    this.sizeAttribute.needsUpdate = true;
  }

  /** The nearest shown box the ray meets inside the height cut [bottom, top], or null. */
  pick(ray: THREE.Ray, bottom: number, top: number): BoxHit | null {
    const origin = [ray.origin.x, ray.origin.y, ray.origin.z];
    const inverse = [1 / ray.direction.x, 1 / ray.direction.y, 1 / ray.direction.z];
    const { centre } = this.boxes, size = this.shownSize;
    let best = Infinity, bestK = -1;
    for (let k = 0; k < this.boxes.count; k++) {
      if (size[3 * k] === 0) continue;
      let near = 0, far = best;
      for (let a = 0; a < 3 && near <= far; a++) {
        const half = size[3 * k + a] / 2;
        let lo = centre[3 * k + a] - half, hi = centre[3 * k + a] + half;
        if (a === 2) {
          lo = Math.max(lo, bottom);
          hi = Math.min(hi, top);
          if (lo > hi) { near = Infinity; continue; } // wholly cut away
        }
        if (inverse[a] === Infinity || inverse[a] === -Infinity) {
          // Parallel to this pair of faces: inside the slab or never.
          if (origin[a] < lo || origin[a] > hi) near = Infinity;
          continue;
        }
        let t0 = (lo - origin[a]) * inverse[a], t1 = (hi - origin[a]) * inverse[a];
        if (t0 > t1) [t0, t1] = [t1, t0];
        if (t0 > near) near = t0;
        if (t1 < far) far = t1;
      }
      if (near <= far && near < best) { best = near; bestK = k; }
    }
    if (bestK < 0) return null;
    return { box: bestK, plane: this.boxes.plane[bestK], distance: best, point: ray.at(best, new THREE.Vector3()) };
  }

  dispose(): void {
    this.mesh.geometry.dispose();
    this.mesh.material.dispose();
  }
}
