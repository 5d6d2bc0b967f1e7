// Users and API tokens (admin; anyone while authentication is off, to add the first user).
// Users: change the role, set a password, delete; add one. Tokens, for machines: revoke; create
// one, whose secret is shown once. Every change is the server's to validate: its message is
// shown at the field, or at the form or row it concerns.
import type { ComponentChildren } from 'preact';
import { useEffect, useRef, useState } from 'preact/hooks';
import { api } from '../../api/client';
import type { components } from '../../api/schema';
import { useStore } from '../../store';
import { auth, checkSession, ROLES, signedIn, type Role } from '../../auth/session';
import { dateTime } from '../../format';
import { ErrorBanner, Field, NumberInput, Panel, errorText, fieldsOf, parseNum } from '../shared/common';

type S = components['schemas'];
export type UserView = S['UserView'];
export type TokenView = S['TokenView'];
export type NewToken = S['NewToken'];
type TokenRequest = S['TokenRequest'];

/** A token's state for the table: revoked, expired (at `now`) or active. */
export function tokenStatus(t: TokenView, now = Date.now()): { kind: 'revoked' | 'expired' | 'active'; text: string; at: string | null } {
  if (t.revoked_at) return { kind: 'revoked', text: `revoked ${dateTime(t.revoked_at)}`, at: t.revoked_at };
  if (t.expires_at && new Date(t.expires_at).getTime() <= now) return { kind: 'expired', text: `expired ${dateTime(t.expires_at)}`, at: t.expires_at };
  return { kind: 'active', text: 'active', at: null };
}

const STATUS_TAG = { revoked: 'tag-red', expired: 'tag-amber', active: 'tag-green' } as const;

function RoleSelect({ value, onChange, name, disabled }: { value: Role; onChange: (r: Role) => void; name: string; disabled?: boolean }) {
  return (
    <select name={name} value={value} disabled={disabled} onChange={(e) => onChange((e.target as HTMLSelectElement).value as Role)}>
      {ROLES.map((r) => (
        <option key={r} value={r}>
          {r}
        </option>
      ))}
    </select>
  );
}

/** A submit button that shows it is busy. */
function Submit({ busy, disabled, name, children }: { busy: boolean; disabled?: boolean; name: string; children: ComponentChildren }) {
  return (
    <button type="submit" class={`btn btn-primary ${busy ? 'busy' : ''}`} name={name} disabled={busy || disabled}>
      {children}
    </button>
  );
}

/** The error of a form or row, where it happened (not floating: it belongs to that form). */
function FormError({ error, testid }: { error: string | null; testid?: string }) {
  if (!error) return null;
  return (
    <div class="banner banner-error form-error" role="alert" data-testid={testid}>
      {error}
    </div>
  );
}

export function UsersPage() {
  const view = useStore(auth);
  const me = signedIn(view);
  const authOn = view.kind === 'app' && !!view.session?.auth_enabled;
  const [users, setUsers] = useState<UserView[] | null>(null);
  const [tokens, setTokens] = useState<TokenView[] | null>(null);
  const [error, setError] = useState<string | null>(null);
  const load = async () => {
    try {
      const [u, t] = await Promise.all([api.GET('/api/v1/users'), api.GET('/api/v1/tokens')]);
      setUsers(u);
      setTokens(t);
      setError(null);
    } catch (e) {
      setError(errorText(e));
    }
  };
  useEffect(() => void load(), []);
  return (
    <div class="page page-users" id="users">
      <div class="page-head">
        <h2>Users and API tokens</h2>
        <span class="muted">{authOn ? 'authentication is on' : 'authentication is off'}</span>
      </div>
      {!authOn && (
        <div class="banner banner-info" data-testid="auth-off">
          <span>
            Authentication is off: every client may do everything. Add the first user, an <b>admin</b>, to turn it on; from then on
            every client must log in or send a token.
          </span>
        </div>
      )}
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <UsersPanel users={users} me={me?.name ?? null} authOn={authOn} reload={load} />
      <TokensPanel tokens={tokens} reload={load} />
    </div>
  );
}

