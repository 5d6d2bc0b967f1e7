// What saving an axis configuration does, in words: the server's `change` (a dry run before the
// save, the real one after it) and, per configuration field, the persistent and online values
// of the parameter behind it where they differ from the configured (start-up) value.
import type { components } from '../api/schema';
import type { ParameterResource, ParamValue } from '../api/types';
import { inputNum } from '../format';

export type ConfigChange = components['schemas']['ConfigChange'];
export type ParameterChange = components['schemas']['ParameterChange'];

/** The configuration fields that are MC_AxisParameter values: field path → parameter number. */
export const FIELD_PARAMS: Record<string, number> = {
  'dynamics.max_velocity': 1003, // AxisVeloMax
  'dynamics.acceleration': 1004, // AxisAcc
  'dynamics.deceleration': 1005, // AxisDec
  'dynamics.jerk': 1006, // AxisJerk
  'dynamics.jog_velocity_slow': 1001, // AxisVeloManSlow
  'dynamics.jog_velocity_fast': 1002, // AxisVeloManFast
  'soft_limits.min': 1017, // AxisMinSoftPosLimit
  'soft_limits.max': 1019, // AxisMaxSoftPosLimit
};

/** A parameter value as text (numbers without float noise). */
export function valueText(v: ParamValue | null | undefined): string {
  if (v === undefined || v === null) return '';
  if (typeof v === 'boolean') return v ? 'true' : 'false';
  return inputNum(v);
}

/** Equal values (numbers to 12 significant digits: what the UI can show). */
export function sameValue(a: ParamValue | null | undefined, b: ParamValue | null | undefined): boolean {
  if (a === b) return true;
  if (typeof a === 'number' && typeof b === 'number') return inputNum(a) === inputNum(b);
  return false;
}

const plural = (n: number, one: string, many = `${one}s`) => `${n} ${n === 1 ? one : many}`;

/** A position for a sentence: at most 3 decimals, with the unit. */
export function positionText(v: number | null | undefined, unit: string): string | null {
  if (v === null || v === undefined || !Number.isFinite(v)) return null;
  return `${inputNum(Number(v.toFixed(3)))} ${unit}`;
}

export interface ChangeSummary {
  /** `ok`: nothing is reset; `warn`: the axis is (or would be) re-created. */
  tone: 'ok' | 'warn';
  /** The one sentence to read first. */
  headline: string;
  /** What happens to persistent values, or null when none is discarded. */
  persistent: string | null;
}

/**
 * What a change says, in words. A dry run speaks of what the save will do, an answer of what
 * it did. `position` is the axis's position now (for the rebuild warning), when known.
 */
export function changeSummary(c: ConfigChange, opts: { unit?: string; position?: number | null } = {}): ChangeSummary {
  const n = c.parameters.length;
  const d = c.persistent_discarded.length;
  const names = c.persistent_discarded.map((p) => `${p.name} ${valueText(p.new)}`).join(', ');
  const persistent = d
    ? c.dry_run
      ? `${plural(d, 'persistent value')} will be discarded (${names}): the configured value replaces ${d === 1 ? 'it' : 'them'}.`
      : `${plural(d, 'persistent value')} discarded (${names}).`
    : null;
  if (c.rebuild) {
    const why = c.rebuild_reasons.length ? ` (${c.rebuild_reasons.join(', ')})` : '';
    const at = positionText(opts.position, opts.unit ?? '');
    if (c.dry_run) {
      return {
        tone: 'warn',
        headline: `The axis will be re-created${why}: its position${at ? ` (now ${at})` : ''}, homed state and online values are lost.`,
        persistent,
      };
    }
    return { tone: 'warn', headline: `Saved. The axis was re-created${why}: its position, homed state and online values were reset.`, persistent };
  }
  if (c.dry_run) {
    return {
      tone: 'ok',
      headline: n ? `This save changes ${plural(n, 'parameter')} online; nothing is reset.` : 'This save changes no parameter; nothing is reset.',
      persistent,
    };
  }
  return {
    tone: 'ok',
    headline: n ? `Saved. ${plural(n, 'parameter')} changed online; nothing was reset.` : 'Saved. No parameter changed; nothing was reset.',
    persistent,
  };
}

export interface ChangeRow {
  name: string;
  number: number;
  configured: string;
  next: string;
  /** The value in force before the save, when it differs from the configured one. */
  online: string | null;
}

