// The wasm module in Node against granbed-cli: the same curve bit for bit
// (the CSV is round-trip exact), the same σ_est and σ_y,eff0.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { WWW, native } from './common.js';
import { advice, MM_UNITS, PA_UNITS, parseDecimal, tick } from '../www/format.js';

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
    [{ type: 'B2', poisson_ratio: 0.6 }, 'poisson_ratio', /-1 < ν < 0\.5$/],
    [{ type: 'B2', eta0: 0.1 }, 'eta0', /ηc < η0 ≤ 1$/],
    [{ type: 'B2', diameter_m: 0 }, 'diameter_m', /1e-6 ≤ d ≤ 1 m$/],
    [{ type: 'B2', diameter_mm: 0.0001 }, 'diameter_mm', /d \(mm\) = 0\.0001 .*0\.001 ≤ d ≤ 1000 mm$/],
    [{ type: 'B2', diameter_mm: 2000 }, 'diameter_mm', /0\.001 ≤ d ≤ 1000 mm$/],
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
  assert.throws(() => new pkg.Granule({ diameter_m: 1e-3, diameter_mm: 1 }), /not both/);
});

test('a diameter in mm is the same run as in m', () => {
  const a = new pkg.Granule({ type: 'B2', mesh: '4x1', diameter_mm: 2 });
  const b = new pkg.Granule({ type: 'B2', mesh: '4x1', diameter_m: 2e-3 });
  assert.equal(a.diameter_m(), b.diameter_m());
  a.free();
  b.free();
});

test('typed numbers: a decimal point is read, a comma or junk refused', () => {
  for (const [text, v] of [['0.3', 0.3], [' .5 ', 0.5], ['3e4', 3e4], ['-1E-2', -0.01], ['7', 7], ['2.', 2]]) {
    assert.equal(parseDecimal(text, 'x', 'f'), v, text);
  }
  assert.throws(() => parseDecimal('0,3', 'μ', 'friction'), (e) => e.field === 'friction' && /decimal comma: write 0\.3/.test(e.message));
  // A comma before three digits is not taken for a decimal comma: the fix
  // of 30,000 Pa was once 30.000, a thousandth of what was meant.
  assert.throws(() => parseDecimal('30,000', 'σy', 'yield_stress_pa'),
    (e) => /“30,000” has a comma: write 30000 if it separates thousands, or 30\.000 if it is a decimal comma$/.test(e.message));
  assert.throws(() => parseDecimal('1,000,000', 'E', 'youngs_modulus_pa'), /“1,000,000” has commas: write 1000000 \(no thousands separators\)$/);
  assert.throws(() => parseDecimal('2,5', 'x', 'f'), /decimal comma: write 2\.5 \(with a point\)$/);
  assert.throws(() => parseDecimal('0,300', 'x', 'f'), /decimal comma: write 0\.300 \(with a point\)$/);
  for (const bad of ['', '1.5.2', '0x10', 'Infinity', '1,000.5', 'abc', '1e', '-inf']) {
    assert.throws(() => parseDecimal(bad, 'x', 'f'), /“.*” (is empty|is not a number)/, bad);
  }
  // inf as typed (the kernel judges the field: σy takes it); a number too
  // large for a double is refused, not read as infinity.
  for (const inf of ['inf', '+inf', ' INF ']) assert.equal(parseDecimal(inf, 'x', 'f'), Infinity, inf);
  assert.throws(() => parseDecimal('1e400', 'σy', 'yield_stress_pa'), (e) => e.field === 'yield_stress_pa' && /too large for a number .* write inf/.test(e.message));
  assert.throws(() => parseDecimal('-1e309', 'ν', 'poisson_ratio'), (e) => /too large for a number \(the largest is about 1\.8e308\)$/.test(e.message));
  // Below the smallest double: refused, not read as 0; zero itself is read.
  assert.throws(() => parseDecimal('1e-400', 'μ', 'friction'), /too small for a number/);
  for (const zero of ['0', '0.0', '-0', '0e5', '.0']) assert.equal(parseDecimal(zero, 'x', 'f'), 0, zero);
});

