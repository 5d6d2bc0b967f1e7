// `GET /metrics?buckets=fine`: Prometheus text (not under /api/v1), read with the tab's
// client id; a refusal is an ApiError as for the JSON API.
import { ApiError, headers, isProblem } from '../api/rest';
import { cycleHistograms, type CycleHistograms } from './prometheus';

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
