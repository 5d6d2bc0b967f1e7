// rest.ts against a fetch double: every request that changes something is declared JSON, also
// without a body (motiond answers 415 otherwise); reads are not.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { del, get, post, put } from '../src/api/rest';

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
    expect(sent.every((r) => r.headers['X-Client-Id'] === 'motiond-ui')).toBe(true);
  });

  it('GET is sent without a content type', async () => {
    serve();
    await get('/axes');
    expect(sent[0].method).toBe('GET');
    expect(sent[0].headers['Content-Type']).toBeUndefined();
  });
});
