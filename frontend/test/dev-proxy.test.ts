import type { IncomingMessage } from 'node:http';
import { describe, expect, it } from 'vitest';
import { asMotiondsOwn } from '../dev-proxy';

// What the dev server's proxy forwards as the request's Origin.
function forwarded(headers: Record<string, string>): string | undefined {
  let origin: string | undefined = headers.origin;
  asMotiondsOwn('http://127.0.0.1:8080')(
    {
      setHeader: (name: string, value: string) => {
        expect(name).toBe('origin');
        origin = value;
      },
    },
    { headers } as unknown as IncomingMessage,
  );
  return origin;
}

describe('dev proxy origin rewrite (decisions 49)', () => {
  it("presents the dev server's own pages as motiond's origin", () => {
    expect(forwarded({ host: 'localhost:5173', origin: 'http://localhost:5173' })).toBe('http://127.0.0.1:8080');
    expect(forwarded({ host: 'localhost:5173', origin: 'https://localhost:5173' })).toBe('http://127.0.0.1:8080');
  });
  it('keeps every other origin, so motiond refuses it as without the proxy', () => {
    expect(forwarded({ host: 'localhost:5173', origin: 'http://evil.example' })).toBe('http://evil.example');
    expect(forwarded({ host: 'localhost:5173', origin: 'http://localhost:5174' })).toBe('http://localhost:5174');
    expect(forwarded({ host: 'localhost:5173', origin: 'null' })).toBe('null');
  });
  it('leaves requests without an Origin alone', () => {
    expect(forwarded({ host: 'localhost:5173' })).toBeUndefined();
  });
});
