// The page: the form, the worker that runs the simulation, the live plot,
// the granule view, the results table and the CSV download.
import { advice, formatStress, formatSlope, MM_UNITS, PA_UNITS, parseDecimal, tick } from './format.js';

const $ = (id) => document.getElementById(id);
const FIELDS = ['yield_stress_pa', 'eta0', 'youngs_modulus_pa', 'poisson_ratio', 'cp', 'eta_c', 'friction'];
const LABELS = {
  yield_stress_pa: 'σy', eta0: 'η0', youngs_modulus_pa: 'E', poisson_ratio: 'ν', cp: 'cp',
  eta_c: 'ηc', friction: 'μ', diameter_mm: 'd',
};
// The fields that take a unit after the number (30 kPa, 1 MPa; 2 mm).
const UNITS = { yield_stress_pa: PA_UNITS, youngs_modulus_pa: PA_UNITS, diameter_mm: MM_UNITS };
// The parameter fields in the form's order: refusals are listed in it.
const FORM_ORDER = [...FIELDS, 'diameter_mm'];
// The form's field of a module's field name (the kernel's `diameter_m` is
// the page's `diameter_mm`).
const formField = (f) => (f === 'diameter_m' ? 'diameter_mm' : f);

let worker = null;
let running = false;
let view = null; // { quads, positions, diameter, x, f, fit }
let csvUrl = null;
// Finished runs' curves, kept to compare the next runs with (oldest
// first, at most HISTORY_MAX): { id, label, x (mm), f (N) }. The run shown
// (view.historyId) is drawn in blue, the others behind it in their colours.
const HISTORY_MAX = 5;
const HISTORY_COLOURS = ['#e08a2c', '#3a9d3a', '#9467bd', '#8c564b', '#e377c2'];
let history = [];
let runCount = 0;
// The status line's note on a run abandoned with its worker (kept when
// the new worker says it is ready), and the strain the run had reached.
let cancelNote = null;
let lastStrain = 0;
// A cancel asked of the worker: the timer that terminates it if it does
// not stop the run (between two chunks, about 0.1 s) in time.
let cancelTimer = null;
const CANCEL_WAIT_MS = 5000;
// The run in progress or last run: its type (or "custom"), mesh, the
// parameters it used (from the worker) and its start time.
let current = null;

function setStatus(text) { $('status').textContent = text; }

// The error box shows `message`; the inputs named by `fields` (one field
// or a list; the kernel's `diameter_m` is the page's `diameter_mm`) are
// marked invalid, described by the box, and the first one is focused.
function showError(message, fields) {
  const box = $('error');
  box.textContent = message;
  box.hidden = false;
  for (const input of document.querySelectorAll('#params input')) {
    input.removeAttribute('aria-invalid');
    input.removeAttribute('aria-describedby');
  }
  const ids = [].concat(fields ?? []).map(formField).filter((id) => $(id));
  for (const id of ids) {
    $(id).setAttribute('aria-invalid', 'true');
    $(id).setAttribute('aria-describedby', 'error');
  }
  if (ids.length && !$(ids[0]).disabled) $(ids[0]).focus();
}

// Refused before or at the start of a run: nothing runs, and nothing of an
// earlier run is left on the page to be read as this one's.
function refuse(message, fields) {
  resetResults();
  clearStale();
  view = null;
  drawAll();
  $('plot').setAttribute('aria-label', history.length
    ? `platen force against displacement of ${history.length} earlier run(s): ${history.map((h) => h.label).join(', ')}`
    : 'platen force against displacement (no run yet)');
  showError(message, fields);
  $('run-inputs').textContent = '–';
  $('results').dataset.state = 'rejected';
  // Nothing ran: the status line says so rather than an earlier run's
  // result, and blames an input only where one is named (the worker also
  // reports a module that would not load, or a run that could not start).
  const named = [].concat(fields ?? []).length > 0;
  setStatus(named ? 'not run: an input was refused (see the message below)' : 'not run (see the message below)');
}

function clearError() {
  $('error').hidden = true;
  $('error').textContent = '';
  for (const input of document.querySelectorAll('#params input')) {
    input.removeAttribute('aria-invalid');
    input.removeAttribute('aria-describedby');
  }
}

