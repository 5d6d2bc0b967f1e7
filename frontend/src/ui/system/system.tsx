// System: what a commissioning engineer checks before trusting the machine. The cycle's timing
// (`GET /system` every 2 s: wake-up latency, compute time and period in µs, overruns) and the
// clock it runs on (`GET /clock`: real, virtual or fast — a machine that is not in real time), its
// distributions (`GET /metrics?buckets=fine`), overruns over the last minutes (kept here), the
// real-time grants, the drive bus (bus.tsx beside this file), the audit log, and the configuration as one document:
// download it, or import a file after seeing what it would change.
import { useEffect, useRef, useState } from 'preact/hooks';
import { ApiError } from '../../api/problem';
import { api } from '../../api/client';
import type { Problem } from '../../api/types';
import type { components } from '../../api/schema';
import { useStore } from '../../store';
import { refreshAxes, statuses } from '../../services';
import { auth, may } from '../../auth/session';
import { Kpi, Led, Panel, errorText } from '../shared/common';
import { getCycleHistograms } from '../../system/api';
import type { CycleHistograms } from '../../system/prometheus';
import { HistogramChart, OverrunChart } from './charts';
import { HISTORY_S, POLL_MS, QUANTILES, TimingHistory, level, us, uptime, type SystemResource } from '../../system/timing';
import {
  ANY,
  FAILURES,
  NO_FILTER,
  PAGE,
  REFRESH_MS,
  actionSuggestions,
  auditParams,
  detailLine,
  distinct,
  filterEntries,
  isFiltered,
  mergeEntries,
  newestId,
  oldestId,
  outcomeKind,
  stamp,
  who,
  type AuditFilter,
  type AuditRecord,
} from '../../system/audit';
import { diffConfig, diffCounts, exportName, importErrors, notADocument, valueText, type ConfigDiff, type ConfigDocument, type ItemDiff } from '../../system/config-diff';
import { BusPanel } from './bus';

type ClockState = components['schemas']['ClockState'];

/** Polls of this page, kept while the page is away (the gap is drawn as one). */
const history = new TimingHistory(HISTORY_S);

const TIMING_ROWS = [
  ['wakeup_latency', 'Wake-up latency', 'wake-up time minus the deadline'],
  ['compute', 'Compute time', 'work per cycle: drives, commands, kernel, snapshot'],
  ['period', 'Period', 'time between consecutive wake-ups'],
] as const;

export function SystemPage() {
  const [sys, setSys] = useState<SystemResource | null>(null);
  const [hist, setHist] = useState<CycleHistograms | null>(null);
  const [sysError, setSysError] = useState<string | null>(null);
  const [histError, setHistError] = useState<string | null>(null);
  const [version, setVersion] = useState(0);
  const [clockState, setClockState] = useState<ClockState | null>(null);
  useEffect(() => {
    let stopped = false;
    let timer: ReturnType<typeof setTimeout> | undefined;
    const tick = async () => {
      if (typeof document === 'undefined' || !document.hidden) {
        const [s, m, c] = await Promise.allSettled([api.GET('/api/v1/system'), getCycleHistograms(), api.GET('/api/v1/clock')]);
        if (stopped) return;
        setClockState(c.status === 'fulfilled' ? c.value : null);
        const h = m.status === 'fulfilled' ? m.value : null;
        if (s.status === 'fulfilled') {
          setSys(s.value);
          setSysError(null);
          history.add(Date.now() / 1000, s.value, h);
          setVersion((v) => v + 1);
        } else setSysError(errorText(s.reason));
        if (m.status === 'fulfilled') {
          setHist(h);
          setHistError(null);
        } else setHistError(errorText(m.reason));
      }
      if (!stopped) timer = setTimeout(tick, POLL_MS);
    };
    void tick();
    void refreshAxes();
    return () => {
      stopped = true;
      clearTimeout(timer);
    };
  }, []);
  return (
    <div class="page page-system" id="system" data-testid="system">
      <div class="page-head sys-head">
        <h2>System</h2>
        {sys && (
          <span class="muted sys-facts" data-testid="sys-facts">
            motiond <b>{sys.version}</b> · {sys.listen} · up {uptime(sys.uptime_s)}
          </span>
        )}
        <span class={`live-ind ${sysError ? 'live-stale' : sys ? 'live-live' : ''}`} title={`GET /system every ${POLL_MS / 1000} s`}>
          <span class="live-dot" />
          {sysError ? 'not updated' : `every ${POLL_MS / 1000} s`}
        </span>
      </div>
      {sysError && (
        <div class="banner banner-error" role="alert" data-testid="system-error">
          <span>{sysError}</span>
        </div>
      )}
      <div class={`sys-grid ${sysError ? 'stale' : ''}`}>
        <TimingPanel sys={sys} clock={clockState} />
        <RealtimePanel sys={sys} />
      </div>
      <HistogramPanel hist={hist} error={histError} version={version} />
      <Panel title="Overruns over time" class="sys-overruns" actions={<span class="muted small">last {HISTORY_S / 60} min, kept by this page</span>}>
        <OverrunChart points={history.points} windowS={HISTORY_S} version={version} />
      </Panel>
      <BusPanel />
      <ConfigPanel />
      <AuditPanel />
    </div>
  );
}

