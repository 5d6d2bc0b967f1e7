import type { ComponentChildren } from 'preact';
import { useState } from 'preact/hooks';
import { stateLamp, STATE_LABEL } from '../../format';
import type { AxisState } from '../../api/types';
import { ApiError, NOT_A_NUMBER } from '../../api/problem';
import { RpcError } from '../../live/client';
import { errorInfo } from '../../api/errors';
import { useStore } from '../../store';
import { live } from '../../services';

/** Whether the socket to motiond is open: every command button is disabled while it is not. */
export function useOnline(): boolean {
  return useStore(live.state).kind === 'open';
}

export function Lamp({ state, errorId = 0, label = false, title }: { state?: AxisState; errorId?: number; label?: boolean; title?: string }) {
  const text = state ? STATE_LABEL[state] : 'unknown';
  return (
    <span class="lamp-wrap" title={title ?? text} data-state={state ?? 'unknown'}>
      <span class={`lamp ${stateLamp(state, errorId)}`} />
      {label && <span class="lamp-label">{text}</span>}
    </span>
  );
}

/** A status LED with its name (TwinCAT online tab style). */
export function Led({ on, label, tone = 'green', title }: { on: boolean | undefined; label: string; tone?: 'green' | 'red' | 'amber' | 'blue'; title?: string }) {
  return (
    <span class={`led ${on ? `led-on led-${tone}` : ''}`} title={title ?? label} data-led={label} data-on={on ? '1' : '0'}>
      <span class="led-dot" />
      {label}
    </span>
  );
}

/** A key figure: its label above its value; `tone` colours it (ok green, warn amber, bad red). */
export function Kpi({ label, value, name, tone, title }: { label: string; value: string; name: string; tone?: 'ok' | 'warn' | 'bad'; title?: string }) {
  return (
    <div class={`kpi ${tone ? `kpi-${tone}` : ''}`} data-kpi={name} title={title}>
      <span class="kpi-label">{label}</span>
      <span class="kpi-value mono">{value}</span>
    </div>
  );
}

export function Panel({ title, children, class: cls, actions, id }: { title: ComponentChildren; children: ComponentChildren; class?: string; actions?: ComponentChildren; id?: string }) {
  return (
    <section class={`panel ${cls ?? ''}`} id={id}>
      <header class="panel-head">
        <h3>{title}</h3>
        {actions && <div class="panel-actions">{actions}</div>}
      </header>
      <div class="panel-body">{children}</div>
    </section>
  );
}

/** A label + input + the server's message for that field. */
export function Field({ label, error, hint, children, class: cls, name }: { label: ComponentChildren; error?: string; hint?: ComponentChildren; children: ComponentChildren; class?: string; name?: string }) {
  return (
    <label class={`field ${error ? 'has-error' : ''} ${cls ?? ''}`} data-field={name}>
      <span class="field-label">{label}</span>
      {children}
      {error ? <span class="field-error" role="alert">{error}</span> : hint ? <span class="field-hint">{hint}</span> : null}
    </label>
  );
}

/** Whether a number field's text is a number (blank is not: it is "nothing typed"). */
export function isNumberText(s: string): boolean {
  const t = s.trim().replace(',', '.');
  return t !== '' && Number.isFinite(Number(t));
}

/**
 * A number input that keeps the text as typed (so "1." or "-" can be entered). Text that is
 * not a number is said beside the field in words ("enter a number") once the field is left —
 * while typing "-" on the way to "-5" nothing flickers; a request with it is never sent
 * (api/problem.ts: NotSentError, whose field error the form shows the same way).
 */
export function NumberInput({ value, onValue, name, placeholder, step = 'any', disabled, class: cls, title }: {
  value: string;
  onValue: (v: string) => void;
  name?: string;
  placeholder?: string;
  step?: string;
  disabled?: boolean;
  class?: string;
  title?: string;
}) {
  const [focused, setFocused] = useState(false);
  const invalid = value.trim() !== '' && !isNumberText(value);
  return (
    <>
      <input
        class={`num ${invalid ? 'num-invalid' : ''} ${cls ?? ''}`}
        type="text"
        inputMode="decimal"
        name={name}
        value={value}
        placeholder={placeholder}
        disabled={disabled}
        step={step}
        title={title}
        aria-invalid={invalid ? 'true' : undefined}
        autocomplete="off"
        spellcheck={false}
        onFocus={() => setFocused(true)}
        onBlur={() => setFocused(false)}
        onInput={(e) => onValue((e.target as HTMLInputElement).value)}
      />
      {invalid && !focused && (
        <span class="field-error num-error" role="alert" data-num-error={name}>
          {NOT_A_NUMBER}
        </span>
      )}
    </>
  );
}

/**
 * Parses an input: '' → the fallback (or NaN), otherwise the number. A text that is not a
 * number gives NaN, which the REST client refuses to send (NotSentError at that field).
 */
export function parseNum(s: string, fallback?: number): number {
  const t = s.trim().replace(',', '.');
  if (t === '') return fallback ?? NaN;
  const v = Number(t);
  return v;
}

/** The text of an error for a banner: problem title/detail with the error number. */
export function errorText(e: unknown): string {
  if (e instanceof ApiError || e instanceof RpcError) {
    const p = e.problem;
    if (p) {
      const id = p.error_id ? ` (${errorInfo(p.error_id).hex})` : '';
      return `${p.title}: ${p.detail}${id}`;
    }
    return e.message;
  }
  return e instanceof Error ? e.message : String(e);
}

export function fieldsOf(e: unknown): Record<string, string> {
  return e instanceof ApiError || e instanceof RpcError ? e.fields : {};
}

/** A button that shows it is busy while its async action runs. */
export function ActionButton({ onClick, children, class: cls, disabled, title, name, kind }: {
  onClick: () => Promise<unknown> | void;
  children: ComponentChildren;
  class?: string;
  disabled?: boolean;
  title?: string;
  name?: string;
  kind?: 'primary' | 'danger' | 'warn' | 'plain';
}) {
  const [busy, setBusy] = useState(false);
  const click = async (ev: MouseEvent) => {
    ev.preventDefault();
    if (busy) return;
    setBusy(true);
    try {
      await onClick();
    } catch {
      /* shown by the caller */
    } finally {
      setBusy(false);
    }
  };
  return (
    <button type="button" class={`btn btn-${kind ?? 'plain'} ${busy ? 'busy' : ''} ${cls ?? ''}`} disabled={disabled} title={title} name={name} onClick={click}>
      {children}
    </button>
  );
}

export function ErrorBanner({ error, onClose }: { error: string | null; onClose?: () => void }) {
  if (!error) return null;
  return (
    <div class="banner banner-error banner-float" role="alert">
      <span>{error}</span>
      {onClose && (
        <button type="button" class="banner-close" name="dismiss-error" onClick={onClose} aria-label="dismiss" title="dismiss">
          ×
        </button>
      )}
    </div>
  );
}

/** Offers `text` as a CSV file download. */
export function download(name: string, text: string): void {
  const blob = new Blob([text], { type: 'text/csv' });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