// After a run, any change of the inputs marks its results as those of the
// inputs shown under "inputs of this run", not of the form as it now is.
function markStale() {
  const state = $('results').dataset.state;
  if (running || !['done', 'failed', 'cancelled'].includes(state)) return;
  $('results').dataset.stale = 'true';
  $('stale').hidden = false;
}

function clearStale() {
  delete $('results').dataset.stale;
  $('stale').hidden = true;
}

// While a run goes, its inputs are locked: the results, the picture and
// the download's name stay those of the inputs that ran.
function setRunning(on) {
  running = on;
  $('run').disabled = on;
  $('cancel').disabled = !on;
  for (const id of ['type', 'mesh', 'custom']) $(id).disabled = on;
  $('params').disabled = on || !$('custom').checked;
}

function startWorker() {
  worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  worker.onmessage = (ev) => onWorker(ev.data);
  worker.onerror = (ev) => {
    clearTimeout(cancelTimer);
    cancelTimer = null;
    setRunning(false);
    // A browser that cannot run a module worker (Firefox before 114) ends
    // here, before the worker can say anything itself.
    showError(`the simulation worker failed: ${ev.message || 'unknown error'}. The page needs a browser that runs ` +
      'module Web Workers and WebAssembly SIMD (Chrome or Edge 91, Firefox 114, Safari 16.4 or later).');
    // Not "checking the inputs…" or a run's progress for ever.
    setStatus('stopped: the simulation worker failed (see the message below)');
  };
  worker.postMessage({ cmd: 'hello' });
}

function onWorker(msg) {
  switch (msg.kind) {
    case 'ready':
      $('run').disabled = running;
      setStatus(cancelNote ? `${cancelNote}; ready` : 'ready');
      $('version').textContent = `granbed ${msg.version}`;
      fillColumns(msg.columns);
      if (!$('custom').checked) requestPreset();
      break;
    case 'preset':
      // A type chosen while "custom" is on sets the fields to that type's
      // values too: the fields always start from the type shown.
      if (!$('custom').checked || msg.chosen) fillParams(msg.values);
      if (msg.chosen && $('custom').checked) setStatus(`parameters set to ${msg.type}'s values; edit them and Run`);
      break;
    case 'checked':
      onChecked(msg.refused, msg.id);
      break;
    case 'error':
      clearTimeout(cancelTimer);
      cancelTimer = null;
      setRunning(false);
      refuse(msg.message, msg.field);
      break;
    case 'start':
      view = { quads: msg.quads, positions: msg.positions, diameter: msg.diameter, x: [], f: [], fit: null };
      current.params = msg.params;
      $('run-inputs').textContent = describeRun(current);
      drawAll();
      break;
    case 'progress':
      lastStrain = msg.strain;
      $('progress').value = msg.progress;
      // (A chunk that ends after a cancel was asked for keeps "cancelling…".)
      if (cancelTimer === null) setStatus(`strain ${(100 * msg.strain).toFixed(1)} %, ${msg.steps} steps${timeLeft(msg.progress)}`);
      Object.assign(view, { positions: msg.positions, x: msg.x, f: msg.f });
      drawAll();
      break;
    case 'done':
      finish(msg);
      break;
    default:
      break;
  }
}

// The CSV's columns and their meanings, from the module (the CLI's
// glossary of force_displacement.csv), once.
function fillColumns(columns) {
  const body = $('csv-columns-body');
  if (!columns || body.rows.length) return;
  for (const [name, meaning] of columns) {
    const row = body.insertRow();
    const th = document.createElement('th');
    th.scope = 'row';
    th.textContent = name;
    row.appendChild(th);
    row.insertCell().textContent = meaning;
  }
}

function fillParams(values) {
  for (const k of FIELDS) $(k).value = values[k];
  $('diameter_mm').value = values.diameter_m * 1e3;
}

// Asks the worker for the type's parameters; `chosen`: the user picked
// the type (the fields follow it even with "custom" on).
function requestPreset(chosen = false) {
  worker.postMessage({ cmd: 'preset', type: $('type').value, chosen });
}