/** The clock as a KPI (short: it fits the tile): `real`, or what makes this machine's time not the wall clock's. */
export function clockText(c: ClockState): string {
  if (c.mode === 'fast') return c.factor ? `fast ×${c.factor}` : 'fast (max)';
  return c.mode;
}

const CLOCK_HELP: Record<string, string> = {
  real: 'one cycle per cycle time',
  virtual: 'cycles advance only when a client asks (POST /api/v1/clock/advance): nothing moves on its own',
  fast: 'cycles run continuously, faster than real time',
};

function TimingPanel({ sys, clock }: { sys: SystemResource | null; clock: ClockState | null }) {
  const t = sys?.timing;
  const ct = sys?.cycle_time ?? 0;
  return (
    <Panel title="Cycle timing" class="sys-timing" actions={sys && <span class="muted small">µs · since start</span>}>
      {!sys ? (
        <p class="muted">Loading…</p>
      ) : (
        <>
          <div class="sys-kpis">
            <Kpi label="Cycle time" value={`${(ct * 1000).toPrecision(4).replace(/\.?0+$/, '')} ms`} name="cycle_time" />
            {clock && <Kpi label="Clock" value={clockText(clock)} name="clock" tone={clock.mode === 'real' ? undefined : 'warn'} title={`${CLOCK_HELP[clock.mode] ?? clock.mode}; clock time ${clock.time_s.toFixed(3)} s`} />}
            <Kpi label="Cycles" value={t!.cycles.toLocaleString('en-US')} name="cycles" />
            <Kpi label="Overruns" value={t!.overruns.toLocaleString('en-US')} name="overruns" tone={t!.overruns ? 'bad' : 'ok'} />
            <Kpi label="Overrun rate" value={t!.cycles ? `${((t!.overruns / t!.cycles) * 100).toPrecision(2)} %` : '—'} name="overrun_rate" tone={t!.overruns ? 'bad' : 'ok'} />
          </div>
          <div class="table-fit">
            <table class="grid sys-timing-table" data-testid="timing">
              <thead>
                <tr>
                  <th />
                  {QUANTILES.map(([k, label]) => (
                    <th key={k} class={`r ${k === 'mean_us' || k === 'p90_us' ? 'hide-phone' : ''}`}>
                      {label}
                    </th>
                  ))}
                </tr>
              </thead>
              <tbody>
                {TIMING_ROWS.map(([k, label, help]) => (
                  <tr key={k} data-metric={k}>
                    <th scope="row" class="sys-row-label" title={help}>
                      {label}
                    </th>
                    {QUANTILES.map(([q]) => {
                      const v = t![k][q];
                      const lv = level(k, v, ct);
                      return (
                        <td key={q} class={`r mono lv-${lv} ${q === 'mean_us' || q === 'p90_us' ? 'hide-phone' : ''}`} data-q={q} title={lv === 'ok' ? undefined : lv === 'bad' ? 'a cycle or more' : 'half a cycle or more off'}>
                          {us(v)}
                        </td>
                      );
                    })}
                  </tr>
                ))}
              </tbody>
            </table>
          </div>
          <p class="muted small sys-note">
            Measured by the cycle thread itself over {t!.wakeup_latency.count.toLocaleString('en-US')} cycles. Amber: half a cycle; red: a whole cycle (wake-up, compute) or
            a skipped cycle (period).
          </p>
        </>
      )}
    </Panel>
  );
}

