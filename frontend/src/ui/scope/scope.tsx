// Scope: pick signals of one or more axes, record N seconds at the cycle rate on the server
// (optionally from a trigger with pre-trigger), then zoom, pan, place two cursors, export CSV.
// The recordings are followed by services' `scope` (ScopeSession), not by this page: leaving
// the page to move the axis does not lose an armed or running recording.
import { useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { axes, scope, scopeLive, system } from '../../services';
import {
  GROUP_SIGNALS,
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
  type Recording,
  type RecordingRequest,
  type ScopeForm,
  type Signal,
} from '../../scope/data';
import { csvUrl, deleteSetup, getRecording, listGroupNames, listSetups, putSetup, scopeAvailable } from '../../scope/api';
import { ScopeStack, type ChartSeries, type StackPane } from '../../scope/chart';
import { Rolling, donePolling } from '../../scope/rolling';
import {
  MAX_CHARTS,
  alignedTime,
  defaultView,
  fitView,
  fromSetup,
  mergeAligned,
  removeChannel,
  setupFieldErrors,
  setupNameError,
  toSetup,
  type Align,
  type ScopeSetupResource,
  type ScopeView,
} from '../../scope/view';
import { ErrorBanner, Field, NumberInput, Panel, download, errorText, fieldsOf, parseNum, useOnline } from '../shared/common';
import { sig } from '../../format';


/** Form state survives leaving the page. */
let savedForm: ScopeForm | null = null;
let savedView: ScopeView | null = null;
let savedSetupName: string | null = null;

/** Rolling mode goes on while another page is open (as a single recording does). */
const rolling: Rolling = new Rolling({
  record: (r) => scope.record(r),
  done: donePolling(getRecording as (id: Recording['id']) => Promise<Recording>, () => rolling.state.get().request?.duration_s ?? 1),
  cancel: () => scope.cancel(),
});

/** What the charts draw: one time axis, rows (each with its chart), the x range. */
interface Plot {
  t: number[];
  rows: (ChartSeries & { chart: number; index: number; data: (number | null)[] })[];
  limits?: { min: number; max: number };
  trigger: { chart: number; scale: string; level: number } | null;
  /** Drawn from the status stream while the recording runs (redrawn in place). */
  live?: boolean;
}

export function ScopePage() {
  const list = useStore(axes);
  const sys = useStore(system);
  const session = useStore(scope.state);
  const roll = useStore(rolling.state);
  const online = useOnline();
  const unitOf = (axis: string | null | undefined) => list.find((a) => a.config.name === axis)?.config.unit ?? '';
  const [available, setAvailable] = useState<boolean | null>(null);
  // Axis groups: a channel may record a group's path signals.
  const [groupNames, setGroupNames] = useState<string[]>([]);
  useEffect(() => {
    void listGroupNames().then(setGroupNames);
  }, []);
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
  const [viewState, setViewState] = useState<ScopeView>(() => savedView ?? defaultView(form.channels.length));
  const view = fitView(viewState, form.channels.length);
  const setView = (v: ScopeView) => setViewState(v);
  const [durationText, setDurationText] = useState(String(form.duration_s));
  const [levelText, setLevelText] = useState(String(form.trigger.level));
  const [preText, setPreText] = useState(String(form.trigger.pre_trigger_s));
  const [chunkText, setChunkText] = useState(String(view.rolling.chunk_s));
  const [windowText, setWindowText] = useState(String(view.rolling.window_s));
  const [errors, setErrors] = useState<Record<string, string>>({});
  const [error, setError] = useState<string | null>(null);
  const running = session.running;
  const rec = session.shown;
  const [cursors, setCursors] = useState<[number | null, number | null]>([null, null]);
  const [range, setRange] = useState<{ min: number; max: number } | null>(null);
  const chartEl = useRef<HTMLDivElement>(null);
  const chart = useRef<ScopeStack | null>(null);
  // saved setups
  const [setups, setSetups] = useState<ScopeSetupResource[] | null>(null);
  const [setupName, setSetupName] = useState<string | null>(savedSetupName);
  const [saving, setSaving] = useState<string | null>(null); // the name being typed
  const [setupErrors, setSetupErrors] = useState<Record<string, string>>({});
  const [confirmDelete, setConfirmDelete] = useState<string | null>(null);
  // compare
  const [compareId, setCompareId] = useState<string>('');
  const [align, setAlign] = useState<Align>('trigger');
  const [other, setOther] = useState<Recording | null>(null);

  const kept = session.kept;
  const done = kept.filter((r) => r.state === 'done');
  // The server's recordings now and every few seconds; an armed or running one is followed.
  useEffect(() => scope.attach(), []);
  useEffect(() => {
    if (online) void scopeAvailable().then(setAvailable);
  }, [online]);
  const reloadSetups = async () => {
    try {
      setSetups(await listSetups());
    } catch {
      setSetups([]);
    }
  };
  useEffect(() => {
    if (online) void reloadSetups();
  }, [online]);
  useEffect(() => {
    savedForm = form;
  }, [form]);
  useEffect(() => {
    savedView = viewState;
  }, [viewState]);
  useEffect(() => {
    savedSetupName = setupName;
  }, [setupName]);
  useEffect(() => {
    // The axes arrive after the page: start with the first axis's positions and velocity.
    if (form.channels.length === 0 && list.length && !savedForm?.channels.length) {
      setForm({ ...form, channels: defaultChannels() });
    }
  }, [list]);
  useEffect(() => {
    if (!compareId) {
      setOther(null);
      return;
    }
    let live = true;
    getRecording(Number(compareId))
      .then((r) => live && setOther(r as Recording))
      .catch((e) => live && setError(errorText(e)));
    return () => {
      live = false;
    };
  }, [compareId]);

  const showRing = !!roll.ring && !!roll.request && (roll.active || view.rolling.enabled) && roll.ring.t.length > 0;
  // While a recording is armed or running its trace is drawn live from the status stream
  // (TwinCAT Scope draws as it records); the server's every-cycle samples replace it when done.
  const trace = useStore(scopeLive);
  const showLive = !showRing && !roll.active && !!running && !!trace && trace.id === running.id;
  const t = useMemo(() => (rec && rec.data ? timeAxis(rec) : null), [rec]);
  const problems = useMemo(() => (rec && rec.data ? checkRecording(rec) : []), [rec]);

  const seriesOf = (c: { axis?: string | null; group?: string | null; signal: string; unit?: string }, i: number, values: (number | null)[], extra: Partial<ChartSeries> = {}) => {
    const unit = c.unit ?? signalUnit(c.signal as Signal, unitOf(c.axis));
    return {
      label: channelLabel({ ...c, signal: c.signal as Signal }),
      unit,
      scale: scaleKey(c.signal as Signal, unitOf(c.axis)),
      values,
      data: values,
      color: view.colors[i],
      chart: view.chart[i] ?? 0,
      index: i,
      ...extra,
    };
  };

  /** The trigger of a recording as drawn: the level on its channel's scale, in its chart. */
  const triggerOf = (r: Pick<Recording, 'trigger' | 'channels'>): Plot['trigger'] => {
    const c = r.trigger ? r.channels[r.trigger.channel] : undefined;
    return r.trigger && c ? { chart: view.chart[r.trigger.channel] ?? 0, scale: scaleKey(c.signal as Signal, unitOf(c.axis)), level: r.trigger.level } : null;
  };

  const plot = useMemo<Plot | null>(() => {
    if (showLive && trace && running) {
      const first = trace.series(performance.now());
      return { t: first.t, rows: trace.channels.map((c, i) => seriesOf(c, i, first.data[i])), limits: first.limits, trigger: triggerOf(running), live: true };
    }
    if (showRing && roll.ring && roll.request) {
      const ring = roll.ring;
      const end = ring.end ?? 0;
      return {
        t: ring.t,
        rows: roll.request.channels.map((c, i) => seriesOf(c, i, ring.data[i] ?? [])),
        limits: { min: end - roll.window_s, max: end },
        trigger: null,
      };
    }
    if (!rec || !rec.data || !t) return null;
    const trig = triggerOf(rec);
    if (other && other.data && other.id !== rec.id) {
      const m = mergeAligned(alignedTime(rec, align), rec.data, alignedTime(other, align), other.data);
      return {
        t: m.t,
        rows: [
          ...rec.channels.map((c, i) => seriesOf(c, i, m.a[i], { spanGaps: true, label: `#${rec.id} ${channelLabel(c)}` })),
          ...other.channels.map((c, i) => seriesOf(c, i, m.b[i], { spanGaps: true, dash: true, label: `#${other.id} ${channelLabel(c)}` })),
        ],
        trigger: align === 'trigger' ? trig : null,
      };
    }
    return { t, rows: rec.channels.map((c, i) => seriesOf(c, i, rec.data![i])), trigger: trig };
  }, [showLive ? trace : rec, t, other, align, showRing, roll.ring, roll.request, roll.window_s, view.chart.join(), view.colors.join(), list]);

  useEffect(() => {
    chart.current?.destroy();
    chart.current = null;
    setCursors([null, null]);
    setRange(null);
    if (!plot || !chartEl.current) return;
    const used = [...new Set(plot.rows.map((r) => Math.min(Math.max(0, r.chart), MAX_CHARTS - 1)))].sort();
    const panes: StackPane[] = used.map((c) => ({
      series: plot.rows.filter((r) => r.chart === c),
      trigger: plot.trigger && plot.trigger.chart === c ? plot.trigger : null,
    }));
    chart.current = new ScopeStack(chartEl.current, plot.t, panes, { onCursors: (a, b) => setCursors([a, b]), onRange: (min, max) => setRange({ min, max }) }, {
      limits: plot.limits,
      height: window.innerWidth < 600 ? 300 : 420,
    });
    // Live: the trace grows ten times a second (and only when something new came).
    let timer: ReturnType<typeof setInterval> | null = null;
    if (plot.live && trace) {
      const el = chartEl.current;
      const redraw = () => {
        const sr = trace.series(performance.now());
        chart.current?.setData(sr.t, used.map((c) => plot.rows.filter((r) => r.chart === c).map((r) => sr.data[r.index])));
        el.dataset.livePoints = String(sr.points);
        el.dataset.armed = sr.armed ? '1' : '0';
      };
      redraw();
      timer = setInterval(redraw, 100);
    }
    return () => {
      if (timer) clearInterval(timer);
      chart.current?.destroy();
      chart.current = null;
    };
  }, [plot]);

  // the readout follows the order of the panes (chart by chart)
  const ordered = plot ? [...plot.rows].sort((a, b) => a.chart - b.chart) : [];
  const readout = plot ? cursorReadout(plot.t, ordered.map((r) => r.data), ordered.map((r) => r.label), cursors[0], cursors[1]) : null;

  const setChannel = (i: number, patch: Partial<ScopeForm['channels'][number]>) =>
    setForm({ ...form, channels: form.channels.map((c, j) => (j === i ? { ...c, ...patch } : c)) });

  /** The form as typed, checked: the request, or null with the errors shown. */
  const currentRequest = (durationOverride?: number): RecordingRequest | null => {
    const f: ScopeForm = {
      ...form,
      duration_s: parseNum(durationText),
      trigger: { ...form.trigger, level: parseNum(levelText), pre_trigger_s: parseNum(preText, 0) },
    };
    setForm(f);
    const { request, errors: errs } = buildRequest(durationOverride === undefined ? f : { ...f, duration_s: durationOverride, trigger: { ...f.trigger, enabled: false } });
    setErrors(errs);
    return request;
  };

  const record = async () => {
    setError(null);
    const request = currentRequest();
    if (!request) return;
    try {
      await scope.record(request);
    } catch (e) {
      setErrors(fieldsOf(e));
      setError(errorText(e));
    }
  };

  const viewWithRolling = (): ScopeView => ({
    ...view,
    rolling: { ...view.rolling, chunk_s: parseNum(chunkText, view.rolling.chunk_s), window_s: parseNum(windowText, view.rolling.window_s) },
  });

  const startRolling = async () => {
    setError(null);
    const v = viewWithRolling();
    const errs: Record<string, string> = {};
    if (!(v.rolling.chunk_s > 0)) errs['rolling.chunk_s'] = 'must be > 0';
    if (!(v.rolling.window_s >= v.rolling.chunk_s)) errs['rolling.window_s'] = 'at least one chunk';
    const request = currentRequest(v.rolling.chunk_s);
    if (Object.keys(errs).length) {
      setErrors((e) => ({ ...e, ...errs }));
      return;
    }
    if (!request) return;
    setView(v);
    try {
      await rolling.start(request, v.rolling.window_s);
    } catch (e) {
      setErrors(fieldsOf(e));
      setError(errorText(e));
    }
  };

  const loadSetup = (s: ScopeSetupResource) => {
    const { form: f, view: v } = fromSetup(s);
    setForm(f);
    setView(v);
    setDurationText(String(f.duration_s));
    setLevelText(String(f.trigger.level));
    setPreText(String(f.trigger.pre_trigger_s));
    setChunkText(String(v.rolling.chunk_s));
    setWindowText(String(v.rolling.window_s));
    setErrors({});
    setSetupErrors({});
    setSetupName(s.name);
  };

  const saveSetup = async (name: string) => {
    setError(null);
    const nameErr = setupNameError(name);
    if (nameErr) {
      setSetupErrors({ name: nameErr });
      return;
    }
    // the setup is saved as typed: the server checks it (and names the field)
    const f: ScopeForm = {
      ...form,
      duration_s: parseNum(durationText),
      trigger: { ...form.trigger, level: parseNum(levelText), pre_trigger_s: parseNum(preText, 0) },
    };
    const { request, errors: errs } = buildRequest(f);
    setErrors(errs);
    if (!request) {
      setSetupErrors({ name: 'fix the recording first' });
      return;
    }
    const v = viewWithRolling();
    try {
      await putSetup(name, toSetup(request, v));
      setSetupErrors({});
      setSaving(null);
      setSetupName(name);
      setView(v);
      await reloadSetups();
    } catch (e) {
      const { form: fe, other: oe } = setupFieldErrors(fieldsOf(e));
      setErrors(fe);
      setSetupErrors(Object.keys(oe).length ? { name: Object.values(oe).join('; ') } : Object.keys(fe).length ? {} : { name: errorText(e) });
      setError(errorText(e));
    }
  };

  const removeSetup = async (name: string) => {
    setConfirmDelete(null);
    try {
      await deleteSetup(name);
      if (setupName === name) setSetupName(null);
    } catch (e) {
      setError(errorText(e));
    }
    await reloadSetups();
  };

  const cycle = rec?.cycle_time_s ?? sys?.cycle_time ?? null;
  const duration = parseNum(durationText);
  const rollingOn = view.rolling.enabled;
  const busy = !!running || roll.active;
  const existing = saving !== null && setups?.some((s) => s.name === saving);
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
        error={error ?? roll.error ?? session.error}
        onClose={() => {
          setError(null);
          scope.clearError();
          rolling.state.set({ ...rolling.state.get(), error: null });
        }}
      />
      <div class="scope-grid">
        <div class="scope-side">
          <Panel title="Recording" class="scope-setup">
            <div class="channels">
              {form.channels.map((c, i) => (
                <div class="channel" key={i} data-channel={i}>
                  <span class="channel-no">
                    <input
                      type="color"
                      class="swatch-input"
                      name={`channel-${i}-color`}
                      title="colour"
                      value={view.colors[i]}
                      onInput={(e) => setView({ ...view, colors: view.colors.map((x, j) => (j === i ? (e.target as HTMLInputElement).value : x)) })}
                    />
                    {i}
                  </span>
                  <select
                    name={`channel-${i}-axis`}
                    value={c.group ? `group:${c.group}` : c.axis}
                    title="axis or group"
                    onChange={(e) => {
                      const v = (e.target as HTMLSelectElement).value;
                      if (v.startsWith('group:')) {
                        setChannel(i, { axis: '', group: v.slice('group:'.length), signal: GROUP_SIGNALS.includes(c.signal) ? c.signal : 'path_velocity' });
                      } else {
                        setChannel(i, { axis: v, group: undefined, signal: SIGNALS.includes(c.signal) ? c.signal : 'set_position' });
                      }
                    }}
                  >
                    {list.map((a) => (
                      <option value={a.config.name}>{a.config.name}</option>
                    ))}
                    {c.axis && !list.some((a) => a.config.name === c.axis) && <option value={c.axis}>{c.axis} (missing)</option>}
                    {(groupNames.length > 0 || c.group) && (
                      <optgroup label="groups (path)">
                        {groupNames.map((g) => (
                          <option value={`group:${g}`}>{g}</option>
                        ))}
                        {c.group && !groupNames.includes(c.group) && <option value={`group:${c.group}`}>{c.group}</option>}
                      </optgroup>
                    )}
                  </select>
                  <select name={`channel-${i}-signal`} value={c.signal} title="signal" onChange={(e) => setChannel(i, { signal: (e.target as HTMLSelectElement).value as Signal })}>
                    {(c.group ? GROUP_SIGNALS : SIGNALS).map((s) => (
                      <option value={s}>{SIGNAL_LABEL[s]}</option>
                    ))}
                  </select>
                  <select
                    name={`channel-${i}-chart`}
                    class="chart-select"
                    title="chart (stacked, one time axis)"
                    value={String(view.chart[i])}
                    onChange={(e) => setView({ ...view, chart: view.chart.map((x, j) => (j === i ? Number((e.target as HTMLSelectElement).value) : x)) })}
                  >
                    {Array.from({ length: MAX_CHARTS }, (_, k) => (
                      <option value={String(k)}>▤{k + 1}</option>
                    ))}
                  </select>
                  <button
                    type="button"
                    class="btn btn-small"
                    title="remove this channel"
                    onClick={() => {
                      setForm({ ...form, channels: form.channels.filter((_, j) => j !== i) });
                      setView(removeChannel(view, i));
                    }}
                  >
                    ×
                  </button>
                  {(errors[`channels[${i}].axis`] || errors[`channels[${i}].group`] || errors[`channels[${i}].signal`]) && (
                    <div class="field-error channel-error" role="alert">
                      {errors[`channels[${i}].axis`] ?? errors[`channels[${i}].group`] ?? errors[`channels[${i}].signal`]}
                    </div>
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
              <label class="check scope-mode">
                <input
                  type="checkbox"
                  name="rolling-on"
                  checked={rollingOn}
                  disabled={roll.active}
                  onChange={(e) => setView({ ...view, rolling: { ...view.rolling, enabled: (e.target as HTMLInputElement).checked } })}
                />{' '}
                rolling (continuous)
              </label>
              {rollingOn ? (
                <>
                  <Field label="Chunk (s)" error={errors['rolling.chunk_s']} name="rolling.chunk_s" hint="one recording">
                    <NumberInput name="rolling.chunk_s" value={chunkText} onValue={setChunkText} />
                  </Field>
                  <Field label="Window (s)" error={errors['rolling.window_s']} name="rolling.window_s" hint="seconds shown">
                    <NumberInput
                      name="rolling.window_s"
                      value={windowText}
                      onValue={(x) => {
                        setWindowText(x);
                        const w = parseNum(x);
                        if (roll.active && w > 0) rolling.setWindow(w);
                      }}
                    />
                  </Field>
                </>
              ) : (
                <>
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
                </>
              )}
            </div>
            <div class="form-actions">
              {rollingOn ? (
                roll.active ? (
                  <button type="button" class="btn btn-primary" name="rolling-stop" onClick={() => void rolling.stop()}>
                    Stop
                  </button>
                ) : (
                  <button type="button" class="btn btn-primary" name="rolling-start" disabled={!available || busy || !online} onClick={() => void startRolling()}>
                    Start rolling
                  </button>
                )
              ) : (
                <button type="button" class="btn btn-primary" name="record" disabled={!available || busy || !online} onClick={() => void record()}>
                  {running ? 'Recording…' : 'Record'}
                </button>
              )}
              {running && !roll.active && (
                <button type="button" class="btn" name="cancel-recording" disabled={!online} onClick={() => void scope.cancel()}>
                  Cancel
                </button>
              )}
            </div>
            {roll.active || (rollingOn && roll.chunks > 0) ? (
              <div class="muted small" data-testid="rolling-state" data-active={String(roll.active)} data-chunks={String(roll.chunks)}>
                {roll.active ? 'rolling' : 'stopped'} · {roll.chunks} recordings · last {roll.window_s} s
                {roll.ring && roll.ring.gaps > 0 ? ` · ${roll.ring.gaps} gaps (${roll.ring.lostSamples} cycles not recorded)` : ''}
              </div>
            ) : (
              running && (
                <div class="muted small" data-testid="recording-state" data-state={running.state} data-recording={String(running.id)}>
                  #{String(running.id)}{' '}
                  {running.state === 'armed'
                    ? 'armed: waiting for the trigger…'
                    : `${running.state}… ${running.samples_recorded ?? 0} / ${running.samples} samples`}
                </div>
              )
            )}
          </Panel>
          <Panel
            title="Setups"
            class="scope-setups"
            actions={
              saving === null && (
                <button type="button" class="btn btn-small" name="setup-save-as" disabled={!online} onClick={() => { setSaving(setupName ?? ''); setSetupErrors({}); }}>
                  Save…
                </button>
              )
            }
          >
            {saving !== null && (
              <form
                class="setup-save"
                onSubmit={(e) => {
                  e.preventDefault();
                  void saveSetup(saving.trim());
                }}
              >
                <Field label="Setup name" error={setupErrors.name} name="setup-name" hint={existing ? 'replaces the saved setup of this name' : 'letters, digits, _ or -'}>
                  <input name="setup-name" value={saving} autoFocus onInput={(e) => setSaving((e.target as HTMLInputElement).value)} />
                </Field>
                <div class="form-actions">
                  <button type="submit" class="btn btn-primary btn-small" name="setup-save">
                    {existing ? 'Replace' : 'Save'}
                  </button>
                  <button type="button" class="btn btn-small" name="setup-cancel" onClick={() => { setSaving(null); setSetupErrors({}); }}>
                    Cancel
                  </button>
                </div>
              </form>
            )}
            {setupName && (
              <div class="muted small" data-testid="setup-current">
                setup: <b>{setupName}</b>
              </div>
            )}
            {setups === null ? (
              <div class="muted small">loading…</div>
            ) : setups.length === 0 ? (
              <div class="muted small">No saved setups: Save… stores the channels, duration, trigger and the charts.</div>
            ) : (
              <ul class="setup-list" data-testid="setups">
                {setups.map((s) => (
                  <li key={s.name} data-setup={s.name} class={s.name === setupName ? 'current' : ''}>
                    <span class="setup-name" title={`${s.recording.channels.map(channelLabel).join(', ')} · ${s.recording.duration_s} s · saved ${s.updated_at}`}>
                      {s.name}
                      <span class="muted small"> · {s.recording.channels.length} ch · {s.recording.duration_s} s</span>
                    </span>
                    {confirmDelete === s.name ? (
                      <span class="confirm">
                        delete?
                        <button type="button" class="btn btn-small btn-danger" name="setup-delete-yes" onClick={() => void removeSetup(s.name)}>
                          Delete
                        </button>
                        <button type="button" class="btn btn-small" onClick={() => setConfirmDelete(null)}>
                          No
                        </button>
                      </span>
                    ) : (
                      <span class="setup-actions">
                        <button type="button" class="btn btn-small" name="setup-load" disabled={roll.active} onClick={() => loadSetup(s)}>
                          Load
                        </button>
                        <button type="button" class="btn btn-small" name="setup-overwrite" title="save the current recording and view under this name" disabled={!online} onClick={() => void saveSetup(s.name)}>
                          Overwrite
                        </button>
                        <button type="button" class="btn btn-small" name="setup-delete" title="delete" disabled={!online} onClick={() => setConfirmDelete(s.name)}>
                          ×
                        </button>
                      </span>
                    )}
                  </li>
                ))}
              </ul>
            )}
          </Panel>
        </div>
        <div class="scope-main">
          <div class="toolbar scope-toolbar">
            <button type="button" class="btn btn-small" name="zoom-in" disabled={!plot} onClick={() => chart.current?.zoom(0.5)} title="zoom in (half the time range)">
              zoom +
            </button>
            <button type="button" class="btn btn-small" name="zoom-out" disabled={!plot} onClick={() => chart.current?.zoom(2)} title="zoom out (twice the time range)">
              zoom −
            </button>
            <button type="button" class="btn btn-small" name="pan-left" disabled={!plot} onClick={() => chart.current?.pan(-0.25)} title="pan left (a quarter of the view)">
              ◀
            </button>
            <button type="button" class="btn btn-small" name="pan-right" disabled={!plot} onClick={() => chart.current?.pan(0.25)} title="pan right (a quarter of the view)">
              ▶
            </button>
            <button type="button" class="btn btn-small" name="full-view" disabled={!plot} onClick={() => chart.current?.reset()}>
              full view
            </button>
            <button type="button" class="btn btn-small" name="clear-cursors" disabled={!plot} onClick={() => chart.current?.clearCursors()}>
              clear cursors
            </button>
            <span class="spacer" />
            {done.length > 0 && !showRing && (
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
                {done.map((r) => (
                  <option value={String(r.id)}>
                    #{String(r.id)} · {r.channels.map(channelLabel).join(', ')} · {r.duration_s ?? ''} s
                  </option>
                ))}
              </select>
            )}
            {rec && !showRing && !showLive && done.length > 1 && (
              <>
                <select name="compare" title="overlay a second recording (dashed)" value={compareId} onChange={(e) => setCompareId((e.target as HTMLSelectElement).value)}>
                  <option value="">compare with…</option>
                  {done
                    .filter((r) => r.id !== rec.id)
                    .map((r) => (
                      <option value={String(r.id)}>
                        #{String(r.id)} · {r.channels.map(channelLabel).join(', ')}
                      </option>
                    ))}
                </select>
                {compareId && (
                  <select name="align" title="align the two recordings" value={align} onChange={(e) => setAlign((e.target as HTMLSelectElement).value as Align)}>
                    <option value="trigger">at the trigger</option>
                    <option value="start">at the start</option>
                  </select>
                )}
              </>
            )}
            {rec && !showRing && !showLive && (
              <>
                <a class="btn btn-small" href={csvUrl(rec.id)} download={`scope-${rec.id}.csv`} data-testid="csv">
                  CSV
                </a>
                <button
                  type="button"
                  class="btn btn-small"
                  disabled={!range || !t || !!other}
                  onClick={() => t && rec.data && range && download(`scope-${rec.id}-view.csv`, toCsv(t, rec.channels, rec.data, { from: range.min, to: range.max }))}
                >
                  CSV of view
                </button>
              </>
            )}
          </div>
          <div class="chart-box">
            <div ref={chartEl} class="chart" data-testid="scope-chart" data-mode={showLive ? 'live' : showRing ? 'rolling' : other ? 'compare' : 'single'} />
            {!plot && (
              <div class="chart-empty muted">
                {rollingOn ? 'Press Start rolling: recordings of one chunk each, one after another, scroll by.' : 'No recording yet. Pick signals, set a duration and press Record; then move the axis.'}
              </div>
            )}
          </div>
          <div class="muted small hint">
            drag: zoom to a range · wheel: zoom · shift-drag: pan · click: place cursor C1, then C2 · double-click: full view · touch: tap for a cursor,
            swipe sideways to pan, the buttons above to zoom · ▤1…▤4: the chart of a channel (stacked, one time axis)
          </div>
          {showRing && roll.ring && (
            <div class="muted small" data-testid="rolling-info">
              rolling · {roll.chunks} recordings of {roll.request?.duration_s} s · gaps between recordings are not recorded and shown as breaks
              {roll.ring.gaps > 0 ? ` (${roll.ring.gaps} so far, ${sig((roll.ring.lostSamples * roll.ring.cycle) || 0)} s in all)` : ''}
            </div>
          )}
          {showLive && running && (
            <div class="muted small" data-testid="live-info" data-recording={String(running.id)}>
              recording {String(running.id)} · {running.state === 'armed' ? 'armed: the pre-trigger history scrolls until the trigger' : 'recording'} · drawn live from the
              status stream (25–50 Hz); the server's every-cycle samples replace it when done ({running.samples_recorded ?? 0} / {running.samples} recorded)
            </div>
          )}
          {rec && !showRing && !showLive && (
            <div class="muted small" data-testid="recording-info">
              recording {String(rec.id)} · {rec.samples} samples × {rec.channels.length} channels · cycle {(rec.cycle_time_s * 1000).toPrecision(3)} ms
              {rec.trigger ? ` · trigger ${channelLabel(rec.channels[rec.trigger.channel])} ${rec.trigger.edge} ${rec.trigger.level}, pre ${rec.trigger.pre_trigger_s} s` : ''}
              {problems.length ? <span class="text-error"> · {problems.join('; ')}</span> : null}
              {other ? ` · compared with ${String(other.id)} (dashed), aligned at the ${align === 'trigger' && rec.trigger && other.trigger ? 'trigger' : align === 'trigger' ? 'trigger (start where none)' : 'start'}` : ''}
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
                      <span class="swatch" style={{ background: ordered[i].color, borderTop: ordered[i].dash ? '2px dashed #fff' : undefined }} />
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
