// The Coupling tab's blocks beyond gear and cam (docs/single-axis-blocks.md): MC_PhasingAbsolute /
// MC_PhasingRelative / MC_HaltPhasing on a coupled slave with the phase shift live, and
// MC_GearInMultiMaster (Enable-type: coupled, its ratios changed by sending it again with the
// same masters, released with DELETE /commands/{id}) with the ratios in force.
import { useEffect, useRef, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { commandLog } from '../../services';
import type { ParameterResource } from '../../api/types';
import { P_ACC, P_DEC, P_JERK, paramDefault } from './axis-params';
import { ActionButton, Led, Panel } from '../shared/common';
import { inputNum, num, pos } from '../../format';
import {
  MULTI_MASTER_DEFAULTS,
  MULTI_MASTER_ROWS,
  PHASING_DEFAULTS,
  SYNC_MODES,
  gearInMultiMasterBody,
  haltPhasingBody,
  multiMasterFields,
  multiMasterForm,
  phasingBody,
  type Form,
} from '../../axis/bodies';
import { useCommand, useForm } from '../../axis/hooks';
import { NumField, Readout, SelectField, release, type BlockProps } from './block-form';
import { couplerOf, couplingInForce } from '../../axis/coupling-kind';

/** The acceleration, deceleration and jerk a blank field of a block stands for (#1004–#1006). */
export function dynamicsDefaults(params: Map<number, ParameterResource> | null) {
  return { acceleration: paramDefault(params, P_ACC), deceleration: paramDefault(params, P_DEC), jerk: paramDefault(params, P_JERK) };
}

/** MC_PhasingAbsolute / MC_PhasingRelative / MC_HaltPhasing of this slave against its master. */
export function PhasingPanel({ axis: a, s, online, send, masters, params }: BlockProps & { masters: string[] }) {
  const u = a.config.unit;
  const dyn = dynamicsDefaults(params);
  const offline = !online;
  const fast = a.config.dynamics?.jog_velocity_fast;
  const [f, set] = useForm({ ...PHASING_DEFAULTS, velocity: fast ? inputNum(fast) : '' });
  const [err, setErr] = useState<Record<string, string>>({});
  // The master: the one the axis is coupled to now, else the first other axis.
  useEffect(() => {
    const m = s?.master || (f.master && masters.includes(f.master) ? f.master : (masters[0] ?? ''));
    if (m !== f.master) set('master', m);
  }, [s?.master, masters.join('\n')]);
  const options = masters.map((m): [string, string] => [m, m]);
  if (f.master && !masters.includes(f.master)) options.unshift([f.master, f.master]);

  return (
    <Panel title="Phasing" class="phasing">
      <Readout label="Absolute phase shift" value={pos(s?.absolute_phase_shift)} unit={u} name="absolute_phase_shift" title="AbsPhasingPos: the shift of this slave against its master" />
      <Readout label="Covered phase shift" value={pos(s?.covered_phase_shift)} unit={u} name="covered_phase_shift" title="What the running phasing command has covered so far" />
      <div class="led-grid phasing-leds">
        <Led on={s?.phasing_active} label="Phasing" tone="blue" title="A phasing command runs (StateDWord bit 15)" />
        <Led on={s?.coupled} label="Coupled" tone="blue" />
      </div>
      <h4 class="sub">MC_PhasingAbsolute · MC_PhasingRelative · MC_HaltPhasing</h4>
      <form
        class="row"
        data-form="phasing"
        onSubmit={(e) => {
          e.preventDefault();
          if (online) void send('phasing-absolute', phasingBody(f), setErr);
        }}
      >
        <SelectField f={f} set={set} k="master" label="Master" errors={err} options={options} name="phasing-master" blank={options.length ? undefined : '(no other axis)'} />
        <NumField f={f} set={set} k="phase_shift" label={`Phase shift (${u})`} errors={err} name="phasing-shift" hint="absolute: the shift to establish; relative: its change" />
        <NumField f={f} set={set} k="velocity" label={`Velocity (${u}/s)`} errors={err} name="phasing-velocity" hint="≥ 0.01" />
        <NumField f={f} set={set} k="acceleration" label={`Acc (${u}/s²)`} errors={err} name="phasing-acceleration" placeholder={dyn.acceleration.placeholder} hint={dyn.acceleration.title} />
        <NumField f={f} set={set} k="deceleration" label={`Dec (${u}/s²)`} errors={err} name="phasing-deceleration" placeholder={dyn.deceleration.placeholder} hint={`${dyn.deceleration.title} (also for Halt phasing)`} />
        <NumField f={f} set={set} k="jerk" label={`Jerk (${u}/s³)`} errors={err} name="phasing-jerk" placeholder={dyn.jerk.placeholder} hint={`${dyn.jerk.title} (also for Halt phasing)`} />
        <div class="row-buttons">
          <button type="submit" class="btn btn-primary" name="phasing-absolute" disabled={offline} title="MC_PhasingAbsolute: establish this phase shift against the master">
            Phasing absolute
          </button>
          <ActionButton name="phasing-relative" disabled={offline} title="MC_PhasingRelative: change the phase shift by this much" onClick={() => send('phasing-relative', phasingBody(f), setErr)}>
            Phasing relative
          </ActionButton>
          <ActionButton name="halt-phasing" kind="warn" disabled={offline} title="MC_HaltPhasing: bring the phase motion to rest (deceleration, jerk); the shift stays where it stops" onClick={() => send('halt-phasing', haltPhasingBody(f), setErr)}>
            Halt phasing
          </ActionButton>
        </div>
      </form>
      <p class="small muted panel-note">
        For a slave coupled to this master by GearIn, a cam, or GearInMultiMaster with advanced slave dynamics in possync1/2 (not GearInDyn). The shift stays when the phasing ends; a new coupling starts at 0.
      </p>
    </Panel>
  );
}

/** MC_GearInMultiMaster: up to four masters and their ratios. */
export function MultiMasterPanel({ axis: a, s, online, send, setBanner, masters, params }: BlockProps & { masters: string[] }) {
  const axis = a.config.name;
  const dyn = dynamicsDefaults(params);
  const u = a.config.unit;
  const offline = !online;
  const log = useStore(commandLog);
  const [f, set, setAll] = useForm(MULTI_MASTER_DEFAULTS);
  const [err, setErr] = useState<Record<string, string>>({});
  // The command: the one this page sent (its id kept), or a newer one of this axis in the log.
  const [sentId, setSentId] = useState<number | null>(null);
  const latest = log.find((e) => e.axis === axis && e.command === 'gear-in-multi-master' && e.id !== null);
  const id = Math.max(sentId ?? 0, latest?.id ?? 0) || null;
  const entry = id ? (log.find((e) => e.id === id) ?? null) : null;
  const cmd = useCommand(id, `${s?.coupled}`);
  const running = entry ? !entry.final : !!cmd && !cmd.final;
  // A running command this page did not send: its masters (and ratios) fill the form.
  const synced = useRef<number | null>(null);
  useEffect(() => {
    if (!cmd || cmd.final || synced.current === cmd.id) return;
    synced.current = cmd.id;
    setAll({ ...f, ...multiMasterForm(cmd.parameters) });
  }, [cmd?.id, cmd?.final]);

  const couple = async () => {
    const r = await send('gear-in-multi-master', gearInMultiMasterBody(f), (e) => setErr(multiMasterFields(f, e)));
    if (r) {
      synced.current = r.id;
      setSentId(r.id);
    }
  };
  const adv = f.advanced_slave_dynamics === '1';
  const inGear = !!(s?.coupled && cmd?.outputs.in_gear);
  // The coupling in force: its masters and ratios only for a multi-master coupling (a cam or a
  // single gear has no Master2…4, and a cam slave's ratios are 0), else what it is.
  const coupler = couplerOf(log, axis);
  const inForce = couplingInForce(s, coupler);
  const names: Form = inForce.kind === 'multi-master' && coupler && coupler.id === cmd?.id ? multiMasterForm(cmd.parameters) : { master1: inForce.master ?? '' };
  const ratios = s?.gear_ratios ?? [];

  return (
    <Panel title="Multi-master gear" class="multi-master">
      <h4 class="sub">MC_GearInMultiMaster</h4>
      <form
        data-form="gear-in-multi-master"
        onSubmit={(e) => {
          e.preventDefault();
          if (online) void couple();
        }}
      >
        <div class="mm-rows">
          {MULTI_MASTER_ROWS.map((i) => (
            <div class="mm-pair" data-master-row={i}>
              <SelectField
                f={f}
                set={set}
                k={`master${i}`}
                label={`Master ${i}`}
                errors={err}
                options={masters.map((m) => [m, m])}
                name={`mm-master${i}`}
                blank="—"
                disabled={running}
                title={running ? 'The masters of a running coupling stay: Release it to couple others' : 'blank = unused'}
              />
              <NumField f={f} set={set} k={`ratio${i}`} label={`Ratio ${i}`} errors={err} name={`mm-ratio${i}`} />
            </div>
          ))}
        </div>
        <div class="row mm-options">
          <NumField f={f} set={set} k="acceleration" label={`Acc (${u}/s²)`} errors={err} name="mm-acceleration" placeholder={dyn.acceleration.placeholder} hint={dyn.acceleration.title} />
          <NumField f={f} set={set} k="deceleration" label={`Dec (${u}/s²)`} errors={err} name="mm-deceleration" placeholder={dyn.deceleration.placeholder} disabled={!adv} hint={`with advanced slave dynamics; ${dyn.deceleration.title}`} />
          <NumField f={f} set={set} k="jerk" label={`Jerk (${u}/s³)`} errors={err} name="mm-jerk" placeholder={dyn.jerk.placeholder} disabled={!adv} hint={`with advanced slave dynamics; ${dyn.jerk.title}`} />
          <SelectField f={f} set={set} k="sync_mode" label="Sync mode" errors={err} options={SYNC_MODES} name="mm-sync-mode" disabled={!adv} title="What a slave with advanced dynamics makes up: the velocity, or the position too" />
          <label class="check" title="The slave synchronises within acceleration, deceleration and jerk (also with the masters moving); without, masters and slave must stand">
            <input type="checkbox" name="mm-advanced" checked={adv} onChange={(e) => set('advanced_slave_dynamics', (e.target as HTMLInputElement).checked ? '1' : '')} /> advanced slave dynamics
          </label>
          <div class="row-buttons">
            <button type="submit" class="btn btn-primary" name="mm-couple" disabled={offline || running} title="MC_GearInMultiMaster: slave = Σ ratio × master's travel">
              Couple
            </button>
            <ActionButton name="mm-change" disabled={offline || !running} title="Send the new ratios to the running coupling (the same masters)" onClick={couple}>
              Change ratios
            </ActionButton>
            <ActionButton name="mm-release" kind="warn" disabled={offline || !running || !id} title={`Release${id ? ` #${id}` : ''} (Enable FALSE: the ratios freeze, the slave stays coupled)`} onClick={() => (id ? release(id, axis, setBanner) : undefined)}>
              Release{running && id ? ` #${id}` : ''}
            </ActionButton>
          </div>
        </div>
      </form>
      {err.body && <div class="field-error">{err.body}</div>}
      <div class="mm-state">
        <div class="led-grid">
          <Led on={inGear} label="InGear" title="InGear of the multi-master command" />
          <Led on={running} label="Enabled" tone="blue" title="The command is enabled (ratios may be changed)" />
        </div>
        <span class="small" data-testid="mm-command">
          {cmd ? (
            <>
              #{cmd.id} · {cmd.state}
            </>
          ) : (
            <span class="muted">no command</span>
          )}
        </span>
      </div>
      {inForce.kind !== 'multi-master' ? (
        <p class="small muted mm-none" data-testid="mm-in-force" data-kind={inForce.kind}>
          {inForce.kind === 'none' ? (
            'Not coupled.'
          ) : (
            <>
              Coupled to {inForce.master ?? 'its master'} by {inForce.text}: not a multi-master gear.
            </>
          )}
        </p>
      ) : (
        <table class="grid mm-ratios" data-testid="gear-ratios">
          <thead>
            <tr>
              <th />
              <th>Axis</th>
              <th class="r">Ratio in force</th>
            </tr>
          </thead>
          <tbody>
            {MULTI_MASTER_ROWS.map((i) => (
              <tr data-gear-ratio={i}>
                <th>Master{i}</th>
                <td>{names[`master${i}`] || <span class="muted">—</span>}</td>
                <td class="mono r">{num(ratios[i - 1], 4)}</td>
              </tr>
            ))}
          </tbody>
        </table>
      )}
    </Panel>
  );
}
