// Create / edit / delete an axis. The form mirrors AxisConfigDto; the server's 422 field
// errors (JSON paths such as `dynamics.jerk`, `drive.plant.damping`, `drive.subdevice`,
// `parameters.X`) are shown at the field they name, anything else in the banner.
//
// The drive is a simulated one (plant model, homing cam, switches) or a CiA-402 servo drive on
// the EtherCAT bus (its SubDevice chosen from `GET /bus`); on the simulated bus CiA-402 is
// offered disabled, with how to start motiond for it. A CiA-402 drive has its profile side
// (`host`: motiond's setpoints every cycle; `drive`: the drive runs the profile, Drive Motion
// Control) and the homing method written to it before it homes (0x6098, blank: its own).
//
// Saving an existing axis first asks the server what the save would do (`?dry_run=true`) and
// shows it (save-panel.tsx beside this file): parameters written online on the running axis, or the axis
// re-created (then it must be disabled). The fields that are parameters show beside them the
// online and persistent values where these differ from the configured (start-up) value.
import { useEffect, useState } from 'preact/hooks';
import type { JSX } from 'preact';
import type { AxisConfig, AxisLiveStatus, AxisResource, BusResource, Cia402Mode, ParamValue, ProfileSide, SimDriveConfig } from '../../api/types';
import { ApiError, NOT_A_NUMBER } from '../../api/problem';
import { api } from '../../api/client';
import { command, refreshAxes, statuses } from '../../services';
import { navigate } from '../../router';
import { useStore } from '../../store';
import { ActionButton, ErrorBanner, Field, NumberInput, Panel, errorText, fieldsOf, useOnline } from '../shared/common';
import { STATE_LABEL, inputNum } from '../../format';
import { useAxisParameters } from '../../config/params';
import { type ConfigChange, type SideValues, differingFields, rebuildBlockedText, sideText } from '../../config/change';
import { SavePanel, SaveResult } from './save-panel';
import { cia402Unavailable, driveOptions, firstFreeDrive } from '../../system/bus';
import { useBus } from '../system/bus';
import { HOMING_METHODS, OTHER_HOMING_METHODS } from '../../axis/drive-executed';

export const UNITS = ['mm', 'm', 'um', 'deg', 'rad', 'rev', 'in', 'inc'];

type PlantKind = 'ideal' | 'pt1' | 'pt2';
export type DriveKind = 'simulated' | 'cia402';

const DRIVE_KINDS: [DriveKind, string][] = [
  ['simulated', 'Simulated'],
  ['cia402', 'CiA-402 on EtherCAT'],
];

const CIA_MODES: [Cia402Mode, string, string][] = [
  ['csp', 'CSP (position)', 'cyclic synchronous position: the drive closes the position loop'],
  ['csv', 'CSV (velocity)', 'cyclic synchronous velocity: motiond closes the position loop'],
  ['cst', 'CST (torque)', 'cyclic synchronous torque: motiond closes the position and velocity loops'],
];

/** Who runs the profile: value, label, what it means. */
const PROFILES: [ProfileSide, string, string][] = [
  ['host', 'motiond (host)', 'motiond plans the motion and sends a setpoint every cycle in the mode below: every block'],
  ['drive', 'the drive (Drive Motion Control)', 'the drive runs profile position, velocity and homing from the targets motiond sends: power, reset, set position, home, jog, halt, stop, the moves and the touch probe only (no coupling, cams, superposition, torque control, jerk or override)'],
];

const PLANTS: [PlantKind, string][] = [
  ['ideal', 'ideal (load = reference)'],
  ['pt1', 'PT1 (first-order lag)'],
  ['pt2', 'PT2 (tuned position loop)'],
];

/**
 * Why the axis cannot be re-created or deleted now, as its live status shows it (the server
 * swaps only a disabled axis: state Disabled and power off), or null. Unknown status: null —
 * the server judges, and its refusal is shown. A save that does not re-create the axis is
 * never blocked by this (it writes the parameters online).
 */
export function reconfigureBlocked(s: Pick<AxisLiveStatus, 'state' | 'power_status'> | null | undefined): string | null {
  if (!s) return null;
  if (s.power_status) return 'The axis is enabled: switch it off to re-create or delete it.';
  if (s.state !== 'disabled') return `The axis is in ${STATE_LABEL[s.state]}: it must be Disabled to be re-created or deleted (reset it).`;
  return null;
}

export interface ConfigForm {
  name: string;
  unit: string;
  modulo: boolean;
  period: string;
  softLimits: boolean;
  min: string;
  max: string;
  dyn: Record<'max_velocity' | 'acceleration' | 'deceleration' | 'jerk' | 'jog_velocity_slow' | 'jog_velocity_fast', string>;
  /** `drive.kind`; the other kind's fields are kept while the kind is switched. */
  driveKind: DriveKind;
  plant: PlantKind;
  time_constant: string;
  natural_frequency_hz: string;
  damping: string;
  drive: Record<'dead_time' | 'velocity_feed_forward' | 'acceleration_feed_forward' | 'enable_delay' | 'coast_deceleration' | 'load_stiffness' | 'velocity_mode_position_gain', string>;
  /** `drive.torque`: the load in torque mode (MC_TorqueControl). */
  torque: Record<TorqueField, string>;
  dead_time_compensation: boolean;
  refCam: boolean;
  camStart: string;
  camEnd: string;
  index: boolean;
  indexPeriod: string;
  indexOffset: string;
  limitNeg: string;
  limitPos: string;
  faultOnHit: boolean;
  /**
   * The CiA-402 drive: `drive.subdevice` etc.; `velocity_increments_per_unit` blank: null (the
   * position increments). Every field is sent whatever the mode (the hidden ones as read), so
   * a save keeps the gains of the other modes.
   */
  cia: Record<CiaField, string>;
  ciaMode: Cia402Mode;
  /** `drive.profile`: who runs the motion profile. */
  ciaProfile: ProfileSide;
  /** `drive.homing_method` (0x6098, 1..37); blank: null, the drive's own. */
  homingMethod: string;
  parameters: { key: string; value: string }[];
  /** `dynamics.jog_deadman_max` (s); blank: not sent, the server's default (1 s). */
  jogDeadmanMax: string;
}

