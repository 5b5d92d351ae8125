// design.js - the Design view: the process (disks in a rectangle, spheres in a box: the
// service's list), the job's inputs as a form made from its description, the target law
// and the joint j(r) drawn as they are typed, the service's own validation (POST
// /processes/{id}/validation) giving the expected number of grains or the problem next
// to its field, and the submission.

import { describe, getJSON, request } from './api.js';
import { binsChart, curveChart } from './charts.js';
import { announce, debounce, el, fmtInt } from './dom.js';
import { makeInput } from './form.js';

// Validation waits for this pause in the typing (ms): one request per burst of keys.
const VALIDATE_DELAY = 300;
// Samples of the j(r) curve.
const CURVE_POINTS = 64;
// What the form of each process holds before anything is chosen: the report's fixed case
// in 2D; in 3D a small box of equal spheres (about 900), quick to run and to look at.
const START = {
  pack2d: {
    domain: { width: 100, height: 100 },
    distribution: { kind: 'constant', radius: 0.9 },
    joint: { law: 'constant', value: 0.1 },
    seed: 1,
  },
  pack3d: {
    domain: { width: 10, height: 10, depth: 10 },
    distribution: { kind: 'constant', radius: 0.5 },
    joint: { law: 'constant', value: 0.05 },
    seed: 1,
  },
};
// The examples offered for each process (served at /ui/example-NAME.json).
const EXAMPLES = {
  pack2d: [
    ['fixed', 'the report’s fixed radius (2789 grains)'],
    ['variable', 'the report’s three bins'],
    ['iron', 'the report’s iron, 12 bins, j = 2 / r'],
    ['bagi', 'Bagi’s uniform law (37,000 grains)'],
  ],
  pack3d: [
    ['iron3d', 'iron in a box of 80, balanced, offset polyhedra'],
  ],
};

// The radii a law can draw: [lo, hi] (lo = hi for a constant radius), or null while the
// law is not complete.
function support(dist) {
  if (!dist) return null;
  if (dist.kind === 'constant') return Number.isFinite(dist.radius) ? [dist.radius, dist.radius] : null;
  if (dist.kind === 'uniform') return Number.isFinite(dist.min) && Number.isFinite(dist.max) ? [dist.min, dist.max] : null;
  if (dist.kind === 'histogram' && Array.isArray(dist.bins)) {
    const used = dist.bins.filter((b) => b.p > 0);
    if (!used.length || !used.every((b) => Number.isFinite(b.min) && Number.isFinite(b.max))) return null;
    return [Math.min(...used.map((b) => b.min)), Math.max(...used.map((b) => b.max))];
  }
  return null;
}

// The law as bins for the chart: a histogram's own, one block for a uniform law, a spike
// for a constant radius.
function targetBins(dist) {
  if (!dist) return null;
  if (dist.kind === 'histogram' && Array.isArray(dist.bins)) {
    const ok = dist.bins.every((b) => [b.min, b.max, b.p].every(Number.isFinite) && b.max >= b.min);
    return ok && dist.bins.length ? dist.bins.map((b) => ({ min: b.min, max: b.max, target: b.p })) : null;
  }
  const s = support(dist);
  return s ? [{ min: s[0], max: s[1], target: 1 }] : null;
}

// j(r) for the joint laws the page knows how to draw (docs/method.md, joint laws).
function thickness(joint, r) {
  if (!joint || joint.law === 'none') return 0;
  if (joint.law === 'constant') return joint.value;
  if (joint.law === 'inverse') return joint.k / r;
  if (joint.law === 'power') return joint.k * r ** joint.exponent;
  return NaN;
}

