// The axis "Functions" tab (TwinCAT XAE: the axis's Functions tab): the reversing sequence for
// tuning (two positions, velocity, dwell, repeats or endless; run by this page as waited
// MC_MoveAbsolute calls, stopped by Stop with an MC_Halt and ended when the page leaves) and
// MC_Home with its mode and options, the homing phase live and the reason a homing failed;
// MC_TorqueControl with the drive's operation mode, the position correction and the encoder
// (function-blocks.tsx).
import { useEffect, useRef, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { command, statuses } from '../../services';
import type { AxisResource, CommandResource } from '../../api/types';
import { href } from '../../router';
import { ActionButton, ErrorBanner, Field, Led, NumberInput, Panel, errorText, fieldsOf, useOnline } from '../shared/common';
import { pos } from '../../format';
import { errorInfo } from '../../api/errors';
import { LiveIndicator } from '../shared/liveness';
import { HOME_DEFAULTS, REFERENCE_MODES, homeBody } from '../../axis/bodies';
import { abortableSleep, reversingConfig, runReversing, type ReversingEnd, type ReversingStep } from '../../axis/reversing';
import { useCommand, useForm } from '../../axis/hooks';
import { NumField, SelectField, useSender } from './block-form';
import { P_HOME_POSITION, P_HOME_SEARCH_INVERSE, P_HOME_SEARCH_VELOCITY, P_HOME_SYNC_INVERSE, P_HOME_SYNC_VELOCITY, P_REFERENCE_MODE, paramDefault, useLiveParameters } from './axis-params';
import { EncoderPanel, PositionCorrectionPanel, TorquePanel } from './function-blocks';
import { driveHomingText, homeModeOptions, homesInDrive, isDriveExecuted } from '../../axis/drive-executed';

/** Longest wait for one move of the sequence (the server's limit). */
const MOVE_TIMEOUT_MS = 600000;

type RunState = { kind: 'idle' } | { kind: 'running'; step: ReversingStep | null } | ReversingEnd;

export function FunctionsTab({ axis: a }: { axis: AxisResource }) {
  const axis = a.config.name;
  const u = a.config.unit;
  const st = useStore(statuses);
  const online = useOnline();
  const offline = !online;
  const liveStatus = st.get(axis);
  const s = liveStatus?.status ?? null;
  // The drive runs the profile (Drive Motion Control): its blocks only.
  const de = isDriveExecuted(a.config, s);
  const [banner, setBanner] = useState<string | null>(null);
  const send = useSender(axis, setBanner);

  // --- reversing sequence -----------------------------------------------------------------
  const [rev, setRev] = useForm({ position1: '0', position2: '100', velocity: '', dwell: '1', repeats: '5', endless: '' });
  const [revErr, setRevErr] = useState<Record<string, string>>({});
  const [run, setRun] = useState<RunState>({ kind: 'idle' });
  const [cycles, setCycles] = useState(0);
  const ctl = useRef<AbortController | null>(null);
  const running = run.kind === 'running';
  useEffect(() => {
    if (rev.velocity === '' && a.config.dynamics?.jog_velocity_fast) setRev('velocity', String(a.config.dynamics.jog_velocity_fast));
  }, []);

  const halt = () => command(axis, 'halt', {}).catch((e) => setBanner(errorText(e)));
  // Leaving the page ends the sequence (and halts the move it was making).
  useEffect(
    () => () => {
      if (ctl.current && !ctl.current.signal.aborted) {
        ctl.current.abort();
        void command(axis, 'halt', {}).catch(() => {});
      }
    },
    [],
  );

  const start = async () => {
    const { config, errors } = reversingConfig({ position1: rev.position1, position2: rev.position2, velocity: rev.velocity, dwell: rev.dwell, repeats: rev.repeats, endless: rev.endless === '1' });
    setRevErr(errors);
    setBanner(null);
    if (!config) return;
    const c = new AbortController();
    ctl.current = c;
    setCycles(0);
    setRun({ kind: 'running', step: null });
    const end = await runReversing(
      config,
      {
        move: async (position, velocity) => {
          try {
            const r: CommandResource = await command(axis, 'move-absolute', { position, velocity }, { query: { wait: true, timeout_ms: MOVE_TIMEOUT_MS } });
            return r.state === 'done';
          } catch (e) {
            const f = fieldsOf(e);
            if (f.velocity) setRevErr({ velocity: f.velocity });
            if (f.position) setRevErr({ [position === config.position1 ? 'position1' : 'position2']: f.position });
            throw e;
          }
        },
        sleep: abortableSleep,
        onCycle: (n) => {
          if (ctl.current === c) setCycles(n);
        },
        onStep: (step) => {
          if (ctl.current === c) setRun({ kind: 'running', step });
        },
      },
      c.signal,
    );
    if (ctl.current !== c) return;
    ctl.current = null;
    setRun(end);
    if (end.kind === 'failed') setBanner(`Reversing sequence ended: ${errorText(end.error)}`);
  };
  const stop = async () => {
    ctl.current?.abort();
    await halt();
  };

  const runText = (() => {
    switch (run.kind) {
      case 'idle':
        return 'idle';
      case 'running':
        return !run.step ? 'starting' : run.step.kind === 'move' ? `moving to ${run.step.position} ${u}` : run.step.kind === 'dwell' ? `dwelling ${run.step.ms / 1000} s` : 'running';
      case 'finished':
        return 'finished';
      case 'stopped':
        return 'stopped';
      default:
        return 'failed';
    }
  })();

  // --- homing -----------------------------------------------------------------------------
  const [home, setHome] = useForm(HOME_DEFAULTS);
  const [homeErr, setHomeErr] = useState<Record<string, string>>({});
  const [homeId, setHomeId] = useState<number | null>(null);
  const homeCmd = useCommand(homeId);
  // Homing in the drive: its method, not motiond's referencing options.
  const inDrive = homesInDrive(home.mode, de);
  const startHome = async () => {
    const r = await send('home', homeBody(home, inDrive), setHomeErr);
    if (r) setHomeId(r.id);
  };
  const homeFailed = homeCmd && homeCmd.final && (homeCmd.state === 'error' || homeCmd.outputs.error_id !== 0) ? homeCmd : null;
  const dirs: [string, string][] = [
    ['positive', 'positive'],
    ['negative', 'negative'],
  ];
  // A blank homing field is the axis's parameter: its value now is the placeholder.
  const params = useLiveParameters(axis, a.id);
  const dirOf = (n: number) => {
    const v = params?.get(n)?.value;
    return typeof v === 'boolean' ? (v ? 'negative' : 'positive') : '';
  };
  const refMode = (() => {
    const v = params?.get(P_REFERENCE_MODE)?.value;
    return typeof v === 'number' ? (REFERENCE_MODES[v] ?? String(v)).replace(/_/g, ' ') : '';
  })();
  const homePos = paramDefault(params, P_HOME_POSITION);
  const searchVelocity = paramDefault(params, P_HOME_SEARCH_VELOCITY);
  const syncVelocity = paramDefault(params, P_HOME_SYNC_VELOCITY);
  const searchDir = paramDefault(params, P_HOME_SEARCH_INVERSE, dirOf(P_HOME_SEARCH_INVERSE));
  const syncDir = paramDefault(params, P_HOME_SYNC_INVERSE, dirOf(P_HOME_SYNC_INVERSE));
  const refModeDefault = paramDefault(params, P_REFERENCE_MODE, refMode);
  const stale = liveStatus?.stale || offline;
  const blocks = { axis: a, s, online, send, setBanner, params, driveExecuted: de };
  const optionTitle = (t: string) => (inDrive ? `not with homing in the drive (${driveHomingText(a.config)})` : t);

  return (
    <div class={`functions ${stale ? 'stale' : ''}`}>
      <ErrorBanner error={banner} onClose={() => setBanner(null)} />
      <div class="functions-grid">
        <div class="functions-col">
          <Panel title="Reversing sequence" class="reversing" actions={<LiveIndicator cycle={liveStatus?.cycle} stale={stale} />}>
            <form
              class="row"
              onSubmit={(e) => {
                e.preventDefault();
                if (online && !running) void start();
              }}
            >
              <NumField f={rev} set={setRev} k="position1" label={`Position 1 (${u})`} errors={revErr} name="rev-position1" />
              <NumField f={rev} set={setRev} k="position2" label={`Position 2 (${u})`} errors={revErr} name="rev-position2" />
              <NumField f={rev} set={setRev} k="velocity" label={`Velocity (${u}/s)`} errors={revErr} name="rev-velocity" />
              <NumField f={rev} set={setRev} k="dwell" label="Dwell time (s)" errors={revErr} name="rev-dwell" />
              <Field label="Repeats" error={revErr.repeats} name="rev-repeats">
                <NumberInput name="rev-repeats" value={rev.endless === '1' ? '' : rev.repeats} placeholder={rev.endless === '1' ? 'endless' : ''} disabled={rev.endless === '1'} onValue={(v) => setRev('repeats', v)} />
              </Field>
              <label class="check">
                <input type="checkbox" name="rev-endless" checked={rev.endless === '1'} onChange={(e) => setRev('endless', (e.target as HTMLInputElement).checked ? '1' : '')} /> endless
              </label>
              <div class="row-buttons">
                <button type="submit" class="btn btn-primary" name="rev-start" disabled={offline || running} title="Start: move to position 1, dwell, to position 2, dwell … (MC_MoveAbsolute)">
                  Start
                </button>
                <ActionButton name="rev-stop" kind="danger" disabled={offline} title="Stop the sequence (MC_Halt)" onClick={stop}>
                  Stop
                </ActionButton>
              </div>
            </form>
            <div class="rev-status" data-testid="reversing-status" data-state={run.kind}>
              <span>
                Cycle <b class="mono" data-testid="reversing-count">{cycles}</b>
                {rev.endless === '1' ? ' of ∞' : rev.repeats ? ` of ${rev.repeats}` : ''}
              </span>
              <span class="muted" data-testid="reversing-state">
                {runText}
              </span>
              <span class="mono small">
                at {pos(s?.actual_position)} {u}
              </span>
            </div>
            <p class="small muted panel-note">
              The <a href={href({ page: 'scope' })}>Scope</a> page records the sequence (positions, velocities, following error) for tuning. The sequence runs in this page: leaving it
              stops it.
            </p>
          </Panel>

          <TorquePanel {...blocks} />

          <EncoderPanel {...blocks} />
        </div>
        <div class="functions-col">
          <Panel title="Homing" class="homing">
            <form
              class="form-grid homing-form"
              onSubmit={(e) => {
                e.preventDefault();
                if (online) void startHome();
              }}
            >
              <SelectField
                f={home}
                set={setHome}
                k="mode"
                label="Mode"
                errors={homeErr}
                name="home-mode"
                title={inDrive ? driveHomingText(a.config) : 'default: the referencing sequence of the reference mode (#1076)'}
                options={homeModeOptions(a.config, de, true)}
              />
              <Field label={`Home position (${u})`} error={homeErr.position} name="home-position">
                <NumberInput name="home-position" value={home.position} onValue={(v) => setHome('position', v)} placeholder={homePos.placeholder} title={homePos.title} />
              </Field>
              <SelectField f={home} set={setHome} k="reference_mode" label="Reference mode" errors={{ reference_mode: homeErr['options.reference_mode'] }} options={REFERENCE_MODES} name="home-reference-mode" blank={`axis: ${refMode || '…'}`} title={optionTitle(refModeDefault.title)} disabled={inDrive} />
              <SelectField f={home} set={setHome} k="search_direction" label="Search direction" errors={{ search_direction: homeErr['options.search_direction'] }} options={dirs} name="home-search-direction" blank={`axis: ${searchDir.placeholder || '…'}`} title={optionTitle(searchDir.title)} disabled={inDrive} />
              <NumField f={home} set={setHome} k="search_velocity" label={`Search velocity (${u}/s)`} errors={{ search_velocity: homeErr['options.search_velocity'] }} name="home-search-velocity" placeholder={searchVelocity.placeholder} hint={optionTitle(searchVelocity.title)} disabled={inDrive} />
              <SelectField f={home} set={setHome} k="sync_direction" label="Sync direction" errors={{ sync_direction: homeErr['options.sync_direction'] }} options={dirs} name="home-sync-direction" blank={`axis: ${syncDir.placeholder || '…'}`} title={optionTitle(syncDir.title)} disabled={inDrive} />
              <NumField f={home} set={setHome} k="sync_velocity" label={`Sync velocity (${u}/s)`} errors={{ sync_velocity: homeErr['options.sync_velocity'] }} name="home-sync-velocity" placeholder={syncVelocity.placeholder} hint={optionTitle(syncVelocity.title)} disabled={inDrive} />
              <div class="form-actions">
                <label class="check" title="MC_Direct only: set position = actual position afterwards">
                  <input type="checkbox" name="home-clear-lag" checked={home.clear_position_lag === '1'} onChange={(e) => setHome('clear_position_lag', (e.target as HTMLInputElement).checked ? '1' : '')} /> clear lag
                </label>
                <button type="submit" class="btn btn-primary" name="home-start" disabled={offline} title="MC_Home">
                  Start
                </button>
              </div>
            </form>
            {inDrive && (
              <p class="small muted panel-note" data-testid="drive-homing">
                Homing in the drive: {driveHomingText(a.config)}. The reference mode, directions and velocities above are motiond’s referencing and are not sent.
              </p>
            )}
            <div class="led-grid">
              <Led on={s?.homed} label="Homed" />
              <Led on={!!s && s.homing_phase !== 'idle'} label="Homing" tone="blue" />
            </div>
            <dl class="kv">
              <dt>Homing phase</dt>
              <dd class="mono" data-testid="homing-phase">
                {s?.homing_phase ?? '—'}
              </dd>
              <dt>Last homing</dt>
              <dd data-testid="homing-result">{homeCmd ? `#${homeCmd.id} ${homeCmd.state}` : <span class="muted">—</span>}</dd>
            </dl>
            {homeFailed && (
              <div class="banner banner-error" role="alert" data-testid="homing-error">
                <span>
                  <b>Homing failed</b> · <b>{errorInfo(homeFailed.outputs.error_id).hex}</b> <code>{homeFailed.error_code ?? errorInfo(homeFailed.outputs.error_id).code}</code> —{' '}
                  {errorInfo(homeFailed.outputs.error_id).text}
                </span>
              </div>
            )}
          </Panel>

          <PositionCorrectionPanel {...blocks} />
        </div>
      </div>
    </div>
  );
}
