// charts.js - the page's plots, drawn as SVG by hand (no plotting library: four kinds of
// chart do not justify one): a law's bins against what a packing achieved, with error
// bars; histograms of counts (F, cell areas, neighbours); a curve (the joint j(r)).
// Colours come from the style sheet (classes), so the charts follow the page's theme.

import { fmtNum, svgEl, uid } from './dom.js';

const W = 480;
const H = 220;
const M = { left: 56, right: 14, top: 30, bottom: 44 };

// About n round tick values covering [lo, hi].
export function ticks(lo, hi, n = 5) {
  const span = hi - lo;
  if (!(span > 0) || !Number.isFinite(span)) return [lo];
  const raw = span / n;
  const magnitude = 10 ** Math.floor(Math.log10(raw));
  const norm = raw / magnitude;
  const step = (norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10) * magnitude;
  const out = [];
  for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
    out.push(Number(v.toPrecision(12)));
  }
  return out;
}

// The smallest tick value at or above v (the top of a y axis).
function niceTop(v) {
  if (!(v > 0)) return 1;
  const t = ticks(0, v, 4);
  const step = t.length > 1 ? t[1] - t[0] : v;
  return Math.ceil(v / step - 1e-9) * step;
}

// An empty chart: title and description for assistive technology, axes with ticks and
// labels, a legend. Returns the svg and the two scales.
function frame({ title, desc, xLabel, yLabel, x0, x1, y1, legend = [] }) {
  const id = uid('chart');
  const svg = svgEl('svg', {
    viewBox: `0 0 ${W} ${H}`, class: 'chart', role: 'img', 'aria-labelledby': `${id}-t ${id}-d`,
  });
  svg.append(svgEl('title', { id: `${id}-t` }, title), svgEl('desc', { id: `${id}-d` }, desc));
  const x = (v) => M.left + ((v - x0) / (x1 - x0)) * (W - M.left - M.right);
  const y = (v) => H - M.bottom - (v / y1) * (H - M.top - M.bottom);
  const axes = svgEl('g', { class: 'axes', 'aria-hidden': 'true' });
  axes.append(svgEl('line', { x1: M.left, x2: W - M.right, y1: y(0), y2: y(0) }));
  axes.append(svgEl('line', { x1: M.left, x2: M.left, y1: y(0), y2: M.top - 6 }));
  for (const t of ticks(x0, x1, 6)) {
    axes.append(svgEl('line', { x1: x(t), x2: x(t), y1: y(0), y2: y(0) + 5 }));
    axes.append(svgEl('text', { x: x(t), y: y(0) + 18, 'text-anchor': 'middle' }, fmtNum(t, 3)));
  }
  for (const t of ticks(0, y1, 4)) {
    axes.append(svgEl('line', { class: 'grid', x1: M.left, x2: W - M.right, y1: y(t), y2: y(t) }));
    axes.append(svgEl('text', { x: M.left - 6, y: y(t) + 4, 'text-anchor': 'end' }, fmtNum(t, 3)));
  }
  axes.append(svgEl('text', { class: 'label', x: (M.left + W - M.right) / 2, y: H - 6, 'text-anchor': 'middle' }, xLabel));
  axes.append(svgEl('text', { class: 'label', x: 4, y: M.top - 14 }, yLabel));
  let lx = W - M.right;
  for (const item of [...legend].reverse()) {
    const text = svgEl('text', { x: lx, y: 14, 'text-anchor': 'end' }, item.label);
    // about 6 px a character at the charts' 11 px
    lx -= 6.2 * item.label.length + 4;
    axes.append(svgEl('rect', { class: `legend ${item.cls}`, x: lx - 11, y: 5, width: 11, height: 11 }), text);
    lx -= 24;
  }
  svg.append(axes);
  return { svg, x, y };
}

// The x range of bins, widened when they are all of zero width (a constant radius).
function binRange(bins) {
  let lo = Math.min(...bins.map((b) => b.min));
  let hi = Math.max(...bins.map((b) => b.max));
  if (!(hi > lo)) {
    const pad = lo > 0 ? 0.25 * lo : 1;
    lo -= pad;
    hi += pad;
  }
  return [lo, hi];
}

