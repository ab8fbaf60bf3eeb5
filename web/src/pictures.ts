// Drawing the 3D view's pictures: on demand (a change asks for one; never in a loop), and a
// picture of many boxes over several frames, a budget of boxes each, in the boxes' shuffled
// order (block_layer.ts): the first frame shows an even sample of the map, the next ones fill it
// in over the picture so far, and a change (a drag, a slider) starts a new picture at once
// instead of waiting for the last one. Without a GPU (SwiftShader on 2 cores) the main job's
// 262k blocks take seconds to draw whole; dragging still gets ~20 frames a second.

import * as THREE from 'three';
import type { BoxLayer } from './block_layer';

// A frame of about this many ms keeps dragging smooth (20 frames a second).
const FRAME_MS = 50;
// boxes a frame: the first guess (a 2-core CPU drawing WebGL manages ~20k in 50 ms idle) and
// the limits of the budget (a GPU draws 2M boxes in well under a frame)
const BUDGET_START = 20_000;
const BUDGET_MIN = 2_000;
const BUDGET_MAX = 2_000_000;
// three.js layers: the boxes, drawn over several frames; the patches and measure markers,
// drawn once all boxes are; everything else (grid, bounds, axes) stays on layer 0.
export const BOX_LAYER = 1;
export const OVERLAY_LAYER = 2;

/** Whether WebGL is drawn by the CPU: the renderer's name, as the browser tells it. */
export function softwareWebGL(): boolean {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|softpipe|software|lavapipe|basic render/i.test(name);
}

export class Pictures {
  private frameRequested = false;
  private progress = 0; // the share of the boxes drawn into the picture so far
  private drawnWhole = true; // the picture is complete (nothing asked yet: nothing to draw)
  private waiting: (() => void)[] = [];
  private budget = BUDGET_START; // boxes a frame, sized so that a frame takes about FRAME_MS
  private fixedBudget = false; // set by setBudget (tests): no adapting
  private lastFrame = 0;
  private lastFrameBoxes = 0;
  private frames = 0; // frames the picture took so far

  /** The renderer must not clear for a background colour (scene.background): the frames of a
   * picture draw over each other. `boxLayers` gives the box layers shown now. */
  constructor(private readonly renderer: THREE.WebGLRenderer, private readonly scene: THREE.Scene,
    private readonly camera: THREE.Camera, private readonly boxLayers: () => BoxLayer[]) {}

  /** Asks for a new picture: started at the next animation frame, once for any number of asks. */
  request(): void {
    this.progress = 0;
    this.drawnWhole = false;
    this.requestFrame();
  }

  /** Resolves once the picture shows the current state with every box drawn. */
  whenDrawn(): Promise<void> {
    if (this.drawnWhole) return Promise.resolve();
    return new Promise((resolve) => this.waiting.push(resolve));
  }

  /** Boxes a frame: a fixed number, or null to size it from the frame times again (for tests). */
  setBudget(boxes: number | null): void {
    this.fixedBudget = boxes !== null;
    this.budget = boxes ?? BUDGET_START;
    this.request();
  }

  /** How the picture is drawn: the frames it took (so far), the boxes a frame and whether it is complete. */
  state(): { frames: number; budget: number; complete: boolean } {
    return { frames: this.frames, budget: this.budget, complete: this.drawnWhole };
  }

  private requestFrame(): void {
    if (this.frameRequested) return;
    this.frameRequested = true;
    requestAnimationFrame(() => {
      this.frameRequested = false;
      this.drawFrame();
    });
  }

  /** One frame of the picture: the boxes' next share, then, once all are drawn, what lies over them. */
  private drawFrame(): void {
    const now = performance.now();
    // Aim at FRAME_MS a frame: the time since the last frame tells what its share cost.
    const interval = now - this.lastFrame;
    if (!this.fixedBudget && this.lastFrameBoxes > 0 && interval < 1000) {
      const scale = Math.min(1.5, Math.max(0.5, FRAME_MS / interval));
      // Only a frame that drew its whole budget says the budget is too small.
      if (scale < 1 || this.lastFrameBoxes >= this.budget) this.budget = Math.min(BUDGET_MAX, Math.max(BUDGET_MIN, this.budget * scale));
    }
    const layers = this.boxLayers().filter((layer) => layer.count > 0);
    const total = layers.reduce((sum, layer) => sum + layer.count, 0);
    const from = this.progress;
    const to = total === 0 ? 1 : Math.min(1, from + this.budget / total);
    for (const layer of layers) layer.setRange(Math.floor(from * layer.chunks), to >= 1 ? layer.chunks : Math.floor(to * layer.chunks));
    const r = this.renderer;
    r.autoClear = from === 0; // a new picture starts on the background
    this.frames = from === 0 ? 1 : this.frames + 1;
    // The first frame: the helpers (grid, bounds, axes) and the boxes' first share; later ones
    // the boxes only, over the picture so far (its depth kept: preserveDrawingBuffer).
    this.camera.layers.set(BOX_LAYER);
    if (from === 0) this.camera.layers.enable(0);
    r.render(this.scene, this.camera);
    if (to >= 1) {
      // Patches (some see-through) and markers (drawn over everything) go on top of all boxes.
      this.camera.layers.set(OVERLAY_LAYER);
      r.autoClear = false;
      r.render(this.scene, this.camera);
    }
    this.camera.layers.enableAll();
    this.lastFrame = now;
    this.lastFrameBoxes = (to - from) * total;
    this.progress = to;
    if (to < 1) {
      this.requestFrame();
      return;
    }
    this.drawnWhole = true;
    const waiting = this.waiting;
    this.waiting = [];
    for (const resolve of waiting) resolve();
  }
}
