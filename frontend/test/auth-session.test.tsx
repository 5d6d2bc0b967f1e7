// The session of the page: what GET /auth/session means (the app, or the login page and why),
// roles, the login page with the server's errors (wrong password, too many attempts), and the
// end of a session (any 401) bringing it back.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { asSent, mountPoint, unmount } from './dom';

vi.mock('../src/ui/shell/app', () => ({ App: () => <div id="the-app">app</div> }));

import { auth, checkSession, login, logout, may, roleAtLeast, sessionEnded, signedIn, viewOf, type AuthView, type SessionState } from '../src/auth/session';
import { Root, loginErrorText } from '../src/ui/shell/root';
import { ApiError } from '../src/api/problem';
import { parseRoute, href } from '../src/router';
import { tokenStatus } from '../src/ui/auth/users';
import { dateTime } from '../src/format';

const off: SessionState = { auth_enabled: false, principal: null, name: null, kind: null, role: null, expires_at: null };
const nobody: SessionState = { auth_enabled: true, principal: null, name: null, kind: null, role: null, expires_at: null };
const anna: SessionState = { auth_enabled: true, principal: 'user:anna', name: 'anna', kind: 'user', role: 'admin', expires_at: '2026-11-25T20:00:00.000Z' };
const otto: SessionState = { ...anna, principal: 'user:otto', name: 'otto', role: 'operator' };

const problem = (status: number, code: string, title: string, detail: string) => ({ type: `urn:motiond:problem:${code}`, title, status, detail, code });

let asked: string[];
/** A fetch double: `answer(method, url, body)` → [status, json] or an Error (unreachable). */
function serve(answer: (method: string, url: string, body: unknown) => [number, unknown] | Error) {
  asked = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const { method, url, body } = await asSent(input, init);
      asked.push(`${method} ${url}`);
      const a = answer(method, url, body ? JSON.parse(body) : undefined);
      if (a instanceof Error) throw a;
      return new Response(a[1] === null ? null : JSON.stringify(a[1]), { status: a[0] });
    }),
  );
}
afterEach(() => vi.unstubAllGlobals());
beforeEach(() => auth.set({ kind: 'checking' }));

describe('what a session answer means', () => {
  it('authentication off, or someone logged in: the app', () => {
    expect(viewOf(off)).toEqual({ kind: 'app', session: off });
    expect(viewOf(anna)).toEqual({ kind: 'app', session: anna });
  });

  it('nobody logged in: the login page; why depends on what was shown before', () => {
    expect(viewOf(nobody)).toEqual({ kind: 'login', reason: 'start' });
    expect(viewOf(nobody, { kind: 'app', session: null })).toEqual({ kind: 'login', reason: 'start' });
    expect(viewOf(nobody, { kind: 'app', session: anna })).toEqual({ kind: 'login', reason: 'ended' });
    // the first user was added while the page ran without authentication
    expect(viewOf(nobody, { kind: 'app', session: off })).toEqual({ kind: 'login', reason: 'auth-enabled' });
    expect(viewOf(nobody, { kind: 'login', reason: 'logged-out' })).toEqual({ kind: 'login', reason: 'logged-out' });
  });

  it('roles are ordered; everything is allowed while authentication is off', () => {
    expect(roleAtLeast('admin', 'operator')).toBe(true);
    expect(roleAtLeast('operator', 'operator')).toBe(true);
    expect(roleAtLeast('viewer', 'operator')).toBe(false);
    expect(roleAtLeast(null, 'viewer')).toBe(false);
    const app = (s: SessionState | null): AuthView => ({ kind: 'app', session: s });
    expect(may(app(off), 'admin')).toBe(true);
    expect(may(app(null), 'admin')).toBe(true);
    expect(may(app(anna), 'admin')).toBe(true);
    expect(may(app(otto), 'admin')).toBe(false);
    expect(may(app(otto), 'operator')).toBe(true);
    expect(may({ kind: 'login', reason: 'start' }, 'viewer')).toBe(false);
    // the header shows a user only while authentication is on
    expect(signedIn(app(anna))).toBe(anna);
    expect(signedIn(app(off))).toBeNull();
    expect(signedIn(app(null))).toBeNull();
  });
});

describe('checking the session', () => {
  it('at start: logged in → app; nobody → login; a stale cookie (401) → login', async () => {
    serve(() => [200, anna]);
    await checkSession();
    expect(auth.get()).toEqual({ kind: 'app', session: anna });
    expect(asked).toEqual(['GET /api/v1/auth/session']);
    auth.set({ kind: 'checking' });
    serve(() => [200, nobody]);
    await checkSession();
    expect(auth.get()).toEqual({ kind: 'login', reason: 'start' });
    auth.set({ kind: 'checking' });
    serve(() => [401, problem(401, 'unauthenticated', 'Authentication required', 'the session has expired: log in again')]);
    await checkSession();
    expect(auth.get().kind).toBe('login');
  });

  it('a server that cannot be reached: the app runs (showing the connection), the next check decides', async () => {
    serve(() => new TypeError('Failed to fetch'));
    await checkSession();
    expect(auth.get()).toEqual({ kind: 'app', session: null });
    // while running, an unreachable server changes nothing
    auth.set({ kind: 'app', session: anna });
    await checkSession();
    expect(auth.get()).toEqual({ kind: 'app', session: anna });
    // the session was ended meanwhile
    serve(() => [401, problem(401, 'unauthenticated', 'Authentication required', 'the session is unknown or was ended: log in again')]);
    await checkSession();
    expect(auth.get()).toEqual({ kind: 'login', reason: 'ended' });
  });

  it('concurrent checks share one request', async () => {
    serve(() => [200, anna]);
    await Promise.all([checkSession(), checkSession(), checkSession()]);
    expect(asked.length).toBe(1);
  });

  it('a 401 while the app runs: "ended"; a second one changes nothing', () => {
    auth.set({ kind: 'app', session: anna });
    sessionEnded();
    expect(auth.get()).toEqual({ kind: 'login', reason: 'ended' });
    sessionEnded();
    expect(auth.get()).toEqual({ kind: 'login', reason: 'ended' });
  });

  it('login and logout', async () => {
    serve((_m, u, b) => (u.endsWith('/auth/login') ? [200, { ...anna, name: (b as { name: string }).name }] : [204, null]));
    await login('anna', 'secret-pass-1');
    expect(auth.get()).toMatchObject({ kind: 'app', session: { name: 'anna', role: 'admin' } });
    await logout();
    expect(asked.at(-1)).toBe('POST /api/v1/auth/logout');
    expect(auth.get()).toEqual({ kind: 'login', reason: 'logged-out' });
  });
});