test('a stress may be typed with its unit, read exactly as the plain number', () => {
  // The unit scales the decimal text (1.1 kPa is 1.1e3), so the double is
  // the one typing 1100 gives, not 1.1 * 1000 = 1100.0000000000002.
  const cases = [['30 kPa', 30000], ['1.1kPa', 1100], ['1.5 MPa', 1.5e6], ['2e-3 GPa', 2e6], ['0.07 MPa', 70000],
    ['30000 Pa', 30000], ['inf Pa', Infinity], ['1e6', 1e6], ['-0 kPa', 0]];
  for (const [text, v] of cases) assert.equal(parseDecimal(text, 'σy', 'yield_stress_pa', PA_UNITS), v, text);
  assert.equal(parseDecimal('2 mm', 'd', 'diameter_mm', MM_UNITS), 2);
  // Other capitals are refused with the spelling (mPa would be a
  // millipascal, a billionth of a megapascal); a field without a unit
  // takes none.
  assert.throws(() => parseDecimal('1 mPa', 'E', 'youngs_modulus_pa', PA_UNITS),
    (e) => e.field === 'youngs_modulus_pa' && /“1 mPa” has the unit “mPa”: mPa is millipascals: write 1 MPa/.test(e.message));
  assert.throws(() => parseDecimal('30 kpa', 'σy', 'f', PA_UNITS), /has the unit “kpa”: write 30 kPa$/);
  assert.throws(() => parseDecimal('30 N', 'σy', 'f', PA_UNITS), /is not a number such as 0\.3 or 3e4 \(units: Pa, kPa, MPa, GPa\)$/);
  for (const bad of ['infinity', '1ekPa', '1e kPa']) {
    assert.throws(() => parseDecimal(bad, 'σy', 'f', PA_UNITS), /is not a number/, bad);
  }
  // Exponents beyond any double's: 0 and too small, not misread.
  assert.equal(parseDecimal('0e9999999999999999999999 kPa', 'σy', 'f', PA_UNITS), 0);
  assert.throws(() => parseDecimal('1e-9999999999999999999999 kPa', 'σy', 'f', PA_UNITS), /too small/);
  assert.throws(() => parseDecimal('1e9999999999999999999999 kPa', 'σy', 'f', PA_UNITS), /too large/);
  // A typographic minus is a minus; spaces between thousands get their fix.
  assert.equal(parseDecimal('\u22120.5', 'ν', 'poisson_ratio'), -0.5);
  assert.equal(parseDecimal('1e\u22123 GPa', 'E', 'f', PA_UNITS), 1e6);
  assert.throws(() => parseDecimal('30 000', 'σy', 'f'), /“30 000” has spaces: write 30000 \(no thousands separators\)$/);
  assert.throws(() => parseDecimal('1 000 000 Pa', 'E', 'f', PA_UNITS), /has spaces: write 1000000 Pa \(no/);
  // A comma's fix keeps the unit: 3.5, as told, would be pascals.
  assert.throws(() => parseDecimal('30,000 Pa', 'σy', 'f', PA_UNITS), /has a comma: write 30000 Pa if .* or 30\.000 Pa if/);
  assert.throws(() => parseDecimal('3,5 kPa', 'σy', 'f', PA_UNITS), /has a decimal comma: write 3\.5 kPa \(with a point\)$/);
  assert.throws(() => parseDecimal('1e305 GPa', 'E', 'f', PA_UNITS), /too large for a number/);
  assert.throws(() => parseDecimal('0.3 kPa', 'ν', 'poisson_ratio'), /is not a number such as 0\.3 or 3e4$/);
});

test('every input out of range is named at once, the diameter in mm too', () => {
  assert.throws(
    () => new pkg.Granule({ type: 'B2', friction: 20, poisson_ratio: 0.6, diameter_mm: 5000 }),
    (e) => {
      assert.deepEqual(e.fields, ['poisson_ratio', 'friction', 'diameter_mm']);
      assert.equal(e.field, 'poisson_ratio');
      const lines = e.message.split('\n');
      assert.equal(lines.length, 3, e.message);
      assert.match(lines[1], /μ = 20 .*0 ≤ μ ≤ 10$/);
      assert.match(lines[2], /d \(mm\) = 5000 .*0\.001 ≤ d ≤ 1000 mm$/);
      return true;
    },
  );
  // check() judges without building a run; a NaN stands in for a field a
  // page could not read and is refused like any other.
  assert.deepEqual(pkg.check({ type: 'B2', mesh: '4x1', poisson_ratio: 0.3 }), []);
  const refused = pkg.check({ type: 'B2', poisson_ratio: 0.6, youngs_modulus_pa: NaN, diameter_mm: NaN });
  assert.deepEqual(refused.map((r) => r.field), ['youngs_modulus_pa', 'poisson_ratio', 'diameter_mm']);
  assert.match(refused[1].message, /^Poisson's ratio ν = 0\.6 is not allowed/);
  assert.throws(() => pkg.check({ type: 'B2', nu: 0.3 }), /unknown input `nu`/);
  // One bad input: `fields` lists it alone.
  assert.throws(() => new pkg.Granule({ type: 'B2', cp: -1 }), (e) => e.field === 'cp' && e.fields.length === 1);
});

test('a stopped run gets advice for the kernel\'s failures', () => {
  // The messages of ElementFailure::InvertedDeformation and of
  // SceneError::Unstable and its kin (kernel/src/scene/platens.rs).
  for (const message of [
    'granule step 120: element 129: inverted element: det F = -2.96e-1',
    'the motion became unstable at step 88 (node 17 moved 3e-4 m in one step)',
    'element 4 folded or inverted (Jacobian ratio -0.2)',
    'non-finite position of node 3',
  ]) {
    assert.match(advice(message), /too soft for the platen speed/, message);
  }
  assert.equal(advice('the output directory cannot be written'), '');
});

test('tick labels fit the margin at any scale', () => {
  assert.equal(tick(0), '0');
  assert.equal(tick(0.25), '0.25');
  assert.equal(tick(12000), '12000');
  assert.equal(tick(1.5e6), '1.5e+6');
  assert.equal(tick(2e7), '2e+7');
  assert.equal(tick(2e-9), '2e-9');
  for (const v of [3e-12, 4.5e-5, 0.001, 1, 99999, 1e5, 1.8e10]) assert.ok(tick(v).length <= 7, `${v}: ${tick(v)}`);
});

test('the SIMD probe is a valid module here, and one wrong byte makes it invalid', async () => {
  const { SIMD_PROBE, hasSimd } = await import('../www/simd.js');
  assert.equal(hasSimd(), true);
  // The splat's opcode cut off: no longer a valid module (the probe is
  // judged on its SIMD instruction, not accepted whatever it holds).
  const broken = SIMD_PROBE.slice();
  broken[broken.length - 2] = 0xff;
  assert.equal(WebAssembly.validate(broken), false);
});

test('presets are the kernel types', () => {
  const p = pkg.preset('c3');
  assert.equal(p.yield_stress_pa, 100e3);
  assert.equal(p.eta0, 1);
  assert.equal(p.diameter_m, 1e-3);
});
