// The simulation's Web Worker: loads the WebAssembly module, runs one
// experiment at a time in chunks of time steps and posts the growing curve
// and the node positions after each chunk. Between chunks it reads its
// messages: a `stop` ends the run there, and the run is posted as done
// (cancelled, with its CSV so far). The page terminates the worker only if
// it does not answer.
import init, { Granule, check, csv_columns as csvColumns, preset, version } from './pkg/granbed_wasm.js';
import { hasSimd } from './simd.js';

// Time steps per chunk: about 0.1 s of work on the standard mesh.
const CHUNK = 1500;

const ready = init();

// Why the module did not load: a browser without WebAssembly SIMD, which
// the module is built with (.cargo/config.toml), or the error itself.
function loadFailure(e) {
  const why = hasSimd()
    ? errorMessage(e).message
    : 'this browser\'s WebAssembly has no SIMD, which the module needs (Chrome or Edge 91, Firefox 89, ' +
      'Safari 16.4 or later have it)';
  return `cannot load the WebAssembly module: ${why}`;
}

function errorMessage(e) {
  return {
    message: e instanceof Error ? e.message : String(e),
    // Every field refused at once where the module lists them.
    field: e && e.fields !== undefined ? e.fields : e && e.field !== undefined ? e.field : null,
  };
}

function curve(g) {
  return { x: g.displacements_m(), f: g.forces_n() };
}

// Set by a `stop` message; read between chunks.
let stopRequested = false;

// Lets the worker's queued messages (a `stop`) be handled: a message to
// itself, which unlike setTimeout is not clamped to 4 ms.
function yieldToMessages() {
  return new Promise((resolve) => {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => resolve();
    channel.port2.postMessage(null);
  });
}

async function run(inputs) {
  stopRequested = false;
  const t0 = performance.now();
  let g;
  try {
    g = new Granule(inputs);
  } catch (e) {
    postMessage({ kind: 'error', ...errorMessage(e) });
    return;
  }
  // The parameters this run uses: the type's preset with the inputs given
  // over it (what the Granule was built from), for the page to show.
  const params = preset(inputs.type ?? 'B2');
  for (const k of Object.keys(params)) if (inputs[k] !== undefined) params[k] = inputs[k];
  params.diameter_m = g.diameter_m();
  postMessage({
    kind: 'start',
    quads: g.surface_quads(),
    positions: g.positions(),
    diameter: g.diameter_m(),
    params,
  });
  let failure = null;
  // The positions after the last chunk that succeeded: after a failure the
  // granule's own are not a state to show.
  let positions = g.positions();
  let cancelled = false;
  try {
    while (!g.finished()) {
      await yieldToMessages();
      if (stopRequested) {
        cancelled = true;
        break;
      }
      const progress = g.step(CHUNK);
      positions = g.positions();
      postMessage({
        kind: 'progress',
        progress,
        strain: g.strain(),
        steps: g.steps(),
        positions,
        ...curve(g),
      });
    }
  } catch (e) {
    failure = errorMessage(e);
  }
  const slope = g.slope_n_per_m();
  postMessage({
    kind: 'done',
    wallMs: performance.now() - t0,
    sigmaEst: g.sigma_est_pa() ?? null,
    sigmaEff0: g.sigma_eff0_pa(),
    slope: slope ?? null,
    intercept: g.intercept_n() ?? null,
    r2: g.fit_r_squared() ?? null,
    kineticToInternal: g.max_kinetic_to_internal() ?? null,
    quasiStatic: g.quasi_static(),
    kineticLimit: g.kinetic_to_internal_limit(),
    massScaling: g.mass_scaling(),
    steps: g.steps(),
    strain: g.strain(),
    diameter: g.diameter_m(),
    positions,
    csv: g.csv(),
    failure,
    cancelled,
    ...curve(g),
  });
  g.free();
}

onmessage = async (ev) => {
  const msg = ev.data;
  try {
    await ready;
  } catch (e) {
    postMessage({ kind: 'error', message: loadFailure(e) });
    return;
  }
  if (msg.cmd === 'hello') {
    postMessage({ kind: 'ready', version: version(), columns: csvColumns() });
  } else if (msg.cmd === 'preset') {
    try {
      postMessage({ kind: 'preset', type: msg.type, chosen: msg.chosen === true, values: preset(msg.type) });
    } catch (e) {
      postMessage({ kind: 'error', ...errorMessage(e) });
    }
  } else if (msg.cmd === 'run') {
    await run(msg.inputs);
  } else if (msg.cmd === 'check') {
    // The inputs the page could read, those it could not as NaN: every
    // refusal, `{ message, field }` each (none: all in range).
    let refused;
    try {
      refused = check(msg.inputs);
    } catch (e) {
      refused = [{ message: errorMessage(e).message, field: e.field ?? null }];
    }
    postMessage({ kind: 'checked', refused, id: msg.id });
  } else if (msg.cmd === 'stop') {
    stopRequested = true;
  }
};