describe('the login page', () => {
  let root: HTMLElement;
  beforeEach(() => (root = mountPoint()));
  afterEach(() => unmount(root));
  const q = (sel: string) => root.querySelector(sel) as HTMLElement | null;
  const type = (sel: string, v: string) =>
    act(() => {
      const el = q(sel) as HTMLInputElement;
      el.value = v;
      el.dispatchEvent(new Event('input', { bubbles: true }));
    });
  const submit = async () => {
    await act(async () => {
      (q('form') as HTMLFormElement).dispatchEvent(new Event('submit', { bubbles: true, cancelable: true }));
    });
    await act(async () => {
      await new Promise((r) => setTimeout(r, 0));
    });
  };

  it('shows what the server said under the form, and then the app', async () => {
    auth.set({ kind: 'login', reason: 'start' });
    act(() => render(<Root />, root));
    expect(q('[data-page="login"]')).not.toBeNull();
    expect(q('[data-testid="login-reason"]')).toBeNull();
    expect((q('button[name="login"]') as HTMLButtonElement).disabled).toBe(true);
    let attempt = 0;
    serve(() => {
      attempt++;
      if (attempt === 1) return [401, problem(401, 'invalid_credentials', 'Invalid credentials', 'wrong user name or password')];
      if (attempt === 2) return [429, problem(429, 'too_many_login_attempts', 'Too many login attempts', '5 failed logins for anna: try again in 30 s')];
      return [200, anna];
    });
    await type('input[name="name"]', 'anna');
    await type('input[name="password"]', 'wrong');
    await submit();
    expect(q('[data-testid="login-error"]')?.textContent).toBe('Invalid credentials: wrong user name or password');
    expect((q('input[name="password"]') as HTMLInputElement).value).toBe('');
    expect(auth.get().kind).toBe('login');
    await type('input[name="password"]', 'wrong again');
    await submit();
    expect(q('[data-testid="login-error"]')?.textContent).toBe('Too many login attempts: 5 failed logins for anna: try again in 30 s');
    await type('input[name="password"]', 'secret-pass-1');
    await submit();
    expect(asked.at(-1)).toBe('POST /api/v1/auth/login');
    expect(q('#the-app')).not.toBeNull();
    expect(q('[data-page="login"]')).toBeNull();
  });

  it('says why it came back', () => {
    auth.set({ kind: 'login', reason: 'ended' });
    act(() => render(<Root />, root));
    expect(q('[data-testid="login-reason"]')?.textContent).toMatch(/^Your session has ended/);
    act(() => auth.set({ kind: 'login', reason: 'logged-out' }));
    expect(q('[data-testid="login-reason"]')?.textContent).toBe('You have logged out.');
    act(() => auth.set({ kind: 'checking' }));
    expect(root.textContent).toMatch(/Connecting to motiond/);
  });

  it('an unreachable server is said so', () => {
    expect(loginErrorText(new ApiError(0, null, 'server not reachable (Failed to fetch)'))).toBe('motiond cannot be reached: server not reachable (Failed to fetch)');
  });
});

describe('users page helpers', () => {
  it('routes #/users', () => {
    expect(parseRoute('#/users')).toEqual({ page: 'users' });
    expect(href({ page: 'users' })).toBe('#/users');
  });

  it('a token is active, expired or revoked', () => {
    const t = { id: 1, name: 'mes', role: 'operator' as const, created_by: 'user:anna', created_at: '2026-11-25T08:00:00.000Z', expires_at: null, last_used_at: null, revoked_at: null };
    const now = Date.parse('2026-11-26T00:00:00Z');
    expect(tokenStatus(t, now).kind).toBe('active');
    expect(tokenStatus({ ...t, expires_at: '2026-11-25T23:00:00Z' }, now).kind).toBe('expired');
    expect(tokenStatus({ ...t, expires_at: '2026-12-25T23:00:00Z' }, now).kind).toBe('active');
    expect(tokenStatus({ ...t, revoked_at: '2026-11-25T09:00:00Z', expires_at: '2026-11-25T23:00:00Z' }, now)).toEqual({
      kind: 'revoked',
      text: `revoked ${dateTime('2026-11-25T09:00:00Z')}`,
      at: '2026-11-25T09:00:00Z',
    });
  });

  it('dates as YYYY-MM-DD HH:MM', () => {
    expect(dateTime('2026-11-25T08:05:00.000Z')).toMatch(/^2026-11-2[45] \d\d:\d5$/);
    expect(dateTime(null)).toBe('');
    expect(dateTime('not a date')).toBe('not a date');
  });
});
