// Which coupling an axis is in now, from its live status and the command that coupled it: the
// Coupling tab names it and shows the multi-master table only for a multi-master coupling (a cam
// slave's status has ratios of 0 for every master, which is no multi-master gear).
import type { AxisLiveStatus } from '../api/types';

export type CouplingKind = 'none' | 'gear' | 'gear-dyn' | 'cam' | 'multi-master';

export interface CouplingInForce {
  kind: CouplingKind;
  /** The master the status names (the first one of a multi-master coupling). */
  master: string | null;
  /** What to call it: "cam table 3 (MC_CamIn)", "gear 1:2 (MC_GearIn)", … */
  text: string;
}

/** What the Coupling tab needs of the command that coupled the axis (the command log's entry). */
export interface Coupler {
  command: string;
  state: string;
}

/** The commands that couple an axis as a slave. */
export const COUPLING_COMMANDS = new Set(['gear-in', 'gear-in-dyn', 'gear-in-multi-master', 'cam-in', 'cam-in-v2', 'cam-exchange', 'cam-add']);

/** The axis's latest coupling command in the command log (one that failed coupled nothing). */
export const couplerOf = <E extends Coupler & { axis: string; id: number | null }>(log: readonly E[], axis: string): E | undefined =>
  log.find((e) => e.axis === axis && e.id !== null && COUPLING_COMMANDS.has(e.command) && e.state !== 'error');

const CAM_COMMANDS: Record<string, string> = {
  'cam-in': 'MC_CamIn',
  'cam-in-v2': 'MC_CamIn_V2',
  'cam-exchange': 'MC_CamExchange',
  'cam-add': 'MC_CamAdd',
};

/**
 * The coupling in force. `coupler` is the axis's latest coupling command (null when the log has
 * none: coupled before this page or by a command too old for it); a coupling command that
 * failed (`error`) coupled nothing and is not taken.
 */
export function couplingInForce(
  s: Pick<AxisLiveStatus, 'coupled' | 'master' | 'gear_ratio' | 'gear_ratios' | 'cam'> | null | undefined,
  coupler: Coupler | null | undefined,
): CouplingInForce {
  if (!s?.coupled) return { kind: 'none', master: null, text: 'not coupled' };
  const master = s.master ?? null;
  const by = coupler && coupler.state !== 'error' ? coupler.command : null;
  const ratio = (r: number) => String(Math.round(r * 1e6) / 1e6);
  const table = s.cam && s.cam.active && s.cam.cam_table_id !== 0 ? s.cam.cam_table_id : null;
  if (table !== null || (by && CAM_COMMANDS[by])) {
    return { kind: 'cam', master, text: `cam${table !== null ? ` table ${table}` : ''}${by && CAM_COMMANDS[by] ? ` (${CAM_COMMANDS[by]})` : ''}` };
  }
  const others = (s.gear_ratios ?? []).slice(1).some((r) => r !== 0);
  if (by === 'gear-in-multi-master' || (by === null && others)) {
    return { kind: 'multi-master', master, text: 'multi-master gear (MC_GearInMultiMaster)' };
  }
  if (by === 'gear-in-dyn') return { kind: 'gear-dyn', master, text: `gear ratio ${ratio(s.gear_ratio)} (MC_GearInDyn)` };
  return { kind: 'gear', master, text: `gear ratio ${ratio(s.gear_ratio)}${by === 'gear-in' ? ' (MC_GearIn)' : ''}` };
}
