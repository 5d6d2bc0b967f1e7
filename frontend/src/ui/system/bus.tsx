// The System page's drive bus (`GET /api/v1/bus`, every second while the page is shown): an
// EtherCAT bus as TwinCAT's device view shows it — kind, interface, state with a banner when
// faulted (saying why) or degraded, the PDU timeout, motiond's TX/RX loop (running, restarts, its
// thread's priority), the frame counters (lost, late, duplicate, malformed), working-counter and
// bus-fault figures, DC, the server's notice, the SubDevices with identity, AL state, the process
// data mapping each drive took (the objects it lacks, the mappings it refused with their AL status
// codes) and their axis — an SDO tool per SubDevice (read anyone, write the engineer role) and
// Reset bus (`POST /bus/reset`, the engineer role). The simulated bus is the axes with simulated drives.
import { Fragment } from 'preact';
import { useEffect, useState } from 'preact/hooks';
import { ApiError } from '../../api/problem';
import type { AxisResource, BusResource } from '../../api/types';
import { useStore } from '../../store';
import { axes, statuses } from '../../services';
import { auth, may } from '../../auth/session';
import { href } from '../../router';
import { Field, Kpi, Lamp, Led, Panel, errorText, fieldsOf, useOnline } from '../shared/common';
import { getBus, resetBus, sdoRead, sdoWrite } from '../../system/api';
import {
  BUS_POLL_MS,
  busBanner,
  busCounters,
  busState,
  busTitle,
  driveKind,
  isEthercat,
  ms,
  parseSdoAddress,
  parseSdoValue,
  plantText,
  resetUnavailable,
  sdoView,
  simulatedAxes,
  subDeviceRows,
  txrxView,
  type MappingView,
  type SdoView,
} from '../../system/bus';

/**
 * The bus resource: read at once, then every `pollMs` while the document is visible (no request
 * while hidden; read again as soon as it is shown), or once when `pollMs` is null.
 */
export function useBus(pollMs: number | null): { bus: BusResource | null; error: string | null; setBus: (b: BusResource) => void } {
  const [bus, setBus] = useState<BusResource | null>(null);
  const [error, setError] = useState<string | null>(null);
  useEffect(() => {
    let stopped = false;
    let busy = false;
    let timer: ReturnType<typeof setTimeout> | undefined;
    const hidden = () => typeof document !== 'undefined' && document.hidden;
    const tick = async () => {
      clearTimeout(timer);
      timer = undefined;
      if (stopped || busy || (pollMs !== null && hidden())) return;
      busy = true;
      try {
        const b = await getBus();
        if (!stopped) {
          setBus(b);
          setError(null);
        }
      } catch (e) {
        if (!stopped) setError(errorText(e));
      } finally {
        busy = false;
      }
      if (!stopped && pollMs !== null) timer = setTimeout(tick, pollMs);
    };
    const shown = () => {
      if (!hidden() && timer === undefined) void tick();
    };
    void tick();
    if (pollMs !== null) document.addEventListener('visibilitychange', shown);
    return () => {
      stopped = true;
      clearTimeout(timer);
      document.removeEventListener('visibilitychange', shown);
    };
  }, [pollMs]);
  return { bus, error, setBus };
}

