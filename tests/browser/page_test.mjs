// page_test.mjs - grainpackd's web page in a real browser: Debian's chromium, headless,
// driven by playwright-core (no browser download). Run by tests/service/test_web_browser.py,
// which starts the daemons and checks what this script leaves behind (downloads, the
// database). Scenarios of issue 14: design the iron histogram by pasting its bins, see the
// expected disks, an invalid bin's error next to its field, submit, progress to success,
// the picture and the achieved histogram, zoom from the keyboard, download the CSV;
// dismiss a long job; My jobs; the keyboard alone; a 3D job (issue 17) with its
// section, polyhedra and .tess; a narrow window; axe-core finds no
// serious or critical violation; with API keys, one user's page does not list another's
// jobs. No console error anywhere; every refused request is one the scenario expects.
// Usage: node page_test.mjs CONFIG.json (see test_web_browser.py for its fields)

import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { chromium } from 'playwright-core';

const require = createRequire(import.meta.url);
const config = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
const AXE_SOURCE = fs.readFileSync(require.resolve('axe-core/axe.min.js'), 'utf8');
// The flags a closed network needs: without them chromium waits on services it cannot reach.
const CHROMIUM_FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync'];
// The page's aim (issue 14): under 200 KB transferred before any result is fetched.
const PAGE_BUDGET = 200 * 1024;
// How long a step may take before the scenario fails (ms): a bound on a broken run.
const STEP = 30000;
// The same for a job to run, or a picture to be drawn: much longer under AddressSanitizer
// on a loaded machine (the iron job that balances and builds cells took over 30 s there).
const JOB = 300000;
const DESKTOP = { width: 1280, height: 800 };
const NARROW = { width: 390, height: 844 };

const failures = [];
const metrics = {};
function check(cond, what) {
  if (!cond) {
    failures.push(what);
    console.error(`FAIL ${what}`);
  }
  return Boolean(cond);
}

// Tab-separated, as a spreadsheet copies cells: the iron histogram of the report.
const IRON_TSV = JSON.parse(fs.readFileSync(path.join(config.examples, 'iron.json'), 'utf8'))
  .inputs.distribution.bins.map((b) => `${b.min}\t${b.max}\t${b.p}`).join('\n');

// Watches a page: console errors and uncaught exceptions fail the run; a refused request
// (4xx, 5xx) must be one that `expected` allows ([method, path pattern, status]).
function watch(page, name, expected = []) {
  page.on('pageerror', (err) => check(false, `${name}: uncaught ${err.message}`));
  page.on('console', (msg) => {
    // Chromium also logs refused requests as console errors: those are judged below
    if (msg.type() === 'error' && !/^Failed to load resource: the server responded with a status of \d+/.test(msg.text())) {
      check(false, `${name}: console error: ${msg.text()}`);
    }
  });
  page.on('response', (response) => {
    if (response.status() < 400) return;
    const url = new URL(response.url());
    const method = response.request().method();
    const ok = expected.some(([m, re, status]) => m === method && re.test(url.pathname) && status === response.status());
    check(ok, `${name}: unexpected ${response.status()} for ${method} ${url.pathname}${url.search}`);
  });
}

async function launch(dir) {
  return chromium.launchPersistentContext(dir, {
    executablePath: config.chromium, headless: true, args: CHROMIUM_FLAGS, viewport: DESKTOP,
    acceptDownloads: true, locale: 'en-GB', timezoneId: 'UTC',
  });
}

async function shot(page, name, fullPage = true) {
  await page.screenshot({ path: path.join(config.out, `${name}.png`), fullPage, animations: 'disabled' });
}

