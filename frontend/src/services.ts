// Application state: the websocket, the axes, their live status, the command log.
import { LiveClient } from './live/client';
import { JogController } from './live/jog';
import { Store } from './store';
import { ApiError, del, enc, get, post } from './api/rest';
import { errorInfo } from './api/errors';
import type { AxisResource, AxisStatus, CommandEvent, CommandResource, SystemResource } from './api/types';
import { RpcError } from './live/client';
import { ScopeSession } from './scope/session';
import { cancelRecording, createRecording, getRecording, listRecordings } from './scope/api';

export interface LiveStatus {
  status: AxisStatus | null;
  cycle: number;
  stale: boolean;
  /** Peak hold of the following error (of the values received), reset by the user. */
  lagMax: number;
  lagMin: number;
}

export interface LogEntry {
  key: string;
  id: number | null;
  axis: string;
  command: string;
  parameters: unknown;
  state: string;
  final: boolean;
  errorId: number;
  errorText: string | null;
  at: string;
  cycle: number;
}

export const STATUS_RATE_HZ = 25;
export const FOCUS_RATE_HZ = 50;
const LOG_MAX = 300;

function wsUrl(): string {
  const l = typeof location !== 'undefined' ? location : ({ protocol: 'http:', host: '127.0.0.1:8080' } as Location);
  return `${l.protocol === 'https:' ? 'wss:' : 'ws:'}//${l.host}/api/v1/ws`;
}

export const live = new LiveClient({ url: wsUrl() });
export const jog = new JogController(live, {
  started: (r) => logCommand(r),
  rejected: (axis, params, e) => logRejected(axis, 'jog', params, e),
});
export const axes = new Store<AxisResource[]>([]);
export const axesLoaded = new Store<boolean>(false);
export const statuses = new Store<Map<string, LiveStatus>>(new Map(), true);
export const system = new Store<SystemResource | null>(null, true);
export const commandLog = new Store<LogEntry[]>([], true);
/** Scope recordings followed across page changes. */
export const scope = new ScopeSession({ list: listRecordings, get: getRecording, create: createRecording, cancel: cancelRecording });

let focus: string | null = null;
const subscribed = new Map<string, { rate: number; off: () => void }>();

function onStatus(name: string, value: AxisStatus | null, stale: boolean, cycle: number): void {
  const m = statuses.get();
  const prev = m.get(name);
  const lag = value?.following_error ?? 0;
  m.set(name, {
    status: value,
    cycle,
    stale,
    lagMax: prev ? Math.max(prev.lagMax, lag) : lag,
    lagMin: prev ? Math.min(prev.lagMin, lag) : lag,
  });
  statuses.emit();
}

export function resetLagPeak(name: string): void {
  const s = statuses.get().get(name);
  if (!s) return;
  const lag = s.status?.following_error ?? 0;
  s.lagMax = lag;
  s.lagMin = lag;
  statuses.emit();
}

/** Keeps one status subscription per axis; the focused axis (online tab) at a higher rate. */
function syncSubscriptions(): void {
  const names = new Set(axes.get().map((a) => a.config.name));
  for (const [name, sub] of subscribed) {
    if (!names.has(name)) {
      sub.off();
      subscribed.delete(name);
      statuses.get().delete(name);
      statuses.emit();
    }
  }
  for (const name of names) {
    const rate = name === focus ? FOCUS_RATE_HZ : STATUS_RATE_HZ;
    const sub = subscribed.get(name);
    if (sub && sub.rate === rate) continue;
    const off = live.subscribe<AxisStatus>(`axes/${name}/status`, rate, (v, stale, cycle) => onStatus(name, v, stale, cycle));
    subscribed.set(name, { rate, off });
  }
}

export function setFocus(name: string | null): void {
  if (focus === name) return;
  focus = name;
  syncSubscriptions();
}

export async function refreshAxes(): Promise<void> {
  try {
    const list = await get<AxisResource[]>('/axes');
    list.sort((a, b) => a.id - b.id);
    const old = axes.get();
    if (JSON.stringify(old) !== JSON.stringify(list)) axes.set(list);
    axesLoaded.set(true);
    syncSubscriptions();
  } catch {
    /* the connection state shows it */
  }
}

// ---- command log -------------------------------------------------------------------------

const fetchedDetails = new Set<number>();

function entryOf(r: CommandResource): LogEntry {
  const errorId = r.outputs.error_id ?? 0;
  return {
    key: `c${r.id}`,
    id: r.id,
    axis: r.axis,
    command: r.command,
    parameters: r.parameters,
    state: r.state,
    final: r.final,
    errorId,
    errorText: errorId ? errorInfo(errorId).text : null,
    at: r.submitted_at,
    cycle: r.last_cycle,
  };
}

function upsert(e: LogEntry): void {
  const list = commandLog.get();
  const i = list.findIndex((x) => x.key === e.key);
  if (i >= 0) {
    // Never go back to an older state of the same command.
    if (list[i].cycle > e.cycle) return;
    list[i] = { ...list[i], ...e, parameters: e.parameters ?? list[i].parameters, at: list[i].at || e.at };
  } else {
    list.unshift(e);
    list.sort((a, b) => (b.id ?? Infinity) - (a.id ?? Infinity) || b.at.localeCompare(a.at));
    if (list.length > LOG_MAX) list.length = LOG_MAX;
  }
  commandLog.emit();
}

export function logCommand(r: CommandResource): void {
  if (r.command === 'power') notePower(r.axis, r.id, r.parameters);
  upsert(entryOf(r));
}

