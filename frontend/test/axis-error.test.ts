// The axis-error banner's text (format.ts axisError).
import { describe, expect, it } from 'vitest';
import { axisError } from '../src/format';

describe('axis error text', () => {
  const st = (state: string, error_id: number, drive_fault = false) => ({ state, error_id, drive_fault }) as Parameters<typeof axisError>[0];
  it('an error number: its entry of the error table', () => {
    expect(axisError(st('error_stop', 0x7010, true))).toEqual({ hex: '0x7010', code: 'drive_fault', text: 'drive fault' });
    expect(axisError(st('error_stop', 0x4550))).toMatchObject({ hex: '0x4550', code: 'following_error' });
  });
  it('error stop without a number: no "0x0000 … not in the error table"', () => {
    expect(axisError(st('error_stop', 0))).toEqual({ hex: null, code: null, text: 'error stop (no error number)' });
    expect(axisError(st('error_stop', 0, true))!.text).toBe('drive fault (no error number)');
  });
  it('no error: nothing', () => {
    expect(axisError(st('standstill', 0))).toBeNull();
    expect(axisError(null)).toBeNull();
  });
});
