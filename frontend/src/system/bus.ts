// The drive bus of the System page, as `GET /api/v1/bus` describes it: its kind, interface and
// state (with the reason of a fault), the frame counters (lost, late, duplicate, malformed) and
// working-counter figures, the PDU timeout, motiond's TX/RX loop, DC, and the SubDevices with
// identity, AL state, the process data mapping each drive took (and the larger ones it refused,
// with their AL status codes) and the axis whose drive each one is (the EtherCAT device view a
// commissioning engineer knows from TwinCAT). On the simulated bus there are no SubDevices: the axes with
// simulated drives are its view (also shown beside an EtherCAT bus when some axes have one).
// Also the SDO tool's parsing and presentation, and the drives the Configuration page offers.
import type { AlState, AxisResource, BusResource, PlantModel, SdoValue, SubDeviceResource } from '../api/types';

/** How often the System page reads the bus while it is shown. */
export const BUS_POLL_MS = 1000;

/** `n` as `0x` + `digits` upper-case hex digits (the unsigned 32-bit pattern of a negative). */
export function hex(n: number | null | undefined, digits: number): string {
  if (n === null || n === undefined || !Number.isFinite(n)) return '—';
  return '0x' + (n >>> 0).toString(16).toUpperCase().padStart(digits, '0');
}

export type Tone = 'green' | 'amber' | 'blue' | 'red';

/** The AL states as TwinCAT writes them, with the colour of their LED. */
export const AL_STATES: Record<AlState, { label: string; tone: Tone }> = {
  init: { label: 'INIT', tone: 'red' },
  pre_op: { label: 'PRE-OP', tone: 'amber' },
  boot: { label: 'BOOT', tone: 'blue' },
  safe_op: { label: 'SAFE-OP', tone: 'amber' },
  op: { label: 'OP', tone: 'green' },
  unknown: { label: 'unknown', tone: 'red' },
};

export const alState = (s: string): { label: string; tone: Tone } => AL_STATES[s as AlState] ?? { label: s, tone: 'red' };

/** The bus's own state: its label and LED colour. */
export function busState(state: string): { label: string; tone: Tone } {
  switch (state) {
    case 'op':
      return { label: 'OP', tone: 'green' };
    case 'degraded':
      return { label: 'degraded', tone: 'amber' };
    case 'faulted':
      return { label: 'faulted', tone: 'red' };
    case 'simulated':
      return { label: 'simulated', tone: 'green' };
    default:
      return { label: state, tone: 'red' };
  }
}

/** What the bus is, in a few words. */
export function busTitle(b: Pick<BusResource, 'kind' | 'interface'>): string {
  switch (b.kind) {
    case 'simulated':
      return 'Simulated bus';
    case 'emulated':
      return 'EtherCAT (emulated segment)';
    default:
      return `EtherCAT on ${b.interface ?? '?'}`;
  }
}

export const isEthercat = (b: Pick<BusResource, 'kind'> | null | undefined): boolean => !!b && b.kind !== 'simulated';

export interface BusBanner {
  tone: 'error' | 'warn';
  title: string;
  text: string;
}

const subdeviceName = (s: SubDeviceResource) => `${s.position} (${s.name}${s.axis ? `, axis ${s.axis}` : ''})`;

const STOPPED_AXES = 'the enabled EtherCAT axes were stopped (ErrorStop 0x70A0 bus_error) and stay in ErrorStop until they are reset (MC_Reset).';

/**
 * The banner a faulted or degraded bus needs, or null when it runs (or is simulated; also when
 * it runs again after faults: the `faults` figure tells that history). A faulted bus says why
 * (`fault_reason`): a TX/RX loop that stopped needs Reset bus; bad frames in a row clear by
 * themselves once good frames flow.
 */
