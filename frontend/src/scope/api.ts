// The scope recording endpoints (POST/GET/DELETE /api/v1/scope/recordings).
import { del, get, post, put, enc } from '../api/rest';
import type { components } from '../api/schema';
import type { RecordingRequest } from './data';

type Recording = components['schemas']['ScopeRecording'];

export const RECORDINGS = '/scope/recordings';

/** Whether the server has the recording endpoints (looked up in its OpenAPI document). */
export async function scopeAvailable(): Promise<boolean> {
  try {
    const doc = await get<{ paths?: Record<string, unknown> }>('/openapi.json');
    return !!doc.paths && Object.keys(doc.paths).some((p) => p.startsWith('/api/v1/scope/recordings'));
  } catch {
    return false;
  }
}

/** The recordings the server keeps (newest first, without data); [] when it has no list. */
export async function listRecordings(): Promise<Recording[]> {
  try {
    const l = await get<Recording[]>(RECORDINGS);
    return Array.isArray(l) ? l : [];
  } catch {
    return [];
  }
}

export const createRecording = (r: RecordingRequest) => post<Recording>(RECORDINGS, r);
export const getRecording = (id: Recording['id']) => get<Recording>(`${RECORDINGS}/${enc(String(id))}`);
export const cancelRecording = (id: Recording['id']) => del<unknown>(`${RECORDINGS}/${enc(String(id))}`);
export const csvUrl = (id: Recording['id']) => `/api/v1${RECORDINGS}/${enc(String(id))}?format=csv`;

// Saved scope setups (GET /scope/setups, GET/PUT/DELETE /scope/setups/{name}).
type Setup = components['schemas']['ScopeSetup'];
type SetupResource = components['schemas']['ScopeSetupResource'];
export const SETUPS = '/scope/setups';
export const listSetups = () => get<SetupResource[]>(SETUPS);
export const getSetup = (name: string) => get<SetupResource>(`${SETUPS}/${enc(name)}`);
export const putSetup = (name: string, s: Setup) => put<SetupResource>(`${SETUPS}/${enc(name)}`, s);
export const deleteSetup = (name: string) => del<unknown>(`${SETUPS}/${enc(name)}`);
