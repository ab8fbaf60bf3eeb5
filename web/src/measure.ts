// The distance measure: while on, each click on the map drops a point; two points give their
// distance (and its horizontal and vertical parts); a third click starts a new pair.

import type { Vec3 } from './planes';

export interface Measurement {
  points: Vec3[];
  distance: number | null; // m, once there are two points
  horizontal: number | null;
  vertical: number | null;
}

export class Measure {
  active = false;
  private points: Vec3[] = [];

  constructor(private readonly button: HTMLButtonElement, private readonly info: HTMLElement,
    private readonly onPoints: (points: Vec3[]) => void) {}

  toggle(on = !this.active): void {
    this.active = on;
    this.button.setAttribute('aria-pressed', String(on));
    this.button.classList.toggle('on', on);
    this.points = [];
    this.update();
  }

  add(point: Vec3): void {
    if (this.points.length === 2) this.points = [];
    this.points.push(point);
    this.update();
  }

  state(): Measurement {
    const [a, b] = this.points;
    if (!a || !b) return { points: [...this.points], distance: null, horizontal: null, vertical: null };
    const horizontal = Math.hypot(b[0] - a[0], b[1] - a[1]);
    const vertical = Math.abs(b[2] - a[2]);
    return { points: [...this.points], distance: Math.hypot(horizontal, vertical), horizontal, vertical };
  }

  private update(): void {
    const m = this.state();
    this.info.hidden = !this.active;
    if (m.distance !== null) {
      this.info.textContent = `distance ${m.distance.toFixed(3)} m · horizontal ${m.horizontal!.toFixed(3)} m · vertical ${m.vertical!.toFixed(3)} m`;
    } else {
      this.info.textContent = this.points.length === 1 ? 'measure: click the second point' : 'measure: click the first point (Esc: stop)';
    }
    this.onPoints(this.points);
  }
}
