// Whether the socket still speaks. Only changes are streamed, so a still machine sends no
// axis updates; the `system` topic (subscribed at 1 Hz, its cycle changes every update) keeps
// a message coming every second while the server runs. No message for STALE_AFTER_MS: stale.

export const STALE_AFTER_MS = 3000;

export type Liveness =
  | { kind: 'offline' }
  | { kind: 'live'; ageMs: number }
  | { kind: 'stale'; ageMs: number | null };

/** The liveness at `now` of a socket (`open`) whose last message came at `lastAt`. */
export function liveness(open: boolean, lastAt: number | null, now: number, staleAfterMs = STALE_AFTER_MS): Liveness {
  if (!open) return { kind: 'offline' };
  if (lastAt === null) return { kind: 'stale', ageMs: null };
  const ageMs = Math.max(0, now - lastAt);
  return ageMs > staleAfterMs ? { kind: 'stale', ageMs } : { kind: 'live', ageMs };
}

/** The latest cycle known from any topic (the axis's own stops while it does not change). */
export function latestCycle(...cycles: (number | null | undefined)[]): number | null {
  let best: number | null = null;
  for (const c of cycles) if (typeof c === 'number' && c >= 0 && (best === null || c > best)) best = c;
  return best;
}

/** "3 s" / "2 min" for the age of the last message. */
export function ageText(ms: number): string {
  const s = Math.floor(ms / 1000);
  return s < 120 ? `${s} s` : `${Math.floor(s / 60)} min`;
}