export function busBanner(b: BusResource): BusBanner | null {
  if (b.state === 'faulted') {
    if (b.txrx && !b.txrx.running) {
      return {
        tone: 'error',
        title: 'Bus faulted',
        text:
          `${sentence(b.fault_reason ?? 'the TX/RX loop stopped')} No frame goes out: ${STOPPED_AXES} ` +
          "Reset bus (or an axis's MC_Reset) starts the TX/RX loop again and asks the SubDevices back to OP.",
      };
    }
    const reason = b.fault_reason ?? `${b.max_errors_in_row} lost frames or wrong working counters in a row`;
    return {
      tone: 'error',
      title: 'Bus faulted',
      text: `${reason}: ${STOPPED_AXES} The bus clears by itself after ${b.max_errors_in_row} good frames in a row.`,
    };
  }
  if (b.state === 'degraded') {
    const out = b.subdevices.filter((s) => s.al_state !== 'op');
    const which = out.length
      ? `${out.length === 1 ? 'SubDevice' : 'SubDevices'} ${out.map((s) => `${subdeviceName(s)} in ${alState(s.al_state).label}`).join(', ')}`
      : 'a SubDevice';
    const one = out.length === 1;
    return {
      tone: 'warn',
      title: 'Bus degraded',
      text: `${which} not in OP: ${one ? 'its axis is' : 'their axes are'} stopped when enabled. Powering on or resetting ${one ? 'the axis' : 'an axis'} asks its SubDevice back to OP.`,
    };
  }
  if (b.state !== 'op' && b.state !== 'simulated') return { tone: 'warn', title: `Bus ${b.state}`, text: 'motiond reports a state this page does not know.' };
  return null;
}

export interface Counter {
  key: string;
  label: string;
  value: string;
  tone?: 'ok' | 'warn' | 'bad';
  title: string;
}

const count = (n: number) => n.toLocaleString('en-US');

/** A server's phrase as a sentence: capital first letter, a full stop at the end. */
export function sentence(t: string): string {
  const s = t.trim();
  if (!s) return s;
  return s[0].toUpperCase() + s.slice(1) + (/[.!?]$/.test(s) ? '' : '.');
}

/** A figure that should stay zero: amber once any happened since start. */
const sinceStart = (key: string, label: string, n: number | undefined, title: string): Counter => ({
  key,
  label,
  value: count(n ?? 0),
  tone: n ? 'warn' : 'ok',
  title,
});

/** Nanoseconds as microseconds with one decimal; '—' when not known. */
export function nsAsUs(ns: number | null | undefined): string {
  if (ns === null || ns === undefined || !Number.isFinite(ns)) return '—';
  return `${(ns / 1000).toFixed(1)} µs`;
}

/** The figures of an EtherCAT bus, in the order shown. */
export function busCounters(b: BusResource): Counter[] {
  const wkcOk = b.last_working_counter === b.expected_working_counter;
  return [
    { key: 'frames', label: 'Frames', value: count(b.frames), title: 'frames exchanged since start (one per cycle)' },
    // Since start: amber once any happened; red is for what is wrong now (the rows below).
    sinceStart('lost_frames', 'Lost frames', b.lost_frames, `frames that got no answer within the PDU timeout (${ms(b.pdu_timeout)}), retries included, since start`),
    sinceStart('late_replies', 'Late replies', b.late_replies, 'answers that came after their frame was answered or given up (a PDU timeout or more after it was sent): counted and dropped, since start'),
    sinceStart('duplicate_replies', 'Duplicate replies', b.duplicate_replies, 'answers that came twice (the same PDU index): counted and dropped, since start'),
    sinceStart('malformed_frames', 'Malformed frames', b.malformed_frames, 'EtherCAT frames received that did not parse: counted and dropped, since start'),
    sinceStart('faults', 'Bus faults', b.faults, 'times the bus faulted (lost frames or wrong working counters in a row, or the TX/RX loop stopped) since start; each stopped the enabled EtherCAT axes'),
    sinceStart('working_counter_errors', 'WKC errors', b.working_counter_errors, 'frames that came back with a wrong working counter, since start'),
    {
      key: 'working_counter',
      label: 'WKC last / expected',
      value: `${b.last_working_counter} / ${b.expected_working_counter}`,
      tone: wkcOk ? 'ok' : 'bad',
      title: 'the working counter of the latest frame and the one every SubDevice answering gives',
    },
    {
      key: 'errors_in_row',
      label: 'Errors in a row / max',
      value: `${b.errors_in_row} / ${b.max_errors_in_row}`,
      tone: b.errors_in_row >= b.max_errors_in_row ? 'bad' : b.errors_in_row ? 'warn' : 'ok',
      title: 'lost frames or wrong working counters in a row now; at the maximum (--bus-max-errors) the bus faults and stops its enabled axes',
    },
    {
      key: 'dc_cycle_offset',
      label: 'DC cycle offset',
      value: nsAsUs(b.dc_cycle_offset_ns),
      title: 'where in its SYNC0 period the latest frame reached the DC reference clock',
    },
  ];
}

export interface TxRxView {
  running: boolean;
  label: string;
  tone: Tone;
  restarts: string;
  /** What the thread got: SCHED_FIFO priority and CPU, or why not. */
  thread: string;
}

