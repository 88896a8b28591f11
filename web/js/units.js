// SI values as a person reads them: Young's modulus in kPa, density in kg/m³, lengths in mm,
// angles in degrees; and a value with its standard deviation to the digits the deviation allows.
import { Unit } from './protocol.js';

// Per SI unit of the protocol: the factor to the unit shown and its symbol.
const SHOWN = {
  [Unit.Pascal]: { scale: 1e-3, symbol: 'kPa' },
  [Unit.None]: { scale: 1, symbol: '' },
  [Unit.KilogramPerCubicMetre]: { scale: 1, symbol: 'kg/m³' },
  [Unit.Metre]: { scale: 1e3, symbol: 'mm' },
  [Unit.Radian]: { scale: 180 / Math.PI, symbol: '°' },
};

// How `unit` is shown: {scale, symbol}; an unknown unit as it came.
export function shownUnit(unit) {
  return SHOWN[unit] ?? { scale: 1, symbol: unit };
}

// Decimals that keep two significant digits of `spread` (a standard deviation, in the unit
// shown); three significant digits of `value` when there is no spread.
export function decimalsFor(value, spread) {
  const basis = spread > 0 && Number.isFinite(spread) ? spread : Math.abs(value) / 10;
  if (!(basis > 0) || !Number.isFinite(basis)) return 2;
  return Math.min(6, Math.max(0, 1 - Math.floor(Math.log10(basis))));
}

// `value` (SI, in `unit`) as shown, with `decimals` or enough for three significant digits.
export function formatValue(value, unit, decimals) {
  if (value === null || value === undefined || !Number.isFinite(value)) return '–';
  const shown = value * shownUnit(unit).scale;
  return shown.toFixed(decimals ?? decimalsFor(shown));
}

// "300.2 ± 4.1": value and standard deviation (SI, in `unit`) in the unit shown, no symbol.
export function formatWithDeviation(value, deviation, unit) {
  const { scale } = shownUnit(unit);
  const decimals = decimalsFor(value * scale, deviation * scale);
  const spread = deviation === null || deviation === undefined ? '–' : (deviation * scale).toFixed(decimals);
  return `${formatValue(value, unit, decimals)} ± ${spread}`;
}
