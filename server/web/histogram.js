// histogram.js - the histogram editor of the radius law: one row per bin {min, max, p},
// add and remove bins, paste two or three columns from a spreadsheet, normalise the
// probabilities when asked (the service never does it by itself), and the sum shown as
// it is typed.

import { announce, el, fmtNum, uid } from './dom.js';

// The service's tolerance on the sum of the probabilities (GP_SPEC_PROBABILITY_TOL).
const SUM_TOLERANCE = 1e-6;

// A number as a spreadsheet may write it: "0.158", "0,158" (decimal comma, when the
// columns are not separated by commas), "15.8%" (then divided by 100).
function readNumber(cell, decimalComma) {
  let text = cell.trim().replace(/\u2212/g, '-');
  const percent = text.endsWith('%');
  if (percent) text = text.slice(0, -1).trim();
  if (decimalComma) text = text.replace(',', '.');
  if (!/^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(text)) return NaN;
  const v = Number(text);
  return percent ? v / 100 : v;
}

// A bin range written in one cell: "2-2.5", "2 – 2.5", "[2, 2.5)".
function readRange(cell, decimalComma) {
  const m = cell.trim().match(/^[[(]?\s*([^,;\s\u2013\u2014]+?)\s*(?:-|\u2013|\u2014|,|;|\.\.)\s*([^,;\s)\]]+)\s*[)\]]?$/);
  if (!m) return null;
  const lo = readNumber(m[1], decimalComma);
  const hi = readNumber(m[2], decimalComma);
  return Number.isFinite(lo) && Number.isFinite(hi) ? [lo, hi] : null;
}

// Reads bins from text copied out of a spreadsheet or a paper's table, one bin a line:
//   three columns:  min  max  p
//   two columns:    a range "min-max" and p, or a bin centre and p (the edges are then
//                   halfway between consecutive centres)
// Columns are separated by tabs, semicolons, commas or spaces; lines that are not
// numbers before the first bin (headers) are skipped. Returns {bins, note} or throws an
// Error saying which line could not be read.
export function parseBins(text) {
  const lines = text.split(/\r?\n/).map((l) => l.trim()).filter((l) => l.length);
  const rows = [];
  lines.forEach((line, index) => {
    const decimalComma = /[\t;]/.test(line);
    const cells = line.split(decimalComma ? /\s*[\t;]\s*/ : /\s*,\s*|\s+/).filter((c) => c.length);
    const numbers = cells.map((c) => readNumber(c, decimalComma));
    if (cells.length >= 3 && numbers.slice(0, 3).every(Number.isFinite)) {
      rows.push({ kind: 'edges', min: numbers[0], max: numbers[1], p: numbers[2] });
    } else if (cells.length === 2 && Number.isFinite(numbers[1]) && readRange(cells[0], decimalComma)) {
      const [min, max] = readRange(cells[0], decimalComma);
      rows.push({ kind: 'edges', min, max, p: numbers[1] });
    } else if (cells.length === 2 && numbers.every(Number.isFinite)) {
      rows.push({ kind: 'centre', centre: numbers[0], p: numbers[1] });
    } else if (rows.length === 0) {
      // a header line
    } else {
      throw new Error(`line ${index + 1} ("${line.slice(0, 40)}") is not min, max, p nor a range or centre and p`);
    }
  });
  if (rows.length === 0) throw new Error('no bins found: paste two or three columns of numbers');
  if (rows.every((r) => r.kind === 'edges')) {
    return { bins: rows.map(({ min, max, p }) => ({ min, max, p })), note: `${rows.length} bins read (min, max, p)` };
  }
  if (!rows.every((r) => r.kind === 'centre')) throw new Error('mixed lines: give every bin the same columns');
  if (rows.length === 1) throw new Error('one bin centre alone has no width: give min, max and p');
  const c = rows.map((r) => r.centre);
  const bins = rows.map((r, i) => {
    const below = i > 0 ? (c[i] + c[i - 1]) / 2 : c[i] - (c[i + 1] - c[i]) / 2;
    const above = i + 1 < c.length ? (c[i] + c[i + 1]) / 2 : c[i] + (c[i] - c[i - 1]) / 2;
    return { min: below, max: above, p: r.p };
  });
  return { bins, note: `${bins.length} bins read from their centres (edges halfway between centres)` };
}

