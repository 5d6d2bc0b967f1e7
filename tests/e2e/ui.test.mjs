// End-to-end tests of the commissioning UI in headless Debian Chromium against the real
// motiond binary. Live values are polled with generous deadlines; nothing asserts timing.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { clippedText, launch, overflowing, picture, readout, rest, shot, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: true });

let browser;
const pages = [];
/** Every request of every page (http, https, ws), to check that none leaves this machine. */
const requests = [];
const LOOPBACK = new Set(['127.0.0.1', 'localhost', '[::1]']);
async function open(path, size) {
  const ctx = size ? (await launch(size)) : null;
  const context = ctx ? ctx.context : browser.context;
  const page = await context.newPage();
  page.on('pageerror', (e) => console.error('pageerror:', e.message));
  page.on('request', (r) => requests.push(r.url()));
  page.on('websocket', (w) => requests.push(w.url()));
  pages.push({ page, ctx });
  await page.goto(`${stack.url}/#${path}`);
  await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
  return page;
}

const AXIS = 'e2e';

before(async () => {
  browser = await launch({ width: 1280, height: 800 });
});

after(async () => {
  for (const p of pages) if (p.ctx) await p.ctx.close();
  await browser?.close();
  await stack.stop();
});

/** Makes sure the test axis exists (a test run alone: created as the 'create an axis' test does). */
async function ensureAxis() {
  if ((await rest(stack.api, 'GET', `/axes/${AXIS}`)).status === 200) return;
  const r = await rest(stack.api, 'POST', '/axes', {
    name: AXIS,
    unit: 'mm',
    soft_limits: { min: -1000, max: 1000 },
    dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
  });
  assert.equal(r.status, 201, JSON.stringify(r.body));
}

/** Makes sure the test axis is enabled and at rest (tests may run alone). */
async function enabled() {
  await ensureAxis();
  const s = await status(stack.api, AXIS);
  if (!s.power_status) {
    const r = await rest(stack.api, 'POST', `/axes/${AXIS}/power`, {});
    assert.equal(r.status, 202, JSON.stringify(r.body));
    await until(async () => (await status(stack.api, AXIS)).power_status, { what: 'axis enabled' });
  }
}

async function atRest() {
  return until(
    async () => {
      const s = await status(stack.api, AXIS);
      return s.state === 'standstill' && s.set_velocity === 0 && !s.has_job ? s : null;
    },
    { what: 'axis at rest' },
  );
}

/** The Online tab's absolute move with this target and velocity (as typed: any text), started. */
async function startAbsolute(page, position, velocity) {
  await page.click('[data-move="move-absolute"]');
  await page.fill('input[name="position"]', position);
  await page.fill('input[name="velocity"]', velocity);
  await page.click('button[name="start"]');
}

async function holdJog(page, key) {
  const box = await page.locator(`[data-jog="${key}"]`).boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
}

