// Mounting components in the happy-dom document for the DOM-level tests.
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { vi } from 'vitest';

/** A fresh element in the document to render into. */
export function mountPoint(): HTMLElement {
  const root = document.createElement('div');
  document.body.appendChild(root);
  return root;
}

/** Unmounts what was rendered into `root` (its effects cleaned up) and removes it. */
export function unmount(root: HTMLElement): void {
  act(() => render(null, root));
  root.remove();
}

export type FetchCall = { method: string; url: string; body: unknown };

/** The URL a fetch double is asked for, as the path and query (the REST client passes a Request). */
export function urlOf(input: RequestInfo | URL): string {
  const u = new URL(typeof input === 'string' ? input : input instanceof URL ? input.href : input.url, location.href);
  return u.origin === location.origin ? u.pathname + u.search : u.href;
}

/** What a fetch double is given: method, URL (path and query), headers and body text (none: undefined). */
export async function asSent(input: RequestInfo | URL, init?: RequestInit): Promise<{ method: string; url: string; headers: Headers; body: string | undefined }> {
  if (input instanceof Request) {
    const body = input.body === null ? undefined : await input.clone().text();
    return { method: input.method, url: urlOf(input), headers: input.headers, body };
  }
  return { method: init?.method ?? 'GET', url: urlOf(input), headers: new Headers(init?.headers), body: init?.body == null ? undefined : String(init.body) };
}

/**
 * Replaces `fetch` by a double: `answer` gives each request's status and JSON body (null: none).
 * Returns the requests made, in order.
 */
export function stubFetch(answer: (c: FetchCall) => [number, unknown]): FetchCall[] {
  const calls: FetchCall[] = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const r = await asSent(input, init);
      const c = { method: r.method, url: r.url, body: r.body ? JSON.parse(r.body) : undefined };
      calls.push(c);
      const [status, json] = answer(c);
      const type = status < 300 ? 'application/json' : 'application/problem+json';
      return new Response(json === null ? null : JSON.stringify(json), { status, headers: { 'content-type': type } });
    }),
  );
  return calls;
}

/** Lets pending answers and the renders they cause happen. */
export async function settle(n = 5): Promise<void> {
  for (let i = 0; i < n; i++) await act(async () => await new Promise((r) => setTimeout(r, 0)));
}

/** Types `value` into an input (an `input` event) or chooses it in a select (`change`), rendered at once. */
export function enter(el: Element | null, value: string): void {
  const e = el as HTMLInputElement | HTMLSelectElement;
  act(() => {
    e.value = value;
    e.dispatchEvent(new Event(e.tagName === 'SELECT' ? 'change' : 'input', { bubbles: true }));
  });
}

/** A problem+json document as motiond sends it. */
export const problem = (status: number, code: string, title: string, detail: string, errors?: { field: string; message: string }[]) => ({
  type: `urn:motiond:problem:${code}`,
  title,
  status,
  detail,
  code,
  ...(errors ? { errors } : {}),
});
