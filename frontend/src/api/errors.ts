import { ERROR_TABLE } from './errors.gen';

export interface ErrorInfo {
  id: number;
  hex: string;
  code: string;
  text: string;
}

const byId = new Map(ERROR_TABLE.map(([id, code, text]) => [id, { id, code, text }]));
const byCode = new Map(ERROR_TABLE.map(([id, code, text]) => [code, { id, code, text }]));

export function hexId(id: number): string {
  return '0x' + id.toString(16).toUpperCase().padStart(4, '0');
}

/** The error table entry of an `error_id` (docs/errors.md), or a placeholder for unknown numbers. */
export function errorInfo(id: number): ErrorInfo {
  const e = byId.get(id);
  return e
    ? { ...e, hex: hexId(id) }
    : { id, hex: hexId(id), code: 'unknown', text: `error ${hexId(id)} (not in the error table)` };
}

export function errorByCode(code: string): ErrorInfo | undefined {
  const e = byCode.get(code);
  return e && { ...e, hex: hexId(e.id) };
}