function UsersPanel({ users, me, authOn, reload }: { users: UserView[] | null; me: string | null; authOn: boolean; reload: () => Promise<void> }) {
  return (
    <>
      <Panel title="Users">
        {users === null ? (
          <p class="muted">Loading…</p>
        ) : (
          <div class="table-scroll">
            <table class="grid users-table" data-testid="users">
              <thead>
                <tr>
                  <th>Name</th>
                  <th>Role</th>
                  <th class="hide-phone">Created</th>
                  <th />
                </tr>
              </thead>
              <tbody>
                {users.map((u) => (
                  <UserRow key={u.name} user={u} me={u.name === me} reload={reload} />
                ))}
                {users.length === 0 && (
                  <tr>
                    <td colSpan={4} class="muted empty">
                      No users yet.
                    </td>
                  </tr>
                )}
              </tbody>
            </table>
          </div>
        )}
      </Panel>
      <AddUser first={users !== null && users.length === 0} authOn={authOn} reload={reload} />
    </>
  );
}

function UserRow({ user, me, reload }: { user: UserView; me: boolean; reload: () => Promise<void> }) {
  const [error, setError] = useState<string | null>(null);
  const [pwOpen, setPwOpen] = useState(false);
  const [pw, setPw] = useState('');
  const [pwError, setPwError] = useState<string | undefined>(undefined);
  const [confirmDelete, setConfirmDelete] = useState(false);
  const [busy, setBusy] = useState(false);
  const [done, setDone] = useState<string | null>(null);
  const act = async (f: () => Promise<unknown>, after?: () => void) => {
    if (busy) return;
    setBusy(true);
    setError(null);
    setDone(null);
    try {
      await f();
      after?.();
      await reload();
      // One's own role or password: the session may have changed (or ended).
      if (me) await checkSession();
    } catch (e) {
      setError(errorText(e));
      setPwError(fieldsOf(e).password);
    } finally {
      setBusy(false);
    }
  };
  const setRole = (role: Role) => act(() => api.PUT('/api/v1/users/{name}', { params: { path: { name: user.name } }, body: { role } }), () => setDone(`role set to ${role}`));
  const setPassword = (ev: Event) => {
    ev.preventDefault();
    void act(
      () => api.PUT('/api/v1/users/{name}', { params: { path: { name: user.name } }, body: { password: pw } }),
      () => {
        setPw('');
        setPwOpen(false);
        setPwError(undefined);
        setDone('password set; the user’s sessions have ended');
      },
    );
  };
  const remove = () => act(() => api.DELETE('/api/v1/users/{name}', { params: { path: { name: user.name } } }));
  return (
    <>
      <tr data-user={user.name} class={error ? 'row-error' : ''}>
        <td class="nowrap">
          <b>{user.name}</b> {me && <span class="tag tag-blue">you</span>}
        </td>
        <td>
          <RoleSelect name="role" value={user.role} disabled={busy} onChange={(r) => void setRole(r)} />
        </td>
        <td class="nowrap muted hide-phone">{dateTime(user.created_at)}</td>
        <td class="row-actions">
          {pwOpen ? (
            <form class="inline-form" onSubmit={setPassword}>
              <Field label="New password" name="password" error={pwError}>
                <input
                  type="password"
                  name="new-password"
                  autocomplete="new-password"
                  placeholder="8 characters or more"
                  value={pw}
                  onInput={(e) => setPw((e.target as HTMLInputElement).value)}
                />
              </Field>
              <Submit busy={busy} disabled={!pw} name="save-password">
                Set
              </Submit>
              <button type="button" class="btn" onClick={() => { setPwOpen(false); setPw(''); setPwError(undefined); }}>
                Cancel
              </button>
            </form>
          ) : confirmDelete ? (
            <span class="confirm">
              <span>
                Delete <b>{user.name}</b>?
              </span>
              <button type="button" class="btn btn-danger" name="delete-confirm" disabled={busy} onClick={() => void remove()}>
                Delete
              </button>
              <button type="button" class="btn" onClick={() => setConfirmDelete(false)}>
                Cancel
              </button>
            </span>
          ) : (
            <span class="inline">
              <button type="button" class="btn btn-small" name="set-password" onClick={() => { setPwOpen(true); setDone(null); }}>
                Set password…
              </button>
              <button type="button" class="btn btn-small btn-danger-outline" name="delete" onClick={() => { setConfirmDelete(true); setError(null); setDone(null); }}>
                Delete…
              </button>
            </span>
          )}
        </td>
      </tr>
      {(error || done) && (
        <tr class="row-msg" data-user-msg={user.name}>
          <td colSpan={4}>{error ? <span class="field-error" role="alert">{error}</span> : <span class="ok-text">{done}</span>}</td>
        </tr>
      )}
    </>
  );
}

