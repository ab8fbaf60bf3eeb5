// The table of patches: sorts by a click on a header, shows only the patches the filter lets
// through, and reports a click on a row.

import type { Patch } from './planes';
import { patchColour, type ColourMode } from './colours';

interface Column {
  key: string;
  title: string;
  numeric: boolean;
  value: (p: Patch) => number | string;
  text: (p: Patch) => string;
  tip?: string;
}

// A fixed number of decimals, without a minus sign on a rounded zero.
const fixed = (digits: number) => (x: number) => (Math.abs(x) < 0.5 * 10 ** -digits ? 0 : x).toFixed(digits);

const COLUMNS: Column[] = [
  { key: 'id', title: 'id', numeric: true, value: (p) => p.id, text: (p) => String(p.id) },
  { key: 'class', title: 'class', numeric: false, value: (p) => p.label, text: (p) => p.label },
  { key: 'area', title: 'area m²', numeric: true, value: (p) => p.area, text: (p) => fixed(2)(p.area) },
  {
    key: 'normal', title: 'normal', numeric: true, value: (p) => Math.abs(p.normal[2]),
    text: (p) => p.normal.map(fixed(2)).join(', '), tip: 'unit normal (x, y, z); sorts by |z|',
  },
  { key: 'height', title: 'height m', numeric: true, value: (p) => p.centroid[2], text: (p) => fixed(2)(p.centroid[2]), tip: 'z of the centroid' },
  { key: 'offset', title: 'offset m', numeric: true, value: (p) => p.offset, text: (p) => fixed(2)(p.offset), tip: 'd in n·x + d = 0' },
  { key: 'blocks', title: 'blocks', numeric: true, value: (p) => p.blocks, text: (p) => String(p.blocks) },
  { key: 'rms', title: 'RMS cm', numeric: true, value: (p) => p.rms, text: (p) => fixed(1)(p.rms * 100), tip: 'RMS distance of the blocks to the plane' },
];

export class PatchTable {
  private patches: Patch[] = [];
  private rows = new Map<number, HTMLTableRowElement>();
  private byId = new Map<number, Patch>();
  private sortKey = 'area';
  private descending = true;
  private selected: number | null = null;
  private mode: ColourMode = 'class';
  private readonly body: HTMLTableSectionElement;
  private readonly headers = new Map<string, HTMLTableCellElement>();

  constructor(table: HTMLTableElement, private readonly onSelect: (id: number) => void) {
    table.replaceChildren();
    const head = table.createTHead().insertRow();
    for (const column of COLUMNS) {
      const th = document.createElement('th');
      th.textContent = column.title;
      th.dataset.key = column.key;
      th.className = column.numeric ? 'num' : '';
      if (column.tip) th.title = column.tip;
      th.addEventListener('click', () => this.sortBy(column.key));
      head.appendChild(th);
      this.headers.set(column.key, th);
    }
    this.body = table.createTBody();
    this.body.addEventListener('click', (e) => {
      const row = (e.target as HTMLElement).closest('tr');
      if (row?.dataset.id) this.onSelect(Number(row.dataset.id));
    });
  }

  setData(patches: Patch[]): void {
    this.patches = patches;
    this.byId = new Map(patches.map((p) => [p.id, p]));
    this.selected = null;
    this.rows.clear();
    for (const patch of patches) {
      const row = document.createElement('tr');
      row.dataset.id = String(patch.id);
      row.dataset.class = patch.label;
      for (const column of COLUMNS) {
        const cell = row.insertCell();
        if (column.numeric) cell.className = 'num';
        if (column.key === 'class') {
          const swatch = document.createElement('span');
          swatch.className = 'swatch';
          cell.append(swatch, column.text(patch));
        } else {
          cell.textContent = column.text(patch);
        }
      }
      this.rows.set(patch.id, row);
    }
    this.recolour();
    this.order();
  }

  setColourMode(mode: ColourMode): void {
    this.mode = mode;
    this.recolour();
  }

  /** Shows only the rows of these ids. */
  setVisible(ids: Set<number>): void {
    for (const [id, row] of this.rows) row.hidden = !ids.has(id);
  }

  /** The rows shown, in the order shown, as CSV: a header line, then the values unrounded. */
  csv(): string {
    const lines = ['id,class,cityjson_type,area_m2,normal_x,normal_y,normal_z,height_m,offset_m,blocks,rms_m'];
    for (const row of Array.from(this.body.rows)) {
      const p = row.hidden ? undefined : this.byId.get(Number(row.dataset.id));
      if (!p) continue;
      lines.push([p.id, p.label, p.cityjson_type ?? '', p.area, ...p.normal, p.centroid[2], p.offset, p.blocks, p.rms].join(','));
    }
    return lines.join('\n') + '\n';
  }

  select(id: number | null, scroll: boolean): void {
    if (this.selected !== null) this.rows.get(this.selected)?.classList.remove('selected');
    this.selected = id;
    const row = id === null ? undefined : this.rows.get(id);
    row?.classList.add('selected');
    if (row && scroll) row.scrollIntoView({ block: 'nearest' });
  }

  private sortBy(key: string): void {
    if (key === this.sortKey) this.descending = !this.descending;
    else { this.sortKey = key; this.descending = key !== 'id' && key !== 'class'; }
    this.order();
  }

  private order(): void {
    const column = COLUMNS.find((c) => c.key === this.sortKey) ?? COLUMNS[0];
    const sign = this.descending ? -1 : 1;
    const sorted = [...this.patches].sort((a, b) => {
      const x = column.value(a), y = column.value(b);
      const c = typeof x === 'number' && typeof y === 'number' ? x - y : String(x).localeCompare(String(y));
      return sign * c || a.id - b.id;
    });
    this.body.replaceChildren(...sorted.map((p) => this.rows.get(p.id)!));
    for (const [key, th] of this.headers) {
      th.classList.toggle('sorted', key === this.sortKey);
      th.dataset.dir = key === this.sortKey ? (this.descending ? 'desc' : 'asc') : '';
      th.setAttribute('aria-sort', key === this.sortKey ? (this.descending ? 'descending' : 'ascending') : 'none');
    }
  }

  private recolour(): void {
    for (const patch of this.patches) {
      const swatch = this.rows.get(patch.id)?.querySelector<HTMLElement>('.swatch');
      if (swatch) swatch.style.background = patchColour(patch, this.mode);
    }
  }
}