// axe-core on the page as it is: no serious or critical violation.
async function axe(page, what) {
  await page.evaluate(AXE_SOURCE);
  const result = await page.evaluate(() => window.axe.run(document, { resultTypes: ['violations'] }));
  const bad = result.violations.filter((v) => v.impact === 'serious' || v.impact === 'critical');
  for (const v of result.violations) {
    console.log(`axe ${what}: ${v.impact} ${v.id} (${v.nodes.length}): ${v.help}`);
  }
  check(bad.length === 0, `axe ${what}: ${bad.map((v) => `${v.id}: ${v.nodes.map((n) => n.target.join(' ')).join(', ')}`).join('; ')}`);
  metrics[`axe_${what}`] = { violations: result.violations.length, serious_or_critical: bad.length };
}

// The page's first paint and what it transferred (Performance API), before any result.
async function measureLoad(page) {
  const m = await page.evaluate(() => {
    const paint = Object.fromEntries(performance.getEntriesByType('paint').map((e) => [e.name, e.startTime]));
    const nav = performance.getEntriesByType('navigation')[0];
    const resources = performance.getEntriesByType('resource');
    const sum = (key) => resources.reduce((s, r) => s + r[key], nav[key]);
    return {
      first_paint_ms: paint['first-paint'], first_contentful_paint_ms: paint['first-contentful-paint'],
      dom_content_loaded_ms: nav.domContentLoadedEventEnd, load_ms: nav.loadEventEnd,
      requests: resources.length + 1, transfer_bytes: sum('transferSize'), body_bytes: sum('encodedBodySize'),
      resources: resources.map((r) => new URL(r.name).pathname),
    };
  });
  Object.assign(metrics, { load: m });
  console.log(`load: first paint ${m.first_paint_ms?.toFixed(0)} ms, first contentful paint ${m.first_contentful_paint_ms?.toFixed(0)} ms, `
    + `${m.requests} requests, ${m.transfer_bytes} bytes transferred (${m.body_bytes} of bodies)`);
  check(m.first_contentful_paint_ms > 0, 'no first contentful paint measured');
  check(m.transfer_bytes > 0 && m.transfer_bytes < PAGE_BUDGET, `the page transferred ${m.transfer_bytes} bytes before any result`);
  check(!m.resources.some((r) => r.includes('/results')), 'a result was fetched on load');
}

const expectedDisks = async (base, inputs) => {
  const r = await fetch(`${base}/processes/pack2d/validation`, {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ inputs }),
  });
  return (await r.json()).expected_disks;
};

// Waits for the expected-disks line to show a number (`n` when given: the page has caught
// up with the last edit), and returns it.
async function shownDisks(page, n) {
  const line = page.locator('.expected strong');
  await line.waitFor({ timeout: STEP });
  if (n !== undefined) {
    await page.waitForFunction((want) => document.querySelector('.expected strong')?.textContent
      .replace(/[^\d]/g, '') === String(want), n, { timeout: STEP }).catch(() => {});
  }
  return Number((await line.textContent()).replace(/[^\d]/g, ''));
}

// Loads the page anew (a hash alone would keep the document and its form).
async function fresh(page, base, hash) {
  await page.goto(`${base}/${hash}`);
  await page.reload();
  await page.locator('body.ready').waitFor({ timeout: STEP });
}

async function designIron(page) {
  await page.getByLabel('Width').fill('237');
  await page.getByLabel('Height').fill('300');
  await page.getByLabel('Kind', { exact: true }).selectOption('histogram');
  // a real paste: the bins on the clipboard, Ctrl+V in the paste area
  const area = page.getByLabel(/Paste from a spreadsheet/);
  await area.focus();
  await page.evaluate((text) => navigator.clipboard.writeText(text), IRON_TSV);
  await page.keyboard.press('Control+V');
  await page.locator('.histogram p.note', { hasText: '12 bins read' }).waitFor({ timeout: STEP });
  check(await page.locator('table.bins tbody tr').count() === 12, 'the pasted histogram does not have 12 rows');
  check((await page.locator('.sum').textContent()) === '1', `sum of p after the paste: ${await page.locator('.sum').textContent()}`);
  check(await page.locator('figure.plot svg.chart rect.target:not(.legend)').count() === 12, 'the target histogram is not drawn with 12 bars');
  await page.getByLabel('Law', { exact: true }).selectOption('inverse');
  await page.locator('[data-pointer="/inputs/joint/k"] input:visible').fill('2');
  // the stages: each a switch and its options, made from the process description
  await page.getByLabel('Balancing').check();
  await page.locator('select[name=method]').selectOption('relocation');
  await page.getByLabel('Laguerre cells').check();
  await page.locator('select[name=shrink]').selectOption('offset');
}