export function BusPanel() {
  const { bus, error, setBus } = useBus(BUS_POLL_MS);
  const sims = simulatedAxes(useStore(axes));
  const onSimBus = bus?.kind === 'simulated';
  const engineer = may(useStore(auth), 'engineer');
  const online = useOnline();
  const [resetting, setResetting] = useState(false);
  /** The latest reset's outcome (a test waits for the next one). */
  const [reset, setReset] = useState<{ n: number; ok: boolean; text: string } | null>(null);
  const why = resetUnavailable(bus, { busy: resetting, engineer, online });
  const doReset = async () => {
    setResetting(true);
    const n = (reset?.n ?? 0) + 1;
    try {
      const b = await resetBus();
      setBus(b);
      setReset({ n, ok: true, text: `Bus reset: ${b.state === 'op' ? 'every SubDevice in OP again' : `the bus is ${busState(b.state).label}`}. Axes the fault stopped stay in ErrorStop until their reset (MC_Reset).` });
    } catch (e) {
      setReset({ n, ok: false, text: `Bus reset failed — ${errorText(e)}` });
    } finally {
      setResetting(false);
    }
  };
  return (
    <Panel
      title="Bus"
      class="sys-bus"
      id="bus"
      actions={
        <>
          <span class={`live-ind ${error ? 'live-stale' : bus ? 'live-live' : ''}`} title={`GET /bus every ${BUS_POLL_MS / 1000} s`}>
            <span class="live-dot" />
            {error ? 'not updated' : `every ${BUS_POLL_MS / 1000} s`}
          </span>
          <button
            type="button"
            class={`btn btn-small btn-warn ${resetting ? 'busy' : ''}`}
            name="bus-reset"
            disabled={why !== null}
            aria-busy={resetting}
            title={why ?? 'start the TX/RX loop again and ask every SubDevice back to OP (POST /bus/reset)'}
            onClick={() => void doReset()}
          >
            {resetting ? 'Resetting…' : 'Reset bus'}
          </button>
        </>
      }
    >
      {error && (
        <div class="banner banner-error" role="alert" data-testid="bus-error">
          <span>{error}</span>
        </div>
      )}
      {reset && (
        <div class={`banner ${reset.ok ? 'banner-ok' : 'banner-error'} bus-banner`} role={reset.ok ? 'status' : 'alert'} data-testid="bus-reset-result" data-ok={reset.ok ? '1' : '0'} data-n={reset.n}>
          <span>{reset.text}</span>
          <button type="button" class="banner-close" name="bus-reset-close" aria-label="close" onClick={() => setReset(null)}>
            ×
          </button>
        </div>
      )}
      {!bus && !error && <p class="muted">Loading…</p>}
      {bus && isEthercat(bus) && <EthercatBus bus={bus} stale={!!error} />}
      {(bus || error) && (onSimBus || sims.length > 0) && <SimulatedDrives axes={sims} onSimBus={onSimBus} />}
    </Panel>
  );
}

