// The height cut: two sliders keep z in [bottom, top], to hide the ceiling (seen from above, a
// building is its ceiling) or to slice out one storey; "No ceiling" cuts just below the lowest
// ceiling patch.

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

export class HeightCut {
  private readonly bottom = $<HTMLInputElement>('cut-bottom');
  private readonly top = $<HTMLInputElement>('cut-top');
  private readonly text = $<HTMLOutputElement>('cut-text');
  private readonly ceilingButton = $<HTMLButtonElement>('cut-ceiling');
  private min = 0;
  private max = 0;
  private ceiling: number | null = null;

  constructor(private readonly onChange: (bottom: number, top: number) => void) {
    this.bottom.addEventListener('input', () => this.changed('bottom'));
    this.top.addEventListener('input', () => this.changed('top'));
    $('cut-clear').addEventListener('click', () => this.set(this.min, this.max));
    this.ceilingButton.addEventListener('click', () => this.cutCeiling());
  }

  /** New data: sliders over [min, max] in steps of a cell, nothing cut. */
  reset(min: number, max: number, step: number, lowestCeiling: number | null): void {
    // A step of at least 1 cm keeps the slider usable on maps of fine cells.
    const s = Math.max(0.01, step);
    this.min = Math.floor(min / s) * s;
    this.max = Math.ceil(max / s) * s;
    this.ceiling = lowestCeiling;
    this.ceilingButton.disabled = lowestCeiling === null;
    for (const input of [this.bottom, this.top]) {
      input.min = String(this.min);
      input.max = String(this.max);
      input.step = String(s);
    }
    this.set(this.min, this.max);
  }

  /** Cuts two steps below the lowest ceiling patch, if there is one. */
  cutCeiling(): void {
    if (this.ceiling !== null) this.set(Number(this.bottom.value), this.ceiling - 2 * Number(this.top.step));
  }

  /** Keeps z in [bottom, top]; an end at the slider's limit cuts nothing on that side. */
  set(bottom: number, top: number): void {
    this.bottom.value = String(bottom);
    this.top.value = String(top);
    this.changed('top');
  }

  /** The cut now: null on a side that cuts nothing. */
  range(): { bottom: number | null; top: number | null } {
    const bottom = Number(this.bottom.value), top = Number(this.top.value);
    // Half a step of slack: the slider's values are min + n·step, rounded its own way.
    const slack = Number(this.top.step) / 2;
    return { bottom: bottom > this.min + slack ? bottom : null, top: top < this.max - slack ? top : null };
  }

  private changed(moved: 'bottom' | 'top'): void {
    // The handles never cross: the one not moved gives way.
    if (Number(this.bottom.value) > Number(this.top.value)) {
      if (moved === 'bottom') this.top.value = this.bottom.value; else this.bottom.value = this.top.value;
    }
    const { bottom, top } = this.range();
    const m = (x: number) => x.toFixed(2);
    this.text.value = bottom === null && top === null ? 'all heights' : `${bottom === null ? '…' : m(bottom)} – ${top === null ? '…' : m(top)} m`;
    this.onChange(bottom ?? -Infinity, top ?? Infinity);
  }
}
