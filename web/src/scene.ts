// The 3D view: every patch as its filled outline polygon (metres, z up), the blocks and voxels layers, a
// floor grid, the map's bounds as a box, orbit/pan/zoom, a height cut (clipping planes on the
// patches and blocks), top / side / reset views, measure markers, and picking by clicking.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { Patch, PlaneClass, PlanesExport, Vec3 } from './planes';
import { patchColour, type ColourMode } from './colours';
import type { BlockSet, VoxelSet } from './blocks';
import { BoxLayer, blockBoxes, voxelBoxes } from './block_layer';
import { BOX_LAYER, OVERLAY_LAYER, Pictures, softwareWebGL } from './pictures';

const HIGHLIGHT = new THREE.Color('#ffe14d');
const BACKGROUND = new THREE.Color('#1b202a');
// m, a cut's plane this far away cuts nothing
const NO_CUT = 1e6;

/** What a click or a probe found: a patch's id (null for an unlabelled block) and the point hit. */
export interface Hit {
  id: number | null;
  point: Vec3;
  what: 'patch' | 'block' | 'voxel';
}

export interface Layers {
  patches: boolean;
  blocks: boolean;
  voxels: boolean;
}

interface PatchObjects {
  patch: Patch;
  fill: THREE.Mesh<THREE.BufferGeometry, THREE.MeshLambertMaterial>;
  edge: THREE.LineLoop<THREE.BufferGeometry, THREE.LineBasicMaterial>;
}

/** Triangles filling a planar polygon: project it on its plane, ear-clip in 2D. */
function fillGeometry(patch: Patch): THREE.BufferGeometry | null {
  const points = patch.outline.map((p) => new THREE.Vector3(p[0], p[1], p[2]));
  if (points.length > 3 && points[0].distanceTo(points[points.length - 1]) < 1e-9) points.pop();
  if (points.length < 3) return null;
  const n = new THREE.Vector3(...patch.normal).normalize();
  const helper = Math.abs(n.z) < 0.9 ? new THREE.Vector3(0, 0, 1) : new THREE.Vector3(1, 0, 0);
  const u = new THREE.Vector3().crossVectors(helper, n).normalize();
  const v = new THREE.Vector3().crossVectors(n, u);
  const flat = points.map((p) => new THREE.Vector2(p.dot(u), p.dot(v)));
  const triangles = THREE.ShapeUtils.triangulateShape(flat, []);
  if (triangles.length === 0) return null;
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  geometry.setIndex(triangles.flat());
  const normals = new Float32Array(points.length * 3);
  for (let i = 0; i < points.length; i++) normals.set([n.x, n.y, n.z], i * 3);
  geometry.setAttribute('normal', new THREE.BufferAttribute(normals, 3));
  return geometry;
}

export class PlanesView {
  private readonly renderer: THREE.WebGLRenderer;
  private readonly scene = new THREE.Scene();
  private readonly camera = new THREE.PerspectiveCamera(45, 1, 0.05, 2000);
  private readonly controls: OrbitControls;
  private readonly content = new THREE.Group();
  private readonly raycaster = new THREE.Raycaster();
  private patches = new Map<number, PatchObjects>();
  private mode: ColourMode = 'class';
  private selected: number | null = null;
  private visible: Set<number> | null = null;
  private boxLayers: { what: 'block' | 'voxel'; layer: BoxLayer }[] = [];
  private layers: Layers = { patches: true, blocks: true, voxels: true };
  private classOf = new Map<number, PlaneClass>();
  private home = new THREE.Box3();
  // Keep z ≤ top and z ≥ bottom (three.js clips where the signed distance is negative).
  private readonly cutTop = new THREE.Plane(new THREE.Vector3(0, 0, -1), NO_CUT);
  private readonly cutBottom = new THREE.Plane(new THREE.Vector3(0, 0, 1), NO_CUT);
  private readonly clipping = [this.cutTop, this.cutBottom];
  private readonly markers = new THREE.Group();
  /** WebGL drawn by the CPU (SwiftShader, llvmpipe): no antialiasing, one pixel a CSS pixel. */
  readonly software: boolean;
  // Pictures drawn on demand, a big one over several frames (pictures.ts).
  private readonly pictures: Pictures;

