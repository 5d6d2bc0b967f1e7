// MC_AxisParameter pages: grouped, with units, ranges and help; each value side by side as
// configured (the axis configuration's start-up value), persistent and online (in force, the
// one edited here); edits are shown as a diff (old → new) and applied one PUT at a time; the
// server's validation errors appear at the row.
import type { ComponentChildren } from 'preact';
import { useEffect, useMemo, useState } from 'preact/hooks';
import { NOT_A_NUMBER } from '../../api/problem';
import { api } from '../../api/client';
import type { AxisResource, ParamGroup, ParameterResource, ParamValue } from '../../api/types';
import { ErrorBanner, errorText, fieldsOf, useOnline } from '../shared/common';
import { inputNum } from '../../format';
import { ApiError } from '../../api/problem';
import { errorInfo } from '../../api/errors';
import { refreshAxes } from '../../services';

export const GROUPS: { key: ParamGroup; label: string }[] = [
  { key: 'dynamics', label: 'Dynamics' },
  { key: 'manual', label: 'Manual (jog)' },
  { key: 'limits', label: 'Limits' },
  { key: 'monitoring', label: 'Monitoring' },
  { key: 'homing', label: 'Homing' },
  { key: 'encoder', label: 'Encoder' },
  { key: 'drive', label: 'Drive' },
  { key: 'controller', label: 'Controller' },
  { key: 'coupling', label: 'Coupling' },
  { key: 'system', label: 'System' },
  { key: 'status', label: 'Status (read-only)' },
];

/** Range text of a descriptor: "> 0", "0 … 1", "≥ 0", "any". min/max are null when unbounded. */
export function rangeText(p: Pick<ParameterResource, 'min' | 'max' | 'min_exclusive' | 'type'>): string {
  const min = p.min as number | null;
  const max = p.max as number | null;
  if (p.type === 'bool') return 'true / false';
  const lo = min === null || min === undefined ? null : min;
  const hi = max === null || max === undefined ? null : max;
  if (lo === null && hi === null) return 'any';
  if (hi === null) return `${p.min_exclusive ? '>' : '≥'} ${lo}`;
  if (lo === null) return `≤ ${hi}`;
  return `${p.min_exclusive ? '>' : ''}${lo} … ${hi}`;
}

export function valueText(v: ParamValue | undefined | null): string {
  if (v === undefined || v === null) return '';
  if (typeof v === 'boolean') return v ? 'true' : 'false';
  return inputNum(v);
}

/** The edited text as the value to send: booleans for BOOL, numbers otherwise. */
export function parseValue(p: ParameterResource, text: string): ParamValue | null {
  if (p.type === 'bool') return text === 'true' ? true : text === 'false' ? false : null;
  const t = text.trim().replace(',', '.');
  if (t === '') return null;
  const v = Number(t);
  return Number.isNaN(v) ? null : v;
}

/** A parameter's name with a break opportunity before each word (AxisEncoder·Homing·Calib·Value). */
export function camelBreaks(name: string): ComponentChildren[] {
  return name.split(/(?=[A-Z][a-z])/).flatMap((w, i) => (i ? [<wbr />, w] : [w]));
}

export interface Change {
  param: ParameterResource;
  old: ParamValue;
  next: ParamValue;
}

export function diff(list: ParameterResource[], edits: Record<number, string>): { changes: Change[]; invalid: Record<number, string> } {
  const changes: Change[] = [];
  const invalid: Record<number, string> = {};
  for (const p of list) {
    const text = edits[p.number];
    if (text === undefined) continue;
    const next = parseValue(p, text);
    if (next === null) {
      invalid[p.number] = p.type === 'bool' ? 'true or false' : NOT_A_NUMBER;
      continue;
    }
    if (next !== p.value) changes.push({ param: p, old: p.value, next });
  }
  return { changes, invalid };
}