/** motiond's TX/RX loop as shown, or null when the server does not say (simulated bus). */
export function txrxView(b: Pick<BusResource, 'txrx'>): TxRxView | null {
  const t = b.txrx;
  if (!t) return null;
  return { running: t.running, label: t.running ? 'running' : 'stopped', tone: t.running ? 'green' : 'red', restarts: count(t.restarts), thread: t.thread };
}

/** `0x60b8` as TwinCAT writes an index: `0x60B8`. */
export const objectIndex = (s: string): string => (/^0x[0-9a-f]+$/i.test(s) ? '0x' + s.slice(2).toUpperCase() : s);

export interface RefusedView {
  mapping: string;
  /** `PDO mapping write` or `PRE-OP to SAFE-OP`. */
  at: string;
  /** `0x001D`, or null when refused by an SDO abort. */
  code: string | null;
  /** The AL status code's ETG.1000 meaning (the reason without its code), or the SDO error. */
  meaning: string;
}

/** A refused mapping: its AL status code upper-case and its meaning apart (the server writes `0x001d: Invalid …`). */
export function refusedView(r: { mapping: string; at: string; al_status_code?: string | null; reason: string }): RefusedView {
  const code = r.al_status_code ? objectIndex(r.al_status_code) : null;
  let meaning = r.reason.trim();
  const c = r.al_status_code?.toLowerCase();
  if (c && meaning.toLowerCase().startsWith(c)) meaning = meaning.slice(c.length).replace(/^\s*:\s*/, '');
  return { mapping: r.mapping, at: r.at, code, meaning };
}

/** A drive's process data: the mapping it took, its sizes, the objects it lacks, the mappings it refused. */
export interface MappingView {
  mapping: string;
  tone: Tone;
  /** `15 B out, 29 B in`. */
  bytes: string;
  missing: string[];
  refused: RefusedView[];
}

export function mappingView(d: NonNullable<SubDeviceResource['drive']>): MappingView {
  return {
    mapping: d.mapping,
    tone: d.mapping === 'full' ? 'green' : 'amber',
    bytes: `${d.output_bytes} B out, ${d.input_bytes} B in`,
    missing: (d.missing_objects ?? []).map(objectIndex),
    refused: (d.refused ?? []).map(refusedView),
  };
}

/**
 * Why Reset bus cannot be pressed now, or null: the simulated bus has no segment; a reset runs;
 * it needs the engineer role and the server.
 */
export function resetUnavailable(b: Pick<BusResource, 'kind'> | null, o: { busy: boolean; engineer: boolean; online: boolean }): string | null {
  if (!b) return 'the bus is not read yet';
  if (!isEthercat(b)) return 'motiond runs the simulated bus: there is no EtherCAT segment to reset';
  if (o.busy) return 'the bus is being reset';
  if (!o.online) return 'motiond is not reachable';
  if (!o.engineer) return 'resetting the bus needs the engineer role';
  return null;
}

export interface SubDeviceRow {
  position: number;
  address: string;
  name: string;
  vendor: string;
  product: string;
  revision: string;
  serial: string;
  al: { state: string; label: string; tone: Tone };
  /** The CiA-402 process data as mapped, or null when the SubDevice is no drive. */
  mapping: string | null;
  /** The same in detail, or null when the SubDevice is no drive. */
  process: MappingView | null;
  dc: boolean;
  axis: string | null;
}

/** The SubDevices as table rows, by position. */
export function subDeviceRows(b: BusResource): SubDeviceRow[] {
  return [...b.subdevices]
    .sort((x, y) => x.position - y.position)
    .map((s) => ({
      position: s.position,
      address: hex(s.configured_address, 4),
      name: s.name,
      vendor: hex(s.vendor_id, 8),
      product: hex(s.product_code, 8),
      revision: hex(s.revision, 8),
      serial: String(s.serial >>> 0),
      al: { state: s.al_state, ...alState(s.al_state) },
      mapping: s.drive ? `${s.drive.mapping} · ${s.drive.output_bytes} B out, ${s.drive.input_bytes} B in` : null,
      process: s.drive ? mappingView(s.drive) : null,
      dc: s.dc,
      axis: s.axis ?? null,
    }));
}

export const driveKind = (a: AxisResource): string => a.config.drive?.kind ?? 'simulated';

