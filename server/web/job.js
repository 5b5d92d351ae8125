// job.js - the Job view: watch a job (its status and progress, live through the
// long-poll GET /jobs/{id}?wait=), dismiss it, then look at what it made: the picture
// (2D: coloured by radius or by F; 3D: the section of the box its spec asked for), the
// statistics beside it (a 3D job's cells are polyhedra), and every download.

import { describe, getBlob, getJSON, getKey, request } from './api.js';
import { binsChart, countsChart } from './charts.js';
import { announce, el, fmtInt, fmtNum, fmtPercent, fmtTime } from './dom.js';
import { Viewer } from './viewer.js';

// Seconds of each long-poll: the answer comes at once when the job finishes, otherwise
// after this long with its progress, so the bar moves about once a second.
const POLL_WAIT = 1;
// After a lost connection, the next try waits this long (ms).
const RETRY_DELAY = 2000;
// Pictures of more grains than this are drawn on request only: their SVG (about 100
// bytes a grain) would take the browser a while.
const PICTURE_AUTO_MAX = 200000;
const FINAL = new Set(['successful', 'failed', 'dismissed']);
const RESULTS_REL = 'http://www.opengis.net/def/rel/ogc/1.0/results';

const sleep = (ms, signal) => new Promise((resolve) => {
  const timer = setTimeout(resolve, ms);
  if (signal) signal.addEventListener('abort', () => { clearTimeout(timer); resolve(); });
});

// A term and its value, for the figures' description lists.
function figure(term, value, title) {
  return [el('dt', { title }, term), el('dd', {}, value)];
}

// A table of rows (arrays of cells) with a caption, hidden under a <details>.
function dataTable(summary, head, rows) {
  return el('details', { class: 'data' }, el('summary', {}, summary),
    el('table', {}, el('thead', {}, el('tr', {}, head.map((h) => el('th', { scope: 'col' }, h)))),
      el('tbody', {}, rows.map((r) => el('tr', {}, r.map((c) => el('td', {}, c)))))));
}

export class JobView {
  constructor(root, { onChanged }) {
    this.root = root;
    this.onChanged = onChanged;
    this.id = null;
    this.controller = null;
    this.pictureUrl = null;
  }

  // Shows job `id` (or the hint when there is none), watching it until it is finished.
  open(id) {
    if (id && id === this.id) return; // shown already, and watched while it runs
    this.close();
    this.id = id;
    if (!id) {
      this.root.replaceChildren(el('p', {}, 'No job open: submit one from ', el('a', { href: '#design' }, 'Design'),
        ' or pick one in ', el('a', { href: '#jobs' }, 'My jobs'), '.'));
      return;
    }
    this.controller = new AbortController();
    this.status = el('span', { class: 'badge' }, '…');
    this.progress = el('progress', { max: 100, value: 0, 'aria-label': 'progress of the job' });
    this.percent = el('span', { class: 'percent' });
    // not a live region: it changes every second; changes of status are announced instead
    this.message = el('p', { class: 'stage' });
    this.times = el('dl', { class: 'times' });
    this.actions = el('div', { class: 'actions' });
    this.error = el('div', { role: 'alert' });
    this.result = el('div', { class: 'result' });
    this.root.replaceChildren(
      el('div', { class: 'job-head' },
        el('p', { class: 'job-id' }, 'Job ', el('code', {}, id), ' ', this.status),
        el('div', { class: 'progress-line' }, this.progress, this.percent),
        this.message, this.times, this.actions, this.error),
      this.result);
    this.watch(id, this.controller.signal);
  }

  close() {
    if (this.controller) this.controller.abort();
    this.controller = null;
    if (this.pictureUrl) URL.revokeObjectURL(this.pictureUrl);
    this.pictureUrl = null;
  }

  async watch(id, signal) {
    let wait = 0;
    let last = null;
    while (!signal.aborted) {
      try {
        const info = await getJSON(`/jobs/${encodeURIComponent(id)}?wait=${wait}`, { signal });
        if (signal.aborted) return;
        this.error.replaceChildren();
        this.showStatus(info, last);
        last = info.status;
        if (FINAL.has(info.status)) {
          this.controller = null;
          if (info.status === 'successful') await this.showResult(info, signal);
          return;
        }
        wait = POLL_WAIT;
      } catch (err) {
        if (err.name === 'AbortError' || signal.aborted) return;
        if (err.status === 404) {
          this.status.textContent = 'not found';
          this.progress.hidden = true;
        }
        this.error.replaceChildren(el('p', { class: 'error-summary' }, err.status === 404
          ? `There is no job ${id} that you may see: it was deleted, or it belongs to someone else.`
          : describe(err)));
        if (err.status && err.status !== 503) {
          this.controller = null;
          return;
        }
        await sleep(RETRY_DELAY, signal);
      }
    }
  }

