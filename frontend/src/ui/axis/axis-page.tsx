import { useEffect, useState } from 'preact/hooks';
import { useStore } from '../../store';
import { axes, axesLoaded, command, statuses } from '../../services';
import { href, type AxisTab } from '../../router';
import { ActionButton, Lamp, useOnline } from '../shared/common';
import { STATE_LABEL, axisError } from '../../format';
import { OnlineTab } from './online';
import { ParametersTab } from '../config/parameters';
import { AxisConfigPage } from '../config/axis-config';
import { CouplingTab } from './coupling';
import { FunctionsTab } from './functions';
import { DRIVE_EXECUTED_TEXT, isDriveExecuted } from '../../axis/drive-executed';

export function AxisPage({ axis, tab }: { axis: string; tab: AxisTab }) {
  const list = useStore(axes);
  const loaded = useStore(axesLoaded);
  const st = useStore(statuses);
  const online = useOnline();
  const a = list.find((x) => x.config.name === axis);
  const [resetError, setResetError] = useState<string | null>(null);
  useEffect(() => setResetError(null), [axis]);
  if (!a) {
    return (
      <div class="page">
        {loaded ? (
          <p>
            There is no axis <b>{axis}</b>. <a href="#/">Overview</a>
          </p>
        ) : (
          <p class="muted">Loading…</p>
        )}
      </div>
    );
  }
  const live = st.get(axis);
  const s = live?.status;
  const err = axisError(s);
  // `short`: the label on a phone, where the five tabs share 390 px.
  const tabLink = (t: typeof tab, label: string, short?: string) => (
    <a href={href({ page: 'axis', axis, tab: t })} class={`tab ${tab === t ? 'active' : ''}`} data-tab={t} title={label}>
      {short ? (
        <>
          <span class="tab-long">{label}</span>
          <span class="tab-short">{short}</span>
        </>
      ) : (
        label
      )}
    </a>
  );
  return (
    <div class="page page-axis">
      <div class="axis-head">
        <h2>
          <Lamp state={s?.state ?? a.state} errorId={s?.error_id ?? 0} />
          {a.config.name}
        </h2>
        <span class="axis-state" data-testid="axis-state">
          {STATE_LABEL[s?.state ?? a.state]}
        </span>
        {isDriveExecuted(a.config, s) && (
          <span
            class="tag tag-blue drive-executed"
            data-testid="drive-executed"
            title="TwinCAT Drive Motion Control: the CiA-402 drive runs profile position, velocity and homing itself from the targets motiond sends (no setpoint every cycle). Only its blocks are offered: power, reset, set position, home, jog, halt, stop, the moves (absolute, relative, modulo, velocity), touch probe; no jerk, no override, no coupling."
          >
            {DRIVE_EXECUTED_TEXT}
          </span>
        )}
        <span class="muted small">
          id {a.id} · {a.config.unit}
          {a.config.modulo ? ` · modulo ${a.config.modulo.period}` : ''}
          {a.config.soft_limits ? ` · soft limits ${a.config.soft_limits.min} … ${a.config.soft_limits.max}` : ''}
          {a.config.drive?.kind === 'cia402' ? ` · CiA-402 drive, SubDevice ${a.config.drive.subdevice}` : ''}
        </span>
        <nav class="tabs">
          {tabLink('online', 'Online')}
          {tabLink('coupling', 'Coupling')}
          {tabLink('functions', 'Functions')}
          {tabLink('parameters', 'Parameters', 'Params')}
          {tabLink('config', 'Configuration', 'Config')}
        </nav>
      </div>
      {err && (
        <div class="banner banner-error axis-error" role="alert" data-testid="axis-error">
          <span>
            <b>Axis in error</b> ·{' '}
            {err.hex && (
              <>
                <b>{err.hex}</b> <code>{err.code}</code> —{' '}
              </>
            )}
            <span data-testid="axis-error-text">{err.text}</span>
            {err.driveCode && (
              <>
                {' '}
                — <span data-testid="axis-drive-code" title="the drive's own error code (CiA-402 0x603F)">drive code <b>{err.driveCode}</b></span>
              </>
            )}
          </span>
          <ActionButton
            kind="danger"
            name="reset-error"
            title="MC_Reset (F8 on the Online tab)"
            disabled={!online}
            onClick={async () => {
              try {
                setResetError(null);
                await command(axis, 'reset', {});
              } catch (e) {
                setResetError((e as Error).message);
              }
            }}
          >
            Reset
          </ActionButton>
          {resetError && <span class="small">{resetError}</span>}
        </div>
      )}
      {/* Keyed by the axis's id: another axis (or one replaced under the same name by an
          import) starts with fresh state, never the previous axis's inputs or parameters. */}
      {tab === 'online' && <OnlineTab key={a.id} axis={a} />}
      {tab === 'coupling' && <CouplingTab key={a.id} axis={a} />}
      {tab === 'functions' && <FunctionsTab key={a.id} axis={a} />}
      {tab === 'parameters' && <ParametersTab key={a.id} axis={a} />}
      {tab === 'config' && <AxisConfigPage key={a.id} axis={a} />}
    </div>
  );
}
