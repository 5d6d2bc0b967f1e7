// The override slider of the Online tab. It sets the MC_SetOverride factor (0–100 %); the
// axis's effective override (`status.override_percent`) is the MC_Power override
// (`status.power_override_percent`) × that factor (`status.set_override_factor`), all three
// reported by the server. It follows changes made elsewhere (another client, a power command)
// unless the user is moving it.
import { useEffect, useRef, useState } from 'preact/hooks';
import { command } from '../../services';
import { errorText } from '../shared/common';
import { num } from '../../format';
import type { AxisStatus } from '../../api/types';

/** After the user's last input the slider waits this long for the axis to follow. */
export const HOLD_MS = 600;
const THROTTLE_MS = 100;

/** The parts of the axis status the control shows. */
export type OverrideStatus = Pick<AxisStatus, 'override_percent' | 'power_override_percent' | 'set_override_factor'>;

/** The MC_SetOverride factor (0…1) as the slider's percent, or null if unknown. */
export function factorPercent(factor: number | null | undefined): number | null {
  if (factor === null || factor === undefined || !Number.isFinite(factor)) return null;
  return Math.min(100, Math.max(0, Math.round(factor * 100)));
}

export function OverrideControl({ axis, status, online, onError, notOffered }: {
  axis: string;
  /** The axis status (null before the first one). */
  status: OverrideStatus | null;
  online: boolean;
  onError: (text: string) => void;
  /** Why MC_SetOverride is not offered on this axis (its drive runs the profile), or null. */
  notOffered?: string | null;
}) {
  const power = status ? status.power_override_percent : null;
  const effective = status?.override_percent;

  const [value, setValue] = useState<number | null>(null);
  const dragging = useRef(false);
  const lastInput = useRef(0);
  const timer = useRef<ReturnType<typeof setTimeout> | null>(null);
  const wanted = useRef<number | null>(null);
  const later = useRef<ReturnType<typeof setTimeout> | null>(null);
  const tracked = factorPercent(status?.set_override_factor);
  const trackedRef = useRef(tracked);
  trackedRef.current = tracked;

  /** Show the axis's value, unless the user is busy with the slider. */
  const sync = () => {
    if (dragging.current || timer.current || Date.now() - lastInput.current < HOLD_MS) return;
    if (trackedRef.current !== null) setValue(trackedRef.current);
  };
  const syncLater = () => {
    if (later.current) clearTimeout(later.current);
    later.current = setTimeout(sync, HOLD_MS + 10);
  };
  useEffect(sync, [tracked]);
  useEffect(
    () => () => {
      if (timer.current) clearTimeout(timer.current);
      if (later.current) clearTimeout(later.current);
    },
    [],
  );

  const send = (v: number) => {
    if (notOffered) return;
    setValue(v);
    wanted.current = v;
    lastInput.current = Date.now();
    // Throttled while dragging: one command every 100 ms, the last value always.
    if (timer.current) return;
    timer.current = setTimeout(async function flush() {
      const v = wanted.current!;
      try {
        await command(axis, 'set-override', { velocity_factor: v / 100 });
      } catch (e) {
        onError(errorText(e));
      }
      if (wanted.current !== v) {
        timer.current = setTimeout(flush, THROTTLE_MS);
      } else {
        timer.current = null;
        syncLater();
      }
    }, THROTTLE_MS);
  };

  const grab = () => {
    dragging.current = true;
    const drop = () => {
      dragging.current = false;
      window.removeEventListener('pointerup', drop);
      window.removeEventListener('pointercancel', drop);
      syncLater();
    };
    window.addEventListener('pointerup', drop);
    window.addEventListener('pointercancel', drop);
  };

  return (
    <div class="row override">
      <span class="field-label" title={notOffered ? `MC_SetOverride is ${notOffered}` : 'MC_SetOverride: velocity factor of this axis'}>
        Override
      </span>
      <input
        type="range"
        name="override"
        min={0}
        max={100}
        step={1}
        value={value ?? 100}
        disabled={!online || !!notOffered}
        title={notOffered ? `MC_SetOverride is ${notOffered}` : undefined}
        onPointerDown={grab}
        onInput={(e) => send(Number((e.target as HTMLInputElement).value))}
      />
      <span class="mono override-value" data-testid="override-value">
        {value ?? '—'} %
      </span>
      {[0, 25, 50, 100].map((v) => (
        <button type="button" class="btn btn-small" name={`override-${v}`} disabled={!online || !!notOffered} title={notOffered ? `MC_SetOverride is ${notOffered}` : undefined} onClick={() => send(v)}>
          {v}
        </button>
      ))}
      {notOffered && (
        <div class="small muted override-power" data-testid="override-not-offered">
          The override is {notOffered}.
        </div>
      )}
      {power !== null && power !== 100 && (
        <div class="small muted override-power" data-testid="override-power">
          × MC_Power override {Number(power.toFixed(1))} % = {num(effective, 1)} % effective
        </div>
      )}
    </div>
  );
}
