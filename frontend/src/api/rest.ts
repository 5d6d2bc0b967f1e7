// REST client: JSON in and out, problem+json errors as ApiError with field errors by path.
import type { Problem } from './types';
import { clientId } from '../auth/client-id';

export class ApiError extends Error {
  readonly status: number;
  readonly problem: Problem | null;
  /** Field path (`dynamics.jerk`, `value`, `velocity`) → message. */
  readonly fields: Record<string, string>;

  constructor(status: number, problem: Problem | null, message?: string) {
    super(message ?? problem?.detail ?? `HTTP ${status}`);
    this.status = status;
    this.problem = problem;
    this.fields = fieldErrors(problem);
  }

  get code(): string {
    return this.problem?.code ?? (this.status === 0 ? 'network_error' : `http_${this.status}`);
  }
}

/**
 * Field errors of a problem, by field path. Type errors of the JSON body come as field
 * `body` (or `params` over the websocket) with serde's message; `missing field `x`` and
 * `unknown field `x`` are mapped to the field they name.
 */
export function fieldErrors(p: Problem | null | undefined): Record<string, string> {
  const out: Record<string, string> = {};
  for (const e of p?.errors ?? []) {
    let field = e.field;
    if (field === 'body' || field === 'params') {
      const m = /(?:missing|unknown) field `([^`]+)`/.exec(e.message);
      if (m) field = m[1];
    }
    out[field] = out[field] ? `${out[field]}; ${e.message}` : e.message;
  }
  return out;
}

/** What a number field says when its text is not a number (the field itself and a refused send). */
export const NOT_A_NUMBER = 'enter a number';

/**
 * The JSON paths (`velocity`, `masters[1].gear_ratio`) of the numbers in a body that JSON cannot
 * carry: a text that is not a number parses to NaN, which JSON.stringify would send as null.
 */
export function nonFiniteFields(body: unknown, path = ''): string[] {
  if (typeof body === 'number') return Number.isFinite(body) ? [] : [path || 'body'];
  if (Array.isArray(body)) return body.flatMap((v, i) => nonFiniteFields(v, `${path}[${i}]`));
  if (body && typeof body === 'object') return Object.entries(body).flatMap(([k, v]) => nonFiniteFields(v, path ? `${path}.${k}` : k));
  return [];
}

/**
 * A request that was not sent because a number field holds something else: a 422 made here,
 * its fields saying "enter a number" as the server's would name them, so forms show it where
 * they show the server's field errors.
 */
export class NotSentError extends ApiError {
  constructor(paths: string[]) {
    super(422, {
      type: 'about:blank',
      title: 'Not sent',
      status: 422,
      code: 'not_a_number',
      detail: `${NOT_A_NUMBER} in ${paths.join(', ')}`,
      errors: paths.map((field) => ({ field, message: NOT_A_NUMBER })),
    });
  }
}

export function isProblem(x: unknown): x is Problem {
  return !!x && typeof x === 'object' && typeof (x as Problem).status === 'number' &&
    typeof (x as Problem).code === 'string';
}

export const BASE = '/api/v1';

/** `/axes` → `/api/v1/axes`; absolute server paths (`/api/…`, `/openapi.json`) stay. */
export function url(path: string): string {
  return path.startsWith('/api/') || path.startsWith('/openapi') ? path : BASE + path;
}

/**
 * Every request that changes something (POST, PUT, DELETE …) is declared JSON, also one without
 * a body: motiond refuses anything else with 415, because a page of another site may send
 * other types to it without asking the browser first (docs/security.md). Every request names
 * this tab (`X-Client-Id`, auth/client-id.ts): the control of the machine is held by a tab.
 */
export function headers(method: string): Record<string, string> {
  const safe = ['GET', 'HEAD', 'OPTIONS'].includes(method.toUpperCase());
  return safe ? { 'X-Client-Id': clientId() } : { 'Content-Type': 'application/json', 'X-Client-Id': clientId() };
}

/**
 * Requests whose 401 is the answer to what the user typed (a wrong password), not the end of
 * the session.
 */
const CREDENTIAL_PATHS = new Set(['/auth/login', '/api/v1/auth/login']);

let unauthorized: ((e: ApiError) => void) | null = null;

/**
 * Called with every 401 (no valid session while authentication is on) of a request other than
 * the login itself: the session has ended, the login page comes back (main.tsx).
 */
export function onUnauthorized(handler: ((e: ApiError) => void) | null): void {
  unauthorized = handler;
}

export async function api<T>(method: string, path: string, body?: unknown): Promise<T> {
  // Never send a number field's "abc" as null (the server would answer with serde's words).
  const bad = nonFiniteFields(body);
  if (bad.length) throw new NotSentError(bad);
  let res: Response;
  try {
    res = await fetch(url(path), {
      method,
      headers: headers(method),
      body: body === undefined ? undefined : JSON.stringify(body),
    });
  } catch (e) {
    throw new ApiError(0, null, `server not reachable (${(e as Error).message})`);
  }
  const text = await res.text();
  let json: unknown = null;
  if (text) {
    try {
      json = JSON.parse(text);
    } catch {
      json = null;
    }
  }
  if (!res.ok) {
    const e = new ApiError(res.status, isProblem(json) ? json : null, isProblem(json) ? undefined : `HTTP ${res.status} ${text.slice(0, 200)}`);
    if (res.status === 401 && !CREDENTIAL_PATHS.has(path)) unauthorized?.(e);
    throw e;
  }
  return json as T;
}

export const get = <T>(path: string) => api<T>('GET', path);
export const post = <T>(path: string, body: unknown = {}) => api<T>('POST', path, body);
export const put = <T>(path: string, body: unknown) => api<T>('PUT', path, body);
export const del = <T>(path: string) => api<T>('DELETE', path);

export const enc = encodeURIComponent;
