// viewer.js - the result's picture, zoomable and pannable: the wheel or the buttons zoom
// (around the pointer for the wheel), a drag pans, and from the keyboard + and - zoom,
// the arrows pan and 0 goes back to the whole picture.

import { el } from './dom.js';

const ZOOM_STEP = 1.25;
const MAX_ZOOM = 64;
// A key press pans by this fraction of the view.
const PAN_STEP = 0.1;

export class Viewer {
  constructor(label) {
    this.scale = 1;
    this.tx = 0;
    this.ty = 0;
    this.img = el('img', { alt: label, draggable: 'false' });
    this.stage = el('div', {
      class: 'viewer', tabindex: 0, role: 'group',
      'aria-label': `${label}: + and - zoom, the arrows pan, 0 shows it whole`,
    }, this.img);
    const button = (text, name, fn) => el('button', { type: 'button', 'aria-label': name, title: name, onclick: fn }, text);
    this.zoomText = el('span', { class: 'zoom', 'aria-live': 'polite' }, '100 %');
    this.node = el('div', { class: 'picture' },
      el('div', { class: 'toolbar' },
        button('+', 'zoom in', () => this.zoomBy(ZOOM_STEP)),
        button('−', 'zoom out', () => this.zoomBy(1 / ZOOM_STEP)),
        button('⟲', 'show the whole picture', () => this.reset()),
        this.zoomText),
      this.stage);
    this.stage.addEventListener('wheel', (e) => this.wheel(e), { passive: false });
    this.stage.addEventListener('pointerdown', (e) => this.grab(e));
    this.stage.addEventListener('keydown', (e) => this.key(e));
    this.stage.addEventListener('dblclick', (e) => this.zoomBy(ZOOM_STEP * ZOOM_STEP, this.point(e)));
  }

  // Shows the picture at url (a blob: URL the caller revokes).
  show(url) {
    this.img.src = url;
    this.reset();
  }

  reset() {
    this.scale = 1;
    this.tx = 0;
    this.ty = 0;
    this.apply();
  }

  apply() {
    this.img.style.transform = `translate(${this.tx}px, ${this.ty}px) scale(${this.scale})`;
    this.zoomText.textContent = `${Math.round(this.scale * 100)} %`;
  }

  // The pointer's position in the stage, in pixels.
  point(e) {
    const r = this.stage.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  // Zooms by factor around a point of the stage (its centre by default), keeping that
  // point of the picture where it is.
  zoomBy(factor, at) {
    const r = this.stage.getBoundingClientRect();
    const p = at || { x: r.width / 2, y: r.height / 2 };
    const scale = Math.min(MAX_ZOOM, Math.max(1, this.scale * factor));
    const k = scale / this.scale;
    this.tx = p.x - k * (p.x - this.tx);
    this.ty = p.y - k * (p.y - this.ty);
    this.scale = scale;
    if (scale === 1) { this.tx = 0; this.ty = 0; }
    this.apply();
  }

  wheel(e) {
    e.preventDefault();
    this.zoomBy(e.deltaY < 0 ? ZOOM_STEP : 1 / ZOOM_STEP, this.point(e));
  }

  grab(e) {
    if (e.button !== 0) return;
    const start = { x: e.clientX - this.tx, y: e.clientY - this.ty };
    this.stage.setPointerCapture(e.pointerId);
    this.stage.classList.add('grabbing');
    const move = (m) => {
      this.tx = m.clientX - start.x;
      this.ty = m.clientY - start.y;
      this.apply();
    };
    const up = () => {
      this.stage.classList.remove('grabbing');
      this.stage.removeEventListener('pointermove', move);
      this.stage.removeEventListener('pointerup', up);
      this.stage.removeEventListener('pointercancel', up);
    };
    this.stage.addEventListener('pointermove', move);
    this.stage.addEventListener('pointerup', up);
    this.stage.addEventListener('pointercancel', up);
  }

  key(e) {
    const r = this.stage.getBoundingClientRect();
    const pans = { ArrowLeft: [1, 0], ArrowRight: [-1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
    if (e.key === '+' || e.key === '=') this.zoomBy(ZOOM_STEP);
    else if (e.key === '-' || e.key === '_') this.zoomBy(1 / ZOOM_STEP);
    else if (e.key === '0') this.reset();
    else if (pans[e.key]) {
      this.tx += pans[e.key][0] * PAN_STEP * r.width;
      this.ty += pans[e.key][1] * PAN_STEP * r.height;
      this.apply();
    } else return;
    e.preventDefault();
  }
}
