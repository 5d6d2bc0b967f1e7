// What a refused request is: problem+json errors as ApiError with field errors by path (thrown by
// the REST client, client.ts, and by the websocket's calls, live/client.ts), and NotSentError,
// the request not sent because a number field holds something else.
import type { Problem } from './types';

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

/**
 * A command not sent because the axis is known to refuse it (a block an axis whose drive runs
 * the profile does not offer, or an input it lacks): a 409 made here with the code and field
 * errors the server's refusal would have, so forms show it where they show the server's.
 */
export class NotOfferedError extends ApiError {
  constructor(code: string, detail: string, fields: Record<string, string> = {}) {
    super(409, {
      type: 'about:blank',
      title: 'Not sent',
      status: 409,
      code,
      detail,
      errors: Object.entries(fields).map(([field, message]) => ({ field, message })),
    });
  }
}

export function isProblem(x: unknown): x is Problem {
  return !!x && typeof x === 'object' && typeof (x as Problem).status === 'number' &&
    typeof (x as Problem).code === 'string';
}