  /** Throws if WebGL cannot start. onClick gets what a click hit, or null for empty space. */
  constructor(private readonly container: HTMLElement, private readonly onClick: (hit: Hit | null) => void) {
    this.software = softwareWebGL();
    // Multisampling and high-DPI pixels multiply the fragments a CPU must shade: off there.
    this.renderer = new THREE.WebGLRenderer({ antialias: !this.software, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(this.software ? 1 : Math.min(window.devicePixelRatio, 2));
    this.renderer.localClippingEnabled = true;
    container.appendChild(this.renderer.domElement);
    // The clear colour, not scene.background: three.js clears for a background colour at every
    // render, and a picture drawn over several frames must not be cleared between them.
    this.renderer.setClearColor(BACKGROUND, 1);
    this.pictures = new Pictures(this.renderer, this.scene, this.camera,
      () => this.boxLayers.filter(({ what }) => this.layerShown(what)).map(({ layer }) => layer));
    this.camera.up.set(0, 0, 1);
    const sky = new THREE.HemisphereLight('#ffffff', '#445066', 1.6);
    const sun = new THREE.DirectionalLight('#ffffff', 1.4);
    sun.position.set(-0.5, -0.8, 1);
    // The lights light every layer; picking sees every layer.
    sky.layers.enableAll();
    sun.layers.enableAll();
    this.raycaster.layers.enableAll();
    this.scene.add(sky);
    this.scene.add(sun, this.content, this.markers);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    new ResizeObserver(() => this.resize()).observe(container);
    this.watchClicks();
    this.resize();
  }

  show(data: PlanesExport, blocks: BlockSet | null = null, voxels: VoxelSet | null = null): void {
    this.clear();
    this.classOf = new Map(data.planes.map((p) => [p.id, p.label]));
    const min = new THREE.Vector3(...data.map.bounds.min);
    const max = new THREE.Vector3(...data.map.bounds.max);
    const box = new THREE.Box3(min, max);
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3());

    const gridSize = Math.max(2, Math.ceil(Math.max(size.x, size.y)) + 2);
    const grid = new THREE.GridHelper(gridSize, gridSize, '#5a6478', '#343b4a');
    grid.rotation.x = Math.PI / 2; // GridHelper lies in x-z; the floor is x-y
    grid.position.set(Math.round(centre.x), Math.round(centre.y), min.z - 0.02);
    grid.name = 'grid';
    const bounds = new THREE.Box3Helper(box, new THREE.Color('#7f8aa3'));
    bounds.name = 'bounds';
    const axes = new THREE.AxesHelper(1);
    axes.position.copy(min);
    this.content.add(grid, bounds, axes);

    const drawn = new THREE.Box3();
    for (const patch of data.planes) {
      for (const q of patch.outline) drawn.expandByPoint(new THREE.Vector3(q[0], q[1], q[2]));
      const geometry = fillGeometry(patch);
      const fill = new THREE.Mesh(geometry ?? new THREE.BufferGeometry(), new THREE.MeshLambertMaterial({
        side: THREE.DoubleSide, transparent: true, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
        clippingPlanes: this.clipping,
      }));
      fill.userData.id = patch.id;
      const edge = new THREE.LineLoop(
        new THREE.BufferGeometry().setFromPoints(patch.outline.map((p) => new THREE.Vector3(p[0], p[1], p[2]))),
        new THREE.LineBasicMaterial({ transparent: true, clippingPlanes: this.clipping }),
      );
      fill.layers.set(OVERLAY_LAYER);
      edge.layers.set(OVERLAY_LAYER);
      this.content.add(fill, edge);
      this.patches.set(patch.id, { patch, fill, edge });
    }
    if (blocks && blocks.count > 0) this.boxLayers.push({ what: 'block', layer: new BoxLayer(blockBoxes(blocks), this.clipping, 'blocks') });
    if (voxels && voxels.count > 0) this.boxLayers.push({ what: 'voxel', layer: new BoxLayer(voxelBoxes(voxels), this.clipping, 'voxels') });
    for (const { layer } of this.boxLayers) {
      layer.mesh.layers.set(BOX_LAYER);
      this.content.add(layer.mesh);
    }
    // Blocks and voxels fill the bounds; patches alone may leave some of it empty.
    this.home = drawn.isEmpty() ? box : drawn;
    this.fit(this.home, new THREE.Vector3(-0.45, -0.75, 0.9));
    this.restyle();
  }

  setLayers(layers: Layers): void {
    this.layers = { ...layers };
    this.restyle();
  }

  /** Hides what lies above top and below bottom (m); ±Infinity for no cut. */
  setCut(bottom: number, top: number): void {
    // Finite: an infinite constant turns into NaN when three.js moves the plane to view space.
    this.cutTop.constant = Math.min(top, NO_CUT);
    this.cutBottom.constant = Math.min(-bottom, NO_CUT);
    this.render();
  }

  /** The camera looking down at the map (north up), from the south, or as first shown. */
  view(which: 'top' | 'side' | 'reset'): void {
    const direction = which === 'top' ? new THREE.Vector3(0, -1e-4, 1) : which === 'side' ? new THREE.Vector3(0, -1, 0.02) : new THREE.Vector3(-0.45, -0.75, 0.9);
    this.fit(this.home, direction);
    this.render();
  }

  /** Marks measured points, joined by a line when there are two. */
  setMarkers(points: Vec3[]): void {
    for (const child of [...this.markers.children]) {
      this.markers.remove(child);
      const obj = child as THREE.Mesh;
      obj.geometry.dispose();
      (obj.material as THREE.Material).dispose();
    }
    const size = Math.max(0.02, this.home.getSize(new THREE.Vector3()).length() / 150);
    for (const p of points) {
      const dot = new THREE.Mesh(new THREE.SphereGeometry(size, 12, 8), new THREE.MeshBasicMaterial({ color: HIGHLIGHT, depthTest: false }));
      dot.position.set(...p);
      dot.renderOrder = 10;
      dot.layers.set(OVERLAY_LAYER);
      this.markers.add(dot);
    }
    if (points.length === 2) {
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(points.map((p) => new THREE.Vector3(...p))),
        new THREE.LineBasicMaterial({ color: HIGHLIGHT, depthTest: false }));
      line.renderOrder = 10;
      line.layers.set(OVERLAY_LAYER);
      this.markers.add(line);
    }
    this.render();
  }

