// The page in Debian's headless chromium: run B2, compare the shown σ_est
// with granbed-cli's, download the CSV (the CLI's bytes, named by the inputs
// that ran), cancel a run (the inputs locked while it goes; the CSV so far
// a prefix of the CLI's), provoke bad inputs (ν = 0.6, a decimal comma, two
// at once, out of range or unreadable, 1e400, a unit), show a failed and
// a not quasi-static run as such, mark results stale when the inputs
// change, lay the page out at a phone's width, and open it as a file.
// Screenshots go to out/.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { serve } from './server.js';
import { OUT, WWW, native } from './common.js';
import { formatStress, formatSlope } from '../www/format.js';

const CHROMIUM = process.env.GRANBED_CHROMIUM ?? '/usr/bin/chromium';
let server, browser, page;
const problems = [];

before(async () => {
  mkdirSync(OUT, { recursive: true });
  server = await serve(WWW);
  browser = await chromium.launch({
    executablePath: CHROMIUM,
    args: ['--headless', '--no-sandbox', '--disable-gpu'],
  });
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1000, height: 1100 } });
  page = await context.newPage();
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('console', (m) => m.type() === 'error' && problems.push(`console error: ${m.text()}`));
  await page.goto(server.url);
  await page.waitForSelector('#run:not([disabled])', { timeout: 60_000 });
});

after(async () => {
  await browser?.close();
  await server?.close();
});

test('B2: the shown sigma_est is the native one; the CSV is the CLI\'s', async () => {
  const ref = native('GRANBED_NATIVE_B2');
  await page.selectOption('#type', 'B2');
  await page.selectOption('#mesh', '8x2');
  assert.equal(await page.inputValue('#poisson_ratio'), '0.3');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="done"]', { timeout: 300_000 });

  const shown = await page.textContent('#sigma-est');
  const value = Number(await page.getAttribute('#sigma-est', 'data-value'));
  assert.equal(shown, formatStress(ref.summary.sigma_est_pa));
  assert.equal(value, ref.summary.sigma_est_pa);
  assert.equal(await page.textContent('#sigma-eff0'), formatStress(ref.summary.sigma_eff0_pa));
  // The result in the status line too (the table may be below the fold),
  // and the version the page runs.
  assert.match(await page.textContent('#status'), new RegExp(`^done: strain 40\\.0 % in .* s; σ_est = ${shown}$`));
  assert.match(await page.textContent('#version'), /^granbed \d+\.\d+\.\d+/);
  assert.equal(await page.textContent('#slope'), formatSlope(ref.summary.slope_n_per_m));
  // The quasi-static row is the CLI summary's certificate (same masses).
  assert.equal(ref.summary.mass_scaling, 1);
  assert.equal(await page.getAttribute('#quasi-static', 'data-value'), String(ref.summary.quasi_static.passed));
  const percent = +(100 * ref.summary.quasi_static.max_kinetic_to_internal).toPrecision(2);
  assert.equal(
    await page.textContent('#quasi-static'),
    `yes: kinetic energy at most ${percent} % of the internal work (limit 1 %)`,
  );
  assert.equal(
    Number(await page.getAttribute('#ratio', 'data-value')),
    ref.summary.sigma_est_pa / ref.summary.sigma_eff0_pa,
  );
  const wall = Number(await page.getAttribute('#wall', 'data-value'));
  console.log(
    `browser B2 8x2: sigma_est shown "${shown}" (${value} Pa), native ${ref.summary.sigma_est_pa} Pa; ` +
      `wall ${wall.toFixed(2)} s in chromium, native ${ref.summary.wall_time_s.toFixed(2)} s, ratio ${(wall / ref.summary.wall_time_s).toFixed(2)}`,
  );

  // The inputs that ran, as the worker built the granule from them.
  assert.match(await page.textContent('#run-inputs'), /^B2, mesh 8x2: σy = 30000 Pa, η0 = 0\.8, .* d = 1 mm$/);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download')]);
  assert.equal(download.suggestedFilename(), 'granule_B2_8x2_force_displacement.csv');
  const file = join(OUT, download.suggestedFilename());
  await download.saveAs(file);
  assert.equal(readFileSync(file, 'utf8'), ref.csv);
  await page.screenshot({ path: join(OUT, 'screenshot.png'), fullPage: true });
  assert.deepEqual(problems, []);
});