// The inputs object of granbed-wasm's Granule: the type and mesh, and with
// "custom" every parameter field (the diameter in mm, as typed), and the
// errors of the fields that cannot be read, which stand in the inputs as
// NaN (the ranges are the kernel's to check: `checkThenRefuse`).
function readInputs() {
  const inputs = { type: $('type').value, mesh: $('mesh').value };
  const unreadable = [];
  if (!$('custom').checked) return { inputs, unreadable };
  for (const k of FORM_ORDER) {
    try {
      inputs[k] = parseDecimal($(k).value, LABELS[k], k, UNITS[k]);
    } catch (e) {
      unreadable.push({ message: e.message, field: e.field });
      inputs[k] = NaN;
    }
  }
  return { inputs, unreadable };
}

// Fields that could not be read: the worker checks the others' ranges
// (`check`), and every bad field is named at once, in the form's order
// (`onChecked`).
// Each check is numbered: only the latest one's answer is shown, and
// none once a run has started.
let unreadableFields = null;
let checkId = 0;

function checkThenRefuse(inputs, unreadable) {
  unreadableFields = unreadable;
  checkId += 1;
  worker.postMessage({ cmd: 'check', inputs, id: checkId });
}

function onChecked(refused, id) {
  if (id !== checkId || running || unreadableFields === null) return;
  const unreadable = unreadableFields;
  unreadableFields = null;
  const named = new Set(unreadable.map((u) => u.field));
  // An unreadable field's own message says more than the range of the
  // NaN it stood in as.
  const lines = [...unreadable, ...refused.filter((r) => !named.has(formField(r.field)))];
  const rank = (f) => {
    const i = FORM_ORDER.indexOf(formField(f));
    return i < 0 ? FORM_ORDER.length : i;
  };
  lines.sort((a, b) => rank(a.field) - rank(b.field));
  refuse(lines.map((l) => l.message).join('\n'), lines.map((l) => formField(l.field)).filter((f) => f));
}

// "B2, mesh 8x2: σy = 30000 Pa, …" for the results table.
function describeRun(run) {
  const p = run.params;
  const head = `${run.custom ? `custom (from ${run.type})` : run.type}, mesh ${run.mesh}`;
  if (!p) return head;
  // As typed: an infinite σy (a purely elastic granule) is written inf.
  const v = (x) => (Number.isFinite(x) || Number.isNaN(x) ? String(x) : x > 0 ? 'inf' : '-inf');
  return `${head}: σy = ${v(p.yield_stress_pa)} Pa, η0 = ${v(p.eta0)}, E = ${v(p.youngs_modulus_pa)} Pa, ` +
    `ν = ${v(p.poisson_ratio)}, cp = ${v(p.cp)}, ηc = ${v(p.eta_c)}, μ = ${v(p.friction)}, ` +
    `d = ${+(p.diameter_m * 1e3).toPrecision(12)} mm`;
}

// ", about 3 min left" from the progress so far (after a few seconds).
function timeLeft(progress) {
  const elapsed = (performance.now() - current.t0) / 1e3;
  if (!(progress > 0) || elapsed < 3) return '';
  const left = (elapsed * (1 - progress)) / progress;
  if (left < 60) return `, about ${Math.ceil(left)} s left`;
  if (left < 5400) return `, about ${Math.round(left / 60)} min left`;
  return `, about ${(left / 3600).toFixed(1)} h left`;
}

// A short tag of a run's inputs for the download's name, so that two
// custom runs do not download under one name: FNV-1a of `text`, 8 hex
// digits.
function tag(text) {
  let h = 0x811c9dc5;
  for (const c of new TextEncoder().encode(text)) h = Math.imul(h ^ c, 0x01000193) >>> 0;
  return h.toString(16).padStart(8, '0');
}

function resetResults() {
  for (const id of ['sigma-est', 'sigma-eff0', 'ratio', 'slope', 'r2', 'steps', 'quasi-static', 'wall', 'run-inputs']) {
    $(id).textContent = '–';
    delete $(id).dataset.value;
  }
  $('download').hidden = true;
  if (csvUrl) URL.revokeObjectURL(csvUrl);
  csvUrl = null;
  $('progress').value = 0;
}