type TorqueField = 'acceleration_per_percent' | 'friction' | 'viscous';

type CiaField = 'subdevice' | 'increments_per_unit' | 'velocity_increments_per_unit' | 'position_gain' | 'velocity_gain' | 'acceleration_feed_forward' | 'max_torque';

export const DEFAULT_FORM: ConfigForm = {
  name: '',
  unit: 'mm',
  modulo: false,
  period: '360',
  softLimits: false,
  min: '0',
  max: '1000',
  dyn: { max_velocity: '500', acceleration: '2500', deceleration: '2500', jerk: '25000', jog_velocity_slow: '10', jog_velocity_fast: '100' },
  jogDeadmanMax: '1',
  driveKind: 'simulated',
  plant: 'pt2',
  time_constant: '0.005',
  natural_frequency_hz: '50',
  damping: '0.8',
  drive: { dead_time: '0.001', velocity_feed_forward: '1', acceleration_feed_forward: '0', enable_delay: '0.005', coast_deceleration: '10000', load_stiffness: '1000', velocity_mode_position_gain: '100' },
  torque: { acceleration_per_percent: '100', friction: '1', viscous: '0' },
  dead_time_compensation: true,
  refCam: true,
  camStart: '20',
  camEnd: '25',
  index: true,
  indexPeriod: '10',
  indexOffset: '0',
  limitNeg: '',
  limitPos: '',
  faultOnHit: false,
  // the server's defaults (a CST drive needs a velocity gain > 0: the server says so at the field)
  cia: { subdevice: '', increments_per_unit: '1000', velocity_increments_per_unit: '', position_gain: '50', velocity_gain: '0', acceleration_feed_forward: '0', max_torque: '1000' },
  ciaMode: 'csp',
  ciaProfile: 'host',
  homingMethod: '',
  parameters: [],
};

export function formOf(c: AxisConfig): ConfigForm {
  const cia = c.drive?.kind === 'cia402' ? c.drive : null;
  const d: Partial<SimDriveConfig> = c.drive && c.drive.kind !== 'cia402' ? c.drive : {};
  const plant = (d.plant ?? { kind: 'pt2', natural_frequency_hz: 50, damping: 0.8 }) as { kind: PlantKind; time_constant?: number; natural_frequency_hz?: number; damping?: number };
  const n = (v: number | null | undefined, dflt = '') => (v === null || v === undefined ? dflt : inputNum(v));
  return {
    name: c.name,
    unit: c.unit,
    modulo: !!c.modulo,
    period: n(c.modulo?.period, '360'),
    softLimits: !!c.soft_limits,
    min: n(c.soft_limits?.min, '0'),
    max: n(c.soft_limits?.max, '1000'),
    dyn: {
      max_velocity: n(c.dynamics.max_velocity),
      acceleration: n(c.dynamics.acceleration),
      deceleration: n(c.dynamics.deceleration),
      jerk: n(c.dynamics.jerk),
      jog_velocity_slow: n(c.dynamics.jog_velocity_slow),
      jog_velocity_fast: n(c.dynamics.jog_velocity_fast),
    },
    jogDeadmanMax: n((c.dynamics as Partial<AxisConfig['dynamics']>).jog_deadman_max),
    plant: plant.kind,
    time_constant: n(plant.time_constant, '0.005'),
    natural_frequency_hz: n(plant.natural_frequency_hz, '50'),
    damping: n(plant.damping, '0.8'),
    drive: {
      dead_time: n(d.dead_time, '0.001'),
      velocity_feed_forward: n(d.velocity_feed_forward, '1'),
      acceleration_feed_forward: n(d.acceleration_feed_forward, '0'),
      enable_delay: n(d.enable_delay, '0.005'),
      coast_deceleration: n(d.coast_deceleration, '10000'),
      load_stiffness: n(d.load_stiffness, '1000'),
      velocity_mode_position_gain: n(d.velocity_mode_position_gain, '100'),
    },
    torque: {
      acceleration_per_percent: n(d.torque?.acceleration_per_percent, '100'),
      friction: n(d.torque?.friction, '1'),
      viscous: n(d.torque?.viscous, '0'),
    },
    dead_time_compensation: d.dead_time_compensation ?? true,
    refCam: !!d.reference_cam,
    camStart: n(d.reference_cam?.start, '20'),
    camEnd: n(d.reference_cam?.end, '25'),
    index: !!d.index_pulse,
    indexPeriod: n(d.index_pulse?.period, '10'),
    indexOffset: n(d.index_pulse?.offset, '0'),
    limitNeg: n(d.limit_switches?.negative),
    limitPos: n(d.limit_switches?.positive),
    faultOnHit: d.limit_switches?.fault_on_hit ?? false,
    driveKind: cia ? 'cia402' : 'simulated',
    cia: cia
      ? {
          subdevice: String(cia.subdevice),
          increments_per_unit: n(cia.increments_per_unit),
          velocity_increments_per_unit: n(cia.velocity_increments_per_unit),
          position_gain: n(cia.position_gain, DEFAULT_FORM.cia.position_gain),
          velocity_gain: n(cia.velocity_gain, DEFAULT_FORM.cia.velocity_gain),
          acceleration_feed_forward: n(cia.acceleration_feed_forward, DEFAULT_FORM.cia.acceleration_feed_forward),
          max_torque: n(cia.max_torque, DEFAULT_FORM.cia.max_torque),
        }
      : { ...DEFAULT_FORM.cia },
    ciaMode: cia?.mode ?? 'csp',
    ciaProfile: cia?.profile ?? 'host',
    homingMethod: typeof cia?.homing_method === 'number' ? String(cia.homing_method) : '',
    parameters: Object.entries(c.parameters ?? {}).map(([key, value]) => ({ key, value: String(value) })),
  };
}