test('Cancel stops a run, keeps its CSV so far, and the page can run again', async () => {
  const ref = native('GRANBED_NATIVE_B2');
  await page.click('#run');
  await page.waitForSelector('#cancel:not([disabled])');
  // The inputs are locked while the run goes.
  for (const id of ['#type', '#mesh', '#custom']) assert.equal(await page.isDisabled(id), true, id);
  // Past a few samples (one per 0.5 % of strain).
  await page.waitForFunction(() => document.getElementById('progress').value > 0.1, null, { timeout: 120_000 });
  await page.click('#cancel');
  await page.waitForSelector('#results[data-state="cancelled"]');
  await page.waitForSelector('#run:not([disabled])', { timeout: 60_000 });
  // No fit of the cut-short curve, only why.
  assert.match(await page.textContent('#sigma-est'), /^n\/a: the run was cancelled at strain \d+\.\d %$/);
  assert.equal(await page.getAttribute('#sigma-est', 'data-value'), null);
  // The status keeps saying that the run was cancelled, and where.
  assert.match(await page.textContent('#status'),
    /^cancelled at strain \d+\.\d %: the curve so far is shown, and its CSV can be downloaded \(its last row at \d+\.\d %\)$/);
  assert.match(await page.getAttribute('#plot', 'aria-label'), /of a run cancelled at strain \d+\.\d %: \d+ points, .* the values are in the CSV$/);
  // The CSV so far: the CLI's rows up to where the run stopped.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download')]);
  const lastRowInName = download.suggestedFilename().match(/^granule_B2_8x2_cancelled_to_(\d+\.\d)pct_force_displacement\.csv$/);
  assert.ok(lastRowInName, download.suggestedFilename());
  assert.equal(lastRowInName[1], (await page.textContent('#status')).match(/last row at (\d+\.\d) %/)[1]);
  const file = join(OUT, download.suggestedFilename());
  await download.saveAs(file);
  const csv = readFileSync(file, 'utf8');
  assert.ok(csv.split('\n').length > 5, csv);
  assert.ok(ref.csv.startsWith(csv), 'the cancelled CSV is not a prefix of the CLI\'s');
  assert.ok(csv.length < ref.csv.length);
  // The CSV's last row is the strain the status names for it.
  const lastRow = Number(csv.trim().split('\n').at(-1).split(',')[2]);
  const said = Number((await page.textContent('#status')).match(/its last row at (\d+\.\d) %/)[1]);
  assert.equal(said, Number((100 * lastRow).toFixed(1)));
  assert.deepEqual(problems, []);
});

test('nu = 0.6 gives a readable error naming the field and its range', async () => {
  await page.check('#custom');
  await page.fill('#poisson_ratio', '0.6');
  await page.click('#run');
  await page.waitForSelector('#error:not([hidden])', { timeout: 60_000 });
  const text = await page.textContent('#error');
  assert.match(text, /Poisson's ratio ν = 0\.6/);
  assert.match(text, /-1 < ν < 0\.5$/);
  assert.equal(await page.getAttribute('#poisson_ratio', 'aria-invalid'), 'true');
  assert.equal(await page.isEnabled('#run'), true);
  // The status line says nothing ran, not an earlier run's result.
  assert.equal(await page.textContent('#status'), 'not run: an input was refused (see the message below)');
  await page.screenshot({ path: join(OUT, 'error.png') });
  // Two values out of range: both named, a line each, both marked.
  await page.fill('#friction', '20');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="rejected"]');
  const both = (await page.textContent('#error')).split('\n');
  assert.equal(both.length, 2, both.join('\n'));
  assert.match(both[0], /Poisson's ratio ν = 0\.6/);
  assert.match(both[1], /friction coefficient μ = 20 .*0 ≤ μ ≤ 10$/);
  for (const id of ['#poisson_ratio', '#friction']) assert.equal(await page.getAttribute(id, 'aria-invalid'), 'true', id);
  // One value out of range and one unreadable: both in one round, in the
  // form's order (σy's unreadable text first).
  await page.fill('#friction', 'abc');
  await page.fill('#yield_stress_pa', '30 kpa');
  await page.click('#run');
  await page.waitForFunction(() => document.getElementById('error').textContent.split('\n').length === 3);
  const three = (await page.textContent('#error')).split('\n');
  assert.match(three[0], /^σy: “30 kpa” has the unit “kpa”: write 30 kPa$/);
  assert.match(three[1], /Poisson's ratio ν = 0\.6 /);
  assert.match(three[2], /^μ: “abc” is not a number/);
  for (const id of ['#yield_stress_pa', '#poisson_ratio', '#friction']) {
    assert.equal(await page.getAttribute(id, 'aria-invalid'), 'true', id);
  }
  await page.fill('#yield_stress_pa', '30000');
  await page.fill('#friction', '0.1');
  assert.deepEqual(problems, []);
});

test('a decimal comma is refused with its fix, not read as another number', async () => {
  await page.check('#custom');
  await page.fill('#poisson_ratio', '0.3');
  await page.fill('#friction', '0,3');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="rejected"]');
  assert.match(await page.textContent('#error'), /μ: “0,3” has a decimal comma: write 0\.3/);
  assert.equal(await page.getAttribute('#friction', 'aria-invalid'), 'true');
  assert.equal(await page.isEnabled('#run'), true);
  await page.fill('#friction', '0.3');
  // A comma before three digits may separate thousands: both readings are
  // offered (the fix offered for 30,000 Pa was once 30.000, i.e. 30 Pa).
  await page.fill('#yield_stress_pa', '30,000');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="rejected"]');
  assert.match(await page.textContent('#error'), /σy: “30,000” has a comma: write 30000 if it separates thousands, or 30\.000 if/);
  await page.fill('#yield_stress_pa', '30000');
  // "custom" off: the refusal goes with the custom values.
  await page.uncheck('#custom');
  assert.equal(await page.getAttribute('#results', 'data-state'), null);
  assert.equal(await page.textContent('#status'), 'ready');
  assert.equal(await page.isHidden('#error'), true);
  assert.deepEqual(problems, []);
});