function RealtimePanel({ sys }: { sys: SystemResource | null }) {
  if (!sys) return <Panel title="Real-time">{<p class="muted">Loading…</p>}</Panel>;
  const r = sys.realtime;
  const t = sys.timing;
  const counters = [
    ['events_dropped', 'Command events dropped', t.events_dropped],
    ['audit_dropped', 'Audit entries dropped', t.audit_dropped],
    ['requests_expired', 'Requests expired', t.requests_expired],
    ['scope_frames_dropped', 'Scope frames dropped', t.scope_frames_dropped],
  ] as const;
  return (
    <Panel title="Real-time" class="sys-rt">
      <div class="led-grid sys-leds" data-testid="realtime">
        <Led on={r.sched_fifo} label="SCHED_FIFO" tone={r.sched_fifo ? 'green' : 'red'} title="the cycle thread runs with real-time priority" />
        <Led on={r.mlockall} label="mlockall" tone="green" title="memory locked: no page faults in the cycle" />
        <Led on={r.pinned_cpu !== null && r.pinned_cpu !== undefined} label={r.pinned_cpu !== null && r.pinned_cpu !== undefined ? `pinned CPU ${r.pinned_cpu}` : 'not pinned'} tone="green" title="the cycle thread is pinned to one CPU" />
        <Led on={r.cpu_dma_latency_zero} label="cpu_dma_latency 0" tone="green" title="/dev/cpu_dma_latency held at 0: no deep C-states" />
      </div>
      {r.notes.length > 0 && (
        <ul class="sys-notes" data-testid="realtime-notes">
          {r.notes.map((n, i) => (
            <li key={i}>{n}</li>
          ))}
        </ul>
      )}
      <dl class="sys-facts-list">
        {counters.map(([k, label, v]) => (
          <div key={k} data-counter={k}>
            <dt>{label}</dt>
            <dd class={`mono ${v ? 'text-error' : ''}`}>{v}</dd>
          </div>
        ))}
        <div>
          <dt>Listen</dt>
          <dd class="mono">{sys.listen}</dd>
        </div>
        <div>
          <dt>Database</dt>
          <dd class="mono sys-path" title={sys.database}>
            {sys.database}
          </dd>
        </div>
        <div>
          <dt>Version · uptime</dt>
          <dd>
            {sys.version} · {uptime(sys.uptime_s)}
          </dd>
        </div>
      </dl>
    </Panel>
  );
}

const WINDOWS: [string, number | null][] = [
  ['since start', null],
  ['10 s', 10],
  ['1 min', 60],
];

function HistogramPanel({ hist, error, version }: { hist: CycleHistograms | null; error: string | null; version: number }) {
  const [win, setWin] = useState<number | null>(null);
  void version;
  const w = win === null ? (hist ? { hist, spanS: Infinity } : null) : history.window(win);
  const shown = w?.hist ?? null;
  return (
    <Panel
      title="Distributions"
      class="sys-hist"
      actions={
        <div class="seg" role="group" aria-label="window">
          {WINDOWS.map(([label, s]) => (
            <button type="button" key={label} class={`seg-btn ${win === s ? 'active' : ''}`} name={`hist-window-${s ?? 'all'}`} onClick={() => setWin(s)}>
              {label}
            </button>
          ))}
        </div>
      }
    >
      {error && <p class="field-error">Histograms: {error}</p>}
      {win !== null && !w && <p class="muted small">Collecting: this window needs polls {win} s apart…</p>}
      <div class="hist-pair">
        <div class="hist-cell">
          <h4>Wake-up latency</h4>
          <HistogramChart name="wakeup_latency" hist={shown?.wakeup_latency} />
        </div>
        <div class="hist-cell">
          <h4>Compute time</h4>
          <HistogramChart name="compute" hist={shown?.compute} />
        </div>
      </div>
      <p class="muted small sys-note">Cycles per bucket (≈6 % wide, log scale), from GET /metrics?buckets=fine.</p>
    </Panel>
  );
}

