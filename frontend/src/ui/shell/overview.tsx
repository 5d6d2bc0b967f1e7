import { useStore } from '../../store';
import { axes, statuses } from '../../services';
import { Lamp } from '../shared/common';
import { pos, vel, STATE_LABEL, axisError } from '../../format';
import { href, navigate } from '../../router';
import { CommandLog } from '../shared/command-log';
import { Panel } from '../shared/common';

export function Overview() {
  const list = useStore(axes);
  const st = useStore(statuses);
  return (
    <div class="page page-overview">
      <div class="page-head">
        <h2>Axes</h2>
        <span class="muted">{list.length} configured · live at 25 Hz</span>
        <a class="btn btn-plain" href="#/new-axis">
          + New axis
        </a>
      </div>
      <div class="table-scroll">
        <table class="grid overview-table" data-testid="overview">
          <thead>
            <tr>
              <th>Axis</th>
              <th>State</th>
              <th class="r">Set position</th>
              <th class="r">Actual position</th>
              <th class="r">Set velocity</th>
              <th class="r">Actual velocity</th>
              <th class="r">Following error</th>
              <th>Enabled</th>
              <th>Homed</th>
              <th>Error</th>
            </tr>
          </thead>
          <tbody>
            {list.map((a) => {
              const live = st.get(a.config.name);
              const s = live?.status;
              const u = a.config.unit;
              const err = axisError(s);
              return (
                <tr
                  key={a.id}
                  class={`clickable ${err ? 'row-error' : ''} ${live?.stale ? 'stale' : ''}`}
                  data-axis={a.config.name}
                  onClick={() => navigate({ page: 'axis', axis: a.config.name, tab: 'online' })}
                >
                  <td data-col="axis">
                    <a href={href({ page: 'axis', axis: a.config.name, tab: 'online' })} class="axis-name">
                      {a.config.name}
                    </a>
                    <span class="muted small"> {u}{a.config.modulo ? ` · modulo ${a.config.modulo.period}` : ''}</span>
                  </td>
                  <td class="nowrap" data-col="state">
                    <Lamp state={s?.state ?? a.state} errorId={s?.error_id ?? 0} />
                    {STATE_LABEL[s?.state ?? a.state]}
                  </td>
                  <td class="r mono" data-col="set_position" data-label="Set position">{pos(s?.set_position)}</td>
                  <td class="r mono" data-col="actual_position" data-label="Actual position">{pos(s?.actual_position)}</td>
                  <td class="r mono" data-col="set_velocity" data-label="Set velocity">{vel(s?.set_velocity)}</td>
                  <td class="r mono" data-col="actual_velocity" data-label="Actual velocity">{vel(s?.actual_velocity)}</td>
                  <td class="r mono" data-col="following_error" data-label="Following error">{pos(s?.following_error)}</td>
                  <td data-col="enabled" data-label="Enabled">{s?.power_status ? <span class="tag tag-green">on</span> : <span class="tag">off</span>}</td>
                  <td data-col="homed" data-label="Homed">{s?.homed ? <span class="tag tag-green">homed</span> : <span class="tag">no</span>}</td>
                  <td class="err-cell" data-col="error">
                    {err ? (
                      <span class="err-text" title={err.code ?? undefined}>
                        {err.hex && <b>{err.hex}</b>} {err.text}
                        {err.driveCode && <> — drive code {err.driveCode}</>}
                      </span>
                    ) : s?.drive_fault ? (
                      <span class="err-text">drive fault</span>
                    ) : (
                      ''
                    )}
                  </td>
                </tr>
              );
            })}
            {list.length === 0 && (
              <tr>
                <td colSpan={10} class="muted empty">
                  No axes yet. <a href="#/new-axis">Create one</a>.
                </td>
              </tr>
            )}
          </tbody>
        </table>
      </div>
      <Panel title="Recent commands (all axes)" class="overview-log">
        <CommandLog limit={15} />
      </Panel>
    </div>
  );
}
