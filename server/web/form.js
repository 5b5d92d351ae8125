// form.js - form controls made from the JSON schemas of the process description
// (GET /processes/pack2d): a number, a choice, a switch for each property, a fieldset for
// an object (with a switch when the input is optional: a stage), a choice of branch for a
// oneOf (a law). A stage or an option the service gains appears here with no code; only
// shapes that deserve a better editor than a generic one (the histogram's bins) are
// special. Every control carries the JSON pointer of its value in the submitted document,
// so that an error of the service lands next to it.

import { el, humanName, uid } from './dom.js';
import { HistogramEditor } from './histogram.js';

// Friendlier labels than the field names, where a name alone says too little.
const LABELS = {
  level_band: 'Level band',
  max_iterations: 'Largest number of sweeps',
  max_step: 'First step (fraction of the way)',
  flush_boundary: 'Keep cells flush with the walls',
  disks: 'Outline the grain disks',
  color: 'Colour the grains by',
  value: 'Thickness c',
  k: 'Coefficient k',
  exponent: 'Exponent e',
  radius: 'Radius',
};

function labelOf(name, schema) {
  return LABELS[name] || schema.title || humanName(name);
}

// A help text under a control, referenced by aria-describedby.
function help(text) {
  return text ? el('p', { class: 'help', id: uid('help') }, text) : null;
}

// One scalar value: a number, integer, string choice or boolean.
export class Field {
  constructor(pointer, name, schema, required) {
    this.pointer = pointer;
    this.schema = schema;
    this.required = required;
    const id = uid('field');
    const note = help(schema.description);
    const describedBy = note ? note.id : null;
    const label = el('label', { for: id }, labelOf(name, schema));
    if (schema.enum) {
      const options = schema.enum.map((v) => el('option', { value: v }, String(v)));
      if (!required) options.unshift(el('option', { value: '' }, schema.default !== undefined ? `default (${schema.default})` : 'default'));
      this.input = el('select', { id, name, 'aria-describedby': describedBy }, options);
    } else if (schema.type === 'boolean') {
      this.input = el('input', { id, name, type: 'checkbox', 'aria-describedby': describedBy });
      this.input.checked = schema.default === true;
    } else if (schema.type === 'number' || schema.type === 'integer') {
      const min = schema.minimum ?? schema.exclusiveMinimum;
      this.input = el('input', {
        id, name, type: 'number', inputmode: schema.type === 'integer' ? 'numeric' : 'decimal',
        step: schema.type === 'integer' ? 1 : 'any', min, max: schema.maximum,
        placeholder: schema.default !== undefined ? `default ${schema.default}` : null,
        required: required, 'aria-describedby': describedBy,
      });
    } else {
      this.input = el('input', { id, name, type: 'text', 'aria-describedby': describedBy });
    }
    const boolean = schema.type === 'boolean';
    this.node = el('div', { class: boolean ? 'field check' : 'field', dataset: { pointer } },
      boolean ? [this.input, label] : [label, this.input], note);
  }

  // The value to send, or undefined to leave the property out (the service's default).
  get() {
    const s = this.schema;
    if (s.type === 'boolean') return this.input.checked;
    const text = this.input.value.trim();
    if (text === '') return undefined;
    if (s.type === 'number' || s.type === 'integer') return Number(text);
    return text;
  }

  set(value) {
    if (this.schema.type === 'boolean') this.input.checked = value === true;
    else this.input.value = value === undefined || value === null ? '' : String(value);
  }
}

// An object: one control per property. An optional input (a stage, an option group) has
// a switch that says whether it is sent at all.
export class Group {
  constructor(pointer, name, schema, { title, description, optional, skip = [], legend = true, onChange } = {}) {
    this.pointer = pointer;
    this.optional = optional;
    this.controls = new Map();
    const required = new Set(schema.required || []);
    const body = el('div', { class: 'group-body' });
    for (const [prop, sub] of Object.entries(schema.properties || {})) {
      if (skip.includes(prop)) continue;
      const control = makeControl(`${pointer}/${prop}`, prop, sub, required.has(prop), onChange);
      this.controls.set(prop, control);
      body.append(control.node);
    }
    const intro = help(description);
    if (optional) {
      const id = uid('use');
      this.toggle = el('input', { id, type: 'checkbox', class: 'use', 'aria-describedby': intro ? intro.id : null });
      this.toggle.addEventListener('change', () => { body.hidden = !this.toggle.checked; });
      body.hidden = true;
      this.node = el('fieldset', { class: 'group optional', dataset: { pointer } },
        el('legend', {}, el('span', { class: 'check' }, this.toggle, el('label', { for: id }, title || humanName(name)))),
        intro, body);
    } else {
      this.node = el(legend ? 'fieldset' : 'div', { class: legend ? 'group' : 'branch', dataset: { pointer } },
        legend ? el('legend', {}, title || humanName(name)) : null, intro, body);
    }
  }

