// The axis "Online" tab: live readouts, status LEDs, enable/override/reset, jog and inching,
// moves, halt/stop, set position, home, TwinCAT's function keys, and the axis's command log.
import { useEffect, useRef, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { command, findHeldStop, jog, releaseCommand, resetFollowingErrorPeak, statuses, stopAndRelease } from '../../services';
import { ActionButton, ErrorBanner, Field, Led, NumberInput, Panel, errorText, fieldsOf, parseNum, useOnline } from '../shared/common';
import { acc, pos, vel, num, inputNum } from '../../format';
import type { AxisLiveStatus, AxisResource, Direction, HomingMode } from '../../api/types';
import type { BlockBody, BlockName } from '../../api/blocks';
import { JogButtons, type JogButtonDef } from './jog-buttons';
import { CommandLog } from '../shared/command-log';
import { OverrideControl } from './override';
import { Inching } from './inching';
import { Trend } from './trend';
import { LiveIndicator } from '../shared/liveness';
import { href } from '../../router';
import { hexId } from '../../api/errors';
import { P_HOME_POSITION, P_JOG_FAST, P_JOG_SLOW, numParam, paramDefault, useLiveParameters } from './axis-params';
import { installFunctionKeys, keyOf, type FunctionAction, type FunctionKeyHandlers } from './fkeys';
import { NOT_OFFERED, driveHomingText, homeModeOptions, homesInDrive, isDriveExecuted } from '../../axis/drive-executed';

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

type MoveKind = 'move-absolute' | 'move-relative' | 'move-velocity' | 'move-modulo';

const MOVE_LABEL: Record<MoveKind, string> = {
  'move-absolute': 'Absolute',
  'move-relative': 'Relative',
  'move-velocity': 'Velocity',
  'move-modulo': 'Modulo',
};

const MODULO_DIRECTIONS: [Direction, string][] = [
  ['positive', 'positive'],
  ['negative', 'negative'],
  ['shortest_way', 'shortest way'],
  ['current_direction', 'current direction'],
];

/**
 * The override to send with MC_Power: the one the axis has now (possibly another client's),
 * so enabling never changes the speed; 100 % only while the status is unknown.
 */
export const powerOverride = (s: Pick<AxisLiveStatus, 'power_override_percent'> | null | undefined): number =>
  typeof s?.power_override_percent === 'number' && Number.isFinite(s.power_override_percent) ? s.power_override_percent : 100;

/** " (F6)" for titles. */
const fk = (a: FunctionAction) => ` (${keyOf(a)})`;

export function OnlineTab({ axis: a }: { axis: AxisResource }) {
  const axis = a.config.name;
  const u = a.config.unit;
  const st = useStore(statuses);
  const online = useOnline();
  const liveStatus = st.get(axis);
  const s = liveStatus?.status ?? null;
  const offline = !online;
  const params = useLiveParameters(axis, a.id);
  const homeDefault = paramDefault(params, P_HOME_POSITION);
  const [error, setError] = useState<string | null>(null);
  // The drive runs the profile (Drive Motion Control): no jerk, no override, no inching.
  const de = isDriveExecuted(a.config, s);

  // --- enable -------------------------------------------------------------------------
  const [ctrl, setCtrl] = useState(true);
  const [feedPos, setFeedPos] = useState(true);
  const [feedNeg, setFeedNeg] = useState(true);
  const seeded = useRef(false);
  useEffect(() => {
    // The enable checkboxes start as the axis is (all on for a disabled axis).
    if (!seeded.current && s) {
      seeded.current = true;
      if (s.power_status) {
        setFeedPos(s.enable_positive);
        setFeedNeg(s.enable_negative);
      }
    }
  }, [s]);

  const run = async <N extends BlockName>(name: N, body: BlockBody<N>) => {
    setError(null);
    try {
      return await command(axis, name, body);
    } catch (e) {
      setError(errorText(e));
      throw e;
    }
  };

  // --- move -----------------------------------------------------------------------------
  const moveKinds: MoveKind[] = a.config.modulo
    ? ['move-absolute', 'move-relative', 'move-modulo', 'move-velocity']
    : ['move-absolute', 'move-relative', 'move-velocity'];
  const [moveKind, setMoveKind] = useState<MoveKind>('move-absolute');
  const [target, setTarget] = useState('');
  const [distance, setDistance] = useState('');
  const [moduloTarget, setModuloTarget] = useState('');
  const [velocity, setVelocity] = useState('');
  const [direction, setDirection] = useState<'positive' | 'negative'>('positive');
  const [moduloDir, setModuloDir] = useState<Direction>('positive');
  const [accel, setAccel] = useState('0');
  const [decel, setDecel] = useState('0');
  const [jerk, setJerk] = useState('0');
  const [moveErrors, setMoveErrors] = useState<Record<string, string>>({});
  const moveFormId = `move-form-${a.id}`;
  useEffect(() => {
    const fast = numParam(params, P_JOG_FAST);
    if (velocity === '' && fast !== null) setVelocity(inputNum(fast));
  }, [params]);
  const startMove = async () => {
    const errs: Record<string, string> = {};
    const dynamics = {
      velocity: parseNum(velocity),
      acceleration: parseNum(accel, 0),
      deceleration: parseNum(decel, 0),
      jerk: de ? 0 : parseNum(jerk, 0),
    };
    // A relative move's input is its distance (PLCopen's name), the others' a target position.
    const position = { 'move-absolute': target, 'move-modulo': moduloTarget, 'move-relative': null, 'move-velocity': null }[moveKind];
    if (position !== null && position.trim() === '') errs.position = 'enter a target position';
    if (moveKind === 'move-relative' && distance.trim() === '') errs.distance = 'enter a distance';
    if (velocity.trim() === '') errs.velocity = 'enter a velocity';
    setMoveErrors(errs);
    if (Object.keys(errs).length) return;
    try {
      if (moveKind === 'move-absolute') await run(moveKind, { ...dynamics, position: parseNum(target) });
      else if (moveKind === 'move-modulo') await run(moveKind, { ...dynamics, position: parseNum(moduloTarget), direction: moduloDir });
      else if (moveKind === 'move-relative') await run(moveKind, { ...dynamics, distance: parseNum(distance) });
      else await run(moveKind, { ...dynamics, direction });
    } catch (e) {
      setMoveErrors(fieldsOf(e));
    }
  };

  // --- halt / stop ----------------------------------------------------------------------
  const [stopDec, setStopDec] = useState('');
  const [stopJerk, setStopJerk] = useState('');
  const [stopErrors, setStopErrors] = useState<Record<string, string>>({});
  const stopBody = () => ({ deceleration: parseNum(stopDec, 0), jerk: de ? 0 : parseNum(stopJerk, 0) });
  const halt = async () => {
    setStopErrors({});
    try {
      await run('halt', stopBody());
    } catch (e) {
      setStopErrors(fieldsOf(e));
    }
  };
  // TwinCAT XAE's F6: MC_Stop, released by the UI once the axis stands (the next F9 is taken).
  const stop = async () => {
    setStopErrors({});
    setError(null);
    try {
      const { followed } = await stopAndRelease(axis, stopBody());
      followed.catch((e) => setError(`the stop was not released at standstill: ${errorText(e)}`));
    } catch (e) {
      setStopErrors(fieldsOf(e));
      setError(errorText(e));
    }
  };
  const releaseStop = async () => {
    setError(null);
    try {
      // Asked of the server now: the stop may be another client's or an earlier page's.
      const id = await findHeldStop(axis);
      if (id === null) throw new Error('the server knows no MC_Stop of this axis that holds the lock');
      await releaseCommand(id, axis);
    } catch (e) {
      setError(errorText(e));
    }
  };

  // --- set position / home --------------------------------------------------------------
  const [setPos, setSetPos] = useState('0');
  const [setPosRelative, setSetPosRelative] = useState(false);
  const [setPosClearLag, setSetPosClearLag] = useState(false);
  const [setPosErrors, setSetPosErrors] = useState<Record<string, string>>({});
  const [homeMode, setHomeMode] = useState<HomingMode>('default');
  const [homePos, setHomePos] = useState('');
  const [homeErrors, setHomeErrors] = useState<Record<string, string>>({});
  const setPosition = async () => {
    setSetPosErrors({});
    try {
      await run('set-position', { position: parseNum(setPos), relative: setPosRelative, clear_position_lag: setPosClearLag });
    } catch (err) {
      setSetPosErrors(fieldsOf(err));
    }
  };
  const home = async () => {
    setHomeErrors({});
    const body: BlockBody<'home'> = { mode: homeMode };
    if (homePos.trim() !== '') body.position = parseNum(homePos);
    try {
      await run('home', body);
    } catch (err) {
      setHomeErrors(fieldsOf(err));
    }
  };
  const reset = () => run('reset', {}).catch(() => {});
  const resetPeak = async () => {
    setError(null);
    try {
      await resetFollowingErrorPeak(axis);
    } catch (e) {
      setError(errorText(e));
    }
  };

  // --- jog and function keys ------------------------------------------------------------
  const slow = numParam(params, P_JOG_SLOW);
  const fast = numParam(params, P_JOG_FAST);
  const jogButtons: JogButtonDef[] = [
    { key: 'fast-backward', label: '−−', direction: 'backward', mode: 'standard_fast', velocity: fast, fkey: keyOf('fast-backward') },
    { key: 'slow-backward', label: '−', direction: 'backward', mode: 'standard_slow', velocity: slow, fkey: keyOf('slow-backward') },
    { key: 'slow-forward', label: '+', direction: 'forward', mode: 'standard_slow', velocity: slow, fkey: keyOf('slow-forward') },
    { key: 'fast-forward', label: '++', direction: 'forward', mode: 'standard_fast', velocity: fast, fkey: keyOf('fast-forward') },
  ];
  const keys: FunctionKeyHandlers = {
    enabled: () => online,
    jog: (k) => {
      const b = jogButtons.find((x) => x.key === k)!;
      jog.press(axis, b.direction, b.mode);
    },
    release: (why) => jog.release(why),
    action: (what) => {
      if (what === 'start') void startMove();
      else if (what === 'stop') void stop();
      else if (what === 'reset') void reset();
      else void home();
    },
  };
  const keysRef = useRef(keys);
  keysRef.current = keys;
  useEffect(() => installFunctionKeys(window, () => keysRef.current), []);

  const stale = liveStatus?.stale || offline;
  const lagUnit = u;
  return (
    <div class={`online ${stale ? 'stale' : ''}`}>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <div class="online-grid">
        <div class="online-col">
          <Panel title="Live" class="dro" actions={<LiveIndicator cycle={liveStatus?.cycle} stale={stale} />}>
            <Readout name="set_position" label="Set position" value={pos(s?.set_position)} unit={u} />
            <Readout name="actual_position" label="Actual position" value={pos(s?.actual_position)} unit={u} />
            <Readout name="set_velocity" label="Set velocity" value={vel(s?.set_velocity)} unit={`${u}/s`} />
            <Readout name="actual_velocity" label="Actual velocity" value={vel(s?.actual_velocity)} unit={`${u}/s`} />
            <Readout name="set_acceleration" label="Set acceleration" value={acc(s?.set_acceleration)} unit={`${u}/s²`} />
            <Readout name="following_error" label="Following error" value={pos(s?.following_error)} unit={lagUnit} />
            <div class="dro-row dro-peak" data-readout="lag_peak">
              <span class="dro-label" title="lowest and highest following error of every cycle since the last reset (TwinCAT: lag distance min/max), kept by the server">
                Lag min / max
              </span>
              <span class="dro-value mono small">
                {pos(s?.following_error_min)} / {pos(s?.following_error_max)}
              </span>
              <span class="dro-unit">
                <button type="button" class="btn btn-small" name="reset-peak" disabled={offline} onClick={resetPeak} title="Restart the peak hold from the present following error">
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
            {s?.master && (
              <div class="small muted" data-testid="master">
                coupled to master <a href={href({ page: 'axis', axis: s.master, tab: 'online' })}>{s.master}</a>
              </div>
            )}
            {s && s.homing_phase !== 'idle' && <div class="small muted">homing phase: {s.homing_phase}</div>}
            {!!s?.drive_error_code && (
              <div class="small text-error" data-testid="drive-error-code" title="the drive's own error code (CiA-402 0x603F)">
                drive error code {hexId(s.drive_error_code)}
              </div>
            )}
          </Panel>
          <Trend axis={axis} unit={u} online={online} />
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
                title="MC_Power with these enables (its override stays as the axis has it)"
                onClick={() => run('power', { enable: ctrl, enable_positive: feedPos, enable_negative: feedNeg, override_percent: powerOverride(s) })}
              >
                Set
              </ActionButton>
              <ActionButton
                name="power-off"
                disabled={offline}
                onClick={() => run('power', { enable: false, enable_positive: false, enable_negative: false, override_percent: powerOverride(s) })}
              >
                Disable
              </ActionButton>
              <ActionButton name="reset" kind="warn" disabled={offline} title={`MC_Reset${fk('reset')}`} onClick={reset}>
                Reset
              </ActionButton>
            </div>
            <OverrideControl axis={axis} status={s} online={online} onError={setError} notOffered={de ? NOT_OFFERED : null} />
          </Panel>

          <Panel title="Jog" class="jog-panel">
            <JogButtons axis={axis} unit={u} buttons={jogButtons} disabled={offline} />
            <Inching axis={axis} unit={u} params={params} online={online} onError={setError} notOffered={de ? NOT_OFFERED : null} />
          </Panel>

          <Panel
            title="Move"
            class="move"
            actions={
              <div class="seg" role="tablist">
                {moveKinds.map((k) => (
                  <button type="button" class={`seg-btn ${moveKind === k ? 'active' : ''}`} data-move={k} onClick={() => { setMoveKind(k); setMoveErrors({}); }}>
                    {MOVE_LABEL[k]}
                  </button>
                ))}
              </div>
            }
          >
            <form
              id={moveFormId}
              class="form-grid move-form"
              onSubmit={(e) => {
                e.preventDefault();
                if (online) void startMove();
              }}
            >
              {moveKind === 'move-absolute' && (
                <Field label={`Target (${u})`} error={moveErrors.position} name="position">
                  <NumberInput name="position" value={target} onValue={setTarget} />
                </Field>
              )}
              {moveKind === 'move-relative' && (
                <Field label={`Distance (${u})`} error={moveErrors.distance} name="distance">
                  <NumberInput name="distance" value={distance} onValue={setDistance} />
                </Field>
              )}
              {moveKind === 'move-modulo' && (
                <Field label={`Modulo target (${u})`} error={moveErrors.position} name="position" hint={`0 … ${a.config.modulo?.period ?? ''}`}>
                  <NumberInput name="position" value={moduloTarget} onValue={setModuloTarget} />
                </Field>
              )}
              {moveKind === 'move-modulo' && (
                <Field label="Direction" error={moveErrors.direction} name="direction">
                  <select name="direction" value={moduloDir} onChange={(e) => setModuloDir((e.target as HTMLSelectElement).value as Direction)}>
                    {MODULO_DIRECTIONS.map(([v, label]) => (
                      <option value={v}>{label}</option>
                    ))}
                  </select>
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
              <Field label={`Jerk (${u}/s³)`} error={moveErrors.jerk} hint={de ? 'none: the drive’s profile' : '0 = axis default'} name="jerk">
                <NumberInput name="jerk" value={de ? '' : jerk} onValue={setJerk} disabled={de} placeholder={de ? '—' : undefined} title={de ? `jerk is ${NOT_OFFERED}` : undefined} />
              </Field>
            </form>
            <div class="row stop-row">
              <button type="submit" form={moveFormId} class="btn btn-primary" name="start" disabled={offline} title={`start the ${MOVE_LABEL[moveKind].toLowerCase()} move${fk('start')}`}>
                Start
              </button>
              <Field label={`Stop dec (${u}/s²)`} error={stopErrors.deceleration} name="stop-deceleration">
                <NumberInput name="stop-deceleration" value={stopDec} onValue={setStopDec} placeholder="default" title="MC_Halt / MC_Stop deceleration; blank or 0 = default" />
              </Field>
              <Field label={`Stop jerk (${u}/s³)`} error={stopErrors.jerk} name="stop-jerk">
                <NumberInput
                  name="stop-jerk"
                  value={de ? '' : stopJerk}
                  onValue={setStopJerk}
                  disabled={de}
                  placeholder={de ? '—' : 'default'}
                  title={de ? `jerk is ${NOT_OFFERED}` : 'MC_Halt / MC_Stop jerk; blank or 0 = default'}
                />
              </Field>
              <ActionButton name="halt" disabled={offline} title="MC_Halt: decelerate to standstill" onClick={halt}>
                Halt
              </ActionButton>
              <ActionButton
                name="stop"
                kind="danger"
                disabled={offline}
                title={`MC_Stop${fk('stop')}: decelerate to standstill; there the UI releases the stop, so the axis is ready again (TwinCAT XAE's F6). A stop sent over the API keeps its lock until released.`}
                onClick={stop}
              >
                Stop
              </ActionButton>
              {s?.motion_commands_locked && (
                <ActionButton name="release-stop" kind="warn" disabled={offline} title="Release the MC_Stop that holds the lock — one sent over the API or by another client (falling edge of Execute)" onClick={releaseStop}>
                  Release stop
                </ActionButton>
              )}
            </div>
          </Panel>

          <Panel title="Position and homing" class="poshome">
            <form
              class="row"
              onSubmit={(e) => {
                e.preventDefault();
                if (online) void setPosition();
              }}
            >
              <Field label={`Set actual position ${setPosRelative ? 'by' : 'to'} (${u})`} error={setPosErrors.position} name="set-position" class="wide">
                <NumberInput name="set-position" value={setPos} onValue={setSetPos} />
              </Field>
              <label class="check" title="shift the position by this amount (also while moving)">
                <input type="checkbox" name="set-position-relative" checked={setPosRelative} onChange={(e) => setSetPosRelative((e.target as HTMLInputElement).checked)} /> relative
              </label>
              <label class="check" title="set position = actual position: the following error becomes 0">
                <input type="checkbox" name="set-position-clear-lag" checked={setPosClearLag} onChange={(e) => setSetPosClearLag((e.target as HTMLInputElement).checked)} /> clear lag
              </label>
              <button type="submit" class="btn" name="set-position-btn" disabled={offline} title="MC_SetPosition">
                Set position
              </button>
            </form>
            <form
              class="row"
              onSubmit={(e) => {
                e.preventDefault();
                if (online) void home();
              }}
            >
              <Field label="Homing mode" name="home-mode" error={homeErrors.mode} class="wide">
                <select
                  name="home-mode"
                  title={homesInDrive(homeMode, de) ? driveHomingText(a.config) : 'default: the referencing sequence of the reference mode (#1076)'}
                  value={homeMode}
                  onChange={(e) => setHomeMode((e.target as HTMLSelectElement).value as HomingMode)}
                >
                  {homeModeOptions(a.config, de).map(([m, label, why]) => (
                    <option value={m} disabled={!!why} title={why ?? undefined}>
                      {label}
                    </option>
                  ))}
                </select>
              </Field>
              <Field label={`Home position (${u})`} name="home-position" error={homeErrors.position}>
                <NumberInput name="home-position" value={homePos} onValue={setHomePos} placeholder={homeDefault.placeholder} title={homeDefault.title} />
              </Field>
              <button type="submit" class="btn" name="home-btn" disabled={offline} title={`MC_Home${fk('home')}`}>
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
