import type { IncomingMessage } from 'node:http';

// motiond refuses a request that changes something, and the websocket, from any origin but its
// own (403 cross_origin_forbidden, docs/security.md). Through the dev server's proxy the UI's
// requests carry the dev server's origin (http://localhost:5173), so the proxy presents them as
// motiond's own — only those: a page of another origin keeps its Origin and is refused as
// without the proxy (docs/decisions.md, entry 49).
export function asMotiondsOwn(targetOrigin: string) {
  return (proxyReq: { setHeader(name: string, value: string): unknown }, req: IncomingMessage) => {
    const { origin, host } = req.headers;
    if (origin && host && (origin === `http://${host}` || origin === `https://${host}`)) {
      proxyReq.setHeader('origin', targetOrigin);
    }
  };
}