export class DesignView {
  // `processes`: the service's list (GET /processes); `first`: the description of the
  // first one, shown at once; the others' are fetched when chosen.
  constructor(root, processes, first, { onSubmitted }) {
    this.root = root;
    this.onSubmitted = onSubmitted;
    this.controls = new Map();
    this.descriptions = new Map([[first.id, first]]);
    this.kept = new Map(); // the inputs typed for each process, while another is shown
    this.ready = false;
    this.scheduleValidation = debounce(() => this.validate(), VALIDATE_DELAY);
    this.fields = el('div', { class: 'fields' });
    const exampleId = 'example';
    this.example = el('select', { id: exampleId, onchange: () => this.loadExample() });
    this.exampleField = el('div', { class: 'field start' }, el('label', { for: exampleId }, 'Start from an example'), this.example);
    this.processChoice = el('fieldset', { class: 'group process' }, el('legend', {}, 'What to pack'),
      processes.map((p) => el('label', { class: 'choice' },
        el('input', { type: 'radio', name: 'process', value: p.id, checked: p.id === first.id, onchange: () => this.choose(p.id) }),
        ` ${p.title}`)));
    this.targetPlot = el('figure', { class: 'plot' });
    this.jointPlot = el('figure', { class: 'plot' });
    this.expected = el('p', { class: 'expected', role: 'status', 'aria-live': 'polite' }, 'Checking the design…');
    this.message = el('div', { class: 'message', role: 'alert' });
    this.normalised = el('pre', { class: 'json', tabindex: 0 });
    this.curl = el('pre', { class: 'json', tabindex: 0 });
    this.submitButton = el('button', { type: 'submit', class: 'primary' }, 'Submit the job');
    this.form = el('form', { class: 'design', novalidate: true, onsubmit: (e) => this.submit(e) },
      el('div', { class: 'design-grid' },
        el('div', { class: 'design-fields' }, this.processChoice, this.exampleField, this.fields),
        el('aside', { class: 'design-side', 'aria-label': 'Preview and submission' },
          this.targetPlot, this.jointPlot,
          el('div', { class: 'summary' }, this.expected, this.message, this.submitButton,
            el('details', {}, el('summary', {}, 'The request, as the service reads it'), this.normalised,
              el('p', {}, 'The same from a terminal:'), this.curl)))));
    root.append(this.form);
    const onChange = () => this.changed();
    this.form.addEventListener('input', onChange);
    this.form.addEventListener('change', onChange);
    this.show(first);
  }

  get path() {
    return `/processes/${this.process.id}`;
  }

  // Builds the form of process description `process`, holding what was typed for it before
  // (or its start values).
  show(process) {
    this.ready = false;
    this.process = process;
    this.controls.clear();
    this.fields.replaceChildren();
    const onChange = () => this.changed();
    for (const [name, description] of Object.entries(process.inputs || {})) {
      const control = makeInput(`/inputs/${name}`, name, description, onChange);
      this.controls.set(name, control);
      this.fields.append(control.node);
    }
    const examples = EXAMPLES[process.id] || [];
    this.example.replaceChildren(el('option', { value: '' }, 'choose…'),
      ...examples.map(([name, label]) => el('option', { value: name }, label)));
    this.exampleField.hidden = examples.length === 0;
    this.clearErrors();
    this.setValues(this.kept.get(process.id) || START[process.id] || {});
    this.ready = true;
    this.changed();
  }

  // The process radio `id` was chosen: its form, its description fetched the first time.
  async choose(id) {
    if (this.process && id === this.process.id) return;
    if (this.process) this.kept.set(this.process.id, this.collect());
    try {
      if (!this.descriptions.has(id)) this.descriptions.set(id, await getJSON(`/processes/${encodeURIComponent(id)}`));
    } catch (err) {
      this.showMessage(describe(err));
      return;
    }
    this.show(this.descriptions.get(id));
    announce(`${this.descriptions.get(id).title}: its form is shown`);
  }

  // The inputs object the form describes (properties left empty are left out).
  collect() {
    const inputs = {};
    for (const [name, control] of this.controls) {
      const v = control.get();
      if (v !== undefined) inputs[name] = v;
    }
    return inputs;
  }

  setValues(inputs) {
    for (const [name, control] of this.controls) control.set(inputs[name]);
  }

  async loadExample() {
    const name = this.example.value;
    if (!name) return;
    try {
      const example = await getJSON(`/ui/example-${name}.json`);
      this.setValues(example.inputs || example);
      this.changed();
      announce(`${name} example loaded`);
    } catch (err) {
      this.showMessage(describe(err));
    }
  }

  // Something was edited: the plots now, the service's verdict after a pause.
  changed() {
    if (!this.ready) return;
    this.drawPlots();
    this.scheduleValidation();
  }

  drawPlots() {
    const inputs = this.collect();
    const bins = targetBins(inputs.distribution);
    this.targetPlot.replaceChildren(bins
      ? binsChart({ bins, title: 'Target radius law' })
      : el('p', { class: 'placeholder' }, 'The target law is drawn once its numbers are complete.'),
    el('figcaption', {}, 'The radius law asked for'));
    const s = support(inputs.distribution);
    const joint = inputs.joint;
    if (!s || !joint) {
      this.jointPlot.replaceChildren();
      return;
    }
    let [lo, hi] = s;
    if (!(hi > lo)) { lo *= 0.5; hi *= 1.5; }
    const xs = Array.from({ length: CURVE_POINTS }, (_, i) => lo + ((hi - lo) * i) / (CURVE_POINTS - 1));
    const ys = xs.map((r) => thickness(joint, r));
    this.jointPlot.replaceChildren(ys.every(Number.isFinite)
      ? curveChart({ xs, series: [{ ys, label: 'j(r)', cls: 'joint' }], title: 'Grain-boundary thickness j(r)', xLabel: 'grain radius r', yLabel: 'j(r)' })
      : el('p', { class: 'placeholder' }, 'j(r) is drawn once its numbers are complete.'),
    el('figcaption', {}, 'The grain boundary j(r) over the radii the law draws: each grain is packed with R = r + j(r)'));
  }

