// Application state: the websocket, the axes, their live status, the command log.
import { LiveClient } from './live/client';
import { JogController } from './live/jog';
import { Store } from './store';
import { ApiError, NotOfferedError, NotSentError } from './api/problem';
import { api } from './api/client';
import { postBlock, type BlockBody, type BlockName, type BlockOptions } from './api/blocks';
import { errorInfo } from './api/errors';
import type { AxisLiveStatus, AxisResource, CommandEvent, CommandResource, PeakResetResource, SystemResource } from './api/types';
import { RpcError } from './live/client';
import { ScopeSession } from './scope/session';
import { cancelRecording, createRecording, getRecording, listRecordings } from './scope/api';
import { TrendBuffer } from './live/trend';
import { releaseWhenDone } from './axis/stop';
import { driveRefusal, isDriveExecuted } from './axis/drive-executed';
import { LiveTrace } from './scope/live';
import { clientId } from './auth/client-id';
import { postGroupBlock, type GroupBlockBody, type GroupBlockName } from './groups/api';

export interface LiveStatus {
  status: AxisLiveStatus | null;
  cycle: number;
  stale: boolean;
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

/** The websocket's URL; `client_id` names this tab as `X-Client-Id` does on REST (auth/client-id.ts). */
export function wsUrl(id: string = clientId()): string {
  const l = typeof location !== 'undefined' ? location : ({ protocol: 'http:', host: '127.0.0.1:8080' } as Location);
  return `${l.protocol === 'https:' ? 'wss:' : 'ws:'}//${l.host}/api/v1/ws?client_id=${encodeURIComponent(id)}`;
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
/**
 * The trace of the armed or running recording, drawn from the status stream until the server's
 * samples are there (scope/live.ts); null while none runs.
 */
export const scopeLive = new Store<LiveTrace | null>(null);

scope.state.subscribe(() => {
  const running = scope.state.get().running;
  const trace = scopeLive.get();
  if (!running) {
    if (trace) scopeLive.set(null);
    return;
  }
  if (trace && trace.id === running.id) {
    trace.update(running);
    return;
  }
  const next = new LiveTrace(running);
  // What the axes stand at now: the trace starts with it, not with the next change.
  for (const [name, l] of statuses.get()) if (l.status && !l.stale) next.push(name, l.status, l.cycle, clock());
  scopeLive.set(next);
});

let focus: string | null = null;
const subscribed = new Map<string, { rate: number; off: () => void }>();

/**
 * The live trend of each axis (set and actual velocity, following error): a fixed-size ring
 * buffer fed by its status subscription, 50 Hz while the axis is on screen.
 */
const trends = new Map<string, TrendBuffer>();

export function trendOf(name: string): TrendBuffer {
  let t = trends.get(name);
  if (!t) trends.set(name, (t = new TrendBuffer()));
  return t;
}

const clock = () => (typeof performance !== 'undefined' ? performance.now() : Date.now());

function onStatus(name: string, value: AxisLiveStatus | null, stale: boolean, cycle: number): void {
  const m = statuses.get();
  m.set(name, { status: value, cycle, stale });
  const trend = trendOf(name);
  if (stale || !value) trend.gap();
  else {
    trend.push(cycle, value.set_velocity, value.actual_velocity, value.following_error, clock());
    scopeLive.get()?.push(name, value, cycle, clock());
  }
  statuses.emit();
}

/**
 * Restarts the server's following-error peak hold of an axis (`following_error_min/max` of
 * its status, kept over every cycle). Not a command: it changes no motion.
 */
export function resetFollowingErrorPeak(axis: string): Promise<PeakResetResource> {
  return api.POST('/api/v1/axes/{axis}/status/following-error-peak/reset', { params: { path: { axis } } });
}

/** Keeps one status subscription per axis; the focused axis (online tab) at a higher rate. */
function syncSubscriptions(): void {
  const names = new Set(axes.get().map((a) => a.config.name));
  for (const [name, sub] of subscribed) {
    if (!names.has(name)) {
      sub.off();
      subscribed.delete(name);
    }
  }
  // Also the values of subscriptions the server ended (axis deleted): no longer an axis.
  let gone = false;
  for (const name of statuses.get().keys()) if (!names.has(name)) gone = statuses.get().delete(name) || gone;
  if (gone) statuses.emit();
  for (const name of trends.keys()) if (!names.has(name)) trends.delete(name);
  for (const name of names) {
    const rate = name === focus ? FOCUS_RATE_HZ : STATUS_RATE_HZ;
    const sub = subscribed.get(name);
    if (sub && sub.rate === rate) continue;
    const entry = { rate, off: () => {} };
    entry.off = live.subscribe<AxisLiveStatus>(
      `axes/${name}/status`,
      rate,
      (v, stale, cycle) => onStatus(name, v, stale, cycle),
      () => subscriptionEnded(name, entry),
    );
    subscribed.set(name, entry);
  }
}

/**
 * The server ended an axis's status subscription: the axis it followed (by id) was deleted or
 * replaced by an import. Its values stay on screen marked stale (the client has said so);
 * the axes are read again and the name subscribed anew if an axis has it now (possibly
 * another axis: its first update is a full object).
 */
function subscriptionEnded(name: string, entry: { rate: number; off: () => void }): void {
  if (subscribed.get(name) === entry) subscribed.delete(name);
  void refreshAxes();
}

export function setFocus(name: string | null): void {
  if (focus === name) return;
  focus = name;
  syncSubscriptions();
}

let axesAsked = 0;
let axesApplied = 0;

export async function refreshAxes(): Promise<void> {
  const n = ++axesAsked;
  try {
    const list = await api.GET('/api/v1/axes');
    // An answer older than one already applied (requests overlap) would bring back the past.
    if (n < axesApplied) return;
    axesApplied = n;
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
    // A group's command addresses no axis: the log names its group.
    axis: r.group ?? r.axis ?? '',
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
    // Newest first by the time it was sent (a refused command has no id but its moment).
    list.sort((a, b) => b.at.localeCompare(a.at) || (b.id ?? 0) - (a.id ?? 0));
    if (list.length > LOG_MAX) list.length = LOG_MAX;
  }
  commandLog.emit();
}

export function logCommand(r: CommandResource): void {
  upsert(entryOf(r));
}

/** A command the server refused (no command resource exists for it). */
export function logRejected(axis: string, command: string, parameters: unknown, e: unknown): void {
  // Never sent (a number field's text is not a number, a block the axis does not offer): nothing the server refused.
  if (e instanceof NotSentError || e instanceof NotOfferedError) return;
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
    axis: ev.group ?? ev.axis,
    command: ev.name,
    parameters: known?.parameters ?? null,
    state: ev.state,
    final: ev.final,
    errorId,
    errorText: errorId ? errorInfo(errorId).text : null,
    at: known?.at ?? new Date().toISOString(),
    cycle: ev.cycle,
  });
  if (!known && !fetchedDetails.has(ev.command)) {
    fetchedDetails.add(ev.command);
    api.GET('/api/v1/commands/{id}', { params: { path: { id: ev.command } } }).then(logCommand, () => {});
  }
  if (ev.final) jog.commandFinal(ev.command, ev.state);
}