async function invalidBin(page) {
  const max = page.locator('[data-pointer="/inputs/distribution/bins/3/max"]');
  await max.locator('input').fill('1');
  const error = max.locator('.error');
  await error.waitFor({ timeout: STEP });
  const text = await error.textContent();
  check(/must be > 3\.5/.test(text), `the bad bin's error says ${text}`);
  check(await max.locator('input').getAttribute('aria-invalid') === 'true', 'the bad bin is not marked invalid');
  const describedBy = await max.locator('input').getAttribute('aria-describedby');
  check(describedBy && describedBy.includes(await error.getAttribute('id')), 'the error is not the field\'s description');
  check(await page.locator('.expected').textContent() === 'No estimate until the design is valid.', 'an estimate for an invalid design');
  await shot(page, 'design-invalid-bin', false);
  // submitting anyway: the 422 lands on the same field, which takes the focus
  await page.getByRole('button', { name: 'Submit the job' }).click();
  await page.waitForFunction(() => document.activeElement && document.activeElement.closest('[data-pointer="/inputs/distribution/bins/3/max"]'), null, { timeout: STEP });
  check(new URL(page.url()).hash === '' || new URL(page.url()).hash === '#design', 'an invalid job was submitted');
  await max.locator('input').fill('4');
  await error.waitFor({ state: 'detached', timeout: STEP });
}

async function result(page, base) {
  await page.waitForURL(/#job\//, { timeout: STEP });
  const id = decodeURIComponent(new URL(page.url()).hash.slice('#job/'.length));
  await page.locator('#view-job .badge.successful').waitFor({ timeout: JOB });
  check(await page.locator('progress').getAttribute('value') === '100', 'progress is not 100 at the end');
  await page.waitForFunction(() => {
    const img = document.querySelector('.viewer img');
    return img && img.complete && img.naturalWidth > 0;
  }, null, { timeout: JOB });
  const achieved = page.locator('.stats svg.chart').first();
  check(await achieved.locator('rect.achieved:not(.legend)').count() === 12, 'the achieved histogram has not 12 bars');
  check(await achieved.locator('path.errorbar').count() >= 10, 'the achieved histogram has no error bars');
  const figures = await page.locator('.stats dl.figures').first().textContent();
  const stats = await (await fetch(`${base}/jobs/${id}/statistics`)).json();
  check(figures.replace(/,/g, '').includes(`grains${stats.count}`), `figures: ${figures}`);
  // F after balancing and the cells, beside the picture coloured by F
  check(await page.locator('.stats svg.chart rect.after:not(.legend)').count() >= 10, 'no histogram of F and neighbours');
  check((await page.locator('.stats').textContent()).includes('grain-boundary band'), 'no cell statistics');
  check(await page.getByLabel('Colour by').inputValue() === 'quality', 'a balanced job is not coloured by F first');
  await shot(page, 'result-screen', false);
  const byF = await page.locator('.viewer img').getAttribute('src');
  await page.getByLabel('Colour by').selectOption('radius');
  await page.waitForFunction((before) => {
    const img = document.querySelector('.viewer img');
    return img.src !== before && img.complete && img.naturalWidth > 0;
  }, byF, { timeout: JOB });
  await shot(page, 'result');
  // the picture from the keyboard: + zooms, 0 shows it whole
  const viewer = page.locator('.viewer');
  await viewer.focus();
  await page.keyboard.press('+');
  check((await page.locator('.zoom').textContent()) === '125 %', 'the + key does not zoom');
  check((await page.locator('.viewer img').evaluate((img) => img.style.transform)).includes('scale(1.25)'), 'no zoom transform');
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('0');
  check((await page.locator('.zoom').textContent()) === '100 %', 'the 0 key does not reset the zoom');
  // the wheel zooms around the pointer
  const box = await viewer.boundingBox();
  await page.mouse.move(box.x + box.width / 3, box.y + box.height / 3);
  await page.mouse.wheel(0, -200);
  check((await page.locator('.zoom').textContent()) !== '100 %', 'the wheel does not zoom');
  // every format offered, the CSV downloaded
  const formats = await page.locator('.download-list a').allTextContents();
  check(['JSON', 'CSV', 'SVG', 'VTK'].every((f) => formats.includes(f)), `downloads offered: ${formats}`);
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: STEP }),
    page.getByRole('link', { name: 'CSV', exact: true }).click()]);
  const csv = path.join(config.out, 'iron.csv');
  await download.saveAs(csv);
  check(download.suggestedFilename() === `job-${id}.csv`, `the CSV is saved as ${download.suggestedFilename()}`);
  return { id, csv, expected: await expectedDisks(base, JSON.parse(fs.readFileSync(path.join(config.examples, 'iron.json'))).inputs) };
}

