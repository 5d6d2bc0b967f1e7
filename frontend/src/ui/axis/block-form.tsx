// What the block panels of the axis tabs (Coupling, Functions) share: the form fields, the sender
// that shows a refusal at its fields, the props every panel gets, a live readout row and the
// release of an Enable-type block.
import type { ComponentChildren } from 'preact';
import { command, releaseCommand } from '../../services';
import type { AxisLiveStatus, AxisResource, ParameterResource } from '../../api/types';
import type { BlockBody, BlockName, BlockOptions } from '../../api/blocks';
import { Field, NumberInput, errorText, fieldsOf } from '../shared/common';
import { label, type Built, type Form } from '../../axis/bodies';
import { NOT_OFFERED } from '../../axis/drive-executed';

/** A text input of a form record with its field error. */
export function NumField({ f, set, k, label: l, errors, hint, name, placeholder, disabled }: { f: Form; set: (k: string, v: string) => void; k: string; label: ComponentChildren; errors: Record<string, string>; hint?: string; name?: string; placeholder?: string; disabled?: boolean }) {
  const n = name ?? k;
  return (
    <Field label={l} error={errors[k]} name={n}>
      <NumberInput name={n} value={f[k] ?? ''} onValue={(v) => set(k, v)} placeholder={placeholder} title={hint} disabled={disabled} />
    </Field>
  );
}

/** A select of a form record with its field error. */
export function SelectField({ f, set, k, label: l, errors, options, name, blank, disabled, title }: {
  f: Form;
  set: (k: string, v: string) => void;
  k: string;
  label: ComponentChildren;
  errors: Record<string, string>;
  /** A value, or value and text, or value, text and why it cannot be chosen (null: it can). */
  options: (string | [string, string] | [string, string, string | null])[];
  name?: string;
  blank?: string;
  disabled?: boolean;
  title?: string;
}) {
  const n = name ?? k;
  return (
    <Field label={l} error={errors[k]} name={n}>
      <select name={n} value={f[k] ?? ''} disabled={disabled} title={title} onChange={(e) => set(k, (e.target as HTMLSelectElement).value)}>
        {blank !== undefined && <option value="">{blank}</option>}
        {options.map((o) => {
          const [v, t, why]: [string, string, (string | null)?] = Array.isArray(o) ? o : [o, label(o)];
          return (
            <option value={v} disabled={!!why} title={why ?? undefined}>
              {t}
            </option>
          );
        })}
      </select>
    </Field>
  );
}

/**
 * Sends a block from a form: the body's own checks first, then the server's answer; a refusal
 * is shown at its fields (problem+json errors[].field) and in the banner. The body is checked by
 * tsc against the block's (api/blocks.ts); `options.query`: `wait`, `timeout_ms`.
 */
export function useSender(axis: string, setBanner: (s: string | null) => void) {
  return async <N extends BlockName>(name: N, built: Built<BlockBody<N>>, setErrors: (e: Record<string, string>) => void, options?: BlockOptions<N>) => {
    setErrors(built.errors);
    setBanner(null);
    if (Object.keys(built.errors).length) return null;
    try {
      return await command(axis, name, built.body, options);
    } catch (e) {
      setErrors(fieldsOf(e));
      setBanner(errorText(e));
      return null;
    }
  };
}

export type Sender = ReturnType<typeof useSender>;

/** What the block panels of an axis tab share. */
export interface BlockProps {
  axis: AxisResource;
  /** The axis's live status (null until it arrives). */
  s: AxisLiveStatus | null;
  online: boolean;
  send: Sender;
  setBanner: (s: string | null) => void;
  /** The axis's parameters (what a blank field stands for), null while they load. */
  params: Map<number, ParameterResource> | null;
  /** The drive runs the axis's profile (Drive Motion Control): only its blocks are offered. */
  driveExecuted: boolean;
}

/**
 * The note of a panel whose blocks an axis whose drive runs the profile does not offer (they are
 * shown disabled beside it); `what` names them.
 */
export function NotOffered({ what }: { what: string }) {
  return (
    <p class="small panel-note not-offered" data-testid="not-offered">
      {what}: {NOT_OFFERED}.
    </p>
  );
}

/** A live value: label, value, unit (the online tab's readout row). */
export function Readout({ label, value, unit, name, title }: { label: ComponentChildren; value: string; unit?: string; name: string; title?: string }) {
  return (
    <div class="dro-row" data-readout={name} title={title}>
      <span class="dro-label">{label}</span>
      <span class="dro-value mono">{value}</span>
      <span class="dro-unit">{unit ?? ''}</span>
    </div>
  );
}

/** Releases an Enable-type command (DELETE /commands/{id}); a refusal goes to the banner. */
export async function release(id: number, axis: string, setBanner: (s: string | null) => void): Promise<void> {
  try {
    setBanner(null);
    await releaseCommand(id, axis);
  } catch (e) {
    setBanner(errorText(e));
  }
}
