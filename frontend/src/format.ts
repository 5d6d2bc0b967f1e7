import type { AxisState } from './api/types';
import { errorInfo, hexId } from './api/errors';

export const STATE_LABEL: Record<AxisState, string> = {
  disabled: 'Disabled',
  standstill: 'Standstill',
  homing: 'Homing',
  discrete_motion: 'Discrete motion',
  continuous_motion: 'Continuous motion',
  synchronized_motion: 'Synchronized',
  stopping: 'Stopping',
  error_stop: 'ErrorStop',
};

/** Lamp colour class of a PLCopen state. */
export function stateLamp(s: AxisState | undefined, errorId = 0): string {
  if (errorId || s === 'error_stop') return 'lamp-red';
  switch (s) {
    case 'standstill':
      return 'lamp-green';
    case 'homing':
    case 'discrete_motion':
    case 'continuous_motion':
    case 'synchronized_motion':
      return 'lamp-blue';
    case 'stopping':
      return 'lamp-amber';
    default:
      return 'lamp-off';
  }
}

export function num(v: number | null | undefined, digits: number): string {
  if (v === null || v === undefined || !Number.isFinite(v)) return '—';
  const s = v.toFixed(digits);
  return s === '-' + (0).toFixed(digits) ? (0).toFixed(digits) : s;
}

export const pos = (v: number | null | undefined) => num(v, 4);
export const vel = (v: number | null | undefined) => num(v, 3);
export const acc = (v: number | null | undefined) => num(v, 1);

/** A number for an input field: trims float noise (0.30000000000000004 → 0.3). */
export function inputNum(v: number | null | undefined): string {
  if (v === null || v === undefined || !Number.isFinite(v)) return '';
  return String(Number(v.toPrecision(12)));
}

/** Significant-digit formatting for the scope readouts. */
export function sig(v: number | null | undefined, digits = 6): string {
  if (v === null || v === undefined || !Number.isFinite(v)) return '—';
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e6 || a < 1e-4) return v.toExponential(digits - 1);
  return String(Number(v.toPrecision(digits)));
}

export function time(iso: string | undefined | null): string {
  if (!iso) return '';
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  return d.toLocaleTimeString(undefined, { hour12: false }) + '.' + String(d.getMilliseconds()).padStart(3, '0');
}

/** What the axis-error banner says: the error number's entry, or (error_id 0) why it stopped. */
export interface AxisErrorText {
  hex: string | null;
  code: string | null;
  text: string;
  /** The drive's own code (CiA-402 0x603F, or the bus's) in hex, when it sent one. */
  driveCode: string | null;
}

export function axisError(s: { state: AxisState; error_id: number; drive_fault: boolean; drive_error_code?: number } | null | undefined): AxisErrorText | null {
  if (!s || (!s.error_id && s.state !== 'error_stop')) return null;
  const driveCode = s.drive_error_code ? hexId(s.drive_error_code) : null;
  if (s.error_id) {
    const e = errorInfo(s.error_id);
    return { hex: e.hex, code: e.code, text: e.text + (s.drive_fault && e.code !== 'drive_fault' ? ' · drive fault' : ''), driveCode };
  }
  return { hex: null, code: null, text: s.drive_fault ? 'drive fault (no error number)' : 'error stop (no error number)', driveCode };
}

/** A moment as `YYYY-MM-DD HH:MM` in local time (users, tokens); '' for none. */
export function dateTime(iso: string | undefined | null): string {
  if (!iso) return '';
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  const p = (n: number) => String(n).padStart(2, '0');
  return `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}`;
}
