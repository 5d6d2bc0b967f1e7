// Press-and-hold jog buttons. Every way of letting go releases the jog: pointerup,
// pointerleave, pointercancel, lost focus of the window, a hidden tab, page hide, and the
// socket closing (then the server stops the axis by itself).
import { useEffect, useState } from 'preact/hooks';
import type { JogDirection, JogMode } from '../../api/types';
import { jog, live } from '../../services';
import type { JogSnapshot } from '../../live/jog';
import { useStore } from '../../store';

export interface JogButtonDef {
  label: string;
  direction: JogDirection;
  mode: JogMode;
  velocity: number | null;
  key: string;
  /** The function key that holds it too (F1 … F4), shown in the title. */
  fkey?: string;
}

let globalHooksInstalled = false;
/** Window-level stop paths; installed once. */
export function installJogSafety(): void {
  if (globalHooksInstalled || typeof window === 'undefined') return;
  globalHooksInstalled = true;
  window.addEventListener('blur', () => jog.release('window lost focus'));
  document.addEventListener('visibilitychange', () => {
    if (document.visibilityState === 'hidden') jog.release('page hidden');
  });
  window.addEventListener('pagehide', () => jog.release('page closed'));
  // A pointerup anywhere (e.g. after the pointer slid off and back) ends the hold too.
  window.addEventListener('pointerup', () => jog.release('button released'));
  window.addEventListener('pointercancel', () => jog.release('pointer cancelled'));
}

function useJog(): JogSnapshot {
  const [s, set] = useState(jog.snapshot());
  useEffect(() => jog.onChange(set), []);
  return s;
}

export function JogButtons({ axis, unit, buttons, disabled }: { axis: string; unit: string; buttons: JogButtonDef[]; disabled: boolean }) {
  const s = useJog();
  const conn = useStore(live.state);
  useEffect(installJogSafety, []);
  const held = (b: JogButtonDef) => s.axis === axis && s.direction === b.direction && s.mode === b.mode;
  return (
    <div class="jog">
      <div class="jog-buttons">
        {buttons.map((b) => (
          <button
            type="button"
            key={b.key}
            name={`jog-${b.key}`}
            data-jog={b.key}
            class={`btn jog-btn ${held(b) ? 'held' : ''}`}
            title={`jog ${b.direction} ${b.mode === 'standard_fast' ? 'fast (#1002)' : 'slow (#1001)'}: hold${b.fkey ? ` (or hold ${b.fkey})` : ''}`}
            disabled={disabled || conn.kind !== 'open'}
            onPointerDown={(e) => {
              if (e.button !== 0) return;
              e.preventDefault();
              jog.press(axis, b.direction, b.mode);
            }}
            onPointerUp={() => jog.release('button released')}
            onPointerLeave={() => jog.release('pointer left the button')}
            onPointerCancel={() => jog.release('pointer cancelled')}
            onContextMenu={(e) => e.preventDefault()}
            onKeyDown={(e) => {
              if ((e.key === ' ' || e.key === 'Enter') && !e.repeat) {
                e.preventDefault();
                jog.press(axis, b.direction, b.mode);
              }
            }}
            onKeyUp={(e) => {
              if (e.key === ' ' || e.key === 'Enter') jog.release('key released');
            }}
            onBlur={() => jog.release('button lost focus')}
          >
            {b.fkey && <kbd class="jog-key">{b.fkey}</kbd>}
            <span class="jog-label">{b.label}</span>
            <span class="jog-velo">{b.velocity === null ? '…' : `${b.velocity} ${unit}/s`}</span>
          </button>
        ))}
      </div>
      <div class="jog-state muted small" data-jog-phase={s.axis === axis ? s.phase : 'idle'}>
        {s.phase !== 'idle' && s.axis === axis
          ? s.phase === 'starting'
            ? 'starting…'
            : `jogging · command #${s.command}`
          : s.phase !== 'idle'
            ? `jogging ${s.axis}`
            : s.lastAxis === axis && s.error
              ? <span class="text-error">jog refused: {s.error}</span>
              : s.lastAxis === axis && s.lastEnd
                ? `released (${s.lastEnd})`
                : 'hold a button to jog (dead-man 0.5 s)'}
      </div>
    </div>
  );
}
