// Browser tests of authentication and the control lease: motiond started with a first admin
// (MOTIOND_ADMIN_USER/MOTIOND_ADMIN_PASSWORD on a fresh database: authentication on) and the
// demo axes. Every wait is for a condition; nothing asserts timing.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, loginCookie, rest, shot, startStack, until } from './lib.mjs';

const ADMIN = 'anna';
const PASSWORD = 'secret-pass-1';
const stack = await startStack({ noDemo: false, env: { MOTIOND_ADMIN_USER: ADMIN, MOTIOND_ADMIN_PASSWORD: PASSWORD } });

let browser;
/** The page the tests share: logged in by the second test, logged out by the last. */
let page;
/** anna's session for requests from here (another client than the browser's tab). */
let cookie;
const OTHER = 'e2e-other-client';
const as = (clientId = OTHER) => ({ cookie, 'x-client-id': clientId });

before(async () => {
  browser = await launch({ width: 1280, height: 800 });
  cookie = await loginCookie(stack.api, ADMIN, PASSWORD);
});

after(async () => {
  await browser?.close();
  await stack.stop();
});

async function newPage(path = '/') {
  const p = await browser.context.newPage();
  p.on('pageerror', (e) => console.error('pageerror:', e.message));
  await p.goto(`${stack.url}/#${path}`);
  return p;
}

const text = (p, sel) => p.locator(sel).first().textContent({ timeout: 10000 });
const controlText = (p) => text(p, '[data-testid="control-text"]');
const tabClientId = (p) => p.evaluate(() => sessionStorage.getItem('motiond.clientId'));
const control = async () => (await rest(stack.api, 'GET', '/control', undefined, as())).body;

async function logIn(p, name, password) {
  await p.fill('input[name="name"]', name);
  await p.fill('input[name="password"]', password);
  await p.click('button[name="login"]');
}

