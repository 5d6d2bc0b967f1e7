// The axis "Coupling" tab (TwinCAT XAE: the axis's Coupling tab and its superposition): MC_GearIn,
// MC_GearInDyn (released with DELETE /commands/{id}), MC_GearOut, MC_CamIn / MC_CamOut /
// MC_CamScaling, MC_MoveSuperImposed / MC_AbortSuperposition, MC_PhasingAbsolute / Relative /
// MC_HaltPhasing and MC_GearInMultiMaster (coupling-blocks.tsx), and the coupling as the live
// status shows it (master, gear ratio, InGear/InSync of the running command, MC_CamInfo).
import { useEffect, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { axes, commandLog, releaseCommand, statuses } from '../../services';
import { couplerOf, couplingInForce } from '../../axis/coupling-kind';
import { P_ACC, paramDefault, useLiveParameters } from './axis-params';
import { api } from '../../api/client';
import type { AxisResource, CamTableResource } from '../../api/types';
import { href } from '../../router';
import { ActionButton, ErrorBanner, Led, Panel, errorText, useOnline } from '../shared/common';
import { num, pos, vel } from '../../format';
import { LiveIndicator } from '../shared/liveness';
import {
  ABORT_OPTIONS,
  ACTIVATION_MODES,
  CAM_IN_DEFAULTS,
  CAM_SCALING_DEFAULTS,
  SCALING_MODES,
  START_MODES,
  SUPERIMPOSED_DEFAULTS,
  SUPERPOSITION_MODES,
  camInBody,
  camInfoRows,
  camScalingBody,
  gearInBody,
  gearInDynBody,
  superimposedBody,
  takesPosition,
  type Form,
} from '../../axis/bodies';
import { useCommand, useForm } from '../../axis/hooks';
import { MultiMasterPanel, PhasingPanel } from './coupling-blocks';
import { NumField, SelectField, useSender } from './block-form';
import { NOT_OFFERED, isDriveExecuted } from '../../axis/drive-executed';

export function CouplingTab({ axis: a }: { axis: AxisResource }) {
  const axis = a.config.name;
  const u = a.config.unit;
  const list = useStore(axes);
  const st = useStore(statuses);
  const log = useStore(commandLog);
  const online = useOnline();
  const offline = !online;
  const liveStatus = st.get(axis);
  const s = liveStatus?.status ?? null;
  // The drive runs the profile (Drive Motion Control): no coupling block is offered.
  const de = isDriveExecuted(a.config, s);
  const [banner, setBanner] = useState<string | null>(null);
  const send = useSender(axis, setBanner);
  const masters = list.map((x) => x.config.name).filter((n) => n !== axis);
  const params = useLiveParameters(axis, a.id);
  const accZero = paramDefault(params, P_ACC).title.replace(/^blank/, '0');

  const [tables, setTables] = useState<CamTableResource[]>([]);
  useEffect(() => {
    api.GET('/api/v1/cam-tables').then(setTables, () => {});
  }, []);

  const [gear, setGear, setGearAll] = useForm({ master: '', ratio_numerator: '1', ratio_denominator: '1' });
  const [gearErr, setGearErr] = useState<Record<string, string>>({});
  const [dyn, setDyn, setDynAll] = useForm({ master: '', gear_ratio: '1', acceleration: '0' });
  const [dynErr, setDynErr] = useState<Record<string, string>>({});
  const [cam, setCam, setCamAll] = useForm(CAM_IN_DEFAULTS);
  const [camErr, setCamErr] = useState<Record<string, string>>({});
  const [scal, setScal] = useForm(CAM_SCALING_DEFAULTS);
  const [scalErr, setScalErr] = useState<Record<string, string>>({});
  const [sup, setSup] = useForm(SUPERIMPOSED_DEFAULTS);
  const [supErr, setSupErr] = useState<Record<string, string>>({});
  const [outErr, setOutErr] = useState<Record<string, string>>({});

  // The master selects start with the first other axis; the cam select with the first table.
  useEffect(() => {
    const m = masters[0] ?? '';
    if (!gear.master && m) setGearAll({ ...gear, master: m });
    if (!dyn.master && m) setDynAll({ ...dyn, master: m });
    if (!cam.master && m) setCamAll({ ...cam, master: m, cam_table: cam.cam_table || (tables[0]?.name ?? '') });
    else if (!cam.cam_table && tables[0]) setCamAll({ ...cam, cam_table: tables[0].name });
  }, [masters.join('\n'), tables]);

  // The running MC_GearInDyn of this axis (this page's or another's): Release ends its Enable.
  const dynCmd = log.find((e) => e.axis === axis && e.command === 'gear-in-dyn' && !e.final && e.id !== null);
  // InGear / InSync: of the command that coupled the axis (MC_GearIn is done once in gear; the
  // axis's latest coupling command in the log, else its running command).
  const coupler = couplerOf(log, axis);
  const running = useCommand(coupler?.id ?? (s?.active_command || null), `${s?.coupled}/${s?.cam?.active}`);
  const inGear = !!(s?.coupled && running?.outputs.in_gear);
  const inSync = !!(s?.coupled && running?.outputs.in_sync);
  const camRows = camInfoRows(s?.cam);
  const inForce = couplingInForce(s, coupler);
  const stale = liveStatus?.stale || offline;

  return (
    <div class={`coupling ${stale ? 'stale' : ''}`}>
      <ErrorBanner error={banner} onClose={() => setBanner(null)} />
      {de && (
        <div class="banner banner-info" data-testid="coupling-not-offered">
          <span>
            Gear, cam, multi-master gear, phasing and superposition are {NOT_OFFERED}: a coupled slave needs a setpoint from motiond every cycle. The blocks are shown
            disabled.
          </span>
        </div>
      )}
      {/* Disabled as a whole where the drive runs the profile: no block of this tab can be sent. */}
      <fieldset class="plain-fieldset" disabled={de} data-blocks="coupling">
        <div class="coupling-grid">
          <div class="coupling-col">
            <Panel title="Coupling state" class="coupling-state" actions={<LiveIndicator cycle={liveStatus?.cycle} stale={stale} />}>
              <div class="dro-row" data-readout="actual_position">
                <span class="dro-label">Actual position</span>
                <span class="dro-value mono">{pos(s?.actual_position)}</span>
                <span class="dro-unit">{u}</span>
              </div>
              <div class="dro-row" data-readout="actual_velocity">
                <span class="dro-label">Actual velocity</span>
                <span class="dro-value mono">{vel(s?.actual_velocity)}</span>
                <span class="dro-unit">{u}/s</span>
              </div>
              <div class="led-grid coupling-leds">
                <Led on={s?.coupled} label="Coupled" tone="blue" />
                <Led on={inGear} label="InGear" title="InGear of the coupling command (MC_GearIn / MC_GearInDyn / MC_GearInMultiMaster)" />
                <Led on={inSync} label="InSync" title="InSync of the coupling command (MC_CamIn)" />
                <Led on={s?.cam?.active} label="Cam active" tone="blue" />
              </div>
              <dl class="kv" data-testid="coupling-kv">
                <dt>Master</dt>
                <dd data-testid="coupling-master">
                  {s?.master ? (
                    <a href={href({ page: 'axis', axis: s.master, tab: 'coupling' })}>{s.master}</a>
                  ) : (
                    <span class="muted">—</span>
                  )}
                </dd>
                <dt>Coupling</dt>
                <dd data-testid="coupling-kind" data-kind={inForce.kind}>
                  {inForce.kind === 'none' ? <span class="muted">{inForce.text}</span> : inForce.text}
                </dd>
                {(inForce.kind === 'gear' || inForce.kind === 'gear-dyn') && (
                  <>
                    <dt>Gear ratio</dt>
                    <dd class="mono" data-testid="coupling-ratio">
                      {num(s?.gear_ratio, 6)}
                    </dd>
                  </>
                )}
                {inForce.kind === 'multi-master' && (
                  <>
                    <dt>Gear ratios</dt>
                    <dd class="mono" data-testid="coupling-ratios" title="MC_GearInMultiMaster: the ratio of Master1…Master4 in force">
                      {(s?.gear_ratios ?? []).map((r) => num(r, 4)).join(' · ')}
                    </dd>
                  </>
                )}
                {s?.coupled && s.absolute_phase_shift !== 0 && (
                  <>
                    <dt>Phase shift</dt>
                    <dd class="mono">{num(s.absolute_phase_shift, 4)}</dd>
                  </>
                )}
                <dt>Command</dt>
                <dd data-testid="running-command">
                  {running ? (
                    <>
                      #{running.id} {running.command} · {running.state}
                    </>
                  ) : (
                    <span class="muted">none</span>
                  )}
                </dd>
              </dl>
              {camRows.length > 0 && s?.cam && s.cam.cam_table_id !== 0 && (
                <table class="grid caminfo" data-testid="caminfo">
                  <caption>MC_CamInfo</caption>
                  <tbody>
                    {camRows.map(([k, l, v]) => (
                      <tr data-caminfo={k}>
                        <th>{l}</th>
                        <td class="mono">{v}</td>
                      </tr>
                    ))}
                  </tbody>
                </table>
              )}
            </Panel>

            <PhasingPanel axis={a} s={s} online={online} send={send} setBanner={setBanner} masters={masters} params={params} driveExecuted={de} />

            <Panel title="Superposition" class="superposition">
              <div class="led-grid">
                <Led on={s?.compensating} label="Compensating" tone="amber" />
              </div>
              <div class="dro-row" data-readout="superimposed_distance">
                <span class="dro-label">Superimposed distance</span>
                <span class="dro-value mono">{pos(s?.superimposed_distance)}</span>
                <span class="dro-unit">{u}</span>
              </div>
              <h4 class="sub">MC_MoveSuperImposed · MC_AbortSuperposition</h4>
              <form
                class="row"
                onSubmit={(e) => {
                  e.preventDefault();
                  if (online) void send('move-superimposed', superimposedBody(sup), setSupErr);
                }}
              >
                <SelectField f={sup} set={setSup} k="mode" label="Mode" errors={supErr} options={SUPERPOSITION_MODES} name="sup-mode" />
                <NumField f={sup} set={setSup} k="distance" label={`Distance (${u})`} errors={supErr} name="sup-distance" />
                <NumField f={sup} set={setSup} k="velocity_diff" label={`Velocity diff (${u}/s)`} errors={supErr} name="sup-velocity-diff" />
                <NumField f={sup} set={setSup} k="acceleration" label={`Acc (${u}/s²)`} errors={supErr} hint="0 = default" name="sup-acceleration" />
                <NumField f={sup} set={setSup} k="deceleration" label={`Dec (${u}/s²)`} errors={supErr} hint="0 = default" name="sup-deceleration" />
                <NumField f={sup} set={setSup} k="velocity_process" label={`Velocity process (${u}/s)`} errors={supErr} name="sup-velocity-process" />
                <NumField f={sup} set={setSup} k="length" label={`Length (${u})`} errors={supErr} name="sup-length" />
                <SelectField f={sup} set={setSup} k="abort_option" label="Abort option" errors={supErr} options={ABORT_OPTIONS} name="sup-abort-option" />
                <div class="row-buttons">
                  <button type="submit" class="btn btn-primary" name="move-superimposed" disabled={offline} title="MC_MoveSuperImposed">
                    Start
                  </button>
                  <ActionButton name="abort-superposition" disabled={offline} title="MC_AbortSuperposition" onClick={() => send('abort-superposition', { body: {}, errors: {} }, setSupErr)}>
                    Abort
                  </ActionButton>
                </div>
              </form>
            </Panel>
          </div>

          <div class="coupling-col">
            <Panel title="Gear" class="gear">
              <h4 class="sub">MC_GearIn · MC_GearOut</h4>
              <form
                class="row"
                data-form="gear-in"
                onSubmit={(e) => {
                  e.preventDefault();
                  if (online) void send('gear-in', gearInBody(gear), setGearErr);
                }}
              >
                <SelectField f={gear} set={setGear} k="master" label="Master" errors={gearErr} options={masters.map((m) => [m, m])} name="gear-master" blank={masters.length ? undefined : '(no other axis)'} />
                <NumField f={gear} set={setGear} k="ratio_numerator" label="Numerator" errors={gearErr} name="ratio-numerator" />
                <NumField f={gear} set={setGear} k="ratio_denominator" label="Denominator" errors={gearErr} name="ratio-denominator" />
                <div class="row-buttons">
                  <button type="submit" class="btn btn-primary" name="gear-in" disabled={offline} title="MC_GearIn: slave = master × numerator / denominator (the slave's dynamics, #1004–#1006, for the coupling)">
                    GearIn
                  </button>
                  <ActionButton name="gear-out" disabled={offline} title="MC_GearOut: decouple; the slave goes on at its velocity" onClick={() => send('gear-out', { body: {}, errors: {} }, setOutErr)}>
                    GearOut
                  </ActionButton>
                </div>
              </form>
              {outErr.body && <div class="field-error">{outErr.body}</div>}
              <h4 class="sub">MC_GearInDyn</h4>
              <form
                class="row"
                data-form="gear-in-dyn"
                onSubmit={(e) => {
                  e.preventDefault();
                  if (online) void send('gear-in-dyn', gearInDynBody(dyn), setDynErr);
                }}
              >
                <SelectField f={dyn} set={setDyn} k="master" label="Master (dyn)" errors={dynErr} options={masters.map((m) => [m, m])} name="dyn-master" blank={masters.length ? undefined : '(no other axis)'} />
                <NumField f={dyn} set={setDyn} k="gear_ratio" label="Gear ratio" errors={dynErr} name="dyn-gear-ratio" />
                <NumField f={dyn} set={setDyn} k="acceleration" label={`Acc (${u}/s²)`} errors={dynErr} hint={accZero} name="dyn-acceleration" />
                <div class="row-buttons">
                  <button type="submit" class="btn btn-primary" name="gear-in-dyn" disabled={offline} title="MC_GearInDyn: a ratio that may change while coupled (again with the same master)">
                    GearInDyn
                  </button>
                  {dynCmd && (
                    <ActionButton
                      name="release-gear-in-dyn"
                      kind="warn"
                      disabled={offline}
                      title={`Release MC_GearInDyn #${dynCmd.id} (Enable FALSE: the ratio freezes, the slave stays coupled)`}
                      onClick={async () => {
                        try {
                          setBanner(null);
                          await releaseCommand(dynCmd.id!, axis);
                        } catch (e) {
                          setBanner(errorText(e));
                        }
                      }}
                    >
                      Release #{dynCmd.id}
                    </ActionButton>
                  )}
                </div>
              </form>
            </Panel>

            <MultiMasterPanel axis={a} s={s} online={online} send={send} setBanner={setBanner} masters={masters} params={params} driveExecuted={de} />

            <Panel title="Cam" class="cam">
              <h4 class="sub">MC_CamIn · MC_CamOut</h4>
              <form
                class="row"
                data-form="cam-in"
                onSubmit={(e) => {
                  e.preventDefault();
                  if (online) void send('cam-in', camInBody(cam), setCamErr);
                }}
              >
                <SelectField f={cam} set={setCam} k="master" label="Master" errors={camErr} options={masters.map((m) => [m, m])} name="cam-master" blank={masters.length ? undefined : '(no other axis)'} />
                <SelectField
                  f={cam}
                  set={setCam}
                  k="cam_table"
                  label={<a href={href({ page: 'cams' })}>Cam table</a>}
                  errors={camErr}
                  options={tables.map((t) => [t.name, `${t.id} · ${t.name}`])}
                  name="cam-table"
                  blank={tables.length ? undefined : '(no cam table)'}
                />
                <SelectField f={cam} set={setCam} k="start_mode" label="Start mode" errors={camErr} options={START_MODES} name="cam-start-mode" />
                <ScalingFields f={cam} set={setCam} errors={camErr} prefix="cam" />
                <SelectField f={cam} set={setCam} k="interpolation" label="Interpolation" errors={camErr} options={['linear', 'spline', 'sliding_spline']} name="cam-interpolation" blank="table's own" />
                {cam.start_mode?.startsWith('ramp_in') && (
                  <>
                    <NumField f={cam} set={setCam} k="ramp_velocity" label={`Ramp-in velocity (${u}/s)`} errors={{ ramp_velocity: camErr['ramp_in.velocity'] ?? camErr['ramp_in'] }} name="cam-ramp-velocity" />
                    <NumField f={cam} set={setCam} k="ramp_acceleration" label={`Ramp-in acc (${u}/s²)`} errors={{ ramp_acceleration: camErr['ramp_in.acceleration'] }} hint={accZero} name="cam-ramp-acceleration" />
                  </>
                )}
                <div class="row-buttons">
                  <button type="submit" class="btn btn-primary" name="cam-in" disabled={offline} title="MC_CamIn">
                    CamIn
                  </button>
                  <ActionButton name="cam-out" disabled={offline} title="MC_CamOut: decouple; the slave goes on at its velocity" onClick={() => send('cam-out', { body: {}, errors: {} }, setCamErr)}>
                    CamOut
                  </ActionButton>
                </div>
              </form>
              <h4 class="sub">MC_CamScaling</h4>
              <form
                class="row cam-scaling"
                data-form="cam-scaling"
                onSubmit={(e) => {
                  e.preventDefault();
                  if (online) void send('cam-scaling', camScalingBody(scal), setScalErr);
                }}
              >
                <ScalingFields f={scal} set={setScal} errors={scalErr} prefix="scaling" />
                <div class="row-buttons">
                  <button type="submit" class="btn" name="cam-scaling" disabled={offline} title="MC_CamScaling: new offsets and scalings of the running cam coupling">
                    CamScaling
                  </button>
                </div>
              </form>
            </Panel>
          </div>
        </div>
      </fieldset>
    </div>
  );
}

/** Offsets, scalings, their modes and the activation of MC_CamIn / MC_CamScaling. */
function ScalingFields({ f, set, errors, prefix }: { f: Form; set: (k: string, v: string) => void; errors: Record<string, string>; prefix: string }) {
  return (
    <>
      <NumField f={f} set={set} k="master_offset" label="Master offset" errors={errors} name={`${prefix}-master-offset`} />
      <NumField f={f} set={set} k="slave_offset" label="Slave offset" errors={errors} name={`${prefix}-slave-offset`} />
      <NumField f={f} set={set} k="master_scaling" label="Master scaling" errors={errors} name={`${prefix}-master-scaling`} />
      <NumField f={f} set={set} k="slave_scaling" label="Slave scaling" errors={errors} name={`${prefix}-slave-scaling`} />
      <SelectField f={f} set={set} k="master_scaling_mode" label="Master scaling mode" errors={errors} options={SCALING_MODES} name={`${prefix}-master-scaling-mode`} />
      <SelectField f={f} set={set} k="slave_scaling_mode" label="Slave scaling mode" errors={errors} options={SCALING_MODES} name={`${prefix}-slave-scaling-mode`} />
      <SelectField f={f} set={set} k="activation_mode" label="Activation" errors={errors} options={ACTIVATION_MODES} name={`${prefix}-activation-mode`} />
      {takesPosition(f.activation_mode ?? '') && <NumField f={f} set={set} k="activation_position" label="Activation position" errors={errors} name={`${prefix}-activation-position`} />}
    </>
  );
}
