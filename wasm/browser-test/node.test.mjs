// The wasm module in Node against granbed-cli: the same curve bit for bit
// (the CSV is round-trip exact), the same σ_est and σ_y,eff0.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { WWW, native } from './common.js';

const pkg = await import(join(WWW, 'pkg', 'granbed_wasm.js'));
pkg.initSync({ module: readFileSync(join(WWW, 'pkg', 'granbed_wasm_bg.wasm')) });

function runToEnd(inputs) {
  const t0 = performance.now();
  const g = new pkg.Granule(inputs);
  while (!g.finished()) g.step(1000);
  const result = {
    seconds: (performance.now() - t0) / 1e3,
    csv: g.csv(),
    sigmaEst: g.sigma_est_pa(),
    sigmaEff0: g.sigma_eff0_pa(),
    slope: g.slope_n_per_m(),
    steps: g.steps(),
    error: g.error(),
  };
  g.free();
  return result;
}

function compare(inputs, env) {
  const ref = native(env);
  const got = runToEnd(inputs);
  assert.equal(got.error, undefined);
  assert.equal(got.sigmaEst, ref.summary.sigma_est_pa);
  assert.equal(got.sigmaEff0, ref.summary.sigma_eff0_pa);
  assert.equal(got.slope, ref.summary.slope_n_per_m);
  assert.equal(got.steps, ref.summary.steps);
  assert.equal(got.csv, ref.csv, 'the CSV differs from force_displacement.csv');
  const ratio = got.seconds / ref.summary.wall_time_s;
  console.log(
    `${inputs.type} ${inputs.mesh}: sigma_est ${got.sigmaEst} Pa (native ${ref.summary.sigma_est_pa}), ` +
      `${got.steps} steps, wasm in Node ${got.seconds.toFixed(2)} s, native ${ref.summary.wall_time_s.toFixed(2)} s, ` +
      `ratio ${ratio.toFixed(2)}`,
  );
}

test('coarse B2 (4x1) to 40 % equals granbed-cli bit for bit', () => {
  compare({ type: 'B2', mesh: '4x1' }, 'GRANBED_NATIVE_B2_COARSE');
});

test('standard B2 (8x2) to 40 % equals granbed-cli bit for bit', () => {
  compare({ type: 'B2', mesh: '8x2' }, 'GRANBED_NATIVE_B2');
});

test('bad inputs throw an Error naming the field and its range', () => {
  const cases = [
    [{ type: 'B2', poisson_ratio: 0.6 }, 'poisson_ratio', /-1 < nu < 0\.5/],
    [{ type: 'B2', eta0: 0.1 }, 'eta0', /eta_c < eta0 <= 1/],
    [{ type: 'B2', diameter_m: 0 }, 'diameter_m', /1e-6 <= d <= 1 m/],
    [{ type: 'D4' }, 'type', /A1, A2/],
  ];
  for (const [inputs, field, allowed] of cases) {
    assert.throws(
      () => new pkg.Granule(inputs),
      (e) => e instanceof Error && e.field === field && allowed.test(e.message),
      JSON.stringify(inputs),
    );
  }
  assert.throws(() => new pkg.Granule({ type: 'B2', nu: 0.3 }), /unknown input `nu`/);
  assert.throws(() => new pkg.Granule({ type: 'B2', cp: 'x' }), /must be a number/);
  assert.throws(() => new pkg.Granule({ type: 'B2', mesh: '3x1' }), /3x1/);
  assert.throws(() => new pkg.Granule(42), /must be an object/);
});

test('presets are the kernel types', () => {
  const p = pkg.preset('c3');
  assert.equal(p.yield_stress_pa, 100e3);
  assert.equal(p.eta0, 1);
  assert.equal(p.diameter_m, 1e-3);
});