function EthercatBus({ bus, stale }: { bus: BusResource; stale: boolean }) {
  const [sdo, setSdo] = useState<number | null>(null);
  const state = busState(bus.state);
  const banner = busBanner(bus);
  const rows = subDeviceRows(bus);
  const txrx = txrxView(bus);
  const open = rows.find((r) => r.position === sdo) ?? null;
  return (
    <div class={`bus bus-ethercat ${stale ? 'stale' : ''}`} data-bus={bus.kind} data-state={bus.state}>
      <div class="bus-head">
        <h4 data-testid="bus-title">{busTitle(bus)}</h4>
        <span class="bus-fact">
          <span class="muted">Interface</span> <b class="mono">{bus.interface ?? '—'}</b>
        </span>
        <span class="bus-fact" data-testid="bus-state" data-state={bus.state}>
          <span class="muted">State</span> <Led on label={state.label} tone={state.tone} />
        </span>
        <span class="bus-fact">
          <span class="muted">Cycle (SYNC0)</span> <b class="mono">{ms(bus.cycle_time)}</b>
        </span>
        <span class="bus-fact" data-testid="bus-pdu-timeout" title="how long a frame may take to come back before it is sent again (twice), then counted as lost">
          <span class="muted">PDU timeout</span> <b class="mono">{ms(bus.pdu_timeout)}</b>
        </span>
        <span class="bus-fact">
          <span class="muted">SubDevices</span> <b class="mono">{bus.subdevices.length}</b>
        </span>
      </div>
      {txrx && (
        <div class="bus-head bus-txrx" data-testid="bus-txrx" data-running={txrx.running ? '1' : '0'} title="motiond's TX/RX loop: its own thread sends the frames and takes the replies">
          <span class="bus-fact">
            <span class="muted">TX/RX loop</span> <Led on label={txrx.label} tone={txrx.tone} />
          </span>
          <span class="bus-fact" data-testid="bus-txrx-restarts" title="times the loop was started again (Reset bus or MC_Reset after it stopped)">
            <span class="muted">Restarts</span> <b class="mono">{txrx.restarts}</b>
          </span>
          <span class="bus-fact bus-thread" data-testid="bus-txrx-thread" title="the thread's scheduling: SCHED_FIFO priority and CPU, or why not">
            <span class="muted">Thread</span> <b class="mono">{txrx.thread}</b>
          </span>
        </div>
      )}
      {banner && (
        <div class={`banner banner-${banner.tone} bus-banner`} role="alert" data-testid="bus-banner" data-tone={banner.tone}>
          <span>
            <b>{banner.title}.</b> {banner.text}
          </span>
        </div>
      )}
      {bus.notice && (
        <div class="banner banner-info bus-banner" data-testid="bus-notice">
          <span>{bus.notice}</span>
        </div>
      )}
      <div class="sys-kpis bus-kpis" data-testid="bus-counters">
        {busCounters(bus).map((c) => (
          <Kpi key={c.key} name={c.key} label={c.label} value={c.value} tone={c.tone} title={c.title} />
        ))}
      </div>
      <div class="table-fit">
        <table class="grid bus-table subdevice-table" data-testid="subdevices">
          <thead>
            <tr>
              <th class="r" title="position on the segment (a CiA-402 drive's subdevice)">Pos</th>
              <th class="hide-phone" title="configured station address">Address</th>
              <th>Name</th>
              <th class="hide-narrow">Vendor</th>
              <th class="hide-narrow">Product</th>
              <th class="hide-narrow">Revision</th>
              <th class="hide-narrow r">Serial</th>
              <th>State</th>
              <th class="hide-phone">Process data</th>
              <th class="hide-phone" title="distributed clocks (SYNC0)">DC</th>
              <th>Axis</th>
              <th class="c-sdo" />
            </tr>
          </thead>
          <tbody>
            {rows.map((r) => (
              <Fragment key={r.position}>
                <tr data-subdevice={r.position} data-al={r.al.state} class={r.al.state !== 'op' ? 'row-warn' : ''}>
                  <td class="r mono" data-col="position">{r.position}</td>
                  <td class="mono hide-phone" data-col="address">{r.address}</td>
                  <td data-col="name">{r.name}</td>
                  <td class="mono hide-narrow" data-col="vendor">{r.vendor}</td>
                  <td class="mono hide-narrow" data-col="product">{r.product}</td>
                  <td class="mono hide-narrow" data-col="revision">{r.revision}</td>
                  <td class="mono hide-narrow r" data-col="serial">{r.serial}</td>
                  <td class="nowrap" data-col="al">
                    <Led on label={r.al.label} tone={r.al.tone} title={`AL state ${r.al.label}`} />
                  </td>
                  <td class="hide-phone small" data-col="mapping" data-mapping={r.process?.mapping}>
                    {r.process ? <MappingCell m={r.process} /> : <span class="muted">no drive</span>}
                  </td>
                  <td class="hide-phone" data-col="dc">{r.dc ? 'SYNC0' : <span class="muted">—</span>}</td>
                  <td data-col="axis">
                    {r.axis ? (
                      <a href={href({ page: 'axis', axis: r.axis, tab: 'online' })}>
                        <b>{r.axis}</b>
                      </a>
                    ) : (
                      <span class="muted">—</span>
                    )}
                  </td>
                  <td class="c-sdo">
                    <button
                      type="button"
                      class={`btn btn-small ${sdo === r.position ? 'active' : ''}`}
                      name="sdo-open"
                      aria-expanded={sdo === r.position}
                      title="read or write an object of this SubDevice (CoE SDO)"
                      onClick={() => setSdo(sdo === r.position ? null : r.position)}
                    >
                      SDO
                    </button>
                  </td>
                </tr>
                {r.process && (r.process.missing.length > 0 || r.process.refused.length > 0) && (
                  <tr class="mapping-row" data-mapping-for={r.position}>
                    <td colSpan={12}>
                      <MappingDetail m={r.process} />
                    </td>
                  </tr>
                )}
                {open && open.position === r.position && (
                  <tr class="sdo-row" data-sdo-for={r.position}>
                    <td colSpan={12}>
                      <SdoTool position={r.position} name={r.name} onClose={() => setSdo(null)} />
                    </td>
                  </tr>
                )}
              </Fragment>
            ))}
            {rows.length === 0 && (
              <tr>
                <td colSpan={12} class="muted empty">
                  No SubDevice on the segment.
                </td>
              </tr>
            )}
          </tbody>
        </table>
      </div>
    </div>
  );
}

/** The mapping a drive took, with its sizes: `full · 15 B out, 29 B in` (amber when smaller than full). */
function MappingCell({ m }: { m: MappingView }) {
  return (
    <span class={`mapping-taken mapping-${m.tone}`} title={m.mapping === 'full' ? 'the full mapping (CSP/CSV/CST targets, touch probe, digital inputs)' : 'a smaller mapping than the full one: see below the row'}>
      <b>{m.mapping}</b> · {m.bytes}
    </span>
  );
}

/**
 * Under a SubDevice whose drive took less than the full mapping: the mapping taken (also on a
 * phone, where the column is hidden), the objects its dictionary lacks, and each refused mapping
 * with where it was refused and the AL status code with its ETG.1000 meaning.
 */
