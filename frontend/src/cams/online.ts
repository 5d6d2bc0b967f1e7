// Online change of a coupled cam table (MC_SetCamOnlineChangeMode): which axes run on the table
// (from their live MC_CamInfo), what each activation mode means, and what a save will do.
import type { AxisLiveStatus, OnlineActivationMode, OnlineChange } from '../api/types';
import { SCALING_MODES } from '../axis/bodies';

/** The modes a table keeps (`delete_queued_data` is an action, offered on its own). */
export const ONLINE_MODES: OnlineActivationMode[] = [
  'instantaneous',
  'as_soon_as_possible',
  'next_cycle',
  'at_master_cam_pos',
  'at_master_axis_pos',
  'at_master_axis_pos_positive_direction',
  'at_master_axis_pos_negative_direction',
  'off',
];
export { SCALING_MODES };

/** When written data reaches a coupled slave, per mode (the API's description, shortened). */
export const ONLINE_MODE_TEXT: Record<OnlineActivationMode, string> = {
  instantaneous: 'in the first cycle where the new data does not move it',
  as_soon_as_possible: 'in the first cycle where the new data does not move it',
  next_cycle: 'from the start of its next cam cycle, in the first cycle where the new data does not move it',
  at_master_cam_pos: 'from the master’s cam position at the activation position, in the first cycle where the new data does not move it',
  at_master_axis_pos: 'from the master axis at the activation position, in the first cycle where the new data does not move it',
  at_master_axis_pos_positive_direction: 'from the master axis passing the activation position forwards, in the first cycle where the new data does not move it',
  at_master_axis_pos_negative_direction: 'from the master axis passing the activation position backwards, in the first cycle where the new data does not move it',
  off: 'never: coupled slaves keep the data they run with (new couplings take the new data)',
  delete_queued_data: 'drops written data that has not reached its slaves',
};

export const takesActivationPosition = (m: OnlineActivationMode | undefined) => !!m && m.startsWith('at_master');

/** An axis coupled through a table. */
export interface CamSlave {
  axis: string;
  master: string;
  /** Written data waits for the slave's activation (`cam_data_queued`). */
  queued: boolean;
}

type Statuses = Iterable<[string, { status: AxisLiveStatus | null }]>;
type CamPos = Pick<NonNullable<AxisLiveStatus['cam']>, 'actual_master_cam_pos' | 'actual_slave_cam_pos'>;

/**
 * The axes whose coupling runs on table `id` now (live MC_CamInfo, multi-cam included), sorted
 * by name, each with its status and where it is on that table (the multi-cam term of it).
 */
function coupledThrough(statuses: Statuses, id: number): { axis: string; s: AxisLiveStatus; at: CamPos | null }[] {
  const out: { axis: string; s: AxisLiveStatus; at: CamPos | null }[] = [];
  for (const [axis, { status: s }] of statuses) {
    const cam = s?.cam;
    if (!s || !cam?.active) continue;
    const term = (cam.cams ?? []).find((c) => c.cam_table_id === id);
    if (cam.cam_table_id !== id && !term) continue;
    out.push({ axis, s, at: term ?? (cam.cam_table_id === id ? cam : null) });
  }
  return out.sort((a, b) => a.axis.localeCompare(b.axis));
}

/** The axes whose coupling runs on table `id` now (their live MC_CamInfo, multi-cam included). */
export function slavesOf(statuses: Statuses, id: number): CamSlave[] {
  return coupledThrough(statuses, id).map(({ axis, s }) => ({ axis, master: s.master ?? '', queued: s.cam_data_queued }));
}

/** Where a slave coupled through a table is on it now: the table's master and slave position. */
export interface CamMarker {
  axis: string;
  master: string;
  /** In the table's own coordinates (one cycle, no offsets or scalings): what the plot shows. */
  x: number;
  y: number;
}

/** The live position on table `id` of every axis coupled through it (MC_CamInfo, multi-cam terms too). */
export function camMarkers(statuses: Statuses, id: number): CamMarker[] {
  return coupledThrough(statuses, id)
    .filter(({ at }) => at && Number.isFinite(at.actual_master_cam_pos) && Number.isFinite(at.actual_slave_cam_pos))
    .map(({ axis, s, at }) => ({ axis, master: s.master ?? '', x: at!.actual_master_cam_pos, y: at!.actual_slave_cam_pos }));
}

/**
 * The units of the plot's axes: the master axis's and the slave axis's of the (first) coupled
 * slave; null while no axis is coupled through the table (a table alone has no units).
 */
export function camUnits(markers: CamMarker[], axes: { config: { name: string; unit: string } }[]): { master: string; slave: string } | null {
  const m = markers[0];
  if (!m) return null;
  const unit = (n: string) => axes.find((a) => a.config.name === n)?.config.unit;
  const master = unit(m.master);
  const slave = unit(m.axis);
  return master && slave ? { master, slave } : null;
}

/** "y (master x)", "y (master x) and z (master x)". */
export function slaveList(slaves: CamSlave[]): string {
  const names = slaves.map((s) => (s.master ? `${s.axis} (master ${s.master})` : s.axis));
  return names.length <= 1 ? names.join('') : `${names.slice(0, -1).join(', ')} and ${names[names.length - 1]}`;
}

/** What saving a coupled table does, said before it is done. */
export function onlineChangeText(slaves: CamSlave[], mode: OnlineChange): string {
  const m = mode.activation_mode ?? 'instantaneous';
  const at = takesActivationPosition(m) ? ` (activation position ${mode.activation_position ?? 0})` : '';
  const auto = [mode.master_scaling_mode === 'auto_offset' && 'master', mode.slave_scaling_mode === 'auto_offset' && 'slave'].filter(Boolean);
  const scaling = auto.length ? `the ${auto.join(' and ')} offset${auto.length > 1 ? 's follow' : ' follows'} (auto_offset)` : 'offsets stay as they are';
  return `This table is coupled: saving is an online change. It reaches ${slaveList(slaves)} by the mode ${m}${at}: ${ONLINE_MODE_TEXT[m]}; ${scaling}.`;
}
