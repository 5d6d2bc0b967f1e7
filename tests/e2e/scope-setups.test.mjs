// Scope extras in headless Debian Chromium against the real motiond: a saved setup (stored on
// the server) survives a reload, loads into the form and view, records into two stacked charts
// with one time axis; rolling mode appends recordings until Stop; two recordings compared.
// Screenshots go to target/ui-screenshots; with DOCS_SHOTS=1 also to docs/ui/scope-*.png.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, picture, rest, shot, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: true });
const AXIS = 'sc';
const SETUP = 'e2e-stacked';
let desk;
let phone;

async function open(browser, path) {
  const page = await browser.context.newPage();
  page.on('pageerror', (e) => console.error('pageerror:', e.message));
  await page.goto(`${stack.url}/#${path}`);
  await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
  return page;
}

const active = async () => (await rest(stack.api, 'GET', '/scope/recordings')).body.filter((r) => r.state === 'armed' || r.state === 'recording');

before(async () => {
  desk = await launch({ width: 1280, height: 800 });
  phone = await launch({ width: 390, height: 844 });
  const r = await rest(stack.api, 'POST', '/axes', {
    name: AXIS,
    unit: 'mm',
    soft_limits: { min: -1000, max: 1000 },
    dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
  });
  assert.equal(r.status, 201, JSON.stringify(r.body));
  assert.equal((await rest(stack.api, 'POST', `/axes/${AXIS}/power`, {})).status, 202);
  await until(async () => (await status(stack.api, AXIS)).power_status, { what: 'axis enabled' });
});

after(async () => {
  await desk?.close();
  await phone?.close();
  await stack.stop();
});

