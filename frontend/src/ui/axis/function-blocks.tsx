// The Functions tab's single-axis blocks (docs/single-axis-blocks.md): MC_TorqueControl with the
// drive's operation mode (MC_ReadDriveOperationMode / MC_WriteDriveOperationMode), the position
// correction (AxisEnablePosCorrection #1046, MC_PositionCorrectionLimiter,
// MC_BacklashCompensation, MC_TableBasedPositionCompensation; Enable-type, released with
// DELETE /commands/{id}), and the encoder (MC_SetEncoderScalingFactor, MC_ConvertIncPosToPos /
// MC_ConvertPosToIncPos).
import { useEffect, useState } from 'preact/hooks';
import { api } from '../../api/client';
import type { BlockBody } from '../../api/blocks';
import { href } from '../../router';
import { ActionButton, Led, Panel, errorText, fieldsOf } from '../shared/common';
import { inputNum, num, pos, sig, vel } from '../../format';
import {
  BACKLASH_DEFAULTS,
  CORRECTION_MODES,
  DISABLE_MODES,
  ENCODER_SCALING_DEFAULTS,
  ENCODER_SCALING_MODES,
  LIMITER_DEFAULTS,
  TABLE_COMPENSATION_DEFAULTS,
  TORQUE_DEFAULTS,
  WRITABLE_DRIVE_MODES,
  backlashBody,
  correctionRows,
  encoderScalingBody,
  incPosParams,
  limiterBody,
  posParams,
  tableCompensationBody,
  torqueControlBody,
  writeDriveModeBody,
  type Built,
  type DriveOperationModeResource,
  type PositionConversion,
} from '../../axis/bodies';
import { useCommand, useForm, useRunning } from '../../axis/hooks';
import { NotOffered, NumField, Readout, SelectField, release, type BlockProps } from './block-form';
import { P_BACKLASH, paramDefault } from './axis-params';

const DRIVE_MODE_LABEL: Record<string, string> = {
  configured: 'configured (the drive’s own)',
  position: 'position (CSP)',
  velocity: 'velocity (CSV)',
  torque: 'torque (CST)',
};

