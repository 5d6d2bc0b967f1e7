// `GET /metrics?buckets=fine`: Prometheus text (not under /api/v1), read with the tab's
// client id; a refusal is an ApiError as for the JSON API. The drive bus (`GET /bus`, its reset) and SDO
// access to its SubDevices.
import { api, getText } from '../api/client';
import type { SdoWrite } from '../api/types';
import { cycleHistograms, type CycleHistograms } from './prometheus';

export const getBus = () => api.GET('/api/v1/bus');

/** Brings the EtherCAT segment back to OP (the TX/RX loop started again); the answer is the bus as it is then. */
export const resetBus = () => api.POST('/api/v1/bus/reset');

const sdo = '/api/v1/bus/subdevices/{position}/sdo/{index}/{sub}';

/** SDO upload of `index:sub` from the SubDevice at `position`. */
export const sdoRead = (position: number, index: string, sub: number) => api.GET(sdo, { params: { path: { position, index, sub } } });

/** SDO download; the answer is the value read back. */
export const sdoWrite = (position: number, index: string, sub: number, body: SdoWrite) => api.PUT(sdo, { params: { path: { position, index, sub } }, body });

export const getMetricsText = () => getText('/metrics', { params: { query: { buckets: 'fine' } } });

export async function getCycleHistograms(): Promise<CycleHistograms> {
  return cycleHistograms(await getMetricsText());
}
