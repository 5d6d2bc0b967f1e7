// Scope: pick signals of one or more axes, record N seconds at the cycle rate on the server
// (optionally from a trigger with pre-trigger), then zoom, pan, place two cursors, export CSV.
// The recordings are followed by services' `scope` (ScopeSession), not by this page: leaving
// the page to move the axis does not lose an armed or running recording.
import { useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { useStore } from '../store';
import { axes, scope, system } from '../services';
import {
  MAX_CHANNELS,
  SIGNALS,
  SIGNAL_LABEL,
  buildRequest,
  channelLabel,
  checkRecording,
  cursorReadout,
  expectedSamples,
  scaleKey,
  signalUnit,
  timeAxis,
  toCsv,
  type Edge,
  type ScopeForm,
  type Signal,
} from '../scope/data';
import { csvUrl, scopeAvailable } from '../scope/api';
import { COLORS, ScopeChart } from '../scope/chart';
import { ErrorBanner, Field, NumberInput, Panel, download, errorText, fieldsOf, parseNum, useOnline } from './common';
import { sig } from '../format';


/** Form state survives leaving the page. */
let savedForm: ScopeForm | null = null;

export function ScopePage() {
  const list = useStore(axes);
  const sys = useStore(system);
  const session = useStore(scope.state);
  const online = useOnline();
  const unitOf = (axis: string) => list.find((a) => a.config.name === axis)?.config.unit ?? '';
  const [available, setAvailable] = useState<boolean | null>(null);
  const defaultChannels = (): ScopeForm['channels'] =>
    list.length
      ? [
          { axis: list[0].config.name, signal: 'set_position' },
          { axis: list[0].config.name, signal: 'actual_position' },
          { axis: list[0].config.name, signal: 'set_velocity' },
        ]
      : [];
  const [form, setForm] = useState<ScopeForm>(
    () =>
      savedForm ?? {
        channels: defaultChannels(),
        duration_s: 2,
        trigger: { enabled: false, channel: 0, level: 0, edge: 'rising', pre_trigger_s: 0.2 },
      },
  );
  const [durationText, setDurationText] = useState(String(form.duration_s));
  const [levelText, setLevelText] = useState(String(form.trigger.level));
  const [preText, setPreText] = useState(String(form.trigger.pre_trigger_s));
  const [errors, setErrors] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const running = session.running;
  const rec = session.shown;
  const [cursors, setCursors] = useState<[number | null, number | null]>([null, null]);
  const [view, setView] = useState<{ min: number; max: number } | null>(null);
  const chartEl = useRef<HTMLDivElement>(null);
  const chart = useRef<ScopeChart | null>(null);

  const kept = session.kept;
  // The server's recordings now and every few seconds; an armed or running one is followed.
  useEffect(() => scope.attach(), []);
  useEffect(() => {
    if (online) void scopeAvailable().then(setAvailable);
  }, [online]);
  useEffect(() => {
    savedForm = form;
  }, [form]);
  useEffect(() => {
    // The axes arrive after the page: start with the first axis's positions and velocity.
    if (form.channels.length === 0 && list.length && !savedForm?.channels.length) {
      setForm({ ...form, channels: defaultChannels() });
    }
  }, [list]);

  const t = useMemo(() => (rec && rec.data ? timeAxis(rec) : null), [rec]);
  const problems = useMemo(() => (rec && rec.data ? checkRecording(rec) : []), [rec]);

  useEffect(() => {
    chart.current?.destroy();
    chart.current = null;
    setCursors([null, null]);
    setView(null);
    if (!rec || !rec.data || !t || !chartEl.current) return;
    chart.current = new ScopeChart(
      chartEl.current,
      t,
      rec.channels.map((c, i) => {
        const unit = c.unit ?? signalUnit(c.signal as Signal, unitOf(c.axis));
        return { label: channelLabel(c), unit, scale: scaleKey(c.signal as Signal, unitOf(c.axis)), values: rec.data![i] };
      }),
      { onCursors: (a, b) => setCursors([a, b]), onRange: (min, max) => setView({ min, max }) },
      rec.trigger && rec.channels[rec.trigger.channel]
        ? { scale: scaleKey(rec.channels[rec.trigger.channel].signal as Signal, unitOf(rec.channels[rec.trigger.channel].axis)), level: rec.trigger.level }
        : null,
    );
    return () => {
      chart.current?.destroy();
      chart.current = null;
    };
  }, [rec, t]);

  const readout = rec?.data && t ? cursorReadout(t, rec.data, rec.channels.map(channelLabel), cursors[0], cursors[1]) : null;

  const setChannel = (i: number, patch: Partial<ScopeForm['channels'][number]>) =>
    setForm({ ...form, channels: form.channels.map((c, j) => (j === i ? { ...c, ...patch } : c)) });

  const record = async () => {
    setError(null);
    const f: ScopeForm = {
      ...form,
      duration_s: parseNum(durationText),
      trigger: { ...form.trigger, level: parseNum(levelText), pre_trigger_s: parseNum(preText, 0) },
    };
    setForm(f);
    const { request, errors: errs } = buildRequest(f);
    setErrors(errs);
    if (!request) return;
    try {
      await scope.record(request);
    } catch (e) {
      setErrors(fieldsOf(e));
      setError(errorText(e));
    }
  };


  const cycle = rec?.cycle_time_s ?? sys?.cycle_time ?? null;
  const duration = parseNum(durationText);
  return (
    <div class="page page-scope">
      <div class="page-head">
        <h2>Scope</h2>
        <span class="muted">
          recorded on the server every cycle{cycle ? ` (${(cycle * 1000).toPrecision(3)} ms)` : ''}
          {cycle && Number.isFinite(duration) && duration > 0 ? ` · ${expectedSamples(duration, cycle)} samples` : ''}
        </span>
      </div>
      {available === false && online && (
        <div class="banner banner-warn" data-testid="scope-unavailable">
          This motiond has no scope recording endpoints yet (<code>POST /api/v1/scope/recordings</code>). Recording is disabled until the
          server provides them.
        </div>
      )}
      <ErrorBanner
        error={error ?? session.error}
        onClose={() => {
          setError(null);
          scope.clearError();
        }}
      />
      <div class="scope-grid">
        <Panel title="Recording" class="scope-setup">
          <div class="channels">
            {form.channels.map((c, i) => (
              <div class="channel" key={i} data-channel={i}>
                <span class="channel-no">
                  <span class="swatch" style={{ background: COLORS[i % COLORS.length] }} />
                  {i}
                </span>
                <select name={`channel-${i}-axis`} value={c.axis} title="axis" onChange={(e) => setChannel(i, { axis: (e.target as HTMLSelectElement).value })}>
                  {list.map((a) => (
                    <option value={a.config.name}>{a.config.name}</option>
                  ))}
                </select>
                <select name={`channel-${i}-signal`} value={c.signal} title="signal" onChange={(e) => setChannel(i, { signal: (e.target as HTMLSelectElement).value as Signal })}>
                  {SIGNALS.map((s) => (
                    <option value={s}>{SIGNAL_LABEL[s]}</option>
                  ))}
                </select>
                <button type="button" class="btn btn-small" title="remove this channel" onClick={() => setForm({ ...form, channels: form.channels.filter((_, j) => j !== i) })}>
                  ×
                </button>
                {(errors[`channels[${i}].axis`] || errors[`channels[${i}].signal`]) && (
                  <div class="field-error channel-error">{errors[`channels[${i}].axis`] ?? errors[`channels[${i}].signal`]}</div>
                )}
              </div>
            ))}
          </div>
          {errors.channels && <div class="field-error">{errors.channels}</div>}
          <button
            type="button"
            class="btn btn-small"
            name="add-channel"
            disabled={form.channels.length >= MAX_CHANNELS || list.length === 0}
            onClick={() => setForm({ ...form, channels: [...form.channels, { axis: form.channels.at(-1)?.axis ?? list[0].config.name, signal: 'actual_position' }] })}
          >
            + channel ({form.channels.length}/{MAX_CHANNELS})
          </button>
          <div class="form-grid scope-form">
            <Field label="Duration (s)" error={errors.duration_s} name="duration_s">
              <NumberInput name="duration_s" value={durationText} onValue={setDurationText} />
            </Field>
            <label class="check">
              <input
                type="checkbox"
                name="trigger-on"
                checked={form.trigger.enabled}
                onChange={(e) => setForm({ ...form, trigger: { ...form.trigger, enabled: (e.target as HTMLInputElement).checked } })}
              />{' '}
              trigger
            </label>
            {form.trigger.enabled && (
              <>
                <Field label="Trigger channel" error={errors['trigger.channel']} name="trigger.channel">
                  <select
                    name="trigger.channel"
                    value={String(form.trigger.channel)}
                    onChange={(e) => setForm({ ...form, trigger: { ...form.trigger, channel: Number((e.target as HTMLSelectElement).value) } })}
                  >
                    {form.channels.map((c, i) => (
                      <option value={String(i)}>
                        {i}: {channelLabel(c)}
                      </option>
                    ))}
                  </select>
                </Field>
                <Field label="Level" error={errors['trigger.level']} name="trigger.level">
                  <NumberInput name="trigger.level" value={levelText} onValue={setLevelText} />
                </Field>
                <Field label="Edge" error={errors['trigger.edge']} name="trigger.edge">
                  <select name="trigger.edge" value={form.trigger.edge} onChange={(e) => setForm({ ...form, trigger: { ...form.trigger, edge: (e.target as HTMLSelectElement).value as Edge } })}>
                    <option value="rising">rising</option>
                    <option value="falling">falling</option>
                    <option value="either">either</option>
                  </select>
                </Field>
                <Field label="Pre-trigger (s)" error={errors['trigger.pre_trigger_s']} name="trigger.pre_trigger_s">
                  <NumberInput name="trigger.pre_trigger_s" value={preText} onValue={setPreText} />
                </Field>
              </>
            )}
          </div>
          <div class="form-actions">
            <button type="button" class="btn btn-primary" name="record" disabled={!available || !!running || !online} onClick={() => void record()}>
              {running ? 'Recording…' : 'Record'}
            </button>
            {running && (
              <button type="button" class="btn" name="cancel-recording" disabled={!online} onClick={() => void scope.cancel()}>
                Cancel
              </button>
            )}
          </div>
          {running && (
            <div class="muted small" data-testid="recording-state" data-state={running.state} data-recording={String(running.id)}>
              #{String(running.id)}{' '}
              {running.state === 'armed'
                ? 'armed: waiting for the trigger…'
                : `${running.state}… ${running.samples_recorded ?? 0} / ${running.samples} samples`}
            </div>
          )}
        </Panel>
        <div class="scope-main">
          <div class="toolbar scope-toolbar">
            <button type="button" class="btn btn-small" name="zoom-in" disabled={!rec} onClick={() => chart.current?.zoom(0.5)} title="zoom in (half the time range)">
              zoom +
            </button>
            <button type="button" class="btn btn-small" name="zoom-out" disabled={!rec} onClick={() => chart.current?.zoom(2)} title="zoom out (twice the time range)">
              zoom −
            </button>
            <button type="button" class="btn btn-small" name="pan-left" disabled={!rec} onClick={() => chart.current?.pan(-0.25)} title="pan left (a quarter of the view)">
              ◀
            </button>
            <button type="button" class="btn btn-small" name="pan-right" disabled={!rec} onClick={() => chart.current?.pan(0.25)} title="pan right (a quarter of the view)">
              ▶
            </button>
            <button type="button" class="btn btn-small" name="full-view" disabled={!rec} onClick={() => chart.current?.reset()}>
              full view
            </button>
            <button type="button" class="btn btn-small" name="clear-cursors" disabled={!rec} onClick={() => chart.current?.clearCursors()}>
              clear cursors
            </button>
            <span class="spacer" />
            {kept.filter((r) => r.state === 'done').length > 0 && (
              <select
                name="recordings"
                title="recordings kept by the server"
                value={rec ? String(rec.id) : ''}
                onChange={(e) => {
                  const id = (e.target as HTMLSelectElement).value;
                  if (id) void scope.show(Number(id));
                }}
              >
                <option value="">recordings…</option>
                {kept
                  .filter((r) => r.state === 'done')
                  .map((r) => (
                    <option value={String(r.id)}>
                      #{String(r.id)} · {r.channels.map(channelLabel).join(', ')} · {r.duration_s ?? ''} s
                    </option>
                  ))}
              </select>
            )}
            {rec && (
              <>
                <a class="btn btn-small" href={csvUrl(rec.id)} download={`scope-${rec.id}.csv`} data-testid="csv">
                  CSV
                </a>
                <button
                  type="button"
                  class="btn btn-small"
                  disabled={!view || !t}
                  onClick={() => t && rec.data && view && download(`scope-${rec.id}-view.csv`, toCsv(t, rec.channels, rec.data, { from: view.min, to: view.max }))}
                >
                  CSV of view
                </button>
              </>
            )}
          </div>
          <div class="chart-box">
            <div ref={chartEl} class="chart" data-testid="scope-chart" />
            {!rec && <div class="chart-empty muted">No recording yet. Pick signals, set a duration and press Record; then move the axis.</div>}
          </div>
          <div class="muted small hint">
            drag: zoom to a range · wheel: zoom · shift-drag: pan · click: place cursor C1, then C2 · double-click: full view · touch: tap for a cursor,
            swipe sideways to pan, the buttons above to zoom
          </div>
          {rec && (
            <div class="muted small" data-testid="recording-info">
              recording {String(rec.id)} · {rec.samples} samples × {rec.channels.length} channels · cycle {(rec.cycle_time_s * 1000).toPrecision(3)} ms
              {rec.trigger ? ` · trigger ${channelLabel(rec.channels[rec.trigger.channel])} ${rec.trigger.edge} ${rec.trigger.level}, pre ${rec.trigger.pre_trigger_s} s` : ''}
              {problems.length ? <span class="text-error"> · {problems.join('; ')}</span> : null}
            </div>
          )}
          {readout && (cursors[0] !== null || cursors[1] !== null) && (
            <table class="grid cursor-table" data-testid="cursor-readout">
              <thead>
                <tr>
                  <th></th>
                  <th class="r">C1</th>
                  <th class="r">C2</th>
                  <th class="r">Δ (C2 − C1)</th>
                </tr>
              </thead>
              <tbody>
                <tr data-row="t">
                  <th>t (s)</th>
                  <td class="r mono">{sig(readout.t1)}</td>
                  <td class="r mono">{sig(readout.t2)}</td>
                  <td class="r mono">
                    {sig(readout.dt)}
                    {readout.dt ? <span class="muted"> ({sig(1 / readout.dt, 4)} Hz)</span> : null}
                  </td>
                </tr>
                {readout.rows.map((r, i) => (
                  <tr key={r.label} data-row={r.label}>
                    <th>
                      <span class="swatch" style={{ background: COLORS[i % COLORS.length] }} />
                      {r.label}
                    </th>
                    <td class="r mono">{sig(r.v1)}</td>
                    <td class="r mono">{sig(r.v2)}</td>
                    <td class="r mono">{sig(r.dv)}</td>
                  </tr>
                ))}
              </tbody>
            </table>
          )}
        </div>
      </div>
    </div>
  );
}