/** The request body, or the fields whose text is not a number (checked here: the server only sees JSON). */
export function configOf(f: ConfigForm): { config: AxisConfig | null; errors: Record<string, string> } {
  const errors: Record<string, string> = {};
  const num = (path: string, s: string): number => {
    const t = s.trim().replace(',', '.');
    const v = t === '' ? NaN : Number(t);
    if (!Number.isFinite(v)) errors[path] = t === '' ? 'required' : NOT_A_NUMBER;
    return v;
  };
  const opt = (path: string, s: string): number | null => (s.trim() === '' ? null : num(path, s));
  const whole = (path: string, s: string): number => {
    const v = num(path, s);
    if (Number.isFinite(v) && !Number.isInteger(v)) errors[path] = 'a whole number';
    return v;
  };
  const plant = () =>
    f.plant === 'ideal'
      ? { kind: 'ideal' as const }
      : f.plant === 'pt1'
        ? { kind: 'pt1' as const, time_constant: num('drive.plant.time_constant', f.time_constant) }
        : { kind: 'pt2' as const, natural_frequency_hz: num('drive.plant.natural_frequency_hz', f.natural_frequency_hz), damping: num('drive.plant.damping', f.damping) };
  const parameters: Record<string, ParamValue> = {};
  for (const p of f.parameters) {
    if (!p.key.trim()) continue;
    const t = p.value.trim();
    parameters[p.key.trim()] = t === 'true' ? true : t === 'false' ? false : num(`parameters.${p.key.trim()}`, t);
  }
  const config: AxisConfig = {
    name: f.name.trim(),
    unit: f.unit,
    ...(f.modulo ? { modulo: { period: num('modulo.period', f.period) } } : {}),
    ...(f.softLimits ? { soft_limits: { min: num('soft_limits.min', f.min), max: num('soft_limits.max', f.max) } } : {}),
    dynamics: {
      max_velocity: num('dynamics.max_velocity', f.dyn.max_velocity),
      acceleration: num('dynamics.acceleration', f.dyn.acceleration),
      deceleration: num('dynamics.deceleration', f.dyn.deceleration),
      jerk: num('dynamics.jerk', f.dyn.jerk),
      jog_velocity_slow: num('dynamics.jog_velocity_slow', f.dyn.jog_velocity_slow),
      jog_velocity_fast: num('dynamics.jog_velocity_fast', f.dyn.jog_velocity_fast),
      ...(f.jogDeadmanMax.trim() !== '' ? { jog_deadman_max: num('dynamics.jog_deadman_max', f.jogDeadmanMax) } : {}),
    } as AxisConfig['dynamics'],
    // The schema says `object` without value types (utoipa value_type = Object).
    parameters: parameters as unknown as AxisConfig['parameters'],
    drive: f.driveKind === 'cia402' ? {
      kind: 'cia402',
      subdevice: whole('drive.subdevice', f.cia.subdevice),
      increments_per_unit: num('drive.increments_per_unit', f.cia.increments_per_unit),
      velocity_increments_per_unit: opt('drive.velocity_increments_per_unit', f.cia.velocity_increments_per_unit),
      mode: f.ciaMode,
      position_gain: num('drive.position_gain', f.cia.position_gain),
      velocity_gain: num('drive.velocity_gain', f.cia.velocity_gain),
      acceleration_feed_forward: num('drive.acceleration_feed_forward', f.cia.acceleration_feed_forward),
      max_torque: num('drive.max_torque', f.cia.max_torque),
      profile: f.ciaProfile,
      homing_method: f.homingMethod.trim() === '' ? null : whole('drive.homing_method', f.homingMethod),
    } : {
      kind: 'simulated',
      plant: plant(),
      dead_time: num('drive.dead_time', f.drive.dead_time),
      dead_time_compensation: f.dead_time_compensation,
      velocity_feed_forward: num('drive.velocity_feed_forward', f.drive.velocity_feed_forward),
      acceleration_feed_forward: num('drive.acceleration_feed_forward', f.drive.acceleration_feed_forward),
      enable_delay: num('drive.enable_delay', f.drive.enable_delay),
      coast_deceleration: num('drive.coast_deceleration', f.drive.coast_deceleration),
      load_stiffness: num('drive.load_stiffness', f.drive.load_stiffness),
      velocity_mode_position_gain: num('drive.velocity_mode_position_gain', f.drive.velocity_mode_position_gain),
      torque: {
        acceleration_per_percent: num('drive.torque.acceleration_per_percent', f.torque.acceleration_per_percent),
        friction: num('drive.torque.friction', f.torque.friction),
        viscous: num('drive.torque.viscous', f.torque.viscous),
      },
      reference_cam: f.refCam ? { start: num('drive.reference_cam.start', f.camStart), end: num('drive.reference_cam.end', f.camEnd) } : null,
      index_pulse: f.index ? { period: num('drive.index_pulse.period', f.indexPeriod), offset: num('drive.index_pulse.offset', f.indexOffset) } : null,
      limit_switches: { negative: opt('drive.limit_switches.negative', f.limitNeg), positive: opt('drive.limit_switches.positive', f.limitPos), fault_on_hit: f.faultOnHit },
    },
  };
  return { config: Object.keys(errors).length ? null : config, errors };
}

