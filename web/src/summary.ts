// The summary: patches by class with their total area (each class a checkbox that shows or hides
// it), the map's size and cell size, the detection's time and counts, and its parameters.

import { CLASSES, type PlaneClass, type PlanesExport } from './planes';
import { CLASS_COLOURS } from './colours';

interface Props { className?: string; type?: string; checked?: boolean }

function el<K extends keyof HTMLElementTagNameMap>(tag: K, props: Props = {}, ...children: (Node | string)[]): HTMLElementTagNameMap[K] {
  const node = document.createElement(tag);
  Object.assign(node, props);
  node.append(...children);
  return node;
}

// Two decimals, without a minus sign on a rounded zero.
const m = (x: number) => (Math.abs(x) < 0.005 ? 0 : x).toFixed(2);

function seconds(s: number): string {
  return s < 1 ? `${(s * 1000).toFixed(0)} ms` : `${s.toFixed(2)} s`;
}

function facts(rows: [string, string][]): HTMLElement {
  const dl = el('dl', { className: 'facts' });
  for (const [k, v] of rows) dl.append(el('dt', {}, k), el('dd', {}, v));
  return dl;
}

/** Renders into container; onClasses gets the set of classes left ticked after each change. */
export function renderSummary(container: HTMLElement, data: PlanesExport, onClasses: (shown: Set<PlaneClass>) => void): void {
  const shown = new Set<PlaneClass>(CLASSES);
  const byClass = new Table();
  const totalArea = data.planes.reduce((s, p) => s + p.area, 0);
  for (const c of CLASSES) {
    const patches = data.planes.filter((p) => p.label === c);
    if (patches.length === 0) continue;
    const box = el('input', { type: 'checkbox', checked: true });
    box.dataset.class = c;
    box.addEventListener('change', () => {
      if (box.checked) shown.add(c); else shown.delete(c);
      onClasses(new Set(shown));
    });
    const swatch = el('span', { className: 'swatch' });
    swatch.style.background = CLASS_COLOURS[c];
    byClass.row([el('label', {}, box, swatch, c)], String(patches.length), m(patches.reduce((s, p) => s + p.area, 0)));
  }
  byClass.row(['all'], String(data.planes.length), m(totalArea)).classList.add('total');

  const { min, max } = data.map.bounds;
  const size = [0, 1, 2].map((i) => max[i] - min[i]);
  const t = data.timings;
  const d = data.detection;
  const params = el('details', { className: 'parameters' }, el('summary', {}, `parameters (${Object.keys(data.parameters).length})`),
    facts(Object.entries(data.parameters).map(([k, v]) => [k, String(v)])));

  container.replaceChildren(
    el('section', { className: 'classes' }, el('h2', {}, 'Patches by class'), byClass.element),
    el('section', { className: 'map' }, el('h2', {}, 'Map'), facts([
      ['source', data.map.source],
      ['size', `${size.map(m).join(' × ')} m`],
      ['bounds', `(${min.map(m).join(', ')}) –\n(${max.map(m).join(', ')})`],
      ['cell size', `${m(data.map.cell_size)} m`],
      ['cells / blocks', `${data.map.cells.toLocaleString('en')} / ${data.map.blocks.toLocaleString('en')}`],
    ])),
    el('section', { className: 'detection' }, el('h2', {}, 'Detection'), facts([
      ['time', `${seconds(t.total_s)} (direction vectors ${seconds(t.direction_vectors_s)}, detection ${seconds(t.detection_s)})`],
      ['candidates', `${d.candidates.toLocaleString('en')} made, ${d.scored.toLocaleString('en')} scored, ${d.accepted} accepted`],
      ['labelled blocks', `${d.labelled_blocks.toLocaleString('en')} of ${data.map.blocks.toLocaleString('en')}`],
    ]), params),
  );
}

class Table {
  readonly element = el('table', { className: 'by-class' });
  constructor() {
    const head = this.element.createTHead().insertRow();
    for (const [title, cls] of [['class', ''], ['patches', 'num'], ['area m²', 'num']]) head.append(el('th', { className: cls }, title));
    this.element.createTBody();
  }
  row(first: (Node | string)[], ...rest: string[]): HTMLTableRowElement {
    const tr = this.element.tBodies[0].insertRow();
    tr.insertCell().append(...first);
    for (const text of rest) {
      const td = tr.insertCell();
      td.className = 'num';
      td.textContent = text;
    }
    return tr;
  }
}