export async function refreshCommands(): Promise<void> {
  try {
    const list = await api.GET('/api/v1/commands', { params: { query: { limit: 100 } } });
    for (const r of list.reverse()) logCommand(r);
  } catch {
    /* shown by the connection state */
  }
}

/**
 * Runs block `name` on `axis` over REST (its body checked by tsc against the block's, api/blocks.ts),
 * logging the outcome; rethrows the error for the form. `options.query`: `wait`, `timeout_ms`.
 */
export async function command<N extends BlockName>(axis: string, name: N, body: BlockBody<N>, options?: BlockOptions<N>): Promise<CommandResource> {
  // An axis whose drive runs the profile: a block or input it does not take is never sent
  // (the pages do not offer them; this holds for every way of sending).
  const refusal = driveExecutedAxis(axis) ? driveRefusal(name, body) : null;
  if (refusal) throw new NotOfferedError(refusal.code, refusal.detail, refusal.fields);
  try {
    const r = await postBlock(axis, name, body, options);
    logCommand(r);
    return r;
  } catch (e) {
    logRejected(axis, name, body, e);
    throw e;
  }
}

/** Whether the drive runs axis `axis`'s profile, as its live status (else its configuration) says. */
export function driveExecutedAxis(axis: string): boolean {
  const a = axes.get().find((x) => x.config.name === axis);
  return isDriveExecuted(a?.config, statuses.get().get(axis)?.status);
}

/** Releases a command (DELETE /commands/{id}): unlocks a stop, ends a power or jog. */
export async function releaseCommand(id: number, axis: string): Promise<void> {
  try {
    const r = await api.DELETE('/api/v1/commands/{id}', { params: { path: { id } } });
    logCommand(r);
  } catch (e) {
    logRejected(axis, 'release', { command: id }, e);
    throw e;
  }
}

