// Development helper: screenshots of the login page, the header with the control of the machine,
// and the users page, against motiond with authentication on (docs/ui/).
// MOTIOND_BIN=… node tests/e2e/shoot-auth.mjs [out-dir]
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { ROOT, launch, loginCookie, rest, startStack, until } from './lib.mjs';

const out = process.argv[2] ?? join(ROOT, 'docs', 'ui');
mkdirSync(out, { recursive: true });
const stack = await startStack({ noDemo: false, env: { MOTIOND_ADMIN_USER: 'anna', MOTIOND_ADMIN_PASSWORD: 'secret-pass-1' } });
try {
  const cookie = await loginCookie(stack.api, 'anna', 'secret-pass-1');
  const as = { cookie, 'x-client-id': 'shoot' };
  for (const [name, role] of [['otto', 'operator'], ['erik', 'engineer'], ['vera', 'viewer']]) {
    await rest(stack.api, 'POST', '/users', { name, role, password: `${name}-pass-123` }, as);
  }
  await rest(stack.api, 'POST', '/tokens', { name: 'line-3-mes', role: 'operator' }, as);
  const old = await rest(stack.api, 'POST', '/tokens', { name: 'old-plc', role: 'viewer', expires_in_days: 30 }, as);
  await rest(stack.api, 'DELETE', `/tokens/${old.body.id}`, undefined, as);
  await rest(stack.api, 'POST', '/axes/x/power', {}, as);

  for (const [w, h, suffix] of [[1280, 800, ''], [390, 844, '-phone']]) {
    const { context, close } = await launch({ width: w, height: h });
    try {
      const page = await context.newPage();
      page.on('pageerror', (e) => console.log('pageerror:', e.message));
      await page.goto(`${stack.url}/#/`);
      await page.waitForSelector('[data-page="login"]');
      await page.fill('input[name="name"]', 'anna');
      await page.fill('input[name="password"]', 'wrong-password');
      await page.click('button[name="login"]');
      await page.waitForSelector('[data-testid="login-error"]');
      await page.fill('input[name="password"]', 'secret-pass-1');
      await page.screenshot({ path: join(out, `auth-login${suffix}.png`) });

      await page.click('button[name="login"]');
      await page.waitForSelector('[data-conn="open"]');
      await page.waitForSelector('.axis-item[data-axis="x"]', { state: 'attached' });
      await page.click('button[name="take-control"]');
      await page.waitForSelector('[data-control="you"]');
      await until(async () => (await page.locator('[data-testid="overview"] tbody tr').count()) === 3, { what: 'the axes' });
      await page.screenshot({ path: join(out, `auth-header${suffix}.png`) });

      await page.click('button[name="release-control"]');
      await page.waitForSelector('[data-control="free"]');
      if (suffix) await page.goto(`${stack.url}/#/users`);
      else await page.click('.nav-link[href="#/users"]');
      await page.waitForSelector('[data-testid="users"] tr[data-user="otto"]');
      await page.fill('input[name="token-name"]', `cell-${w}`);
      await page.click('button[name="create-token"]');
      await page.waitForSelector('[data-testid="new-token"]');
      await page.screenshot({ path: join(out, `users${suffix}.png`), fullPage: true });
      await page.click('button[name="logout"]');
      await page.waitForSelector('[data-page="login"]');
    } finally {
      await close();
    }
  }
  console.log(`screenshots in ${out}`);
} finally {
  await stack.stop();
}
