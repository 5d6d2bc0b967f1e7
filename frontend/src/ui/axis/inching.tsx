// Inching (MC_Jog mode inching): one step per click at the slow manual velocity (#1001). The
// steps start as #1015 AxisJogIncrementBackward and #1014 AxisJogIncrementForward; until the
// parameters are known the buttons are disabled (a velocity of 0 would be refused anyway).
import { useEffect, useState } from 'preact/hooks';
import type { ParameterResource } from '../../api/types';
import { command } from '../../services';
import { ActionButton, Field, NumberInput, errorText, fieldsOf, parseNum } from '../shared/common';
import { inputNum } from '../../format';
import { P_INC_BACKWARD, P_INC_FORWARD, P_JOG_SLOW, numParam } from './axis-params';

export function Inching({ axis, unit, params, online, onError, notOffered }: {
  axis: string;
  unit: string;
  params: Map<number, ParameterResource> | null;
  online: boolean;
  onError: (text: string) => void;
  /** Why inching is not offered on this axis (its drive runs the profile: DMC jogs while held only), or null. */
  notOffered?: string | null;
}) {
  const [back, setBack] = useState('');
  const [fwd, setFwd] = useState('');
  const [errors, setErrors] = useState<{ backward?: string; forward?: string }>({});
  useEffect(() => {
    const b = numParam(params, P_INC_BACKWARD);
    const f = numParam(params, P_INC_FORWARD);
    if (back === '' && b !== null) setBack(inputNum(b));
    if (fwd === '' && f !== null) setFwd(inputNum(f));
  }, [params]);
  const velocity = numParam(params, P_JOG_SLOW);
  const inch = async (forward: boolean) => {
    if (velocity === null || notOffered) return;
    const key = forward ? 'forward' : 'backward';
    setErrors({});
    try {
      // One step per click; not held (a positioning job of `position` distance).
      await command(axis, 'jog', {
        direction: key,
        mode: 'inching',
        position: parseNum(forward ? fwd : back),
        velocity,
      });
    } catch (e) {
      const f = fieldsOf(e);
      setErrors({ [key]: f.position ?? f.velocity });
      onError(errorText(e));
    }
  };
  const ready = online && velocity !== null && !notOffered;
  const why = velocity === null ? ' (waiting for the parameters)' : '';
  if (notOffered) {
    return (
      <div class="row inching" data-testid="inching-not-offered">
        <span class="small muted">Inching (one step per click) is {notOffered}: hold a jog button.</span>
      </div>
    );
  }
  return (
    <div class="row inching">
      <Field label={`Step − (${unit})`} error={errors.backward} name="inch-step-backward">
        <NumberInput name="inch-step-backward" value={back} onValue={setBack} title="#1015 AxisJogIncrementBackward" />
      </Field>
      <ActionButton name="inch-backward" disabled={!ready} onClick={() => inch(false)} title={`one step backward at #1001 ${velocity ?? '…'} ${unit}/s${why}`}>
        ◀ step
      </ActionButton>
      <ActionButton name="inch-forward" disabled={!ready} onClick={() => inch(true)} title={`one step forward at #1001 ${velocity ?? '…'} ${unit}/s${why}`}>
        step ▶
      </ActionButton>
      <Field label={`Step + (${unit})`} error={errors.forward} name="inch-step-forward">
        <NumberInput name="inch-step-forward" value={fwd} onValue={setFwd} title="#1014 AxisJogIncrementForward" />
      </Field>
    </div>
  );
}