  get() {
    if (this.optional && !this.toggle.checked) return undefined;
    const out = {};
    for (const [prop, control] of this.controls) {
      const v = control.get();
      if (v !== undefined) out[prop] = v;
    }
    return out;
  }

  set(value) {
    if (this.optional) {
      this.toggle.checked = value !== undefined && value !== null;
      this.toggle.dispatchEvent(new Event('change'));
    }
    for (const [prop, control] of this.controls) control.set(value ? value[prop] : undefined);
  }
}

// The property that tells the branches of a oneOf apart (each branch has it as a const).
function discriminator(branches) {
  const first = branches[0].properties || {};
  return Object.keys(first).find((k) => branches.every((b) => b.properties && b.properties[k] && 'const' in b.properties[k]));
}

// A oneOf with a const discriminator (kind, law): a choice of branch, then its fields.
export class Choice {
  constructor(pointer, name, schema, { title, description, optional, onChange } = {}) {
    this.pointer = pointer;
    this.key = discriminator(schema.oneOf);
    this.branches = new Map();
    const id = uid('choice');
    const intro = help(description);
    this.select = el('select', { id, name: this.key, 'aria-describedby': intro ? intro.id : null });
    const fields = el('div', { class: 'branches' });
    for (const branch of schema.oneOf) {
      const value = branch.properties[this.key].const;
      this.select.append(el('option', { value }, String(value)));
      const group = new Group(pointer, value, branch, { skip: [this.key], legend: false, onChange });
      group.node.hidden = true;
      this.branches.set(value, group);
      fields.append(group.node);
    }
    this.select.addEventListener('change', () => this.show());
    this.node = el('fieldset', { class: 'group', dataset: { pointer } },
      el('legend', {}, title || humanName(name)), intro,
      el('div', { class: 'field', dataset: { pointer: `${pointer}/${this.key}` } },
        el('label', { for: id }, humanName(this.key)), this.select),
      fields);
    this.optional = optional;
    this.show();
  }

  show() {
    for (const [value, group] of this.branches) group.node.hidden = value !== this.select.value;
  }

  get() {
    const group = this.branches.get(this.select.value);
    return { [this.key]: this.select.value, ...(group ? group.get() : {}) };
  }

  set(value) {
    if (value && this.branches.has(value[this.key])) this.select.value = value[this.key];
    this.show();
    const group = this.branches.get(this.select.value);
    if (group && value) group.set(value);
  }
}

// A value of a shape no generic control fits: edited as JSON text.
class JsonField {
  constructor(pointer, name, schema) {
    const id = uid('json');
    const note = help(schema.description || 'as JSON');
    this.input = el('textarea', { id, rows: 3, spellcheck: 'false', 'aria-describedby': note ? note.id : null });
    this.node = el('div', { class: 'field', dataset: { pointer } }, el('label', { for: id }, humanName(name)), this.input, note);
  }

  get() {
    const text = this.input.value.trim();
    if (!text) return undefined;
    try {
      return JSON.parse(text);
    } catch {
      return text; // sent as a string: the service says what it expected
    }
  }

  set(value) {
    this.input.value = value === undefined ? '' : JSON.stringify(value);
  }
}

// Whether an array schema holds histogram bins {min, max, p}.
function isBins(schema) {
  const items = schema.items || {};
  const props = items.properties || {};
  return schema.type === 'array' && 'min' in props && 'max' in props && 'p' in props;
}

// The control for a property's schema.
export function makeControl(pointer, name, schema, required, onChange) {
  if (schema.oneOf && discriminator(schema.oneOf)) return new Choice(pointer, name, schema, { onChange });
  if (schema.type === 'object' && schema.properties) return new Group(pointer, name, schema, { onChange });
  if (isBins(schema)) return new HistogramEditor(pointer, onChange);
  if (['number', 'integer', 'boolean', 'string'].includes(schema.type) || schema.enum) {
    return new Field(pointer, name, schema, required);
  }
  return new JsonField(pointer, name, schema);
}

// The control of one input of the process description.
export function makeInput(pointer, name, description, onChange) {
  const schema = description.schema || {};
  const options = {
    title: description.title, description: description.description, optional: description.minOccurs === 0, onChange,
  };
  if (schema.oneOf && discriminator(schema.oneOf)) return new Choice(pointer, name, schema, options);
  if (schema.type === 'object' && schema.properties) return new Group(pointer, name, schema, options);
  // a single value (the seed): a field of its own, titled by the description
  const control = makeControl(pointer, name, { ...schema, title: description.title, description: description.description },
    !options.optional, onChange);
  control.node = el('div', { class: 'group scalar' }, control.node);
  return control;
}
