// An axis's parameters for the Online tab (jog velocities, inching steps).
import { useEffect, useState } from 'preact/hooks';
import { get, enc } from '../api/rest';
import type { ParameterResource } from '../api/types';

/**
 * The axis's parameters by number; null until those of this axis (name and id: an import can
 * put another axis under the same name) have loaded, never another axis's meanwhile.
 */
export function useParameters(axis: string, id: number, version = 0): Map<number, ParameterResource> | null {
  const key = `${id}/${axis}`;
  const [loaded, setLoaded] = useState<{ key: string; map: Map<number, ParameterResource> } | null>(null);
  useEffect(() => {
    let gone = false;
    get<ParameterResource[]>(`/axes/${enc(axis)}/parameters`).then(
      (list) => !gone && setLoaded({ key, map: new Map(list.map((p) => [p.number, p])) }),
      () => {},
    );
    return () => {
      gone = true;
    };
  }, [key, version]);
  return loaded?.key === key ? loaded.map : null;
}

/** A numeric parameter's value, null when unknown (not loaded, no such parameter). */
export const numParam = (m: Map<number, ParameterResource> | null, n: number): number | null => {
  const v = m?.get(n)?.value;
  return typeof v === 'number' ? v : null;
};

/** #1001 AxisVeloManSlow, #1002 AxisVeloManFast, #1014/#1015 AxisJogIncrementForward/Backward. */
export const P_JOG_SLOW = 1001;
export const P_JOG_FAST = 1002;
export const P_INC_FORWARD = 1014;
export const P_INC_BACKWARD = 1015;