function run(ev) {
  ev.preventDefault();
  if (running) return;
  clearError();
  const { inputs, unreadable } = readInputs();
  if (unreadable.length) {
    // Until the worker's range checks answer, the page is neither the
    // earlier refusal (its message is cleared) nor a run.
    $('results').dataset.state = 'checking';
    setStatus('checking the inputs…');
    checkThenRefuse(inputs, unreadable);
    return;
  }
  // (An answer to an earlier check is no longer wanted.)
  unreadableFields = null;
  resetResults();
  clearStale();
  cancelNote = null;
  lastStrain = 0;
  current = {
    type: inputs.type, mesh: inputs.mesh, custom: $('custom').checked, params: null, t0: performance.now(),
  };
  $('run-inputs').textContent = describeRun(current);
  setRunning(true);
  setStatus('starting…');
  $('results').dataset.state = 'running';
  worker.postMessage({ cmd: 'run', inputs });
}

function finish(msg) {
  clearTimeout(cancelTimer);
  cancelTimer = null;
  setRunning(false);
  Object.assign(view, { positions: msg.positions, x: msg.x, f: msg.f });
  // A cut-short curve's fit is no result: not drawn either.
  const whole = !msg.failure && !msg.cancelled;
  if (whole && msg.slope !== null) {
    view.fit = { slope: msg.slope, intercept: msg.intercept, x0: 0.1 * msg.diameter, x1: Math.min(0.4, msg.strain) * msg.diameter };
  }
  drawAll();
  const last = msg.f.length ? msg.f[msg.f.length - 1] : 0;
  $('plot').setAttribute('aria-label',
    `platen force against platen approach${msg.cancelled ? ` of a run cancelled at strain ${(100 * msg.strain).toFixed(1)} %` : ''}: ` +
    `${msg.f.length} points, to x = ${(1e3 * (msg.x[msg.x.length - 1] ?? 0)).toPrecision(3)} mm ` +
    `and F = ${last.toPrecision(3)} N; the values are in the CSV`);
  const set = (id, text, value) => {
    $(id).textContent = text;
    if (value !== undefined && value !== null) $(id).dataset.value = String(value);
  };
  set('sigma-eff0', formatStress(msg.sigmaEff0), msg.sigmaEff0);
  if (!whole) {
    // A fit of a curve cut short is no result (after an error it can even
    // come out negative): none is shown, only why.
    const why = `n/a: the run ${msg.failure ? 'stopped by an error' : 'was cancelled'} at strain ${(100 * msg.strain).toFixed(1)} %`;
    for (const id of ['sigma-est', 'ratio', 'slope', 'r2']) set(id, why);
  } else {
    set('sigma-est', formatStress(msg.sigmaEst), msg.sigmaEst);
    const ratio = msg.sigmaEst !== null && Number.isFinite(msg.sigmaEff0) && msg.sigmaEff0 > 0 ? msg.sigmaEst / msg.sigmaEff0 : null;
    set('ratio', ratio === null ? 'n/a' : ratio.toFixed(3), ratio);
    set('slope', formatSlope(msg.slope), msg.slope);
    set('r2', msg.r2 === null ? 'n/a' : msg.r2.toFixed(5), msg.r2);
  }
  set('steps', String(msg.steps), msg.steps);
  set('quasi-static',
    !whole
      ? 'n/a: the run stopped early'
      : msg.kineticToInternal === null
      ? 'n/a'
      : `${msg.quasiStatic ? 'yes' : 'NO'}: kinetic energy at most ${percent(msg.kineticToInternal)} of the internal work ` +
        `(limit ${100 * msg.kineticLimit} %)${msg.massScaling === 1 ? '' : `, masses ×${msg.massScaling}`}`,
    whole ? msg.quasiStatic : undefined);
  set('wall', `${(msg.wallMs / 1e3).toFixed(2)} s`, msg.wallMs / 1e3);
  // A run cancelled before its first sample (every 0.5 % of strain) has
  // only the unloaded row: nothing to download or draw.
  const sampled = msg.f.length > 1;
  // The strain of the CSV's last row (the run went on to msg.strain).
  const lastRow = sampled ? (100 * msg.x[msg.x.length - 1]) / msg.diameter : 0;
  if (whole || sampled) {
    csvUrl = URL.createObjectURL(new Blob([msg.csv], { type: 'text/csv' }));
    const a = $('download');
    a.href = csvUrl;
    const name = current.custom ? `custom-${tag(describeRun(current))}` : current.type;
    // A cancelled run's file names where its rows end, so that two
    // cancelled runs of one preset are told apart.
    const cut = msg.cancelled ? `_cancelled_to_${lastRow.toFixed(1)}pct` : '';
    a.download = `granule_${name}_${current.mesh}${cut}_force_displacement.csv`;
    a.textContent = `Download CSV (${a.download})`;
    a.hidden = false;
  }
  $('progress').value = whole ? 1 : $('progress').value;
  // A cancelled run's curve is kept with the finished ones (marked), so
  // that a refused input or the next run does not lose it.
  if (whole || (msg.cancelled && sampled)) {
    runCount += 1;
    const label = `${current.custom ? `custom-${tag(describeRun(current)).slice(0, 4)}` : current.type} ${current.mesh}` +
      (msg.cancelled ? ` (to ${lastRow.toFixed(1)} %, cancelled)` : '') +
      (whole && judgedNotQuasiStatic(msg) ? ' (not quasi-static)' : '');
    // Its colour for as long as it is drawn (by run, not by place in the list).
    const colour = HISTORY_COLOURS[(runCount - 1) % HISTORY_COLOURS.length];
    history.push({ id: runCount, label, colour, x: Array.from(msg.x, (v) => v * 1e3), f: Array.from(msg.f) });
    if (history.length > HISTORY_MAX) history.shift();
    view.historyId = runCount;
    drawPlot();
  }
  if (msg.cancelled) {
    const at = `cancelled at strain ${(100 * msg.strain).toFixed(1)} %`;
    setStatus(sampled
      ? `${at}: the curve so far is shown, and its CSV can be downloaded (its last row at ${lastRow.toFixed(1)} %)`
      : `${at}, before the first sample (one every 0.5 % of strain): nothing to show`);
    $('results').dataset.state = 'cancelled';
  } else if (msg.failure) {
    setStatus('stopped by an error');
    const kept = sampled
      ? 'The curve up to that point is shown and in the CSV; '
      : 'It stopped before the first sample (0.5 % of strain): there is no curve to show; ';
    showError(`${msg.failure.message}\n${advice(msg.failure.message)}${kept}` +
      'the picture shows the granule after the last chunk of steps that succeeded (within about 1 % strain of the failure).',
    msg.failure.field);
    $('results').dataset.state = 'failed';
  } else {
    // The result in the status line too: the table may be below the fold.
    // A run whose inertia was not negligible says so where its result is
    // read: its curve is the platens' speed's as much as the material's.
    const inertia = judgedNotQuasiStatic(msg)
      ? '; NOT quasi-static: the kinetic energy was not negligible, so the curve carries inertia as ' +
        'well as the granule\'s response'
      : '';
    setStatus(`done: strain ${(100 * msg.strain).toFixed(1)} % in ${(msg.wallMs / 1e3).toFixed(2)} s; ` +
      `σ_est = ${formatStress(msg.sigmaEst)}${inertia}`);
    $('results').dataset.state = 'done';
  }
}

