// An axis's parameters for the axis tabs: jog velocities, inching steps, and what a blank field
// of a block stands for (the parameter's value in force, shown as the field's placeholder).
import { useEffect, useState } from 'preact/hooks';
import { api } from '../../api/client';
import type { ParameterResource } from '../../api/types';
import { inputNum } from '../../format';

/**
 * The axis's parameters by number; null until those of this axis (name and id: an import can
 * put another axis under the same name) have loaded, never another axis's meanwhile.
 */
export function useParameters(axis: string, id: number, version = 0): Map<number, ParameterResource> | null {
  const key = `${id}/${axis}`;
  const [loaded, setLoaded] = useState<{ key: string; map: Map<number, ParameterResource> } | null>(null);
  useEffect(() => {
    let gone = false;
    api.GET('/api/v1/axes/{axis}/parameters', { params: { path: { axis } } }).then(
      (list) => !gone && setLoaded({ key, map: new Map(list.map((p) => [p.number, p])) }),
      () => {},
    );
    return () => {
      gone = true;
    };
  }, [key, version]);
  return loaded?.key === key ? loaded.map : null;
}

/** How often the tabs read the parameters again: a placeholder shows what the axis uses now. */
export const PARAMS_REFRESH_MS = 5000;

/** useParameters, read again every PARAMS_REFRESH_MS while shown (another client may change them). */
export function useLiveParameters(axis: string, id: number): Map<number, ParameterResource> | null {
  const [version, setVersion] = useState(0);
  useEffect(() => {
    const t = setInterval(() => setVersion((v) => v + 1), PARAMS_REFRESH_MS);
    return () => clearInterval(t);
  }, []);
  return useParameters(axis, id, version);
}

/** A parameter's value in force as text: numbers as typed into a field, booleans as on/off. */
export function paramText(m: Map<number, ParameterResource> | null, n: number): string {
  const v = m?.get(n)?.value;
  if (typeof v === 'number') return inputNum(v);
  if (typeof v === 'boolean') return v ? 'on' : 'off';
  return '';
}

/**
 * What a blank number field stands for: the parameter's value in force as the placeholder
 * (what the axis uses now, not its number), its number and name in the tooltip.
 */
export function paramDefault(m: Map<number, ParameterResource> | null, n: number, shown?: string): { placeholder: string; title: string } {
  const p = m?.get(n);
  const value = shown ?? paramText(m, n);
  const unit = p?.unit_text ? ` ${p.unit_text}` : '';
  return {
    placeholder: value,
    title: `blank = the axis's #${n}${p ? ` ${p.name}` : ''}${value ? `, now ${value}${unit}` : ''}`,
  };
}

/** A numeric parameter's value, null when unknown (not loaded, no such parameter). */
export const numParam = (m: Map<number, ParameterResource> | null, n: number): number | null => {
  const v = m?.get(n)?.value;
  return typeof v === 'number' ? v : null;
};

/** #1001 AxisVeloManSlow, #1002 AxisVeloManFast, #1014/#1015 AxisJogIncrementForward/Backward. */
export const P_ACC = 1004;
export const P_DEC = 1005;
export const P_JERK = 1006;
export const P_HOME_SEARCH_VELOCITY = 1012;
export const P_HOME_SYNC_VELOCITY = 1013;
export const P_BACKLASH = 1036;
export const P_HOME_SEARCH_INVERSE = 1073;
export const P_HOME_SYNC_INVERSE = 1074;
export const P_HOME_POSITION = 1075;
export const P_REFERENCE_MODE = 1076;
export const P_JOG_SLOW = 1001;
export const P_JOG_FAST = 1002;
export const P_INC_FORWARD = 1014;
export const P_INC_BACKWARD = 1015;
