// What a blank field of a block stands for: the parameter's value in force as the placeholder
// (what the axis uses now — not "#1012"), its number and name in the tooltip.
import { describe, expect, it } from 'vitest';
import { paramDefault, paramText } from '../src/ui/axis/axis-params';
import type { ParameterResource } from '../src/api/types';

const p = (number: number, name: string, value: number | boolean, unit_text = '') => [number, { number, name, value, unit_text } as ParameterResource] as const;
const params = new Map([p(1012, 'AxisCalibrationVelocityForward', 30, 'mm/s'), p(1004, 'AxisAcc', 2500.000000000001, 'mm/s²'), p(1073, 'AxisEncoderHomingInvDirCamSearch', false)]);

describe('paramDefault', () => {
  it('the value in force as the placeholder, the number and name in the tooltip', () => {
    expect(paramDefault(params, 1012)).toEqual({ placeholder: '30', title: "blank = the axis's #1012 AxisCalibrationVelocityForward, now 30 mm/s" });
    expect(paramDefault(params, 1004).placeholder).toBe('2500');
  });
  it('a value shown in words (a direction from a BOOL)', () => {
    expect(paramText(params, 1073)).toBe('off');
    expect(paramDefault(params, 1073, 'positive')).toEqual({ placeholder: 'positive', title: "blank = the axis's #1073 AxisEncoderHomingInvDirCamSearch, now positive" });
  });
  it('while the parameters load: no number shown as if it were a value', () => {
    expect(paramDefault(null, 1012)).toEqual({ placeholder: '', title: "blank = the axis's #1012" });
  });
});
