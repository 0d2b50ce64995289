// Number formats and the parsing of typed numbers: pure functions of the
// page, shared with the tests (the browser test compares the shown text with
// the native value printed the same way).

/** A stress in Pa as kPa with six significant digits, e.g. "44.6423 kPa". */
export function formatStress(pa) {
  return pa === null || pa === undefined || !Number.isFinite(pa) ? 'n/a' : `${(pa / 1e3).toPrecision(6)} kPa`;
}

/** A slope in N/m with six significant digits. */
export function formatSlope(nPerM) {
  return nPerM === null || nPerM === undefined || !Number.isFinite(nPerM) ? 'n/a' : `${nPerM.toPrecision(6)} N/m`;
}

// A decimal number as typed: digits with a decimal point and an optional
// exponent (0.3, .5, 3e4, -1E-2), or inf (the kernel judges whether the
// field takes it: σy does, for a purely elastic granule), and for a field
// with a unit the unit or a multiple of it after the number (`units`, e.g.
// PA_UNITS: 30 kPa, 1.5MPa). Anything else is refused, a decimal comma
// with its own message, never read as another number; so is a number too
// large for a double (1e400), which would otherwise be read as infinity
// without a word.
const DECIMAL = /^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;
const INFINITY = /^\+?inf$/i;

/** The units a stress field takes, with their powers of ten. */
export const PA_UNITS = { Pa: 0, kPa: 3, MPa: 6, GPa: 9 };
/** The unit a length in mm may be followed by. */
export const MM_UNITS = { mm: 0 };

export function parseDecimal(text, label, field, units = null) {
  // A typographic minus (−, as a word processor writes it) is a minus.
  const t = text.trim().replace(/\u2212/g, '-');
  const [number, unit] = units ? splitUnit(t, label, field, units) : [t, null];
  if (INFINITY.test(number)) return Infinity;
  let why;
  if (DECIMAL.test(number)) {
    // Scaled by the unit in the decimal text itself (1.1 kPa is read as
    // 1.1e3, exactly the double that 1100 gives), not by a multiplication.
    const power = unit === null ? 0 : units[unit];
    const [mantissa, exponent = '0'] = number.split(/[eE]/);
    const scaled = Number(exponent) + power;
    // (An exponent of a million or more, far beyond any double's, is not
    // written out again, where it could print as 1e+21: the number is then
    // 0 or infinite whatever the unit.)
    const v = power === 0 ? Number(number)
      : Math.abs(scaled) < 1e6 ? Number(`${mantissa}e${scaled}`) : Number(number) * 10 ** power;
    const zero = /^[+-]?[0.]*([eE].*)?$/.test(number);
    // (-0 is read as 0.)
    if (Number.isFinite(v) && (v !== 0 || zero)) return v === 0 ? 0 : v;
    why = v === 0
      ? 'is too small for a number (the smallest is about 5e-324; write 0 for zero)'
      : v > 0
        ? 'is too large for a number (the largest is about 1.8e308; write inf for infinity)'
        : 'is too large for a number (the largest is about 1.8e308)';
  } else {
    why = t === ''
      ? 'is empty'
      : separatorHint(number, unit) ?? `is not a number such as 0.3 or 3e4${units ? ` (units: ${Object.keys(units).join(', ')})` : ''}`;
  }
  throw Object.assign(new Error(`${label}: “${t}” ${why}`), { field });
}

// The number and the unit of `t` ("30 kPa" → ["30", "kPa"]; no unit: [t,
// null]). A unit written in other capitals is refused with the spelling
// it takes (mPa would be millipascals, kpa is not a unit); other letters
// are left to be refused as no number.
function splitUnit(t, label, field, units) {
  const m = /^(.*?\d|.*?inf)\s*([A-Za-zµ]+)$/i.exec(t);
  if (!m || INFINITY.test(t)) return [t, null];
  const [, number, unit] = m;
  if (Object.prototype.hasOwnProperty.call(units, unit)) return [number.trim(), unit];
  const known = Object.keys(units);
  const meant = known.find((u) => u.toLowerCase() === unit.toLowerCase());
  // Letters that are no unit in any capitals (1e, 1ekPa, infinity): not a
  // number, said as such.
  if (!meant) return [t, null];
  const hint = unit === 'mPa'
    ? `mPa is millipascals: write ${number.trim()} MPa for megapascals, or the millipascals in Pa (1 mPa = 0.001 Pa)`
    : `write ${number.trim()} ${meant}`;
  throw Object.assign(new Error(`${label}: “${t}” has the unit “${unit}”: ${hint}`), { field });
}

// What a number typed with separators meant, said as its fix, or
// undefined: a comma before exactly three digits (30,000, as Pa are typed)
// may separate thousands or be a decimal comma, and which one is the
// student's to say (the page must not read 30,000 Pa as 30 Pa); several
// such groups (1,000,000) separate thousands; any other single comma (0,5,
// 0,300: no group of thousands starts with 0) is a decimal comma; spaces
// between groups of three digits (30 000) separate thousands.
// The fix keeps the unit typed after the number (`unit`, or null): 3,5 kPa
// is to be written 3.5 kPa, not 3.5 (which would be pascals).
function separatorHint(t, unit = null) {
  const u = unit ? ` ${unit}` : '';
  if (/^[+-]?[1-9]\d{0,2},\d{3}$/.test(t)) {
    return `has a comma: write ${t.replace(',', '')}${u} if it separates thousands, or ${t.replace(',', '.')}${u} ` +
      'if it is a decimal comma';
  }
  if (/^[+-]?[1-9]\d{0,2}(,\d{3}){2,}$/.test(t)) return `has commas: write ${t.replaceAll(',', '')}${u} (no thousands separators)`;
  if (/^[+-]?\d*,\d+$/.test(t)) return `has a decimal comma: write ${t.replace(',', '.')}${u} (with a point)`;
  // Spaces as thousands separators (30 000, as many languages write it).
  if (/^[+-]?[1-9]\d{0,2}([ \u00a0\u202f]\d{3})+$/.test(t)) {
    return `has spaces: write ${t.replace(/[ \u00a0\u202f]/g, '')}${u} (no thousands separators)`;
  }
  return undefined;
}

// A tick label that fits the margin: plain digits for 0.001 ≤ |v| < 1e5,
// else with an exponent (1.5e+6, 2e-9).
export function tick(v) {
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a >= 1e5 || a < 1e-3) return v.toExponential(1).replace('.0e', 'e');
  return +v.toPrecision(4) + '';
}

// What a student can do about a run that stopped: the kernel's message
// names what broke (an element turned inside out or folded, the motion
// unstable, a value not finite); this says what to change, or nothing.
export function advice(message) {
  if (/inverted|folded|unstable|non-finite/.test(message)) {
    return 'The granule deformed too violently for the simulation: it is probably too soft for the platen speed ' +
      '(try a larger E or σy), or the coarse mesh is too coarse for this deformation (try the standard mesh). ';
  }
  if (/converge/.test(message)) {
    return 'The plastic return did not converge: parameters far from the types\' (ν near −1 or 0.5, a σy tiny against E, ' +
      'an extreme cp or ηc) can take it beyond what double precision resolves; move them towards the types\' values. ';
  }
  return '';
}
