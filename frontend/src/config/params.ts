// An axis's parameters (online, persistent and configured values) for the Configuration page.
import { useEffect, useState } from 'preact/hooks';
import { api } from '../api/client';
import type { ParameterResource } from '../api/types';

/**
 * The parameters of the axis by number: null while loading, for no axis (a new one), or when
 * they could not be read. Read again when `version` changes (after a save).
 */
export function useAxisParameters(axis: string | null, id: number, version: number): Map<number, ParameterResource> | null {
  const key = axis === null ? null : `${id}/${axis}/${version}`;
  const [loaded, setLoaded] = useState<{ key: string; map: Map<number, ParameterResource> } | null>(null);
  useEffect(() => {
    if (axis === null || key === null) return;
    let gone = false;
    api.GET('/api/v1/axes/{axis}/parameters', { params: { path: { axis } } }).then(
      (list) => !gone && setLoaded({ key, map: new Map(list.map((p) => [p.number, p])) }),
      () => {},
    );
    return () => {
      gone = true;
    };
  }, [key]);
  // The previous version's values stay until the new ones are there (no flicker after a save).
  return loaded && axis !== null && loaded.key.startsWith(`${id}/${axis}/`) ? loaded.map : null;
}