// ───────────────────────────── configuration ─────────────────────────────

type ImportState =
  | { kind: 'idle' }
  | { kind: 'reading' }
  | { kind: 'diff'; file: string; doc: ConfigDocument; current: ConfigDocument; diff: ConfigDiff }
  | { kind: 'done'; file: string; axes: number; tables: number | null };

/** Offers `text` as a JSON file download. */
function downloadJson(name: string, text: string): void {
  const blob = new Blob([text], { type: 'application/json' });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

export function ConfigPanel() {
  const engineer = may(useStore(auth), 'engineer');
  const [state, setState] = useState<ImportState>({ kind: 'idle' });
  const [error, setError] = useState<string | null>(null);
  const [problem, setProblem] = useState<{ status: number; problem: Problem | null; text: string } | null>(null);
  const [busy, setBusy] = useState(false);
  const [stale, setStale] = useState(false);
  const file = useRef<HTMLInputElement>(null);

  const download = async () => {
    setError(null);
    try {
      const doc = await api.GET('/api/v1/config');
      downloadJson(exportName(), JSON.stringify(doc, null, 2) + '\n');
    } catch (e) {
      setError(errorText(e));
    }
  };

  const chosen = async (f: File | undefined) => {
    if (!f) return;
    setError(null);
    setProblem(null);
    setStale(false);
    setState({ kind: 'reading' });
    try {
      const text = await f.text();
      let doc: unknown;
      try {
        doc = JSON.parse(text);
      } catch (e) {
        throw new Error(`${f.name} is not JSON: ${(e as Error).message}`);
      }
      const bad = notADocument(doc);
      if (bad) throw new Error(`${f.name}: ${bad}`);
      const current = await api.GET('/api/v1/config');
      setState({ kind: 'diff', file: f.name, doc: doc as ConfigDocument, current, diff: diffConfig(current, doc as ConfigDocument) });
    } catch (e) {
      setState({ kind: 'idle' });
      setError(errorText(e));
    } finally {
      if (file.current) file.current.value = '';
    }
  };

  const doImport = async () => {
    if (state.kind !== 'diff' || busy) return;
    setBusy(true);
    setError(null);
    setProblem(null);
    try {
      // The diff shown must be the one that applies: if the configuration changed meanwhile,
      // show the new diff and ask again.
      const now = await api.GET('/api/v1/config');
      if (JSON.stringify(now) !== JSON.stringify(state.current)) {
        setState({ ...state, current: now, diff: diffConfig(now, state.doc) });
        setStale(true);
        return;
      }
      const done = await api.PUT('/api/v1/config', { body: state.doc });
      setState({ kind: 'done', file: state.file, axes: done.axes.length, tables: state.doc.cam_tables ? (done.cam_tables ?? []).length : null });
      void refreshAxes();
    } catch (e) {
      if (e instanceof ApiError && e.status > 0) setProblem({ status: e.status, problem: e.problem, text: errorText(e) });
      else setError(errorText(e));
    } finally {
      setBusy(false);
    }
  };

  const cancel = () => {
    setState({ kind: 'idle' });
    setProblem(null);
    setStale(false);
  };

  return (
    <Panel
      title="Configuration"
      class="sys-config"
      id="config"
      actions={
        <>
          <button type="button" class="btn btn-small" name="config-download" onClick={() => void download()} title="GET /api/v1/config as a JSON file">
            Download
          </button>
          <button
            type="button"
            class="btn btn-small"
            name="config-import"
            disabled={!engineer || state.kind === 'reading' || busy}
            title={engineer ? 'choose a configuration file: what it changes is shown before anything is imported' : 'importing needs the engineer role'}
            onClick={() => file.current?.click()}
          >
            Import…
          </button>
        </>
      }
    >
      <input ref={file} type="file" name="config-file" accept=".json,application/json" hidden tabIndex={-1} onChange={(e) => void chosen((e.target as HTMLInputElement).files?.[0])} />
      <p class="muted small panel-note">
        The whole configuration as one JSON document: every axis with its persistent parameters, and the cam tables. An import shows first what it would change;
        it replaces every axis (all must be disabled) and, if the file has <code>cam_tables</code>, the cam tables.
      </p>
      {error && (
        <div class="banner banner-error form-error" role="alert" data-testid="config-error">
          <span>{error}</span>
        </div>
      )}
      {state.kind === 'reading' && <p class="muted">Reading the file…</p>}
      {state.kind === 'done' && (
        <div class="banner banner-ok" data-testid="import-done">
          <span>
            Imported <b>{state.file}</b>: {state.axes} {state.axes === 1 ? 'axis' : 'axes'}
            {state.tables === null ? ', cam tables kept' : `, ${state.tables} cam ${state.tables === 1 ? 'table' : 'tables'}`}.
          </span>
          <button type="button" class="banner-close" onClick={cancel} aria-label="dismiss">
            ×
          </button>
        </div>
      )}
      {state.kind === 'diff' && (
        <ImportDiff file={state.file} doc={state.doc} diff={state.diff} busy={busy} stale={stale} problem={problem} onImport={() => void doImport()} onCancel={cancel} />
      )}
    </Panel>
  );
}

function ImportDiff({ file, doc, diff, busy, stale, problem, onImport, onCancel }: {
  file: string;
  doc: ConfigDocument;
  diff: ConfigDiff;
  busy: boolean;
  stale: boolean;
  problem: { status: number; problem: Problem | null; text: string } | null;
  onImport: () => void;
  onCancel: () => void;
}) {
  const c = diffCounts(diff);
  const st = useStore(statuses);
  const enabled = [...st.entries()].filter(([, s]) => s.status?.power_status).map(([n]) => n);
  const sameAxes = diff.axes.filter((a) => a.kind === 'same').map((a) => a.name);
  const sameTables = (diff.camTables ?? []).filter((a) => a.kind === 'same').map((a) => a.name);
  const errors = importErrors(problem?.problem ?? null, doc);
  return (
    <div class="import-diff diff" data-testid="import-diff">
      <div class="import-head">
        <b>Import {file}?</b>{' '}
        <span class="muted" data-testid="diff-summary">
          {diff.same
            ? 'nothing differs from the configuration now active'
            : `${c.changed} changed (${c.fields} ${c.fields === 1 ? 'field' : 'fields'}), ${c.added} added, ${c.removed} removed`}
        </span>
      </div>
      {stale && (
        <div class="banner banner-warn" data-testid="diff-stale">
          <span>The configuration changed since this diff was made: it is shown anew. Check it, then import again.</span>
        </div>
      )}
      <h4>Axes</h4>
      {diff.axes.filter((a) => a.kind !== 'same').map((a) => (
        <DiffItem key={`a-${a.name}`} item={a} what="axis" />
      ))}
      {sameAxes.length > 0 && <p class="muted small">Unchanged: {sameAxes.join(', ')}</p>}
      <h4>Cam tables</h4>
      {diff.camTables === null ? (
        <p class="muted small" data-testid="cams-kept">
          The file has no <code>cam_tables</code>: the stored cam tables stay as they are.
        </p>
      ) : (
        <>
          {diff.camTables.filter((t) => t.kind !== 'same').map((t) => (
            <DiffItem key={`t-${t.name}`} item={t} what="cam" />
          ))}
          {sameTables.length > 0 && <p class="muted small">Unchanged: {sameTables.join(', ')}</p>}
          {diff.camTables.length === 0 && <p class="muted small">No cam tables, neither stored nor in the file.</p>}
        </>
      )}
      {diff.document.length > 0 && (
        <p class="small">
          Document version: {valueText(diff.document[0].old)} → {valueText(diff.document[0].new)}
        </p>
      )}
      {problem && (
        <div class="banner banner-error import-problem" role="alert" data-testid="import-problem" data-status={problem.status}>
          <div>
            {problem.status === 409 ? (
              <>
                <b>All axes must be disabled before an import.</b> {problem.problem?.detail ?? problem.text}
                {enabled.length > 0 && <div class="small">Enabled now: {enabled.join(', ')}</div>}
              </>
            ) : problem.status === 422 ? (
              <>
                <b>motiond refused the file:</b>
                {errors.length ? (
                  <ul class="import-errors" data-testid="import-errors">
                    {errors.map((e, i) => (
                      <li key={i} data-field={e.field}>
                        <b>{e.label}</b>: {e.message}
                      </li>
                    ))}
                  </ul>
                ) : (
                  <> {problem.problem?.detail ?? problem.text}</>
                )}
              </>
            ) : (
              problem.text
            )}
          </div>
        </div>
      )}
      <div class="banner banner-warn import-warn">
        <span>Importing re-creates every axis from the file: all axes must be disabled; their positions and homed states are lost.</span>
      </div>
      <div class="form-actions">
        <button type="button" class={`btn btn-primary ${busy ? 'busy' : ''}`} name="import-confirm" disabled={busy} onClick={onImport}>
          Import
        </button>
        <button type="button" class="btn" name="import-cancel" onClick={onCancel}>
          Cancel
        </button>
      </div>
    </div>
  );
}

const KIND_TAG = { added: 'tag-green', removed: 'tag-red', changed: 'tag-amber', same: '' } as const;

function DiffItem({ item, what }: { item: ItemDiff; what: 'axis' | 'cam' }) {
  return (
    <div class="diff-item" data-diff-item={item.name} data-diff-kind={item.kind} data-diff-what={what}>
      <div class="diff-item-head">
        <span class={`tag ${KIND_TAG[item.kind]}`}>{item.kind}</span> <b>{item.name}</b>
        {item.summary && <span class="muted small"> {item.summary}</span>}
      </div>
      {item.changes.length > 0 && (
        <div class="table-fit">
          <table class="grid diff-table">
            <tbody>
              {item.changes.map((ch) => (
                <tr key={ch.path} data-path={ch.path}>
                  <td class="mono diff-path">{ch.path}</td>
                  <td class="mono diff-vals">
                    <span class={ch.old === undefined ? 'muted' : 'old'}>{valueText(ch.old)}</span> →{' '}
                    <span class={ch.new === undefined ? 'muted' : 'new'}>{valueText(ch.new)}</span>
                    {ch.note && <span class="muted small"> ({ch.note})</span>}
                  </td>
                </tr>
              ))}
            </tbody>
          </table>
        </div>
      )}
    </div>
  );
}

// ───────────────────────────── audit log ─────────────────────────────

type AuditError = { kind: 'forbidden'; text: string } | { kind: 'other'; text: string };

export function AuditPanel() {
  const [entries, setEntries] = useState<AuditRecord[] | null>(null);
  const [error, setError] = useState<AuditError | null>(null);
  const [filter, setFilter] = useState<AuditFilter>(NO_FILTER);
  const [end, setEnd] = useState(false);
  const [loadingOlder, setLoadingOlder] = useState(false);
  const list = useRef<AuditRecord[]>([]);
  const forbidden = error?.kind === 'forbidden';
  // Refused (the role): no more asking every 5 s; Refresh asks again.
  const refused = useRef(false);
  refused.current = forbidden;

  const fail = (e: unknown) => {
    if (e instanceof ApiError && e.status === 403) setError({ kind: 'forbidden', text: e.problem?.detail ?? e.message });
    else setError({ kind: 'other', text: errorText(e) });
  };
  const set = (l: AuditRecord[]) => {
    list.current = l;
    setEntries(l);
  };
  const loadNewest = async () => {
    try {
      const since = newestId(list.current);
      if (since === null) {
        const got = await api.GET('/api/v1/audit', { params: { query: auditParams({ limit: PAGE }) } });
        set(got);
        setEnd(got.length < PAGE);
      } else {
        const got = await api.GET('/api/v1/audit', { params: { query: auditParams({ limit: PAGE, since }) } });
        // More new entries than a page: the ones between are not loaded; start again from these.
        if (got.length >= PAGE) {
          set(got);
          setEnd(false);
        } else if (got.length) set(mergeEntries(list.current, got));
      }
      setError(null);
    } catch (e) {
      fail(e);
    }
  };
  const loadOlder = async () => {
    const before = oldestId(list.current);
    if (before === null || loadingOlder) return;
    setLoadingOlder(true);
    try {
      const got = await api.GET('/api/v1/audit', { params: { query: auditParams({ limit: PAGE, before }) } });
      set(mergeEntries(list.current, got));
      if (got.length < PAGE) setEnd(true);
      setError(null);
    } catch (e) {
      fail(e);
    } finally {
      setLoadingOlder(false);
    }
  };
  useEffect(() => {
    let stopped = false;
    let timer: ReturnType<typeof setTimeout> | undefined;
    const tick = async () => {
      if (!refused.current && (typeof document === 'undefined' || !document.hidden)) await loadNewest();
      if (!stopped) timer = setTimeout(tick, REFRESH_MS);
    };
    void tick();
    return () => {
      stopped = true;
      clearTimeout(timer);
    };
  }, []);
  const all = entries ?? [];
  const shown = filterEntries(all, filter);
  const setF = (p: Partial<AuditFilter>) => setFilter((f) => ({ ...f, ...p }));
  const outcomes = distinct(all, 'outcome');
  return (
    <Panel
      title="Audit log"
      class="sys-audit"
      id="audit"
      actions={
        <>
          <span class={`live-ind ${error ? 'live-stale' : entries ? 'live-live' : ''}`} title={`the newest entries every ${REFRESH_MS / 1000} s`}>
            <span class="live-dot" />
            {forbidden ? 'refused' : error ? 'not updated' : `every ${REFRESH_MS / 1000} s`}
          </span>
          <button type="button" class="btn btn-small" name="audit-refresh" onClick={() => void loadNewest()}>
            Refresh
          </button>
        </>
      }
    >
      {forbidden ? (
        <div class="banner banner-warn" data-testid="audit-forbidden">
          <span>
            <b>The audit log needs the engineer role.</b> motiond says: {error.text}
          </span>
        </div>
      ) : (
        <>
          {error && (
            <div class="banner banner-error" role="alert" data-testid="audit-error">
              <span>{error.text}</span>
            </div>
          )}
          <div class="toolbar audit-filters" data-testid="audit-filters">
            <label class="field">
              <span class="field-label">Action starts with</span>
              <input type="search" name="audit-action" list="audit-actions" placeholder="command." value={filter.action} onInput={(e) => setF({ action: (e.target as HTMLInputElement).value })} />
            </label>
            <label class="field">
              <span class="field-label">Target</span>
              <input type="search" name="audit-target" list="audit-targets" placeholder="axis, command id" value={filter.target} onInput={(e) => setF({ target: (e.target as HTMLInputElement).value })} />
            </label>
            <label class="field">
              <span class="field-label">Outcome</span>
              <select name="audit-outcome" value={filter.outcome} onChange={(e) => setF({ outcome: (e.target as HTMLSelectElement).value })}>
                <option value={ANY}>any</option>
                <option value={FAILURES}>failures (rejected, error, aborted)</option>
                {outcomes.map((o) => (
                  <option key={o} value={o}>
                    {o}
                  </option>
                ))}
              </select>
            </label>
            {isFiltered(filter) && (
              <button type="button" class="btn btn-small audit-clear" name="audit-clear" onClick={() => setFilter(NO_FILTER)}>
                Clear filters
              </button>
            )}
            <span class="muted small audit-count" data-testid="audit-count">
              {entries === null ? 'loading…' : isFiltered(filter) ? `${shown.length} of ${all.length} loaded` : `${all.length} loaded`}
            </span>
            <datalist id="audit-actions">
              {actionSuggestions(all).map((a) => (
                <option key={a} value={a} />
              ))}
            </datalist>
            <datalist id="audit-targets">
              {distinct(all, 'target').map((a) => (
                <option key={a} value={a} />
              ))}
            </datalist>
          </div>
          <table class="grid audit-table" data-testid="audit">
            <colgroup>
              <col class="c-time" />
              <col class="c-who" />
              <col class="c-action" />
              <col class="c-target" />
              <col class="c-cmd" />
              <col class="c-outcome" />
              <col />
            </colgroup>
            <thead>
              <tr>
                <th>Time</th>
                <th>Who</th>
                <th>Action</th>
                <th>Target</th>
                <th class="r">Cmd</th>
                <th>Outcome</th>
                <th>Detail</th>
              </tr>
            </thead>
            <tbody>
              {shown.map((e) => (
                <AuditRow key={e.id} e={e} />
              ))}
              {entries !== null && shown.length === 0 && (
                <tr class="audit-empty">
                  <td colSpan={7} class="muted empty">
                    {all.length ? 'No loaded entry matches the filters; older ones may: Load older.' : 'The audit log is empty.'}
                  </td>
                </tr>
              )}
            </tbody>
          </table>
          <div class="audit-foot">
            {end ? (
              <span class="muted small" data-testid="audit-end">
                Start of the log.
              </span>
            ) : (
              <button type="button" class={`btn btn-small ${loadingOlder ? 'busy' : ''}`} name="audit-older" disabled={entries === null || loadingOlder} onClick={() => void loadOlder()}>
                Load older
              </button>
            )}
          </div>
        </>
      )}
    </Panel>
  );
}

/** A code with a line break allowed after each ':' and '_' (rejected:target_above_soft_limit). */
const breakAfter = (code: string) => code.split(/(?<=[:_])/).flatMap((w, i) => (i ? [<wbr />, w] : [w]));

const OUTCOME_TAG = { ok: 'tag-green', fail: 'tag-red', aborted: 'tag-amber', none: '' } as const;

function AuditRow({ e }: { e: AuditRecord }) {
  const w = who(e);
  const line = detailLine(e.detail);
  const t = stamp(e.at);
  return (
    <tr data-audit-id={e.id} data-action={e.action}>
      <td class="mono nowrap audit-time" title={e.at}>
        <span class="audit-date">{t.slice(0, 11)}</span>
        {t.slice(11)}
      </td>
      <td class="audit-who">
        {w.principal && <b class="audit-principal">{w.principal}</b>}
        {w.client && <span class="mono audit-client">{w.client}</span>}
        {w.addr && <span class="muted small mono audit-addr">{w.addr}</span>}
        {!w.principal && !w.client && !w.addr && <span class="muted">motiond</span>}
      </td>
      <td class="mono audit-action">{e.action}</td>
      <td class="mono audit-target">{e.target ?? ''}</td>
      <td class="r mono audit-cmd">{e.command_id ?? ''}</td>
      <td class="audit-outcome">
        {e.outcome && (
          <span class={`tag ${OUTCOME_TAG[outcomeKind(e.outcome)]}`} title={e.outcome}>
            {breakAfter(e.outcome)}
          </span>
        )}
      </td>
      <td class="audit-detail">
        {line && (
          <details>
            <summary class="mono">{line}</summary>
            <pre class="mono">{JSON.stringify(e.detail, null, 2)}</pre>
          </details>
        )}
      </td>
    </tr>
  );
}