// The editor. `pointer` is the JSON pointer of the bins array in the submitted document,
// so that the service's errors find their field; onChange is called after every edit.
export class HistogramEditor {
  constructor(pointer, onChange) {
    this.pointer = pointer;
    this.onChange = onChange;
    this.tbody = el('tbody');
    this.sum = el('span', { class: 'sum' });
    this.status = el('p', { class: 'note', role: 'status' });
    const pasteId = uid('paste');
    this.paste = el('textarea', {
      id: pasteId, rows: 3, class: 'paste', spellcheck: 'false',
      placeholder: 'min\tmax\tp\n2\t2.5\t0.158\n…',
      onpaste: (e) => this.pasted(e),
    });
    this.node = el('div', { class: 'histogram', dataset: { pointer } },
      el('table', { class: 'bins' },
        el('caption', {}, 'Histogram bins: a radius in [min, max) drawn with probability p'),
        el('thead', {}, el('tr', {},
          el('th', { scope: 'col' }, '#'), el('th', { scope: 'col' }, 'min'),
          el('th', { scope: 'col' }, 'max'), el('th', { scope: 'col' }, 'p'),
          el('th', { scope: 'col' }, el('span', { class: 'visually-hidden' }, 'remove')))),
        this.tbody),
      el('div', { class: 'row-actions' },
        el('button', { type: 'button', onclick: () => this.addBin() }, 'Add a bin'),
        el('button', { type: 'button', onclick: () => this.normalise() }, 'Normalise p'),
        el('span', {}, 'Sum of p: ', this.sum)),
      el('label', { for: pasteId }, 'Paste from a spreadsheet: two or three columns (min, max, p; or range, p; or centre, p)'),
      this.paste,
      el('div', { class: 'row-actions' },
        el('button', { type: 'button', onclick: () => this.readPasteArea() }, 'Read the pasted text')),
      this.status);
    // a block of cells pasted into any bin field replaces the table too
    this.tbody.addEventListener('paste', (e) => {
      const text = e.clipboardData ? e.clipboardData.getData('text/plain') : '';
      if (/[\t\n]/.test(text.trim())) this.pasted(e);
    });
    this.set([{ min: 1, max: 2, p: 1 }]);
  }

  get() {
    return [...this.tbody.rows].map((row) => {
      const bin = {};
      for (const input of row.querySelectorAll('input')) {
        bin[input.name] = input.value.trim() === '' ? null : Number(input.value);
      }
      return bin;
    });
  }

  set(bins) {
    this.tbody.replaceChildren(...bins.map((b, i) => this.row(b, i)));
    this.update();
  }

  row(bin, i) {
    const cell = (name) => {
      const id = uid('bin');
      const pointer = `${this.pointer}/${i}/${name}`;
      return el('td', { class: 'cell', dataset: { pointer } },
        el('label', { for: id, class: 'visually-hidden' }, `bin ${i + 1} ${name}`),
        el('input', {
          id, name, type: 'number', step: 'any', min: 0, inputmode: 'decimal',
          value: bin[name] === null || bin[name] === undefined ? '' : String(bin[name]),
          oninput: () => this.update(),
        }));
    };
    return el('tr', {},
      el('th', { scope: 'row' }, String(i + 1)), cell('min'), cell('max'), cell('p'),
      el('td', {}, el('button', {
        type: 'button', class: 'icon', 'aria-label': `remove bin ${i + 1}`, title: 'remove this bin',
        onclick: () => this.removeBin(i),
      }, '×')));
  }

  addBin() {
    const bins = this.get();
    const last = bins[bins.length - 1];
    const width = last && last.max > last.min ? last.max - last.min : 1;
    const start = last && Number.isFinite(last.max) ? last.max : 1;
    bins.push({ min: start, max: Number((start + width).toPrecision(12)), p: 0 });
    this.set(bins);
    this.tbody.rows[bins.length - 1].querySelector('input').focus();
    announce(`bin ${bins.length} added`);
  }

  removeBin(i) {
    const bins = this.get();
    if (bins.length === 1) {
      this.status.textContent = 'A histogram keeps at least one bin.';
      return;
    }
    bins.splice(i, 1);
    this.set(bins);
    const row = this.tbody.rows[Math.min(i, bins.length - 1)];
    row.querySelector('button').focus();
    announce(`bin ${i + 1} removed`);
  }

  normalise() {
    const bins = this.get();
    const total = bins.reduce((s, b) => s + (Number.isFinite(b.p) ? b.p : 0), 0);
    if (!(total > 0)) {
      this.status.textContent = 'Nothing to normalise: no bin has a probability above 0.';
      return;
    }
    this.set(bins.map((b) => ({ ...b, p: Number.isFinite(b.p) ? Number((b.p / total).toPrecision(15)) : b.p })));
    this.status.textContent = `Probabilities divided by ${fmtNum(total, 8)}.`;
  }

  pasted(event) {
    const text = event.clipboardData ? event.clipboardData.getData('text/plain') : '';
    if (!text) return; // nothing readable: the browser pastes into the text area
    event.preventDefault();
    this.readText(text);
  }

  readPasteArea() {
    this.readText(this.paste.value);
  }

  readText(text) {
    try {
      const { bins, note } = parseBins(text);
      this.set(bins);
      this.paste.value = '';
      this.status.textContent = `${note}.`;
      announce(this.status.textContent);
    } catch (err) {
      this.status.textContent = `Not read: ${err.message}.`;
    }
  }

  // The sum of p, and the caller told.
  update() {
    const total = this.get().reduce((s, b) => s + (Number.isFinite(b.p) ? b.p : 0), 0);
    this.sum.textContent = fmtNum(total, 10);
    this.sum.classList.toggle('bad', Math.abs(total - 1) > SUM_TOLERANCE);
    if (this.onChange) this.onChange();
  }
}