// Whether a finished run's certificate was judged and failed (not judged,
// the table says n/a and nothing is claimed).
function judgedNotQuasiStatic(msg) {
  return msg.kineticToInternal !== null && msg.quasiStatic === false;
}

// "0.00057 %" for a ratio; "4.7e+17 %" rather than 18 digits.
function percent(ratio) {
  const p = 100 * ratio;
  return `${Math.abs(p) >= 1e6 ? p.toExponential(1) : +p.toPrecision(2)} %`;
}

// Asks the worker to stop the run between two chunks: it answers with the
// run so far (`finish`, with its CSV). One that does not answer in
// CANCEL_WAIT_MS is terminated (`abandon`).
function cancel() {
  if (!running || cancelTimer !== null) return;
  $('cancel').disabled = true;
  setStatus('cancelling…');
  worker.postMessage({ cmd: 'stop' });
  cancelTimer = setTimeout(abandon, CANCEL_WAIT_MS);
}

// The run abandoned with its worker: the curve drawn so far stays, its CSV
// is lost; a new worker is started.
function abandon() {
  cancelTimer = null;
  if (!running) return;
  worker.terminate();
  setRunning(false);
  $('run').disabled = true;
  cancelNote = `cancelled at strain ${(100 * lastStrain).toFixed(1)} % (the curve so far is shown)`;
  // The picture's description says what it shows now (the cancelled
  // worker took the run's CSV with it: the curve is only drawn).
  // (A run cancelled before it started has no curve; `view` is then an
  // earlier run's or none.)
  const points = $('results').dataset.state === 'running' && current?.params ? view.f.length : 0;
  $('plot').setAttribute('aria-label', `platen force against platen approach of a run cancelled at strain ` +
    `${(100 * lastStrain).toFixed(1)} %: ${points} points, not saved`);
  setStatus(`${cancelNote}; restarting…`);
  $('progress').value = 0;
  $('results').dataset.state = 'cancelled';
  startWorker();
}