async function longJob(page) {
  await fresh(page, config.open, '#design');
  await page.getByLabel('Width').fill(String(config.long_side));
  await page.getByLabel('Height').fill(String(config.long_side));
  await page.getByLabel('Radius', { exact: true }).fill('0.5');
  await page.getByLabel('Balancing').check();
  await page.locator('select[name=method]').selectOption('relocation');
  await shownDisks(page);
  await page.getByRole('button', { name: 'Submit the job' }).click();
  await page.waitForURL(/#job\//, { timeout: STEP });
  const id = decodeURIComponent(new URL(page.url()).hash.slice('#job/'.length));
  await page.locator('#view-job .badge.running').waitFor({ timeout: JOB });
  await page.waitForFunction(() => Number(document.querySelector('progress').value) > 0, null, { timeout: JOB });
  const stage = await page.locator('.stage').textContent();
  check(/^running: \w+ \d+%$/.test(stage), `the running job's stage line: ${stage}`);
  await shot(page, 'running', false);
  await page.getByRole('button', { name: 'Dismiss this job' }).click();
  await page.locator('#view-job .badge.dismissed').waitFor({ timeout: JOB });
  return id;
}

async function myJobs(page, ids) {
  await page.goto(`${config.open}/#jobs`);
  await page.locator('body.ready').waitFor({ timeout: STEP });
  await page.locator('table.jobs tbody tr').first().waitFor({ timeout: STEP });
  const listed = await page.locator('table.jobs tbody code').allTextContents();
  check(ids.every((id) => listed.includes(id)), `My jobs lists ${listed}, not all of ${ids}`);
  await shot(page, 'jobs', false);
  await page.getByLabel('Status', { exact: true }).selectOption('dismissed');
  await page.waitForFunction((id) => [...document.querySelectorAll('table.jobs tbody code')].map((c) => c.textContent).join() === id,
    ids[1], { timeout: STEP });
  page.once('dialog', (dialog) => dialog.accept());
  await page.getByRole('button', { name: `Delete job ${ids[1]}` }).click();
  await page.getByText(`Job ${ids[1]} deleted.`).waitFor({ timeout: STEP });
  check(await page.locator('table.jobs tbody tr').count() === 0, 'the deleted job is still listed');
}

// Only the keyboard: every control reached with Tab shows its focus, and Enter on the
// submit button submits.
async function keyboard(page) {
  await fresh(page, config.open, '#design');
  await shownDisks(page);
  const seen = [];
  for (let i = 0; i < 120; i++) {
    await page.keyboard.press('Tab');
    const f = await page.evaluate(() => {
      const e = document.activeElement;
      const style = getComputedStyle(e);
      return { tag: e.tagName, name: e.getAttribute('aria-label') || (e.labels && e.labels[0] && e.labels[0].textContent) || e.textContent.trim(),
        outline: style.outlineStyle !== 'none' && parseFloat(style.outlineWidth) >= 2 };
    });
    seen.push(f);
    if (f.tag === 'BUTTON' && f.name === 'Submit the job') break;
  }
  const last = seen[seen.length - 1];
  check(last.name === 'Submit the job', `Tab never reached the submit button (${seen.length} stops)`);
  check(seen.every((f) => f.outline), `focus not visible on ${seen.filter((f) => !f.outline).map((f) => f.name).join(', ')}`);
  check(seen.some((f) => f.name === 'Add a bin' || f.name === 'Kind'), 'Tab skipped the law');
  metrics.tab_stops_to_submit = seen.length;
  await page.keyboard.press('Enter');
  await page.waitForURL(/#job\//, { timeout: STEP });
  await page.locator('#view-job .badge.successful').waitFor({ timeout: JOB });
}

const expectedSpheres = async (base, inputs) => {
  const r = await fetch(`${base}/processes/pack3d/validation`, {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ inputs }),
  });
  return (await r.json()).expected_spheres;
};

