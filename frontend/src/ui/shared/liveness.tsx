// The liveness of the live values: the latest cycle heard of and whether the socket still
// speaks (src/live/liveness.ts), re-evaluated every second so that silence shows.
import { useEffect, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { live, system } from '../../services';
import { ageText, latestCycle, liveness, type Liveness } from '../../live/liveness';

export function useLiveness(): Liveness {
  const conn = useStore(live.state);
  useStore(system); // each system update (1 Hz) renders anew
  const [, tick] = useState(0);
  useEffect(() => {
    const t = setInterval(() => tick((n) => n + 1), 1000);
    return () => clearInterval(t);
  }, []);
  return liveness(conn.kind === 'open', live.lastMessageAt, Date.now());
}

/**
 * "● cycle N" while messages arrive (the cycle advances every second even at standstill),
 * "no message for N s" when the socket has been silent for longer than STALE_AFTER_MS, "not
 * live" while disconnected or while `stale` (the caller's subscription awaits its first value).
 */
export function LiveIndicator({ cycle, stale = false }: { cycle?: number | null; stale?: boolean }) {
  const sys = useStore(system);
  const l = useLiveness();
  const n = latestCycle(cycle, sys?.cycle);
  if (l.kind === 'offline' || stale) {
    return (
      <span class="live-ind live-off" data-live="off">
        not live
      </span>
    );
  }
  const age = l.ageMs === null ? 'no message yet' : `last message ${ageText(l.ageMs)} ago`;
  return (
    <span class={`live-ind live-${l.kind}`} data-live={l.kind} data-cycle={n ?? ''} title={`${age} · the server sends its cycle every second`}>
      <span class="live-dot" />
      {l.kind === 'stale' && <span class="live-silent">{l.ageMs === null ? 'no message' : `no message for ${ageText(l.ageMs)}`} · </span>}
      {n !== null && <span class="mono">cycle {n}</span>}
    </span>
  );
}