/** The changed parameters as rows: configured → new, with the online value when it differs. */
export function changeRows(list: ParameterChange[]): ChangeRow[] {
  return list.map((p) => ({
    name: p.name,
    number: p.number,
    configured: valueText(p.configured),
    next: valueText(p.new),
    online: sameValue(p.online, p.configured) ? null : valueText(p.online),
  }));
}

/** The persistent and online values of a parameter where they differ from the configured one. */
export interface SideValues {
  online: string | null;
  persistent: string | null;
}

export function sideValues(p: Pick<ParameterResource, 'value' | 'persistent_value' | 'configured_value'> | null | undefined): SideValues | null {
  if (!p || p.configured_value === undefined || p.configured_value === null) return null;
  const online = sameValue(p.value, p.configured_value) ? null : valueText(p.value);
  const hasPersistent = p.persistent_value !== undefined && p.persistent_value !== null;
  const persistent = hasPersistent && !sameValue(p.persistent_value, p.configured_value) ? valueText(p.persistent_value) : null;
  return online === null && persistent === null ? null : { online, persistent };
}

/** "online 650 · persistent 800" (empty when nothing differs). */
export function sideText(s: SideValues | null): string {
  if (!s) return '';
  return [s.online !== null ? `online ${s.online}` : null, s.persistent !== null ? `persistent ${s.persistent}` : null].filter(Boolean).join(' · ');
}

/**
 * The configuration fields whose parameter runs with (or keeps persistently) another value than
 * the configured one: field path → what differs.
 */
export function differingFields(params: Map<number, Pick<ParameterResource, 'value' | 'persistent_value' | 'configured_value'>> | null): Record<string, SideValues> {
  const out: Record<string, SideValues> = {};
  if (!params) return out;
  for (const [field, number] of Object.entries(FIELD_PARAMS)) {
    const s = sideValues(params.get(number));
    if (s) out[field] = s;
  }
  return out;
}

/** An online value a rebuild loses, and the value the re-created axis starts with instead. */
export interface LostValue {
  name: string;
  number: number;
  online: string;
  after: string;
  /** Where `after` comes from: the kept persistent value, or the configured one. */
  from: 'persistent' | 'configured';
}

type ParamLike = Pick<ParameterResource, 'number' | 'name' | 'storage' | 'read_only' | 'group' | 'value' | 'persistent_value' | 'configured_value'>;

/**
 * The online values a rebuild loses besides those of the parameters the save changes (listed
 * with their online value already): those of the other parameters (each once: no aliases, no
 * status entries) whose value in force differs from what the re-created axis starts with — the
 * persistent value where there is one (kept), else the configured one. Nothing without a rebuild.
 */
export function lostOnlineValues(params: Iterable<ParamLike> | null, c: ConfigChange): LostValue[] {
  if (!params || !c.rebuild) return [];
  const changed = new Set(c.parameters.map((p) => p.number));
  const discarded = new Set(c.persistent_discarded.map((p) => p.number));
  const out: LostValue[] = [];
  for (const p of params) {
    if (p.read_only || p.group === 'status' || p.storage !== p.number || changed.has(p.number)) continue;
    if (p.configured_value === undefined || p.configured_value === null) continue;
    const hasPersistent = p.persistent_value !== undefined && p.persistent_value !== null && !discarded.has(p.number);
    const [after, from]: [ParamValue, LostValue['from']] = hasPersistent
      ? [p.persistent_value as ParamValue, 'persistent']
      : [p.configured_value, 'configured'];
    if (!sameValue(p.value, after)) out.push({ name: p.name, number: p.number, online: valueText(p.value), after: valueText(after), from });
  }
  return out.sort((a, b) => a.number - b.number);
}

/**
 * Why a save that re-creates the axis is blocked now (its live status), or null: the server
 * swaps only a disabled axis (state Disabled and power off). Unknown status: null.
 */
export function rebuildBlockedText(s: { state: string; power_status: boolean } | null | undefined, stateLabel: (state: string) => string): string | null {
  if (!s) return null;
  if (s.power_status) return 'Save is blocked: re-creating the axis needs it disabled, and it is enabled.';
  if (s.state !== 'disabled') return `Save is blocked: re-creating the axis needs it Disabled, and it is in ${stateLabel(s.state)} (reset it).`;
  return null;
}
