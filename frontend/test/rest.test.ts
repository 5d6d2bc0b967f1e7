// rest.ts against a fetch double: every request that changes something is declared JSON, also
// without a body (motiond answers 415 otherwise); reads are not.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { ApiError, del, get, onUnauthorized, post, put } from '../src/api/rest';
import { clientId } from '../src/auth/client-id';

let sent: { method: string; url: string; headers: Record<string, string>; body: unknown }[];
function serve() {
  sent = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (url: string, init?: RequestInit) => {
      sent.push({ method: init?.method ?? 'GET', url, headers: { ...(init?.headers as Record<string, string>) }, body: init?.body });
      return new Response('{}', { status: 200 });
    }),
  );
}
afterEach(() => vi.unstubAllGlobals());

describe('content type', () => {
  it('POST, PUT and DELETE are sent as application/json, with or without a body', async () => {
    serve();
    await post('/axes/x/power');
    await post('/axes/x/move-absolute', { position: 1, velocity: 2 });
    await put('/axes/x/parameters/AxisVeloMax', { value: 600 });
    await del('/commands/7');
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
    await get('/axes');
    expect(sent[0].method).toBe('GET');
    expect(sent[0].headers['Content-Type']).toBeUndefined();
    expect(sent[0].headers['X-Client-Id']).toBe(clientId());
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
    await expect(get('/axes')).rejects.toMatchObject({ status: 401, code: 'unauthenticated' });
    await expect(post('/control', { lease_ms: 5000 })).rejects.toBeInstanceOf(ApiError);
    expect(seen.map((e) => e.code)).toEqual(['unauthenticated', 'unauthenticated']);
  });

  it('but not the 401 of a login: that is a wrong password, for the form', async () => {
    const seen: ApiError[] = [];
    onUnauthorized((e) => seen.push(e));
    answer401('invalid_credentials');
    await expect(post('/auth/login', { name: 'a', password: 'b' })).rejects.toMatchObject({ code: 'invalid_credentials' });
    expect(seen).toEqual([]);
  });
});
