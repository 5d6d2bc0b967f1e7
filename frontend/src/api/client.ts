// The UI's REST client, typed from the server's OpenAPI document: openapi-fetch on the `paths`
// that `npm run gen:api` generates into schema.d.ts from openapi/openapi.json. A path the API
// does not have, a missing path parameter, a query parameter or a body field that is not the
// operation's (a block's body sent to another block) is a tsc error, and the answer is typed:
//
//   const r = await api.POST('/api/v1/axes/{axis}/move-absolute', {
//     params: { path: { axis: 'x' }, query: { wait: true, timeout_ms: 20000 } },
//     body: { position: 100, velocity: 50 },
//   }); // r: CommandResource
//
// What every request does: it names this tab (`X-Client-Id`: the control of the machine is
// held by a tab); one that changes something (POST, PUT, DELETE) is declared JSON also without a
// body (motiond answers 415 otherwise: docs/security.md), a bodyless POST sends `{}`; the session
// is the browser's cookie (same origin). A number that JSON cannot carry (a field's "abc" parsed
// to NaN) is never sent: NotSentError, a 422 made here. A refusal (problem+json) is thrown as
// ApiError with its field errors, a server that cannot be reached as ApiError status 0, and a 401
// of anything but the login ends the session (onUnauthorized). `signal` aborts a request as
// fetch's does; `?wait=true&timeout_ms=…` of a block is its typed query (api/blocks.ts).
import createClient, { type FetchResponse, type Middleware, type ParamsOption, type RequestBodyOption } from 'openapi-fetch';
import type { paths } from './schema';
import { ApiError, NotSentError, isProblem, nonFiniteFields } from './problem';
import { clientId } from '../auth/client-id';

/** The server's OpenAPI document, served beside the API but not one of its paths. */
interface OpenApiDocument {
  parameters: { query?: never; header?: never; path?: never; cookie?: never };
  get: {
    parameters: { query?: never; header?: never; path?: never; cookie?: never };
    requestBody?: never;
    responses: { 200: { headers: { [name: string]: unknown }; content: { 'application/json': { paths?: Record<string, unknown> } } } };
  };
}

/** Every path the UI calls: the API's, and `/openapi.json`. */
export type Paths = paths & { '/openapi.json': OpenApiDocument };

type Method = 'get' | 'put' | 'post' | 'delete';
type PathOf<M extends Method> = { [P in keyof Paths]: Paths[P] extends { [K in M]: object } ? P : never }[keyof Paths];
/** The operation of a path and method in the generated types. */
export type Operation<P extends keyof Paths, M extends Method> = Paths[P] extends { [K in M]: infer O } ? O : never;

/** What a call takes: the operation's parameters and body, and fetch's `signal` and `keepalive`. */
export type Init<O> = ParamsOption<O> & RequestBodyOption<O> & { signal?: AbortSignal; keepalive?: boolean };
/** The keys of T that are not optional (`{}` has none of them). */
type RequiredKeys<T> = { [K in keyof T]-?: {} extends Pick<T, K> ? never : K }[keyof T];
/** The init is optional where the operation needs no parameter and no body. */
type InitArg<O> = RequiredKeys<Init<O>> extends never ? [init?: Init<O>] : [init: Init<O>];
/** The operation's answer: its success body (JSON), null for one without (204). */
export type Answer<O> = O extends Record<string | number, unknown> ? OrNull<NonNullable<Extract<FetchResponse<O, object, 'application/json'>, { error?: never }>['data']>> : never;
type OrNull<T> = [T] extends [never] ? null : T;

type Call<M extends Method> = <P extends PathOf<M>>(path: P, ...init: InitArg<Operation<P, M>>) => Promise<Answer<Operation<P, M>>>;

/** The login's 401 is the answer to a wrong password, not the end of the session. */
const CREDENTIAL_PATHS = new Set(['/api/v1/auth/login']);

let unauthorized: ((e: ApiError) => void) | null = null;

/**
 * Called with every 401 (no valid session while authentication is on) of a request other than
 * the login itself: the session has ended, the login page comes back (main.tsx).
 */
export function onUnauthorized(handler: ((e: ApiError) => void) | null): void {
  unauthorized = handler;
}

/** The headers every request carries (a change is declared JSON; everything names this tab). */
function headers(method: string): Record<string, string> {
  const safe = ['GET', 'HEAD', 'OPTIONS'].includes(method.toUpperCase());
  return safe ? { 'X-Client-Id': clientId() } : { 'Content-Type': 'application/json', 'X-Client-Id': clientId() };
}

const motiond: Middleware = {
  async onResponse({ response, schemaPath }) {
    if (response.ok) return undefined;
    const text = await response.text();
    let json: unknown = null;
    try {
      json = text ? JSON.parse(text) : null;
    } catch {
      json = null;
    }
    const e = new ApiError(response.status, isProblem(json) ? json : null, isProblem(json) ? undefined : `HTTP ${response.status} ${text.slice(0, 200)}`);
    if (response.status === 401 && !CREDENTIAL_PATHS.has(schemaPath)) unauthorized?.(e);
    throw e;
  },
  onError({ error }) {
    return error instanceof ApiError ? error : new ApiError(0, null, `server not reachable (${(error as Error).message})`);
  },
};

/** The openapi-fetch client with motiond's behaviour (headers, errors, the 401 hook); `api` wraps it. */
const client = createClient<Paths>({
  // The headers are set here, not in an onRequest middleware (which openapi-fetch awaits): fetch
  // is called in the same task as the call, as before — a release at pagehide goes out at once.
  // globalThis.fetch is looked up at each request (tests replace it).
  fetch: (request) => {
    for (const [k, v] of Object.entries(headers(request.method))) request.headers.set(k, v);
    return globalThis.fetch(request);
  },
  // Never a number field's "abc" as null (the server would answer with serde's words).
  bodySerializer(body: unknown) {
    const bad = nonFiniteFields(body);
    if (bad.length) throw new NotSentError(bad);
    return JSON.stringify(body);
  },
});
client.use(motiond);

function call(method: 'GET' | 'PUT' | 'POST' | 'DELETE') {
  return async (path: string, init: Init<unknown> = {}) => {
    const body = init.body ?? (method === 'POST' ? {} : undefined);
    // The answer's text, parsed here: an empty answer (204, a DELETE) is null, as before.
    const r = await client.request(method.toLowerCase() as Lowercase<typeof method>, path as never, { ...init, body, parseAs: 'text' } as never);
    const text = (r as { data?: string }).data;
    if (!text) return null;
    try {
      return JSON.parse(text);
    } catch {
      return null;
    }
  };
}

/** A text answer (`GET /metrics`: Prometheus text), or a thrown ApiError. */
export async function getText<P extends PathOf<'get'>>(path: P, ...init: InitArg<Operation<P, 'get'>>): Promise<string> {
  const r = await client.request('get', path as never, { ...init[0], parseAs: 'text', headers: { Accept: 'text/plain' } } as never);
  return (r as { data?: string }).data ?? '';
}

/** The typed calls: the answer's body, or a thrown ApiError. */
export const api = {
  GET: call('GET') as Call<'get'>,
  PUT: call('PUT') as Call<'put'>,
  POST: call('POST') as Call<'post'>,
  DELETE: call('DELETE') as Call<'delete'>,
};

/** The paths that have a POST. */
export type PostPath = PathOf<'post'>;
