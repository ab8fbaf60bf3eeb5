// The blocks and voxels layers of the 3D view: every block (or voxel) a box, drawn in one
// instanced draw call. An instance is a chunk of CHUNK boxes (8 corners each, shaded flat), whose
// places, sizes and colours the vertex shader reads from data textures: 48 bytes a box on the
// GPU. Not one instance a box: software WebGL (SwiftShader, what a browser without a GPU uses)
// runs each instance as a draw of its own, at ~37 µs a box measured on a 2-core machine
// (0.75 s a frame for 20k blocks); chunks cut that overhead CHUNK-fold. A click is found by a
// ray-box test over the boxes' columns rather than three.js' per-instance raycast.

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

/** A fixed shuffle of 0..n-1 (xorshift, seeded): any prefix of it is an even sample of the boxes. */
function shuffled(n: number): Uint32Array {
  const order = new Uint32Array(n);
  for (let k = 0; k < n; k++) order[k] = k;
  let x = 0x9e3779b9;
  for (let k = n - 1; k > 0; k--) {
    x ^= x << 13; x ^= x >>> 17; x ^= x << 5;
    const r = (x >>> 0) % (k + 1);
    const t = order[k]; order[k] = order[r]; order[r] = t;
  }
  return order;
}

// boxes an instance; the texture's width in texels (a box a texel in each texture)
const CHUNK = 64;
const TEXTURE_WIDTH = 2048;

/** CHUNK unit boxes (corners at ±0.5) with their index in the chunk, faced outwards as BoxGeometry is. */
function chunkGeometry(): THREE.InstancedBufferGeometry {
  const box = new THREE.BoxGeometry(1, 1, 1);
  const p = box.getAttribute('position');
  // BoxGeometry's 24 vertices (4 a face) onto the box's 8 corners: corner = x + 2y + 4z.
  const cornerOf = (v: number) => (p.getX(v) > 0 ? 1 : 0) + (p.getY(v) > 0 ? 2 : 0) + (p.getZ(v) > 0 ? 4 : 0);
  const triangles = Array.from(box.getIndex()!.array, cornerOf);
  box.dispose();
  const position = new Float32Array(CHUNK * 8 * 3), slot = new Float32Array(CHUNK * 8);
  const index = new Uint32Array(CHUNK * triangles.length);
  for (let b = 0; b < CHUNK; b++) {
    for (let c = 0; c < 8; c++) {
      position.set([c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5], 3 * (8 * b + c));
      slot[8 * b + c] = b;
    }
    for (let t = 0; t < triangles.length; t++) index[b * triangles.length + t] = 8 * b + triangles[t];
  }
  const geometry = new THREE.InstancedBufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('boxSlot', new THREE.BufferAttribute(slot, 1));
  geometry.setIndex(new THREE.BufferAttribute(index, 1));
  return geometry;
}

function dataTexture(data: Float32Array, rows: number): THREE.DataTexture {
  const texture = new THREE.DataTexture(data, TEXTURE_WIDTH, rows, THREE.RGBAFormat, THREE.FloatType);
  texture.minFilter = texture.magFilter = THREE.NearestFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  return texture;
}

export class BoxLayer {
  readonly mesh: THREE.Mesh<THREE.InstancedBufferGeometry, THREE.MeshLambertMaterial>;
  private readonly order: Uint32Array; // the boxes in a fixed shuffled order
  private readonly shown: Uint8Array; // per box: 1 while drawn (its plane passes the filter)
  private readonly colours: Float32Array; // per box: r g b
  // The GPU's slots: the shown boxes in shuffled order, so drawing only the first m of them
  // (while the view moves) draws an even sample of the map, not one corner of it. Slots past
  // the shown boxes have size 0.
  private readonly slotCentre: THREE.DataTexture;
  private readonly slotSize: THREE.DataTexture;
  private readonly slotColour: THREE.DataTexture;
  private shownCount: number;
  private readonly chunkOffset = { value: 0 }; // the first chunk drawn (a uniform)

  constructor(readonly boxes: Boxes, clipping: THREE.Plane[], name: string) {
    const n = boxes.count;
    this.order = shuffled(n);
    this.shown = new Uint8Array(n).fill(1);
    this.shownCount = n;
    this.colours = new Float32Array(3 * n);
    const rows = Math.max(1, Math.ceil(n / TEXTURE_WIDTH));
    const texels = () => new Float32Array(4 * TEXTURE_WIDTH * rows);
    this.slotCentre = dataTexture(texels(), rows);
    this.slotSize = dataTexture(texels(), rows);
    this.slotColour = dataTexture(texels(), rows);
    const geometry = chunkGeometry();
    // Shaded flat (normals from the screen-space slopes): a box needs only its 8 corners.
    const material = new THREE.MeshLambertMaterial({ vertexColors: true, flatShading: true, clippingPlanes: clipping });
    material.onBeforeCompile = (shader) => {
      shader.uniforms.boxCentres = { value: this.slotCentre };
      shader.uniforms.boxSizes = { value: this.slotSize };
      shader.uniforms.boxColours = { value: this.slotColour };
      shader.uniforms.chunkOffset = this.chunkOffset;
      shader.vertexShader = shader.vertexShader
        .replace('#include <common>', `#include <common>
attribute float boxSlot;
uniform highp sampler2D boxCentres;
uniform highp sampler2D boxSizes;
uniform highp sampler2D boxColours;
uniform int chunkOffset;`)
        .replace('#include <color_vertex>', `int boxIndex = (gl_InstanceID + chunkOffset) * ${CHUNK} + int(boxSlot);
ivec2 boxTexel = ivec2(boxIndex % ${TEXTURE_WIDTH}, boxIndex / ${TEXTURE_WIDTH});
vColor = vec4(texelFetch(boxColours, boxTexel, 0).rgb, 1.0);`)
        .replace('#include <begin_vertex>', 'vec3 transformed = position * texelFetch(boxSizes, boxTexel, 0).xyz + texelFetch(boxCentres, boxTexel, 0).xyz;');
    };
    material.customProgramCacheKey = () => `mlmap-boxes-${CHUNK}-${TEXTURE_WIDTH}`;
    this.mesh = new THREE.Mesh(geometry, material);
    this.mesh.frustumCulled = false; // the geometry's bounds are the unit boxes', not the boxes'
    this.mesh.name = name;
    this.layout();
  }