  showStatus(info, previous) {
    this.status.textContent = info.status;
    this.status.className = `badge ${info.status}`;
    this.progress.value = info.progress || 0;
    this.percent.textContent = `${info.progress || 0} %`;
    this.message.textContent = info.message || '';
    this.times.replaceChildren(
      ...figure('submitted', fmtTime(info.created)),
      ...(info.started ? figure('started', fmtTime(info.started)) : []),
      ...(info.finished ? figure('finished', fmtTime(info.finished)) : []));
    const active = info.status === 'accepted' || info.status === 'running';
    this.actions.replaceChildren(el('button', {
      type: 'button', class: active ? 'danger' : '', onclick: () => this.dismiss(active),
    }, active ? 'Dismiss this job' : 'Delete this job and its results'));
    if (info.status !== previous && previous !== null) announce(`job ${info.status}`);
    if (info.status !== previous && this.onChanged) this.onChanged();
  }

  async dismiss(active) {
    if (!active && !window.confirm(`Delete job ${this.id} and its results?`)) return;
    try {
      const info = await (await request(`/jobs/${encodeURIComponent(this.id)}`, { method: 'DELETE' })).json();
      if (active) {
        this.showStatus(info, null);
        announce('job dismissed');
      } else {
        const id = this.id;
        this.close();
        this.id = null;
        this.root.replaceChildren(el('p', { role: 'status' }, `Job ${id} was deleted with its results.`));
        if (this.onChanged) this.onChanged();
      }
    } catch (err) {
      this.error.replaceChildren(el('p', { class: 'error-summary' }, describe(err)));
    }
  }

  async showResult(info, signal) {
    let stats;
    try {
      stats = await getJSON(`/jobs/${encodeURIComponent(this.id)}/statistics`, { signal });
    } catch (err) {
      if (err.name !== 'AbortError') this.error.replaceChildren(el('p', { class: 'error-summary' }, describe(err)));
      return;
    }
    if (signal.aborted) return;
    const picture = el('section', { class: 'panel picture-panel', 'aria-labelledby': 'pic-h' }, el('h2', { id: 'pic-h' }, 'Picture'));
    const numbers = el('section', { class: 'panel stats', 'aria-labelledby': 'stats-h' }, el('h2', { id: 'stats-h' }, 'Statistics'));
    const downloads = el('section', { class: 'panel downloads', 'aria-labelledby': 'dl-h' }, el('h2', { id: 'dl-h' }, 'Downloads'));
    this.result.replaceChildren(el('div', { class: 'look' }, picture, numbers), downloads);
    if (info.processID === 'pack3d') {
      this.fillSection(picture);
      this.fillStatistics(numbers, stats, true);
    } else {
      this.fillPicture(picture, stats);
      this.fillStatistics(numbers, stats, false);
    }
    this.fillDownloads(downloads, info);
  }

  fillPicture(section, stats) {
    const viewer = new Viewer(`picture of job ${this.id}: ${fmtInt(stats.count)} grains`);
    const balanced = Boolean(stats.balance);
    const choice = el('select', { id: 'colour-by' },
      el('option', { value: 'radius' }, 'grain radius r'),
      balanced ? el('option', { value: 'quality' }, 'balance criterion F') : null);
    if (balanced) choice.value = 'quality';
    const note = el('p', { class: 'note', role: 'status' });
    const draw = async () => {
      note.textContent = 'Drawing…';
      try {
        const blob = await getBlob(`/jobs/${encodeURIComponent(this.id)}/results?f=svg&color=${choice.value}`, 'image/svg+xml');
        if (this.pictureUrl) URL.revokeObjectURL(this.pictureUrl);
        this.pictureUrl = URL.createObjectURL(blob);
        viewer.show(this.pictureUrl);
        note.textContent = '';
      } catch (err) {
        note.textContent = describe(err);
      }
    };
    choice.addEventListener('change', draw);
    section.append(el('div', { class: 'field inline' }, el('label', { for: 'colour-by' }, 'Colour by'), choice), viewer.node, note);
    if (stats.count <= PICTURE_AUTO_MAX) {
      draw();
    } else {
      const button = el('button', { type: 'button', onclick: () => { button.remove(); draw(); } },
        `Draw the picture (${fmtInt(stats.count)} grains, about ${fmtInt(stats.count * 1e-4)} MB of SVG)`);
      note.replaceChildren(button);
    }
  }