describe('scope setups, stacked charts, rolling, compare', () => {
  test('save a setup, reload, load it, record into two stacked charts; roll; compare', async () => {
    const page = await open(desk, '/scope');
    await page.waitForSelector('[data-channel="0"]');
    while ((await page.locator('[data-channel]').count()) < 2) await page.click('button[name="add-channel"]');
    while ((await page.locator('[data-channel]').count()) > 2) await page.locator('[data-channel="2"] button[title="remove this channel"]').click();
    await page.selectOption('select[name="channel-0-signal"]', 'set_position');
    await page.selectOption('select[name="channel-1-signal"]', 'set_velocity');
    await page.selectOption('select[name="channel-1-chart"]', '1');
    await page.fill('input[name="duration_s"]', '0.8');

    // a name the server would refuse is refused at the field, in the page
    await page.click('button[name="setup-save-as"]');
    await page.fill('input[name="setup-name"]', '9 bad');
    await page.click('button[name="setup-save"]');
    await page.waitForSelector('[data-field="setup-name"] .field-error');
    await page.fill('input[name="setup-name"]', SETUP);
    await page.click('button[name="setup-save"]');
    await page.waitForSelector(`[data-setup="${SETUP}"]`);
    const saved = (await rest(stack.api, 'GET', `/scope/setups/${SETUP}`)).body;
    assert.deepEqual(saved.recording.channels, [
      { axis: AXIS, signal: 'set_position' },
      { axis: AXIS, signal: 'set_velocity' },
    ]);
    assert.equal(saved.recording.duration_s, 0.8);
    assert.deepEqual(saved.view.charts, [[0], [1]]);

    // a setup naming a missing axis (stored by another client) is refused at the channel
    const bad = await rest(stack.api, 'PUT', '/scope/setups/other', { recording: { channels: [{ axis: 'nope', signal: 'set_position' }], duration_s: 1 } });
    assert.equal(bad.status, 422);
    assert.ok(bad.body.errors.some((e) => e.field === 'recording.channels[0].axis'), JSON.stringify(bad.body));

    // reload: the form starts afresh; loading the setup fills it and the view
    await page.reload();
    await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
    await page.waitForSelector(`[data-setup="${SETUP}"] button[name="setup-load"]`);
    await page.click(`[data-setup="${SETUP}"] button[name="setup-load"]`);
    await until(async () => (await page.locator('[data-channel]').count()) === 2, { what: 'two channels loaded' });
    assert.equal(await page.inputValue('select[name="channel-0-signal"]'), 'set_position');
    assert.equal(await page.inputValue('select[name="channel-1-signal"]'), 'set_velocity');
    assert.equal(await page.inputValue('select[name="channel-0-chart"]'), '0');
    assert.equal(await page.inputValue('select[name="channel-1-chart"]'), '1');
    assert.equal(await page.inputValue('input[name="duration_s"]'), '0.8');
    assert.match(await page.locator('[data-testid="setup-current"]').textContent(), new RegExp(SETUP));

    // run it while the axis moves: two stacked charts, one time axis
    await page.click('button[name="record"]');
    await until(async () => (await active()).length > 0, { what: 'the recording to start' });
    await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute`, { position: 100, velocity: 400 });
    const chart = page.locator('[data-testid="scope-chart"]');
    await page.waitForSelector('[data-testid="scope-chart"][data-charts="2"] canvas', { timeout: 30000 });
    assert.equal(await chart.getAttribute('data-series'), '2');
    assert.equal(await page.locator('[data-testid="scope-chart"] .chart-pane').count(), 2);
    const first = /recording (\S+)/.exec(await page.locator('[data-testid="recording-info"]').textContent())[1];
    // zoom in one chart: both follow
    await page.click('button[name="zoom-in"]');
    await until(async () => {
      const views = await page.$$eval('[data-testid="scope-chart"] .chart-pane', (ps) => ps.map((p) => p.dataset.view));
      return views.length === 2 && views[0] === views[1] && views[0] === (await chart.getAttribute('data-view')) ? views : null;
    }, { what: 'the zoom in both charts' });
    await page.click('button[name="full-view"]');
    await until(async () => (await status(stack.api, AXIS)).in_target_position, { what: 'the move to end' });
    await picture(page, 'scope-stacked');

    // a second recording (moving back), compared with the first: dashed, aligned at the start
    await page.click('button[name="record"]');
    await until(async () => (await active()).length > 0, { what: 'the second recording to start' });
    await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute`, { position: 0, velocity: 400 });
    await until(async () => {
      const t = await page.locator('[data-testid="recording-info"]').textContent().catch(() => '');
      const m = /recording (\S+)/.exec(t ?? '');
      return m && m[1] !== first;
    }, { what: 'the second recording shown', timeout: 30000 });
    await page.selectOption('select[name="compare"]', first);
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="compare"][data-series="4"] canvas', { timeout: 10000 });
    await page.selectOption('select[name="align"]', 'start');
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="compare"][data-series="4"] canvas');
    await shot(page, 'scope-compare');
    await page.selectOption('select[name="compare"]', '');
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="single"] canvas');

    // rolling: recordings of 0.25 s one after another, scrolling, until Stop
    await page.check('input[name="rolling-on"]');
    await page.fill('input[name="rolling.chunk_s"]', '0.25');
    await page.fill('input[name="rolling.window_s"]', '3');
    await page.click('button[name="rolling-start"]');
    const state = page.locator('[data-testid="rolling-state"]');
    await until(async () => Number(await state.getAttribute('data-chunks')) >= 3, { what: 'three rolling recordings', timeout: 30000 });
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="rolling"][data-charts="2"] canvas');
    assert.ok(Number(await chart.getAttribute('data-samples')) > 0, 'the ring has samples');
    const [v0, v1] = (await chart.getAttribute('data-view')).split(',').map(Number);
    assert.ok(Math.abs(v1 - v0 - 3) < 1e-6, `the last 3 s are shown: ${v0} … ${v1}`);
    await shot(page, 'scope-rolling');
    await page.click('button[name="rolling-stop"]');
    await until(async () => (await state.getAttribute('data-active')) === 'false', { what: 'rolling stopped' });
    await until(async () => (await active()).length === 0, { what: 'no recording left running on the server' });
    const chunks = Number(await state.getAttribute('data-chunks'));
    assert.ok(chunks >= 3);
    // what was recorded stays on screen
    assert.ok(Number(await chart.getAttribute('data-samples')) > 0);
    assert.equal(await page.locator('button[name="rolling-start"]').isDisabled(), false);
    await page.close();
  });

  test('a recording is drawn while it records (TwinCAT Scope: live), not "No recording yet"; when done the server’s every-cycle samples replace it', async () => {
    await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute?wait=true`, { position: 0, velocity: 400 });
    const page = await open(desk, '/scope');
    await page.waitForSelector('[data-channel="0"]');
    await page.fill('input[name="duration_s"]', '3');
    if (await page.isChecked('input[name="rolling-on"]')) await page.uncheck('input[name="rolling-on"]');
    if (await page.isChecked('input[name="trigger-on"]')) await page.uncheck('input[name="trigger-on"]');
    await page.click('button[name="record"]');
    const rec = await until(async () => (await active())[0], { what: 'the recording to start' });
    await rest(stack.api, 'POST', `/axes/${AXIS}/move-absolute`, { position: 200, velocity: 200 });
    const chart = page.locator('[data-testid="scope-chart"]');
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="live"] canvas', { timeout: 10000 });
    assert.equal(await page.locator('.chart-empty').count(), 0, 'no "No recording yet" while recording');
    assert.equal(await page.getAttribute('[data-testid="live-info"]', 'data-recording'), String(rec.id));
    // it grows as statuses come in, while the server is still recording
    const p1 = await until(async () => {
      const n = Number(await chart.getAttribute('data-live-points'));
      return n >= 10 ? n : null;
    }, { what: 'ten samples drawn live' });
    await until(async () => Number(await chart.getAttribute('data-live-points')) > p1, { what: 'more samples drawn' });
    const now = (await rest(stack.api, 'GET', `/scope/recordings/${rec.id}`)).body;
    assert.equal(now.state, 'recording', 'drawn before the recording is done');
    await until(async () => (await status(stack.api, AXIS)).in_target_position, { what: 'the move to end' });
    await picture(page, 'scope-live');
    // done: the recording itself, every cycle
    await page.waitForSelector('[data-testid="scope-chart"][data-mode="single"] canvas', { timeout: 30000 });
    const done = (await rest(stack.api, 'GET', `/scope/recordings/${rec.id}`)).body;
    assert.equal(done.state, 'done');
    assert.equal(await chart.getAttribute('data-samples'), String(done.samples));
    assert.match(await page.locator('[data-testid="recording-info"]').textContent(), new RegExp(`recording ${rec.id} `));
    await page.close();
  });

  test('phone: the saved setup loads and the stacked recording reads', async () => {
    const page = await open(phone, '/scope');
    await page.waitForSelector(`[data-setup="${SETUP}"] button[name="setup-load"]`);
    await page.click(`[data-setup="${SETUP}"] button[name="setup-load"]`);
    await until(async () => (await page.inputValue('select[name="channel-1-chart"]')) === '1', { what: 'the setup loaded' });
    const done = (await rest(stack.api, 'GET', '/scope/recordings')).body.find((r) => r.state === 'done' && r.samples === Math.round(0.8 / r.cycle_time_s));
    assert.ok(done, 'a recording of the setup');
    await page.waitForSelector('select[name="recordings"]');
    await page.selectOption('select[name="recordings"]', String(done.id));
    await page.waitForSelector('[data-testid="scope-chart"][data-charts="2"] canvas');
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth - document.documentElement.clientWidth);
    assert.ok(overflow <= 1, `no sideways scrolling (${overflow}px)`);
    await page.locator('.chart-box').scrollIntoViewIfNeeded();
    await picture(page, 'scope-phone');
    await page.close();
  });
});