test('a run an error stops shows no fit as its result, and says why', async () => {
  // σy = 10 Pa on the coarse mesh: an element inverts past 10 % strain,
  // where a fit of the curve so far gives a negative "σ_est".
  await page.check('#custom');
  await page.selectOption('#mesh', '4x1');
  await page.fill('#yield_stress_pa', '10');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="failed"]', { timeout: 60_000 });
  for (const id of ['#sigma-est', '#ratio', '#slope', '#r2']) {
    assert.match(await page.textContent(id), /^n\/a: the run stopped by an error at strain \d+\.\d %$/, id);
    assert.equal(await page.getAttribute(id, 'data-value'), null, id);
  }
  assert.equal(await page.textContent('#status'), 'stopped by an error');
  // E = 1 mPa, far too soft for the platens: the run ends at 40 %, stepped
  // (once it took one step past 40 %), and says it is not quasi-static.
  await page.fill('#yield_stress_pa', '30000');
  await page.fill('#youngs_modulus_pa', '0.001');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="done"]', { timeout: 60_000 });
  assert.match(await page.textContent('#status'), /^done: strain 40\.\d % in .*; NOT quasi-static: /);
  assert.ok(Number(await page.getAttribute('#steps', 'data-value')) >= 400);
  assert.match(await page.textContent('#quasi-static'), /^NO: kinetic energy at most [\d.e+]+ % /);
  await page.fill('#youngs_modulus_pa', '1e6');
  await page.uncheck('#custom');
  await page.selectOption('#mesh', '8x2');
  assert.deepEqual(problems, []);
});

test('results are marked once the inputs change, and cleared when inputs are refused', async () => {
  await page.uncheck('#custom');
  await page.selectOption('#type', 'B2');
  await page.selectOption('#mesh', '4x1');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="done"]', { timeout: 120_000 });
  assert.equal(await page.isHidden('#stale'), true);
  // Another type: its values fill the fields, and B2's results are marked.
  await page.selectOption('#type', 'C1');
  await page.waitForFunction(() => document.getElementById('yield_stress_pa').value === '100000');
  assert.equal(await page.inputValue('#eta0'), '0.6');
  assert.equal(await page.isVisible('#stale'), true);
  assert.equal(await page.getAttribute('#results', 'data-stale'), 'true');
  assert.match(await page.textContent('#run-inputs'), /^B2, mesh 4x1/);
  // With "custom" on, a type chosen still sets the fields to its values.
  await page.check('#custom');
  await page.selectOption('#type', 'B1');
  await page.waitForFunction(() => document.getElementById('yield_stress_pa').value === '30000');
  assert.equal(await page.inputValue('#eta0'), '0.6');
  // Two fields unreadable: both named and marked; the old results go.
  await page.fill('#youngs_modulus_pa', '1 N');
  await page.fill('#poisson_ratio', '0,3');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="rejected"]');
  const text = await page.textContent('#error');
  assert.match(text, /^E: “1 N” is not a number such as 0\.3 or 3e4 \(units: Pa, kPa, MPa, GPa\)/);
  assert.match(text, /\nν: “0,3” has a decimal comma/);
  for (const id of ['#youngs_modulus_pa', '#poisson_ratio']) {
    assert.equal(await page.getAttribute(id, 'aria-invalid'), 'true', id);
    const border = await page.$eval(id, (e) => getComputedStyle(e).borderTopColor);
    assert.equal(border, 'rgb(221, 51, 51)', `${id} not marked`);
  }
  assert.equal(await page.textContent('#sigma-est'), '–');
  assert.equal(await page.isHidden('#download'), true);
  // No notice about results that are no longer shown.
  assert.equal(await page.isHidden('#stale'), true);
  assert.equal(await page.getAttribute('#results', 'data-stale'), null);
  // The earlier runs' curves stay, named (B2 8x2 twice, B2 4x1 once).
  assert.match(await page.getAttribute('#plot', 'aria-label'), /^platen force against displacement of \d earlier run\(s\): .*B2 4x1$/);
  // A number beyond a double is refused, not read as infinity...
  // (E with its unit: read as 1e6 Pa.)
  await page.fill('#youngs_modulus_pa', '1 MPa');
  await page.fill('#poisson_ratio', '0.3');
  await page.fill('#yield_stress_pa', '1e400');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="rejected"]');
  assert.match(await page.textContent('#error'), /^σy: “1e400” is too large for a number/);
  // ... while inf, as the kernel's range allows for σy, runs elastic.
  await page.fill('#yield_stress_pa', 'inf');
  await page.click('#run');
  await page.waitForSelector('#results[data-state="done"]', { timeout: 120_000 });
  assert.match(await page.textContent('#run-inputs'), /^custom \(from B1\), mesh 4x1: σy = inf Pa, .*E = 1000000 Pa/);
  assert.equal(await page.textContent('#sigma-eff0'), 'n/a');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download')]);
  assert.match(download.suggestedFilename(), /^granule_custom-[0-9a-f]{8}_4x1_force_displacement\.csv$/);
  await page.screenshot({ path: join(OUT, 'custom.png'), fullPage: true });
  await page.fill('#yield_stress_pa', '30000');
  await page.uncheck('#custom');
  await page.selectOption('#type', 'B2');
  await page.selectOption('#mesh', '8x2');
  assert.deepEqual(problems, []);
});