describe('commissioning UI', () => {
  test('an empty machine: the overview says so and offers to create an axis', async () => {
    const page = await open('/');
    await page.waitForSelector('text=No axes yet');
    await shot(page, 'overview-empty');
    await page.close();
  });

  test('an invalid value shows the server’s error at the field (new axis)', async () => {
    const page = await open('/new-axis');
    await page.fill('input[name="name"]', AXIS);
    await page.fill('input[name="dynamics.jerk"]', '-1');
    await page.click('button[name="save"]');
    const msg = await page.locator('[data-field="dynamics.jerk"] .field-error').textContent({ timeout: 10000 });
    // exactly what the server said for that field
    const server = await rest(stack.api, 'POST', '/axes', {
      name: 'probe',
      unit: 'mm',
      dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: -1, jog_velocity_slow: 10, jog_velocity_fast: 100 },
    });
    assert.equal(server.status, 422);
    const expected = server.body.errors.find((e) => e.field === 'dynamics.jerk').message;
    assert.equal(msg, expected);
    assert.equal((await rest(stack.api, 'GET', `/axes/${AXIS}`)).status, 404, 'nothing was created');
    await shot(page, 'config-new-axis-invalid');
    await page.close();
  });

  test('create an axis', async () => {
    const page = await open('/new-axis');
    await page.fill('input[name="name"]', AXIS);
    await page.check('input[name="soft-limits-on"]');
    await page.fill('input[name="soft_limits.min"]', '-1000');
    await page.fill('input[name="soft_limits.max"]', '1000');
    await page.click('button[name="save"]');
    await page.waitForURL(/#\/axes\/e2e$/, { timeout: 10000 });
    const r = await rest(stack.api, 'GET', `/axes/${AXIS}`);
    assert.equal(r.status, 200);
    assert.deepEqual(r.body.config.soft_limits, { min: -1000, max: 1000 });
    await page.waitForSelector(`.axis-item[data-axis="${AXIS}"]`);
    await page.close();
  });

  test('enable the axis, hold jog + and see the position grow, release and see it stop', async () => {
    const page = await open(`/axes/${AXIS}`);
    await page.click('button[name="power-set"]');
    await page.waitForSelector('[data-led="Enabled"][data-on="1"]', { timeout: 10000 });
    assert.ok((await status(stack.api, AXIS)).power_status);
    // the jog buttons show #1001/#1002
    assert.match(await page.locator('[data-jog="slow-forward"]').textContent(), /10 mm\/s/);
    assert.match(await page.locator('[data-jog="fast-forward"]').textContent(), /100 mm\/s/);
    const start = (await status(stack.api, AXIS)).actual_position;
    await holdJog(page, 'slow-forward');
    await page.waitForSelector('[data-jog-phase="held"]', { timeout: 10000 });
    // held beyond the 0.5 s dead-man: the renewal keeps it going (10 mm/s → > 8 mm takes > 0.8 s)
    await until(async () => (await readout(page, 'actual_position')) > start + 8, { what: 'the UI position to grow' });
    const moving = await status(stack.api, AXIS);
    assert.ok(moving.set_velocity > 0 && moving.state === 'continuous_motion', JSON.stringify(moving));
    // the live trend draws the jog: samples in its 10 s window, the jog velocity among them
    const trend = page.locator('[data-testid="trend"]');
    const drawn = () => trend.evaluate((e) => ({ points: Number(e.dataset.points), vmax: Number(e.dataset.vmax) }));
    await until(async () => {
      const d = await drawn();
      return d.points >= 25 && Math.abs(d.vmax - 10) < 1e-3 ? d : null;
    }, { what: 'the trend to draw the jog' });
    await shot(page, 'online-jogging');
    await page.mouse.up();
    const rest1 = await atRest();
    // the jog is over on the server and the kernel has run on for 300 more cycles: still there
    await until(async () => (await rest(stack.api, 'GET', `/commands?axis=${AXIS}&limit=20`)).body.find((c) => c.command === 'jog')?.final, { what: 'the jog released' });
    const rest2 = await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.nc_cycle_counter >= rest1.nc_cycle_counter + 300 ? s : null;
    }, { what: '300 cycles after the stop' });
    assert.equal(rest2.set_position, rest1.set_position, 'no motion after the release');
    await until(async () => Math.abs((await readout(page, 'set_position')) - rest2.set_position) < 1e-3, { what: 'the UI to show the stop' });
    // the log shows the jog, released
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="jog"]');
    // the trend paused stands still (recording goes on); clear empties it; resumed it draws
    await page.click('button[name="trend-pause"]');
    await page.waitForSelector('[data-testid="trend"][data-paused="1"]');
    const frozen = await drawn();
    // the axis moves while paused: once the page shows where it went, the trend is still as it was
    const before = (await status(stack.api, AXIS)).set_position;
    assert.equal((await rest(stack.api, 'POST', `/axes/${AXIS}/move-relative`, { distance: 1, velocity: 10 })).status, 202);
    await until(async () => Math.abs((await readout(page, 'set_position')) - (before + 1)) < 1e-3, { what: 'the page to receive the move while paused' });
    assert.deepEqual(await drawn(), frozen, 'a paused trend is not redrawn');
    await page.click('button[name="trend-clear"]');
    assert.equal((await drawn()).points, 0);
    await page.click('button[name="trend-pause"]');
    await page.waitForSelector('[data-testid="trend"][data-paused="0"]');
    assert.equal((await rest(stack.api, 'POST', `/axes/${AXIS}/move-relative`, { distance: 2, velocity: 10 })).status, 202);
    await until(async () => (await drawn()).points >= 5, { what: 'the trend to draw again after resume' });
    await atRest();
    await page.close();
  });

  test('leaving the button while holding it stops the jog', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    await holdJog(page, 'slow-backward');
    await until(async () => (await status(stack.api, AXIS)).set_velocity < 0, { what: 'jogging backward' });
    await page.mouse.move(5, 5); // pointerleave, button still down
    await atRest();
    await page.mouse.up();
    await page.close();
  });

  test('closing the page mid-jog: the server stops the axis', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    await holdJog(page, 'fast-forward');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 50, { what: 'jogging' });
    await page.close(); // button still held
    const s = await atRest();
    assert.equal(s.error_id, 0);
    const jogs = (await rest(stack.api, 'GET', `/commands?axis=${AXIS}&limit=20`)).body.filter((c) => c.command === 'jog');
    assert.ok(jogs[0].final, 'the jog is over');
  });

  test('the renderer dying mid-jog: the socket closes and the server stops the axis', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    await holdJog(page, 'slow-forward');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'jogging' });
    const cdp = await page.context().newCDPSession(page);
    cdp.send('Page.crash').catch(() => {}); // no pagehide, no release: only the socket closing
    await atRest();
  });

  test(
    'a frozen page (script hung, socket still open): the dead-man stops the jog',
    async () => {
      await enabled();
      const page = await open(`/axes/${AXIS}`);
      await holdJog(page, 'slow-forward');
      await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'jogging' });
      // 3 s without a single keepalive from the page; the socket stays open
      const frozen = page.evaluate(() => {
        const end = Date.now() + 3000;
        while (Date.now() < end) {}
      });
      try {
        await until(async () => (await status(stack.api, AXIS)).set_velocity === 0, { what: 'the dead-man to stop the axis', timeout: 2500 });
      } finally {
        await frozen.catch(() => {});
        await page.mouse.up();
        await page.close();
        await atRest();
      }
    },
  );

  test('move absolute: the target is reached', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    await page.click('[data-move="move-absolute"]');
    await page.fill('input[name="position"]', '250');
    await page.fill('input[name="velocity"]', '200');
    await page.click('button[name="start"]');
    await until(async () => Math.abs((await readout(page, 'actual_position')) - 250) < 0.01, { what: 'the UI to show 250' });
    const s = await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.in_target_position ? s : null;
    }, { what: 'in target' });
    assert.ok(Math.abs(s.actual_position - 250) < 0.01);
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="move-absolute"][data-state="done"]');
    await shot(page, 'online-after-move');
    await page.close();
  });

  test('an invalid value shows the server’s error at the field (move), a refused command its error text', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    await page.fill('input[name="position"]', '100');
    await page.fill('input[name="velocity"]', '0');
    await page.click('button[name="start"]');
    const msg = await page.locator('[data-field="velocity"] .field-error').textContent({ timeout: 10000 });
    const server = await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute`, { position: 100, velocity: 0 });
    assert.equal(server.status, 422);
    assert.equal(msg, server.body.errors.find((e) => e.field === 'velocity').message);
    // beyond the software limit: refused by the axis (409), shown in the log with its text
    await page.fill('input[name="position"]', '5000');
    await page.fill('input[name="velocity"]', '100');
    const before = await page.locator('button[name="start"]').boundingBox();
    await page.click('button[name="start"]');
    // The error banner floats: the Start button has not moved under the pointer.
    await page.waitForSelector('.banner-error');
    const after = await page.locator('button[name="start"]').boundingBox();
    assert.deepEqual(after, before, 'the page moved when the error banner appeared');
    const row = page.locator('[data-testid="command-log"] tr[data-state="rejected"]', { hasText: 'move-absolute' }).filter({ hasText: 'position=5000' });
    const text = await row.textContent({ timeout: 10000 });
    assert.match(text, /0x7001/);
    assert.match(text, /positive software limit/);
    // The log is in time order: a command sent after the refused one is listed above it.
    await page.fill('input[name="position"]', '10');
    await page.click('button[name="start"]');
    await until(async () => {
      const rows = await page.locator('[data-testid="command-log"] tbody tr').evaluateAll((trs) =>
        trs.map((tr) => `${tr.getAttribute('data-state')} ${tr.textContent}`));
      const accepted = rows.findIndex((r) => !r.startsWith('rejected') && r.includes('position=10 '));
      const refused = rows.findIndex((r) => r.startsWith('rejected') && r.includes('position=5000'));
      return accepted >= 0 && refused > accepted;
    }, { what: 'the later command above the refused one' });
    await shot(page, 'online-errors');
    await page.close();
  });

  test('a number field with text that is not a number: "enter a number" beside it, nothing sent, no serde text', async () => {
    await enabled();
    await atRest();
    const page = await open(`/axes/${AXIS}`);
    const sent = [];
    page.on('request', (r) => r.method() === 'POST' && r.url().includes(`/axes/${AXIS}/move-absolute`) && sent.push(r.postDataJSON()));
    await startAbsolute(page, '20', 'abc');
    const said = page.locator('[data-field="velocity"] .field-error:visible');
    await said.waitFor();
    assert.equal((await said.textContent()).trim(), 'enter a number');
    assert.equal(await page.getAttribute('input[name="velocity"]', 'aria-invalid'), 'true');
    await picture(page, 'online-not-a-number');
    // a number then: that one is sent — and it is the only move sent
    const answered = page.waitForResponse((r) => r.request().method() === 'POST' && r.url().includes(`/axes/${AXIS}/move-absolute`));
    await page.fill('input[name="velocity"]', '100');
    await page.click('button[name="start"]');
    assert.equal((await answered).status(), 202);
    assert.deepEqual(sent.map((b) => b.velocity), [100], 'the move with "abc" was never sent');
    await page.waitForSelector('[data-field="velocity"] .field-error', { state: 'detached' });
    assert.equal(await page.locator('text=invalid type').count(), 0, 'no serde message anywhere');
    assert.equal(await page.locator('[data-testid="command-log"] tr[data-state="rejected"][data-command="move-absolute"]', { hasText: 'enter a number' }).count(), 0, 'nothing logged as refused by the server');
    // a block's field on another tab (Functions: homing's search velocity) says it the same way
    await page.click('[data-tab="functions"]');
    await page.fill('input[name="home-search-velocity"]', '12x');
    await page.click('button[name="home-start"]');
    await page.locator('[data-field="home-search-velocity"] .field-error:visible').waitFor();
    assert.equal((await page.locator('[data-field="home-search-velocity"] .field-error:visible').textContent()).trim(), 'enter a number');
    await atRest();
    await page.close();
  });

  for (const [width, height] of [
    [1280, 800],
    [390, 844],
  ]) {
    test(`the error toast at ${width}×${height}: in the bottom corner, over neither the header nor the axis's name, state and tabs; × dismisses it`, async () => {
      await enabled();
      await atRest();
      const page = await open(`/axes/${AXIS}`, { width, height });
      await startAbsolute(page, '5000', '100');
      const toast = page.locator('.banner-float');
      await toast.waitFor();
      assert.match(await toast.textContent(), /0x7001/);
      const t = await toast.boundingBox();
      for (const sel of ['.topbar', '.axis-head', '.tabs']) {
        const r = await page.locator(sel).first().boundingBox();
        const apart = t.x + t.width <= r.x || r.x + r.width <= t.x || t.y + t.height <= r.y || r.y + r.height <= t.y;
        assert.ok(apart, `the toast ${JSON.stringify(t)} covers ${sel} ${JSON.stringify(r)}`);
      }
      assert.ok(t.y + t.height <= height && t.y >= height / 2, `in the lower half of the window: ${JSON.stringify(t)}`);
      assert.ok(t.x >= 0 && t.x + t.width <= width, `inside the window: ${JSON.stringify(t)}`);
      await picture(page, width < 700 ? 'online-error-toast-phone' : 'online-error-toast');
      await page.click('button[name="dismiss-error"]');
      await toast.waitFor({ state: 'detached' });
      await page.close();
    });
  }

  test('feed enables; override; Stop released at standstill (XAE), an API stop held until released; home with a chosen mode', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}`);
    // without the positive feed enable a forward jog is refused, with its error text
    await page.uncheck('input[name="feed-positive"]');
    await page.click('button[name="power-set"]');
    await page.waitForSelector('[data-led="Feed +"][data-on="0"]', { timeout: 10000 });
    await holdJog(page, 'slow-forward');
    const refused = await page.locator('[data-jog-phase="idle"] .text-error').textContent({ timeout: 10000 });
    await page.mouse.up();
    assert.match(refused, /0x7020/);
    await page.waitForSelector('[data-testid="command-log"] tr[data-state="rejected"][data-command="jog"]');
    await page.check('input[name="feed-positive"]');
    await page.click('button[name="power-set"]');
    await page.waitForSelector('[data-led="Feed +"][data-on="1"]', { timeout: 10000 });
    // override slider → set-override
    await page.click('.override button:has-text("50")');
    await until(async () => (await status(stack.api, AXIS)).override_percent === 50, { what: 'override 50 %' });
    await page.click('.override button:has-text("100")');
    await until(async () => (await status(stack.api, AXIS)).override_percent === 100, { what: 'override 100 %' });
    // changed by another client: the slider follows; under a power override of 50 % it still
    // shows the MC_SetOverride factor (effective = 50 % × 30 % = 15 %)
    await rest(stack.api, 'POST', `/axes/${AXIS}/set-override`, { velocity_factor: 0.3 });
    await until(async () => (await page.inputValue('input[name="override"]')) === '30', { what: 'the slider to follow set-override' });
    await rest(stack.api, 'POST', `/axes/${AXIS}/power`, { override_percent: 50 });
    await until(async () => (await status(stack.api, AXIS)).override_percent === 15, { what: 'effective override 15 %' });
    await page.waitForSelector('[data-testid="override-power"]:has-text("50 %")', { timeout: 10000 });
    // the page has the status with the effective 15 %: the slider still shows the factor
    await until(async () => (await readout(page, 'override')) === 15, { what: 'the effective override 15 % shown' });
    assert.equal(await page.inputValue('input[name="override"]'), '30');
    // the UI's power keeps that override: enabling never changes the speed
    const powerSent = page.waitForRequest((r) => r.method() === 'POST' && r.url().endsWith(`/axes/${AXIS}/power`));
    const powerDone = page.waitForResponse((r) => r.request().method() === 'POST' && r.url().endsWith(`/axes/${AXIS}/power`));
    await page.click('button[name="power-set"]');
    assert.equal((await powerSent).postDataJSON().override_percent, 50);
    const done = await powerDone;
    assert.equal(done.status(), 202);
    const { id } = await done.json();
    await until(async () => (await rest(stack.api, 'GET', `/commands/${id}`)).body?.outputs?.status === true, { what: 'the UI’s power to be on' });
    const kept = await status(stack.api, AXIS);
    assert.equal(kept.power_override_percent, 50);
    assert.equal(kept.override_percent, 15);
    await page.waitForSelector('[data-testid="override-power"]:has-text("50 %")', { timeout: 10000 });
    // back to 100 % by the other client's power, and the slider
    await rest(stack.api, 'POST', `/axes/${AXIS}/power`, { override_percent: 100 });
    await page.click('.override button:has-text("100")');
    await until(async () => (await status(stack.api, AXIS)).override_percent === 100, { what: 'override 100 % again' });
    await page.waitForSelector('[data-testid="override-power"]', { state: 'detached', timeout: 10000 });
    // Stop (TwinCAT XAE's F6): MC_Stop, and at standstill the UI releases it — the axis is
    // ready again without a Release
    assert.match(await page.getAttribute('button[name="stop"]', 'title'), /the UI releases the stop, so the axis is ready again/);
    await page.click('[data-move="move-velocity"]');
    await page.fill('input[name="velocity"]', '50');
    await page.click('button[name="start"]');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'moving' });
    const stopSent = page.waitForResponse((r) => r.request().method() === 'POST' && r.url().endsWith(`/axes/${AXIS}/stop`));
    const released = page.waitForResponse((r) => r.request().method() === 'DELETE' && /\/commands\/\d+$/.test(r.url()));
    await page.click('button[name="stop"]');
    const stopId = (await (await stopSent).json()).id;
    assert.ok((await released).url().endsWith(`/commands/${stopId}`), 'the page released its own stop');
    const stopped = (await rest(stack.api, 'GET', `/commands/${stopId}`)).body;
    assert.equal(stopped.state, 'done', 'released once done (at standstill)');
    assert.equal(stopped.final, true);
    const ready = await atRest();
    assert.equal(ready.motion_commands_locked, false);
    await page.waitForSelector('[data-led="Stop lock"][data-on="0"]', { timeout: 10000 });
    assert.equal(await page.locator('button[name="release-stop"]').count(), 0);
    // the next command is taken at once
    await page.click('[data-move="move-relative"]');
    await page.fill('input[name="distance"]', '5');
    await page.click('button[name="start"]');
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="move-relative"][data-state="done"]', { timeout: 10000 });
    await atRest();
    // a stop sent over the API keeps its PLCopen lock: the axis stays in Stopping, a move is
    // refused, until it is released — here from this page
    const other = await rest(stack.api, 'POST', `/axes/${AXIS}/stop`, { deceleration: 1000 });
    assert.equal(other.status, 202, JSON.stringify(other.body));
    await page.waitForSelector('button[name="release-stop"]', { timeout: 10000 });
    await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.set_velocity === 0 && s.state === 'stopping';
    }, { what: 'stopped and locked' });
    await until(async () => (await page.locator('[data-testid="axis-state"]').textContent()) === 'Stopping', { what: 'Stopping shown' });
    await page.fill('input[name="distance"]', '10');
    await page.click('button[name="start"]');
    await page.waitForSelector('[data-testid="command-log"] tr[data-state="rejected"][data-command="move-relative"]');
    assert.equal((await rest(stack.api, 'GET', `/commands/${other.body.id}`)).body.final, false, 'the API’s stop is not released by the page on its own');
    await page.click('button[name="release-stop"]');
    await page.waitForSelector('[data-led="Stop lock"][data-on="0"]', { timeout: 10000 });
    assert.ok((await rest(stack.api, 'GET', `/commands/${other.body.id}`)).body.final, 'the other client’s stop was released');
    await atRest();
    // MC_Home, mode direct at 12.5
    await page.selectOption('select[name="home-mode"]', 'direct');
    await page.fill('input[name="home-position"]', '12.5');
    await page.click('button[name="home-btn"]');
    await page.waitForSelector('[data-led="Homed"][data-on="1"]', { timeout: 10000 });
    const s = await status(stack.api, AXIS);
    assert.ok(s.homed);
    assert.ok(Math.abs(s.set_position - 12.5) < 1e-9, `homed at ${s.set_position}`);
    await shot(page, 'online-homed');
    // inching: one step of the chosen increment per click; the steps start as #1015 / #1014
    assert.equal(await page.inputValue('input[name="inch-step-backward"]'), String((await rest(stack.api, 'GET', `/axes/${AXIS}/parameters/1015`)).body.value));
    assert.equal(await page.inputValue('input[name="inch-step-forward"]'), String((await rest(stack.api, 'GET', `/axes/${AXIS}/parameters/1014`)).body.value));
    await page.fill('input[name="inch-step-forward"]', '2.5');
    await page.fill('input[name="inch-step-backward"]', '2.5');
    await page.click('button[name="inch-forward"]');
    await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.in_target_position && Math.abs(s.set_position - 15) < 1e-9;
    }, { what: 'one inching step forward' });
    await page.click('button[name="inch-backward"]');
    await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.in_target_position && Math.abs(s.set_position - 12.5) < 1e-9;
    }, { what: 'one inching step backward' });
    // the following-error peak hold is the server's (every cycle): the readout shows its
    // min / max, and reset restarts it on the server, not only on this page
    const lagText = (v) => (v.toFixed(4) === '-0.0000' ? '0.0000' : v.toFixed(4));
    const peakShown = async () => (await page.locator('[data-readout="lag_peak"] .dro-value').textContent()).trim();
    const before = await status(stack.api, AXIS);
    assert.ok(before.following_error_max - before.following_error_min > 1e-4, `a peak to reset: ${JSON.stringify(before)}`);
    await until(async () => (await peakShown()) === `${lagText(before.following_error_min)} / ${lagText(before.following_error_max)}`, {
      what: 'the readout to show the server’s peak hold',
    });
    await page.click('button[name="reset-peak"]');
    const after = await until(
      async () => {
        const s = await status(stack.api, AXIS);
        return s.following_error_max - s.following_error_min < 1e-6 ? s : null;
      },
      { what: 'the server’s peak hold restarted' },
    );
    assert.ok(Math.abs(after.following_error_max - after.following_error) < 1e-6, JSON.stringify(after));
    await until(async () => (await peakShown()) === `${lagText(after.following_error_min)} / ${lagText(after.following_error_max)}`, {
      what: 'the readout to agree with GET status after the reset',
    });
    await page.close();
  });

  test('TwinCAT function keys on the Online tab: F3/F2 held jog, F5 starts the move, F6 stops (released at standstill), F9 homes, F8 resets', async () => {
    await enabled();
    await atRest();
    const page = await open(`/axes/${AXIS}`);
    await page.waitForSelector('[data-led="Enabled"][data-on="1"]', { timeout: 10000 });
    assert.match(await page.getAttribute('[data-jog="slow-forward"]', 'title'), /F3/);
    assert.match(await page.getAttribute('button[name="stop"]', 'title'), /\(F6\)/);
    assert.match(await page.getAttribute('button[name="start"]', 'title'), /\(F5\)/);
    assert.match(await page.getAttribute('button[name="reset"]', 'title'), /\(F8\)/);
    assert.match(await page.getAttribute('button[name="home-btn"]', 'title'), /\(F9\)/);
    // F5 must not reload the page: a mark on the window survives
    await page.evaluate(() => (window.__mark = 1));
    // with the focus in a text field too: the F-keys type nothing
    await page.click('input[name="velocity"]');
    const start = (await status(stack.api, AXIS)).set_position;
    await page.keyboard.down('F3');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'F3 jogs forward' });
    await page.waitForSelector('[data-jog="slow-forward"].held');
    // beyond the 0.5 s dead-man — 7 mm at 10 mm/s is 0.7 s of jogging: the key keeps it going
    await until(async () => (await status(stack.api, AXIS)).set_position > start + 7, { what: 'F3 to jog 7 mm (0.7 s)' });
    assert.ok((await status(stack.api, AXIS)).set_velocity > 0, 'still jogging while F3 is held');
    await page.keyboard.up('F3');
    const s1 = await atRest();
    assert.ok(s1.set_position > start + 5, `moved forward (${start} → ${s1.set_position})`);
    await page.keyboard.down('F2');
    await until(async () => (await status(stack.api, AXIS)).set_velocity < 0, { what: 'F2 jogs backward' });
    await page.keyboard.up('F2');
    await atRest();
    // F5: the selected move (absolute to 40)
    await page.click('[data-move="move-absolute"]');
    await page.fill('input[name="position"]', '40');
    await page.fill('input[name="velocity"]', '200');
    await page.keyboard.press('F5');
    await until(async () => {
      const s = await status(stack.api, AXIS);
      return s.in_target_position && Math.abs(s.set_position - 40) < 1e-9;
    }, { what: 'F5 moved to 40' });
    assert.equal(await page.evaluate(() => window.__mark), 1, 'F5 did not reload the page');
    // F6 during a velocity move: MC_Stop, with the stop deceleration of the form
    await page.click('[data-move="move-velocity"]');
    await page.fill('input[name="velocity"]', '50');
    await page.fill('input[name="stop-deceleration"]', '800');
    await page.keyboard.press('F5');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'F5 started the velocity move' });
    const stopSent = page.waitForResponse((r) => r.request().method() === 'POST' && r.url().endsWith(`/axes/${AXIS}/stop`));
    await page.keyboard.press('F6');
    const stop = await (await stopSent).json();
    assert.equal(stop.parameters.deceleration, 800);
    // as in TwinCAT XAE: at standstill the stop is released, the axis is ready — F9 homes at once
    await until(async () => (await rest(stack.api, 'GET', `/commands/${stop.id}`)).body.final, { what: 'the F6 stop released at standstill' });
    assert.equal((await rest(stack.api, 'GET', `/commands/${stop.id}`)).body.state, 'done');
    await atRest();
    await page.waitForSelector('[data-led="Stop lock"][data-on="0"]', { timeout: 10000 });
    await page.fill('input[name="stop-deceleration"]', '');
    // F9: MC_Home with the chosen mode, right after the stop
    await page.selectOption('select[name="home-mode"]', 'direct');
    await page.fill('input[name="home-position"]', '7');
    await page.keyboard.press('F9');
    await until(async () => Math.abs((await status(stack.api, AXIS)).set_position - 7) < 1e-9, { what: 'F9 homed at 7' });
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="home"][data-state="done"]', { timeout: 10000 });
    // F8: MC_Reset
    await page.keyboard.press('F8');
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="reset"]', { timeout: 10000 });
    await shot(page, 'online-function-keys');
    await page.close();
  });

  test('halt with its own deceleration (a bad one at its field), set position relative', async () => {
    await enabled();
    await atRest();
    const page = await open(`/axes/${AXIS}`);
    await page.click('[data-move="move-velocity"]');
    await page.fill('input[name="velocity"]', '50');
    await page.click('button[name="start"]');
    await until(async () => (await status(stack.api, AXIS)).set_velocity > 0, { what: 'moving' });
    await page.fill('input[name="stop-deceleration"]', '-1');
    await page.click('button[name="halt"]');
    const msg = await page.locator('[data-field="stop-deceleration"] .field-error').textContent({ timeout: 10000 });
    const server = await rest(stack.api, 'POST', `/axes/${AXIS}/halt`, { deceleration: -1 });
    assert.equal(server.status, 422);
    assert.equal(msg, server.body.errors.find((e) => e.field === 'deceleration').message);
    await page.fill('input[name="stop-deceleration"]', '600');
    await page.fill('input[name="stop-jerk"]', '60000');
    await page.click('button[name="halt"]');
    await atRest();
    const halt = (await rest(stack.api, 'GET', `/commands?axis=${AXIS}&limit=5`)).body.find((c) => c.command === 'halt');
    assert.deepEqual([halt.parameters.deceleration, halt.parameters.jerk], [600, 60000]);
    // MC_SetPosition relative: shifted by 10
    const before = (await status(stack.api, AXIS)).set_position;
    await page.fill('input[name="set-position"]', '10');
    await page.check('input[name="set-position-relative"]');
    await page.click('button[name="set-position-btn"]');
    await until(async () => Math.abs((await status(stack.api, AXIS)).set_position - (before + 10)) < 1e-9, { what: 'position shifted by 10' });
    await page.close();
  });

  test('a modulo axis offers MC_MoveModulo with a direction', async () => {
    const created = await rest(stack.api, 'POST', '/axes', {
      name: 'rot',
      unit: 'deg',
      modulo: { period: 360 },
      dynamics: { max_velocity: 720, acceleration: 3600, deceleration: 3600, jerk: 36000, jog_velocity_slow: 10, jog_velocity_fast: 90 },
    });
    assert.equal(created.status, 201, JSON.stringify(created.body));
    try {
      await rest(stack.api, 'POST', '/axes/rot/power', {});
      await until(async () => (await status(stack.api, 'rot')).power_status, { what: 'rot enabled' });
      const page = await open('/axes/rot');
      await page.click('[data-move="move-modulo"]');
      await page.fill('input[name="position"]', '270');
      await page.selectOption('select[name="direction"]', 'negative');
      await page.fill('input[name="velocity"]', '360');
      await page.click('button[name="start"]');
      // from 0 the negative way to 270 is −90°
      await until(async () => {
        const s = await status(stack.api, 'rot');
        return s.in_target_position && Math.abs(s.modulo_set_position - 270) < 1e-6 ? s : null;
      }, { what: 'rot at 270° modulo' });
      assert.ok(Math.abs((await status(stack.api, 'rot')).set_position + 90) < 1e-6, 'went the negative way');
      const cmd = (await rest(stack.api, 'GET', '/commands?axis=rot&limit=5')).body.find((c) => c.command === 'move-modulo');
      assert.equal(cmd.parameters.direction, 'negative');
      // coupled as a gear slave: the Online tab names its master
      await enabled();
      const gear = await rest(stack.api, 'POST', '/axes/rot/gear-in', { master: AXIS, ratio_numerator: 1, ratio_denominator: 1 });
      assert.equal(gear.status, 202, JSON.stringify(gear.body));
      await until(async () => (await status(stack.api, 'rot')).master === AXIS, { what: 'rot coupled to e2e' });
      assert.equal((await page.locator('[data-testid="master"]').textContent({ timeout: 10000 })).trim(), `coupled to master ${AXIS}`);
      assert.equal((await rest(stack.api, 'POST', '/axes/rot/gear-out', {})).status, 202);
      await page.waitForSelector('[data-testid="master"]', { state: 'detached', timeout: 10000 });
      await page.close();
      // the linear axis has no modulo move
      const lin = await open(`/axes/${AXIS}`);
      assert.equal(await lin.locator('[data-move="move-modulo"]').count(), 0);
      await lin.close();
    } finally {
      await rest(stack.api, 'POST', '/axes/rot/power', { enable: false });
      await until(async () => !(await status(stack.api, 'rot')).power_status, { what: 'rot disabled' });
      assert.equal((await rest(stack.api, 'DELETE', '/axes/rot')).status, 204);
    }
  });

  test('an axis in error is shown with its error text; reset clears it', async () => {
    await enabled();
    const f = await rest(stack.api, 'POST', `/axes/${AXIS}/simulation/fault`, { kind: 'drive_fault', code: 8976 });
    assert.ok(f.status < 300, JSON.stringify(f.body));
    const page = await open(`/axes/${AXIS}`);
    const banner = page.locator('[data-testid="axis-error"]');
    await banner.waitFor({ timeout: 10000 });
    assert.match(await banner.textContent(), /0x7010/);
    assert.match(await banner.textContent(), /drive fault/);
    await page.goto(`${stack.url}/#/`);
    await page.waitForSelector(`tr[data-axis="${AXIS}"].row-error`);
    await shot(page, 'overview-axis-in-error');
    await page.goto(`${stack.url}/#/axes/${AXIS}`);
    await rest(stack.api, 'POST', `/axes/${AXIS}/simulation/fault`, { kind: 'clear' });
    await page.click('button[name="reset-error"]');
    await banner.waitFor({ state: 'detached', timeout: 10000 });
    assert.equal((await status(stack.api, AXIS)).error_id, 0);
    await page.close();
  });

  test('parameters: a change is shown as a diff and applied; an invalid one shows the server’s error at the row', async () => {
    const page = await open(`/axes/${AXIS}/parameters`);
    const row = page.locator('tr[data-param="AxisVeloManSlow"]');
    await row.waitFor();
    await row.locator('input').fill('20');
    await page.click('button[name="review"]');
    const diff = page.locator('[data-testid="param-diff"] tr[data-param="AxisVeloManSlow"]');
    assert.match(await diff.locator('.old').textContent(), /^10$/);
    assert.match(await diff.locator('.new').textContent(), /^20$/);
    await shot(page, 'parameters-diff');
    await page.check('input[name="persistent"]');
    await page.click('button[name="apply"]');
    await page.waitForSelector('[data-testid="apply-message"]');
    const p = (await rest(stack.api, 'GET', `/axes/${AXIS}/parameters/1001`)).body;
    assert.equal(p.value, 20);
    assert.equal(p.persistent_value, 20);
    // invalid: above AxisVeloMax
    await row.locator('input').fill('-5');
    await page.click('button[name="review"]');
    await page.click('button[name="apply"]');
    const err = await row.locator('.field-error').textContent({ timeout: 10000 });
    const server = await rest(stack.api, 'PUT', `/axes/${AXIS}/parameters/1001`, { value: -5 });
    assert.equal(server.status, 422);
    assert.ok(err.startsWith(server.body.errors[0].message), `${err} / ${server.body.errors[0].message}`);
    await shot(page, 'parameters-error');
    // Aliases only with "aliases" ticked; a search that matches hidden ones says so.
    await row.locator('input').fill('');
    await page.fill('input[name="filter"]', 'MaxVelocityAppl');
    await until(async () => /1 alias match/.test(await page.locator('.params .toolbar').first().textContent()), { what: 'the hidden alias hint' });
    assert.equal(await page.locator('tr[data-param="MaxVelocityAppl"]').count(), 0);
    await page.check('input[name="aliases"]');
    await page.locator('tr[data-param="MaxVelocityAppl"]').waitFor();
    await page.uncheck('input[name="aliases"]');
    await page.fill('input[name="filter"]', '');
    // the online tab's jog button follows the parameter
    await page.goto(`${stack.url}/#/axes/${AXIS}`);
    await until(async () => /20 mm\/s/.test(await page.locator('[data-jog="slow-forward"]').textContent()), { what: 'jog button velocity' });
    await page.close();
  });

  test('server gone: the UI says so, every command button is disabled, then it reconnects by itself', async () => {
    await enabled();
    // an axis in error (the banner's Reset) with an edited parameter (Review & apply)
    assert.ok((await rest(stack.api, 'POST', `/axes/${AXIS}/simulation/fault`, { kind: 'drive_fault', code: 8976 })).status < 300);
    const page = await open(`/axes/${AXIS}/parameters`);
    await page.locator('[data-testid="axis-error"]').waitFor({ timeout: 10000 });
    await page.locator('tr[data-param="AxisVeloManFast"] input').fill('150');
    assert.equal(await page.locator('button[name="review"]').isDisabled(), false);
    await stack.killMotiond();
    await page.waitForSelector('[data-notice="server-gone"]', { timeout: 15000 });
    const disabled = async (where, names) => {
      for (const n of names) assert.equal(await page.locator(n).first().isDisabled(), true, `${n} disabled while offline (${where})`);
    };
    await disabled('parameters', ['button[name="review"]', 'button[name="reset-error"]']);
    await page.click('[data-tab="config"]');
    await disabled('configuration', ['button[name="save"]', 'button[name="delete"]']);
    await page.click('[data-tab="online"]');
    await disabled('online', [
      '[data-jog="slow-forward"]',
      'button[name="inch-forward"]',
      'button[name="power-set"]',
      'button[name="reset"]',
      'button[name="start"]',
      'button[name="halt"]',
      'button[name="stop"]',
      'button[name="set-position-btn"]',
      'button[name="home-btn"]',
      'input[name="override"]',
      'button[name="reset-error"]',
      'button[name="reset-peak"]',
    ]);
    assert.equal(await page.locator('[data-testid="trend-state"]').textContent(), 'not live');
    assert.match(await page.getAttribute('.trend', 'class'), /trend-off/);
    await shot(page, 'online-server-gone');
    await page.click('.nav a:has-text("Scope")');
    await disabled('scope', ['button[name="record"]']);
    await stack.restartMotiond();
    await page.waitForSelector('[data-conn="open"]', { timeout: 30000 });
    await page.waitForSelector('[data-notice="server-gone"]', { state: 'detached' });
    await page.waitForSelector('button[name="record"]:not([disabled])', { timeout: 10000 });
    await page.click(`.axis-item[data-axis="${AXIS}"]`);
    await until(async () => Number.isFinite(await readout(page, 'actual_position')), { what: 'live values again' });
    await page.close();
  });

  /** A cam table for the editor's page in the every-page test (a test run alone makes it). */
  async function pagesCam() {
    if ((await rest(stack.api, 'GET', '/cam-tables/pages')).status === 200) return;
    const p = (i, x, y, law = 'polynom5', type = 'rest') => ({ point_index: i, function_type: law, point_type: type, master_pos: x, slave_pos: y });
    const r = await rest(stack.api, 'POST', '/cam-tables', { name: 'pages', table_type: 'motion_function', periodic: true, points: [p(1, 0, 0), p(2, 100, 50, 'polynom1', 'motion'), p(3, 200, 100, 'polynom5', 'motion'), p(4, 360, 0)] });
    assert.equal(r.status, 201, JSON.stringify(r.body));
  }

  for (const [width, height] of [
    [1600, 1000],
    [1280, 800],
    [1024, 768],
    [390, 844],
  ]) {
    // At the largest and the smallest size also no text cut off inside its own box (a label,
    // table cell, select, button or number field showing only part of what it holds).
    const whole = (width === 1600 && height === 1000) || (width === 390 && height === 844);
    test(`every page at ${width}×${height}: screenshots, nothing wider than the window${whole ? ', no text cut off' : ''}`, async () => {
      await enabled();
      await pagesCam();
      const page = await open('/', { width, height });
      const cut = [];
      // [name, route, what shows that its content has loaded (one selector or several)]
      const pagesToSee = [
        ['overview', '/', `.main [data-axis="${AXIS}"] [data-col="actual_position"]:text-matches("[0-9]")`],
        ['online', `/axes/${AXIS}`, '[data-readout="actual_position"]'],
        ['coupling', `/axes/${AXIS}/coupling`, '[data-testid="coupling-kv"]'],
        ['functions', `/axes/${AXIS}/functions`, '[data-testid="homing-phase"]'],
        ['parameters', `/axes/${AXIS}/parameters`, '.params'],
        ['configuration', `/axes/${AXIS}/config`, 'select[name="drive.plant.kind"]'],
        ['new-axis', '/new-axis', 'input[name="name"]'],
        ['scope', '/scope', '[data-channel="0"]'],
        ['cams', '/cams', 'tr[data-cam="pages"]'],
        // the editor with a jump warned (Polynom 1 from a MOTION point) and its handles
        ['cam-editor', '/cams/pages', ['[data-analysis="current"]', 'tr.has-warning', '[data-handle="1"]']],
        ['system', '/system', '[data-testid="timing"] tr[data-metric="period"]'],
        // authentication is off in this stack: the users page is open to anyone
        ['users', '/users', '[data-testid="users"]'],
      ];
      for (const [name, path, ready] of pagesToSee) {
        await page.goto(`${stack.url}/#${path}`);
        await page.waitForSelector('[data-conn="open"]');
        await page.waitForSelector('.main .page');
        for (const sel of [ready].flat()) await page.waitForSelector(sel);
        // live values there for the picture: every live indicator of the page says so
        await page.waitForFunction(() => [...document.querySelectorAll('.main .live-ind[data-live]')].every((e) => e.dataset.live === 'live'));
        await shot(page, `${name}-${width}x${height}`);
        const o = await overflowing(page);
        assert.ok(o.doc <= 0 && o.main <= 0, `${name} at ${width}×${height} scrolls sideways: ${JSON.stringify(o)}`);
        assert.deepEqual(o.wide, [], `${name} at ${width}×${height}: elements beyond the window's right edge`);
        if (whole) cut.push(...(await clippedText(page)).map((c) => `${name}: ${c}`));
        if (name === 'overview' && width < 700) {
          // on a phone every value of the overview is on the screen, none behind a sideways scroll
          const off = await page.$$eval('[data-testid="overview"] td', (tds) =>
            tds.filter((td) => {
              const r = td.getBoundingClientRect();
              return r.width > 0 && (r.left < 0 || r.right > document.documentElement.clientWidth);
            }).map((td) => td.dataset.col ?? td.textContent.trim()),
          );
          assert.deepEqual(off, [], 'overview cells off the screen at 390×844');
          await picture(page, 'overview-phone');
        }
      }
      assert.deepEqual(cut, [], `text cut off at ${width}×${height}:\n${cut.join('\n')}`);
    });
  }

  test('cam editor: the table is plotted from the server, a point edited and saved, a bad one refused at its row', async () => {
    const r = await rest(stack.api, 'POST', '/cam-tables', { name: 'lift', table_type: 'motion_function', points: [
      { point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
      { point_index: 2, function_type: 'polynom5', point_type: 'rest', master_pos: 200, slave_pos: 100 } ] });
    assert.equal(r.status, 201, JSON.stringify(r.body));
    const page = await open('/cams');
    await page.click('tr[data-cam="lift"] a');
    await page.waitForSelector('#cam[data-version="1"]');
    const chart = page.locator('[data-chart="cam"]');
    await until(async () => Number(await chart.getAttribute('data-samples')) > 700, { what: 'the plot' });
    assert.equal(await chart.getAttribute('data-series'), 'position,velocity,acceleration,jerk');
    assert.equal(await page.locator('[data-charac="slave_velo_max"]').textContent(), '0.9375');
    await shot(page, 'cam-editor');
    // The end of the lift from 100 to 120: saved, the version rises, the plot follows.
    await page.fill('input[name="slave_pos-2"]', '120');
    await page.click('button[name="save-cam"]');
    await page.waitForSelector('#cam[data-version="2"]');
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/lift')).body.slave_end, 120);
    await until(async () => (await page.locator('[data-charac="slave_velo_max"]').textContent()) === '1.125', { what: 'new characteristics' });
    // The first point IGNORE: the server refuses it (safety rule) and says so at the row.
    await page.selectOption('select[name="point_type-1"]', 'ignore');
    await page.click('button[name="save-cam"]');
    await page.waitForSelector('tr[data-point="1"].has-error');
    assert.match(await page.locator('tr[data-point="1"] .field-error').textContent(), /point_type: the first and the last point must not be IGNORE/);
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/lift')).body.version, 2, 'nothing stored');
    await page.close();
  });

  test('scope: a recording survives leaving the page to move the axis; the chart shows it', async () => {
    await enabled();
    await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute?wait=true`, { position: 0, velocity: 500 });
    await atRest();
    const page = await open('/scope');
    // channels: e2e.set_position, e2e.set_velocity
    await page.waitForSelector('[data-channel="0"]');
    while ((await page.locator('[data-channel]').count()) < 2) await page.click('button[name="add-channel"]');
    await page.selectOption('select[name="channel-0-axis"]', AXIS);
    await page.selectOption('select[name="channel-0-signal"]', 'set_position');
    await page.selectOption('select[name="channel-1-axis"]', AXIS);
    await page.selectOption('select[name="channel-1-signal"]', 'set_velocity');
    while ((await page.locator('[data-channel]').count()) > 2) await page.locator('[data-channel="2"] button').click();
    await page.fill('input[name="duration_s"]', '1');
    await page.check('input[name="trigger-on"]');
    await page.selectOption('select[name="trigger.channel"]', '1');
    await page.fill('input[name="trigger.level"]', '1');
    await page.selectOption('select[name="trigger.edge"]', 'rising');
    await page.fill('input[name="trigger.pre_trigger_s"]', '0.1');
    await page.click('button[name="record"]');
    const state = page.locator('[data-testid="recording-state"]');
    await state.waitFor({ timeout: 10000 });
    const armed = (await rest(stack.api, 'GET', '/scope/recordings')).body[0];
    assert.equal(armed.state, 'armed');
    assert.equal(await state.getAttribute('data-recording'), String(armed.id));
    // a reload (or another browser) finds the armed recording on the server
    await page.reload();
    await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
    await page.waitForSelector(`[data-testid="recording-state"][data-recording="${armed.id}"][data-state="armed"]`, { timeout: 10000 });
    assert.equal(await page.locator('button[name="record"]').isDisabled(), true, 'no second recording while one is armed');
    // the trigger looks only once the pre-trigger history is full
    await until(async () => (await rest(stack.api, 'GET', '/system')).body.cycle > armed.start_cycle + armed.pre_trigger_samples + 10, {
      what: 'the pre-trigger history',
    });
    // to the Online tab, move the axis there, back to the Scope page
    await page.click(`.axis-item[data-axis="${AXIS}"]`);
    await page.waitForSelector('button[name="start"]');
    await page.click('[data-move="move-absolute"]');
    await page.fill('input[name="position"]', '100');
    await page.fill('input[name="velocity"]', '400');
    await page.click('button[name="start"]');
    await until(async () => (await status(stack.api, AXIS)).in_target_position && (await status(stack.api, AXIS)).set_position === 100, { what: 'moved to 100' });
    await page.click('.nav a:has-text("Scope")');
    const info = await page
      .locator('[data-testid="recording-info"]')
      .textContent({ timeout: 30000 })
      .catch(async (e) => {
        await shot(page, 'scope-recording-failed');
        const list = await rest(stack.api, 'GET', '/scope/recordings');
        throw new Error(`${e.message}\nrecordings: ${JSON.stringify(list.body)}`);
      });
    const cycle = (await rest(stack.api, 'GET', '/system')).body.cycle_time;
    const id = /recording (\S+)/.exec(info)[1];
    assert.equal(id, String(armed.id));
    const rec = (await rest(stack.api, 'GET', `/scope/recordings/${id}`)).body;
    const n = Math.round(1 / cycle);
    assert.equal(rec.samples, n, 'samples = duration / cycle time');
    assert.equal(rec.t.length, n);
    assert.equal(rec.data.length, 2);
    assert.equal(rec.data[0].length, n);
    assert.ok(Math.abs(rec.t[0] + 0.1) < cycle, `t starts at −pre-trigger (${rec.t[0]})`);
    assert.ok(Math.abs(rec.data[0][0]) < 1e-6, 'first sample: at 0');
    assert.ok(Math.abs(rec.data[0][n - 1] - 100) < 1e-6, 'last sample: at the target');
    assert.ok(Math.max(...rec.data[1]) > 390, 'the velocity reached the commanded 400');
    // what the UI shows: every sample of both channels drawn, the sample count in the info line
    assert.match(info, new RegExp(`${n} samples × 2 channels`));
    const chart = page.locator('[data-testid="scope-chart"]');
    await page.waitForSelector('[data-testid="scope-chart"] canvas');
    assert.equal(await chart.getAttribute('data-samples'), String(n));
    assert.equal(await chart.getAttribute('data-series'), '2');
    // the kept recordings list names it
    assert.ok((await page.locator('select[name="recordings"] option').allTextContents()).some((t) => t.startsWith(`#${id} `)));
    // zoom and pan with the toolbar (no mouse wheel on a tablet)
    const view = async () => (await chart.getAttribute('data-view')).split(',').map(Number);
    const full = async () => {
      const [a, b] = await view();
      return Math.abs(a - rec.t[0]) < 1e-9 && Math.abs(b - rec.t[n - 1]) < 1e-9;
    };
    const [t0, t1] = await view();
    assert.ok(await full(), `full view ${t0} … ${t1}`);
    await page.click('button[name="zoom-in"]');
    const [z0, z1] = await view();
    assert.ok(Math.abs(z1 - z0 - (t1 - t0) / 2) < 1e-9, `zoomed to half: ${z0} … ${z1}`);
    await page.click('button[name="pan-right"]');
    const [p0, p1] = await view();
    assert.ok(p0 > z0 && Math.abs(p1 - p0 - (z1 - z0)) < 1e-9, `panned right: ${p0} … ${p1}`);
    await page.click('button[name="full-view"]');
    assert.ok(await full(), `full view again: ${await view()}`);
    // two cursors: the readout shows the recorded values at the samples under them
    const box = await page.locator('[data-testid="scope-chart"] .u-over').boundingBox();
    await page.mouse.click(box.x + box.width * 0.2, box.y + box.height / 2);
    await page.mouse.click(box.x + box.width * 0.8, box.y + box.height / 2);
    const table = page.locator('[data-testid="cursor-readout"]');
    await table.waitFor();
    const cells = async (row) => (await table.locator(`tr[data-row="${row}"] td`).allTextContents()).map((x) => parseFloat(x));
    const [c1, c2, dt] = await cells('t');
    assert.ok(c1 < c2 && Math.abs(dt - (c2 - c1)) < 1e-6, `cursor times ${c1}, ${c2}, Δ ${dt}`);
    const at = (t) => rec.t.reduce((best, x, i) => (Math.abs(x - t) < Math.abs(rec.t[best] - t) ? i : best), 0);
    const close = (a, b) => Math.abs(a - b) <= 1e-5 * Math.max(1, Math.abs(b));
    const [v1, v2] = await cells(`${AXIS}.set_position`);
    assert.ok(close(v1, rec.data[0][at(c1)]) && close(v2, rec.data[0][at(c2)]), `readout ${v1}, ${v2} vs ${rec.data[0][at(c1)]}, ${rec.data[0][at(c2)]}`);
    await shot(page, 'scope-recording');
    const csv = await (await fetch(`${stack.url}/api/v1/scope/recordings/${id}?format=csv`)).text();
    assert.match(csv.split('\n')[0], new RegExp(`^t,${AXIS}\\.set_position,${AXIS}\\.set_velocity`));
    await page.close();
  });

  test('LIVE panel: the cycle advances while nothing moves; a silent socket shows as stale', async () => {
    await enabled();
    await atRest();
    const page = await open(`/axes/${AXIS}`);
    const ind = page.locator('.dro [data-live]');
    await until(async () => (await ind.getAttribute('data-live')) === 'live', { what: 'the live indicator' });
    const first = Number(await ind.getAttribute('data-cycle'));
    const axisState = async () => (await status(stack.api, AXIS)).state;
    // the axis stands still: only the system topic (1 Hz) speaks, and its cycle advances
    await until(async () => Number(await ind.getAttribute('data-cycle')) > first, { what: 'the cycle to advance at standstill' });
    assert.equal(await axisState(), 'standstill');
    // a server that is there but silent (stopped): no message for 3 s is shown
    stack.signalMotiond('SIGSTOP');
    try {
      await until(async () => (await ind.getAttribute('data-live')) === 'stale', { what: 'the stale indicator' });
      assert.match(await ind.textContent(), /no message for \d+ s/);
      // the header says so too (its own 1 s tick)
      await until(async () => (await page.locator('.topbar [data-conn="open"]').getAttribute('data-live')) === 'stale', { what: 'the silent header' });
      await shot(page, 'online-live-silent');
    } finally {
      stack.signalMotiond('SIGCONT');
    }
    await until(async () => (await ind.getAttribute('data-live')) === 'live', { what: 'live again' });
    await page.close();
  });

  for (const [width, height] of [
    [1280, 800],
    [390, 844],
  ]) {
    test(`the Plant select shows its whole option text at ${width}×${height}`, async () => {
      await ensureAxis();
      const page = await open(`/axes/${AXIS}/config`, { width, height });
      const plant = page.locator('select[name="drive.plant.kind"]');
      await plant.waitFor();
      const m = await plant.evaluate((s) => {
        // its natural width (the longest option and the arrow), measured on a free copy
        const free = s.cloneNode(true);
        free.style.cssText = 'position:absolute;left:0;top:0;width:auto;max-width:none';
        document.body.appendChild(free);
        const need = free.getBoundingClientRect().width;
        free.remove();
        const r = s.getBoundingClientRect();
        return { need, has: r.width, left: r.left, right: r.right, vw: window.innerWidth, title: s.title, text: s.selectedOptions[0].textContent };
      });
      assert.ok(m.has >= m.need - 0.5, `the select is ${m.has} px wide, its text needs ${m.need} px`);
      assert.ok(m.left >= 0 && m.right <= m.vw, `inside the window: ${JSON.stringify(m)}`);
      assert.equal(m.title, m.text);
      await page.close();
    });
  }

  test('phone 390×844: the axis list is a menu in the header, the header is whole, every axis tab is reachable', async () => {
    await ensureAxis();
    // the desktop is as it was: the list beside the page, no menu button
    const desk = await open(`/axes/${AXIS}`);
    assert.equal(await desk.locator('#sidebar').isVisible(), true);
    assert.equal(await desk.locator('button[name="menu"]').isVisible(), false);
    await desk.close();

    const page = await open(`/axes/${AXIS}`, { width: 390, height: 844 });
    const sidebar = page.locator('#sidebar');
    const menu = page.locator('button[name="menu"]');
    assert.equal(await sidebar.isVisible(), false);
    assert.equal(await menu.isVisible(), true);
    // the header: every part inside the window, none over another
    const parts = await page.evaluate(() =>
      [...document.querySelectorAll('.topbar > *, .topbar .nav-link, .topbar-right > *')].map((e) => {
        const r = e.getBoundingClientRect();
        return { what: e.className || e.tagName, parent: e.parentElement.className, l: r.left, r: r.right, t: r.top, b: r.bottom };
      }),
    );
    for (const p of parts) assert.ok(p.l >= 0 && p.r <= 390 && p.t >= 0, `${p.what} is cut: ${JSON.stringify(p)}`);
    const siblings = parts.filter((p) => p.parent === 'topbar');
    for (const a of siblings)
      for (const b of siblings)
        if (a !== b) assert.ok(a.r <= b.l || b.r <= a.l || a.b <= b.t || b.b <= a.t, `${a.what} overlaps ${b.what}`);
    // every tab inside the window and clickable
    for (const [tab, url] of [
      ['parameters', /\/parameters$/],
      ['config', /\/config$/],
      ['online', new RegExp(`/axes/${AXIS}$`)],
    ]) {
      const t = page.locator(`.tabs [data-tab="${tab}"]`);
      const box = await t.boundingBox();
      assert.ok(box.x >= 0 && box.x + box.width <= 390, `tab ${tab} is cut: ${JSON.stringify(box)}`);
      await t.click();
      await page.waitForURL(url);
      await page.waitForSelector(`.tabs [data-tab="${tab}"].active`);
    }
    await shot(page, 'phone-online');
    // the menu opens over the page, an axis in it navigates and closes it
    await menu.click();
    await sidebar.waitFor({ state: 'visible' });
    assert.equal(await menu.getAttribute('aria-expanded'), 'true');
    await shot(page, 'phone-menu-open');
    await page.keyboard.press('Escape');
    await sidebar.waitFor({ state: 'hidden' });
    await menu.click();
    await page.click('#sidebar a[href="#/new-axis"]');
    await page.waitForURL(/#\/new-axis$/);
    await sidebar.waitFor({ state: 'hidden' });
    await menu.click();
    await page.click(`#sidebar .axis-item[data-axis="${AXIS}"]`);
    await page.waitForURL(new RegExp(`#/axes/${AXIS}`));
    await sidebar.waitFor({ state: 'hidden' });
    await page.close();
  });

  test('edit and delete the axis (a save that needs no rebuild keeps it enabled; Delete needs it disabled: the UI offers to do it)', async () => {
    await enabled();
    const page = await open(`/axes/${AXIS}/config`);
    await page.fill('input[name="dynamics.jog_velocity_fast"]', '150');
    // while the axis is enabled: Save asks the server what it would do; Delete is off, the
    // reason and a way out beside it
    const save = page.locator('button[name="save"]');
    await page.waitForSelector('[data-testid="delete-blocked"]');
    assert.equal(await save.isDisabled(), false);
    assert.equal(await page.locator('button[name="delete"]').isDisabled(), true);
    assert.match(await page.locator('[data-testid="delete-blocked"]').textContent(), /enabled: switch it off to re-create or delete it/);
    await shot(page, 'configuration-enabled');
    await save.click();
    await page.waitForSelector('[data-testid="save-panel"][data-rebuild="0"]');
    assert.match(await page.locator('[data-testid="save-headline"]').textContent(), /nothing is reset/);
    await page.click('button[name="confirm-save"]');
    await page.waitForSelector('[data-testid="save-result"]', { timeout: 10000 });
    assert.equal((await rest(stack.api, 'GET', `/axes/${AXIS}`)).body.config.dynamics.jog_velocity_fast, 150);
    assert.ok((await status(stack.api, AXIS)).power_status, 'still enabled');
    await shot(page, 'configuration-saved');
    await page.click('button[name="disable-axis"]');
    await until(async () => !(await status(stack.api, AXIS)).power_status, { what: 'axis disabled' });
    await page.waitForSelector('button[name="delete"]:not([disabled])');
    await page.waitForSelector('[data-testid="delete-blocked"]', { state: 'detached' });
    await page.click('button[name="delete"]');
    await page.click('button[name="delete-confirm"]');
    await page.waitForURL(/#\/$/, { timeout: 10000 });
    assert.equal((await rest(stack.api, 'GET', `/axes/${AXIS}`)).status, 404);
    await page.waitForSelector('text=No axes yet');
    await page.close();
  });

  test('the UI makes no request to any host but this machine', () => {
    assert.ok(requests.length > 50, `the pages’ requests were seen (${requests.length})`);
    const foreign = requests.filter((u) => {
      const x = new URL(u);
      return !['data:', 'blob:', 'about:'].includes(x.protocol) && !LOOPBACK.has(x.hostname);
    });
    assert.deepEqual(foreign, []);
  });
});