/** MC_TorqueControl, back to position control (MC_Halt), and the drive's operation mode. */
export function TorquePanel({ axis: a, s, online, send, driveExecuted }: BlockProps) {
  const axis = a.config.name;
  const u = a.config.unit;
  const offline = !online;
  const vmax = a.config.dynamics?.max_velocity;
  const [f, set] = useForm({ ...TORQUE_DEFAULTS, velocity_limit_high: vmax ? inputNum(vmax) : '', velocity_limit_low: vmax ? inputNum(-vmax) : '' });
  const [err, setErr] = useState<Record<string, string>>({});
  const [haltErr, setHaltErr] = useState<Record<string, string>>({});
  const running = useRunning(axis, 'torque-control');
  const cmd = useCommand(running?.id ?? null);
  const inTorque = !!(running && cmd?.outputs.in_torque);

  // MC_ReadDriveOperationMode on opening and after a write; MC_WriteDriveOperationMode.
  const [read, setRead] = useState<DriveOperationModeResource | null>(null);
  const [readErr, setReadErr] = useState<string | null>(null);
  const [dm, setDm] = useForm({ drive_operation_mode: 'position' });
  const [dmErr, setDmErr] = useState<Record<string, string>>({});
  const readMode = async () => {
    try {
      setRead(await api.GET('/api/v1/axes/{axis}/read-drive-operation-mode', { params: { path: { axis } } }));
      setReadErr(null);
    } catch (e) {
      setReadErr(errorText(e));
    }
  };
  useEffect(() => {
    void readMode();
  }, [axis]);
  const writeMode = async () => {
    await send('write-drive-operation-mode', writeDriveModeBody(dm), setDmErr, { query: { wait: true, timeout_ms: 2000 } });
    await readMode();
  };
  const mode = s?.drive_operation_mode;

  return (
    <Panel title="Torque control" class="torque">
      <Readout label="Drive operation mode" value={mode ?? '—'} name="drive_operation_mode" title="The mode the drive reports (live status)" />
      <Readout label="Actual torque" value={num(s?.actual_torque, 2)} unit="%" name="actual_torque" title="The drive's actual torque, percent of rated torque" />
      <Readout label="Set torque" value={num(s?.set_torque, 2)} unit="%" name="set_torque" title="MC_TorqueControl's torque setpoint now" />
      <Readout label="Actual velocity" value={vel(s?.actual_velocity)} unit={`${u}/s`} name="actual_velocity" />
      <div class="led-grid torque-leds">
        <Led on={mode === 'torque'} label="Torque mode" tone="blue" />
        <Led on={inTorque} label="InTorque" title="The torque is built up and no velocity limit is active" />
        <Led on={s?.torque_velocity_limited} label="Velocity limited" tone="amber" title="The drive holds the velocity at a limit" />
        <Led on={s?.control_loop_closed} label="Loop closed" title="Operational with the position loop closed (open in torque mode)" />
      </div>
      {driveExecuted && <NotOffered what="MC_TorqueControl and MC_WriteDriveOperationMode" />}
      <fieldset class="plain-fieldset" disabled={driveExecuted} data-blocks="torque-control">
        <h4 class="sub">MC_TorqueControl · MC_Halt</h4>
        <form
          class="row"
          data-form="torque-control"
          onSubmit={(e) => {
            e.preventDefault();
            if (online) void send('torque-control', torqueControlBody(f), setErr);
          }}
        >
          <NumField f={f} set={set} k="torque" label={f.relative === '1' ? 'Torque change (%)' : 'Torque (%)'} errors={err} name="torque-torque" hint="of rated torque; positive drives the positive way" />
          <NumField f={f} set={set} k="torque_ramp" label="Torque ramp (%/s)" errors={err} name="torque-ramp" hint="> 0" />
          <NumField f={f} set={set} k="velocity_limit_high" label={`Limit high (${u}/s)`} errors={err} name="torque-limit-high" hint="velocity limit high: within ±AxisVeloMax" />
          <NumField f={f} set={set} k="velocity_limit_low" label={`Limit low (${u}/s)`} errors={err} name="torque-limit-low" hint="velocity limit low: ≤ the high limit" />
          <NumField f={f} set={set} k="manual_start_torque" label="Start torque (%)" errors={err} name="torque-start-torque" placeholder="actual" hint="blank = the drive's actual torque" />
          <label class="check" title="The torque is a change of the running torque control's target">
            <input type="checkbox" name="torque-relative" checked={f.relative === '1'} onChange={(e) => set('relative', (e.target as HTMLInputElement).checked ? '1' : '')} /> relative
          </label>
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="torque-start" disabled={offline} title="MC_TorqueControl: the drive in torque mode, the torque ramped, the velocity kept within the limits">
              Start
            </button>
            <ActionButton name="torque-halt" kind="warn" disabled={offline} title="MC_Halt: back to position control, from where the load is and how fast it goes" onClick={() => send('halt', { body: {}, errors: {} }, setHaltErr)}>
              Back to position control
            </ActionButton>
          </div>
        </form>
        {haltErr.body && <div class="field-error">{haltErr.body}</div>}
        <p class="small muted panel-note">
          {running ? `#${running.id} ${running.state}. ` : ''}Halt, Stop or any move takes the axis back to position control. On the simulated drive the torque moves a model (acceleration per
          percent, friction).
        </p>
      </fieldset>
      <h4 class="sub">MC_ReadDriveOperationMode · MC_WriteDriveOperationMode</h4>
      <form
        class="row drive-mode"
        data-form="drive-mode"
        onSubmit={(e) => {
          e.preventDefault();
          if (online && !driveExecuted) void writeMode();
        }}
      >
        <div class="field drive-mode-read" data-field="drive-mode-read">
          <span class="field-label">Drive reports</span>
          <span class="drive-mode-value" data-testid="drive-mode-read" title={read ? `E_DriveOperationMode ${read.code}, cycle ${read.cycle}` : undefined}>
            {read ? (
              <>
                <b>{read.drive_operation_mode}</b> <span class="muted small">code {read.code}</span>
              </>
            ) : (
              <span class="muted">{readErr ?? '—'}</span>
            )}
          </span>
        </div>
        <ActionButton name="drive-mode-read" title="MC_ReadDriveOperationMode" onClick={readMode}>
          Read
        </ActionButton>
        <SelectField
          f={dm}
          set={setDm}
          k="drive_operation_mode"
          label="Mode to write"
          errors={dmErr}
          options={WRITABLE_DRIVE_MODES.map((m) => [m, DRIVE_MODE_LABEL[m] ?? m])}
          name="drive-mode"
          title="Position-based modes only, at rest (torque is MC_TorqueControl's)"
          disabled={driveExecuted}
        />
        <div class="row-buttons">
          <button type="submit" class="btn" name="drive-mode-write" disabled={offline || driveExecuted} title="MC_WriteDriveOperationMode (at rest); Done once the drive reports the mode">
            Write
          </button>
        </div>
      </form>
    </Panel>
  );
}