// ---- drawing -------------------------------------------------------------

function niceStep(range, count) {
  const raw = range / count;
  const p = 10 ** Math.floor(Math.log10(raw));
  const m = raw / p;
  return (m < 1.5 ? 1 : m < 3 ? 2 : m < 7 ? 5 : 10) * p;
}

// A canvas's 2D context drawn in CSS pixels at the width the page gives it
// (its aspect ratio kept), with a backing store of device pixels: on a
// phone the labels stay 12 px and sharp instead of scaled down. Returns
// [context, width, height] in CSS pixels.
function sized(c) {
  // The drawing's own size, read once from the canvas's attributes: its
  // aspect ratio, and the width to draw at while the canvas has no layout
  // box (its backing store, once resized, is in device pixels).
  const aspect = Number(c.dataset.aspect ?? (c.dataset.aspect = String(c.height / c.width)));
  const natural = Number(c.dataset.width ?? (c.dataset.width = String(c.width)));
  const W = Math.max(1, Math.round(c.clientWidth || natural));
  const H = Math.round(W * aspect);
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round(W * dpr), h = Math.round(H * dpr);
  if (c.width !== w || c.height !== h) {
    c.width = w;
    c.height = h;
  }
  const g = c.getContext('2d');
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  return [g, W, H];
}

function drawPlot() {
  const c = $('plot');
  const [g, W, H] = sized(c);
  const L = 64, R = 16, T = 16, B = 44;
  g.clearRect(0, 0, W, H);
  const x = view ? Array.from(view.x, (v) => v * 1e3) : [];
  const f = view ? Array.from(view.f) : [];
  const d = view ? view.diameter * 1e3 : 1;
  const earlier = history.filter((h) => !view || h.id !== view.historyId);
  // The button to forget them whenever there are any drawn.
  $('clear-history').hidden = earlier.length === 0;
  const xMax = Math.max(view || !earlier.length ? 0.4 * d : 0, ...x, ...earlier.flatMap((h) => h.x)) * 1.02;
  const fMax = Math.max(1e-12, ...f, ...earlier.flatMap((h) => h.f)) * 1.08;
  const px = (v) => L + (v / xMax) * (W - L - R);
  const py = (v) => H - B - (v / fMax) * (H - T - B);
  g.strokeStyle = '#999'; g.fillStyle = '#333'; g.lineWidth = 1; g.font = '12px system-ui, sans-serif';
  g.beginPath(); g.moveTo(L, T); g.lineTo(L, H - B); g.lineTo(W - R, H - B); g.stroke();
  g.textAlign = 'center'; g.textBaseline = 'top';
  const xs = niceStep(xMax, 6);
  for (let v = 0; v <= xMax + 1e-12 * xMax; v += xs) {
    g.fillText(tick(v), px(v), H - B + 6);
    g.beginPath(); g.moveTo(px(v), H - B); g.lineTo(px(v), H - B + 4); g.stroke();
  }
  g.fillText('platen approach x, mm', (L + W - R) / 2, H - 18);
  g.textAlign = 'right'; g.textBaseline = 'middle';
  if (f.length || earlier.length) {
    const fs = niceStep(fMax, 6);
    for (let v = 0; v <= fMax + 1e-15 * fMax; v += fs) {
      g.fillText(tick(v), L - 6, py(v));
      g.strokeStyle = '#eee'; g.beginPath(); g.moveTo(L + 1, py(v)); g.lineTo(W - R, py(v)); g.stroke();
    }
  }
  g.save(); g.translate(14, (T + H - B) / 2); g.rotate(-Math.PI / 2); g.textAlign = 'center';
  g.fillStyle = '#333'; g.fillText('platen force F, N', 0, 0); g.restore();
  for (const h of earlier) {
    g.strokeStyle = h.colour; g.lineWidth = 1.5; g.beginPath();
    h.x.forEach((v, i) => (i ? g.lineTo(px(v), py(h.f[i])) : g.moveTo(px(v), py(h.f[i]))));
    g.stroke();
  }
  const shown = earlier.length + (x.length > 1 ? 1 : 0);
  c.dataset.curves = String(shown);
  if (earlier.length) {
    // The legend: the earlier runs, then this one.
    const mine = history.find((h) => view && h.id === view.historyId);
    const entries = [...earlier.map((h) => [h.colour, h.label]), ...(x.length > 1 ? [['#1f5fbf', mine ? `${mine.label} (this run)` : 'this run']] : [])];
    g.textAlign = 'left'; g.textBaseline = 'middle'; g.font = '11px system-ui, sans-serif';
    entries.forEach(([colour, label], i) => {
      const y = T + 8 + 15 * i;
      g.strokeStyle = colour; g.lineWidth = 2; g.beginPath(); g.moveTo(L + 10, y); g.lineTo(L + 28, y); g.stroke();
      g.fillStyle = '#333'; g.fillText(label, L + 33, y);
    });
  }
  if (x.length > 1) {
    g.strokeStyle = '#1f5fbf'; g.lineWidth = 2; g.beginPath();
    x.forEach((v, i) => (i ? g.lineTo(px(v), py(f[i])) : g.moveTo(px(v), py(f[i]))));
    g.stroke();
  }
  if (view && view.fit) {
    const { slope, intercept, x0, x1 } = view.fit;
    g.strokeStyle = '#c33'; g.lineWidth = 1.5; g.setLineDash([6, 4]); g.beginPath();
    g.moveTo(px(x0 * 1e3), py(slope * x0 + intercept)); g.lineTo(px(x1 * 1e3), py(slope * x1 + intercept));
    g.stroke(); g.setLineDash([]);
  }
}

