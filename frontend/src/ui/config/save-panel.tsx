// The confirmation before an axis configuration is saved: what the server's dry run says the
// save will do (parameters written online, or the axis re-created and what that loses, and the
// persistent values given up), then Save / Cancel. A save that re-creates the axis is blocked
// while the axis is not disabled, with the reason and a way to switch it off.
import type { ComponentChildren } from 'preact';
import { useEffect, useRef } from 'preact/hooks';
import { ActionButton } from '../shared/common';
import type { ParameterResource } from '../../api/types';
import { type ConfigChange, changeRows, changeSummary, lostOnlineValues, valueText } from '../../config/change';

export interface SavePanelProps {
  /** The dry run's answer. */
  change: ConfigChange;
  axis: string;
  /** The name after the save (a rename is said). */
  newName: string;
  unit: string;
  /** The axis's position now, when known. */
  position: number | null;
  /** Why a save that re-creates the axis is blocked now (live status), or null. */
  blocked: string | null;
  /** The axis's parameters as read before the save (the online values a rebuild loses). */
  params: Iterable<ParameterResource> | null;
  /** The axis is powered: "Disable now" can help. */
  powered: boolean;
  online: boolean;
  saving: boolean;
  onSave: () => void;
  onCancel: () => void;
  onDisable: () => Promise<void>;
}

function Section({ title, children, testid }: { title: string; children: ComponentChildren; testid: string }) {
  return (
    <div class="cfgsave-section" data-testid={testid}>
      <h4>{title}</h4>
      {children}
    </div>
  );
}

export function SavePanel(p: SavePanelProps) {
  const { change } = p;
  const s = changeSummary(change, { unit: p.unit, position: p.position });
  const rows = changeRows(change.parameters);
  const discarded = changeRows(change.persistent_discarded);
  const lost = lostOnlineValues(p.params, change);
  const saveBlocked = change.rebuild && !!p.blocked;
  const cancelRef = useRef<HTMLButtonElement>(null);
  useEffect(() => {
    cancelRef.current?.focus();
    const key = (e: KeyboardEvent) => {
      if (e.key === 'Escape') p.onCancel();
    };
    document.addEventListener('keydown', key);
    return () => document.removeEventListener('keydown', key);
  }, []);
  // The configured value the save sets where a persistent one is given up.
  const nextOf = new Map(change.parameters.map((c) => [c.number, valueText(c.new)]));
  return (
    <div class="cfgsave-backdrop" onClick={(e) => e.target === e.currentTarget && p.onCancel()}>
      <div class={`cfgsave cfgsave-${s.tone}`} role="dialog" aria-modal="true" aria-labelledby="cfgsave-title" data-testid="save-panel" data-rebuild={change.rebuild ? '1' : '0'}>
        <h3 id="cfgsave-title">Save the configuration of {p.axis}?</h3>
        <p class={`cfgsave-headline cfgsave-headline-${s.tone}`} data-testid="save-headline">
          {s.tone === 'warn' && <b>Warning: </b>}
          {s.headline}
        </p>
        {p.newName !== p.axis && (
          <p class="cfgsave-note">
            The axis is renamed <b>{p.axis}</b> → <b>{p.newName}</b>.
          </p>
        )}
        {rows.length > 0 && (
          <Section title={`Parameters changed (${rows.length})`} testid="save-changes">
            <div class="table-scroll">
              <table class="grid cfgsave-table">
                <thead>
                  <tr>
                    <th class="r c-no">No.</th>
                    <th>Name</th>
                    <th class="r">Configured</th>
                    <th></th>
                    <th class="r">New</th>
                    <th class="r" title="the value in force now, where an online or persistent write made it differ from the configured one">Online now</th>
                  </tr>
                </thead>
                <tbody>
                  {rows.map((r) => (
                    <tr key={r.number} data-param={r.name}>
                      <td class="r mono c-no">{r.number}</td>
                      <td>{r.name}</td>
                      <td class="r mono old">{r.configured}</td>
                      <td>→</td>
                      <td class="r mono new">{r.next}</td>
                      <td class="r mono online">{r.online ?? ''}</td>
                    </tr>
                  ))}
                </tbody>
              </table>
            </div>
          </Section>
        )}
        {discarded.length > 0 && (
          <Section title={`Persistent values discarded (${discarded.length})`} testid="save-discarded">
            <ul class="cfgsave-list">
              {discarded.map((d) => (
                <li key={d.number} data-param={d.name}>
                  <b>{d.name}</b> (#{d.number}): persistent <span class="mono old">{d.next}</span>
                  {nextOf.has(d.number) ? (
                    <>
                      {' '}
                      is given up; the configured <span class="mono">{nextOf.get(d.number)}</span> applies
                    </>
                  ) : (
                    ' is given up'
                  )}
                </li>
              ))}
            </ul>
          </Section>
        )}
        {lost.length > 0 && (
          <Section title={`Online values lost (${lost.length})`} testid="save-lost">
            <ul class="cfgsave-list">
              {lost.map((l) => (
                <li key={l.number} data-param={l.name}>
                  <b>{l.name}</b> (#{l.number}): online <span class="mono old">{l.online}</span> → <span class="mono">{l.after}</span>{' '}
                  <span class="muted">({l.from})</span>
                </li>
              ))}
            </ul>
          </Section>
        )}
        {!change.rebuild && rows.length > 0 && (
          <p class="muted small cfgsave-note">Persistent values of the parameters this save does not change are kept.</p>
        )}
        {saveBlocked && (
          <div class="cfgsave-blocked" id="save-blocked" data-testid="save-blocked">
            <span>{p.blocked}</span>
            {p.powered && (
              <ActionButton kind="warn" name="disable-axis" disabled={!p.online} onClick={p.onDisable}>
                Disable {p.axis} now
              </ActionButton>
            )}
          </div>
        )}
        <div class="form-actions cfgsave-actions">
          <button
            type="button"
            class={`btn ${change.rebuild ? 'btn-danger' : 'btn-primary'}`}
            name="confirm-save"
            disabled={!p.online || p.saving || saveBlocked}
            aria-describedby={saveBlocked ? 'save-blocked' : undefined}
            onClick={p.onSave}
          >
            {p.saving ? 'Saving…' : change.rebuild ? 'Save and re-create' : 'Save'}
          </button>
          <button type="button" class="btn" name="cancel-save" ref={cancelRef} onClick={p.onCancel}>
            Cancel
          </button>
        </div>
      </div>
    </div>
  );
}

/** What the answer of the real save says happened (under the form, after the save). */
export function SaveResult({ change, onClose }: { change: ConfigChange; onClose: () => void }) {
  const s = changeSummary(change);
  const rows = changeRows(change.parameters);
  return (
    <div class={`banner ${s.tone === 'warn' ? 'banner-warn' : 'banner-ok'} cfgsave-result`} data-testid="save-result" data-rebuild={change.rebuild ? '1' : '0'}>
      <span>
        <b>{s.headline}</b>
        {rows.length > 0 && (
          <span class="cfgsave-result-list">
            {' '}
            {rows.map((r, i) => (
              <span key={r.number} data-param={r.name}>
                {i ? ', ' : ''}
                {r.name} {r.configured} → {r.next}
              </span>
            ))}
            .
          </span>
        )}
        {s.persistent && <span> {s.persistent}</span>}
      </span>
      <button type="button" class="banner-close" onClick={onClose} aria-label="dismiss">
        ×
      </button>
    </div>
  );
}
