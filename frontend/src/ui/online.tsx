// The axis "Online" tab: live readouts, status LEDs, enable/override/reset, jog, moves,
// halt/stop, set position, home, and the axis's command log.
import { useEffect, useRef, useState } from 'preact/hooks';
import { useStore } from '../store';
import { command, live, releaseCommand, resetLagPeak, statuses } from '../services';
import { ActionButton, ErrorBanner, Field, Led, NumberInput, Panel, errorText, fieldsOf, parseNum } from './common';
import { acc, pos, vel, num, inputNum } from '../format';
import { get, enc } from '../api/rest';
import type { AxisResource, CommandResource, HomingMode, ParameterResource } from '../api/types';
import { JogButtons, type JogButtonDef } from './jog-buttons';
import { CommandLog } from './command-log';

/** The axis's parameters by number (for jog velocities, increments). */
export function useParameters(axis: string, version = 0): Map<number, ParameterResource> {
  const [map, setMap] = useState(new Map<number, ParameterResource>());
  useEffect(() => {
    let gone = false;
    get<ParameterResource[]>(`/axes/${enc(axis)}/parameters`).then(
      (list) => !gone && setMap(new Map(list.map((p) => [p.number, p]))),
      () => {},
    );
    return () => {
      gone = true;
    };
  }, [axis, version]);
  return map;
}

const numParam = (m: Map<number, ParameterResource>, n: number): number | null => {
  const v = m.get(n)?.value;
  return typeof v === 'number' ? v : null;
};

/** Stop commands issued from this page, by axis (to release the MC_Stop lock). */
const stopIds = new Map<string, number>();

async function findStopCommand(axis: string): Promise<number | null> {
  const known = stopIds.get(axis);
  if (known) return known;
  const list = await get<CommandResource[]>(`/commands?axis=${enc(axis)}&limit=200`);
  const stop = list.find((c) => c.command === 'stop');
  return stop ? stop.id : null;
}

function Readout({ label, value, unit, name, extra }: { label: string; value: string; unit: string; name: string; extra?: preact.ComponentChildren }) {
  return (
    <div class="dro-row" data-readout={name}>
      <span class="dro-label">{label}</span>
      <span class="dro-value mono">{value}</span>
      <span class="dro-unit">{unit}</span>
      {extra}
    </div>
  );
}

type MoveKind = 'move-absolute' | 'move-relative' | 'move-velocity';