  // Asks the service whether the design is a valid job, and how many grains it expects.
  async validate() {
    const inputs = this.collect();
    if (this.pending) this.pending.abort();
    const pending = new AbortController();
    this.pending = pending;
    const path = this.path;
    try {
      const answer = await getJSON(`${path}/validation`, { method: 'POST', body: { inputs }, signal: pending.signal });
      if (path !== this.path) return; // the process changed meanwhile
      this.clearErrors();
      // 2D answers in disks, 3D in spheres
      const spheres = answer.expected_spheres !== undefined;
      const limits = answer.limits || {};
      this.expected.replaceChildren(
        el('strong', {}, `≈ ${fmtInt(spheres ? answer.expected_spheres : answer.expected_disks)} ${spheres ? 'spheres' : 'disks'} expected`),
        ` (the service’s estimate, on the high side; at most ${fmtInt(spheres ? limits.max_spheres : limits.max_disks)} a job)`);
      this.normalised.textContent = JSON.stringify({ inputs: answer.inputs }, null, 1);
      this.curl.textContent = `curl -s -H 'Content-Type: application/json' -d '${JSON.stringify({ inputs })}' ${location.origin}${path}/execution`;
    } catch (err) {
      if (err.name === 'AbortError' || path !== this.path) return;
      this.expected.textContent = 'No estimate until the design is valid.';
      if (err.status === 400 || err.status === 422) this.showProblem(err.problem);
      else this.showMessage(describe(err));
    } finally {
      if (this.pending === pending) this.pending = null;
    }
  }

  clearErrors() {
    this.message.replaceChildren();
    for (const node of this.form.querySelectorAll('.error')) node.remove();
    for (const node of this.form.querySelectorAll('[aria-invalid]')) {
      node.removeAttribute('aria-invalid');
      const ids = (node.getAttribute('aria-describedby') || '').split(' ').filter((id) => !id.startsWith('err-'));
      if (ids.length) node.setAttribute('aria-describedby', ids.join(' '));
      else node.removeAttribute('aria-describedby');
    }
  }

  showMessage(text) {
    this.clearErrors();
    this.message.replaceChildren(el('p', { class: 'error-summary' }, text));
  }

  // Shows a problem next to the field its JSON pointer names (the deepest element of the
  // form whose pointer is that one or an ancestor of it), and in the summary.
  showProblem(problem) {
    this.clearErrors();
    const pointer = problem.pointer;
    let target = null;
    if (typeof pointer === 'string') {
      for (const node of this.form.querySelectorAll('[data-pointer]')) {
        if (node.closest('[hidden]')) continue; // another branch of a law shares the pointer
        const p = node.dataset.pointer;
        const matches = pointer === p || pointer.startsWith(`${p}/`);
        if (matches && (!target || p.length > target.dataset.pointer.length)) target = node;
      }
    }
    const text = problem.expected || problem.detail || problem.title;
    if (target) {
      const id = `err-${Math.random().toString(36).slice(2, 9)}`;
      target.append(el('p', { class: 'error', id }, text));
      const input = target.querySelector('input, select, textarea');
      if (input) {
        input.setAttribute('aria-invalid', 'true');
        input.setAttribute('aria-describedby', `${input.getAttribute('aria-describedby') || ''} ${id}`.trim());
      }
    }
    const go = target && target.querySelector('input, select, textarea');
    this.message.replaceChildren(el('p', { class: 'error-summary' },
      `${problem.detail || problem.title}`, go ? ' ' : null,
      go ? el('button', { type: 'button', class: 'link', onclick: () => go.focus() }, 'Go to the field') : null));
    return go;
  }

  async submit(event) {
    event.preventDefault();
    this.submitButton.disabled = true;
    try {
      const response = await request(`${this.path}/execution`, { method: 'POST', body: { inputs: this.collect() } });
      const info = await response.json();
      this.message.replaceChildren();
      this.onSubmitted(info);
    } catch (err) {
      if (err.status === 400 || err.status === 422) {
        const field = this.showProblem(err.problem);
        if (field) field.focus();
      } else {
        this.showMessage(describe(err));
      }
    } finally {
      this.submitButton.disabled = false;
    }
  }

  // The key changed: what the service says may change too.
  refresh() {
    this.validate();
  }
}