function AddUser({ first, authOn, reload }: { first: boolean; authOn: boolean; reload: () => Promise<void> }) {
  const [name, setName] = useState('');
  const [role, setRole] = useState<Role>('operator');
  const [password, setPassword] = useState('');
  const [fields, setFields] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const [busy, setBusy] = useState(false);
  // The first user must be an admin (the server says so too).
  useEffect(() => {
    if (first) setRole('admin');
  }, [first]);
  const submit = async (ev: Event) => {
    ev.preventDefault();
    if (busy) return;
    setBusy(true);
    setError(null);
    setFields({});
    try {
      await api.POST('/api/v1/users', { body: { name: name.trim(), role, password } });
      setName('');
      setPassword('');
      // The first user turns authentication on: this page must now log in.
      if (!authOn) await checkSession();
      else await reload();
    } catch (e) {
      setFields(fieldsOf(e));
      setError(errorText(e));
    } finally {
      setBusy(false);
    }
  };
  return (
    <Panel title="Add user">
      <form class="form-row form-top" onSubmit={submit} data-testid="add-user">
        <Field label="Name" name="name" error={fields.name} hint="letters, digits and .-_@">
          <input type="text" name="user-name" autocomplete="off" spellcheck={false} value={name} onInput={(e) => setName((e.target as HTMLInputElement).value)} />
        </Field>
        <Field label="Role" name="role" error={fields.role}>
          <RoleSelect name="user-role" value={role} onChange={setRole} />
        </Field>
        <Field label="Password" name="password" error={fields.password} hint="8 characters or more">
          <input type="password" name="user-password" autocomplete="new-password" value={password} onInput={(e) => setPassword((e.target as HTMLInputElement).value)} />
        </Field>
        <Submit busy={busy} disabled={!name.trim() || !password} name="add-user">
          Add user
        </Submit>
      </form>
      {first && <p class="muted small">The first user must be an admin. Adding it turns authentication on: you will be asked to log in.</p>}
      <FormError error={error} testid="add-user-error" />
    </Panel>
  );
}

function TokensPanel({ tokens, reload }: { tokens: TokenView[] | null; reload: () => Promise<void> }) {
  const [fresh, setFresh] = useState<NewToken | null>(null);
  return (
    <>
      <Panel title="API tokens">
        <p class="muted small panel-note">
          For machines (MES, PLC, scripts): sent as <code>Authorization: Bearer …</code>, with the role given here.
        </p>
        {tokens === null ? (
          <p class="muted">Loading…</p>
        ) : (
          <div class="table-scroll">
            <table class="grid tokens-table" data-testid="tokens">
              <thead>
                <tr>
                  <th>Name</th>
                  <th>Role</th>
                  <th class="hide-phone">Created by</th>
                  <th class="hide-phone">Created</th>
                  <th class="hide-phone">Expires</th>
                  <th class="hide-phone">Last used</th>
                  <th>Status</th>
                  <th />
                </tr>
              </thead>
              <tbody>
                {tokens.map((t) => (
                  <TokenRow key={t.id} token={t} reload={reload} />
                ))}
                {tokens.length === 0 && (
                  <tr>
                    <td colSpan={8} class="muted empty">
                      No tokens yet.
                    </td>
                  </tr>
                )}
              </tbody>
            </table>
          </div>
        )}
      </Panel>
      <NewTokenPanel
        fresh={fresh}
        onCreated={async (t) => {
          setFresh(t);
          await reload();
        }}
        onDone={() => setFresh(null)}
      />
    </>
  );
}

function TokenRow({ token: t, reload }: { token: TokenView; reload: () => Promise<void> }) {
  const [confirm, setConfirm] = useState(false);
  const [error, setError] = useState<string | null>(null);
  const [busy, setBusy] = useState(false);
  const status = tokenStatus(t);
  const revoke = async () => {
    setBusy(true);
    setError(null);
    try {
      await api.DELETE('/api/v1/tokens/{id}', { params: { path: { id: t.id } } });
      setConfirm(false);
      await reload();
    } catch (e) {
      setError(errorText(e));
    } finally {
      setBusy(false);
    }
  };
  return (
    <>
      <tr data-token={t.name} data-status={status.kind} class={status.kind === 'active' ? '' : 'muted'}>
        <td class="nowrap">
          <b>{t.name}</b>
        </td>
        <td>{t.role}</td>
        <td class="nowrap hide-phone">{t.created_by}</td>
        <td class="nowrap hide-phone">{dateTime(t.created_at)}</td>
        <td class="nowrap hide-phone">{t.expires_at ? dateTime(t.expires_at) : <span class="muted">never</span>}</td>
        <td class="nowrap hide-phone">{t.last_used_at ? dateTime(t.last_used_at) : <span class="muted">never</span>}</td>
        <td class="nowrap">
          <span class={`tag ${STATUS_TAG[status.kind]}`} title={status.text}>
            {status.kind}
          </span>
          {status.at && <span class="muted small hide-phone"> {dateTime(status.at)}</span>}
        </td>
        <td class="row-actions">
          {!t.revoked_at &&
            (confirm ? (
              <span class="confirm">
                <span>
                  Revoke <b>{t.name}</b>?
                </span>
                <button type="button" class="btn btn-danger" name="revoke-confirm" disabled={busy} onClick={() => void revoke()}>
                  Revoke
                </button>
                <button type="button" class="btn" onClick={() => setConfirm(false)}>
                  Cancel
                </button>
              </span>
            ) : (
              <button type="button" class="btn btn-small btn-danger-outline" name="revoke" onClick={() => setConfirm(true)}>
                Revoke…
              </button>
            ))}
        </td>
      </tr>
      {error && (
        <tr class="row-msg">
          <td colSpan={8}>
            <span class="field-error" role="alert">
              {error}
            </span>
          </td>
        </tr>
      )}
    </>
  );
}

