// Who uses this page: motiond's session (GET /auth/session). Authentication is on as soon as
// one user exists; then a page without a valid session shows the login page instead of the
// app, and any 401 later (the session expired, was logged out elsewhere, the user deleted)
// brings it back. While authentication is off every client may do everything.
import { Store } from '../store';
import { ApiError } from '../api/problem';
import { api } from '../api/client';
import type { components } from '../api/schema';

export type SessionState = components['schemas']['SessionState'];
export type Role = components['schemas']['Role'];

export const ROLES: readonly Role[] = ['viewer', 'operator', 'engineer', 'admin'];

/** Why the login page is shown. */
export type LoginReason = 'start' | 'ended' | 'logged-out' | 'auth-enabled';

export type AuthView =
  /** Asking the server at start. */
  | { kind: 'checking' }
  /**
   * The app runs: authentication off (`session.auth_enabled` false), a user logged in, or not
   * known yet (`session` null: the server could not be asked; the next check decides).
   */
  | { kind: 'app'; session: SessionState | null }
  | { kind: 'login'; reason: LoginReason };

export const auth = new Store<AuthView>({ kind: 'checking' });

/** Whether `role` is at least `need` (viewer < operator < engineer < admin). */
export function roleAtLeast(role: Role | null | undefined, need: Role): boolean {
  return !!role && ROLES.indexOf(role) >= ROLES.indexOf(need);
}

/**
 * What a session answer means for the page. `before` is what was shown until now: a page that
 * ran without authentication and now must log in learns that authentication was turned on.
 */
export function viewOf(s: SessionState, before: AuthView = { kind: 'checking' }): AuthView {
  if (!s.auth_enabled || s.principal) return { kind: 'app', session: s };
  if (before.kind === 'login') return before;
  if (before.kind === 'app' && before.session) {
    return { kind: 'login', reason: before.session.auth_enabled ? 'ended' : 'auth-enabled' };
  }
  return { kind: 'login', reason: 'start' };
}

/** What the page may do: true for everything while authentication is off. */
export function may(view: AuthView, need: Role): boolean {
  if (view.kind !== 'app') return false;
  const s = view.session;
  if (!s || !s.auth_enabled) return true;
  return roleAtLeast(s.role ?? null, need);
}

/** The session shown in the header: null while authentication is off or unknown. */
export function signedIn(view: AuthView): SessionState | null {
  return view.kind === 'app' && view.session?.auth_enabled && view.session.principal ? view.session : null;
}

let checking: Promise<void> | null = null;

/**
 * Asks the server who this page is. A stale cookie is a 401: logged out. A server that cannot
 * be reached changes nothing (at start the app runs and shows the connection state; the next
 * check, when the websocket opens or closes, decides).
 */
export function checkSession(): Promise<void> {
  return (checking ??= (async () => {
    try {
      const s = await api.GET('/api/v1/auth/session');
      auth.set(viewOf(s, auth.get()));
    } catch (e) {
      if (e instanceof ApiError && e.status === 401) sessionEnded();
      else if (auth.get().kind === 'checking') auth.set({ kind: 'app', session: null });
    } finally {
      checking = null;
    }
  })());
}

/** A 401 anywhere: the login page comes back ("Your session has ended"). */
export function sessionEnded(): void {
  const v = auth.get();
  if (v.kind === 'login') return;
  auth.set({ kind: 'login', reason: v.kind === 'checking' ? 'start' : 'ended' });
}

/** Logs in; the server's error (401 invalid_credentials, 429 …) is thrown for the form. */
export async function login(name: string, password: string): Promise<SessionState> {
  const s = await api.POST('/api/v1/auth/login', { body: { name, password } });
  auth.set({ kind: 'app', session: s });
  return s;
}

/** Logs out (the server clears the cookie); the login page follows whatever it answered. */
export async function logout(): Promise<void> {
  try {
    await api.POST('/api/v1/auth/logout');
  } finally {
    auth.set({ kind: 'login', reason: 'logged-out' });
  }
}