describe('authentication and control', () => {
  test('the login page comes first; a wrong password shows the server’s error under the form', async () => {
    page = await newPage('/');
    await page.waitForSelector('[data-page="login"]');
    assert.equal(await page.locator('.topbar').count(), 0, 'no app before the login');
    assert.equal(await page.locator('[data-testid="login-reason"]').count(), 0, 'no "session ended" at first');
    await logIn(page, ADMIN, 'not-the-password');
    const msg = await text(page, '[data-testid="login-error"]');
    const server = await rest(stack.api, 'POST', '/auth/login', { name: ADMIN, password: 'not-the-password' });
    assert.equal(server.status, 401);
    assert.equal(msg, `${server.body.title}: ${server.body.detail}`);
    assert.equal(await page.inputValue('input[name="password"]'), '', 'the wrong password is cleared');
    await shot(page, 'auth-login-error');
  });

  test('too many wrong passwords: the 429 message is shown', async () => {
    const p = await newPage('/');
    await p.waitForSelector('[data-page="login"]');
    // Five wrong passwords for a name lock it (its own name: anna is not locked).
    for (let i = 0; i < 5; i++) await rest(stack.api, 'POST', '/auth/login', { name: 'mallory', password: 'wrong-password' });
    await logIn(p, 'mallory', 'wrong-password');
    const msg = await text(p, '[data-testid="login-error"]');
    assert.match(msg, /^Too many login attempts: .*try again in \d+ s/);
    await p.close();
  });

  test('the right password shows the app with the axes; the header shows anna (admin)', async () => {
    await logIn(page, ADMIN, PASSWORD);
    await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
    for (const axis of ['x', 'y', 'spindle']) await page.waitForSelector(`.axis-item[data-axis="${axis}"]`);
    await page.waitForSelector('[data-testid="overview"] tbody tr');
    const user = page.locator('.user');
    assert.equal(await user.getAttribute('data-user'), ADMIN);
    assert.equal(await user.getAttribute('data-role'), 'admin');
    assert.match(await user.textContent(), /anna\s*admin\s*Log out/);
    assert.equal(await page.locator('.nav-link[href="#/users"]').count(), 1, 'admins see the users page');
    await until(async () => (await controlText(page)) === 'Control: free', { what: 'Control: free' });
    // The tab has its own client id, on REST and on the websocket.
    assert.match(await tabClientId(page), /^ui-[a-z0-9]{8}$/);
  });

  test('Take control: "Control: you", renewed; another client’s motion is refused (409), its stop passes', async () => {
    // The axis is enabled while nobody holds control (anyone may then).
    const power = await rest(stack.api, 'POST', '/axes/x/power', {}, as());
    assert.equal(power.status, 202, JSON.stringify(power.body));
    await until(async () => (await rest(stack.api, 'GET', '/axes/x/status', undefined, as())).body.status.power_status, { what: 'x enabled' });

    await page.click('button[name="take-control"]');
    await until(async () => (await controlText(page)) === 'Control: you', { what: 'Control: you' });
    await page.waitForSelector('[data-control="you"] button[name="release-control"]');
    const id = await tabClientId(page);
    const seen = await control();
    assert.equal(seen.yours, false);
    assert.equal(seen.holder.client_id, id);
    assert.equal(seen.holder.principal, `user:${ADMIN}`);
    // The tab renews its lease: the time left grows again, twice, with the same holder.
    let last = seen.holder.expires_in_ms;
    let renewals = 0;
    await until(
      async () => {
        const c = await control();
        assert.equal(c.holder?.client_id, id, 'the tab keeps control');
        assert.equal(c.holder.since, seen.holder.since);
        if (c.holder.expires_in_ms > last) renewals++;
        last = c.holder.expires_in_ms;
        return renewals >= 2;
      },
      { what: 'two renewals', interval: 200 },
    );
    await shot(page, 'auth-control-you');

    // anna from another client (her session, another X-Client-Id): a move is refused …
    const move = await rest(stack.api, 'POST', '/axes/x/move-relative', { distance: 5, velocity: 10 }, as());
    assert.equal(move.status, 409, JSON.stringify(move.body));
    assert.equal(move.body.code, 'control_held');
    assert.match(move.body.detail, new RegExp(`client ${id}`));
    // … and so is a machine's, with an operator token made through the API.
    const made = await rest(stack.api, 'POST', '/tokens', { name: 'e2e-mes', role: 'operator' }, as());
    assert.equal(made.status, 201, JSON.stringify(made.body));
    const bearer = { authorization: `Bearer ${made.body.token}`, 'x-client-id': 'e2e-mes' };
    const byToken = await rest(stack.api, 'POST', '/axes/x/move-absolute', { position: 50, velocity: 10 }, bearer);
    assert.equal(byToken.status, 409, JSON.stringify(byToken.body));
    assert.equal(byToken.body.code, 'control_held');
    // A stop always passes.
    const stop = await rest(stack.api, 'POST', '/axes/x/stop', {}, bearer);
    assert.equal(stop.status, 202, JSON.stringify(stop.body));
    const released = await rest(stack.api, 'DELETE', `/commands/${stop.body.id}`, undefined, bearer);
    assert.ok(released.status < 300, JSON.stringify(released.body));
    // Another tab of anna's is another client: it sees who holds control, and may take over.
    const other = await newPage('/');
    await until(async () => (await other.locator('[data-testid="control-text"]').count()) && (await controlText(other)) === 'Control: user:anna (other tab)', {
      what: 'the other tab to see the holder',
    });
    await other.waitForSelector('button[name="take-over"]');
    await other.close();

    await page.click('button[name="release-control"]');
    await until(async () => (await controlText(page)) === 'Control: free', { what: 'Control: free after Release' });
    assert.equal((await control()).holder, null, 'released on the server');
  });

  test('a page that holds control gives it back when it closes', async () => {
    const p = await newPage('/');
    await p.waitForSelector('button[name="take-control"]');
    const id = await tabClientId(p);
    await p.click('button[name="take-control"]');
    await p.waitForSelector('[data-control="you"]');
    await until(async () => (await control()).holder?.client_id === id, { what: 'the new tab to hold control' });
    await p.close({ runBeforeUnload: true });
    await until(async () => (await control()).holder === null, { what: 'control to be free' });
    // Released by the closing page (keepalive), not run out: the release is in the audit log.
    const audit = await rest(stack.api, 'GET', '/audit?limit=50', undefined, as());
    assert.equal(audit.status, 200, JSON.stringify(audit.body));
    assert.ok(
      audit.body.some((e) => e.action === 'control.release' && e.client_id === id),
      `a control.release by ${id} in ${JSON.stringify(audit.body.map((e) => [e.action, e.client_id]))}`,
    );
  });

  test('the users page: add a user, change its role; a token is shown once and can be revoked', async () => {
    await page.click('.nav-link[href="#/users"]');
    await page.waitForSelector(`[data-testid="users"] tr[data-user="${ADMIN}"]`);
    // A server error at the field: too short a password.
    await page.fill('input[name="user-name"]', 'otto');
    await page.selectOption('select[name="user-role"]', 'operator');
    await page.fill('input[name="user-password"]', 'short');
    await page.click('button[name="add-user"]');
    assert.equal(await text(page, '[data-testid="add-user"] [data-field="password"] .field-error'), 'must be 8 to 1024 characters');
    await page.fill('input[name="user-password"]', 'otto-pass-123');
    await page.click('button[name="add-user"]');
    await page.waitForSelector('[data-testid="users"] tr[data-user="otto"]');
    assert.equal(await page.inputValue('tr[data-user="otto"] select[name="role"]'), 'operator');
    await page.selectOption('tr[data-user="otto"] select[name="role"]', 'engineer');
    await until(async () => (await rest(stack.api, 'GET', '/users/otto', undefined, as())).body.role === 'engineer', { what: 'otto an engineer' });
    // The last admin cannot be deleted: the server's word at the row.
    await page.click(`tr[data-user="${ADMIN}"] button[name="delete"]`);
    await page.click(`tr[data-user="${ADMIN}"] button[name="delete-confirm"]`);
    assert.match(await text(page, `tr[data-user-msg="${ADMIN}"] .field-error`), /last admin/);

    await page.fill('input[name="token-name"]', 'line-3');
    await page.selectOption('select[name="token-role"]', 'viewer');
    await page.fill('input[name="token-days"]', '30');
    await page.click('button[name="create-token"]');
    await page.waitForSelector('[data-testid="new-token"]');
    const token = await page.inputValue('input[name="new-token"]');
    assert.match(await text(page, '[data-testid="new-token"]'), /will not be shown again/);
    // The token works.
    const who = await rest(stack.api, 'GET', '/auth/session', undefined, { authorization: `Bearer ${token}` });
    assert.equal(who.body.principal, 'token:line-3');
    assert.equal(who.body.role, 'viewer');
    await page.waitForSelector('[data-testid="tokens"] tr[data-token="line-3"][data-status="active"]');
    await shot(page, 'auth-users');
    await page.click('button[name="token-done"]');
    assert.equal(await page.locator('[data-testid="new-token"]').count(), 0, 'shown once');
    await page.click('tr[data-token="line-3"] button[name="revoke"]');
    await page.click('tr[data-token="line-3"] button[name="revoke-confirm"]');
    await page.waitForSelector('[data-testid="tokens"] tr[data-token="line-3"][data-status="revoked"]');
    assert.equal((await rest(stack.api, 'GET', '/auth/session', undefined, { authorization: `Bearer ${token}` })).status, 401);
  });

  test('a session ended elsewhere brings the login page back: "Your session has ended"', async () => {
    await page.goto(`${stack.url}/#/`);
    await page.waitForSelector('[data-conn="open"]');
    const session = (await browser.context.cookies(stack.url)).find((c) => c.name === 'motiond_session');
    assert.ok(session, 'the browser has a session cookie');
    const out = await rest(stack.api, 'POST', '/auth/logout', undefined, { cookie: `motiond_session=${session.value}` });
    assert.equal(out.status, 204);
    await page.waitForSelector('[data-page="login"][data-reason="ended"]', { timeout: 20000 });
    assert.match(await text(page, '[data-testid="login-reason"]'), /Your session has ended/);
    // Logging in again brings the app back.
    await logIn(page, ADMIN, PASSWORD);
    await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
    await page.waitForSelector('.axis-item[data-axis="x"]');
  });

  test('Log out returns to the login page; the session is over on the server', async () => {
    const session = (await browser.context.cookies(stack.url)).find((c) => c.name === 'motiond_session');
    await page.click('button[name="logout"]');
    await page.waitForSelector('[data-page="login"][data-reason="logged-out"]');
    assert.equal(await page.locator('.topbar').count(), 0);
    const after = await rest(stack.api, 'GET', '/auth/session', undefined, { cookie: `motiond_session=${session.value}` });
    assert.equal(after.status, 401, 'the old cookie is no longer valid');
    await page.close();
  });
});