test('finished runs stay drawn to compare with, until cleared', async () => {
  await page.selectOption('#mesh', '4x1');
  for (const type of ['A2', 'C2']) {
    await page.selectOption('#type', type);
    await page.waitForFunction((t) => document.getElementById('yield_stress_pa').value === (t === 'A2' ? '10000' : '100000'), type);
    await page.click('#run');
    await page.waitForSelector('#results[data-state="done"]', { timeout: 120_000 });
  }
  const curves = Number(await page.getAttribute('#plot', 'data-curves'));
  assert.ok(curves >= 2, `${curves} curves drawn`);
  assert.equal(await page.isVisible('#clear-history'), true);
  await page.screenshot({ path: join(OUT, 'compare.png') });
  await page.click('#clear-history');
  assert.equal(await page.getAttribute('#plot', 'data-curves'), '1');
  assert.equal(await page.isHidden('#clear-history'), true);
  await page.selectOption('#type', 'B2');
  await page.selectOption('#mesh', '8x2');
  assert.deepEqual(problems, []);
});

test('the page fits a phone: nothing wider than its 375 px', async () => {
  await page.setViewportSize({ width: 375, height: 800 });
  const width = await page.evaluate(() => document.documentElement.scrollWidth);
  assert.ok(width <= 375, `the page is ${width} px wide`);
  const plot = await page.evaluate(() => document.getElementById('plot').getBoundingClientRect().width);
  assert.ok(plot <= 375, `the plot is ${plot} px wide`);
  // Drawn at the width it is shown (one device pixel per CSS pixel here),
  // not a 560 px drawing scaled down with its labels.
  // (The page redraws on its resize event, which follows the new size.)
  const drawn = await page
    .waitForFunction(() => {
      const c = document.getElementById('plot');
      return c.clientWidth < 560 && c.width === c.clientWidth;
    }, null, { timeout: 5_000 })
    .then(() => true, () => false);
  const [backing, shownWidth] = await page.evaluate(() => {
    const c = document.getElementById('plot');
    return [c.width, c.clientWidth];
  });
  assert.ok(drawn, `canvas ${backing} px for ${shownWidth} px shown`);
  await page.screenshot({ path: join(OUT, 'phone.png'), fullPage: true });
  await page.setViewportSize({ width: 1000, height: 1100 });
});

test('opened as a file, the page says how to serve it instead of loading for ever', async () => {
  const file = await browser.newPage();
  await file.goto(`file://${join(WWW, 'index.html')}`);
  assert.match(await file.textContent('#status'), /^this page must be served over http, not opened as a file: run "python3 -m http\.server/);
  await file.close();
});

test('the CSV\'s columns are explained on the page, as the CLI\'s glossary has them', async () => {
  const names = await page.$$eval('#csv-columns-body th', (ths) => ths.map((t) => t.textContent));
  assert.equal(names.length, 18);
  assert.deepEqual(names.slice(0, 4), ['time_s', 'displacement_m', 'strain', 'force_n']);
  const meaning = await page.$eval('#csv-columns-body tr:nth-child(4) td', (td) => td.textContent);
  assert.equal(meaning, 'mean of the upper and lower platen forces, N');
});