// A 3D job from the page: the process chosen among the service's, its own form (a depth,
// polyhedra), the estimate in spheres, the submission; the section drawn, the polyhedra's
// statistics, the .tess and VTU offered and the .tess downloaded; back in 2D the design
// typed before is still there.
async function threeD(page) {
  await fresh(page, config.open, '#design');
  await shownDisks(page);
  await page.getByLabel('Width').fill('123');
  await page.getByLabel('Pack a box with spheres (advancing front)').check();
  await page.getByLabel('Depth').waitFor({ timeout: STEP });
  check(await page.getByLabel('Width').inputValue() === '10', '3D does not start from its own box');
  const box = { width: 6, height: 5, depth: 4 };
  for (const [name, v] of Object.entries(box)) await page.getByLabel(name[0].toUpperCase() + name.slice(1)).fill(String(v));
  await page.getByLabel('Laguerre polyhedra').check();
  await page.locator('select[name=shrink]').selectOption('offset');
  const inputs = { domain: box, distribution: { kind: 'constant', radius: 0.5 }, joint: { law: 'constant', value: 0.05 }, seed: 1, laguerre: { shrink: 'offset' } };
  const want = await expectedSpheres(config.open, inputs);
  const shown = await shownDisks(page, want);
  check(shown === want, `the page shows ${shown} expected spheres, the service says ${want}`);
  check((await page.locator('.expected strong').textContent()).includes('spheres expected'), 'the 3D estimate is not in spheres');
  await shot(page, 'design-3d', false);
  await page.getByRole('button', { name: 'Submit the job' }).click();
  await page.waitForURL(/#job\//, { timeout: STEP });
  const id = decodeURIComponent(new URL(page.url()).hash.slice('#job/'.length));
  await page.locator('#view-job .badge.successful').waitFor({ timeout: JOB });
  await page.waitForFunction(() => {
    const img = document.querySelector('.viewer img');
    return img && img.complete && img.naturalWidth > 0;
  }, null, { timeout: JOB });
  await page.locator('.picture-panel .note', { hasText: 'The box cut by the plane z = ' }).waitFor({ timeout: STEP });
  const stats = await (await fetch(`${config.open}/jobs/${id}/statistics`)).json();
  const text = (await page.locator('.stats').textContent()).replace(/,/g, '');
  check(text.includes(`grains${stats.count}`) && text.includes(`polyhedra${stats.cells.count}`), `3D figures: ${text.slice(0, 300)}`);
  check(text.includes('grain-boundary phase') && text.includes('faces per cell'), 'no polyhedra statistics');
  check(await page.locator('.stats svg.chart').count() >= 3, 'the 3D statistics draw fewer than 3 charts');
  check(await page.getByLabel('Colour by').count() === 0, 'a 3D section offers a colouring it does not have');
  const formats = await page.locator('.download-list a').allTextContents();
  check(['JSON', 'CSV', 'SVG', 'VTU', 'TESS'].every((f) => formats.includes(f)), `3D downloads offered: ${formats}`);
  await shot(page, 'result-3d');
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: STEP }),
    page.getByRole('link', { name: 'TESS', exact: true }).click()]);
  const tess = path.join(config.out, 'box.tess');
  await download.saveAs(tess);
  check(download.suggestedFilename() === `job-${id}.tess`, `the .tess is saved as ${download.suggestedFilename()}`);
  // back to the design: 3D is still chosen; 2D holds what was typed in it
  await page.goto(`${config.open}/#design`);
  check(await page.getByLabel('Depth').inputValue() === '4', 'the 3D design was lost on the way back');
  await page.getByLabel('Pack a rectangle with disks (advancing front)').check();
  await page.getByLabel('Depth').waitFor({ state: 'detached', timeout: STEP });
  check(await page.getByLabel('Width').inputValue() === '123', 'the 2D design was lost across the switch');
  await axe(page, 'design-3d-back');
  return { id, tess };
}

