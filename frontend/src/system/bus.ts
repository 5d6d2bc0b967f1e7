// The drive bus of the System page: the axes grouped by the bus their drive is on. Today every
// drive is simulated; an EtherCAT drive kind gets its own bus (and section) here.
import type { AxisResource, DriveConfig, PlantModel } from '../api/types';

/** The buses the UI knows, in the order shown. */
export type BusKind = 'simulated' | 'unknown';

export interface Bus {
  kind: BusKind;
  /** The drive kinds on it (the server's `config.drive.kind`). */
  driveKinds: string[];
  axes: AxisResource[];
}

export const driveKind = (a: AxisResource): string => a.config.drive?.kind ?? 'simulated';

/** The bus a drive kind is on. */
export function busOf(kind: string): BusKind {
  return kind === 'simulated' ? 'simulated' : 'unknown';
}

/** The axes by bus (only buses with axes; the simulated bus also when there are no axes at all). */
export function buses(axes: AxisResource[]): Bus[] {
  const out = new Map<BusKind, Bus>();
  for (const a of [...axes].sort((x, y) => x.id - y.id)) {
    const k = driveKind(a);
    const b = busOf(k);
    let bus = out.get(b);
    if (!bus) out.set(b, (bus = { kind: b, driveKinds: [], axes: [] }));
    if (!bus.driveKinds.includes(k)) bus.driveKinds.push(k);
    bus.axes.push(a);
  }
  if (!out.size) out.set('simulated', { kind: 'simulated', driveKinds: [], axes: [] });
  return [...out.values()];
}

/** The plant model in a few words: `PT2 50 Hz, ζ 0.8`. */
export function plantText(p: PlantModel | undefined): string {
  if (!p) return 'PT2 (default)';
  switch (p.kind) {
    case 'ideal':
      return 'ideal';
    case 'pt1':
      return `PT1 T ${p.time_constant ?? '?'} s`;
    case 'pt2':
      return `PT2 ${p.natural_frequency_hz ?? '?'} Hz, ζ ${p.damping ?? '?'}`;
    default:
      return String((p as { kind?: string }).kind ?? '?');
  }
}

/** Milliseconds of a time in seconds (`0.001` → `1 ms`), '—' if not set. */
export function ms(s: number | undefined | null): string {
  if (s === undefined || s === null || !Number.isFinite(s)) return '—';
  return `${Number((s * 1000).toPrecision(4))} ms`;
}

export type { DriveConfig };
