// The header's session and control: who is logged in (with Log out), and who controls the
// machine (Take control / Release / Take over). Nothing of the first while authentication is
// off, nothing of the second while motiond runs without control leases.
import { useState } from 'preact/hooks';
import { useStore } from '../../store';
import { auth, logout, may, signedIn } from '../../auth/session';
import { control, controlKind, controlText, holderName } from '../../auth/control';
import { ErrorBanner, errorText } from '../shared/common';

/** Gives control back (if held) and logs out; the login page follows. */
export async function signOut(): Promise<void> {
  await control.release().catch(() => {});
  await logout().catch(() => {});
}

export function ControlBadge() {
  const v = useStore(control.view);
  const view = useStore(auth);
  const [error, setError] = useState<string | null>(null);
  const [confirming, setConfirming] = useState(false);
  const [busy, setBusy] = useState(false);
  const s = v.state;
  const me = signedIn(view)?.principal ?? null;
  const text = controlText(s, me);
  const kind = controlKind(s);
  if (!text || !kind || !s) return null;
  const h = s.holder;
  const title = h
    ? `${holderName(h)}${h.client_id ? ` · client ${h.client_id}` : ''} at ${h.client_addr}, since ${new Date(h.since).toLocaleTimeString()}` +
      (kind === 'you' ? ' · motion commands of every other client are refused' : ' · your motion commands are refused; stop, halt and power off always pass')
    : 'Nobody holds control: every operator may command motion';
  const run = async (f: () => Promise<void>) => {
    if (busy) return;
    setBusy(true);
    setError(null);
    try {
      await f();
      setConfirming(false);
    } catch (e) {
      setError(errorText(e));
    } finally {
      setBusy(false);
    }
  };
  return (
    <>
      <div class={`ctl ctl-${kind}`} data-control={kind} title={title}>
        <span class="ctl-dot" />
        <span class="ctl-text" data-testid="control-text">
          {text}
        </span>
        {kind === 'free' && may(view, 'operator') && (
          <button type="button" class="btn btn-small btn-top" name="take-control" disabled={busy} onClick={() => run(() => control.take())}>
            Take control
          </button>
        )}
        {kind === 'you' && (
          <button type="button" class="btn btn-small btn-top" name="release-control" disabled={busy} onClick={() => run(() => control.release())}>
            Release
          </button>
        )}
        {kind === 'other' &&
          may(view, 'admin') &&
          (confirming ? (
            <span class="ctl-confirm">
              <button type="button" class="btn btn-small btn-warn" name="take-over-confirm" disabled={busy} onClick={() => run(() => control.take(true))}>
                Take over
              </button>
              <button type="button" class="btn btn-small btn-top" name="take-over-cancel" onClick={() => setConfirming(false)}>
                Cancel
              </button>
            </span>
          ) : (
            <button type="button" class="btn btn-small btn-top" name="take-over" onClick={() => setConfirming(true)}>
              Take over…
            </button>
          ))}
      </div>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      {v.lost && (
        <div class="banner banner-warn banner-float" role="alert" data-testid="control-lost">
          <span>{v.lost}</span>
          <button type="button" class="banner-close" onClick={() => control.dismissLost()} aria-label="dismiss">
            ×
          </button>
        </div>
      )}
    </>
  );
}

export function UserBadge() {
  const view = useStore(auth);
  const s = signedIn(view);
  const [busy, setBusy] = useState(false);
  if (!s) return null;
  const until = s.expires_at ? `, session until ${new Date(s.expires_at).toLocaleString()}` : '';
  return (
    <div class="user" data-user={s.name ?? ''} data-role={s.role ?? ''} title={`${s.principal}${until}`}>
      <span class="user-name">{s.name}</span>
      <span class="user-role">{s.role}</span>
      <button
        type="button"
        class={`btn btn-small btn-top ${busy ? 'busy' : ''}`}
        name="logout"
        disabled={busy}
        onClick={async () => {
          setBusy(true);
          await signOut();
        }}
      >
        Log out
      </button>
    </div>
  );
}
