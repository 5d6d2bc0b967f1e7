// The REST client (api/client.ts, typed from openapi.json) against a fetch double: every request
// that changes something is declared JSON, also without a body (motiond answers 415 otherwise);
// reads are not; every request names this tab; a block goes to its path with its query and
// body; refusals, an unreachable server and a 401 are what the UI shows.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { ApiError, NotSentError } from '../src/api/problem';
import { api, getText, onUnauthorized } from '../src/api/client';
import { postBlock } from '../src/api/blocks';
import { clientId } from '../src/auth/client-id';
import { asSent } from './dom';

/** `content-type` → `Content-Type`, as the headers were written. */
const headerName = (k: string) => k.replace(/(^|-)([a-z])/g, (_, d: string, c: string) => d + c.toUpperCase());

type Sent = { method: string; url: string; headers: Record<string, string>; body: unknown; keepalive: boolean };
let sent: Sent[];
function serve(answer: () => Response | Promise<Response> = () => new Response('{}', { status: 200 })) {
  sent = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const r = await asSent(input, init);
      const headers = Object.fromEntries([...r.headers].map(([k, v]) => [headerName(k), v]));
      sent.push({ method: r.method, url: r.url, headers, body: r.body, keepalive: input instanceof Request && input.keepalive === true });
      return answer();
    }),
  );
}
afterEach(() => vi.unstubAllGlobals());