  /** How many boxes are shown (pass the filter). */
  get count(): number {
    return this.shownCount;
  }

  /** How many chunks (instances) the shown boxes fill. */
  get chunks(): number {
    return Math.ceil(this.shownCount / CHUNK);
  }

  /** The next draw draws chunks [from, to) only (a frame of a picture drawn over several). */
  setRange(from: number, to: number): void {
    this.chunkOffset.value = from;
    this.mesh.geometry.instanceCount = Math.max(0, to - from);
  }

  /** Colours every box by mode (height: of its top); the boxes of `highlighted` in the highlight colour. */
  recolour(mode: ColourMode, classOf: (plane: number) => PlaneClass | undefined, highlighted: number | null, highlight: THREE.Color): void {
    const { boxes, colours } = this;
    const byPlane = new Map<number, THREE.Color>();
    const unlabelled = new THREE.Color(UNLABELLED_COLOUR);
    const rgb: [number, number, number] = [0, 0, 0];
    for (let k = 0; k < boxes.count; k++) {
      const plane = boxes.plane[k];
      if (plane === highlighted && plane !== 0) {
        colours[3 * k] = highlight.r; colours[3 * k + 1] = highlight.g; colours[3 * k + 2] = highlight.b;
      } else if (mode === 'height') {
        heightRgb(boxes.centre[3 * k + 2] + boxes.size[3 * k + 2] / 2, rgb);
        colours[3 * k] = rgb[0]; colours[3 * k + 1] = rgb[1]; colours[3 * k + 2] = rgb[2];
      } else {
        let c = byPlane.get(plane);
        if (!c) {
          const cls = plane === 0 ? undefined : classOf(plane);
          c = plane === 0 ? unlabelled : new THREE.Color(mode === 'class' ? (cls ? CLASS_COLOURS[cls] : UNLABELLED_COLOUR) : idColour(plane));
          byPlane.set(plane, c);
        }
        colours[3 * k] = c.r; colours[3 * k + 1] = c.g; colours[3 * k + 2] = c.b;
      }
    }
    this.writeSlots(false);
  }

  /** Shows only the boxes whose plane passes `shown` (plane 0: on none). */
  setVisible(shown: (plane: number) => boolean): void {
    const { boxes } = this;
    const verdict = new Map<number, boolean>();
    let changed = false;
    for (let k = 0; k < boxes.count; k++) {
      const plane = boxes.plane[k];
      let v = verdict.get(plane);
      if (v === undefined) { v = shown(plane); verdict.set(plane, v); }
      const flag = v ? 1 : 0;
      if (this.shown[k] !== flag) { this.shown[k] = flag; changed = true; }
    }
    if (changed) this.layout();
  }

  /** Puts the shown boxes, shuffled, into the first slots; draws them all. */
  private layout(): void {
    this.writeSlots(true);
    this.setRange(0, this.chunks);
  }

  private writeSlots(placeAlso: boolean): void {
    const { order, shown, colours, boxes } = this;
    const centre = this.slotCentre.image.data as Float32Array, size = this.slotSize.image.data as Float32Array;
    const colour = this.slotColour.image.data as Float32Array;
    let s = 0;
    for (let o = 0; o < order.length; o++) {
      const k = order[o];
      if (!shown[k]) continue;
      for (let a = 0; a < 3; a++) {
        colour[4 * s + a] = colours[3 * k + a];
        if (placeAlso) {
          centre[4 * s + a] = boxes.centre[3 * k + a];
          size[4 * s + a] = boxes.size[3 * k + a];
        }
      }
      s++;
    }
    this.shownCount = s;
    this.slotColour.needsUpdate = true;
    if (placeAlso) {
      size.fill(0, 4 * s); // the last chunk's slots past the shown boxes draw nothing
      this.slotCentre.needsUpdate = true;
      this.slotSize.needsUpdate = true;
    }
  }

  /** The nearest shown box the ray meets inside the height cut [bottom, top], or null. */
  pick(ray: THREE.Ray, bottom: number, top: number): BoxHit | null {
    const origin = [ray.origin.x, ray.origin.y, ray.origin.z];
    const inverse = [1 / ray.direction.x, 1 / ray.direction.y, 1 / ray.direction.z];
    const { centre, size } = this.boxes, shown = this.shown;
    let best = Infinity, bestK = -1;
    for (let k = 0; k < this.boxes.count; k++) {
      if (!shown[k]) continue;
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
    for (const texture of [this.slotCentre, this.slotSize, this.slotColour]) texture.dispose();
  }
}
