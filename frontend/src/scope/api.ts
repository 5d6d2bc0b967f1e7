// The scope recording endpoints (POST/GET/DELETE /api/v1/scope/recordings) and saved setups.
import { api } from '../api/client';
import type { components } from '../api/schema';
import type { RecordingRequest } from './data';

type Recording = components['schemas']['ScopeRecording'];

/** Whether the server has the recording endpoints (looked up in its OpenAPI document). */
export async function scopeAvailable(): Promise<boolean> {
  try {
    const doc = await api.GET('/openapi.json');
    return !!doc.paths && Object.keys(doc.paths).some((p) => p.startsWith('/api/v1/scope/recordings'));
  } catch {
    return false;
  }
}

/** The recordings the server keeps (newest first, without data); [] when it has no list. */
export async function listRecordings(): Promise<Recording[]> {
  try {
    const l = await api.GET('/api/v1/scope/recordings');
    return Array.isArray(l) ? l : [];
  } catch {
    return [];
  }
}

const recording = '/api/v1/scope/recordings/{id}';
export const createRecording = (r: RecordingRequest) => api.POST('/api/v1/scope/recordings', { body: r });
export const getRecording = (id: Recording['id']) => api.GET(recording, { params: { path: { id } } });
export const cancelRecording = (id: Recording['id']) => api.DELETE(recording, { params: { path: { id } } });
export const csvUrl = (id: Recording['id']) => `/api/v1/scope/recordings/${encodeURIComponent(String(id))}?format=csv`;

/** The names of the axis groups (their path signals can be recorded); [] when there are none. */
export async function listGroupNames(): Promise<string[]> {
  try {
    const l = await api.GET('/api/v1/groups');
    return Array.isArray(l) ? l.map((g) => g.name) : [];
  } catch {
    return [];
  }
}

// Saved scope setups (GET /scope/setups, GET/PUT/DELETE /scope/setups/{name}).
type Setup = components['schemas']['ScopeSetup'];
const setup = '/api/v1/scope/setups/{name}';
export const listSetups = () => api.GET('/api/v1/scope/setups');
export const getSetup = (name: string) => api.GET(setup, { params: { path: { name } } });
export const putSetup = (name: string, s: Setup) => api.PUT(setup, { params: { path: { name } }, body: s });
export const deleteSetup = (name: string) => api.DELETE(setup, { params: { path: { name } } });