  // A 3D job's picture: the section of the box by the plane of its spec ("picture":
  // {"section"}), one layer of grains (a small SVG whatever the job's size), drawn at once.
  fillSection(section) {
    const viewer = new Viewer(`section of job ${this.id}`);
    const note = el('p', { class: 'note', role: 'status' }, 'Drawing…');
    section.append(viewer.node, note);
    getBlob(`/jobs/${encodeURIComponent(this.id)}/results?f=svg`, 'image/svg+xml').then(async (blob) => {
      // the picture's own title names the plane: "... section z = 5 (x to the right, y up)"
      const title = /<title>[^<]*section ([^<]*)<\/title>/.exec(await blob.slice(0, 1024).text());
      if (this.pictureUrl) URL.revokeObjectURL(this.pictureUrl);
      this.pictureUrl = URL.createObjectURL(blob);
      viewer.show(this.pictureUrl);
      note.textContent = title ? `The box cut by the plane ${title[1]}.` : '';
    }).catch((err) => { note.textContent = describe(err); });
  }

  fillStatistics(section, s, three) {
    const dist = s.distribution || {};
    const radius = s.radius || {};
    section.append(el('dl', { class: 'figures' },
      ...figure('grains', fmtInt(s.count)),
      ...figure('packing density', fmtNum(s.packing_density, 4), three ? 'sum of 4/3 π R³ over the box volume' : 'sum of π R² over the domain area'),
      ...figure('grain fraction', fmtNum(s.grain_fraction, 4), three ? 'sum of 4/3 π r³ over the box volume' : 'sum of π r² over the domain area'),
      ...figure('radius r: min / mean / max', `${fmtNum(radius.min)} / ${fmtNum(radius.mean)} / ${fmtNum(radius.max)}`),
      ...figure('χ² (degrees of freedom)', `${fmtNum(dist.chi2, 4)} (${dist.dof})`, 'Pearson’s statistic of the achieved against the target bins'),
      ...figure('p-value', fmtNum(dist.p_value, 3)),
      ...figure('largest |z|', fmtNum(dist.max_abs_z, 3), 'the largest deviation of a bin, in standard errors'),
      ...figure('seed', String(s.seed)),
      ...figure('time', `${fmtNum(s.total_seconds, 3)} s`, (s.timings || []).map((t) => `${t.stage} ${fmtNum(t.seconds, 3)} s`).join(', '))));
    if (Array.isArray(dist.bins) && dist.bins.length) {
      section.append(el('figure', { class: 'plot' },
        binsChart({ bins: dist.bins, achieved: true, title: 'Target and achieved radius distribution' }),
        el('figcaption', {}, 'Target law (outline) and the packing’s frequencies with ± 2 standard errors (about 95 % if the law holds)')),
      dataTable('The bins as a table', ['min', 'max', 'target', 'achieved', 'standard error', 'z'],
        dist.bins.map((b) => [fmtNum(b.min), fmtNum(b.max), fmtNum(b.target), fmtNum(b.achieved), fmtNum(b.se, 3), fmtNum(b.z, 3)])));
    }
    if (s.balance) this.fillBalance(section, s.balance);
    if (s.cells && three) this.fillPolyhedra(section, s.cells);
    else if (s.cells) this.fillCells(section, s.cells);
  }

  fillBalance(section, b) {
    const { before, after } = b;
    const fRange = (q) => (q ? `${fmtNum(q.max, 4)} / ${fmtNum(q.mean, 4)}` : 'not kept');
    section.append(el('h3', {}, 'Balance of the gaps (criterion F)'), el('dl', { class: 'figures' },
      ...figure('method', b.method),
      ...figure('F max / mean before', fRange(before), before ? '' : 'the service keeps F before balancing only while the job runs'),
      ...figure('F max / mean after', fRange(after)),
      ...(b.sweeps !== undefined ? figure('sweeps', `${b.sweeps} (${b.stop})`) : []),
      ...figure('interior grains measured', fmtInt(after && after.interior))));
    const series = [];
    if (before) series.push({ lo: before.min, hi: before.max, counts: before.histogram, label: 'before', cls: 'before' });
    if (after) series.push({ lo: after.min, hi: after.max, counts: after.histogram, label: 'after', cls: 'after' });
    if (series.length) {
      section.append(el('figure', { class: 'plot' },
        countsChart({ series, title: 'Distribution of F', xLabel: 'F = (max gap − min gap) / R' }),
        el('figcaption', {}, 'F over the interior grains: the lower and narrower, the more even the gaps')));
    }
  }

