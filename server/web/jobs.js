// jobs.js - the My jobs view: the jobs this key may see (all of them on an open
// service), newest first, a page at a time (the list's own "next" links), filtered by
// status; each can be opened, dismissed or deleted.

import { describe, getJSON, request } from './api.js';
import { el, fmtTime } from './dom.js';

const PAGE_SIZE = 10;
const STATUSES = ['accepted', 'running', 'successful', 'failed', 'dismissed'];

export class JobsView {
  constructor(root) {
    this.root = root;
    this.pages = []; // hrefs of the pages seen, to go back
    this.filter = el('select', { id: 'status-filter', onchange: () => this.load() },
      el('option', { value: '' }, 'any'), STATUSES.map((s) => el('option', { value: s }, s)));
    this.body = el('tbody');
    this.note = el('p', { role: 'status', class: 'note' });
    this.newer = el('button', { type: 'button', onclick: () => this.back() }, '← Newer');
    this.older = el('button', { type: 'button', onclick: () => this.forward() }, 'Older →');
    root.append(
      el('div', { class: 'list-tools' },
        el('div', { class: 'field inline' }, el('label', { for: 'status-filter' }, 'Status'), this.filter),
        el('button', { type: 'button', onclick: () => this.reload() }, 'Refresh')),
      el('div', { class: 'table-wrap' }, el('table', { class: 'jobs' },
        el('caption', { class: 'visually-hidden' }, 'Your jobs, newest first'),
        el('thead', {}, el('tr', {}, ['Job', 'Process', 'Status', 'Progress', 'Submitted', 'Actions'].map((h) => el('th', { scope: 'col' }, h)))),
        this.body)),
      this.note,
      el('nav', { class: 'pager', 'aria-label': 'pages of jobs' }, this.newer, this.older));
  }

  // The first page with the current filter.
  load() {
    const status = this.filter.value;
    this.pages = [`/jobs?limit=${PAGE_SIZE}${status ? `&status=${status}` : ''}`];
    return this.show();
  }

  // The page shown now, again.
  reload() {
    return this.pages.length ? this.show() : this.load();
  }

  forward() {
    if (this.next) {
      this.pages.push(this.next);
      this.show();
    }
  }

  back() {
    if (this.pages.length > 1) {
      this.pages.pop();
      this.show();
    }
  }

  async show() {
    const href = this.pages[this.pages.length - 1];
    this.note.textContent = 'Loading…';
    try {
      const page = await getJSON(href);
      const next = (page.links || []).find((l) => l.rel === 'next');
      this.next = next ? next.href : null;
      this.body.replaceChildren(...page.jobs.map((job) => this.row(job)));
      this.note.textContent = page.jobs.length
        ? `${page.jobs.length} job${page.jobs.length > 1 ? 's' : ''} on this page.`
        : 'No jobs here yet.';
    } catch (err) {
      this.next = null;
      this.body.replaceChildren();
      this.note.textContent = describe(err);
    }
    this.newer.disabled = this.pages.length <= 1;
    this.older.disabled = !this.next;
  }

  row(job) {
    const active = job.status === 'accepted' || job.status === 'running';
    const label = active ? 'Dismiss' : 'Delete';
    return el('tr', {},
      el('td', {}, el('a', { href: `#job/${encodeURIComponent(job.jobID)}` }, el('code', {}, job.jobID))),
      el('td', {}, job.processID || ''),
      el('td', {}, el('span', { class: `badge ${job.status}` }, job.status)),
      el('td', {}, active ? `${job.progress || 0} % ${job.message || ''}` : job.message || ''),
      el('td', {}, fmtTime(job.created)),
      el('td', {}, el('button', {
        type: 'button', class: 'small', 'aria-label': `${label} job ${job.jobID}`,
        onclick: () => this.remove(job, active),
      }, label)));
  }

  async remove(job, active) {
    if (!active && !window.confirm(`Delete job ${job.jobID} and its results?`)) return;
    try {
      await request(`/jobs/${encodeURIComponent(job.jobID)}`, { method: 'DELETE' });
      await this.reload();
      this.note.textContent = active ? `Job ${job.jobID} dismissed.` : `Job ${job.jobID} deleted.`;
    } catch (err) {
      this.note.textContent = describe(err);
    }
  }
}
