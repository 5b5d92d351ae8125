// app.js - the page's entry: reads what the service is (GET /health, its processes and the
// first one's description), builds the three views, switches between them with the address's hash
// (#design, #job/ID, #jobs: a job can be linked to; the key never appears in it), and
// keeps the API key of this tab.

import { describe, getJSON, getKey, setKey } from './api.js';
import { DesignView } from './design.js';
import { el, fmtInt } from './dom.js';
import { JobView } from './job.js';
import { JobsView } from './jobs.js';

const views = ['design', 'job', 'jobs'];
// The process the design view shows first: the report's own, disks in a rectangle.
const FIRST_PROCESS = 'pack2d';
let design = null;
let job = null;
let jobs = null;
let health = null;

// Which view and job the address names.
function route() {
  const hash = decodeURIComponent(location.hash.slice(1));
  if (hash.startsWith('job/')) return { view: 'job', id: hash.slice(4) };
  return { view: views.includes(hash) ? hash : 'design', id: null };
}

function showView({ view, id }, focus) {
  for (const name of views) document.getElementById(`view-${name}`).hidden = name !== view;
  for (const link of document.querySelectorAll('nav.views a')) {
    if (link.dataset.view === view) link.setAttribute('aria-current', 'page');
    else link.removeAttribute('aria-current');
  }
  const jobLink = document.querySelector('nav.views a[data-view="job"]');
  if (id) jobLink.href = `#job/${encodeURIComponent(id)}`;
  if (view === 'job' && job) job.open(id || (job.id !== null ? job.id : null));
  if (view === 'jobs' && jobs) jobs.reload();
  if (focus) document.getElementById(`${view}-h`).focus();
}

function showService() {
  const line = document.getElementById('service');
  if (!health) return;
  const access = health.access === 'keys' ? 'API keys required' : 'open: no key needed';
  line.textContent = `grainpackd ${health.version} · ${health.workers_busy} of ${health.workers} workers busy · `
    + `${fmtInt(health.queue_depth)} queued · ${access}`;
}

async function refreshHealth() {
  try {
    health = await getJSON('/health');
  } catch (err) {
    document.getElementById('service').textContent = describe(err);
    return;
  }
  showService();
  document.getElementById('key-form').hidden = health.access !== 'keys';
}

function setupKey() {
  const form = document.getElementById('key-form');
  const input = document.getElementById('key');
  const state = document.getElementById('key-state');
  const shown = () => {
    state.textContent = getKey() ? 'a key is in use in this tab' : 'no key yet';
  };
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    setKey(input.value.trim());
    input.value = '';
    shown();
    if (design) design.refresh();
    if (jobs) jobs.load();
    if (job && job.id) { const id = job.id; job.close(); job.id = null; job.open(id); }
  });
  document.getElementById('key-forget').addEventListener('click', () => {
    setKey('');
    shown();
    if (design) design.refresh();
    if (jobs) jobs.load();
  });
  shown();
}

async function start() {
  setupKey();
  // the list and the first process's description at once; the others' when chosen
  const [list, first] = await Promise.all([getJSON('/processes'), getJSON(`/processes/${FIRST_PROCESS}`), refreshHealth()]);
  job = new JobView(document.getElementById('job'), { onChanged: () => refreshHealth() });
  jobs = new JobsView(document.getElementById('jobs'));
  design = new DesignView(document.getElementById('design'), list.processes, first, {
    onSubmitted: (info) => { location.hash = `job/${encodeURIComponent(info.jobID)}`; },
  });
  window.addEventListener('hashchange', () => showView(route(), true));
  showView(route(), false);
  jobs.load();
  document.body.classList.add('ready');
}

start().catch((err) => {
  const main = document.getElementById('main');
  main.prepend(el('p', { class: 'error-summary', role: 'alert' }, `The page could not start: ${describe(err)}`));
});