  fillCells(section, c) {
    const area = c.area || {};
    const req = c.equivalent_radius || {};
    section.append(el('h3', {}, 'Laguerre cells'), el('dl', { class: 'figures' },
      ...figure('cells', fmtInt(c.count)),
      ...figure('shrink', c.shrink + (c.flush_boundary ? ', flush with the walls' : '')),
      ...figure('grain-boundary band', fmtPercent(c.band_fraction, 2), 'share of the domain between the cells'),
      ...figure('cell area: min / mean / max', `${fmtNum(area.min)} / ${fmtNum(area.mean)} / ${fmtNum(area.max)}`),
      ...figure('neighbours per cell (mean)', fmtNum(c.neighbours && c.neighbours.mean, 3)),
      ...figure('equivalent radius / r (mean)', fmtNum(req.mean_ratio, 4), 'sqrt(area / π) of a cell over its grain’s radius')));
    const nb = (c.neighbours && c.neighbours.histogram) || [];
    if (nb.length) {
      section.append(el('figure', { class: 'plot' },
        countsChart({ series: [{ lo: -0.5, hi: nb.length - 0.5, counts: nb, label: 'cells', cls: 'after' }], title: 'Neighbours per cell', xLabel: 'neighbours' }),
        el('figcaption', {}, 'How many cells have k neighbours')));
    }
    if (Array.isArray(req.bins) && req.bins.length) {
      section.append(el('figure', { class: 'plot' },
        binsChart({ bins: req.bins, achieved: true, title: 'Equivalent radii of the cells against the law', xLabel: 'equivalent radius sqrt(area / π)' }),
        el('figcaption', {}, `The cells’ equivalent radii in the law’s bins (${fmtInt(req.outside)} outside every bin)`)));
    }
  }

  // A 3D job's Laguerre polyhedra: volumes, faces, the boundary phase, equivalent radii.
  fillPolyhedra(section, c) {
    const volume = c.volume || {};
    const faces = c.faces_per_cell || {};
    const req = c.equivalent_radius || {};
    section.append(el('h3', {}, 'Laguerre polyhedra'), el('dl', { class: 'figures' },
      ...figure('polyhedra', fmtInt(c.count)),
      ...figure('shrink', c.shrink),
      ...figure('grain-boundary phase', fmtPercent(c.boundary_fraction, 2), 'share of the box between the polyhedra'),
      ...figure('cell volume: min / mean / max', `${fmtNum(volume.min)} / ${fmtNum(volume.mean)} / ${fmtNum(volume.max)}`),
      ...figure('faces per cell (mean)', fmtNum(faces.mean, 3)),
      ...figure('neighbours per cell (mean)', fmtNum(c.neighbours_mean, 3), 'faces shared with another cell; the others lie on the walls'),
      ...figure('equivalent radius / r (mean)', fmtNum(req.mean_ratio, 4), 'the radius of the sphere of the cell’s volume over its grain’s radius')));
    const hist = faces.histogram || [];
    if (hist.length) {
      section.append(el('figure', { class: 'plot' },
        countsChart({ series: [{ lo: -0.5, hi: hist.length - 0.5, counts: hist, label: 'cells', cls: 'after' }], title: 'Faces per cell', xLabel: 'faces' }),
        el('figcaption', {}, 'How many cells have k faces')));
    }
    if (Array.isArray(volume.histogram) && volume.histogram.length && volume.max > volume.min) {
      section.append(el('figure', { class: 'plot' },
        countsChart({ series: [{ lo: volume.min, hi: volume.max, counts: volume.histogram, label: 'cells', cls: 'after' }], title: 'Cell volumes', xLabel: 'volume of the shrunk cell' }),
        el('figcaption', {}, 'How many cells have each volume')));
    }
    if (Array.isArray(req.bins) && req.bins.length) {
      section.append(el('figure', { class: 'plot' },
        binsChart({ bins: req.bins, achieved: true, title: 'Equivalent radii of the cells against the law', xLabel: 'equivalent radius (3 V / 4 π)^(1/3)' }),
        el('figcaption', {}, `The cells’ equivalent radii in the law’s bins${req.outside !== undefined ? ` (${fmtInt(req.outside)} outside every bin)` : ''}`)));
    }
  }

  fillDownloads(section, info) {
    const links = (info.links || []).filter((l) => l.rel === RESULTS_REL || l.rel === 'statistics');
    const list = el('ul', { class: 'download-list' });
    for (const link of links) {
      const format = link.rel === 'statistics' ? 'statistics' : new URL(link.href, location.href).searchParams.get('f') || 'json';
      const name = link.rel === 'statistics' ? `job-${this.id}-statistics.json` : `job-${this.id}.${format}`;
      const a = el('a', { href: link.href, download: name, type: link.type }, format.toUpperCase());
      // with a key, a plain link would go without it: fetched here, saved from a blob
      a.addEventListener('click', (e) => {
        if (!getKey()) return;
        e.preventDefault();
        this.saveWithKey(link.href, name, link.type);
      });
      list.append(el('li', {}, a, el('span', { class: 'type' }, ` ${link.type}`)));
    }
    section.append(list);
  }

  async saveWithKey(href, name, type) {
    try {
      const blob = await getBlob(href, type);
      const url = URL.createObjectURL(blob);
      const a = el('a', { href: url, download: name, hidden: true });
      document.body.append(a);
      a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(url), 60000);
    } catch (err) {
      this.error.replaceChildren(el('p', { class: 'error-summary' }, describe(err)));
    }
  }
}