/**
 * MC_Stop from the Online tab (Stop, F6) as TwinCAT XAE's: sent, then released once the axis
 * stands (axis/stop.ts), so the axis is ready for the next command. Resolves with the stop as
 * sent; `followed` settles when it is released (or ended otherwise).
 */
export async function stopAndRelease(axis: string, body: BlockBody<'stop'>): Promise<{ stop: CommandResource; followed: Promise<'released' | 'ended'> }> {
  const stop = await command(axis, 'stop', body);
  const followed = releaseWhenDone(stop.id, {
    read: (id) => api.GET('/api/v1/commands/{id}', { params: { path: { id } } }),
    watch: (id, on) => {
      const check = () => {
        const e = commandLog.get().find((x) => x.id === id);
        if (e) on(e);
      };
      check();
      return commandLog.subscribe(check);
    },
    release: (id) => releaseCommand(id, axis),
  });
  return { stop, followed };
}

/**
 * The MC_Stop of this axis that still holds its lock (not final), asked of the server at
 * the moment it is needed: a stop may come from another client or an earlier page. While
 * ramping it is `active`, at standstill `done` but not final until released.
 */
export async function findHeldStop(axis: string): Promise<number | null> {
  for (const state of ['active', 'done'] as const) {
    const list = await api.GET('/api/v1/commands', { params: { query: { axis, state, limit: 500 } } });
    const stop = list.find((c) => c.command === 'stop' && !c.final);
    if (stop) return stop.id;
  }
  return null;
}

// ---- axis groups ---------------------------------------------------------------------------

/** Runs group block `name` on `group` over REST (body checked by tsc), logging it as `command` does. */
export async function groupCommand<N extends GroupBlockName>(group: string, name: N, body: GroupBlockBody<N>): Promise<CommandResource> {
  try {
    const r = await postGroupBlock(group, name, body);
    logCommand(r);
    return r;
  } catch (e) {
    logRejected(group, name, body, e);
    throw e;
  }
}

/**
 * MC_GroupStop from the Groups page as the axis page's Stop: sent, then released once the group
 * stands (the stop `done`: axis/stop.ts), so the group is back in standby for the next path.
 */
export async function groupStopAndRelease(group: string, body: GroupBlockBody<'stop'>): Promise<{ stop: CommandResource; followed: Promise<'released' | 'ended'> }> {
  const stop = await groupCommand(group, 'stop', body);
  const followed = releaseWhenDone(stop.id, {
    read: (id) => api.GET('/api/v1/commands/{id}', { params: { path: { id } } }),
    watch: (id, on) => {
      const check = () => {
        const e = commandLog.get().find((x) => x.id === id);
        if (e) on(e);
      };
      check();
      return commandLog.subscribe(check);
    },
    release: (id) => releaseCommand(id, group),
  });
  return { stop, followed };
}

/**
 * The MC_GroupStop of this group that still holds its lock, asked of the server when needed (it
 * may be another client's). `GET /commands` has no group filter: the newest active / done
 * commands are searched for a stop of this group.
 */
export async function findHeldGroupStop(group: string, groupId: number): Promise<number | null> {
  for (const state of ['active', 'done'] as const) {
    const list = await api.GET('/api/v1/commands', { params: { query: { state, limit: 2000 } } });
    const stop = list.find((c) => c.command === 'stop' && !c.final && (c.group === group || c.group_id === groupId));
    if (stop) return stop.id;
  }
  return null;
}

// ---- wiring -----------------------------------------------------------------------------

let started = false;
let wired = false;
let pollTimer: ReturnType<typeof setInterval> | null = null;

/** Connects (again, after a stop: the handlers are installed once). */
export function start(): void {
  if (started) return;
  started = true;
  if (!wired) wire();
  live.start();
  // Axis configurations have no topic: look for other clients' changes now and then.
  pollTimer = setInterval(() => {
    if (live.connected) void refreshAxes();
  }, 5000);
}

function wire(): void {
  wired = true;
  live.on('command_event', onCommandEvent);
  live.on('commands_lagged', () => void refreshCommands());
  // Subscriptions are re-sent by the client on every (re)connection.
  live.subscribe<SystemResource>('system', 1, (v) => {
    if (v) {
      system.set(v);
      scopeLive.get()?.tick(v.cycle, clock());
    }
  });
  live.subscribe('commands', 1, () => {});
  live.onOpen(() => {
    void refreshAxes();
    void refreshCommands();
  });
  live.onClose(() => jog.connectionLost());
}

/** Disconnects (logged out: nothing may be read until the next login). */
export function stop(): void {
  if (pollTimer) clearInterval(pollTimer);
  pollTimer = null;
  if (started) live.stop();
  started = false;
}