/** The field paths of the CiA-402 drive's inputs in a mode (position gain: CSV and CST; the torque loop's: CST). */
function ciaFields(mode: Cia402Mode): string[] {
  return [
    'drive.subdevice',
    'drive.increments_per_unit',
    'drive.velocity_increments_per_unit',
    'drive.mode',
    'drive.profile',
    'drive.homing_method',
    ...(mode !== 'csp' ? ['drive.position_gain'] : []),
    ...(mode === 'cst' ? ['drive.velocity_gain', 'drive.acceleration_feed_forward', 'drive.max_torque'] : []),
  ];
}

/** Every field path the form shows (errors for other paths go to the banner). */
export function shownFields(f: ConfigForm): Set<string> {
  const common = [
    'name',
    'unit',
    'modulo',
    'modulo.period',
    'soft_limits',
    'soft_limits.min',
    'soft_limits.max',
    ...Object.keys(f.dyn).map((k) => `dynamics.${k}`),
    'dynamics.jog_deadman_max',
    'drive.kind',
  ];
  if (f.driveKind === 'cia402') return new Set([...common, ...ciaFields(f.ciaMode), ...f.parameters.map((p) => `parameters.${p.key.trim()}`)]);
  const s = new Set([
    ...common,
    'drive.plant.time_constant',
    'drive.plant.natural_frequency_hz',
    'drive.plant.damping',
    ...Object.keys(f.drive).map((k) => `drive.${k}`),
    'drive.reference_cam.start',
    'drive.reference_cam.end',
    'drive.index_pulse.period',
    'drive.index_pulse.offset',
    'drive.limit_switches.negative',
    'drive.limit_switches.positive',
  ]);
  for (const p of f.parameters) s.add(`parameters.${p.key.trim()}`);
  return s;
}

const DYN_LABELS: [keyof ConfigForm['dyn'], string, string, string][] = [
  ['max_velocity', 'Max velocity', '/s', '#1003 AxisVeloMax'],
  ['acceleration', 'Acceleration', '/s²', '#1004 AxisAcc'],
  ['deceleration', 'Deceleration', '/s²', '#1005 AxisDec'],
  ['jerk', 'Jerk', '/s³', '#1006 AxisJerk'],
  ['jog_velocity_slow', 'Jog velocity slow', '/s', '#1001 AxisVeloManSlow (− / +)'],
  ['jog_velocity_fast', 'Jog velocity fast', '/s', '#1002 AxisVeloManFast (−− / ++)'],
];

const DRIVE_LABELS: [keyof ConfigForm['drive'], string, string][] = [
  ['dead_time', 'Dead time (s)', '0 … 0.1'],
  ['enable_delay', 'Enable delay (s)', '0 … 10'],
  ['velocity_feed_forward', 'Velocity feed-forward', '0 … 2 (1 = full)'],
  ['acceleration_feed_forward', 'Acceleration feed-forward', '0 … 2 (PT2 only)'],
  ['coast_deceleration', 'Coast deceleration (u/s²)', 'power stage off'],
  ['load_stiffness', 'Load stiffness', '> 0'],
  ['velocity_mode_position_gain', 'Velocity-mode position gain (1/s)', 'CSV: motiond closes the loop'],
];

const TORQUE_LABELS: [TorqueField, string, string][] = [
  ['acceleration_per_percent', 'Torque mode: acceleration per % (u/s²)', 'rated torque ÷ inertia'],
  ['friction', 'Torque mode: friction (%)', 'Coulomb, ≥ 0'],
  ['viscous', 'Torque mode: viscous friction (% per u/s)', '≥ 0'],
];

/** A dry run waiting for the user's word: its answer and the configuration it was asked for. */
interface Pending {
  change: ConfigChange;
  config: AxisConfig;
}

