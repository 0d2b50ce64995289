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
// field takes it: σy does, for a purely elastic granule). Anything else is
// refused, a decimal comma with its own message, never read as another
// number; so is a number too large for a double (1e400), which would
// otherwise be read as infinity without a word.
const DECIMAL = /^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;
const INFINITY = /^\+?inf$/i;

export function parseDecimal(text, label, field) {
  const t = text.trim();
  if (INFINITY.test(t)) return Infinity;
  let why;
  if (DECIMAL.test(t)) {
    const v = Number(t);
    const zero = /^[+-]?[0.]*([eE].*)?$/.test(t);
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
      : commaHint(t) ?? 'is not a number such as 0.3 or 3e4';
  }
  throw Object.assign(new Error(`${label}: “${t}” ${why}`), { field });
}

// What a number typed with commas meant, said as its fix, or undefined: a
// comma before exactly three digits (30,000, as Pa are typed) may separate
// thousands or be a decimal comma, and which one is the student's to say
// (the page must not read 30,000 Pa as 30 Pa); several such groups
// (1,000,000) separate thousands; any other single comma (0,5, 0,300: no
// group of thousands starts with 0) is a decimal comma.
function commaHint(t) {
  if (/^[+-]?[1-9]\d{0,2},\d{3}$/.test(t)) {
    return `has a comma: write ${t.replace(',', '')} if it separates thousands, or ${t.replace(',', '.')} ` +
      'if it is a decimal comma';
  }
  if (/^[+-]?[1-9]\d{0,2}(,\d{3}){2,}$/.test(t)) return `has commas: write ${t.replaceAll(',', '')} (no thousands separators)`;
  if (/^[+-]?\d*,\d+$/.test(t)) return `has a decimal comma: write ${t.replace(',', '.')} (with a point)`;
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
