import type { ProxyOptions } from 'vite';
import { defineConfig } from 'vitest/config';
import { asMotiondsOwn } from './dev-proxy.ts';

// Development: `npm run dev` serves the UI with a proxy to a running motiond
// (MOTIOND_URL, default http://127.0.0.1:8080). `npm run preview` serves dist/ the same way.
const target = process.env.MOTIOND_URL ?? 'http://127.0.0.1:8080';

// The UI's own requests are presented as motiond's own origin (dev-proxy.ts).
const rewrite = asMotiondsOwn(new URL(target).origin);
const configure: ProxyOptions['configure'] = (proxy) => {
  proxy.on('proxyReq', rewrite);
  proxy.on('proxyReqWs', rewrite);
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