async function narrow(page) {
  await page.setViewportSize(NARROW);
  for (const hash of ['#design', '#jobs']) {
    await page.goto(`${config.open}/${hash}`);
    await page.locator('body.ready').waitFor({ timeout: STEP });
    if (hash === '#design') await shownDisks(page);
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    check(overflow <= 0, `${hash} is ${overflow} px wider than a narrow window`);
    await shot(page, `narrow-${hash.slice(1)}`);
  }
}

async function openService(dir) {
  const context = await launch(dir);
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: config.open });
  const page = context.pages()[0] || await context.newPage();
  watch(page, 'open service', [
    ['POST', /^\/processes\/pack2d\/(validation|execution)$/, 422],
  ]);
  await page.goto(`${config.open}/`);
  await page.locator('body.ready').waitFor({ timeout: STEP });
  await shownDisks(page);
  await measureLoad(page);
  check(await page.locator('#key-form').isHidden(), 'an open service asks for a key');
  await axe(page, 'design');
  await designIron(page);
  const ironInputs = JSON.parse(fs.readFileSync(path.join(config.examples, 'iron.json'))).inputs;
  const disks = await shownDisks(page, await expectedDisks(config.open, ironInputs));
  await shot(page, 'design');
  await page.locator('.summary').scrollIntoViewIfNeeded();
  await shot(page, 'design-screen', false);
  await invalidBin(page);
  await page.getByRole('button', { name: 'Submit the job' }).click();
  const iron = await result(page, config.open);
  check(disks === iron.expected, `the page shows ${disks} expected disks, the service says ${iron.expected}`);
  await axe(page, 'result');
  const long = await longJob(page);
  await myJobs(page, [iron.id, long]);
  await axe(page, 'jobs');
  await keyboard(page);
  const box = await threeD(page);
  await narrow(page);
  await context.close();
  return { iron: iron.id, csv: iron.csv, long, box: box.id, tess: box.tess };
}

