// @vitest-environment node
// The Vite config loads without the warning Vite prints for what its coming native config
// loader cannot do (an import without its file extension, __dirname …): `npm run build` and
// `npm run dev` stay quiet.
import { describe, expect, it } from 'vitest';
import { fileURLToPath } from 'node:url';
import { createLogger, loadConfigFromFile } from 'vite';

describe('vite.config.ts', () => {
  it('loads without a warning', async () => {
    const warnings: string[] = [];
    const logger = createLogger('warn', { allowClearScreen: false });
    logger.warn = (msg) => void warnings.push(msg);
    logger.warnOnce = (msg) => void warnings.push(msg);
    const root = fileURLToPath(new URL('..', import.meta.url));
    const loaded = await loadConfigFromFile({ command: 'build', mode: 'production' }, `${root}/vite.config.ts`, root, 'warn', logger);
    expect(loaded?.config.server?.proxy).toBeTruthy();
    expect(warnings).toEqual([]);
  });
});