/** The axes with simulated drives, by id (the simulated bus's view). */
export function simulatedAxes(axes: AxisResource[]): AxisResource[] {
  return axes.filter((a) => driveKind(a) === 'simulated').sort((x, y) => x.id - y.id);
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

// ───────────────────────────── the Configuration page ─────────────────────────────

/** Why a CiA-402 drive cannot be chosen, or null: only an EtherCAT bus has them (unknown bus: the server judges). */
export function cia402Unavailable(b: Pick<BusResource, 'kind'> | null | undefined): string | null {
  if (!b || b.kind !== 'simulated') return null;
  return 'motiond runs the simulated bus; start motiond with --bus ethercat --interface IFACE, or --bus emulated.';
}

export interface DriveOption {
  position: number;
  label: string;
  /** The axis whose drive it is now (null: free). */
  axis: string | null;
}

/**
 * The CiA-402 drives on the bus an axis may be given, by position, each with its name and the
 * axis that uses it (another axis's drive stays offered: the server refuses it, at the field).
 * `current` (the axis's configured position) is offered even when the bus has no drive there.
 */
export function driveOptions(b: BusResource | null, axis: string | null, current: number | null): DriveOption[] {
  const out: DriveOption[] = (b?.subdevices ?? [])
    .filter((s) => s.drive)
    .sort((x, y) => x.position - y.position)
    .map((s) => {
      const user = s.axis ?? null;
      const who = user === null ? 'free' : user === axis ? `axis ${user}` : `used by ${user}`;
      return { position: s.position, label: `${s.position} · ${s.name} — ${who}`, axis: user };
    });
  if (current !== null && Number.isInteger(current) && !out.some((o) => o.position === current)) {
    out.push({ position: current, label: `${current} · ${b ? 'no CiA-402 drive there on the bus' : 'bus not read'}`, axis: axis });
    out.sort((x, y) => x.position - y.position);
  }
  return out;
}

/** The first drive no axis uses, or null. */
export const firstFreeDrive = (options: DriveOption[]): number | null => options.find((o) => o.axis === null)?.position ?? null;

// ───────────────────────────── SDO ─────────────────────────────

/** An object address as typed: the index (`0x1018` or decimal) and the subindex. */
export function parseSdoAddress(index: string, sub: string): { index: string; sub: number; errors: Record<string, string> } {
  const errors: Record<string, string> = {};
  const i = index.trim();
  if (i === '') errors.index = 'required';
  else if (!/^(0x[0-9a-f]+|\d+)$/i.test(i)) errors.index = 'hex like 0x1018, or decimal';
  const t = sub.trim();
  const s = /^0x[0-9a-f]+$/i.test(t) ? parseInt(t, 16) : t === '' ? NaN : Number(t);
  if (!Number.isInteger(s) || s < 0) errors.sub = t === '' ? 'required' : 'a whole number ≥ 0';
  return { index: i, sub: s, errors };
}

/** A value to write as typed: decimal or `0x` hex, with an optional sign; null when it is no whole number. */
export function parseSdoValue(value: string): number | null {
  const t = value.trim().replace(/_/g, '');
  const m = /^([+-]?)(0x[0-9a-f]+|\d+)$/i.exec(t);
  if (!m) return null;
  const v = m[2].toLowerCase().startsWith('0x') ? parseInt(m[2].slice(2), 16) : Number(m[2]);
  return Number.isSafeInteger(v) ? (m[1] === '-' ? -v : v) : null;
}

export const sdoPath = (position: number, index: string, sub: number) => `/bus/subdevices/${position}/sdo/${encodeURIComponent(index)}/${sub}`;

export interface SdoView {
  /** `0x1018:01`. */
  address: string;
  /** The bytes as sent (little endian): `ce 0a ff 00`. */
  bytes: string;
  /** The integer of 1 to 8 bytes in hex, as wide as the object: `0x00FF0ACE`; null for longer ones. */
  value: string | null;
  unsigned: string | null;
  signed: string | null;
  text: string | null;
}

/** An SDO answer as the tool shows it. */
export function sdoView(v: SdoValue): SdoView {
  const b = v.bytes ?? [];
  const two = (n: number) => n.toString(16).padStart(2, '0');
  const idx = /^0x/i.test(v.index) ? '0x' + v.index.slice(2).toUpperCase() : v.index;
  return {
    address: `${idx}:${two(v.sub).toUpperCase()}`,
    bytes: b.map(two).join(' '),
    value: b.length >= 1 && b.length <= 8 ? '0x' + [...b].reverse().map(two).join('').toUpperCase() : null,
    unsigned: v.unsigned === null || v.unsigned === undefined ? null : String(v.unsigned),
    signed: v.signed === null || v.signed === undefined ? null : String(v.signed),
    text: v.text ?? null,
  };
}