function NewTokenPanel({ fresh, onCreated, onDone }: { fresh: NewToken | null; onCreated: (t: NewToken) => Promise<void>; onDone: () => void }) {
  const [name, setName] = useState('');
  const [role, setRole] = useState<Role>('operator');
  const [days, setDays] = useState('');
  const [fields, setFields] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const [busy, setBusy] = useState(false);
  const submit = async (ev: Event) => {
    ev.preventDefault();
    if (busy) return;
    setBusy(true);
    setError(null);
    setFields({});
    try {
      const body: TokenRequest = { name: name.trim(), role };
      if (days.trim()) body.expires_in_days = parseNum(days);
      const t = await api.POST('/api/v1/tokens', { body });
      setName('');
      setDays('');
      await onCreated(t);
    } catch (e) {
      setFields(fieldsOf(e));
      setError(errorText(e));
    } finally {
      setBusy(false);
    }
  };
  return (
    <Panel title="New API token">
      {fresh && <TokenOnce token={fresh} onDone={onDone} />}
      <form class="form-row form-top" onSubmit={submit} data-testid="new-token-form">
        <Field label="Name" name="name" error={fields.name} hint="names it in the audit log">
          <input type="text" name="token-name" autocomplete="off" spellcheck={false} value={name} onInput={(e) => setName((e.target as HTMLInputElement).value)} />
        </Field>
        <Field label="Role" name="role" error={fields.role}>
          <RoleSelect name="token-role" value={role} onChange={setRole} />
        </Field>
        <Field label="Expires in (days)" name="expires_in_days" error={fields.expires_in_days} hint="empty: never">
          <NumberInput name="token-days" value={days} onValue={setDays} placeholder="never" />
        </Field>
        <Submit busy={busy} disabled={!name.trim()} name="create-token">
          Create token
        </Submit>
      </form>
      <FormError error={error} testid="new-token-error" />
    </Panel>
  );
}

/** A new token's secret: shown this once, to be copied now. */
function TokenOnce({ token, onDone }: { token: NewToken; onDone: () => void }) {
  const input = useRef<HTMLInputElement>(null);
  const [copied, setCopied] = useState<boolean | null>(null);
  const copy = async () => {
    input.current?.select();
    try {
      await navigator.clipboard.writeText(token.token);
      setCopied(true);
    } catch {
      // No clipboard access (an insecure origin): the text is selected for Ctrl+C.
      setCopied(document.execCommand?.('copy') ?? false);
    }
  };
  return (
    <div class="token-once" data-testid="new-token" data-token-name={token.name}>
      <div class="banner banner-warn">
        <span>
          The token <b>{token.name}</b> ({token.role}): copy it now. motiond keeps only its hash: <b>it will not be shown again</b>.
        </span>
      </div>
      <div class="token-box">
        <input
          ref={input}
          type="text"
          class="mono"
          name="new-token"
          readOnly
          value={token.token}
          spellcheck={false}
          onFocus={(e) => (e.target as HTMLInputElement).select()}
          aria-label="the new token"
        />
        <button type="button" class="btn btn-primary" name="copy-token" onClick={() => void copy()}>
          {copied ? 'Copied' : 'Copy'}
        </button>
        <button type="button" class="btn" name="token-done" onClick={onDone}>
          Done
        </button>
      </div>
      {copied === false && <p class="muted small">Select it and press Ctrl+C: this page may not use the clipboard.</p>}
    </div>
  );
}
