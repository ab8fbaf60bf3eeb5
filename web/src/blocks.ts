// The map's blocks and occupied voxels as `mlmap export --dashboard` writes them (blocks.bin,
// mlmap.blocks/1, include/mlmap/io/dashboard_blocks.hpp; voxels.bin, mlmap.voxels/1,
// include/mlmap/io/dashboard_voxels.hpp): a 24-byte header, then one column per field. Read
// into typed arrays, checked as the C++ readers check them.

export interface BlockSet {
  cellSize: number;
  count: number;
  j: Int32Array; // column: x of the cell's centre = (j + 0.5) · cellSize
  i: Int32Array; // row: y of the cell's centre = (i + 0.5) · cellSize
  top: Float32Array; // m, the surface (horizontal) or the top (vertical)
  depth: Float32Array; // m, the extent below the top; 0 for horizontal blocks
  plane: Int32Array; // the planes JSON's id, 0 = none
  kind: Uint8Array; // 0 horizontal, 1 vertical
}

/** Occupied voxels: the centre of voxel k is ((x, y, z)[k] + 0.5) · voxelSize. */
export interface VoxelSet {
  voxelSize: number;
  count: number;
  x: Int32Array;
  y: Int32Array;
  z: Int32Array;
  plane: Int32Array;
}

export class BlocksError extends Error {}

const MAGIC = 'MLBLOCKS';
const HEADER_BYTES = 24;
const BYTES_PER_BLOCK = 21;

/** Reads blocks.bin's bytes; throws BlocksError saying what is wrong. */
export function parseBlocks(buffer: ArrayBuffer): BlockSet {
  const view = new DataView(buffer);
  const magic = buffer.byteLength >= 8 ? String.fromCharCode(...new Uint8Array(buffer, 0, 8)) : '';
  if (buffer.byteLength < HEADER_BYTES || magic !== MAGIC) throw new BlocksError('not an mlmap blocks file (no "MLBLOCKS" header)');
  const version = view.getUint32(8, true);
  if (version !== 1) throw new BlocksError(`blocks file version ${version}, this page knows version 1`);
  const count = view.getUint32(12, true);
  const expected = HEADER_BYTES + BYTES_PER_BLOCK * count;
  if (buffer.byteLength !== expected) {
    throw new BlocksError(`the header says ${count} blocks, which take ${expected} bytes, but the file has ${buffer.byteLength} (cut short or damaged?)`);
  }
  const cellSize = view.getFloat64(16, true);
  if (!Number.isFinite(cellSize) || cellSize <= 0) throw new BlocksError('the cell size is not a positive number');
  // Copies, so each column is aligned whatever the host; DataView reads little-endian anywhere.
  const int32 = (at: number) => { const out = new Int32Array(count); for (let k = 0; k < count; k++) out[k] = view.getInt32(at + 4 * k, true); return out; };
  const float32 = (at: number) => { const out = new Float32Array(count); for (let k = 0; k < count; k++) out[k] = view.getFloat32(at + 4 * k, true); return out; };
  const set: BlockSet = {
    cellSize, count,
    j: int32(HEADER_BYTES), i: int32(HEADER_BYTES + 4 * count),
    top: float32(HEADER_BYTES + 8 * count), depth: float32(HEADER_BYTES + 12 * count),
    plane: int32(HEADER_BYTES + 16 * count), kind: new Uint8Array(buffer.slice(HEADER_BYTES + 20 * count)),
  };
  for (let k = 0; k < count; k++) {
    if (!Number.isFinite(set.top[k])) throw new BlocksError(`block ${k}: the top is not a finite number`);
    if (!(set.depth[k] >= 0) || !Number.isFinite(set.depth[k])) throw new BlocksError(`block ${k}: the depth is not a number ≥ 0`);
    if (set.kind[k] > 1) throw new BlocksError(`block ${k}: kind ${set.kind[k]}, expected 0 (horizontal) or 1 (vertical)`);
  }
  return set;
}

/** Reads voxels.bin's bytes; throws BlocksError saying what is wrong. */
export function parseVoxels(buffer: ArrayBuffer): VoxelSet {
  const view = new DataView(buffer);
  const magic = buffer.byteLength >= 8 ? String.fromCharCode(...new Uint8Array(buffer, 0, 8)) : '';
  if (buffer.byteLength < HEADER_BYTES || magic !== 'MLVOXELS') throw new BlocksError('not an mlmap voxels file (no "MLVOXELS" header)');
  const version = view.getUint32(8, true);
  if (version !== 1) throw new BlocksError(`voxels file version ${version}, this page knows version 1`);
  const count = view.getUint32(12, true);
  const expected = HEADER_BYTES + 16 * count;
  if (buffer.byteLength !== expected) {
    throw new BlocksError(`the header says ${count} voxels, which take ${expected} bytes, but the file has ${buffer.byteLength} (cut short or damaged?)`);
  }
  const voxelSize = view.getFloat64(16, true);
  if (!Number.isFinite(voxelSize) || voxelSize <= 0) throw new BlocksError('the voxel size is not a positive number');
  const int32 = (column: number) => {
    const out = new Int32Array(count);
    for (let k = 0; k < count; k++) out[k] = view.getInt32(HEADER_BYTES + 4 * (column * count + k), true);
    return out;
  };
  return { voxelSize, count, x: int32(0), y: int32(1), z: int32(2), plane: int32(3) };
}

/** blocks.js holds the file as base64 (window.MLMAP_BLOCKS), since file:// pages cannot fetch. */
export function base64ToBuffer(text: string): ArrayBuffer {
  let binary: string;
  try {
    binary = atob(text);
  } catch {
    throw new BlocksError('not base64 text');
  }
  const bytes = new Uint8Array(binary.length);
  for (let k = 0; k < binary.length; k++) bytes[k] = binary.charCodeAt(k);
  return bytes.buffer;
}

/** The lowest and highest z any block reaches. */
export function blockHeights(set: BlockSet): { min: number; max: number } {
  let min = Infinity, max = -Infinity;
  for (let k = 0; k < set.count; k++) {
    min = Math.min(min, set.top[k] - set.depth[k]);
    max = Math.max(max, set.top[k]);
  }
  return { min, max };
}