function MappingDetail({ m }: { m: MappingView }) {
  return (
    <div class="mapping-detail">
      <span class="mapping-fact" data-testid="mapping-taken">
        <span class="muted">Process data</span> <MappingCell m={m} />
      </span>
      {m.missing.length > 0 && (
        <span class="mapping-fact" data-testid="mapping-missing" title="objects of the full mapping this drive does not have (SDO abort 0x06020000): features needing them are refused on its axis (409)">
          <span class="muted">Missing objects</span> <span class="mono">{m.missing.join(', ')}</span>
        </span>
      )}
      {m.refused.map((r, i) => (
        <span key={i} class="mapping-fact mapping-refused" data-testid="mapping-refused" data-mapping={r.mapping} data-al-code={r.code ?? ''}>
          <span class="muted">Refused</span> <b>{r.mapping}</b> <span class="muted">at</span> {r.at}
          {r.code ? (
            <>
              {' '}
              <span class="muted">— AL status</span> <b class="mono">{r.code}</b> {r.meaning}
            </>
          ) : (
            <> — {r.meaning}</>
          )}
        </span>
      ))}
    </div>
  );
}

/** What a refused SDO transfer says: the SubDevice's abort (code and meaning) as motiond words it. */
export function sdoErrorText(e: unknown): string {
  if (e instanceof ApiError && e.problem && (e.problem.code === 'sdo_aborted' || e.problem.code === 'bus_not_ethercat' || e.problem.code === 'sdo_failed')) {
    return e.problem.detail;
  }
  return errorText(e);
}

const SDO_FIELDS = new Set(['index', 'sub', 'value', 'size']);

function SdoTool({ position, name, onClose }: { position: number; name: string; onClose: () => void }) {
  const engineer = may(useStore(auth), 'engineer');
  const online = useOnline();
  const [index, setIndex] = useState('0x1018');
  const [sub, setSub] = useState('1');
  const [value, setValue] = useState('');
  const [size, setSize] = useState(4);
  const [fields, setFields] = useState<Record<string, string>>({});
  const [result, setResult] = useState<{ kind: 'read' | 'written'; view: SdoView } | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [busy, setBusy] = useState(false);
  /** Answers received (a test waits for the next one). */
  const [answers, setAnswers] = useState(0);

  const run = async (write: boolean) => {
    const a = parseSdoAddress(index, sub);
    const errors = { ...a.errors };
    const v = write ? parseSdoValue(value) : null;
    if (write && v === null) errors.value = value.trim() === '' ? 'required' : 'a whole number (decimal or 0x hex)';
    setFields(errors);
    setError(null);
    setResult(null);
    if (Object.keys(errors).length) return;
    setBusy(true);
    try {
      const r = write ? await sdoWrite(position, a.index, a.sub, { value: v!, size }) : await sdoRead(position, a.index, a.sub);
      setResult({ kind: write ? 'written' : 'read', view: sdoView(r) });
    } catch (e) {
      const f = fieldsOf(e);
      setFields(f);
      const atFields = Object.keys(f).length > 0 && Object.keys(f).every((k) => SDO_FIELDS.has(k));
      setError(atFields ? null : sdoErrorText(e));
    } finally {
      setBusy(false);
      setAnswers((n) => n + 1);
    }
  };

  const r = result?.view;
  return (
    <div class="sdo" data-testid="sdo-tool" data-position={position} data-answers={answers}>
      <div class="sdo-head">
        <b>SDO</b>
        <span class="muted">
          SubDevice {position} · {name}
        </span>
        <button type="button" class="banner-close" name="sdo-close" aria-label="close the SDO tool" onClick={onClose}>
          ×
        </button>
      </div>
      <form
        class="sdo-form"
        onSubmit={(e) => {
          e.preventDefault();
          if (!busy) void run(false);
        }}
      >
        <div class="sdo-group">
          <Field label="Index" name="index" error={fields.index}>
            <input type="text" class="mono" name="sdo-index" value={index} autocomplete="off" spellcheck={false} onInput={(e) => setIndex((e.target as HTMLInputElement).value)} />
          </Field>
          <Field label="Sub" name="sub" error={fields.sub}>
            <input type="text" class="num" name="sdo-sub" inputMode="numeric" value={sub} autocomplete="off" onInput={(e) => setSub((e.target as HTMLInputElement).value)} />
          </Field>
          <button type="submit" class={`btn btn-small ${busy ? 'busy' : ''}`} name="sdo-read" disabled={busy}>
            Read
          </button>
        </div>
        <div class="sdo-group">
          <Field label="Value" name="value" error={fields.value}>
            <input type="text" class="num" name="sdo-value" value={value} placeholder="e.g. 0x0A" autocomplete="off" spellcheck={false} onInput={(e) => setValue((e.target as HTMLInputElement).value)} />
          </Field>
          <Field label="Size" name="size" error={fields.size}>
            <select name="sdo-size" value={String(size)} onChange={(e) => setSize(Number((e.target as HTMLSelectElement).value))}>
              <option value="1">1 byte</option>
              <option value="2">2 bytes</option>
              <option value="4">4 bytes</option>
            </select>
          </Field>
          <button
            type="button"
            class={`btn btn-small btn-warn ${busy ? 'busy' : ''}`}
            name="sdo-write"
            disabled={busy || !online || !engineer}
            title={engineer ? 'SDO download, then the value read back' : 'writing needs the engineer role'}
            onClick={() => void run(true)}
          >
            Write
          </button>
        </div>
      </form>
      {error && (
        <div class="banner banner-error sdo-error" role="alert" data-testid="sdo-error">
          <span>{error}</span>
        </div>
      )}
      {r && result && (
        <dl class="sdo-result" data-testid="sdo-result" data-kind={result.kind}>
          {sdoEntries(result.kind, r).map(([key, label, value]) => (
            <div key={key} class={`sdo-${key}`}>
              <dt>{label}</dt>
              <dd class={key === 'text' ? '' : 'mono'} data-sdo={key}>
                {value}
              </dd>
            </div>
          ))}
        </dl>
      )}
    </div>
  );
}

