// Number formats of the results table, shared with the browser test so that
// it compares the shown text with the native value printed the same way.

/** A stress in Pa as kPa with six significant digits, e.g. "44.6423 kPa". */
export function formatStress(pa) {
  return pa === null || pa === undefined || !Number.isFinite(pa) ? 'n/a' : `${(pa / 1e3).toPrecision(6)} kPa`;
}

/** A slope in N/m with six significant digits. */
export function formatSlope(nPerM) {
  return nPerM === null || nPerM === undefined || !Number.isFinite(nPerM) ? 'n/a' : `${nPerM.toPrecision(6)} N/m`;
}