export function AxisConfigPage({ axis }: { axis: AxisResource | null }) {
  const creating = axis === null;
  const [form, setForm] = useState<ConfigForm>(() => (axis ? formOf(axis.config) : DEFAULT_FORM));
  const [fields, setFields] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const [notDisabled, setNotDisabled] = useState(false);
  const [message, setMessage] = useState<string | null>(null);
  const [result, setResult] = useState<ConfigChange | null>(null);
  const [pending, setPending] = useState<Pending | null>(null);
  const [checking, setChecking] = useState(false);
  const [saving, setSaving] = useState(false);
  const [paramsVersion, setParamsVersion] = useState(0);
  const [confirmDelete, setConfirmDelete] = useState(false);
  const st = useStore(statuses);
  const online = useOnline();
  const params = useAxisParameters(axis ? axis.config.name : null, axis?.id ?? 0, paramsVersion);
  // The bus, read once: whether CiA-402 drives exist, and which ones (and whose) to offer.
  const { bus } = useBus(null);
  useEffect(() => {
    setForm(axis ? formOf(axis.config) : DEFAULT_FORM);
    setFields({});
    setError(null);
    setPending(null);
    setResult(null);
  }, [axis?.id]);
  const live = axis ? st.get(axis.config.name) : undefined;
  const fresh = live && !live.stale ? live.status : null;
  // While the status is stale the buttons are off anyway (offline) or the server judges.
  const blocked = axis ? reconfigureBlocked(fresh) : null;
  const powered = !!(blocked && fresh?.power_status);
  const disableNow = async () => {
    if (!axis) return;
    try {
      await command(axis.config.name, 'power', { enable: false, enable_positive: false, enable_negative: false, override_percent: 100 });
      setNotDisabled(false);
    } catch (e) {
      setError(errorText(e));
    }
  };

  const set = <K extends keyof ConfigForm>(k: K, v: ConfigForm[K]) => setForm({ ...form, [k]: v });
  const err = (path: string) => fields[path];
  // Online and persistent values that differ from the configured ones, by field path.
  const sides: Record<string, SideValues> = creating ? {} : differingFields(params);
  const side = (path: string) =>
    sides[path] ? (
      <span class="cfg-side" data-side={path} title="the parameter's value in force (online) and its persistent value, where they differ from the configured start-up value">
        {sideText(sides[path])}
      </span>
    ) : null;
  const limitSide = () => {
    if (!form.softLimits || !(sides['soft_limits.min'] || sides['soft_limits.max'])) return null;
    const part = (k: 'min' | 'max') => (sides[`soft_limits.${k}`] ? `${k}: ${sideText(sides[`soft_limits.${k}`])}` : null);
    return (
      <span class="cfg-side" data-side="soft_limits">
        {[part('min'), part('max')].filter(Boolean).join('; ')}
      </span>
    );
  };

  const fail = (e: unknown) => {
    const f = { ...fieldsOf(e) };
    if (e instanceof ApiError && e.problem?.code === 'axis_name_taken') f.name = e.problem.detail;
    setFields(f);
    setNotDisabled(e instanceof ApiError && e.problem?.code === 'axis_not_disabled');
    const shown = shownFields(form);
    const other = Object.entries(f).filter(([k]) => !shown.has(k));
    if (Object.keys(f).length && other.length === 0) setError('The server refused the configuration: see the fields marked red.');
    else setError(errorText(e));
  };

  /** Save pressed: a new axis is created; an existing one's save is first asked as a dry run. */
  const save = async () => {
    setMessage(null);
    setResult(null);
    setError(null);
    setNotDisabled(false);
    const { config, errors } = configOf(form);
    setFields(errors);
    if (!config) {
      setError('Some fields are not numbers: see the fields marked red.');
      return;
    }
    if (creating) {
      try {
        const r = await api.POST('/api/v1/axes', { body: config });
        await refreshAxes();
        navigate({ page: 'axis', axis: r.config.name, tab: 'online' });
      } catch (e) {
        fail(e);
      }
      return;
    }
    setChecking(true);
    // the values beside the fields and those a rebuild would lose, read anew
    setParamsVersion((v) => v + 1);
    try {
      const r = await api.PUT('/api/v1/axes/{axis}', { params: { path: { axis: axis.config.name }, query: { dry_run: true } }, body: config });
      if (!r.change) throw new Error('The server did not say what the save would change.');
      setPending({ change: r.change, config });
    } catch (e) {
      fail(e);
    } finally {
      setChecking(false);
    }
  };

  /** The confirmed save: exactly the configuration the dry run was asked for. */
  const confirmSave = async () => {
    if (!axis || !pending) return;
    setSaving(true);
    try {
      const r = await api.PUT('/api/v1/axes/{axis}', { params: { path: { axis: axis.config.name } }, body: pending.config });
      setPending(null);
      setFields({});
      setForm(formOf(r.config));
      setResult(r.change ?? null);
      if (!r.change) setMessage('Saved.');
      setParamsVersion((v) => v + 1);
      await refreshAxes();
      if (r.config.name !== axis.config.name) navigate({ page: 'axis', axis: r.config.name, tab: 'config' });
    } catch (e) {
      setPending(null);
      fail(e);
    } finally {
      setSaving(false);
    }
  };

  const remove = async () => {
    if (!axis) return;
    setError(null);
    try {
      await api.DELETE('/api/v1/axes/{axis}', { params: { path: { axis: axis.config.name } } });
      await refreshAxes();
      navigate({ page: 'overview' });
    } catch (e) {
      setConfirmDelete(false);
      fail(e);
    }
  };

  const num = (path: string, value: string, on: (v: string) => void, label: string, hint?: string) => (
    <Field label={label} error={err(path)} hint={hint} name={path}>
      <NumberInput name={path} value={value} onValue={on} />
      {side(path)}
    </Field>
  );

  return (
    <div class={creating ? 'page page-config' : 'config'}>
      {creating && (
        <div class="page-head">
          <h2>New axis</h2>
          <span class="muted">a simulated drive or a CiA-402 drive on EtherCAT; every field can be changed later</span>
        </div>
      )}
      <ErrorBanner error={error} onClose={() => setError(null)} />
      {notDisabled && axis && (
        <div class="banner banner-warn" data-testid="not-disabled">
          The server refused: the axis must be disabled first.
          {!powered && (
            <ActionButton kind="warn" name="disable-axis" disabled={!online} onClick={disableNow}>
              Disable {axis.config.name} now
            </ActionButton>
          )}
        </div>
      )}
      {message && <div class="banner banner-ok">{message}</div>}
      {result && <SaveResult change={result} onClose={() => setResult(null)} />}
      {pending && axis && (
        <SavePanel
          change={pending.change}
          axis={axis.config.name}
          newName={pending.config.name}
          unit={axis.config.unit}
          position={fresh ? fresh.actual_position : null}
          blocked={rebuildBlockedText(fresh, (s) => STATE_LABEL[s as AxisLiveStatus['state']] ?? s)}
          params={params ? [...params.values()] : null}
          powered={powered}
          online={online}
          saving={saving}
          onSave={() => void confirmSave()}
          onCancel={() => setPending(null)}
          onDisable={disableNow}
        />
      )}
      <form
        class="config-form"
        onSubmit={(e) => {
          e.preventDefault();
          if (online && !checking && !pending) void save();
        }}
      >
        <div class="config-grid">
          <Panel title="Axis">
            <div class="form-grid">
              <Field label="Name" error={err('name')} name="name" hint="letter or _, then letters, digits, _ or -">
                <input type="text" name="name" value={form.name} autocomplete="off" onInput={(e) => set('name', (e.target as HTMLInputElement).value)} />
              </Field>
              <Field label="Unit" error={err('unit')} name="unit">
                <select name="unit" value={form.unit} onChange={(e) => set('unit', (e.target as HTMLSelectElement).value)}>
                  {UNITS.map((u) => (
                    <option value={u}>{u}</option>
                  ))}
                </select>
              </Field>
              <Field label="Modulo (rotary)" error={err('modulo')} name="modulo">
                <span class="inline">
                  <input type="checkbox" name="modulo-on" checked={form.modulo} onChange={(e) => set('modulo', (e.target as HTMLInputElement).checked)} />
                  <NumberInput name="modulo.period" value={form.period} onValue={(v) => set('period', v)} disabled={!form.modulo} placeholder="period" />
                </span>
              </Field>
              {err('modulo.period') && <div class="field-error">{err('modulo.period')}</div>}
              <Field label="Software limits" error={err('soft_limits')} name="soft_limits">
                <span class="inline">
                  <input type="checkbox" name="soft-limits-on" checked={form.softLimits} onChange={(e) => set('softLimits', (e.target as HTMLInputElement).checked)} />
                  <NumberInput name="soft_limits.min" value={form.min} onValue={(v) => set('min', v)} disabled={!form.softLimits} placeholder="min" />
                  <NumberInput name="soft_limits.max" value={form.max} onValue={(v) => set('max', v)} disabled={!form.softLimits} placeholder="max" />
                </span>
                {limitSide()}
              </Field>
              {(err('soft_limits.min') || err('soft_limits.max')) && <div class="field-error">{err('soft_limits.min') ?? err('soft_limits.max')}</div>}
            </div>
          </Panel>
          <Panel title="Dynamics (defaults when a command passes 0)">
            <div class="form-grid">
              {DYN_LABELS.map(([k, label, per, hint]) =>
                num(`dynamics.${k}`, form.dyn[k], (v) => set('dyn', { ...form.dyn, [k]: v }), `${label} (${form.unit}${per})`, hint),
              )}
              {num('dynamics.jog_deadman_max', form.jogDeadmanMax, (v) => set('jogDeadmanMax', v), 'Jog dead-man max (s)', '0.05 … 10 (default 1)')}
            </div>
          </Panel>
          <Panel title="Drive">
            <DriveFields form={form} setForm={setForm} bus={bus} axis={axis?.config.name ?? null} err={err} num={num} />
          </Panel>
          {form.driveKind === 'simulated' && (
            <Panel title="Homing and switches (simulated)">
              <div class="form-grid">
                <Field label={`Reference cam (${form.unit})`} name="drive.reference_cam" error={err('drive.reference_cam.start') ?? err('drive.reference_cam.end')}>
                  <span class="inline">
                    <input type="checkbox" name="ref-cam-on" checked={form.refCam} onChange={(e) => set('refCam', (e.target as HTMLInputElement).checked)} />
                    <NumberInput name="drive.reference_cam.start" value={form.camStart} onValue={(v) => set('camStart', v)} disabled={!form.refCam} placeholder="start" />
                    <NumberInput name="drive.reference_cam.end" value={form.camEnd} onValue={(v) => set('camEnd', v)} disabled={!form.refCam} placeholder="end" />
                  </span>
                </Field>
                <Field label={`Index pulse (${form.unit})`} name="drive.index_pulse" error={err('drive.index_pulse.period') ?? err('drive.index_pulse.offset')}>
                  <span class="inline">
                    <input type="checkbox" name="index-on" checked={form.index} onChange={(e) => set('index', (e.target as HTMLInputElement).checked)} />
                    <NumberInput name="drive.index_pulse.period" value={form.indexPeriod} onValue={(v) => set('indexPeriod', v)} disabled={!form.index} placeholder="period" />
                    <NumberInput name="drive.index_pulse.offset" value={form.indexOffset} onValue={(v) => set('indexOffset', v)} disabled={!form.index} placeholder="offset" />
                  </span>
                </Field>
                {num('drive.limit_switches.negative', form.limitNeg, (v) => set('limitNeg', v), `Limit switch − (${form.unit})`, 'blank = none')}
                {num('drive.limit_switches.positive', form.limitPos, (v) => set('limitPos', v), `Limit switch + (${form.unit})`, 'blank = none')}
                <label class="check">
                  <input type="checkbox" name="drive.limit_switches.fault_on_hit" checked={form.faultOnHit} onChange={(e) => set('faultOnHit', (e.target as HTMLInputElement).checked)} /> a switch
                  faults the drive
                </label>
              </div>
            </Panel>
          )}
          <Panel title="Further base parameters (MC_AxisParameter by name)" class="wide">
            <table class="grid kv kv-params">
              <tbody>
                {form.parameters.map((p, i) => (
                  <tr key={i}>
                    <td class="kv-key">
                      <input type="text" value={p.key} placeholder="AxisTargetPositionWindow" onInput={(e) => set('parameters', form.parameters.map((q, j) => (j === i ? { ...q, key: (e.target as HTMLInputElement).value } : q)))} />
                    </td>
                    <td>
                      <input type="text" class="num" value={p.value} onInput={(e) => set('parameters', form.parameters.map((q, j) => (j === i ? { ...q, value: (e.target as HTMLInputElement).value } : q)))} />
                      {err(`parameters.${p.key.trim()}`) && <div class="field-error">{err(`parameters.${p.key.trim()}`)}</div>}
                    </td>
                    <td>
                      <button type="button" class="btn btn-small" onClick={() => set('parameters', form.parameters.filter((_, j) => j !== i))}>
                        remove
                      </button>
                    </td>
                  </tr>
                ))}
              </tbody>
            </table>
            <button type="button" class="btn btn-small" onClick={() => set('parameters', [...form.parameters, { key: '', value: '' }])}>
              + parameter
            </button>
          </Panel>
        </div>
        <div class="form-actions sticky-actions">
          <button type="submit" class="btn btn-primary" name="save" disabled={!online || checking || !!pending}>
            {creating ? 'Create axis' : checking ? 'Checking…' : 'Save configuration…'}
          </button>
          {!creating && (
            <button
              type="button"
              class="btn"
              name="revert"
              onClick={() => {
                setForm(formOf(axis.config));
                setFields({});
                setError(null);
              }}
            >
              Revert
            </button>
          )}
          {!creating &&
            (confirmDelete ? (
              <span class="confirm">
                Delete axis <b>{axis.config.name}</b> and its persistent parameters?
                <ActionButton kind="danger" name="delete-confirm" disabled={!online || !!blocked} onClick={remove}>
                  Delete
                </ActionButton>
                <button type="button" class="btn" onClick={() => setConfirmDelete(false)}>
                  Cancel
                </button>
              </span>
            ) : (
              <button
                type="button"
                class="btn btn-danger-outline"
                name="delete"
                disabled={!online || !!blocked}
                aria-describedby={blocked ? 'delete-blocked' : undefined}
                onClick={() => setConfirmDelete(true)}
              >
                Delete axis…
              </button>
            ))}
          {blocked && axis && (
            <span class="cfg-delete-blocked" id="delete-blocked" data-testid="delete-blocked">
              {blocked}
              {powered && !pending && (
                <ActionButton kind="warn" class="btn-small" name="disable-axis" disabled={!online} onClick={disableNow}>
                  Disable {axis.config.name} now
                </ActionButton>
              )}
            </span>
          )}
        </div>
      </form>
    </div>
  );
}

