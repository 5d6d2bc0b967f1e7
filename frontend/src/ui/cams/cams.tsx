// Cam tables (TwinCAT NC Camming): the list, and the cam editor of one table. The editor plots
// the table as edited — every edit is posted to `POST /cam-analysis` (the server is the one
// source of the cam math) and the answer redrawn: position (its points as handles to drag),
// velocity, acceleration and jerk over the master, the characteristic values, the jumps where
// a law's boundary conditions are not met (listed and marked at their row) and the server's
// validation errors at their row, before anything is saved. Undo/redo goes through whole
// table states (cams/history.ts). Saving sends the whole table; saving a table that axes are
// coupled through is an online change, said before it is done, by the table's online-change
// mode (shown and editable here).
import type { ComponentChildren } from 'preact';
import { useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { ApiError } from '../../api/problem';
import { api } from '../../api/client';
import type { CamAnalysisResource, CamCharacteristics, CamTableBody, CamTableResource, OnlineChange, TableType } from '../../api/types';
import { CamChart, type DragPhase } from '../../cams/chart';
import {
  LAWS,
  POINT_TYPES,
  bodyOf,
  csvToRows,
  dragDraft,
  draftOf,
  handlesOf,
  nextRow,
  rowsToCsv,
  stepOf,
  type Draft,
  type PointRow,
  type TableMeta,
} from '../../cams/data';
import { LiveAnalysis, discontinuityText, errorsByRow, samplesFor, warningsByRow, type Analysis } from '../../cams/analysis';
import { canRedo, canUndo, historyKey, historyOf, record, redo, settle, undo, type History } from '../../cams/history';
import { ONLINE_MODES, ONLINE_MODE_TEXT, SCALING_MODES, camMarkers, camUnits, onlineChangeText, slavesOf, takesActivationPosition, type CamSlave } from '../../cams/online';
import { href, navigate } from '../../router';
import { axes, statuses } from '../../services';
import { useStore } from '../../store';
import { ActionButton, ErrorBanner, Field, Led, NumberInput, Panel, download, errorText, fieldsOf } from '../shared/common';
import { sig } from '../../format';

const TYPES: [TableType, string][] = [
  ['motion_function', 'Motion function'],
  ['non_equidistant', 'Position table'],
  ['equidistant', 'Position table, equidistant'],
];

/** A periodic table to start from: up and down again (at rest at both ends for a motion function). */
function starter(name: string, type: TableType): CamTableBody {
  if (type !== 'motion_function') return { name, table_type: type, periodic: true, interpolation: 'spline', rows: [[0, 0], [90, 50], [180, 100], [270, 50], [360, 0]] };
  const p = (i: number, x: number, y: number) => ({ point_index: i, function_type: 'polynom5' as const, point_type: 'rest' as const, master_pos: x, slave_pos: y });
  return { name, table_type: 'motion_function', periodic: true, points: [p(1, 0, 0), p(2, 180, 100), p(3, 360, 0)] };
}

export function CamListPage() {
  const [tables, setTables] = useState<CamTableResource[] | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [name, setName] = useState('');
  const [type, setType] = useState<TableType>('motion_function');
  const [fields, setFields] = useState<Record<string, string>>({});
  const load = () => api.GET('/api/v1/cam-tables').then(setTables, (e) => setError(errorText(e)));
  useEffect(() => void load(), []);
  const create = async () => {
    try {
      const t = await api.POST('/api/v1/cam-tables', { body: starter(name.trim(), type) });
      navigate({ page: 'cam', table: t.name });
    } catch (e) {
      setFields(fieldsOf(e));
      setError(errorText(e));
      throw e;
    }
  };
  return (
    <div class="page" id="cams">
      <h2>Cam tables</h2>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <Panel title="Tables">
        {tables === null ? (
          <p class="muted">Loading…</p>
        ) : tables.length === 0 ? (
          <p class="muted">No cam tables yet.</p>
        ) : (
          <div class="table-scroll">
            <table class="grid cam-list">
              <thead>
                <tr>
                  <th>Id</th>
                  <th>Name</th>
                  <th>Type</th>
                  <th>Rows / points</th>
                  <th>Master period</th>
                  <th>Slave stroke</th>
                  <th>Version</th>
                </tr>
              </thead>
              <tbody>
                {tables.map((t) => (
                  <tr key={t.id} data-cam={t.name}>
                    <td>{t.id}</td>
                    <td>
                      <a href={`#/cams/${encodeURIComponent(t.name)}`}>{t.name}</a>
                    </td>
                    <td>
                      {t.table_type.replace('_', ' ')}
                      {t.periodic ? ', periodic' : ''}
                    </td>
                    <td class="num">{t.row_count}</td>
                    <td class="num">{sig(t.master_period)}</td>
                    <td class="num">{sig(t.slave_stroke)}</td>
                    <td class="num">{t.version}</td>
                  </tr>
                ))}
              </tbody>
            </table>
          </div>
        )}
      </Panel>
      <Panel title="New cam table">
        <div class="form-row">
          <Field label="Name" name="name" error={fields.name}>
            <input type="text" name="cam-name" value={name} onInput={(e) => setName((e.target as HTMLInputElement).value)} />
          </Field>
          <Field label="Type" name="table_type" error={fields.table_type}>
            <select name="cam-type" value={type} onChange={(e) => setType((e.target as HTMLSelectElement).value as TableType)}>
              {TYPES.map(([v, l]) => (
                <option key={v} value={v}>
                  {l}
                </option>
              ))}
            </select>
          </Field>
          <ActionButton kind="primary" name="create-cam" onClick={create} disabled={!name.trim()}>
            Create
          </ActionButton>
        </div>
        <p class="muted small">Starts as a periodic stroke up and down again (a motion function: Polynom 5 at rest at both ends); edit it on the next page.</p>
      </Panel>
    </div>
  );
}

/** The characteristic values shown: value, and the master position where it is (if any). */
const CHARACTERISTICS: [keyof CamCharacteristics, keyof CamCharacteristics | null, string][] = [
  ['slave_pos_max', 'm_pos_at_s_pos_max', 'Position max'],
  ['slave_pos_min', 'm_pos_at_s_pos_min', 'Position min'],
  ['slave_velo_max', 'm_pos_at_s_velo_max', 'Velocity max'],
  ['slave_velo_min', 'm_pos_at_s_velo_min', 'Velocity min'],
  ['slave_velo_mean', null, 'Velocity mean'],
  ['slave_acc_max', 'm_pos_at_s_acc_max', 'Acceleration max'],
  ['slave_acc_min', 'm_pos_at_s_acc_min', 'Acceleration min'],
  ['slave_jerk_max', 'm_pos_at_s_jerk_max', 'Jerk max'],
  ['slave_jerk_min', 'm_pos_at_s_jerk_min', 'Jerk min'],
];

type LiveState = 'pending' | 'current' | 'invalid' | 'error';

const sameDraft = (a: Draft, b: Draft) => JSON.stringify(a) === JSON.stringify(b);

export function CamPage({ table }: { table: string }) {
  const [t, setT] = useState<CamTableResource | null>(null);
  const [hist, setHist] = useState<History<Draft> | null>(null);
  /** The answer to the latest valid table (the plot, the characteristic values, the warnings). */
  const [result, setResult] = useState<CamAnalysisResource | null>(null);
  const [liveState, setLiveState] = useState<LiveState>('pending');
  const [liveText, setLiveText] = useState('');
  const [pending, setPending] = useState(true);
  /** The server's field errors (live analysis or save), by JSON path. */
  const [fields, setFields] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const [asked, setAsked] = useState<{ text: string; slaves: CamSlave[] } | null>(null);
  const chartEl = useRef<HTMLDivElement>(null);
  const chart = useRef<CamChart | null>(null);
  const analyser = useRef<LiveAnalysis | null>(null);
  const meta = useRef<TableMeta | null>(null);
  const steps = useRef({ master: 0.1, slave: 0.1 });
  const dragKey = useRef<string | null>(null);
  const drags = useRef(0);

  // The live analysis: posts the table as edited, keeps only the latest answer.
  useEffect(() => {
    const a = new LiveAnalysis(
      (body) => api.POST('/api/v1/cam-analysis', { params: { query: { samples: samplesFor(body) } }, body }),
      (x: Analysis) => {
        if (x.kind === 'ok') {
          setResult(x.result);
          setFields({});
          setLiveState('current');
          setLiveText('');
        } else if (x.kind === 'invalid') {
          setFields(x.fields);
          setLiveState('invalid');
          setLiveText(x.text);
        } else {
          setLiveState('error');
          setLiveText(x.text);
        }
      },
      setPending,
    );
    analyser.current = a;
    return () => a.dispose();
  }, []);

  const load = async () => {
    try {
      const one = await api.GET('/api/v1/cam-tables/{table}', { params: { path: { table } } });
      setT(one);
      meta.current = one;
      setHist(historyOf(draftOf(one)));
    } catch (e) {
      setError(errorText(e));
    }
  };
  useEffect(() => void load(), [table]);

  const draft = hist?.present ?? null;
  const saved = useMemo(() => (t ? draftOf(t) : null), [t]);
  const dirty = !!(draft && saved && !sameDraft(draft, saved));

  // Every edit (and the table as loaded) is analysed; the first at once, then debounced.
  const analysedOnce = useRef(false);
  useEffect(() => {
    if (!t || !draft || !analyser.current) return;
    analyser.current.schedule(bodyOf(t, draft));
    if (!analysedOnce.current) {
      analysedOnce.current = true;
      void analyser.current.flush();
    }
  }, [t, draft]);

  // The chart: made once the page is there, fed by the answers and the draft.
  const onDrag = (i: number, master: number, slave: number, phase: DragPhase) => {
    const m = meta.current;
    if (!m) return;
    if (phase === 'start') {
      dragKey.current = `drag-${++drags.current}`;
      return;
    }
    if (phase === 'end') {
      setHist((h) => h && settle(h));
      return;
    }
    const key = dragKey.current;
    setHist((h) => h && record(h, dragDraft(m, h.present, i, master, slave, steps.current.master, steps.current.slave), key));
  };
  const hasChart = !!t;
  useEffect(() => {
    if (!hasChart || !chartEl.current) return;
    chart.current = new CamChart(chartEl.current, { onDrag });
    return () => {
      chart.current?.destroy();
      chart.current = null;
    };
  }, [hasChart]);
  // The slaves coupled through this table: where they are on it now, and the axes' units.
  const tableId = t?.id ?? null;
  useEffect(() => {
    if (tableId === null || !hasChart) return;
    const show = () => {
      const c = chart.current;
      if (!c) return;
      const m = camMarkers(statuses.get(), tableId);
      c.setMarkers(m);
      c.setUnits(camUnits(m, axes.get()));
    };
    show();
    const offs = [statuses.subscribe(show), axes.subscribe(show)];
    return () => offs.forEach((off) => off());
  }, [tableId, hasChart]);
  const warnings = result?.discontinuities ?? [];
  useEffect(() => {
    if (!result || !chart.current) return;
    chart.current.setData(result.values.rows, result.master_start, result.master_end, [...new Set(result.discontinuities.map((d) => d.master))]);
    const c = result.characteristics;
    steps.current = { master: stepOf(result.master_end - result.master_start), slave: stepOf((c.slave_pos_max - c.slave_pos_min) || Math.abs(result.slave_end - result.slave_start)) };
  }, [result]);
  const showWarnings = liveState !== 'invalid';
  useEffect(() => {
    if (!t || !draft || !chart.current) return;
    chart.current.setHandles(handlesOf(t, draft), new Set(showWarnings ? warnings.map((d) => d.index) : []));
  }, [t, draft, result, showWarnings]);

  // Undo / redo from the keyboard, also while a field of the table has the focus.
  useEffect(() => {
    const onKey = (e: KeyboardEvent) => {
      const what = historyKey(e);
      if (!what) return;
      const el = e.target as HTMLElement | null;
      if (el?.closest?.('[data-native-undo]')) return;
      e.preventDefault();
      setHist((h) => h && (what === 'undo' ? undo(h) : redo(h)));
    };
    window.addEventListener('keydown', onKey);
    return () => window.removeEventListener('keydown', onKey);
  }, []);

  const change = (f: (d: Draft) => Draft, key: string | null = null) => setHist((h) => h && record(h, f(h.present), key));
  const editPoint = (i: number, patch: Partial<PointRow>, key: string | null = null) =>
    change((d) => ({ ...d, points: d.points.map((r, k) => (k === i ? { ...r, ...patch } : r)) }), key);

  const doSave = async () => {
    if (!t || !draft) return;
    setAsked(null);
    try {
      const table = String(t.id);
      await api.PUT('/api/v1/cam-tables/{table}', { params: { path: { table } }, body: bodyOf(t, draft) });
      const one = await api.GET('/api/v1/cam-tables/{table}', { params: { path: { table } } });
      setT(one);
      meta.current = one;
      setHist((h) => h && record(h, draftOf(one)));
      setError(null);
    } catch (e) {
      if (e instanceof ApiError && e.status === 422) setFields(fieldsOf(e));
      setError(errorText(e));
      throw e;
    }
  };
  // A table that axes are coupled through: say first that this is an online change, whom it
  // reaches and by which mode (the mode in force, read from the server now).
  const save = async () => {
    if (!t) return;
    const slaves = slavesOf(statuses.get(), t.id);
    if (!slaves.length) return doSave();
    try {
      const mode = await api.GET('/api/v1/cam-tables/{table}/online-change-mode', { params: { path: { table: String(t.id) } } });
      setAsked({ text: onlineChangeText(slaves, mode), slaves });
    } catch (e) {
      setError(errorText(e));
      throw e;
    }
  };
  const remove = async () => {
    if (!t || !confirm(`Delete cam table '${t.name}'?`)) return;
    try {
      await api.DELETE('/api/v1/cam-tables/{table}', { params: { path: { table: String(t.id) } } });
      navigate({ page: 'cams' });
    } catch (e) {
      setError(errorText(e));
      throw e;
    }
  };

  if (!t || !draft || !hist) {
    return (
      <div class="page">
        <ErrorBanner error={error} onClose={() => setError(null)} />
        <p class="muted">Loading…</p>
      </div>
    );
  }
  const motion = t.table_type === 'motion_function';
  const errs = errorsByRow(fields);
  const warnByRow = showWarnings ? warningsByRow(warnings) : new Map();
  const state: LiveState = pending ? 'pending' : liveState;
  /** The values shown are the last valid state's, not the table as edited (dimmed). */
  const old = liveState === 'invalid' || liveState === 'error';
  const what = motion ? 'point' : 'row';
  return (
    <div class="page cam-editor" id="cam" data-cam={t.name} data-version={t.version} data-dirty={dirty ? '1' : '0'}>
      <div class="page-head cam-head">
        <h2>
          <a href="#/cams">Cam tables</a> / {t.name}{' '}
          <span class="muted small">
            id {t.id}, version {t.version}
            {dirty ? ', edited' : ''}
          </span>
        </h2>
        <div class="cam-tools">
          <button type="button" class="btn" name="undo" title="Undo (Ctrl+Z)" disabled={!canUndo(hist)} onClick={() => setHist(undo(hist))}>
            ↶ Undo
          </button>
          <button type="button" class="btn" name="redo" title="Redo (Ctrl+Shift+Z, Ctrl+Y)" disabled={!canRedo(hist)} onClick={() => setHist(redo(hist))}>
            ↷ Redo
          </button>
          <ActionButton kind="primary" name="save-cam" onClick={save} disabled={!dirty || !!asked}>
            Save
          </ActionButton>
          <ActionButton kind="danger" name="delete-cam" onClick={remove}>
            Delete
          </ActionButton>
        </div>
      </div>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      {asked && (
        <div class="banner banner-warn cam-confirm" role="alertdialog" data-testid="online-change-confirm">
          <span data-testid="online-change-text">{asked.text}</span>
          <span class="cam-confirm-buttons">
            <ActionButton kind="primary" name="confirm-save-cam" onClick={doSave}>
              Save: online change
            </ActionButton>
            <button type="button" class="btn" name="cancel-save-cam" onClick={() => setAsked(null)}>
              Cancel
            </button>
          </span>
        </div>
      )}
      <div class="cam-grid">
        <div class="cam-col">
          <Panel
            title="Over the master"
            class={`cam-plot ${old ? 'cam-stale' : ''}`}
            actions={
              <>
                {!old && warnings.length > 0 && (
                  <span class="cam-jumps small" data-testid="cam-jumps" title={warnings.map((d) => discontinuityText(d, what)).join('\n')}>
                    ⚠ {warnings.length} jump{warnings.length > 1 ? 's' : ''} (see Warnings)
                  </span>
                )}
                <span class="cam-live small" data-testid="cam-live" data-analysis={state}>
                  {state === 'pending'
                    ? 'analysing the edit…'
                    : state === 'current'
                      ? dirty
                        ? 'the table as edited (not saved)'
                        : 'the saved table'
                      : state === 'invalid'
                        ? 'invalid: showing the last valid state'
                        : 'no answer: showing the last valid state'}
                </span>
              </>
            }
          >
            {(liveState === 'invalid' || liveState === 'error') && (
              <div class="banner banner-warn cam-stale-note" data-testid="cam-stale-note">
                {liveState === 'invalid'
                  ? `The table as edited is invalid (${errs.rows.size ? `see the marked ${what}s` : liveText}); the plots, values and warnings show the last valid state.`
                  : `The server did not analyse the edit (${liveText}); the plots, values and warnings show the last valid state.`}
              </div>
            )}
            <div ref={chartEl} class="cam-chart" data-chart="cam" />
          </Panel>
          <Panel
            title={motion ? 'Points (motion function)' : 'Rows (position table)'}
            class="cam-table"
            actions={
              <label class="check">
                <input type="checkbox" name="periodic" checked={draft.periodic} onChange={(e) => change((d) => ({ ...d, periodic: (e.target as HTMLInputElement).checked }))} /> periodic
              </label>
            }
          >
            {errs.table.length > 0 && (
              <div class="field-error cam-table-errors" role="alert" data-testid="cam-table-errors">
                {errs.table.join('; ')}
              </div>
            )}
            {motion ? (
              <PointsEditor rows={draft.points} errs={errs.rows} warn={warnByRow} edit={editPoint} change={change} settle={() => setHist((h) => h && settle(h))} />
            ) : (
              <RowsEditor name={t.name} csv={draft.csv} errs={errs.rows} change={change} settle={() => setHist((h) => h && settle(h))} />
            )}
          </Panel>
        </div>
        <div class="cam-col cam-side">
          <Panel title="Characteristic values (per master unit)" class={`cam-charac-panel ${old ? 'cam-old' : ''}`}>
            {result ? (
              <table class="grid cam-charac">
                <tbody>
                  {CHARACTERISTICS.map(([v, at, label]) => (
                    <tr key={label}>
                      <th>{label}</th>
                      <td class="num" data-charac={v}>
                        {sig(result.characteristics[v] as number)}
                      </td>
                      <td class="muted">{at ? `at master ${sig(result.characteristics[at] as number, 5)}` : ''}</td>
                    </tr>
                  ))}
                </tbody>
              </table>
            ) : (
              <p class="muted">Waiting for the server's analysis…</p>
            )}
          </Panel>
          <Panel title="Warnings" class={`cam-warnings ${old ? 'cam-old' : ''}`}>
            {!result ? (
              <p class="muted">—</p>
            ) : warnings.length === 0 ? (
              <p class="muted" data-testid="cam-no-warnings">
                No jumps: every law meets the boundary conditions of its neighbours.
              </p>
            ) : (
              <ul class="cam-warning-list" data-testid="cam-warnings">
                {warnings.map((d) => (
                  <li key={`${d.index}-${d.quantity}-${d.wrap}`} data-warning-index={d.index} data-quantity={d.quantity}>
                    {discontinuityText(d, what)}
                  </li>
                ))}
              </ul>
            )}
            {result && warnings.length > 0 && <p class="muted small">A slave coupled through the table jumps there (the table can still be saved).</p>}
          </Panel>
          <OnlineChangePanel table={t} />
        </div>
      </div>
    </div>
  );
}

const NUMBER_COLS = [
  ['master_pos', 'Master'],
  ['slave_pos', 'Slave'],
  ['slave_velo', 'Velocity'],
  ['slave_acc', 'Acceleration'],
  ['slave_jerk', 'Jerk'],
] as const;

function PointsEditor({ rows, errs, warn, edit, change, settle: settleNow }: {
  rows: PointRow[];
  errs: Map<number, string[]>;
  warn: Map<number, { quantity: string; wrap: boolean }[]>;
  edit: (i: number, patch: Partial<PointRow>, key?: string | null) => void;
  change: (f: (d: Draft) => Draft, key?: string | null) => void;
  settle: () => void;
}) {
  return (
    <>
      <div class="table-scroll">
        <table class="grid cam-points">
          <thead>
            <tr>
              <th>#</th>
              {NUMBER_COLS.map(([, l]) => (
                <th key={l}>{l}</th>
              ))}
              <th>Point type</th>
              <th>Law to the next point</th>
              <th />
            </tr>
          </thead>
          {/* leaving a field ends its typing: the next keystrokes there are a new undo step */}
          <tbody onFocusOut={settleNow}>
            {rows.map((r, i) => {
              const err = errs.get(i)?.join('; ') ?? '';
              const w = warn.get(i) ?? [];
              const wtext = w.map((d) => `${d.quantity} jump${d.wrap ? ' at the periodic wrap' : ''}`).join(', ');
              return (
                <tr key={i} data-point={i + 1} class={`${err ? 'has-error' : ''} ${w.length ? 'has-warning' : ''}`} data-warning={w.map((d) => d.quantity).join(',') || undefined}>
                  <td class="cam-idx">
                    {i + 1}
                    {w.length > 0 && (
                      <span class="cam-warn-mark" title={wtext} aria-label={wtext}>
                        ⚠
                      </span>
                    )}
                  </td>
                  {NUMBER_COLS.map(([k]) => (
                    <td key={k}>
                      <NumberInput name={`${k}-${i + 1}`} value={r[k]} onValue={(v) => edit(i, { [k]: v }, `${k}-${i}`)} />
                    </td>
                  ))}
                  <td>
                    <select name={`point_type-${i + 1}`} value={r.point_type} onChange={(e) => edit(i, { point_type: (e.target as HTMLSelectElement).value as PointRow['point_type'] })}>
                      {POINT_TYPES.map((p) => (
                        <option key={p} value={p}>
                          {p}
                        </option>
                      ))}
                    </select>
                  </td>
                  <td>
                    {i < rows.length - 1 ? (
                      <select name={`function_type-${i + 1}`} value={r.function_type} onChange={(e) => edit(i, { function_type: (e.target as HTMLSelectElement).value as PointRow['function_type'] })}>
                        {LAWS.map((l) => (
                          <option key={l.type} value={l.type}>
                            {l.label}
                          </option>
                        ))}
                      </select>
                    ) : (
                      <span class="muted">(last point)</span>
                    )}
                    {err && (
                      <div class="field-error" role="alert">
                        {err}
                      </div>
                    )}
                    {w.length > 0 && <div class="cam-warn-text">{wtext}</div>}
                  </td>
                  <td>
                    <button
                      type="button"
                      class="btn btn-plain small"
                      name={`remove-point-${i + 1}`}
                      title="remove this point"
                      disabled={rows.length <= 2}
                      onClick={() => change((d) => ({ ...d, points: d.points.filter((_, k) => k !== i) }))}
                    >
                      −
                    </button>
                  </td>
                </tr>
              );
            })}
          </tbody>
        </table>
      </div>
      <button type="button" class="btn btn-plain" name="add-point" onClick={() => change((d) => ({ ...d, points: [...d.points, nextRow(d.points)] }))}>
        + Point
      </button>
    </>
  );
}

function RowsEditor({ name, csv, errs, change, settle: settleNow }: {
  name: string;
  csv: string;
  errs: Map<number, string[]>;
  change: (f: (d: Draft) => Draft, key?: string | null) => void;
  settle: () => void;
}) {
  const file = useRef<HTMLInputElement>(null);
  const count = useMemo(() => csvToRows(csv).length, [csv]);
  const rowErrors: ComponentChildren[] = [...errs.entries()].map(([i, m]) => (
    <li key={i} data-row={i}>
      row {i + 1}: {m.join('; ')}
    </li>
  ));
  const importFile = async (f: File | undefined) => {
    if (!f) return;
    const text = await f.text();
    change((d) => ({ ...d, csv: text }));
  };
  return (
    <>
      <Field label={`Rows as CSV (master,slave per line; ${count} rows)`} name="rows">
        <textarea name="rows-csv" rows={10} value={csv} onInput={(e) => change((d) => ({ ...d, csv: (e.target as HTMLTextAreaElement).value }), 'csv')} onBlur={settleNow} />
      </Field>
      {rowErrors.length > 0 && (
        <ul class="field-error cam-row-errors" role="alert" data-testid="cam-row-errors">
          {rowErrors}
        </ul>
      )}
      <div class="form-row">
        <button type="button" class="btn btn-plain" name="import-csv" onClick={() => file.current?.click()}>
          Import CSV…
        </button>
        <input ref={file} type="file" accept=".csv,text/csv,text/plain" name="csv-file" hidden onChange={(e) => void importFile((e.target as HTMLInputElement).files?.[0])} />
        <button type="button" class="btn btn-plain" name="export-csv" onClick={() => download(`${name}.csv`, rowsToCsv(csvToRows(csv)))}>
          Export CSV
        </button>
      </div>
    </>
  );
}

/**
 * The axes coupled through this table now (live MC_CamInfo) and the table's online-change mode
 * (MC_SetCamOnlineChangeMode): how a save reaches them. Its fields keep their own undo.
 */
function OnlineChangePanel({ table: t }: { table: CamTableResource }) {
  const st = useStore(statuses);
  const slaves = slavesOf(st, t.id);
  const [mode, setMode] = useState<OnlineChange | null>(null);
  const [form, setForm] = useState<OnlineChange | null>(null);
  const [errors, setErrors] = useState<Record<string, string>>({});
  const [banner, setBanner] = useState<string | null>(null);
  const [pos, setPos] = useState('0');
  const load = () =>
    api.GET('/api/v1/cam-tables/{table}/online-change-mode', { params: { path: { table: String(t.id) } } }).then(
      (m) => {
        setMode(m);
        setForm(m);
        setPos(String(m.activation_position ?? 0));
      },
      (e) => setBanner(errorText(e)),
    );
  useEffect(() => void load(), [t.id]);
  const apply = async (body: OnlineChange) => {
    setErrors({});
    setBanner(null);
    try {
      const m = await api.PUT('/api/v1/cam-tables/{table}/online-change-mode', { params: { path: { table: String(t.id) } }, body });
      setMode(m);
      setForm(m);
      setPos(String(m.activation_position ?? 0));
    } catch (e) {
      setErrors(fieldsOf(e));
      setBanner(errorText(e));
      throw e;
    }
  };
  const posNum = Number(pos.trim().replace(',', '.'));
  const wanted: OnlineChange | null = form && { ...form, activation_position: pos.trim() === '' ? 0 : posNum };
  const changed = !!(wanted && mode && JSON.stringify(wanted) !== JSON.stringify({ ...mode, activation_position: mode.activation_position ?? 0 }));
  const set = (patch: Partial<OnlineChange>) => form && setForm({ ...form, ...patch });
  const queued = slaves.some((s) => s.queued);
  return (
    <Panel title="Online change" class="cam-online">
      <div data-testid="cam-slaves" data-slaves={slaves.map((s) => s.axis).join(',')}>
        {slaves.length === 0 ? (
          <p class="muted">No axis is coupled through this table: a save is in force for the next coupling.</p>
        ) : (
          <>
            <p>Coupled through this table now:</p>
            <ul class="cam-slaves">
              {slaves.map((s) => (
                <li key={s.axis} data-slave={s.axis}>
                  <a href={href({ page: 'axis', axis: s.axis, tab: 'coupling' })}>{s.axis}</a>
                  {s.master && <span class="muted"> (master {s.master})</span>}
                  <Led on={s.queued} label="data queued" tone="amber" title="Written data waits to reach this slave (cam_data_queued)" />
                </li>
              ))}
            </ul>
          </>
        )}
      </div>
      <div data-native-undo="1">
        <h4 class="sub">Online-change mode (MC_SetCamOnlineChangeMode)</h4>
        <ErrorBanner error={banner} onClose={() => setBanner(null)} />
        {!form ? (
          <p class="muted">Loading…</p>
        ) : (
          <div class="form-grid cam-mode-form">
            <ModeSelect label="Activation" k="activation_mode" options={ONLINE_MODES} form={form} set={set} errors={errors} />
            {takesActivationPosition(form.activation_mode) && (
              <Field label="Activation position" name="activation_position" error={errors.activation_position}>
                <NumberInput name="online-activation-position" value={pos} onValue={setPos} />
              </Field>
            )}
            <ModeSelect label="Master scaling mode" k="master_scaling_mode" options={SCALING_MODES} form={form} set={set} errors={errors} />
            <ModeSelect label="Slave scaling mode" k="slave_scaling_mode" options={SCALING_MODES} form={form} set={set} errors={errors} />
            <p class="muted small cam-mode-text" data-testid="online-mode-text">
              {mode ? `In force: ${mode.activation_mode} — written data reaches a coupled slave ${ONLINE_MODE_TEXT[mode.activation_mode ?? 'instantaneous']}.` : ''}
              {changed ? ' (Changed here, not applied yet.)' : ''}
            </p>
            <div class="form-actions">
              <ActionButton kind="primary" name="apply-online-mode" disabled={!changed} onClick={() => apply(wanted!)}>
                Apply mode
              </ActionButton>
              {queued && (
                <ActionButton kind="warn" name="delete-queued-data" title="MC_SetCamOnlineChangeMode DELETEQUEUEDDATA: drop written data that has not reached its slaves (the mode stays)" onClick={() => apply({ activation_mode: 'delete_queued_data' })}>
                  Drop queued data
                </ActionButton>
              )}
            </div>
          </div>
        )}
      </div>
    </Panel>
  );
}

/** A select of the online-change mode form (named `online-…` after its field), with its error. */
function ModeSelect<K extends 'activation_mode' | 'master_scaling_mode' | 'slave_scaling_mode'>({ label, k, options, form, set, errors }: {
  label: string;
  k: K;
  options: readonly NonNullable<OnlineChange[K]>[];
  form: OnlineChange;
  set: (patch: Partial<OnlineChange>) => void;
  errors: Record<string, string>;
}) {
  return (
    <Field label={label} name={k} error={errors[k]}>
      <select name={`online-${k.replace(/_/g, '-')}`} value={form[k]} title={form[k]} onChange={(e) => set({ [k]: (e.target as HTMLSelectElement).value })}>
        {options.map((m) => (
          <option key={m} value={m}>
            {m}
          </option>
        ))}
      </select>
    </Field>
  );
}
