import { defineConfig } from 'vitest/config';

// Development: `npm run dev` serves the UI with a proxy to a running motiond
// (MOTIOND_URL, default http://127.0.0.1:8080). `npm run preview` serves dist/ the same way.
const target = process.env.MOTIOND_URL ?? 'http://127.0.0.1:8080';
const proxy = {
  '/api/v1/ws': { target, ws: true, changeOrigin: true },
  '/api': { target, changeOrigin: true },
  '/openapi.json': { target, changeOrigin: true },
  '/docs': { target, changeOrigin: true },
  '/metrics': { target, changeOrigin: true },
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
