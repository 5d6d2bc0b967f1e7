// A group's configuration form (`POST /groups`, `PUT /groups/{group}`) as typed, and the body it
// sends. The axes are chosen by role (the convention's, then ADDAX1..n); a role left blank is not
// sent, so `axes[i]` of the body — where the server's 422 points — is the i-th role that has an
// axis: `memberField` gives each role the JSON path its select is named by. No UI code.
import type { AxesConvention, GroupBody, GroupResource, GroupRole, PathDynamics } from '../api/types';
import { groupRoles } from './rows';

export const CONVENTIONS: [AxesConvention, string][] = [
  ['xy', 'XY (2D)'],
  ['xyz', 'XYZ (3D)'],
  ['xyzc', 'XYZC (3D + C)'],
];

export const DYNAMICS: (keyof PathDynamics)[] = ['velocity', 'acceleration', 'deceleration', 'jerk'];

type DynText = Record<keyof PathDynamics, string>;

export interface GroupDraft {
  /** The id of the group edited (PUT), null for a new one. */
  id: number | null;
  name: string;
  convention: AxesConvention;
  additional: string;
  /** Role → axis name ('' = none). */
  axes: Partial<Record<GroupRole, string>>;
  defaults: DynText;
  maximum: DynText;
  rampTime: string;
}

const dynText = (d: PathDynamics): DynText => ({
  velocity: String(d.velocity),
  acceleration: String(d.acceleration),
  deceleration: String(d.deceleration),
  jerk: String(d.jerk),
});

/** The server's defaults (GroupConfig::default: v 100, a/d 1000, j 10000; max v 1000, a/d 10000, j 1e6; ramp 0.1 s). */
export function newDraft(axisNames: string[]): GroupDraft {
  return {
    id: null,
    name: '',
    convention: 'xy',
    additional: '0',
    axes: { x: axisNames[0] ?? '', y: axisNames[1] ?? '' },
    defaults: dynText({ velocity: 100, acceleration: 1000, deceleration: 1000, jerk: 10000 }),
    maximum: dynText({ velocity: 1000, acceleration: 10000, deceleration: 10000, jerk: 1000000 }),
    rampTime: '0.1',
  };
}

export function draftOf(g: GroupResource): GroupDraft {
  const axes: Partial<Record<GroupRole, string>> = {};
  for (const m of g.axes) axes[m.role] = m.axis;
  return {
    id: g.id,
    name: g.name,
    convention: g.convention,
    additional: String(g.additional_axes),
    axes,
    defaults: dynText(g.default_dynamics),
    maximum: dynText(g.maximum_dynamics),
    rampTime: String(g.override_ramp_time),
  };
}

const number = (s: string) => (s.trim() === '' ? NaN : Number(s.trim().replace(',', '.')));

/** The roles the form offers (the additional count as typed; nothing beyond 8). */
export function draftRoles(d: GroupDraft): GroupRole[] {
  const n = Number(d.additional);
  return groupRoles(d.convention, Number.isInteger(n) ? n : 0);
}

/** The roles sent, in the body's order (those with an axis). */
export function sentRoles(d: GroupDraft): GroupRole[] {
  return draftRoles(d).filter((r) => (d.axes[r] ?? '').trim() !== '');
}

/** The JSON path a role's select is named by: `axes[i].axis` as sent, `axes.<role>` while blank. */
export function memberField(d: GroupDraft, role: GroupRole): string {
  const i = sentRoles(d).indexOf(role);
  return i < 0 ? `axes.${role}` : `axes[${i}].axis`;
}

/** The error of a role's select: its `axes[i].axis` or `axes[i].role`. */
export function memberError(d: GroupDraft, role: GroupRole, fields: Record<string, string>): string | undefined {
  const i = sentRoles(d).indexOf(role);
  if (i < 0) return undefined;
  return [fields[`axes[${i}].axis`], fields[`axes[${i}].role`], fields[`axes[${i}]`]].filter(Boolean).join('; ') || undefined;
}

export function bodyOf(d: GroupDraft): GroupBody {
  const dyn = (t: DynText): PathDynamics => ({
    velocity: number(t.velocity),
    acceleration: number(t.acceleration),
    deceleration: number(t.deceleration),
    jerk: number(t.jerk),
  });
  const body: GroupBody = {
    name: d.name.trim(),
    convention: d.convention,
    additional_axes: number(d.additional),
    axes: sentRoles(d).map((role) => ({ role, axis: (d.axes[role] ?? '').trim() })),
    default_dynamics: dyn(d.defaults),
    maximum_dynamics: dyn(d.maximum),
    override_ramp_time: number(d.rampTime),
  };
  if (d.id !== null) body.id = d.id;
  return body;
}
