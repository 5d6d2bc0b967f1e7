// Axis groups (TwinCAT TF5420 CM group): the list with each group's state, a form to create a
// group (and to edit or delete a disabled one), and for the selected group its online panel
// (state with the error's text, enable / disable / reset, override, halt, stop with its release,
// blocker and release), the path editor whose rows are MC_MovePath's entries (run with
// `move-path`; the server's 422 lands at the row and field it names), the XY (XZ, YZ) view and
// the charts of the plan: every edit of the rows is planned by the server (`POST
// /path-analysis`, debounced; its refusals land at their row and field too) and drawn — the
// planned trace with its blends over the programmed geometry (groups/geometry.ts), the path
// velocity and every axis's velocity and acceleration over time — and while the path runs, the
// live trace (the members' actual positions) and path velocity over the plan, from the group's websocket topic
// `groups/{group}/status`.
import { useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { api } from '../../api/client';
import { errorInfo } from '../../api/errors';
import type { GroupResource, GroupRole, GroupState, GroupStatus, PathAnalysisBody, PathAnalysisResource } from '../../api/types';
import { LiveAnalysis } from '../../cams/analysis';
import { PlanChart } from '../../groups/chart';
import { LiveRun, analysisBody, planText, plannedTrace } from '../../groups/plan';
import { bodyOf, CONVENTIONS, draftOf, draftRoles, DYNAMICS, memberError, memberField, newDraft, type GroupDraft } from '../../groups/config';
import { PATH_DIMS, preview, type Preview } from '../../groups/geometry';
import {
  BUFFER_MODES,
  CIRC_MODES,
  ENTRY_TYPES,
  PATH_CHOICES,
  TRANSITION_MODES,
  blendCorners,
  exactStops,
  fitRow,
  groupRoles,
  moveRow,
  movePathBody,
  newRow,
  previewEntry,
  roleDim,
  rowErrors,
  type EntryType,
  type PathRow,
} from '../../groups/rows';
import { TraceBuffer, XY, XZ, YZ, drawView, type Plane, type ViewData } from '../../groups/view';
import { navigate } from '../../router';
import { axes, findHeldGroupStop, groupCommand, groupStopAndRelease, live, releaseCommand, system } from '../../services';
import { useStore } from '../../store';
import { num } from '../../format';
import { ActionButton, ErrorBanner, Field, NumberInput, Panel, errorText, fieldsOf, useOnline } from '../shared/common';
import { CommandLog } from '../shared/command-log';

export const GROUP_STATE_LABEL: Record<GroupState, string> = {
  disabled: 'Disabled',
  not_ready: 'NotReady',
  standby: 'Standby',
  moving: 'Moving',
  stopping: 'Stopping',
  error_stop: 'ErrorStop',
};

function groupLamp(s: GroupStatus | null | undefined): string {
  if (!s) return 'lamp-off';
  if (s.state === 'error_stop' || s.error_id) return 'lamp-red';
  switch (s.state) {
    case 'standby':
      return 'lamp-green';
    case 'moving':
      return 'lamp-blue';
    case 'stopping':
    case 'not_ready':
      return 'lamp-amber';
    default:
      return 'lamp-off';
  }
}

function GroupLamp({ status, label = true }: { status: GroupStatus | null | undefined; label?: boolean }) {
  const text = status ? GROUP_STATE_LABEL[status.state] : 'unknown';
  return (
    <span class="lamp-wrap" data-group-state={status?.state ?? 'unknown'} title={text}>
      <span class={`lamp ${groupLamp(status)}`} />
      {label && <span class="lamp-label">{text}</span>}
    </span>
  );
}

/** The state with GroupErrorDisabled told apart (error_stop without the enable request). */
function stateText(s: GroupStatus): string {
  if (s.state === 'error_stop' && !s.enable_requested) return 'ErrorStop (disabled)';
  return GROUP_STATE_LABEL[s.state];
}

/** The live status updates of a group per second (the websocket's topic; at most 100). */
const GROUP_RATE_HZ = 50;

/**
 * A group's status from its websocket topic `groups/{group}/status` (kept across reconnections;
 * stale while the socket is down); `on` sees every update.
 */
function useGroupStatus(group: string, on?: (s: GroupStatus) => void): { status: GroupStatus | null; stale: boolean } {
  const [status, setStatus] = useState<GroupStatus | null>(null);
  const [stale, setStale] = useState(false);
  const onRef = useRef(on);
  onRef.current = on;
  useEffect(
    () =>
      live.subscribe<GroupStatus>(`groups/${group}/status`, GROUP_RATE_HZ, (v, isStale) => {
        setStale(isStale);
        if (!v) return;
        setStatus(v);
        if (!isStale) onRef.current?.(v);
      }),
    [group],
  );
  return { status, stale };
}

/** The path point of a status's positions (role → value), other dims 0. */
function pointOf(position: Record<string, number> | undefined): number[] {
  const p = new Array<number>(PATH_DIMS).fill(0);
  for (const [role, v] of Object.entries(position ?? {})) {
    const d = roleDim(role as GroupRole);
    if (d >= 0) p[d] = v;
  }
  return p;
}

// ---- the page --------------------------------------------------------------------------------

export function GroupsPage({ group }: { group: string | null }) {
  const [list, setList] = useState<GroupResource[] | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [creating, setCreating] = useState(false);
  const load = () => api.GET('/api/v1/groups').then(setList, (e) => setError(errorText(e)));
  useEffect(() => {
    void load();
    const t = setInterval(() => document.visibilityState === 'visible' && void load(), 1000);
    return () => clearInterval(t);
  }, []);
  const selected = group === null ? null : (list?.find((g) => g.name === group || String(g.id) === group) ?? null);
  return (
    <div class="page" id="groups">
      <div class="page-head">
        <h2>Axis groups</h2>
        <span class="muted small">TF5420 coordinated motion: lines, arcs, blended corners</span>
      </div>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <Panel
        title="Groups"
        actions={
          <button type="button" class="btn btn-small" name="new-group" onClick={() => setCreating(!creating)}>
            {creating ? 'Close' : '+ New group'}
          </button>
        }
      >
        {list === null ? (
          <p class="muted">Loading…</p>
        ) : list.length === 0 ? (
          <p class="muted">No groups yet.</p>
        ) : (
          <div class="table-scroll">
            <table class="grid group-list">
              <thead>
                <tr>
                  <th>Id</th>
                  <th>Name</th>
                  <th>State</th>
                  <th>Convention</th>
                  <th>Axes</th>
                  <th class="r">Override</th>
                  <th class="r">Path velocity</th>
                </tr>
              </thead>
              <tbody>
                {list.map((g) => (
                  <tr key={g.id} data-group={g.name} class={selected?.id === g.id ? 'selected' : ''}>
                    <td>{g.id}</td>
                    <td>
                      <a href={`#/groups/${encodeURIComponent(g.name)}`}>{g.name}</a>
                    </td>
                    <td>
                      <GroupLamp status={g.status} />
                    </td>
                    <td>{g.convention.toUpperCase()}{g.additional_axes ? ` + ${g.additional_axes}` : ''}</td>
                    <td class="mono small">{g.axes.map((m) => `${m.role}=${m.axis}`).join(' ') || '—'}</td>
                    <td class="num">{g.status ? `${num(g.status.actual_override * 100, 0)} %` : '—'}</td>
                    <td class="num">{num(g.status?.path_velocity, 2)}</td>
                  </tr>
                ))}
              </tbody>
            </table>
          </div>
        )}
      </Panel>
      {creating && (
        <Panel title="New group">
          <GroupForm
            group={null}
            onSaved={(g) => {
              setCreating(false);
              void load();
              navigate({ page: 'group', group: g.name });
            }}
          />
        </Panel>
      )}
      {group !== null && list !== null && !selected && <p class="muted">No group “{group}”.</p>}
      {selected && <GroupView key={selected.id} group={selected} onChanged={load} />}
    </div>
  );
}

// ---- the configuration form ----------------------------------------------------------------

function GroupForm({ group, onSaved, onDeleted }: { group: GroupResource | null; onSaved: (g: GroupResource) => void; onDeleted?: () => void }) {
  const axisList = useStore(axes);
  const names = axisList.map((a) => a.config.name);
  const [d, setD] = useState<GroupDraft>(() => (group ? draftOf(group) : newDraft(names)));
  const [fields, setFields] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const [saved, setSaved] = useState(false);
  const [confirmDelete, setConfirmDelete] = useState(false);
  const online = useOnline();
  const editable = !group || !group.status || group.status.state === 'disabled';
  const set = (p: Partial<GroupDraft>) => {
    setD({ ...d, ...p });
    setSaved(false);
  };
  const save = async () => {
    setError(null);
    setFields({});
    try {
      const body = bodyOf(d);
      const g = group
        ? await api.PUT('/api/v1/groups/{group}', { params: { path: { group: String(group.id) } }, body })
        : await api.POST('/api/v1/groups', { body });
      setSaved(true);
      onSaved(g);
    } catch (e) {
      setFields(fieldsOf(e));
      setError(errorText(e));
      throw e;
    }
  };
  const remove = async () => {
    if (!group) return;
    try {
      await api.DELETE('/api/v1/groups/{group}', { params: { path: { group: String(group.id) } } });
      onDeleted?.();
    } catch (e) {
      setError(errorText(e));
    }
  };
  const roles = draftRoles(d);
  const dyn = (which: 'defaults' | 'maximum', path: string) =>
    DYNAMICS.map((k) => (
      <Field key={k} label={k} name={`${path}.${k}`} error={fields[`${path}.${k}`]}>
        <NumberInput name={`${path}.${k}`} value={d[which][k]} onValue={(v) => set({ [which]: { ...d[which], [k]: v } })} />
      </Field>
    ));
  return (
    <form
      class="group-form"
      onSubmit={(e) => {
        e.preventDefault();
        void save().catch(() => {});
      }}
    >
      {!editable && <p class="banner banner-info">The group is enabled: disable it to change or delete its configuration.</p>}
      <fieldset disabled={!editable} class="plain-fieldset">
        <div class="form-grid">
          <Field label="Name" name="name" error={fields.name}>
            <input type="text" name="name" value={d.name} onInput={(e) => set({ name: (e.target as HTMLInputElement).value })} />
          </Field>
          <Field label="Axes convention" name="convention" error={fields.convention}>
            <select name="convention" value={d.convention} onChange={(e) => set({ convention: (e.target as HTMLSelectElement).value as GroupDraft['convention'] })}>
              {CONVENTIONS.map(([v, l]) => (
                <option key={v} value={v}>
                  {l}
                </option>
              ))}
            </select>
          </Field>
          <Field label="Additional axes (0–8)" name="additional_axes" error={fields.additional_axes}>
            <NumberInput name="additional_axes" value={d.additional} onValue={(v) => set({ additional: v })} />
          </Field>
          <Field label="Override ramp time (s)" name="override_ramp_time" error={fields.override_ramp_time}>
            <NumberInput name="override_ramp_time" value={d.rampTime} onValue={(v) => set({ rampTime: v })} />
          </Field>
        </div>
        <h4 class="form-sub">Axes by role</h4>
        <div class="form-grid">
          {roles.map((r) => (
            <Field key={r} label={r.toUpperCase()} name={memberField(d, r)} error={memberError(d, r, fields)}>
              <select name={memberField(d, r)} data-role={r} value={d.axes[r] ?? ''} onChange={(e) => set({ axes: { ...d.axes, [r]: (e.target as HTMLSelectElement).value } })}>
                <option value="">— none —</option>
                {names.map((n) => (
                  <option key={n} value={n}>
                    {n}
                  </option>
                ))}
              </select>
            </Field>
          ))}
        </div>
        {fields.axes && <p class="field-error">{fields.axes}</p>}
        <h4 class="form-sub">Default dynamics (“default”)</h4>
        <div class="form-grid">{dyn('defaults', 'default_dynamics')}</div>
        <h4 class="form-sub">Maximum dynamics (“maximum”, the cap)</h4>
        <div class="form-grid">{dyn('maximum', 'maximum_dynamics')}</div>
        <div class="form-actions">
          <ActionButton kind="primary" name="save-group" onClick={save} disabled={!online || !d.name.trim()}>
            {group ? 'Save' : 'Create'}
          </ActionButton>
          {saved && <span class="ok-text">saved</span>}
          {group &&
            (confirmDelete ? (
              <span class="confirm">
                Delete group {group.name}?
                <ActionButton kind="danger" name="confirm-delete-group" onClick={remove} disabled={!online}>
                  Delete
                </ActionButton>
                <button type="button" class="btn" onClick={() => setConfirmDelete(false)}>
                  Cancel
                </button>
              </span>
            ) : (
              <button type="button" class="btn btn-danger-outline" name="delete-group" disabled={!online || !editable} onClick={() => setConfirmDelete(true)}>
                Delete…
              </button>
            ))}
        </div>
      </fieldset>
      {error && <p class="banner banner-error form-error" role="alert">{error}</p>}
    </form>
  );
}

// ---- one group --------------------------------------------------------------------------------

/** The path editor's rows of each group, kept while the page is left (by group id). */
const savedRows = new Map<number, PathRow[]>();

function starterRows(axes: number): PathRow[] {
  // The README tour's shape: a line, a quarter arc about a centre, a line.
  const a = newRow(axes);
  a.position = ['100', '0', ...a.position.slice(2)];
  a.velocity = '200';
  const b = newRow(axes, a, 'circular');
  b.circMode = 'center';
  b.aux = ['100', '50', '0'];
  b.position = ['150', '50', ...b.position.slice(2)];
  const c = newRow(axes, b);
  c.position = ['150', '150', ...c.position.slice(2)];
  return [a, b, c];
}

function GroupView({ group, onChanged }: { group: GroupResource; onChanged: () => void }) {
  const roles = useMemo(() => groupRoles(group.convention, group.additional_axes), [group.convention, group.additional_axes]);
  const dims = useMemo(() => roles.map(roleDim), [roles]);
  const online = useOnline();
  const axisList = useStore(axes);
  // The unit of the charts: the members' (when they all have one unit).
  const units = new Set(group.axes.map((m) => axisList.find((a) => a.config.name === m.axis)?.config.unit ?? ''));
  const axisUnit = units.size === 1 ? [...units][0] : '';
  const [error, setError] = useState<string | null>(null);
  const trace = useRef(new TraceBuffer());
  const liveRun = useRef(new LiveRun());
  const [, setLiveTick] = useState(0);
  const { status, stale } = useGroupStatus(group.name, (s) => {
    if (s.state === 'moving' || s.state === 'stopping') {
      // The members' actual positions (their drives' feedback), of the status's cycle.
      trace.current.push(pointOf({ ...s.position, ...s.actual_position }));
      liveRun.current.push(s.cycle, s.path_velocity);
      setLiveTick((n) => n + 1);
    }
  });
  const s = status ?? group.status ?? null;

  const run = async (name: 'enable' | 'disable' | 'reset' | 'halt', body: object = {}) => {
    setError(null);
    try {
      await groupCommand(group.name, name, body as never);
      onChanged();
    } catch (e) {
      setError(errorText(e));
    }
  };
  const stop = async () => {
    setError(null);
    try {
      const { followed } = await groupStopAndRelease(group.name, {});
      followed.catch((e) => setError(`the stop was not released at standstill: ${errorText(e)}`));
    } catch (e) {
      setError(errorText(e));
    }
  };
  const releaseStop = async () => {
    setError(null);
    try {
      const id = await findHeldGroupStop(group.name, group.id);
      if (id === null) throw new Error('the server knows no MC_GroupStop of this group that holds the lock');
      await releaseCommand(id, group.name);
    } catch (e) {
      setError(errorText(e));
    }
  };
  const releaseBlocker = async () => {
    if (!s?.blocker_id) return;
    setError(null);
    try {
      await groupCommand(group.name, 'release-blocker', { blocker_id: s.blocker_id });
    } catch (e) {
      setError(errorText(e));
    }
  };

  const moving = s?.state === 'moving' || s?.state === 'stopping';

  // ---- the path editor
  const [rows, setRowsState] = useState<PathRow[]>(() => (savedRows.get(group.id) ?? starterRows(roles.length)).map((r) => fitRow(r, roles.length)));
  const setRows = (r: PathRow[]) => {
    savedRows.set(group.id, r);
    setRowsState(r);
    // Edited rows are a new path: it would start where the group is now (the last run's traces go).
    if (!moving) {
      setRunStart(null);
      trace.current.clear();
      liveRun.current.clear();
    }
  };
  const [pathFields, setPathFields] = useState<Record<string, string>>({});
  const [pathError, setPathError] = useState<string | null>(null);
  const [radius, setRadius] = useState('5');
  const [selectedRow, setSelectedRow] = useState(-1);
  const [runCommand, setRunCommand] = useState<number | null>(null);
  /** Where the path starts: the group's position when the rows were last run, else now. */
  const [runStart, setRunStart] = useState<number[] | null>(null);
  const editRow = (i: number, p: Partial<PathRow>) => {
    setRows(rows.map((r, j) => (j === i ? { ...r, ...p } : r)));
  };
  const addRow = (type: EntryType) => setRows([...rows, newRow(roles.length, rows[rows.length - 1], type)]);
  const runPath = async () => {
    setPathError(null);
    setPathFields({});
    try {
      const start = pointOf(s?.position);
      const cycle = s?.cycle ?? 0;
      const r = await groupCommand(group.name, 'move-path', movePathBody(rows));
      trace.current.clear();
      trace.current.push(start);
      liveRun.current.begin(cycle, plan?.cycle_time ?? system.get()?.cycle_time ?? 0.001);
      setRunStart(start);
      setRunCommand(r.id);
    } catch (e) {
      setPathFields(fieldsOf(e));
      setPathError(errorText(e));
    }
  };

  // The path just run is drawn from where it started (with its trace) until the rows are edited.
  const start = runStart ?? pointOf(s?.position);
  const pv: Preview = useMemo(() => preview(rows.map(previewEntry), start, dims, group.convention === 'xy'), [rows, start.join(','), dims, group.convention]);
  const activeEntry = moving && s?.command === runCommand ? (s?.entry_index ?? -1) : -1;

  // ---- the server's plan of the rows (from where the path starts), redone on every edit
  const [plan, setPlan] = useState<PathAnalysisResource | null>(null);
  const [planFields, setPlanFields] = useState<Record<string, string>>({});
  const [planError, setPlanError] = useState<string | null>(null);
  const [planPending, setPlanPending] = useState(false);
  const analysis = useMemo(
    () =>
      new LiveAnalysis<PathAnalysisBody, PathAnalysisResource>(
        (body) => api.POST('/api/v1/path-analysis', { body }),
        (a) => {
          if (a.kind === 'ok') {
            setPlan(a.result);
            setPlanFields({});
            setPlanError(null);
          } else {
            setPlan(null);
            setPlanFields(a.kind === 'invalid' ? a.fields : {});
            setPlanError(a.text);
          }
        },
        setPlanPending,
        { delay: 300, maxWait: 900 },
      ),
    [group.name],
  );
  useEffect(() => () => analysis.dispose(), [analysis]);
  // While the group moves the start stays where it is (a run's plan is not redone each update).
  const haveStart = runStart !== null || s !== null;
  const startKey = haveStart && !(moving && runStart === null) ? roles.map((r) => start[roleDim(r)].toFixed(6)).join(',') : 'none';
  useEffect(() => {
    if (rows.length === 0) {
      analysis.cancel();
      setPlan(null);
      setPlanFields({});
      setPlanError(null);
      setPlanPending(false);
      return;
    }
    analysis.schedule(analysisBody(group.name, rows, roles, startKey === 'none' ? null : start));
  }, [rows, startKey, analysis]);
  const planned = useMemo(() => (plan ? plannedTrace(plan) : null), [plan]);
  const view: ViewData = { preview: pv, plan: planned, trace: trace.current.points, now: s ? pointOf(s.position) : null, activeEntry, selectedEntry: selectedRow, dim: stale || planPending };
  const rowFields = { ...planFields, ...pathFields };

  const errorId = s?.error_id ?? 0;
  const err = errorId ? errorInfo(errorId) : null;
  return (
    <>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <div class="group-grid">
        <Panel title={<>Group {group.name}</>} class="group-online" actions={<span class={`live-ind live-${stale ? 'stale' : status ? 'live' : 'off'}`} data-live={stale ? 'stale' : status ? 'live' : 'off'} title={`the group's status over the websocket (groups/${group.name}/status, ${GROUP_RATE_HZ} Hz)`}><span class="live-dot" />{stale ? 'stale' : status ? 'live' : 'waiting'}</span>}>
          <div class="group-state-row">
            <GroupLamp status={s} label={false} />
            <b class="group-state" data-testid="group-state">{s ? stateText(s) : '—'}</b>
            <span class="muted small">{group.convention.toUpperCase()} · {group.axes.map((m) => `${m.role}=${m.axis}`).join(' ')}</span>
          </div>
          {err && (
            <div class="banner axis-error group-error" role="alert" data-testid="group-error">
              <span>
                <b>{err.hex}</b> {err.code}: {err.text}
              </span>
            </div>
          )}
          <div class="row group-buttons">
            <ActionButton name="group-enable" kind="primary" disabled={!online} title="MC_GroupEnable: standby once every member is powered" onClick={() => run('enable')}>
              Enable
            </ActionButton>
            <ActionButton name="group-disable" disabled={!online} title="MC_GroupDisable: disabled at once (a moving group stops abruptly: halt or stop first)" onClick={() => run('disable')}>
              Disable
            </ActionButton>
            <ActionButton name="group-reset" kind="warn" disabled={!online} title="MC_GroupReset: clear the errors of the group and its axes" onClick={() => run('reset')}>
              Reset
            </ActionButton>
            <span class="spacer" />
            <ActionButton name="group-halt" disabled={!online} title="MC_GroupHalt: stop on the path, flush the queue" onClick={() => run('halt')}>
              Halt
            </ActionButton>
            <ActionButton name="group-stop" kind="danger" disabled={!online} title="MC_GroupStop: stop on the path; the UI releases it once the group stands. A stop sent over the API keeps its lock until released." onClick={stop}>
              Stop
            </ActionButton>
            {s?.state === 'stopping' && (
              <ActionButton name="group-release-stop" kind="warn" disabled={!online} title="Release the MC_GroupStop that holds the group (falling edge of Execute)" onClick={releaseStop}>
                Release stop
              </ActionButton>
            )}
          </div>
          <GroupOverride group={group.name} factor={s?.override_factor ?? null} actual={s?.actual_override ?? null} online={online} onError={setError} />
          <div class={`blocker-row ${s?.blocked ? 'blocked' : ''}`} data-blocked={s?.blocked ? '1' : '0'}>
            {s?.blocked ? (
              <>
                <span class="tag tag-amber">blocked</span> at blocker <b class="mono" data-testid="blocker-id">{s.blocker_id}</b>
                <ActionButton name="release-blocker" kind="primary" disabled={!online} title="MC_ReleaseBlocker: let the path go on" onClick={releaseBlocker}>
                  Release
                </ActionButton>
              </>
            ) : (
              <span class="muted small">not blocked</span>
            )}
          </div>
          <div class="dro group-dro">
            <Readout name="path_velocity" label="Path velocity" value={num(s?.path_velocity, 2)} unit={`${axisUnit}/s`} />
            <Readout name="entry" label="Entry / invoke id" value={s && s.queued_entries > 0 ? `${s.entry_index + 1} / ${s.invoke_id}` : '—'} />
            <Readout name="remaining_distance" label="Remaining distance" value={num(s?.remaining_distance, 3)} />
            <Readout name="path_position" label="Path position" value={num(s?.path_position, 3)} />
            {roles.map((r) => (
              <Readout key={r} name={`pos-${r}`} label={`${r.toUpperCase()} (${s?.members?.[r] ?? '—'})`} value={num(s?.position?.[r], 3)} />
            ))}
          </div>
          {s?.tracking && (
            // MC_TrackConveyorBelt (REST / websocket): which conveyor, whether in sync.
            <div class="group-tracking small" data-testid="group-tracking" data-in-sync={s.tracking.in_sync ? '1' : '0'}>
              tracking conveyor <b>{s.tracking.conveyor}</b> ·{' '}
              {s.tracking.in_sync ? 'in sync' : `synchronising (${num(s.tracking.remaining_distance_to_sync, 3)} to go)`}
              {s.tracking.conveyor_error && <span class="field-error"> · conveyor in error</span>}
            </div>
          )}
        </Panel>
        <Panel
          title="Path view"
          class="group-view"
          actions={
            <span class="view-legend small">
              <span class="key key-plan">planned</span>
              <span class="key key-blend">blend</span>
              <span class="key key-programmed">programmed</span>
              <span class="key key-trace" title="the member axes' actual positions while the path runs">live trace (actual)</span>
            </span>
          }
        >
          <div class={`view-planes ${group.convention !== 'xy' ? 'view-planes-3d' : ''}`}>
            <PathCanvas data={view} plane={XY} />
            {group.convention !== 'xy' && <PathCanvas data={view} plane={XZ} />}
            {group.convention !== 'xy' && <PathCanvas data={view} plane={YZ} />}
          </div>
          <p class="small view-note" data-testid="plan-summary" data-state={planPending ? 'pending' : plan ? 'ok' : planError ? 'refused' : 'none'} data-length={plan?.length ?? ''} data-duration={plan?.duration ?? ''}>
            {plan ? (
              <>
                <b>{planText(plan)}</b> <span class="muted">(at 100 % override, blockers released at once)</span>
              </>
            ) : planError ? <span class="text-error">not planned: {planError}</span> : <span class="muted">{rows.length ? 'planning…' : 'no rows to plan'}</span>}
            {planPending && plan && <span class="muted"> · planning the edit…</span>}
          </p>
          <p class="muted small view-note" data-testid="preview-length">
            {pv.segments.length} segments, programmed length {num(pv.length, 2)}
            {pv.errors.length > 0 && <span class="text-error"> · row {pv.errors.map((e) => `${e.entry + 1}: ${e.text}`).join('; ')}</span>}
          </p>
        </Panel>
      </div>

      <Panel title="Planned dynamics" class="plan-panel" actions={<span class="muted small">the server's plan of the rows over time · blends shaded · each row's start marked</span>}>
        <PlanCharts plan={plan} roles={roles} unit={axisUnit} live={liveRun.current} />
      </Panel>

      <Panel
        title="Path (MC_MovePath)"
        class="path-panel"
        actions={
          <ActionButton name="run-path" kind="primary" disabled={!online || rows.length === 0} title="MC_MovePath with these rows (the server checks every field)" onClick={runPath}>
            Run
          </ActionButton>
        }
      >
        <div class="toolbar path-toolbar">
          {ENTRY_TYPES.map((t) => (
            <button key={t} type="button" class="btn btn-small" name={`add-${t}`} onClick={() => addRow(t)}>
              + {t}
            </button>
          ))}
          <span class="spacer" />
          <label class="inline small">
            corner radius
            <input type="text" class="num radius-input" name="blend-radius" value={radius} onInput={(e) => setRadius((e.target as HTMLInputElement).value)} />
          </label>
          <button type="button" class="btn btn-small" name="blend-corners" title="Every row after the first: blending_previous + corner_distance with this radius" onClick={() => setRows(blendCorners(rows, radius))}>
            Blend corners
          </button>
          <button type="button" class="btn btn-small" name="exact-stops" title="Every row after the first: buffered / none (stop at each corner)" onClick={() => setRows(exactStops(rows))}>
            Exact stops
          </button>
          <button type="button" class="btn btn-small btn-danger-outline" name="clear-rows" onClick={() => setRows([])}>
            Clear
          </button>
        </div>
        {pathError && (
          <p class="banner banner-error" role="alert" data-testid="path-error">
            {pathError}
          </p>
        )}
        {(pathFields.entries ?? planFields.entries) && <p class="field-error">{pathFields.entries ?? planFields.entries}</p>}
        <div class="table-scroll">
          <table class="grid path-table">
            <thead>
              <tr>
                <th>#</th>
                <th>Type</th>
                <th>Target ({roles.join(', ')})</th>
                <th>Circle</th>
                <th>Velocity</th>
                <th>Buffer / transition</th>
                <th>Invoke id</th>
                <th />
              </tr>
            </thead>
            <tbody>
              {rows.map((r, i) => (
                <PathRowView
                  key={r.key}
                  row={r}
                  index={i}
                  count={rows.length}
                  roles={roles}
                  errors={rowErrors(rowFields, i)}
                  selected={selectedRow === i}
                  active={activeEntry === i}
                  onSelect={() => setSelectedRow(i)}
                  onEdit={(p) => editRow(i, p)}
                  onMove={(by) => setRows(moveRow(rows, i, by))}
                  onRemove={() => setRows(rows.filter((_, j) => j !== i))}
                />
              ))}
            </tbody>
          </table>
        </div>
        {rows.length === 0 && <p class="muted">No rows: add a linear or circular entry.</p>}
      </Panel>

      <details class="panel group-config">
        <summary class="panel-head">Configuration of {group.name}</summary>
        <div class="panel-body">
          <GroupForm
            group={group}
            onSaved={(g) => {
              onChanged();
              if (g.name !== group.name) navigate({ page: 'group', group: g.name });
            }}
            onDeleted={() => {
              onChanged();
              navigate({ page: 'groups' });
            }}
          />
        </div>
      </details>
      <Panel title="Commands of this group">
        <CommandLog axis={group.name} limit={15} />
      </Panel>
    </>
  );
}

/** The charts of the plan (groups/chart.ts): made once per group, fed the plan and the live run. */
function PlanCharts({ plan, roles, unit, live: run }: { plan: PathAnalysisResource | null; roles: GroupRole[]; unit: string; live: LiveRun }) {
  const ref = useRef<HTMLDivElement>(null);
  const chart = useRef<PlanChart | null>(null);
  useEffect(() => {
    if (!ref.current) return;
    chart.current = new PlanChart(ref.current, roles, unit);
    return () => {
      chart.current?.destroy();
      chart.current = null;
    };
  }, [roles.join(','), unit]);
  useEffect(() => chart.current?.setPlan(plan), [plan, roles.join(','), unit]);
  useEffect(() => chart.current?.setLive(run.t, run.v), [run.t.length, run.running]);
  return <div ref={ref} class="plan-chart" data-testid="plan-chart" />;
}

function Readout({ name, label, value, unit }: { name: string; label: string; value: string; unit?: string }) {
  return (
    <div class="dro-row" data-readout={name}>
      <span class="dro-label">{label}</span>
      <span class="dro-value mono">{value}</span>
      <span class="dro-unit">{unit ?? ''}</span>
    </div>
  );
}

/** The canvas of one plane, redrawn with its data and when its box changes size. */
function PathCanvas({ data, plane }: { data: ViewData; plane: Plane }) {
  const ref = useRef<HTMLCanvasElement>(null);
  const dataRef = useRef(data);
  dataRef.current = data;
  const draw = () => {
    const c = ref.current;
    if (!c) return;
    const w = c.clientWidth;
    const h = c.clientHeight;
    const dpr = window.devicePixelRatio || 1;
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    const ctx = c.getContext('2d');
    if (!ctx) return;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    drawView(ctx, w, h, dataRef.current, plane);
  };
  useEffect(draw);
  useEffect(() => {
    const c = ref.current;
    if (!c || typeof ResizeObserver === 'undefined') return;
    const ro = new ResizeObserver(draw);
    ro.observe(c);
    return () => ro.disconnect();
  }, []);
  return (
    <figure class="path-plane">
      <canvas ref={ref} class="path-canvas" data-plane={plane.name} data-trace={data.trace.length} data-segments={data.preview?.segments.length ?? 0} data-plan={data.plan?.points.length ?? 0} />
      <figcaption class="small muted">{plane.hLabel}{plane.vLabel} plane</figcaption>
    </figure>
  );
}

/** One row of the path editor: its inputs named by their JSON paths (`entries[i].…`). */
function PathRowView({ row: r, index: i, count, roles, errors, selected, active, onSelect, onEdit, onMove, onRemove }: {
  row: PathRow;
  index: number;
  count: number;
  roles: GroupRole[];
  errors: Record<string, string>;
  selected: boolean;
  active: boolean;
  onSelect: () => void;
  onEdit: (p: Partial<PathRow>) => void;
  onMove: (by: number) => void;
  onRemove: () => void;
}) {
  const path = (f: string) => `entries[${i}].${f}`;
  const moves = r.type === 'linear' || r.type === 'circular';
  const vec = r.type === 'circular' ? 'end_point' : 'position';
  const vecError = errors[vec] ?? roles.map((_, j) => errors[`${vec}[${j}]`]).filter(Boolean).join('; ');
  const auxError = errors.aux_point ?? [0, 1, 2].map((j) => errors[`aux_point[${j}]`]).filter(Boolean).join('; ');
  const tpError = errors.transition_parameters ?? [0, 1].map((j) => errors[`transition_parameters[${j}]`]).filter(Boolean).join('; ');
  const text = (name: string, value: string, on: (v: string) => void, cls = '', placeholder = '') => (
    <input
      type="text"
      class={`num ${cls} ${errors[name] ? 'num-invalid' : ''}`}
      name={path(name)}
      value={value}
      placeholder={placeholder}
      aria-invalid={errors[name] ? 'true' : undefined}
      onInput={(e) => on((e.target as HTMLInputElement).value)}
    />
  );
  const err = (m: string | undefined) => (m ? <span class="field-error" role="alert">{m}</span> : null);
  const other = Object.entries(errors).filter(([k]) => !/^(position|end_point|aux_point|transition_parameters)(\[\d+\])?$/.test(k) && !['type', 'circ_mode', 'path_choice', 'velocity', 'acceleration', 'deceleration', 'jerk', 'buffer_mode', 'transition_mode', 'blocker_id', 'time', 'invoke_id'].includes(k));
  return (
    <tr class={`path-row ${selected ? 'selected' : ''} ${active ? 'active' : ''} ${Object.keys(errors).length ? 'row-error' : ''}`} data-row={i} onFocusIn={onSelect} onClick={onSelect}>
      <td class="mono">{i + 1}</td>
      <td>
        <select name={path('type')} value={r.type} onChange={(e) => onEdit({ type: (e.target as HTMLSelectElement).value as EntryType })}>
          {ENTRY_TYPES.map((t) => (
            <option key={t} value={t}>
              {t}
            </option>
          ))}
        </select>
        {err(errors.type)}
      </td>
      <td>
        {moves ? (
          <>
            <div class="vec">
              {roles.map((role, j) => (
                <label key={role} class="vec-cell">
                  <span class="vec-label">{role}</span>
                  {text(`${vec}[${j}]`, r.position[j] ?? '', (v) => onEdit({ position: r.position.map((x, k) => (k === j ? v : x)) }), errors[vec] ? 'num-invalid' : '')}
                </label>
              ))}
            </div>
            {err(vecError || undefined)}
          </>
        ) : r.type === 'blocker' ? (
          <label class="vec-cell">
            <span class="vec-label">blocker id</span>
            {text('blocker_id', r.blockerId, (v) => onEdit({ blockerId: v }))}
            {err(errors.blocker_id)}
          </label>
        ) : (
          <label class="vec-cell">
            <span class="vec-label">time (s)</span>
            {text('time', r.time, (v) => onEdit({ time: v }))}
            {err(errors.time)}
          </label>
        )}
      </td>
      <td>
        {r.type === 'circular' ? (
          <>
            <div class="vec">
              <select name={path('circ_mode')} value={r.circMode} title="what the aux point is: a point on the arc, the centre, or the normal whose length is the radius" onChange={(e) => onEdit({ circMode: (e.target as HTMLSelectElement).value as PathRow['circMode'] })}>
                {CIRC_MODES.map((m) => (
                  <option key={m} value={m}>
                    {m}
                  </option>
                ))}
              </select>
              <select name={path('path_choice')} value={r.pathChoice} disabled={r.circMode === 'border'} title="which arc (ignored for border)" onChange={(e) => onEdit({ pathChoice: (e.target as HTMLSelectElement).value as PathRow['pathChoice'] })}>
                {PATH_CHOICES.map((m) => (
                  <option key={m} value={m}>
                    {m.replace('_', ' ')}
                  </option>
                ))}
              </select>
            </div>
            <div class="vec">
              {(['x', 'y', 'z'] as const).map((a, j) => (
                <label key={a} class="vec-cell">
                  <span class="vec-label">{r.circMode === 'radius' ? `n${a}` : `aux ${a}`}</span>
                  {text(`aux_point[${j}]`, r.aux[j], (v) => onEdit({ aux: r.aux.map((x, k) => (k === j ? v : x)) as PathRow['aux'] }), errors.aux_point ? 'num-invalid' : '')}
                </label>
              ))}
            </div>
            {err(errors.circ_mode)}
            {err(errors.path_choice)}
            {err(auxError || undefined)}
          </>
        ) : (
          <span class="muted">—</span>
        )}
      </td>
      <td>
        {moves ? (
          <>
            {text('velocity', r.velocity, (v) => onEdit({ velocity: v }), 'vel-input', 'v or maximum')}
            {err(errors.velocity)}
            <details class="dyn">
              <summary class="small">a / d / j</summary>
              {text('acceleration', r.acceleration, (v) => onEdit({ acceleration: v }), '', 'default')}
              {text('deceleration', r.deceleration, (v) => onEdit({ deceleration: v }), '', 'default')}
              {text('jerk', r.jerk, (v) => onEdit({ jerk: v }), '', 'default')}
            </details>
            {err(errors.acceleration)}
            {err(errors.deceleration)}
            {err(errors.jerk)}
          </>
        ) : (
          <span class="muted">—</span>
        )}
      </td>
      <td>
        <div class="vec">
          <select name={path('buffer_mode')} value={r.bufferMode} class={errors.buffer_mode ? 'sel-invalid' : ''} onChange={(e) => onEdit({ bufferMode: (e.target as HTMLSelectElement).value as PathRow['bufferMode'] })}>
            {BUFFER_MODES.map((m) => (
              <option key={m} value={m}>
                {m.replace('_', ' ')}
              </option>
            ))}
          </select>
          {moves && (
            <select name={path('transition_mode')} value={r.transitionMode} class={errors.transition_mode ? 'sel-invalid' : ''} onChange={(e) => onEdit({ transitionMode: (e.target as HTMLSelectElement).value as PathRow['transitionMode'] })}>
              {TRANSITION_MODES.map((m) => (
                <option key={m} value={m}>
                  {m.replace(/_/g, ' ')}
                </option>
              ))}
            </select>
          )}
        </div>
        {moves && r.transitionMode !== 'none' && (
          <div class="vec">
            <label class="vec-cell">
              <span class="vec-label">{r.transitionMode === 'corner_distance' ? 'radius' : 'r in'}</span>
              {text('transition_parameters[0]', r.rIn, (v) => onEdit({ rIn: v }), errors.transition_parameters ? 'num-invalid' : '')}
            </label>
            {r.transitionMode === 'corner_distance_advanced' && (
              <label class="vec-cell">
                <span class="vec-label">r out</span>
                {text('transition_parameters[1]', r.rOut, (v) => onEdit({ rOut: v }), errors.transition_parameters ? 'num-invalid' : '')}
              </label>
            )}
          </div>
        )}
        {err(errors.buffer_mode)}
        {err(errors.transition_mode)}
        {err(tpError || undefined)}
      </td>
      <td>
        {text('invoke_id', r.invokeId, (v) => onEdit({ invokeId: v }), 'id-input', '0')}
        {err(errors.invoke_id)}
      </td>
      <td class="row-actions">
        <button type="button" class="btn btn-small" name={`row-up-${i}`} title="move up" disabled={i === 0} onClick={() => onMove(-1)}>
          ↑
        </button>
        <button type="button" class="btn btn-small" name={`row-down-${i}`} title="move down" disabled={i === count - 1} onClick={() => onMove(1)}>
          ↓
        </button>
        <button type="button" class="btn btn-small btn-danger-outline" name={`row-remove-${i}`} title="remove" onClick={onRemove}>
          ×
        </button>
        {other.map(([k, m]) => (
          <span key={k} class="field-error" role="alert">
            {k}: {m}
          </span>
        ))}
      </td>
    </tr>
  );
}

/** MC_GroupSetOverride as a slider (0–100 %); follows the group unless the user holds it. */
function GroupOverride({ group, factor, actual, online, onError }: { group: string; factor: number | null; actual: number | null; online: boolean; onError: (t: string) => void }) {
  const [value, setValue] = useState<number | null>(null);
  const lastInput = useRef(0);
  const busy = useRef(false);
  const wanted = useRef<number | null>(null);
  const tracked = factor === null ? null : Math.round(factor * 100);
  useEffect(() => {
    if (busy.current || Date.now() - lastInput.current < 600) return;
    if (tracked !== null) setValue(tracked);
  }, [tracked]);
  const send = async (v: number) => {
    setValue(v);
    lastInput.current = Date.now();
    wanted.current = v;
    if (busy.current) return;
    busy.current = true;
    try {
      while (wanted.current !== null) {
        const w = wanted.current;
        wanted.current = null;
        await groupCommand(group, 'set-override', { factor: w / 100 });
      }
    } catch (e) {
      onError(errorText(e));
    } finally {
      busy.current = false;
      wanted.current = null;
    }
  };
  return (
    <div class="row override">
      <span class="field-label" title="MC_GroupSetOverride: the path velocity factor, ramped over the override ramp time">
        Override
      </span>
      <input type="range" name="group-override" min={0} max={100} step={1} value={value ?? 100} disabled={!online} onInput={(e) => void send(Number((e.target as HTMLInputElement).value))} />
      <span class="mono override-value" data-testid="group-override-value">
        {value ?? '—'} %
      </span>
      {[0, 50, 100].map((v) => (
        <button key={v} type="button" class="btn btn-small" name={`group-override-${v}`} disabled={!online} onClick={() => void send(v)}>
          {v}
        </button>
      ))}
      <span class="small muted" title="ActOverrideFactor: the override in effect (ramped)">
        in effect {actual === null ? '—' : `${num(actual * 100, 0)} %`}
      </span>
    </div>
  );
}
