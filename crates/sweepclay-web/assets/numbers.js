// Numbers as potters type them (docs/MODELER.md): a decimal comma is a
// decimal point; anything else that is not a plain number is refused.

/**
 * A number as a potter types it: "1.5", or with a decimal comma "1,5";
 * anything else (two separators, letters, "1,5,0") is NaN, never a
 * silent 15.
 */
export function parseDecimal(text) {
  const t = String(text).trim().replace(/^(-?\d*),(\d+)$/, '$1.$2');
  return /^-?(\d+\.?\d*|\.\d+)(e-?\d+)?$/i.test(t) ? Number(t) : NaN;
}

/** A length as the page shows it: at most two decimals, no trailing zeros. */
export const fmtMm = (v) => String(Number(v.toFixed(2)));


/**
 * An extrusion calibration (E per mm³) as the page shows it: five
 * significant digits, no trailing zeros (0.41575168807678786 → 0.41575).
 */
export const fmtE = (v) => String(Number(Number(v).toPrecision(5)));
