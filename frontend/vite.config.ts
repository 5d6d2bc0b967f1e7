import type { IncomingMessage } from 'node:http';
import type { ProxyOptions } from 'vite';
import { defineConfig } from 'vitest/config';

// Development: `npm run dev` serves the UI with a proxy to a running motiond
// (MOTIOND_URL, default http://127.0.0.1:8080). `npm run preview` serves dist/ the same way.
const target = process.env.MOTIOND_URL ?? 'http://127.0.0.1:8080';

// motiond refuses a request that changes something, and the websocket, from any origin but its
// own (403 cross_origin_forbidden, docs/security.md). Through this proxy the UI's requests carry
// the dev server's origin (http://localhost:5173), so the proxy presents them as motiond's own —
// only those: a page of another origin keeps its Origin and is refused as without the proxy.
const targetOrigin = new URL(target).origin;
function asMotiondsOwn(proxyReq: { setHeader(name: string, value: string): unknown }, req: IncomingMessage) {
  const { origin, host } = req.headers;
  if (origin && host && (origin === `http://${host}` || origin === `https://${host}`)) {
    proxyReq.setHeader('origin', targetOrigin);
  }
}
const configure: ProxyOptions['configure'] = (proxy) => {
  proxy.on('proxyReq', asMotiondsOwn);
  proxy.on('proxyReqWs', asMotiondsOwn);
};
const to = (extra: ProxyOptions = {}): ProxyOptions => ({ target, changeOrigin: true, configure, ...extra });
const proxy = {
  '/api/v1/ws': to({ ws: true }),
  '/api': to(),
  '/openapi.json': to(),
  '/docs': to(),
  '/metrics': to(),
};

export default defineConfig({
  // Preact's automatic JSX runtime; no framework plugin needed.
  oxc: { jsx: { runtime: 'automatic', importSource: 'preact' } },
  build: {
    target: 'es2022',
    sourcemap: true,
    chunkSizeWarningLimit: 800,
  },
  server: { proxy },
  preview: { proxy },
  test: {
    environment: 'happy-dom',
    include: ['test/**/*.test.{ts,tsx}'],
  },
});
