import { useStore } from '../../store';
import { commandLog, type LogEntry } from '../../services';
import { time } from '../../format';
import { hexId } from '../../api/errors';

function params(p: unknown): string {
  if (!p || typeof p !== 'object') return '';
  return Object.entries(p as Record<string, unknown>)
    .filter(([k]) => k !== 'deadman_timeout')
    .map(([k, v]) => `${k}=${typeof v === 'object' ? JSON.stringify(v) : String(v)}`)
    .join(' ');
}

const STATE_CLASS: Record<string, string> = {
  busy: 'tag-blue',
  active: 'tag-blue',
  done: 'tag-green',
  aborted: 'tag-amber',
  error: 'tag-red',
  rejected: 'tag-red',
};

export function CommandLog({ axis, limit = 40 }: { axis?: string; limit?: number }) {
  const all = useStore(commandLog);
  const list: LogEntry[] = (axis ? all.filter((e) => e.axis === axis) : all).slice(0, limit);
  return (
    <div class="log-wrap">
      <table class="grid log-table" data-testid="command-log">
        <thead>
          <tr>
            <th>Time</th>
            <th class="r">#</th>
            {!axis && <th>Axis</th>}
            <th>Command</th>
            <th>Parameters</th>
            <th>State</th>
            <th>Error</th>
          </tr>
        </thead>
        <tbody>
          {list.map((e) => (
            <tr key={e.key} data-command={e.command} data-state={e.state}>
              <td class="mono nowrap">{time(e.at)}</td>
              <td class="r mono">{e.id ?? '—'}</td>
              {!axis && <td>{e.axis}</td>}
              <td class="nowrap">{e.command}</td>
              <td class="params mono" title={params(e.parameters)}>
                {params(e.parameters)}
              </td>
              <td>
                <span class={`tag ${STATE_CLASS[e.state] ?? ''}`}>{e.state}</span>
              </td>
              <td class="err-cell">
                {e.errorId ? <b>{hexId(e.errorId)} </b> : null}
                {e.errorText}
              </td>
            </tr>
          ))}
          {list.length === 0 && (
            <tr>
              <td colSpan={7} class="muted empty">
                No commands yet.
              </td>
            </tr>
          )}
        </tbody>
      </table>
    </div>
  );
}