// The view angles of the granule picture (drag on it to turn it): azimuth
// about the platen axis and elevation above the equator, radians.
const viewAngles = { phi: 0.5, theta: 0.35 };

// The octant's surface mirrored into all eight octants, seen from the view
// angles; painter's order, back faces culled, Lambert shading.
function drawGranule() {
  const c = $('granule');
  const [g, W, H] = sized(c);
  g.clearRect(0, 0, W, H);
  if (!view) return;
  const p = view.positions, q = view.quads, d = view.diameter;
  const { phi, theta } = viewAngles;
  const cp = Math.cos(phi), sp = Math.sin(phi), ct = Math.cos(theta), st = Math.sin(theta);
  const scale = (0.45 * W) / d;
  const cam = [0, -ct, st];
  const light = [-0.4, -0.7, 0.6];
  const ln = Math.hypot(...light);
  const faces = [];
  for (const sx of [-1, 1]) for (const sy of [-1, 1]) for (const sz of [-1, 1]) {
    for (let k = 0; k < q.length; k += 4) {
      const v = [];
      for (let j = 0; j < 4; j++) {
        const n = q[k + j] * 3;
        const X = sx * p[n], Y = sy * p[n + 1], Z = sz * p[n + 2];
        v.push([X * cp - Y * sp, X * sp + Y * cp, Z]);
      }
      const a = v[2].map((t, i) => t - v[0][i]), b = v[3].map((t, i) => t - v[1][i]);
      let nrm = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const cen = [0, 1, 2].map((i) => (v[0][i] + v[1][i] + v[2][i] + v[3][i]) / 4);
      if (nrm[0] * cen[0] + nrm[1] * cen[1] + nrm[2] * cen[2] < 0) nrm = nrm.map((t) => -t);
      const nl = Math.hypot(...nrm) || 1;
      if ((nrm[0] * cam[0] + nrm[1] * cam[1] + nrm[2] * cam[2]) / nl < -0.05) continue;
      const shade = 0.3 + 0.7 * Math.max(0, (nrm[0] * light[0] + nrm[1] * light[1] + nrm[2] * light[2]) / (nl * ln));
      faces.push({ v, depth: cen[0] * cam[0] + cen[1] * cam[1] + cen[2] * cam[2], shade });
    }
  }
  faces.sort((a, b) => a.depth - b.depth);
  const sx = (v) => W / 2 + scale * v[0];
  const sy = (v) => H / 2 - scale * (v[1] * st + v[2] * ct);
  // The platens: squares of side 1.5 d at the granule's top and bottom.
  let top = 0;
  for (let n = 2; n < p.length; n += 3) top = Math.max(top, p[n]);
  const plate = (z) => {
    const a = 0.75 * d;
    const corners = [[-a, -a], [a, -a], [a, a], [-a, a]].map(([X, Y]) => [X * cp - Y * sp, X * sp + Y * cp, z]);
    g.fillStyle = 'rgba(110,110,110,0.35)';
    g.strokeStyle = 'rgba(60,60,60,0.8)';
    g.beginPath();
    corners.forEach((v, i) => (i ? g.lineTo(sx(v), sy(v)) : g.moveTo(sx(v), sy(v))));
    g.closePath(); g.fill(); g.stroke();
  };
  // Painter's order for the platens too: the one farther from the eye
  // first (the lower one when seen from above, theta > 0).
  const [far, near] = theta >= 0 ? [-top, top] : [top, -top];
  plate(far);
  for (const face of faces) {
    const s = Math.round(90 + 150 * face.shade);
    g.fillStyle = `rgb(${Math.round(s * 0.75)},${Math.round(s * 0.85)},${s})`;
    g.strokeStyle = 'rgba(20,30,60,0.35)';
    g.beginPath();
    face.v.forEach((v, i) => (i ? g.lineTo(sx(v), sy(v)) : g.moveTo(sx(v), sy(v))));
    g.closePath(); g.fill(); g.stroke();
  }
  plate(near);
}