  /** The picture, every box drawn, as a PNG blob. */
  async png(): Promise<Blob> {
    await this.whenDrawn();
    return new Promise((resolve, reject) => this.renderer.domElement.toBlob((b) => (b ? resolve(b) : reject(new Error('the view could not be saved'))), 'image/png'));
  }

  setColourMode(mode: ColourMode): void {
    this.mode = mode;
    this.restyle();
  }

  /** Shows only these ids (null: all). */
  setVisible(ids: Set<number> | null): void {
    this.visible = ids;
    this.restyle();
  }

  select(id: number | null): void {
    this.selected = id !== null && this.patches.has(id) ? id : null;
    this.restyle();
  }

  /** The id whose patch is drawn highlighted, read back from the scene (for tests). */
  highlightedId(): number | null {
    for (const [id, o] of this.patches) if (o.fill.userData.highlighted) return id;
    return null;
  }

  /** The patch under a point in client (CSS pixel) coordinates, or null. */
  pickAt(clientX: number, clientY: number): number | null {
    return this.probe(clientX, clientY)?.id ?? null;
  }

  /** The nearest shown patch or block under a point in client coordinates, inside the height cut. */
  probe(clientX: number, clientY: number): Hit | null {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const top = this.cutTop.constant, bottom = -this.cutBottom.constant;
    const inCut = (z: number) => z <= top + 1e-6 && z >= bottom - 1e-6;
    let best: Hit | null = null, bestDistance = Infinity;
    if (this.layers.patches) {
      const fills = [...this.patches.values()].filter((o) => o.fill.visible).map((o) => o.fill);
      const hit = this.raycaster.intersectObjects(fills, false).find((h) => inCut(h.point.z));
      if (hit) {
        best = { id: hit.object.userData.id as number, point: hit.point.toArray() as Vec3, what: 'patch' };
        bestDistance = hit.distance;
      }
    }
    for (const { what, layer } of this.boxLayers) {
      if (!this.layerShown(what)) continue;
      const hit = layer.pick(this.raycaster.ray, bottom, top);
      // A patch lies on its blocks' surface: prefer it when the two are that close.
      if (hit && hit.distance < bestDistance - 1e-3) {
        best = { id: hit.plane === 0 ? null : hit.plane, point: hit.point.toArray() as Vec3, what };
        bestDistance = hit.distance;
      }
    }
    return best;
  }

