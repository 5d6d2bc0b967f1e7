// The name of this browser tab towards motiond: `ui-` and 8 random characters, kept in
// sessionStorage so that a reload keeps it (and with it the control of the machine), while
// every other tab has its own. Sent as `X-Client-Id` on every REST request and as
// `?client_id=` on the websocket (a browser cannot set headers there): the server knows a
// client by its user and this id, for the audit log and for the control lease.

export const CLIENT_ID_KEY = 'motiond.clientId';
const ALPHABET = 'abcdefghijklmnopqrstuvwxyz0123456789';
const PATTERN = /^ui-[a-z0-9]{8}$/;

/** 8 random characters of [a-z0-9]; `random` gives uniform bytes (crypto by default). */
export function makeClientId(random: (n: number) => Uint8Array = cryptoBytes): string {
  const bytes = random(8);
  let s = 'ui-';
  for (let i = 0; i < 8; i++) s += ALPHABET[bytes[i] % ALPHABET.length];
  return s;
}

function cryptoBytes(n: number): Uint8Array {
  const b = new Uint8Array(n);
  if (typeof crypto !== 'undefined' && typeof crypto.getRandomValues === 'function') crypto.getRandomValues(b);
  else for (let i = 0; i < n; i++) b[i] = Math.floor(Math.random() * 256);
  return b;
}

export function isClientId(s: unknown): s is string {
  return typeof s === 'string' && PATTERN.test(s);
}

type StorageLike = Pick<Storage, 'getItem' | 'setItem'>;

/**
 * The id kept in `storage`, or a new one stored there. Without a usable storage (disabled,
 * full, private mode) the id lives as long as the page.
 */
export function loadClientId(storage: StorageLike | null, make: () => string = makeClientId): string {
  try {
    const kept = storage?.getItem(CLIENT_ID_KEY);
    if (isClientId(kept)) return kept;
  } catch {
    /* no storage: a new id for this page */
  }
  const id = make();
  try {
    storage?.setItem(CLIENT_ID_KEY, id);
  } catch {
    /* kept in memory only */
  }
  return id;
}

let current: string | null = null;

function sessionStore(): StorageLike | null {
  try {
    return typeof sessionStorage !== 'undefined' ? sessionStorage : null;
  } catch {
    return null;
  }
}

/** This tab's client id (made on first use). */
export function clientId(): string {
  return (current ??= loadClientId(sessionStore()));
}

/** Tests: forget the id of this page (the stored one stays). */
export function resetClientId(): void {
  current = null;
}
