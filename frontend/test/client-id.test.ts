// The tab's client id: `ui-` + 8 characters, kept in sessionStorage (a reload keeps it, another
// tab has its own), sent as X-Client-Id and as the websocket's ?client_id=.
import { describe, expect, it } from 'vitest';
import { CLIENT_ID_KEY, isClientId, loadClientId, makeClientId } from '../src/auth/client-id';
import { wsUrl } from '../src/services';

function memory(): Storage & { data: Map<string, string> } {
  const data = new Map<string, string>();
  return {
    data,
    getItem: (k: string) => data.get(k) ?? null,
    setItem: (k: string, v: string) => void data.set(k, v),
  } as unknown as Storage & { data: Map<string, string> };
}

describe('client id', () => {
  it('is ui- and 8 characters of [a-z0-9]', () => {
    expect(makeClientId(() => new Uint8Array([0, 1, 25, 26, 35, 36, 255, 100]))).toBe('ui-abz09ad2');
    for (let i = 0; i < 50; i++) expect(makeClientId()).toMatch(/^ui-[a-z0-9]{8}$/);
    expect(isClientId('ui-abc12345')).toBe(true);
    expect(isClientId('motiond-ui')).toBe(false);
    expect(isClientId(null)).toBe(false);
  });

  it('is made once and kept in the storage; a reload finds it', () => {
    const s = memory();
    let made = 0;
    const make = () => `ui-0000000${++made}`;
    const first = loadClientId(s, make);
    expect(first).toBe('ui-00000001');
    expect(s.data.get(CLIENT_ID_KEY)).toBe(first);
    expect(loadClientId(s, make)).toBe(first);
    expect(made).toBe(1);
  });

  it('another tab (another sessionStorage) gets another id', () => {
    expect(loadClientId(memory())).not.toBe(loadClientId(memory()));
  });

  it('a stored value that is not an id is replaced', () => {
    const s = memory();
    s.setItem(CLIENT_ID_KEY, 'x'.repeat(200));
    const id = loadClientId(s);
    expect(id).toMatch(/^ui-[a-z0-9]{8}$/);
    expect(s.data.get(CLIENT_ID_KEY)).toBe(id);
  });

  it('without a usable storage the id lives with the page', () => {
    const broken = { getItem: () => { throw new Error('denied'); }, setItem: () => { throw new Error('denied'); } };
    expect(loadClientId(broken)).toMatch(/^ui-[a-z0-9]{8}$/);
    expect(loadClientId(null)).toMatch(/^ui-[a-z0-9]{8}$/);
  });

  it('names the websocket too', () => {
    expect(wsUrl('ui-abc12345')).toMatch(/^wss?:\/\/[^/]+\/api\/v1\/ws\?client_id=ui-abc12345$/);
  });
});