  /** Where a point of the world lands on the page, in client coordinates. */
  project(point: [number, number, number]): { x: number; y: number } {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3(...point).project(this.camera);
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  /** Where the camera is and what it looks at (for tests). */
  cameraState(): { position: Vec3; target: Vec3 } {
    return { position: this.camera.position.toArray() as Vec3, target: this.controls.target.toArray() as Vec3 };
  }

  /** Asks for a new picture, drawn from the next animation frame on (pictures.ts). */
  render(): void {
    this.pictures.request();
  }

  /** Resolves once the picture shows the current state with every box drawn (for tests and the PNG). */
  whenDrawn(): Promise<void> {
    return this.pictures.whenDrawn();
  }

  /** Boxes a frame: a fixed number, or null to size it from the frame times again (for tests). */
  setFrameBudget(boxes: number | null): void {
    this.pictures.setBudget(boxes);
  }

  /** How the picture is drawn: the frames it took (so far), the boxes a frame and whether it is complete. */
  drawing(): { frames: number; budget: number; complete: boolean } {
    return this.pictures.state();
  }

  private clear(): void {
    for (const child of [...this.content.children]) {
      child.traverse((o) => {
        const obj = o as THREE.Mesh;
        obj.geometry?.dispose();
        const m = obj.material;
        if (Array.isArray(m)) m.forEach((x) => x.dispose()); else m?.dispose();
      });
      this.content.remove(child);
    }
    this.patches.clear();
    for (const { layer } of this.boxLayers) layer.dispose();
    this.boxLayers = [];
    this.selected = null;
    this.visible = null;
    this.setMarkers([]);
  }

  private restyle(): void {
    const dimOthers = this.selected !== null;
    for (const [id, { patch, fill, edge }] of this.patches) {
      const shown = this.visible === null || this.visible.has(id);
      const chosen = id === this.selected;
      const base = new THREE.Color(patchColour(patch, this.mode));
      fill.visible = edge.visible = shown && this.layers.patches;
      fill.userData.highlighted = chosen && shown;
      fill.material.color.copy(chosen ? HIGHLIGHT : base);
      fill.material.emissive.copy(chosen ? HIGHLIGHT : new THREE.Color(0, 0, 0)).multiplyScalar(chosen ? 0.45 : 0);
      // Ceilings cover the rooms from above: draw them faint unless chosen.
      const opacity = chosen ? 1 : patch.label === 'ceiling' ? 0.18 : 0.88;
      fill.material.opacity = dimOthers && !chosen ? opacity * 0.45 : opacity;
      fill.material.depthWrite = fill.material.opacity > 0.5;
      fill.renderOrder = chosen ? 2 : patch.label === 'ceiling' ? 1 : 0;
      edge.material.color.set(chosen ? '#ffffff' : base.clone().multiplyScalar(0.6));
      edge.material.opacity = dimOthers && !chosen ? 0.35 : 1;
      edge.renderOrder = chosen ? 3 : 0;
    }
    const visible = this.visible;
    // Unlabelled blocks belong to no patch: a filter that hides some patches hides them too.
    const filtering = visible !== null && visible.size < this.patches.size;
    for (const { what, layer } of this.boxLayers) {
      layer.mesh.visible = this.layerShown(what);
      layer.recolour(this.mode, (plane) => this.classOf.get(plane), this.selected, HIGHLIGHT);
      layer.setVisible((plane) => (plane === 0 ? !filtering : visible === null || visible.has(plane)));
    }
    this.render();
  }

  private layerShown(what: 'block' | 'voxel'): boolean {
    return what === 'block' ? this.layers.blocks : this.layers.voxels;
  }

  /** Frames the box: the nearest camera distance, looking along -direction, at which all its
   * corners land inside the view. */
  private fit(box: THREE.Box3, towards: THREE.Vector3): void {
    this.resize();
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(0.5, box.getSize(new THREE.Vector3()).length() / 2);
    const corners = [0, 1, 2, 3, 4, 5, 6, 7].map((i) => new THREE.Vector3(
      i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z));
    const direction = towards.clone().normalize();
    const fits = (distance: number) => {
      this.camera.position.copy(centre).addScaledVector(direction, distance);
      this.camera.lookAt(centre);
      this.camera.updateMatrixWorld();
      return corners.every((c) => {
        const p = c.clone().project(this.camera);
        return Math.abs(p.x) <= 0.94 && Math.abs(p.y) <= 0.92;
      });
    };
    let near = radius * 1.01, far = radius * 50;
    for (let i = 0; i < 40; i++) {
      const mid = (near + far) / 2;
      if (fits(mid)) far = mid; else near = mid;
    }
    this.camera.position.copy(centre).addScaledVector(direction, far);
    this.camera.near = Math.max(0.01, far / 500);
    this.camera.far = (far + radius) * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  /** A click is a press and release without dragging (dragging orbits). */
  private watchClicks(): void {
    const canvas = this.renderer.domElement;
    let down: { x: number; y: number } | null = null;
    canvas.addEventListener('pointerdown', (e) => { down = { x: e.clientX, y: e.clientY }; });
    canvas.addEventListener('pointerup', (e) => {
      if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) < 5) this.onClick(this.probe(e.clientX, e.clientY));
      down = null;
    });
  }
}