describe('without authentication and without control leases', () => {
  let open;
  let ctx;
  before(async () => {
    // No user: authentication off; `--control-lease false`: nobody can hold control.
    open = await startStack({ noDemo: false, args: ['--control-lease', 'false'] });
    ctx = await launch({ width: 1280, height: 800 });
  });
  after(async () => {
    await ctx?.close();
    await open?.stop();
  });

  test('no login, no user and no control in the header; adding the first admin turns authentication on', async () => {
    const p = await ctx.context.newPage();
    p.on('pageerror', (e) => console.error('pageerror:', e.message));
    await p.goto(`${open.url}/#/users`);
    await p.waitForSelector('[data-conn="open"]');
    await p.waitForSelector('[data-testid="auth-off"]');
    // the control is read, and there is none to show
    await until(async () => (await rest(open.api, 'GET', '/control')).body.lease_enabled === false, { what: 'the control state' });
    await p.waitForSelector('[data-testid="users"]');
    assert.equal(await p.locator('[data-control]').count(), 0);
    assert.equal(await p.locator('.user').count(), 0);
    assert.equal(await p.locator('.nav-link[href="#/users"]').count(), 1, 'anyone may add the first user');
    // the first user must be an admin: the form offers that
    assert.equal(await p.inputValue('select[name="user-role"]'), 'admin');
    await p.fill('input[name="user-name"]', 'root');
    await p.fill('input[name="user-password"]', 'root-pass-123');
    await p.click('button[name="add-user"]');
    await p.waitForSelector('[data-page="login"][data-reason="auth-enabled"]');
    assert.match(await text(p, '[data-testid="login-reason"]'), /Authentication is now on/);
    await logIn(p, 'root', 'root-pass-123');
    await p.waitForSelector('.user[data-user="root"][data-role="admin"]');
    await p.waitForSelector('[data-conn="open"]');
    assert.equal(await p.locator('[data-control]').count(), 0, 'still no control leases');
    await p.close();
  });
});