/** A command the server refused (no command resource exists for it). */
export function logRejected(axis: string, command: string, parameters: unknown, e: unknown): void {
  const p = e instanceof ApiError || e instanceof RpcError ? e.problem : null;
  const errorId = p?.error_id ?? 0;
  const text = p ? `${p.title}: ${p.detail}` : (e as Error).message;
  upsert({
    key: `r${Date.now()}-${Math.random()}`,
    id: null,
    axis,
    command,
    parameters,
    state: 'rejected',
    final: true,
    errorId,
    errorText: text,
    at: new Date().toISOString(),
    cycle: Number.MAX_SAFE_INTEGER,
  });
}

function onCommandEvent(ev: CommandEvent): void {
  const errorId = ev.outputs.error_id ?? 0;
  const list = commandLog.get();
  const known = list.find((x) => x.id === ev.command);
  upsert({
    key: `c${ev.command}`,
    id: ev.command,
    axis: ev.axis,
    command: ev.name,
    parameters: known?.parameters ?? null,
    state: ev.state,
    final: ev.final,
    errorId,
    errorText: errorId ? errorInfo(errorId).text : null,
    at: known?.at ?? new Date().toISOString(),
    cycle: ev.cycle,
  });
  if (ev.name === 'power') notePower(ev.axis, ev.command, known?.parameters ?? null);
  if (!known && !fetchedDetails.has(ev.command)) {
    fetchedDetails.add(ev.command);
    get<CommandResource>(`/commands/${ev.command}`).then(logCommand, () => {});
  }
  if (ev.final) jog.commandFinal(ev.command, ev.state);
}

export async function refreshCommands(): Promise<void> {
  try {
    const list = await get<CommandResource[]>('/commands?limit=100');
    for (const r of list.reverse()) logCommand(r);
  } catch {
    /* shown by the connection state */
  }
}

/** Runs a command over REST, logging the outcome; rethrows the error for the form. */
export async function command(axis: string, name: string, body: Record<string, unknown> = {}): Promise<CommandResource> {
  try {
    const r = await post<CommandResource>(`/axes/${enc(axis)}/${name}`, body);
    logCommand(r);
    return r;
  } catch (e) {
    logRejected(axis, name, body, e);
    throw e;
  }
}

/** Releases a command (DELETE /commands/{id}): unlocks a stop, ends a power or jog. */
export async function releaseCommand(id: number, axis: string): Promise<void> {
  try {
    const r = await del<CommandResource>(`/commands/${id}`);
    logCommand(r);
  } catch (e) {
    logRejected(axis, 'release', { command: id }, e);
    throw e;
  }
}

/**
 * The MC_Stop of this axis that still holds its lock (not final), asked of the server at
 * the moment it is needed: a stop may come from another client or an earlier page. While
 * ramping it is `active`, at standstill `done` but not final until released.
 */
export async function findHeldStop(axis: string): Promise<number | null> {
  for (const state of ['active', 'done'] as const) {
    const list = await get<CommandResource[]>(`/commands?axis=${enc(axis)}&state=${state}&limit=500`);
    const stop = list.find((c) => c.command === 'stop' && !c.final);
    if (stop) return stop.id;
  }
  return null;
}

/**
 * The MC_Power override (percent) in force per axis: that of the axis's newest accepted power
 * command (`percent` null while its parameters are not known yet). The effective override
 * (`status.override_percent`) is this × the MC_SetOverride factor.
 */
export const powerOverrides = new Store<Map<string, { id: number; percent: number | null }>>(new Map());

function notePower(axis: string, id: number, parameters: unknown): void {
  const m = powerOverrides.get();
  const old = m.get(axis);
  if (old && old.id > id) return;
  const v = parameters && typeof parameters === 'object' ? (parameters as { override_percent?: unknown }).override_percent : undefined;
  // The server's default is 100 when the body leaves it out.
  const percent = parameters && typeof parameters === 'object' ? (typeof v === 'number' ? v : 100) : null;
  if (old && old.id === id && (percent === null || old.percent === percent)) return;
  m.set(axis, { id, percent });
  powerOverrides.emit();
}

/** The power override of an axis: 100 (the server's default) when no power command is known. */
export function powerOverride(axis: string): number | null {
  const p = powerOverrides.get().get(axis);
  return p ? p.percent : 100;
}

/** Learns the axis's newest power command (it may be older than the command log's window). */
export async function loadPowerCommand(axis: string): Promise<void> {
  try {
    const list = await get<CommandResource[]>(`/commands?axis=${enc(axis)}&limit=500`);
    const p = list.find((c) => c.command === 'power');
    if (p) notePower(p.axis, p.id, p.parameters);
  } catch {
    /* shown by the connection state */
  }
}

// ---- wiring -----------------------------------------------------------------------------

let started = false;
let pollTimer: ReturnType<typeof setInterval> | null = null;

export function start(): void {
  if (started) return;
  started = true;
  live.on('command_event', onCommandEvent);
  live.on('commands_lagged', () => void refreshCommands());
  // Subscriptions are re-sent by the client on every (re)connection.
  live.subscribe<SystemResource>('system', 1, (v) => {
    if (v) system.set(v);
  });
  live.subscribe('commands', 1, () => {});
  live.onOpen(() => {
    // Command ids start again after a server restart: forget what was learnt before.
    powerOverrides.set(new Map());
    void refreshAxes();
    void refreshCommands();
  });
  live.onClose(() => jog.connectionLost());
  live.start();
  // Axis configurations have no topic: look for other clients' changes now and then.
  pollTimer = setInterval(() => {
    if (live.connected) void refreshAxes();
  }, 5000);
}

export function stop(): void {
  if (pollTimer) clearInterval(pollTimer);
  live.stop();
  started = false;
}