/** AxisEnablePosCorrection (#1046) and the three correction sources. */
export function PositionCorrectionPanel({ axis: a, s, online, send, setBanner, params, driveExecuted }: BlockProps) {
  const axis = a.config.name;
  const u = a.config.unit;
  const backlash = paramDefault(params, P_BACKLASH);
  const offline = !online;
  const [param, setParam] = useState<boolean | null>(null);
  const [paramErr, setParamErr] = useState<string | null>(null);
  const readParam = () =>
    api.GET('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis, parameter: 'AxisEnablePosCorrection' } } }).then(
      (p) => setParam(p.value === true || p.value === 1),
      () => setParam(null),
    );
  useEffect(() => {
    void readParam();
  }, [axis]);
  const enable = async () => {
    try {
      setParamErr(null);
      const p = await api.PUT('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis, parameter: 'AxisEnablePosCorrection' } }, body: { value: true } });
      setParam(p.value === true || p.value === 1);
    } catch (e) {
      setParamErr(errorText(e));
    }
  };

  const [lim, setLim] = useForm(LIMITER_DEFAULTS);
  const [limErr, setLimErr] = useState<Record<string, string>>({});
  const [bl, setBl] = useForm(BACKLASH_DEFAULTS);
  const [blErr, setBlErr] = useState<Record<string, string>>({});
  const [tab, setTab] = useForm(TABLE_COMPENSATION_DEFAULTS);
  const [tabErr, setTabErr] = useState<Record<string, string>>({});
  const limCmd = useRunning(axis, 'position-correction-limiter');
  const blCmd = useRunning(axis, 'backlash-compensation');
  const tabCmd = useRunning(axis, 'table-based-position-compensation');
  // A refusal for want of #1046 (invalid_mode): read the parameter again, someone may have changed it.
  const start = async <N extends 'position-correction-limiter' | 'backlash-compensation' | 'table-based-position-compensation'>(name: N, built: Built<BlockBody<N>>, setErr: (e: Record<string, string>) => void) => {
    const r = await send(name, built, setErr);
    if (!r) void readParam();
  };
  const table = a.config.position_compensation_table;
  const c = s?.position_correction;
  const rows = correctionRows(c);
  const releaseButton = (name: string, running: { id: number | null } | null, what: string) => (
    <ActionButton
      name={name}
      kind="warn"
      disabled={offline || !running?.id}
      title={running?.id ? `Release #${running.id} (${what})` : 'Nothing to release'}
      onClick={() => (running?.id ? release(running.id, axis, setBanner) : undefined)}
    >
      Release{running?.id ? ` #${running.id}` : ''}
    </ActionButton>
  );

  return (
    <Panel title="Position correction" class="poscorr">
      <div class="poscorr-param" data-testid="pos-correction-param" data-on={param ? '1' : '0'}>
        <span>
          <a href={href({ page: 'axis', axis, tab: 'parameters' })}>AxisEnablePosCorrection</a> (#1046):{' '}
          <b data-testid="pos-correction-enabled">{param === null ? '—' : param ? 'on' : 'off'}</b>
        </span>
        <ActionButton name="enable-pos-correction" disabled={offline || param === true} title="PUT /parameters/AxisEnablePosCorrection {value: true} (online, not saved in the configuration)" onClick={enable}>
          Enable #1046
        </ActionButton>
      </div>
      {paramErr && <div class="field-error">{paramErr}</div>}
      <p class="small muted panel-note">The limiter, backlash and table compensation need #1046. Their sum is taken off the drive's setpoint and added to the actual position.</p>
      <table class="grid correction" data-testid="position-correction">
        <thead>
          <tr>
            <th>Source</th>
            <th class="r">Correction ({u})</th>
            <th>Enabled</th>
            <th>Limiting</th>
          </tr>
        </thead>
        <tbody>
          {rows.map(([k, l, v, on, limiting]) => (
            <tr data-correction={k}>
              <th>{l}</th>
              <td class="mono r" data-value>
                {pos(v)}
              </td>
              <td>
                <Led on={on} label={on ? 'yes' : 'no'} tone="blue" />
              </td>
              <td>
                <Led on={limiting} label={limiting ? 'yes' : 'no'} tone="amber" />
              </td>
            </tr>
          ))}
          <tr data-correction="total" class="correction-total">
            <th>Total</th>
            <td class="mono r" data-value>
              {pos(c?.total)}
            </td>
            <td colSpan={2} />
          </tr>
        </tbody>
      </table>

      {driveExecuted && <NotOffered what="The limiter, backlash and table compensation" />}
      <fieldset class="plain-fieldset" disabled={driveExecuted} data-blocks="position-correction">
        <h4 class="sub">MC_PositionCorrectionLimiter</h4>
        <form
          class="row"
          data-form="limiter"
          onSubmit={(e) => {
            e.preventDefault();
            if (online) void start('position-correction-limiter', limiterBody(lim), setLimErr);
          }}
        >
          <NumField f={lim} set={setLim} k="value" label={`Correction (${u})`} errors={limErr} name="limiter-value" />
          <SelectField f={lim} set={setLim} k="mode" label="Mode" errors={limErr} options={CORRECTION_MODES} name="limiter-mode" />
          {lim.mode === 'fast' && <NumField f={lim} set={setLim} k="acceleration" label={`Acc (${u}/s²)`} errors={limErr} name="limiter-acceleration" placeholder="0" hint="blank or 0 = no limitation" />}
          {lim.mode === 'full_length' && <NumField f={lim} set={setLim} k="correction_length" label={`Correction length (${u})`} errors={limErr} name="limiter-length" hint="the travel a change is spread over (> 0)" />}
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="limiter-start" disabled={offline} title="MC_PositionCorrectionLimiter (a running one is taken over from where it is)">
              Start
            </button>
            {releaseButton('limiter-release', limCmd, 'the correction stays where it is')}
          </div>
        </form>

        <h4 class="sub">MC_BacklashCompensation</h4>
        <form
          class="row"
          data-form="backlash"
          onSubmit={(e) => {
            e.preventDefault();
            if (online) void start('backlash-compensation', backlashBody(bl), setBlErr);
          }}
        >
          <NumField f={bl} set={setBl} k="backlash" label={`Backlash (${u})`} errors={blErr} name="backlash-value" placeholder={backlash.placeholder} hint={backlash.title} />
          <NumField f={bl} set={setBl} k="ramp" label={`Ramp (${u}/s)`} errors={blErr} name="backlash-ramp" hint="> 0" />
          <SelectField f={bl} set={setBl} k="disable_mode" label="On release" errors={blErr} options={DISABLE_MODES} name="backlash-disable-mode" title="hold: the correction stays; reset: back to 0 at once" />
          <label class="check" title="false: compensated while travelling negative (left flank); true: while positive">
            <input
              type="checkbox"
              name="backlash-positive"
              checked={bl.compensate_in_positive_direction === '1'}
              onChange={(e) => setBl('compensate_in_positive_direction', (e.target as HTMLInputElement).checked ? '1' : '')}
            />{' '}
            positive direction
          </label>
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="backlash-start" disabled={offline} title="MC_BacklashCompensation">
              Start
            </button>
            {releaseButton('backlash-release', blCmd, `${bl.disable_mode || 'hold'} as started`)}
          </div>
        </form>

        <h4 class="sub">MC_TableBasedPositionCompensation</h4>
        <form
          class="row"
          data-form="table-compensation"
          onSubmit={(e) => {
            e.preventDefault();
            if (online) void start('table-based-position-compensation', tableCompensationBody(tab), setTabErr);
          }}
        >
          <NumField f={tab} set={setTab} k="ramp" label={`Ramp (${u}/s)`} errors={tabErr} name="table-ramp" hint="> 0" />
          <SelectField f={tab} set={setTab} k="disable_mode" label="On release" errors={tabErr} options={DISABLE_MODES} name="table-disable-mode" title="hold: the correction stays; reset: back to 0 at once" />
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="table-start" disabled={offline} title="MC_TableBasedPositionCompensation">
              Start
            </button>
            {releaseButton('table-release', tabCmd, 'as its disable mode says')}
          </div>
        </form>
      </fieldset>
      <p class="small muted panel-note" data-testid="compensation-table">
        The table is <code>position_compensation_table</code> of the axis configuration (set with the configuration, not on this page):{' '}
        {table ? (
          <>
            {table.compensation.length} values from {num(table.min_position, 3)} to {num(table.max_position, 3)} {u}
            {table.direction && table.direction !== 'both' ? `, ${table.direction} travel only` : ''}
            {table.modulo ? ', periodic' : ''}.
          </>
        ) : (
          <>none configured.</>
        )}
      </p>
    </Panel>
  );
}

type Conversion = { ok: PositionConversion } | null;

/** The encoder: its scaling and count, MC_SetEncoderScalingFactor, and the conversions. */
export function EncoderPanel({ axis: a, s, online, send, driveExecuted }: BlockProps) {
  const axis = a.config.name;
  const u = a.config.unit;
  const offline = !online;
  const [f, set] = useForm(ENCODER_SCALING_DEFAULTS);
  const [err, setErr] = useState<Record<string, string>>({});
  const [conv, setConv] = useForm({ inc_pos: '', position: '' });
  const [convErr, setConvErr] = useState<Record<string, string>>({});
  const [toPos, setToPos] = useState<Conversion>(null);
  const [toInc, setToInc] = useState<Conversion>(null);

  const convert = async (key: 'inc_pos' | 'position', errors: Record<string, string>, read: () => Promise<PositionConversion>, setOut: (c: Conversion) => void) => {
    const others = Object.fromEntries(Object.entries(convErr).filter(([k]) => k !== key));
    if (errors[key]) {
      setConvErr({ ...others, ...errors });
      return;
    }
    try {
      setOut({ ok: await read() });
      setConvErr(others);
    } catch (e) {
      const fl = fieldsOf(e);
      setOut(null);
      setConvErr({ ...others, [key]: fl[key] ?? fl.query ?? errorText(e) });
    }
  };

  return (
    <Panel title="Encoder" class="encoder">
      <Readout label="Scaling factor" value={sig(s?.encoder_scaling_factor, 9)} unit={`${u}/inc`} name="encoder_scaling_factor" title="AxisEncoderScalingFactor (#1040) now" />
      <Readout label="Encoder count" value={s ? String(s.encoder_count) : '—'} unit="inc" name="encoder_count" title="The raw count (drive position ÷ the build-time scaling, masked by #1043)" />
      {driveExecuted && <NotOffered what="MC_SetEncoderScalingFactor" />}
      <fieldset class="plain-fieldset" disabled={driveExecuted} data-blocks="encoder-scaling">
        <h4 class="sub">MC_SetEncoderScalingFactor</h4>
        <form
          class="row"
          data-form="encoder-scaling"
          onSubmit={(e) => {
            e.preventDefault();
            if (online) void send('set-encoder-scaling-factor', encoderScalingBody(f), setErr);
          }}
        >
          <NumField f={f} set={set} k="scaling_factor" label={`Scaling factor (${u}/inc)`} errors={err} name="encoder-scaling-factor" placeholder={s ? sig(s.encoder_scaling_factor, 9) : ''} hint="> 0" />
          <SelectField f={f} set={set} k="mode" label="Mode" errors={err} options={ENCODER_SCALING_MODES} name="encoder-scaling-mode" title="absolute: the position jumps (at rest only); relative: no jump, also in motion" />
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="encoder-scaling-set" disabled={offline} title="MC_SetEncoderScalingFactor">
              Set
            </button>
          </div>
        </form>
      </fieldset>
      <h4 class="sub">MC_ConvertIncPosToPos · MC_ConvertPosToIncPos</h4>
      <form
        class="row conv"
        data-form="convert-inc-pos"
        onSubmit={(e) => {
          e.preventDefault();
          const q = incPosParams(conv);
          void convert('inc_pos', q.errors, () => api.GET('/api/v1/axes/{axis}/convert-inc-pos-to-pos', { params: { path: { axis }, query: q.body } }), setToPos);
        }}
      >
        <NumField f={conv} set={setConv} k="inc_pos" label="Encoder count (inc)" errors={convErr} name="convert-inc-pos" />
        <div class="row-buttons">
          <button type="submit" class="btn" name="convert-inc" title="MC_ConvertIncPosToPos">
            → position
          </button>
        </div>
        <span class="conv-result mono" data-testid="convert-to-pos">
          {toPos ? `${pos(toPos.ok.position)} ${u}` : ''}
        </span>
      </form>
      <form
        class="row conv"
        data-form="convert-position"
        onSubmit={(e) => {
          e.preventDefault();
          const q = posParams(conv);
          void convert('position', q.errors, () => api.GET('/api/v1/axes/{axis}/convert-pos-to-inc-pos', { params: { path: { axis }, query: q.body } }), setToInc);
        }}
      >
        <NumField f={conv} set={setConv} k="position" label={`Position (${u})`} errors={convErr} name="convert-position" />
        <div class="row-buttons">
          <button type="submit" class="btn" name="convert-pos" title="MC_ConvertPosToIncPos">
            → count
          </button>
        </div>
        <span class="conv-result mono" data-testid="convert-to-inc">
          {toInc ? `${toInc.ok.inc_pos} inc` : ''}
        </span>
      </form>
      {(toPos || toInc) && (
        <p class="small muted panel-note">
          Counted from count {(toInc ?? toPos)!.ok.encoder_count} at {pos((toInc ?? toPos)!.ok.actual_position)} {u} (cycle {(toInc ?? toPos)!.ok.cycle}), the short way round the counter.
        </p>
      )}
    </Panel>
  );
}
