// Cam tables (TwinCAT NC Camming): the list, and one table — its plot (position, velocity,
// acceleration, jerk over the master, sampled by the server), its characteristic values, and
// its points (motion functions: law and point type per segment) or rows (position tables: CSV
// import and export). Saving sends the whole table; the server validates it and answers per
// field (`points[2].point_type` …), shown at the row.
import { useEffect, useRef, useState } from 'preact/hooks';
import { del, enc, get, post, put } from '../api/rest';
import type { CamCharacteristics, CamTableBody, CamTableResource, CamValuesResource } from '../api/types';
import { CamChart } from '../cams/chart';
import { LAWS, POINT_TYPES, csvToRows, increment, nextRow, pointsOf, rowsOf, rowsToCsv, type PointRow } from '../cams/data';
import { navigate } from '../router';
import { ActionButton, ErrorBanner, Field, NumberInput, Panel, download, errorText, fieldsOf } from './common';
import { sig } from '../format';


/** A periodic motion function to start from: up and down again, at rest at both ends. */
function starter(name: string): CamTableBody {
  const p = (i: number, x: number, y: number) => ({ point_index: i, function_type: 'polynom5' as const, point_type: 'rest' as const, master_pos: x, slave_pos: y });
  return { name, table_type: 'motion_function', periodic: true, points: [p(1, 0, 0), p(2, 180, 100), p(3, 360, 0)] };
}

export function CamListPage() {
  const [tables, setTables] = useState<CamTableResource[] | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [name, setName] = useState('');
  const [fields, setFields] = useState<Record<string, string>>({});
  const load = () => get<CamTableResource[]>('/cam-tables').then(setTables, (e) => setError(errorText(e)));
  useEffect(() => void load(), []);
  const create = async () => {
    try {
      const t = await post<CamTableResource>('/cam-tables', starter(name.trim()));
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
                    <a href={`#/cams/${enc(t.name)}`}>{t.name}</a>
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
        )}
      </Panel>
      <Panel title="New motion function">
        <div class="form-row">
          <Field label="Name" name="name" error={fields.name}>
            <input type="text" name="cam-name" value={name} onInput={(e) => setName((e.target as HTMLInputElement).value)} />
          </Field>
          <ActionButton kind="primary" name="create-cam" onClick={create} disabled={!name.trim()}>
            Create
          </ActionButton>
        </div>
        <p class="muted small">Starts as a periodic Polynom 5 up and down again; edit its points on the next page.</p>
      </Panel>
    </div>
  );
}

const CHARACTERISTICS: [keyof CamCharacteristics, keyof CamCharacteristics, string][] = [
  ['slave_velo_max', 'm_pos_at_s_velo_max', 'Velocity max'],
  ['slave_velo_min', 'm_pos_at_s_velo_min', 'Velocity min'],
  ['slave_acc_max', 'm_pos_at_s_acc_max', 'Acceleration max'],
  ['slave_acc_min', 'm_pos_at_s_acc_min', 'Acceleration min'],
  ['slave_jerk_max', 'm_pos_at_s_jerk_max', 'Jerk max'],
  ['slave_jerk_min', 'm_pos_at_s_jerk_min', 'Jerk min'],
];

