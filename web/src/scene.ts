// The 3D view: every patch as its filled outline polygon (metres, z up), a floor grid, the map's
// bounds as a box, orbit/pan/zoom, and picking a patch by clicking it.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { Patch, PlanesExport } from './planes';
import { patchColour, type ColourMode } from './colours';

const HIGHLIGHT = new THREE.Color('#ffe14d');
const BACKGROUND = new THREE.Color('#1b202a');

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

  /** Throws if WebGL cannot start. onPick gets the clicked patch's id, or null for empty space. */
  constructor(private readonly container: HTMLElement, private readonly onPick: (id: number | null) => void) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    container.appendChild(this.renderer.domElement);
    this.scene.background = BACKGROUND;
    this.camera.up.set(0, 0, 1);
    this.scene.add(new THREE.HemisphereLight('#ffffff', '#445066', 1.6));
    const sun = new THREE.DirectionalLight('#ffffff', 1.4);
    sun.position.set(-0.5, -0.8, 1);
    this.scene.add(sun, this.content);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    new ResizeObserver(() => this.resize()).observe(container);
    this.watchClicks();
    this.resize();
  }

  show(data: PlanesExport): void {
    this.clear();
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
      }));
      fill.userData.id = patch.id;
      const edge = new THREE.LineLoop(
        new THREE.BufferGeometry().setFromPoints(patch.outline.map((p) => new THREE.Vector3(p[0], p[1], p[2]))),
        new THREE.LineBasicMaterial({ transparent: true }),
      );
      this.content.add(fill, edge);
      this.patches.set(patch.id, { patch, fill, edge });
    }
    this.fit(drawn.isEmpty() ? box : drawn);
    this.restyle();
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
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const fills = [...this.patches.values()].filter((o) => o.fill.visible).map((o) => o.fill);
    const hit = this.raycaster.intersectObjects(fills, false)[0];
    return hit ? (hit.object.userData.id as number) : null;
  }

  /** Where a point of the world lands on the page, in client coordinates. */
  project(point: [number, number, number]): { x: number; y: number } {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3(...point).project(this.camera);
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  render(): void {
    this.renderer.render(this.scene, this.camera);
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
    this.selected = null;
    this.visible = null;
  }

  private restyle(): void {
    const dimOthers = this.selected !== null;
    for (const [id, { patch, fill, edge }] of this.patches) {
      const shown = this.visible === null || this.visible.has(id);
      const chosen = id === this.selected;
      const base = new THREE.Color(patchColour(patch, this.mode));
      fill.visible = edge.visible = shown;
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
    this.render();
  }

  /** Frames the box: the nearest camera distance, looking from the south-west and above, at
   * which all its corners land inside the view. */
  private fit(box: THREE.Box3): void {
    this.resize();
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(0.5, box.getSize(new THREE.Vector3()).length() / 2);
    const corners = [0, 1, 2, 3, 4, 5, 6, 7].map((i) => new THREE.Vector3(
      i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z));
    const direction = new THREE.Vector3(-0.45, -0.75, 0.9).normalize();
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
      if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) < 5) this.onPick(this.pickAt(e.clientX, e.clientY));
      down = null;
    });
  }
}