function drawAll() { drawPlot(); drawGranule(); }

// ---- wiring --------------------------------------------------------------

$('inputs').addEventListener('submit', run);
$('cancel').addEventListener('click', cancel);
// Forget the earlier runs' curves (the run shown stays).
$('clear-history').addEventListener('click', () => {
  history = history.filter((h) => view && h.id === view.historyId);
  drawPlot();
});
$('type').addEventListener('change', () => requestPreset(true));
$('custom').addEventListener('change', () => {
  $('params').disabled = !$('custom').checked;
  if (!$('custom').checked) {
    clearError();
    // The custom values are gone, and with them a refusal's message and
    // the answer of a check still pending (`onChecked` drops it).
    unreadableFields = null;
    if (['rejected', 'checking'].includes($('results').dataset.state)) {
      delete $('results').dataset.state;
      setStatus('ready');
    }
    requestPreset();
  }
});
// Typing in a field or choosing another type, mesh or "custom" after a
// run marks its results as no longer those of the form.
$('inputs').addEventListener('input', markStale);
$('inputs').addEventListener('change', markStale);
// Drag on the picture (or use the arrow keys on it) to turn the granule.
{
  const c = $('granule');
  let last = null;
  c.addEventListener('pointerdown', (e) => { last = [e.clientX, e.clientY]; c.setPointerCapture(e.pointerId); });
  c.addEventListener('pointerup', () => { last = null; });
  c.addEventListener('pointermove', (e) => {
    if (!last) return;
    viewAngles.phi += 0.01 * (e.clientX - last[0]);
    viewAngles.theta = Math.max(-1.5, Math.min(1.5, viewAngles.theta + 0.01 * (e.clientY - last[1])));
    last = [e.clientX, e.clientY];
    drawGranule();
  });
  const KEYS = { ArrowLeft: [-0.15, 0], ArrowRight: [0.15, 0], ArrowUp: [0, -0.15], ArrowDown: [0, 0.15] };
  c.addEventListener('keydown', (e) => {
    const k = KEYS[e.key];
    if (!k) return;
    e.preventDefault();
    viewAngles.phi += k[0];
    viewAngles.theta = Math.max(-1.5, Math.min(1.5, viewAngles.theta + k[1]));
    drawGranule();
  });
}
window.addEventListener('resize', drawAll);
drawAll();
startWorker();