describe('content type', () => {
  it('POST, PUT and DELETE are sent as application/json, with or without a body', async () => {
    serve();
    await api.POST('/api/v1/axes/{axis}/power', { params: { path: { axis: 'x' } } });
    await api.POST('/api/v1/axes/{axis}/move-absolute', { params: { path: { axis: 'x' } }, body: { position: 1, velocity: 2 } });
    await api.PUT('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis: 'x', parameter: 'AxisVeloMax' } }, body: { value: 600 } });
    await api.DELETE('/api/v1/commands/{id}', { params: { path: { id: 7 } } });
    expect(sent.map((r) => [r.method, r.headers['Content-Type']])).toEqual([
      ['POST', 'application/json'],
      ['POST', 'application/json'],
      ['PUT', 'application/json'],
      ['DELETE', 'application/json'],
    ]);
    // A bodyless POST still sends `{}` (the server reads an empty body as `{}` too); DELETE sends none.
    expect(sent[0].body).toBe('{}');
    expect(sent[3].body).toBeUndefined();
    // Every request names this tab (the control of the machine is held by a tab).
    expect(clientId()).toMatch(/^ui-[a-z0-9]{8}$/);
    expect(sent.every((r) => r.headers['X-Client-Id'] === clientId())).toBe(true);
  });

  it('GET is sent without a content type', async () => {
    serve();
    await api.GET('/api/v1/axes');
    expect(sent[0].method).toBe('GET');
    expect(sent[0].headers['Content-Type']).toBeUndefined();
    expect(sent[0].headers['X-Client-Id']).toBe(clientId());
  });
});

describe('what is sent', () => {
  it('a block: POST to its path (the axis encoded), its query, its body as JSON, the headers', async () => {
    serve(() => new Response(JSON.stringify({ id: 12, command: 'move-absolute', state: 'done' }), { status: 202 }));
    const r = await postBlock('x y', 'move-absolute', { position: 100, velocity: 50 }, { query: { wait: true, timeout_ms: 20000 } });
    expect(r).toMatchObject({ id: 12, state: 'done' });
    expect(sent).toEqual([
      {
        method: 'POST',
        url: '/api/v1/axes/x%20y/move-absolute?wait=true&timeout_ms=20000',
        headers: { 'Content-Type': 'application/json', 'X-Client-Id': clientId() },
        body: '{"position":100,"velocity":50}',
        keepalive: false,
      },
    ]);
  });

  it('a read: GET with its query in the order given, no body; the answer parsed', async () => {
    serve(() => new Response('[{"id":1}]', { status: 200 }));
    expect(await api.GET('/api/v1/commands', { params: { query: { axis: 'x', state: 'active', limit: 500 } } })).toEqual([{ id: 1 }]);
    expect(sent[0]).toEqual({ method: 'GET', url: '/api/v1/commands?axis=x&state=active&limit=500', headers: { 'X-Client-Id': clientId() }, body: undefined, keepalive: false });
  });

  it('an answer without a body is null; the release at unload is sent with keepalive, at once (in the pagehide handler)', async () => {
    serve(() => new Response(null, { status: 204 }));
    const released = api.DELETE('/api/v1/control', { keepalive: true });
    expect(vi.mocked(fetch)).toHaveBeenCalledTimes(1);
    expect(await released).toBeNull();
    expect(sent[0]).toMatchObject({ method: 'DELETE', url: '/api/v1/control', keepalive: true, body: undefined });
  });

  it('a text answer (Prometheus metrics) asks for text and is the text', async () => {
    serve(() => new Response('# HELP x\nx 1\n', { status: 200, headers: { 'content-type': 'text/plain' } }));
    expect(await getText('/metrics', { params: { query: { buckets: 'fine' } } })).toBe('# HELP x\nx 1\n');
    expect(sent[0]).toMatchObject({ method: 'GET', url: '/metrics?buckets=fine', headers: { Accept: 'text/plain', 'X-Client-Id': clientId() } });
  });

  it('signal: an aborted request ends as fetch ends it (an ApiError, status 0); ?wait=true with timeout_ms bounds the server\'s wait', async () => {
    vi.stubGlobal(
      'fetch',
      vi.fn(
        (input: Request) =>
          new Promise<Response>((_, reject) => {
            const aborted = () => reject(new DOMException('The operation was aborted.', 'AbortError'));
            if (input.signal.aborted) aborted();
            else input.signal.addEventListener('abort', aborted);
          }),
      ),
    );
    const c = new AbortController();
    const waited = postBlock('x', 'move-absolute', { position: 1, velocity: 1 }, { query: { wait: true, timeout_ms: 600000 }, signal: c.signal });
    await new Promise((r) => setTimeout(r, 0)); // the request is out, the server waits
    expect(vi.mocked(fetch)).toHaveBeenCalledTimes(1);
    c.abort();
    await expect(waited).rejects.toMatchObject({ status: 0, code: 'network_error' });
  });

  it('a number that is none (a field\'s "abc") is never sent', async () => {
    serve();
    await expect(api.POST('/api/v1/axes/{axis}/move-absolute', { params: { path: { axis: 'x' } }, body: { position: NaN, velocity: 1 } })).rejects.toBeInstanceOf(NotSentError);
    expect(sent).toEqual([]);
  });
});

describe('refusals', () => {
  const problem = { type: 'urn:motiond:problem:validation_failed', title: 'Unprocessable Entity', status: 422, detail: 'velocity: must be > 0', code: 'validation_failed', errors: [{ field: 'velocity', message: 'must be > 0' }] };

  it('problem+json: an ApiError with its code, detail and fields', async () => {
    serve(() => new Response(JSON.stringify(problem), { status: 422, headers: { 'content-type': 'application/problem+json' } }));
    const e = await postBlock('x', 'move-velocity', { velocity: 0 }).catch((x) => x);
    expect(e).toBeInstanceOf(ApiError);
    expect(e).toMatchObject({ status: 422, code: 'validation_failed', message: 'velocity: must be > 0', fields: { velocity: 'must be > 0' } });
  });

  it('anything else: an ApiError saying the status and the start of the text', async () => {
    serve(() => new Response('Bad Gateway', { status: 502 }));
    await expect(api.GET('/api/v1/system')).rejects.toMatchObject({ status: 502, code: 'http_502', message: 'HTTP 502 Bad Gateway', problem: null });
  });

  it('a server that cannot be reached: status 0, network_error', async () => {
    vi.stubGlobal('fetch', vi.fn(async () => Promise.reject(new TypeError('Failed to fetch'))));
    await expect(api.GET('/api/v1/system')).rejects.toMatchObject({ status: 0, code: 'network_error', message: 'server not reachable (Failed to fetch)' });
  });
});

describe('401', () => {
  const problem = (code: string) => ({ type: 'x', title: 't', status: 401, detail: 'd', code });
  function answer401(code: string) {
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify(problem(code)), { status: 401 })));
  }
  afterEach(() => onUnauthorized(null));

  it('a 401 of any request ends the session (the handler is told), and is thrown as usual', async () => {
    const seen: ApiError[] = [];
    onUnauthorized((e) => seen.push(e));
    answer401('unauthenticated');
    await expect(api.GET('/api/v1/axes')).rejects.toMatchObject({ status: 401, code: 'unauthenticated' });
    await expect(api.POST('/api/v1/control', { body: { lease_ms: 5000 } })).rejects.toBeInstanceOf(ApiError);
    expect(seen.map((e) => e.code)).toEqual(['unauthenticated', 'unauthenticated']);
  });

  it('but not the 401 of a login: that is a wrong password, for the form', async () => {
    const seen: ApiError[] = [];
    onUnauthorized((e) => seen.push(e));
    answer401('invalid_credentials');
    await expect(api.POST('/api/v1/auth/login', { body: { name: 'a', password: 'b' } })).rejects.toMatchObject({ code: 'invalid_credentials' });
    expect(seen).toEqual([]);
  });
});
