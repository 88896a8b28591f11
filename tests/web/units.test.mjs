// The calibration table's numbers: SI values in the units a person reads, with as many digits as
// the standard deviation allows (web/js/units.js).
import { describe, it } from 'node:test';
import assert from 'node:assert/strict';
import { formatValue, formatWithDeviation, shownUnit } from '../../web/js/units.js';
import { Unit } from '../../web/js/protocol.js';
import { heldExplanation, verdictOf } from '../../web/js/calibration_panel.js';

describe('readable units', () => {
  it('shows each SI unit of a calibration parameter in its readable unit', () => {
    assert.deepEqual([Unit.Pascal, Unit.None, Unit.KilogramPerCubicMetre, Unit.Metre, Unit.Radian].map((u) => shownUnit(u).symbol),
      ['kPa', '', 'kg/m³', 'mm', '°']);
    assert.equal(formatWithDeviation(301234, 4120, Unit.Pascal), '301.2 ± 4.1');
    assert.equal(formatWithDeviation(0.00391, 0.00012, Unit.Metre), '3.91 ± 0.12');
    assert.equal(formatWithDeviation(0.052, 0.0031, Unit.Radian), '2.98 ± 0.18');
    assert.equal(formatWithDeviation(0.3012, 0.0004, Unit.None), '0.30120 ± 0.00040');
    assert.equal(formatWithDeviation(41.7, 2.3, Unit.KilogramPerCubicMetre), '41.7 ± 2.3');
  });

  it('keeps three significant digits without a deviation, and a dash for no number', () => {
    assert.equal(formatValue(200000, Unit.Pascal), '200');
    assert.equal(formatValue(0.3, Unit.None), '0.300');
    assert.equal(formatValue(null, Unit.Metre), '–');
    assert.equal(formatValue(Number.NaN, Unit.Metre), '–');
    assert.equal(formatWithDeviation(0.004, null, Unit.Metre), '4.00 ± –');
  });

  it('explains a held parameter, also one whose direction the observations do not see at all', () => {
    assert.equal(heldExplanation(0.62),
      'the observations leave it undetermined: ± 0.62 × its typical size (identifiable below 0.1)');
    // The server sends an infinite deviation as null: no exception, a sentence.
    assert.equal(heldExplanation(null), 'the observations do not constrain it at all');
  });

  it('gives each fitted parameter its verdict, prior, trade-off and suggestion', () => {
    const weak = verdictOf({ name: 'youngs_modulus', unit: 'Pa', verdict: 'weakly determined', prior: null,
      implausible: false, trades_off_with: ['density'], suggestion: 'add a frame with a known load' });
    assert.equal(weak.short, 'weak');
    assert.equal(weak.className, 'muted');
    assert.equal(weak.explanation, "Young's modulus: weakly determined\ntrades off with density\nadd a frame with a known load");
    const tilted = verdictOf({ name: 'object_pose.rotation.x', unit: 'rad', verdict: 'determined', prior: 0.0349,
      implausible: true, trades_off_with: [], suggestion: '' });
    assert.equal(tilted.short, 'determined, implausible');
    assert.equal(tilted.className, 'warning');
    assert.match(tilted.explanation, /prior: ± 0\.035 rad around its start\nimplausible: more than 3 prior σ/);
    // From a server that sends no verdict yet: held is not determined, fitted is determined.
    assert.equal(verdictOf({ name: 'density', unit: 'kg/m^3', held: true }).short, 'held');
    assert.equal(verdictOf({ name: 'density', unit: 'kg/m^3', held: false }).short, 'determined');
  });
});
