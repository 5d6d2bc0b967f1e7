// `GET /metrics?buckets=fine`: Prometheus text (not under /api/v1), read with the tab's
// client id; a refusal is an ApiError as for the JSON API. The drive bus (`GET /bus`, its reset) and SDO
// access to its SubDevices.
import { ApiError, get, headers, isProblem, post, put } from '../api/rest';
import type { BusResource, SdoValue, SdoWrite } from '../api/types';
import { cycleHistograms, type CycleHistograms } from './prometheus';
import { sdoPath } from './bus';

export const getBus = () => get<BusResource>('/bus');

/** Brings the EtherCAT segment back to OP (the TX/RX loop started again); the answer is the bus as it is then. */
export const resetBus = () => post<BusResource>('/bus/reset', {});

/** SDO upload of `index:sub` from the SubDevice at `position`. */
export const sdoRead = (position: number, index: string, sub: number) => get<SdoValue>(sdoPath(position, index, sub));

/** SDO download; the answer is the value read back. */
export const sdoWrite = (position: number, index: string, sub: number, body: SdoWrite) => put<SdoValue>(sdoPath(position, index, sub), body);

export async function getMetricsText(): Promise<string> {
  let res: Response;
  try {
    res = await fetch('/metrics?buckets=fine', { headers: { ...headers('GET'), Accept: 'text/plain' } });
  } catch (e) {
    throw new ApiError(0, null, `server not reachable (${(e as Error).message})`);
  }
  const text = await res.text();
  if (!res.ok) {
    let json: unknown = null;
    try {
      json = JSON.parse(text);
    } catch {
      /* not a problem document */
    }
    throw new ApiError(res.status, isProblem(json) ? json : null, isProblem(json) ? undefined : `HTTP ${res.status}`);
  }
  return text;
}

export async function getCycleHistograms(): Promise<CycleHistograms> {
  return cycleHistograms(await getMetricsText());
}
