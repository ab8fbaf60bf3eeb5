// The mlmap.planes/1 export (web/planes.schema.json) as types, and a small validator that
// checks what the dashboard relies on: the schema tag, the required fields and their types.

export const SCHEMA = 'mlmap.planes/1';

export type Vec3 = [number, number, number];

export const CLASSES = ['floor', 'ceiling', 'wall', 'table', 'step', 'other'] as const;
export type PlaneClass = (typeof CLASSES)[number];

export interface Patch {
  id: number;
  label: PlaneClass;
  cityjson_type?: string;
  normal: Vec3;
  offset: number;
  centroid: Vec3;
  area: number;
  blocks: number;
  rms: number;
  outline: Vec3[];
  source_plane: number;
  candidates: number;
}

export interface PlanesExport {
  schema: typeof SCHEMA;
  map: {
    source: string;
    cell_size: number;
    cells: number;
    blocks: number;
    bounds: { min: Vec3; max: Vec3 };
  };
  parameters: Record<string, number>;
  detection: Record<string, number>;
  timings: { direction_vectors_s: number; detection_s: number; total_s: number } & Record<string, number>;
  planes: Patch[];
}

/** Thrown for input that is not a usable planes export; the message is shown to the user. */
export class PlanesError extends Error {}

type Json = unknown;

function isObject(v: Json): v is Record<string, Json> {
  return typeof v === 'object' && v !== null && !Array.isArray(v);
}

function fail(path: string, what: string): never {
  throw new PlanesError(`${path}: ${what}`);
}

function object(v: Json, path: string): Record<string, Json> {
  if (!isObject(v)) fail(path, 'expected an object');
  return v;
}

function field(obj: Record<string, Json>, key: string, path: string): Json {
  if (!(key in obj)) fail(path, `missing required field "${key}"`);
  return obj[key];
}

function number(v: Json, path: string, min?: number, exclusive = false): number {
  if (typeof v !== 'number' || !Number.isFinite(v)) fail(path, 'expected a finite number');
  if (min !== undefined && (exclusive ? v <= min : v < min)) {
    fail(path, `expected a number ${exclusive ? '>' : '≥'} ${min}, got ${v}`);
  }
  return v;
}

function integer(v: Json, path: string, min?: number): number {
  const n = number(v, path, min);
  if (!Number.isInteger(n)) fail(path, `expected an integer, got ${n}`);
  return n;
}

function vec3(v: Json, path: string): Vec3 {
  if (!Array.isArray(v) || v.length !== 3) fail(path, 'expected an array of 3 numbers');
  return [number(v[0], `${path}[0]`), number(v[1], `${path}[1]`), number(v[2], `${path}[2]`)];
}

function numberRecord(v: Json, path: string, required: string[], isInteger: boolean): Record<string, number> {
  const obj = object(v, path);
  for (const key of required) field(obj, key, path);
  const out: Record<string, number> = {};
  for (const [key, value] of Object.entries(obj)) {
    out[key] = isInteger ? integer(value, `${path}.${key}`, 0) : number(value, `${path}.${key}`);
  }
  return out;
}

function patch(v: Json, path: string): Patch {
  const p = object(v, path);
  const label = field(p, 'label', path);
  if (typeof label !== 'string' || !(CLASSES as readonly string[]).includes(label)) {
    fail(`${path}.label`, `expected one of ${CLASSES.join(', ')}, got ${JSON.stringify(label)}`);
  }
  const outline = field(p, 'outline', path);
  if (!Array.isArray(outline)) fail(`${path}.outline`, 'expected an array of points');
  const result: Patch = {
    id: integer(field(p, 'id', path), `${path}.id`, 1),
    label: label as PlaneClass,
    normal: vec3(field(p, 'normal', path), `${path}.normal`),
    offset: number(field(p, 'offset', path), `${path}.offset`),
    centroid: vec3(field(p, 'centroid', path), `${path}.centroid`),
    area: number(field(p, 'area', path), `${path}.area`, 0),
    blocks: integer(field(p, 'blocks', path), `${path}.blocks`, 1),
    rms: number(field(p, 'rms', path), `${path}.rms`, 0),
    outline: outline.map((q, i) => vec3(q, `${path}.outline[${i}]`)),
    source_plane: integer(field(p, 'source_plane', path), `${path}.source_plane`, 1),
    candidates: integer(field(p, 'candidates', path), `${path}.candidates`, 0),
  };
  if (typeof p.cityjson_type === 'string') result.cityjson_type = p.cityjson_type;
  return result;
}

/** Checks a parsed JSON value against the essentials of mlmap.planes/1; throws PlanesError. */
export function validatePlanes(data: Json): PlanesExport {
  if (!isObject(data)) throw new PlanesError('Not an mlmap planes export: the file holds no JSON object.');
  if (data.schema !== SCHEMA) {
    const found = 'schema' in data ? JSON.stringify(data.schema) : 'no "schema" field';
    throw new PlanesError(`Not an mlmap planes export: schema is ${found}, expected "${SCHEMA}".`);
  }
  const map = object(field(data, 'map', '(root)'), 'map');
  const source = field(map, 'source', 'map');
  if (typeof source !== 'string') fail('map.source', 'expected a string');
  const bounds = object(field(map, 'bounds', 'map'), 'map.bounds');
  const timings = numberRecord(field(data, 'timings', '(root)'), 'timings', ['direction_vectors_s', 'detection_s', 'total_s'], false);
  const planesJson = field(data, 'planes', '(root)');
  if (!Array.isArray(planesJson)) fail('planes', 'expected an array');
  const planes = planesJson.map((p, i) => patch(p, `planes[${i}]`));
  const seen = new Set<number>();
  for (const p of planes) {
    if (seen.has(p.id)) fail('planes', `patch id ${p.id} occurs twice`);
    seen.add(p.id);
  }
  return {
    schema: SCHEMA,
    map: {
      source,
      cell_size: number(field(map, 'cell_size', 'map'), 'map.cell_size', 0, true),
      cells: integer(field(map, 'cells', 'map'), 'map.cells', 0),
      blocks: integer(field(map, 'blocks', 'map'), 'map.blocks', 0),
      bounds: { min: vec3(field(bounds, 'min', 'map.bounds'), 'map.bounds.min'), max: vec3(field(bounds, 'max', 'map.bounds'), 'map.bounds.max') },
    },
    parameters: numberRecord(field(data, 'parameters', '(root)'), 'parameters',
      ['radius_cells', 'epsilon', 'kappa_deg', 'theta_deg', 'min_probability', 'min_area', 'max_candidates', 'seed'], false),
    detection: numberRecord(field(data, 'detection', '(root)'), 'detection',
      ['candidates', 'scored', 'accepted', 'labelled_blocks', 'blocks_with_direction'], true),
    timings: timings as PlanesExport['timings'],
    planes,
  };
}

/** Parses the text of a file and validates it; throws PlanesError with a readable reason. */
export function parsePlanes(text: string): PlanesExport {
  let data: Json;
  try {
    data = JSON.parse(text);
  } catch (e) {
    const reason = e instanceof Error ? e.message : String(e);
    throw new PlanesError(`The file is not valid JSON (damaged or cut short?): ${reason}`);
  }
  return validatePlanes(data);
}
