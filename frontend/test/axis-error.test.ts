// The axis-error banner's text (format.ts axisError).
import { describe, expect, it } from 'vitest';
import { axisError } from '../src/format';

describe('axis error text', () => {
  const st = (state: string, error_id: number, drive_fault = false) => ({ state, error_id, drive_fault }) as Parameters<typeof axisError>[0];
  it('an error number: its entry of the error table', () => {
    expect(axisError(st('error_stop', 0x7010, true))).toEqual({ hex: '0x7010', code: 'drive_fault', text: 'drive fault', driveCode: null });
    expect(axisError(st('error_stop', 0x4550))).toMatchObject({ hex: '0x4550', code: 'following_error' });
  });
  it('error stop without a number: no "0x0000 … not in the error table"', () => {
    expect(axisError(st('error_stop', 0))).toEqual({ hex: null, code: null, text: 'error stop (no error number)', driveCode: null });
    expect(axisError(st('error_stop', 0, true))!.text).toBe('drive fault (no error number)');
  });
  it("a drive's own code (CiA-402 0x603F) in hex beside the error; the bus's error by its entry", () => {
    const fault = { state: 'error_stop', error_id: 0x7010, drive_fault: true, drive_error_code: 0x2310 } as Parameters<typeof axisError>[0];
    expect(axisError(fault)).toEqual({ hex: '0x7010', code: 'drive_fault', text: 'drive fault', driveCode: '0x2310' });
    const bus = { state: 'error_stop', error_id: 0x70a0, drive_fault: false, drive_error_code: 0 } as Parameters<typeof axisError>[0];
    expect(axisError(bus)).toMatchObject({ hex: '0x70A0', code: 'bus_error', driveCode: null });
    expect(axisError(bus)!.text).toMatch(/^the drive bus lost the drive/);
  });
  it('no error: nothing', () => {
    expect(axisError(st('standstill', 0))).toBeNull();
    expect(axisError(null)).toBeNull();
  });
});