type NumField = (path: string, value: string, on: (v: string) => void, label: string, hint?: string) => JSX.Element;

/** The drive's kind and the fields of that kind: the simulated drive's model, or the CiA-402 drive on the bus. */
function DriveFields({ form, setForm, bus, axis, err, num }: {
  form: ConfigForm;
  setForm: (f: ConfigForm) => void;
  bus: BusResource | null;
  axis: string | null;
  err: (path: string) => string | undefined;
  num: NumField;
}) {
  const set = <K extends keyof ConfigForm>(k: K, v: ConfigForm[K]) => setForm({ ...form, [k]: v });
  const setCia = (k: keyof ConfigForm['cia'], v: string) => set('cia', { ...form.cia, [k]: v });
  const noCia = cia402Unavailable(bus);
  const sub = form.cia.subdevice.trim() === '' ? null : Number(form.cia.subdevice);
  const options = driveOptions(bus, axis, sub);
  const chooseKind = (k: DriveKind) => {
    // A new CiA-402 drive starts on the first drive no axis uses.
    const free = k === 'cia402' && form.cia.subdevice.trim() === '' ? firstFreeDrive(options) : null;
    setForm({ ...form, driveKind: k, ...(free !== null ? { cia: { ...form.cia, subdevice: String(free) } } : {}) });
  };
  const u = form.unit;
  return (
    <div class="form-grid">
      <Field
        label="Drive"
        name="drive.kind"
        class="field-row"
        error={err('drive.kind')}
        hint={noCia && form.driveKind !== 'cia402' ? <span data-testid="cia402-unavailable">CiA-402 is not offered: {noCia}</span> : undefined}
      >
        <select name="drive.kind" class="select-fit" value={form.driveKind} onChange={(e) => chooseKind((e.target as HTMLSelectElement).value as DriveKind)}>
          {DRIVE_KINDS.map(([k, label]) => (
            <option value={k} disabled={k === 'cia402' && !!noCia && form.driveKind !== 'cia402'}>
              {label}
            </option>
          ))}
        </select>
      </Field>
      {form.driveKind === 'cia402' ? (
        <>
          <Field label="SubDevice (position on the bus)" name="drive.subdevice" class="field-row" error={err('drive.subdevice')} hint={options.length ? undefined : bus ? 'no CiA-402 drive on the bus' : 'the bus could not be read'}>
            {options.length ? (
              <select name="drive.subdevice" class="select-fit" value={form.cia.subdevice} onChange={(e) => setCia('subdevice', (e.target as HTMLSelectElement).value)}>
                {sub === null && <option value="">choose a drive…</option>}
                {options.map((o) => (
                  <option value={String(o.position)}>{o.label}</option>
                ))}
              </select>
            ) : (
              <NumberInput name="drive.subdevice" value={form.cia.subdevice} onValue={(v) => setCia('subdevice', v)} placeholder="0" />
            )}
          </Field>
          {num('drive.increments_per_unit', form.cia.increments_per_unit, (v) => setCia('increments_per_unit', v), `Increments per ${u}`, 'position 0x6064 / 0x607A, > 0')}
          {num('drive.velocity_increments_per_unit', form.cia.velocity_increments_per_unit, (v) => setCia('velocity_increments_per_unit', v), 'Velocity increments', `per ${u}/s (0x606C / 0x60FF); blank = as position`)}
          <Field label="Mode" name="drive.mode" error={err('drive.mode')}>
            <select name="drive.mode" value={form.ciaMode} title={CIA_MODES.find(([k]) => k === form.ciaMode)?.[2]} onChange={(e) => set('ciaMode', (e.target as HTMLSelectElement).value as Cia402Mode)}>
              {CIA_MODES.map(([k, label, title]) => (
                <option value={k} title={title}>
                  {label}
                </option>
              ))}
            </select>
          </Field>
          <Field label="Motion profile" name="drive.profile" class="field-row" error={err('drive.profile')} hint={PROFILES.find(([k]) => k === form.ciaProfile)?.[2]}>
            <select name="drive.profile" class="select-fit" value={form.ciaProfile} onChange={(e) => set('ciaProfile', (e.target as HTMLSelectElement).value as ProfileSide)}>
              {PROFILES.map(([k, label, title]) => (
                <option value={k} title={title}>
                  {label}
                </option>
              ))}
            </select>
          </Field>
          <Field
            label="Homing method (0x6098)"
            name="drive.homing_method"
            class="field-row"
            error={err('drive.homing_method')}
            hint="for homing in the drive (MC_Home drive-based; default too when the drive runs the profile): written to the drive before it homes"
          >
            <select name="drive.homing_method" class="select-fit" value={form.homingMethod} onChange={(e) => set('homingMethod', (e.target as HTMLSelectElement).value)}>
              <option value="">the drive’s own (not written)</option>
              {HOMING_METHODS.map(([n, label]) => (
                <option value={String(n)}>
                  {n} · {label}
                </option>
              ))}
              <optgroup label="other CiA-402 methods">
                {OTHER_HOMING_METHODS.map((n) => (
                  <option value={String(n)}>{n}</option>
                ))}
              </optgroup>
            </select>
          </Field>
          {form.ciaMode !== 'csp' && num('drive.position_gain', form.cia.position_gain, (v) => setCia('position_gain', v), 'Position gain (1/s)', 'the position loop motiond closes, > 0')}
          {form.ciaMode === 'cst' && (
            <>
              {num('drive.velocity_gain', form.cia.velocity_gain, (v) => setCia('velocity_gain', v), `Velocity gain (‰ per ${u}/s)`, 'of rated torque (0x6071) per velocity error, > 0')}
              {num('drive.acceleration_feed_forward', form.cia.acceleration_feed_forward, (v) => setCia('acceleration_feed_forward', v), `Acceleration feed-forward (‰ per ${u}/s²)`, 'of rated torque per set acceleration (the inertia), ≥ 0')}
              {num('drive.max_torque', form.cia.max_torque, (v) => setCia('max_torque', v), 'Max torque (‰)', 'of rated torque, 1–32767')}
            </>
          )}
        </>
      ) : (
        <>
          <Field label="Plant" name="drive.plant" class="field-row">
            <select
              name="drive.plant.kind"
              class="select-fit"
              value={form.plant}
              title={PLANTS.find(([k]) => k === form.plant)?.[1]}
              onChange={(e) => set('plant', (e.target as HTMLSelectElement).value as PlantKind)}
            >
              {PLANTS.map(([k, label]) => (
                <option value={k}>{label}</option>
              ))}
            </select>
          </Field>
          {form.plant === 'pt1' && num('drive.plant.time_constant', form.time_constant, (v) => set('time_constant', v), 'Time constant (s)', '> 0 and ≤ 10')}
          {form.plant === 'pt2' && num('drive.plant.natural_frequency_hz', form.natural_frequency_hz, (v) => set('natural_frequency_hz', v), 'Natural frequency (Hz)', '> 0 and ≤ 1000')}
          {form.plant === 'pt2' && num('drive.plant.damping', form.damping, (v) => set('damping', v), 'Damping', '1 = critically damped')}
          {DRIVE_LABELS.map(([k, label, hint]) => num(`drive.${k}`, form.drive[k], (v) => set('drive', { ...form.drive, [k]: v }), label, hint))}
          {TORQUE_LABELS.map(([k, label, hint]) => num(`drive.torque.${k}`, form.torque[k], (v) => set('torque', { ...form.torque, [k]: v }), label, hint))}
          <label class="check">
            <input type="checkbox" name="drive.dead_time_compensation" checked={form.dead_time_compensation} onChange={(e) => set('dead_time_compensation', (e.target as HTMLInputElement).checked)} /> dead-time
            compensation
          </label>
        </>
      )}
    </div>
  );
}