/** The SDO result's entries: [key, label, value], those the answer has. */
function sdoEntries(kind: 'read' | 'written', r: SdoView): [string, string, string][] {
  const all: [string, string, string | null][] = [
    ['address', kind === 'read' ? 'Read' : 'Written, read back', r.address],
    ['value', 'Hex', r.value],
    ['unsigned', 'Unsigned', r.unsigned],
    ['signed', 'Signed', r.signed],
    ['text', 'Text', r.text],
    ['bytes', 'Bytes (as sent)', r.bytes || '—'],
  ];
  return all.filter((e): e is [string, string, string] => e[2] !== null);
}

function SimulatedDrives({ axes: list, onSimBus }: { axes: AxisResource[]; onSimBus: boolean }) {
  const st = useStore(statuses);
  const n = `${list.length} ${list.length === 1 ? 'axis' : 'axes'}`;
  return (
    <div class="bus" data-bus="simulated">
      <h4 data-testid={onSimBus ? 'bus-title' : 'sim-title'}>{onSimBus ? `Simulated bus: ${n}` : `Simulated drives beside the bus: ${n}`}</h4>
      {list.length > 0 && (
        <div class="table-fit">
          <table class="grid bus-table">
            <thead>
              <tr>
                <th>Axis</th>
                <th class="r hide-phone">Id</th>
                <th>Drive</th>
                <th>Plant</th>
                <th class="r">Dead time</th>
                <th class="r hide-phone">Enable delay</th>
              </tr>
            </thead>
            <tbody>
              {list.map((a) => (
                <SimAxisRow key={a.id} a={a} state={st.get(a.config.name)?.status?.state ?? a.state} />
              ))}
            </tbody>
          </table>
        </div>
      )}
    </div>
  );
}

function SimAxisRow({ a, state }: { a: AxisResource; state: AxisResource['state'] }) {
  const d = a.config.drive?.kind === 'cia402' ? undefined : a.config.drive;
  return (
    <tr data-axis={a.config.name}>
      <td class="nowrap">
        <Lamp state={state} />
        <a href={href({ page: 'axis', axis: a.config.name, tab: 'config' })}>
          <b>{a.config.name}</b>
        </a>
      </td>
      <td class="r mono hide-phone">{a.id}</td>
      <td data-drive-kind={driveKind(a)}>{driveKind(a)}</td>
      <td>{plantText(d?.plant).replace(/ /g, '\u00a0').replace(/,\u00a0/g, ', ')}</td>
      <td class="r mono nowrap">{ms(d?.dead_time)}</td>
      <td class="r mono nowrap hide-phone">{ms(d?.enable_delay)}</td>
    </tr>
  );
}