export function CamPage({ table }: { table: string }) {
  const [t, setT] = useState<CamTableResource | null>(null);
  const [rows, setRows] = useState<PointRow[]>([]);
  const [periodic, setPeriodic] = useState(false);
  const [csv, setCsv] = useState('');
  const [values, setValues] = useState<CamValuesResource | null>(null);
  const [charac, setCharac] = useState<CamCharacteristics | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [fields, setFields] = useState<Record<string, string>>({});
  const [dirty, setDirty] = useState(false);
  const chartEl = useRef<HTMLDivElement>(null);
  const chart = useRef<CamChart | null>(null);

  const load = async () => {
    try {
      const one = await get<CamTableResource>(`/cam-tables/${enc(table)}`);
      setT(one);
      setRows(rowsOf(one.points ?? []));
      setPeriodic(one.periodic);
      setCsv(one.rows ? rowsToCsv(one.rows) : '');
      setDirty(false);
      const inc = increment(one);
      const [v, c] = await Promise.all([
        get<CamValuesResource>(`/cam-tables/${enc(table)}/values?start=${one.master_start}&end=${one.master_end}&increment=${inc}`),
        get<CamCharacteristics>(`/cam-tables/${enc(table)}/characteristics`),
      ]);
      setValues(v);
      setCharac(c);
    } catch (e) {
      setError(errorText(e));
    }
  };
  useEffect(() => void load(), [table]);
  useEffect(() => {
    if (!chartEl.current || !values) return;
    chart.current?.destroy();
    chart.current = new CamChart(chartEl.current, values.columns, values.rows);
    return () => {
      chart.current?.destroy();
      chart.current = null;
    };
  }, [values]);

  const edit = (i: number, patch: Partial<PointRow>) => {
    setRows(rows.map((r, k) => (k === i ? { ...r, ...patch } : r)));
    setDirty(true);
  };
  const save = async () => {
    if (!t) return;
    const body: CamTableBody =
      t.table_type === 'motion_function'
        ? { id: t.id, name: t.name, table_type: t.table_type, periodic, points: pointsOf(rows) }
        : { id: t.id, name: t.name, table_type: t.table_type, periodic, interpolation: t.interpolation, rows: csvToRows(csv) };
    try {
      await put<CamTableResource>(`/cam-tables/${t.id}`, body);
      setFields({});
      setError(null);
      await load();
    } catch (e) {
      setFields(fieldsOf(e));
      setError(errorText(e));
      throw e;
    }
  };
  const remove = async () => {
    if (!t || !confirm(`Delete cam table '${t.name}'?`)) return;
    try {
      await del(`/cam-tables/${t.id}`);
      navigate({ page: 'cams' });
    } catch (e) {
      setError(errorText(e));
      throw e;
    }
  };
  const rowError = (i: number) =>
    Object.entries(fields)
      .filter(([f]) => f.startsWith(`points[${i}]`))
      .map(([f, m]) => `${f.slice(`points[${i}].`.length)}: ${m}`)
      .join('; ');

  if (!t) {
    return (
      <div class="page">
        <ErrorBanner error={error} onClose={() => setError(null)} />
        <p class="muted">Loading…</p>
      </div>
    );
  }
  return (
    <div class="page" id="cam" data-cam={t.name} data-version={t.version}>
      <h2>
        <a href="#/cams">Cam tables</a> / {t.name} <span class="muted small">id {t.id}, version {t.version}</span>
      </h2>
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <Panel title="Over the master" class="cam-plot">
        <div ref={chartEl} class="cam-chart" data-chart="cam" />
      </Panel>
      {charac && (
        <Panel title="Characteristic values (per master unit)">
          <table class="grid cam-charac">
            <tbody>
              {CHARACTERISTICS.map(([v, at, label]) => (
                <tr key={label}>
                  <th>{label}</th>
                  <td class="num" data-charac={v}>{sig(charac[v] as number)}</td>
                  <td class="muted">at master {sig(charac[at] as number)}</td>
                </tr>
              ))}
            </tbody>
          </table>
        </Panel>
      )}
      <Panel
        title={t.table_type === 'motion_function' ? 'Points (motion function)' : 'Rows (position table)'}
        actions={
          <>
            <label class="check">
              <input type="checkbox" checked={periodic} onChange={(e) => (setPeriodic((e.target as HTMLInputElement).checked), setDirty(true))} /> periodic
            </label>
            <ActionButton kind="primary" name="save-cam" onClick={save} disabled={!dirty}>
              Save
            </ActionButton>
            <ActionButton kind="danger" name="delete-cam" onClick={remove}>
              Delete
            </ActionButton>
          </>
        }
      >
        {t.table_type === 'motion_function' ? (
          <>
            <div class="table-scroll">
              <table class="grid cam-points">
                <thead>
                  <tr>
                    <th>#</th>
                    <th>Master</th>
                    <th>Slave</th>
                    <th>Velocity</th>
                    <th>Acceleration</th>
                    <th>Jerk</th>
                    <th>Point type</th>
                    <th>Law to the next point</th>
                    <th />
                  </tr>
                </thead>
                <tbody>
                  {rows.map((r, i) => {
                    const err = rowError(i);
                    return (
                      <tr key={i} data-point={i + 1} class={err ? 'has-error' : ''}>
                        <td>{i + 1}</td>
                        {(['master_pos', 'slave_pos', 'slave_velo', 'slave_acc', 'slave_jerk'] as const).map((k) => (
                          <td key={k}>
                            <NumberInput name={`${k}-${i + 1}`} value={r[k]} onValue={(v) => edit(i, { [k]: v })} />
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
                        </td>
                        <td>
                          <button type="button" class="btn btn-plain small" title="remove this point" disabled={rows.length <= 2} onClick={() => (setRows(rows.filter((_, k) => k !== i)), setDirty(true))}>
                            −
                          </button>
                        </td>
                      </tr>
                    );
                  })}
                </tbody>
              </table>
            </div>
            <button type="button" class="btn btn-plain" name="add-point" onClick={() => (setRows([...rows, nextRow(rows)]), setDirty(true))}>
              + Point
            </button>
          </>
        ) : (
          <>
            <Field label="Rows as CSV (master,slave per line)" name="rows" error={fields.rows}>
              <textarea name="rows-csv" rows={10} value={csv} onInput={(e) => (setCsv((e.target as HTMLTextAreaElement).value), setDirty(true))} />
            </Field>
            <button type="button" class="btn btn-plain" onClick={() => download(`${t.name}.csv`, csv)}>
              Export CSV
            </button>
          </>
        )}
      </Panel>
    </div>
  );
}