// Bins of a radius law (each {min, max, target}) and, when known, what was achieved
// ({achieved, se}): the target as an outlined bar over the whole bin, the achieved
// frequency as a filled bar inside it with an error bar of +- 2 standard errors (about
// 95 % if the law holds). Unequal bins are drawn as densities (p / width) so that the
// areas stay the probabilities.
export function binsChart({ bins, title, xLabel = 'grain radius r', achieved = false }) {
  const widths = bins.map((b) => b.max - b.min);
  const equal = widths.every((w) => Math.abs(w - widths[0]) <= 1e-9 * Math.max(1, widths[0]));
  const scale = (b, v) => (equal || !(b.max > b.min) ? v : v / (b.max - b.min));
  const top = Math.max(...bins.map((b) => scale(b, Math.max(b.target,
    achieved ? b.achieved + 2 * (b.se || 0) : 0))));
  const [x0, x1] = binRange(bins);
  const legend = achieved
    ? [{ label: 'target', cls: 'target' }, { label: 'achieved ± 2 s.e.', cls: 'achieved' }]
    : [{ label: 'target', cls: 'target' }];
  const desc = bins.map((b) => `[${fmtNum(b.min)}, ${fmtNum(b.max)}): target ${fmtNum(b.target, 3)}`
    + (achieved ? `, achieved ${fmtNum(b.achieved, 3)} ± ${fmtNum(2 * b.se, 2)}` : '')).join('; ');
  const { svg, x, y } = frame({
    title, desc, xLabel, yLabel: equal ? 'probability per bin' : 'probability / bin width',
    x0, x1, y1: niceTop(top * 1.05), legend,
  });
  const minWidth = (x1 - x0) / 60;
  const marks = svgEl('g', { 'aria-hidden': 'true' });
  bins.forEach((b) => {
    const left = b.max > b.min ? b.min : b.min - minWidth / 2;
    const right = b.max > b.min ? b.max : b.min + minWidth / 2;
    const t = scale(b, b.target);
    marks.append(svgEl('rect', { class: 'target', x: x(left), y: y(t), width: Math.max(1, x(right) - x(left)), height: y(0) - y(t) }));
    if (!achieved) return;
    const a = scale(b, b.achieved);
    const inset = (x(right) - x(left)) * 0.22;
    marks.append(svgEl('rect', { class: 'achieved', x: x(left) + inset, y: y(a), width: Math.max(1, x(right) - x(left) - 2 * inset), height: y(0) - y(a) }));
    const e = scale(b, 2 * (b.se || 0));
    const cx = (x(left) + x(right)) / 2;
    if (e > 0) {
      marks.append(svgEl('path', {
        class: 'errorbar',
        d: `M${cx},${y(Math.max(0, a - e))}V${y(a + e)}M${cx - 4},${y(a + e)}h8M${cx - 4},${y(Math.max(0, a - e))}h8`,
      }));
    }
  });
  svg.append(marks);
  return svg;
}

// Histograms of counts: each series {lo, hi, counts, label, cls} has its bins spread
// evenly over [lo, hi] (how the service reports F and the cell areas).
export function countsChart({ series, title, xLabel, yLabel = 'count' }) {
  const shown = series.filter((s) => s.counts && s.counts.length);
  let x0 = Math.min(...shown.map((s) => s.lo));
  let x1 = Math.max(...shown.map((s) => s.hi));
  if (!(x1 > x0)) { x0 -= 0.5; x1 += 0.5; }
  const top = Math.max(1, ...shown.flatMap((s) => s.counts));
  const desc = shown.map((s) => `${s.label}: ${s.counts.join(', ')} over [${fmtNum(s.lo)}, ${fmtNum(s.hi)}]`).join('; ');
  const { svg, x, y } = frame({
    title, desc, xLabel, yLabel, x0, x1, y1: niceTop(top * 1.05),
    legend: shown.length > 1 ? shown.map((s) => ({ label: s.label, cls: s.cls })) : [],
  });
  const marks = svgEl('g', { 'aria-hidden': 'true' });
  shown.forEach((s) => {
    const width = (s.hi - s.lo) / s.counts.length || (x1 - x0) / 40;
    s.counts.forEach((count, i) => {
      const left = s.lo + i * width;
      marks.append(svgEl('rect', { class: s.cls, x: x(left), y: y(count), width: Math.max(1, x(left + width) - x(left)), height: y(0) - y(count) }));
    });
  });
  svg.append(marks);
  return svg;
}

// Curves y(x) sampled at xs: each series {ys, label, cls}; `marks` are x values to flag
// (the radii a law can draw).
export function curveChart({ xs, series, title, xLabel, yLabel }) {
  const top = Math.max(...series.flatMap((s) => s.ys).filter(Number.isFinite), 0);
  const desc = series.map((s) => `${s.label} from ${fmtNum(s.ys[0], 3)} at ${xLabel} = ${fmtNum(xs[0], 3)} `
    + `to ${fmtNum(s.ys[s.ys.length - 1], 3)} at ${fmtNum(xs[xs.length - 1], 3)}`).join('; ');
  const { svg, x, y } = frame({
    title, desc, xLabel, yLabel, x0: xs[0], x1: xs[xs.length - 1], y1: niceTop(top * 1.05 || 1),
    legend: series.length > 1 ? series.map((s) => ({ label: s.label, cls: s.cls })) : [],
  });
  const marks = svgEl('g', { 'aria-hidden': 'true' });
  for (const s of series) {
    const d = xs.map((v, i) => `${i ? 'L' : 'M'}${x(v).toFixed(2)},${y(Math.max(0, s.ys[i])).toFixed(2)}`).join('');
    marks.append(svgEl('path', { class: `curve ${s.cls}`, d }));
  }
  svg.append(marks);
  return svg;
}
