// What the page shows before the app: the session check at start, and the login page while
// authentication is on and nobody is logged in (at start, or after a 401 ended the session).
import { useEffect, useRef, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { auth, login, type LoginReason } from '../../auth/session';
import { ApiError } from '../../api/problem';
import { App } from './app';
import { Field } from '../shared/common';

export function Root() {
  const view = useStore(auth);
  if (view.kind === 'checking') {
    return (
      <div class="login-page" data-page="checking">
        <p class="muted">Connecting to motiond…</p>
      </div>
    );
  }
  if (view.kind === 'login') return <LoginPage reason={view.reason} />;
  return <App />;
}

const REASON: Record<LoginReason, { cls: string; text: string } | null> = {
  start: null,
  ended: { cls: 'banner-warn', text: 'Your session has ended. Log in again to go on.' },
  'logged-out': { cls: 'banner-info', text: 'You have logged out.' },
  'auth-enabled': { cls: 'banner-info', text: 'Authentication is now on: log in with a user of this motiond.' },
};

/** The text of a refused login: what the server said (wrong password, too many attempts …). */
export function loginErrorText(e: unknown): string {
  if (e instanceof ApiError) {
    if (e.status === 0) return `motiond cannot be reached: ${e.message}`;
    if (e.problem) return `${e.problem.title}: ${e.problem.detail}`;
    return e.message;
  }
  return e instanceof Error ? e.message : String(e);
}

export function LoginPage({ reason }: { reason: LoginReason }) {
  const [name, setName] = useState('');
  const [password, setPassword] = useState('');
  const [error, setError] = useState<string | null>(null);
  const [fields, setFields] = useState<Record<string, string>>({});
  const [busy, setBusy] = useState(false);
  const nameEl = useRef<HTMLInputElement>(null);
  const passwordEl = useRef<HTMLInputElement>(null);
  useEffect(() => nameEl.current?.focus(), []);
  const note = REASON[reason];
  const submit = async (ev: Event) => {
    ev.preventDefault();
    if (busy) return;
    setBusy(true);
    setError(null);
    setFields({});
    try {
      await login(name.trim(), password);
    } catch (e) {
      setError(loginErrorText(e));
      setFields(e instanceof ApiError ? e.fields : {});
      setPassword('');
      passwordEl.current?.focus();
    } finally {
      setBusy(false);
    }
  };
  return (
    <div class="login-page" data-page="login" data-reason={reason}>
      <form class="login-card" onSubmit={submit} aria-labelledby="login-title">
        <div class="login-head">
          <span class="brand">motiond</span>
          <span class="muted">commissioning</span>
        </div>
        <div class="login-body">
          <h2 id="login-title">Log in</h2>
          {note && (
            <div class={`banner ${note.cls}`} data-testid="login-reason">
              {note.text}
            </div>
          )}
          <Field label="User name" name="name" error={fields.name}>
            <input
              ref={nameEl}
              type="text"
              name="name"
              autocomplete="username"
              autocapitalize="none"
              spellcheck={false}
              required
              value={name}
              onInput={(e) => setName((e.target as HTMLInputElement).value)}
            />
          </Field>
          <Field label="Password" name="password" error={fields.password}>
            <input
              ref={passwordEl}
              type="password"
              name="password"
              autocomplete="current-password"
              required
              value={password}
              onInput={(e) => setPassword((e.target as HTMLInputElement).value)}
            />
          </Field>
          <button type="submit" class={`btn btn-primary login-submit ${busy ? 'busy' : ''}`} name="login" disabled={busy || !name.trim() || !password}>
            Log in
          </button>
          {error && (
            <div class="banner banner-error login-error" role="alert" data-testid="login-error">
              {error}
            </div>
          )}
        </div>
      </form>
    </div>
  );
}