export function ParametersTab({ axis: a }: { axis: AxisResource }) {
  const axis = a.config.name;
  const [list, setList] = useState<ParameterResource[] | null>(null);
  const [edits, setEdits] = useState<Record<number, string>>({});
  const [rowErrors, setRowErrors] = useState<Record<number, string>>({});
  const [filter, setFilter] = useState('');
  const [group, setGroup] = useState<ParamGroup | 'all'>('all');
  const [persistent, setPersistent] = useState(false);
  const [review, setReview] = useState(false);
  const [applying, setApplying] = useState(false);
  const [error, setError] = useState<string | null>(null);
  const [message, setMessage] = useState<string | null>(null);
  const [messageError, setMessageError] = useState(false);
  const [openHelp, setOpenHelp] = useState<number | null>(null);
  const [aliases, setAliases] = useState(false);
  const online = useOnline();

  const load = () =>
    api.GET('/api/v1/axes/{axis}/parameters', { params: { path: { axis } } }).then(setList, (e) => setError(errorText(e)));
  useEffect(() => {
    void load();
  }, [axis]);

  const { changes, invalid } = useMemo(() => diff(list ?? [], edits), [list, edits]);
  const f = filter.trim().toLowerCase();
  // Aliases (PLCopen names sharing a TwinCAT entry's storage) only when asked for (or edited);
  // a search that matches hidden ones says how many.
  const isAlias = (p: ParameterResource) => p.storage !== 0 && p.storage !== p.number;
  const matching = (list ?? []).filter(
    (p) =>
      (group === 'all' || p.group === group) &&
      (!f || p.name.toLowerCase().includes(f) || String(p.number).includes(f) || p.help.toLowerCase().includes(f)),
  );
  const shown = matching.filter((p) => aliases || !isAlias(p) || edits[p.number] !== undefined);
  const hiddenAliases = matching.length - shown.length;

  const apply = async () => {
    setApplying(true);
    setError(null);
    setMessage(null);
    const errs: Record<number, string> = {};
    let ok = 0;
    const remaining: Record<number, string> = { ...edits };
    for (const c of changes) {
      try {
        const r = await api.PUT('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis, parameter: String(c.param.number) } }, body: { value: c.next, persistent } });
        ok++;
        delete remaining[c.param.number];
        setList((l) => l && l.map((p) => (p.number === r.number ? r : p)));
      } catch (e) {
        const fields = fieldsOf(e);
        const id = e instanceof ApiError ? e.problem?.error_id : undefined;
        errs[c.param.number] = (fields.value ?? errorText(e)) + (id ? ` (${errorInfo(id).hex} ${errorInfo(id).code})` : '');
      }
    }
    setEdits(remaining);
    setRowErrors(errs);
    setApplying(false);
    setReview(false);
    const failed = Object.keys(errs).length;
    const refused = changes
      .filter((c) => errs[c.param.number])
      .map((c) => `${c.param.name} (${errs[c.param.number]})`)
      .join('; ');
    setMessage(`${ok} parameter${ok === 1 ? '' : 's'} written${persistent ? ' persistently' : ''}.${failed ? ` Refused: ${refused}.` : ''}`);
    setMessageError(failed > 0);
    // Aliases and dependent entries may have changed too.
    void load();
    void refreshAxes();
  };

  if (!list) return <div class="muted">{error ?? 'Loading parameters…'}</div>;

  return (
    <div class="params">
      <ErrorBanner error={error} onClose={() => setError(null)} />
      <div class="toolbar">
        <input class="filter" type="search" name="filter" placeholder="filter: name, number, text" value={filter} onInput={(e) => setFilter((e.target as HTMLInputElement).value)} />
        <label class="check" title="PLCopen names that share the storage of a TwinCAT entry (e.g. MaxVelocityAppl → #1003)">
          <input type="checkbox" name="aliases" checked={aliases} onChange={(e) => setAliases((e.target as HTMLInputElement).checked)} /> aliases
        </label>
        <span class="muted small">
          {shown.length} of {list.length}
          {f && hiddenAliases > 0 && !aliases ? ` · ${hiddenAliases} alias${hiddenAliases > 1 ? 'es' : ''} match (tick “aliases”)` : ''}
        </span>
        <div class="seg">
          <button type="button" class={`seg-btn ${group === 'all' ? 'active' : ''}`} onClick={() => setGroup('all')}>
            All
          </button>
          {GROUPS.filter((g) => list.some((p) => p.group === g.key)).map((g) => (
            <button type="button" class={`seg-btn ${group === g.key ? 'active' : ''}`} data-group={g.key} onClick={() => setGroup(g.key)}>
              {g.label.replace(' (read-only)', '')}
            </button>
          ))}
        </div>
      </div>
      <div class="toolbar apply-bar">
        <label class="check" title="MC_WriteParameterPersistent: kept across restarts until the axis configuration is replaced">
          <input type="checkbox" name="persistent" checked={persistent} onChange={(e) => setPersistent((e.target as HTMLInputElement).checked)} /> persistent
        </label>
        <span class="muted" data-testid="change-count">
          {changes.length} change{changes.length === 1 ? '' : 's'}
          {Object.keys(invalid).length ? ` · ${Object.keys(invalid).length} invalid` : ''}
        </span>
        <button type="button" class="btn btn-primary" name="review" disabled={changes.length === 0 || applying || !online} onClick={() => setReview(true)}>
          Review & apply…
        </button>
        <button
          type="button"
          class="btn"
          name="discard"
          disabled={Object.keys(edits).length === 0}
          onClick={() => {
            setEdits({});
            setRowErrors({});
          }}
        >
          Discard
        </button>
        {message && (
          <span class={`msg ${messageError ? 'text-error' : ''}`} data-testid="apply-message">
            {message}
          </span>
        )}
      </div>

      {review && (
        <div class="diff" data-testid="param-diff">
          <h4>
            Apply {changes.length} change{changes.length === 1 ? '' : 's'} to axis {axis}
            {persistent ? ' (persistent)' : ' (until restart)'}?
          </h4>
          <table class="grid">
            <thead>
              <tr>
                <th class="r">No.</th>
                <th>Name</th>
                <th class="r">Old</th>
                <th></th>
                <th class="r">New</th>
                <th>Unit</th>
              </tr>
            </thead>
            <tbody>
              {changes.map((c) => (
                <tr key={c.param.number} data-param={c.param.name}>
                  <td class="r mono">{c.param.number}</td>
                  <td>{c.param.name}</td>
                  <td class="r mono old">{valueText(c.old)}</td>
                  <td>→</td>
                  <td class="r mono new">{valueText(c.next)}</td>
                  <td>{c.param.unit_text}</td>
                </tr>
              ))}
            </tbody>
          </table>
          <div class="form-actions">
            <button type="button" class="btn btn-primary" name="apply" disabled={applying || !online} onClick={() => void apply()}>
              {applying ? 'Applying…' : 'Apply'}
            </button>
            <button type="button" class="btn" name="cancel" onClick={() => setReview(false)}>
              Cancel
            </button>
          </div>
        </div>
      )}

      {/* On a phone the table keeps readable columns and scrolls sideways in its box. */}
      <div class="table-scroll">
        <table class="grid param-table">
          <colgroup>
            <col class="c-no" />
            <col class="c-name" />
            <col class="c-conf" />
            <col class="c-pers" />
            <col class="c-value" />
            <col class="c-unit" />
            <col class="c-range" />
          </colgroup>
          <thead>
            <tr>
              <th class="r">No.</th>
              <th>Name</th>
              <th class="r" title="the axis configuration's value: the start-up value when the configuration is (re)applied">Configured</th>
              <th class="r" title="value of the persistent overlay (MC_WriteParameterPersistent)">Persistent</th>
              <th class="r" title="the value in force (MC_ReadParameter); edit it here">Online</th>
              <th>Unit</th>
              <th>Range</th>
            </tr>
          </thead>
          {GROUPS.filter((g) => shown.some((p) => p.group === g.key)).map((g) => (
            <tbody key={g.key}>
              <tr class="group-row">
                <th colSpan={7}>{g.label}</th>
              </tr>
              {shown
                .filter((p) => p.group === g.key)
                .map((p) => {
                  const edited = edits[p.number] !== undefined && edits[p.number] !== valueText(p.value);
                  const err = rowErrors[p.number] ?? invalid[p.number];
                  const ro = p.read_only || p.group === 'status';
                  const configured = p.configured_value ?? null;
                  const pers = p.persistent_value ?? null;
                  // Highlighted where a value differs from the configured one.
                  const differs = (v: ParamValue | null) => configured !== null && v !== null && valueText(v) !== valueText(configured);
                  return (
                      <tr key={p.number} class={`${edited ? 'edited' : ''} ${err ? 'row-error' : ''} ${ro ? 'ro' : ''}`} data-param={p.name}>
                        <td class="r mono">{p.number}</td>
                        <td class="pname" onClick={() => setOpenHelp(openHelp === p.number ? null : p.number)} title={p.help}>
                          <span class="pname-text">{camelBreaks(p.name)}</span>
                          {p.storage && p.storage !== p.number ? <span class="muted small"> → #{p.storage}</span> : null}
                          <div class={`help ${openHelp === p.number ? 'help-open' : 'help-short'}`}>{p.help}</div>
                        </td>
                        <td class="r mono small" data-col="configured">{valueText(configured)}</td>
                        <td class={`r mono small ${differs(pers) ? 'pv-differs' : ''}`} data-col="persistent">
                          {valueText(pers)}
                        </td>
                        <td class={`r value-cell ${differs(p.value) ? 'pv-differs' : ''}`} data-col="online">
                          {ro ? (
                            <span class="mono">{valueText(p.value)}</span>
                          ) : p.type === 'bool' ? (
                            <select
                              name={`param-${p.number}`}
                              value={edits[p.number] ?? valueText(p.value)}
                              onChange={(e) => setEdits({ ...edits, [p.number]: (e.target as HTMLSelectElement).value })}
                            >
                              <option value="true">true</option>
                              <option value="false">false</option>
                            </select>
                          ) : (
                            <input
                              class="num"
                              type="text"
                              inputMode="decimal"
                              name={`param-${p.number}`}
                              value={edits[p.number] ?? valueText(p.value)}
                              onInput={(e) => setEdits({ ...edits, [p.number]: (e.target as HTMLInputElement).value })}
                            />
                          )}
                          {err && (
                            <div class="field-error" role="alert">
                              {err}
                            </div>
                          )}
                        </td>
                        <td>{p.unit_text}</td>
                        <td class="mono small">{rangeText(p)}</td>
                      </tr>
                  );
                })}
            </tbody>
          ))}
        </table>
      </div>
    </div>
  );
}
