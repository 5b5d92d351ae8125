// dom.js - small helpers every module of the page shares: building elements, number
// formatting, a debounce and the screen-reader announcer.

const SVG_NS = 'http://www.w3.org/2000/svg';

// Adds children (strings, nodes, arrays of them; null and false skipped) to a node.
function append(node, children) {
  for (const child of children.flat(Infinity)) {
    if (child === null || child === undefined || child === false) continue;
    node.append(child instanceof Node ? child : String(child));
  }
  return node;
}

// Sets attributes; `on*` functions become listeners, `class` and `text` are shortcuts,
// and a false or null value leaves the attribute out.
function setAttributes(node, attrs) {
  for (const [name, value] of Object.entries(attrs || {})) {
    if (value === false || value === null || value === undefined) continue;
    if (name.startsWith('on') && typeof value === 'function') node.addEventListener(name.slice(2), value);
    else if (name === 'text') node.textContent = value;
    else if (name === 'dataset') Object.assign(node.dataset, value);
    else node.setAttribute(name, value === true ? '' : String(value));
  }
  return node;
}

// An HTML element: el('p', {class: 'note'}, 'text', child...).
export function el(tag, attrs, ...children) {
  return append(setAttributes(document.createElement(tag), attrs), children);
}

// An SVG element, the same way.
export function svgEl(tag, attrs, ...children) {
  return append(setAttributes(document.createElementNS(SVG_NS, tag), attrs), children);
}

const integer = new Intl.NumberFormat('en', { maximumFractionDigits: 0 });

// 1234567 -> "1,234,567".
export function fmtInt(n) {
  return Number.isFinite(n) ? integer.format(n) : '–';
}

// A number with `digits` significant digits, without a trailing exponent for everyday
// magnitudes.
export function fmtNum(x, digits = 4) {
  if (x === null || x === undefined || !Number.isFinite(x)) return '–';
  if (x === 0) return '0';
  const a = Math.abs(x);
  if (a >= 1e-3 && a < 1e6) return String(Number(x.toPrecision(digits)));
  return x.toExponential(digits - 1);
}

export function fmtPercent(x, digits = 1) {
  return Number.isFinite(x) ? `${(100 * x).toFixed(digits)} %` : '–';
}

// A time stamp of the API (RFC 3339, UTC) in the reader's local time.
export function fmtTime(text) {
  if (!text) return '–';
  const d = new Date(text);
  return Number.isNaN(d.getTime()) ? text : d.toLocaleString();
}

// Calls fn once `ms` after the last of a burst of calls.
export function debounce(fn, ms) {
  let timer = 0;
  return (...args) => {
    clearTimeout(timer);
    timer = setTimeout(() => fn(...args), ms);
  };
}

// Says a short message to screen readers (the polite live region of the page).
export function announce(text) {
  const region = document.getElementById('announcer');
  if (!region) return;
  region.textContent = '';
  // a new text node after a tick, so that the same message twice is read twice
  setTimeout(() => { region.textContent = text; }, 50);
}

// A label from a field name: "max_iterations" -> "Max iterations".
export function humanName(name) {
  const text = name.replace(/_/g, ' ');
  return text.charAt(0).toUpperCase() + text.slice(1);
}

let ids = 0;
// A fresh id for label/for and aria-describedby pairs.
export function uid(prefix = 'f') {
  ids += 1;
  return `${prefix}-${ids}`;
}