// With API keys: alice's jobs are hers; bob's page does not list them or open them.
async function keysService(dirA, dirB) {
  const alice = await launch(dirA);
  const pageA = alice.pages()[0] || await alice.newPage();
  watch(pageA, 'alice', [['GET', /^\/jobs$/, 401], ['POST', /^\/processes\/pack2d\/validation$/, 401]]);
  await pageA.goto(`${config.keys}/#jobs`);
  await pageA.locator('body.ready').waitFor({ timeout: STEP });
  // The jobs view says so (the design view, hidden, says it too once its validation is
  // refused: which of the two comes first in the document depends on which answer came first).
  await pageA.locator('#view-jobs').getByText('This service needs an API key').waitFor({ timeout: STEP });
  await pageA.getByLabel('API key').fill(config.alice);
  await pageA.getByRole('button', { name: 'Use this key' }).click();
  await pageA.getByText('No jobs here yet.').waitFor({ timeout: STEP });
  await pageA.goto(`${config.keys}/#design`);
  await shownDisks(pageA);
  await pageA.getByRole('button', { name: 'Submit the job' }).click();
  await pageA.waitForURL(/#job\//, { timeout: STEP });
  const id = decodeURIComponent(new URL(pageA.url()).hash.slice('#job/'.length));
  await pageA.locator('#view-job .badge.successful').waitFor({ timeout: JOB });
  await pageA.waitForFunction(() => document.querySelector('.viewer img')?.naturalWidth > 0, null, { timeout: JOB });
  const [download] = await Promise.all([pageA.waitForEvent('download', { timeout: STEP }),
    pageA.getByRole('link', { name: 'CSV', exact: true }).click()]);
  const csv = path.join(config.out, 'alice.csv');
  await download.saveAs(csv);
  check(!pageA.url().includes(config.alice), 'the key is in the address');
  check(await pageA.evaluate(() => localStorage.length) === 0, 'something was kept in localStorage');
  await pageA.goto(`${config.keys}/#jobs`);
  await pageA.locator('table.jobs tbody code').first().waitFor({ timeout: STEP });
  check((await pageA.locator('table.jobs tbody code').allTextContents()).includes(id), 'alice does not see her job');
  await shot(pageA, 'keys-alice', false);
  await alice.close();

  const bob = await launch(dirB);
  const pageB = bob.pages()[0] || await bob.newPage();
  watch(pageB, 'bob', [['GET', /^\/jobs$/, 401], ['POST', /^\/processes\/pack2d\/validation$/, 401],
    ['GET', /^\/jobs\/[^/]+$/, 404]]);
  await pageB.goto(`${config.keys}/#jobs`);
  await pageB.locator('body.ready').waitFor({ timeout: STEP });
  check(await pageB.evaluate(() => sessionStorage.length) === 0, 'bob\'s tab starts with a key');
  await pageB.getByLabel('API key').fill(config.bob);
  await pageB.getByRole('button', { name: 'Use this key' }).click();
  await pageB.getByText('No jobs here yet.').waitFor({ timeout: STEP });
  check(!(await pageB.locator('#view-jobs').textContent()).includes(id), 'bob\'s page lists alice\'s job');
  await pageB.goto(`${config.keys}/#job/${id}`);
  await pageB.getByText(`There is no job ${id} that you may see`).waitFor({ timeout: STEP });
  await shot(pageB, 'keys-bob', false);
  await bob.close();
  return { id, csv };
}

async function main() {
  fs.mkdirSync(config.out, { recursive: true });
  for (const old of fs.readdirSync(config.out)) {
    if (old.startsWith('profiles-')) fs.rmSync(path.join(config.out, old), { recursive: true, force: true });
  }
  const profiles = fs.mkdtempSync(path.join(config.out, 'profiles-'));
  const dir = (name) => fs.mkdtempSync(path.join(profiles, `${name}-`));
  const out = {};
  try {
    Object.assign(out, { open: await openService(dir('open')) });
    Object.assign(out, { keys: await keysService(dir('alice'), dir('bob')) });
  } catch (err) {
    check(false, `scenario stopped: ${err.stack || err}`);
  } finally {
    fs.rmSync(profiles, { recursive: true, force: true });
  }
  out.metrics = metrics;
  out.failures = failures;
  fs.writeFileSync(path.join(config.out, 'outcome.json'), JSON.stringify(out, null, 1));
  process.exit(failures.length ? 1 : 0);
}

main();