export function OnlineTab({ axis: a }: { axis: AxisResource }) {
  const axis = a.config.name;
  const u = a.config.unit;
  const st = useStore(statuses);
  const conn = useStore(live.state);
  const liveStatus = st.get(axis);
  const s = liveStatus?.status ?? null;
  const offline = conn.kind !== 'open';
  const params = useParameters(axis);
  const [error, setError] = useState<string | null>(null);

  // --- enable -------------------------------------------------------------------------
  const [ctrl, setCtrl] = useState(true);
  const [feedPos, setFeedPos] = useState(true);
  const [feedNeg, setFeedNeg] = useState(true);
  const [override, setOverride] = useState<number | null>(null);
  const seeded = useRef(false);
  useEffect(() => {
    if (override === null && s) setOverride(Math.round(s.override_percent));
    // The enable checkboxes start as the axis is (all on for a disabled axis).
    if (!seeded.current && s) {
      seeded.current = true;
      if (s.power_status) {
        setFeedPos(s.enable_positive);
        setFeedNeg(s.enable_negative);
      }
    }
  }, [s, override]);
  const overrideTimer = useRef<ReturnType<typeof setTimeout> | null>(null);
  const overrideSent = useRef<number | null>(null);
  const sendOverride = (v: number) => {
    setOverride(v);
    overrideSent.current = v;
    // Throttled while dragging: one command every 100 ms, the last value always.
    if (overrideTimer.current) return;
    overrideTimer.current = setTimeout(async function flush() {
      const value = overrideSent.current!;
      try {
        await command(axis, 'set-override', { velocity_factor: value / 100 });
      } catch (e) {
        setError(errorText(e));
      }
      overrideTimer.current = overrideSent.current !== value ? setTimeout(flush, 100) : null;
    }, 100);
  };

  const run = async (name: string, body: Record<string, unknown> = {}) => {
    setError(null);
    try {
      return await command(axis, name, body);
    } catch (e) {
      setError(errorText(e));
      throw e;
    }
  };

  // --- move -----------------------------------------------------------------------------
  const [moveKind, setMoveKind] = useState<MoveKind>('move-absolute');
  const [target, setTarget] = useState('');
  const [distance, setDistance] = useState('');
  const [velocity, setVelocity] = useState('');
  const [direction, setDirection] = useState<'positive' | 'negative'>('positive');
  const [accel, setAccel] = useState('0');
  const [decel, setDecel] = useState('0');
  const [jerk, setJerk] = useState('0');
  const [moveErrors, setMoveErrors] = useState<Record<string, string>>({});
  useEffect(() => {
    const fast = numParam(params, 1002);
    if (velocity === '' && fast !== null) setVelocity(inputNum(fast));
  }, [params]);
  const startMove = async () => {
    const errs: Record<string, string> = {};
    const body: Record<string, unknown> = {
      velocity: parseNum(velocity),
      acceleration: parseNum(accel, 0),
      deceleration: parseNum(decel, 0),
      jerk: parseNum(jerk, 0),
    };
    if (moveKind === 'move-absolute') {
      if (target.trim() === '') errs.position = 'enter a target position';
      body.position = parseNum(target);
    } else if (moveKind === 'move-relative') {
      if (distance.trim() === '') errs.position = 'enter a distance';
      body.position = parseNum(distance);
    } else {
      body.direction = direction;
    }
    if (velocity.trim() === '') errs.velocity = 'enter a velocity';
    setMoveErrors(errs);
    if (Object.keys(errs).length) return;
    try {
      await run(moveKind, body);
    } catch (e) {
      setMoveErrors(fieldsOf(e));
    }
  };

  // --- set position / home --------------------------------------------------------------
  const [setPos, setSetPos] = useState('0');
  const [setPosErrors, setSetPosErrors] = useState<Record<string, string>>({});
  const [homeMode, setHomeMode] = useState<HomingMode>('default');
  const [homePos, setHomePos] = useState('');
  const [homeErrors, setHomeErrors] = useState<Record<string, string>>({});

  // --- inching --------------------------------------------------------------------------
  const [inc, setInc] = useState('');
  const [incErrors, setIncErrors] = useState<Record<string, string>>({});
  useEffect(() => {
    const i = numParam(params, 1014);
    if (inc === '' && i !== null) setInc(inputNum(i));
  }, [params]);
  const inch = async (forward: boolean) => {
    setIncErrors({});
    const slow = numParam(params, 1001) ?? 0;
    try {
      // One step per click; not held (a positioning job of `position` distance).
      await command(axis, 'jog', {
        direction: forward ? 'forward' : 'backward',
        mode: 'inching',
        position: parseNum(inc),
        velocity: slow,
      });
    } catch (e) {
      setIncErrors(fieldsOf(e));
      setError(errorText(e));
    }
  };

  const slow = numParam(params, 1001);
  const fast = numParam(params, 1002);
  const jogButtons: JogButtonDef[] = [
    { key: 'fast-backward', label: '−−', direction: 'backward', mode: 'standard_fast', velocity: fast },
    { key: 'slow-backward', label: '−', direction: 'backward', mode: 'standard_slow', velocity: slow },
    { key: 'slow-forward', label: '+', direction: 'forward', mode: 'standard_slow', velocity: slow },
    { key: 'fast-forward', label: '++', direction: 'forward', mode: 'standard_fast', velocity: fast },
  ];

  const stale = liveStatus?.stale || offline;
  const lagUnit = u;
  return (
    <div class={`online ${stale ? 'stale' : ''}`}>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <div class="online-grid">
        <div class="online-col">
          <Panel title="Live" class="dro" actions={<span class="muted small">{stale ? 'not live' : s ? `cycle ${liveStatus?.cycle}` : ''}</span>}>
            <Readout name="set_position" label="Set position" value={pos(s?.set_position)} unit={u} />
            <Readout name="actual_position" label="Actual position" value={pos(s?.actual_position)} unit={u} />
            <Readout name="set_velocity" label="Set velocity" value={vel(s?.set_velocity)} unit={`${u}/s`} />
            <Readout name="actual_velocity" label="Actual velocity" value={vel(s?.actual_velocity)} unit={`${u}/s`} />
            <Readout name="set_acceleration" label="Set acceleration" value={acc(s?.set_acceleration)} unit={`${u}/s²`} />
            <Readout name="following_error" label="Following error" value={pos(s?.following_error)} unit={lagUnit} />
            <div class="dro-row dro-peak" data-readout="lag_peak">
              <span class="dro-label" title="lowest and highest following error seen since the last reset">Lag peak − / +</span>
              <span class="dro-value mono small">
                {pos(liveStatus?.lagMin)} / {pos(liveStatus?.lagMax)}
              </span>
              <span class="dro-unit">
                <button type="button" class="btn btn-small" name="reset-peak" onClick={() => resetLagPeak(axis)} title="Reset the peak hold">
                  reset
                </button>
              </span>
            </div>
            <Readout name="target_position" label="Target position" value={pos(s?.target_position)} unit={u} />
            <Readout name="remaining_distance" label="Remaining distance" value={pos(s?.remaining_distance)} unit={u} />
            <Readout name="override" label="Override (effective)" value={num(s?.override_percent, 1)} unit="%" />
            {a.config.modulo && <Readout name="modulo" label="Modulo set position" value={pos(s?.modulo_set_position)} unit={`${u} (turn ${s?.modulo_set_turns ?? '—'})`} />}
          </Panel>
          <Panel title="Status" class="leds">
            <div class="led-grid">
              <Led on={s?.power_status} label="Enabled" />
              <Led on={s?.enable_positive} label="Feed +" />
              <Led on={s?.enable_negative} label="Feed −" />
              <Led on={s?.homed} label="Homed" />
              <Led on={s?.has_job} label="Has job" tone="blue" />
              <Led on={s?.moving_forward} label="Moving +" tone="blue" />
              <Led on={s?.moving_backward} label="Moving −" tone="blue" />
              <Led on={s?.constant_velocity} label="Const. velocity" tone="blue" />
              <Led on={s?.in_target_position} label="In target" />
              <Led on={s?.in_position_area} label="In pos. range" />
              <Led on={s?.command_buffered} label="Buffered" tone="blue" />
              <Led on={s?.motion_commands_locked} label="Stop lock" tone="amber" />
              <Led on={s?.soft_limit_min_exceeded} label="Soft limit −" tone="red" />
              <Led on={s?.soft_limit_max_exceeded} label="Soft limit +" tone="red" />
              <Led on={s?.coupled} label="Coupled" tone="blue" />
              <Led on={s?.drive_fault} label="Drive fault" tone="red" />
            </div>
            {s && s.homing_phase !== 'idle' && <div class="small muted">homing phase: {s.homing_phase}</div>}
          </Panel>
        </div>

        <div class="online-col">
          <Panel title="Enable" class="enable">
            <div class="row">
              <label class="check">
                <input type="checkbox" name="controller" checked={ctrl} onChange={(e) => setCtrl((e.target as HTMLInputElement).checked)} /> Controller
              </label>
              <label class="check">
                <input type="checkbox" name="feed-positive" checked={feedPos} onChange={(e) => setFeedPos((e.target as HTMLInputElement).checked)} /> Feed +
              </label>
              <label class="check">
                <input type="checkbox" name="feed-negative" checked={feedNeg} onChange={(e) => setFeedNeg((e.target as HTMLInputElement).checked)} /> Feed −
              </label>
              <ActionButton
                kind="primary"
                name="power-set"
                disabled={offline}
                title="MC_Power with these enables"
                onClick={() => run('power', { enable: ctrl, enable_positive: feedPos, enable_negative: feedNeg, override_percent: 100 })}
              >
                Set
              </ActionButton>
              <ActionButton
                name="power-off"
                disabled={offline}
                onClick={() => run('power', { enable: false, enable_positive: false, enable_negative: false, override_percent: 100 })}
              >
                Disable
              </ActionButton>
              <ActionButton name="reset" kind="warn" disabled={offline} title="MC_Reset" onClick={() => run('reset')}>
                Reset
              </ActionButton>
            </div>
            <div class="row override">
              <span class="field-label">Override</span>
              <input
                type="range"
                name="override"
                min={0}
                max={100}
                step={1}
                value={override ?? 100}
                disabled={offline}
                onInput={(e) => sendOverride(Number((e.target as HTMLInputElement).value))}
              />
              <span class="mono override-value">{override ?? '—'} %</span>
              {[0, 25, 50, 100].map((v) => (
                <button type="button" class="btn btn-small" disabled={offline} onClick={() => sendOverride(v)}>
                  {v}
                </button>
              ))}
            </div>
          </Panel>

          <Panel title="Jog" class="jog-panel">
            <JogButtons axis={axis} unit={u} buttons={jogButtons} disabled={offline} />
            <div class="row inching">
              <Field label={`Inching step (${u})`} error={incErrors.position} name="inch-step">
                <NumberInput name="inch-step" value={inc} onValue={setInc} />
              </Field>
              <ActionButton name="inch-backward" disabled={offline} onClick={() => inch(false)} title="one step backward">
                ◀ step
              </ActionButton>
              <ActionButton name="inch-forward" disabled={offline} onClick={() => inch(true)} title="one step forward">
                step ▶
              </ActionButton>
            </div>
          </Panel>

          <Panel
            title="Move"
            class="move"
            actions={
              <div class="seg" role="tablist">
                {(
                  [
                    ['move-absolute', 'Absolute'],
                    ['move-relative', 'Relative'],
                    ['move-velocity', 'Velocity'],
                  ] as const
                ).map(([k, label]) => (
                  <button type="button" class={`seg-btn ${moveKind === k ? 'active' : ''}`} data-move={k} onClick={() => { setMoveKind(k); setMoveErrors({}); }}>
                    {label}
                  </button>
                ))}
              </div>
            }
          >
            <form
              class="form-grid move-form"
              onSubmit={(e) => {
                e.preventDefault();
                void startMove();
              }}
            >
              {moveKind === 'move-absolute' && (
                <Field label={`Target (${u})`} error={moveErrors.position} name="position">
                  <NumberInput name="position" value={target} onValue={setTarget} />
                </Field>
              )}
              {moveKind === 'move-relative' && (
                <Field label={`Distance (${u})`} error={moveErrors.position} name="position">
                  <NumberInput name="position" value={distance} onValue={setDistance} />
                </Field>
              )}
              {moveKind === 'move-velocity' && (
                <Field label="Direction" error={moveErrors.direction} name="direction">
                  <select name="direction" value={direction} onChange={(e) => setDirection((e.target as HTMLSelectElement).value as 'positive')}>
                    <option value="positive">positive</option>
                    <option value="negative">negative</option>
                  </select>
                </Field>
              )}
              <Field label={`Velocity (${u}/s)`} error={moveErrors.velocity} name="velocity">
                <NumberInput name="velocity" value={velocity} onValue={setVelocity} />
              </Field>
              <Field label={`Acc (${u}/s²)`} error={moveErrors.acceleration} hint="0 = axis default" name="acceleration">
                <NumberInput name="acceleration" value={accel} onValue={setAccel} />
              </Field>
              <Field label={`Dec (${u}/s²)`} error={moveErrors.deceleration} hint="0 = axis default" name="deceleration">
                <NumberInput name="deceleration" value={decel} onValue={setDecel} />
              </Field>
              <Field label={`Jerk (${u}/s³)`} error={moveErrors.jerk} hint="0 = axis default" name="jerk">
                <NumberInput name="jerk" value={jerk} onValue={setJerk} />
              </Field>
              <div class="form-actions">
                <button type="submit" class="btn btn-primary" name="start" disabled={offline}>
                  Start
                </button>
                <ActionButton name="halt" disabled={offline} title="MC_Halt: decelerate to standstill" onClick={() => run('halt')}>
                  Halt
                </ActionButton>
                <ActionButton
                  name="stop"
                  kind="danger"
                  disabled={offline}
                  title="MC_Stop: stop and lock motion until released"
                  onClick={async () => {
                    const r = await run('stop');
                    stopIds.set(axis, r.id);
                  }}
                >
                  Stop
                </ActionButton>
                {s?.motion_commands_locked && (
                  <ActionButton
                    name="release-stop"
                    kind="warn"
                    disabled={offline}
                    title="Release the MC_Stop (falling edge of Execute)"
                    onClick={async () => {
                      setError(null);
                      try {
                        const id = await findStopCommand(axis);
                        if (id === null) throw new Error('no stop command of this axis is known to the server');
                        await releaseCommand(id, axis);
                        stopIds.delete(axis);
                      } catch (e) {
                        setError(errorText(e));
                      }
                    }}
                  >
                    Release stop
                  </ActionButton>
                )}
              </div>
            </form>
          </Panel>

          <Panel title="Position and homing" class="poshome">
            <form
              class="row"
              onSubmit={async (e) => {
                e.preventDefault();
                setSetPosErrors({});
                try {
                  await run('set-position', { position: parseNum(setPos) });
                } catch (err) {
                  setSetPosErrors(fieldsOf(err));
                }
              }}
            >
              <Field label={`Set actual position to (${u})`} error={setPosErrors.position} name="set-position" class="wide">
                <NumberInput name="set-position" value={setPos} onValue={setSetPos} />
              </Field>
              <button type="submit" class="btn" name="set-position-btn" disabled={offline} title="MC_SetPosition">
                Set position
              </button>
            </form>
            <form
              class="row"
              onSubmit={async (e) => {
                e.preventDefault();
                setHomeErrors({});
                const body: Record<string, unknown> = { mode: homeMode };
                if (homePos.trim() !== '') body.position = parseNum(homePos);
                try {
                  await run('home', body);
                } catch (err) {
                  setHomeErrors(fieldsOf(err));
                }
              }}
            >
              <Field label="Homing mode" name="home-mode" error={homeErrors.mode} class="wide">
                <select name="home-mode" value={homeMode} onChange={(e) => setHomeMode((e.target as HTMLSelectElement).value as HomingMode)}>
                  <option value="default">default: referencing sequence (#1076)</option>
                  <option value="direct">direct: set the position here</option>
                  <option value="force_calibration">force calibration: mark as homed</option>
                  <option value="reset_calibration">reset calibration: mark as not homed</option>
                </select>
              </Field>
              <Field label={`Home position (${u})`} name="home-position" error={homeErrors.position}>
                <NumberInput name="home-position" value={homePos} onValue={setHomePos} placeholder="#1075" title="blank = the calibration value (#1075)" />
              </Field>
              <button type="submit" class="btn" name="home-btn" disabled={offline} title="MC_Home">
                Home
              </button>
            </form>
          </Panel>
        </div>
      </div>
      <Panel title="Commands" class="log-panel">
        <CommandLog axis={axis} limit={30} />
      </Panel>
    </div>
  );
}
