// The single-axis blocks of the Coupling and Functions tabs in headless Chromium against the real
// motiond: y geared to x from the Gear panel, a phasing absolute of 5 from the Phasing panel shown
// as y's absolute phase shift; a multi-master coupling made, its ratios changed and released;
// torque control on y shown as the drive's torque mode and back to position control;
// AxisEnablePosCorrection set and a limiter of 0.5 shown as the limiter's correction; the encoder
// conversions. Mistakes in a form are named at their fields and nothing is sent.
// Screenshots go to target/ui-screenshots; with DOCS_SHOTS=1 also to docs/ui/coupling-phasing.png
// and docs/ui/functions-torque.png.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, overflowing, picture, powerOn, readout, rest, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: true });

let desk;
const opened = [];

async function open(ctx, path) {
  const page = await ctx.context.newPage();
  page.on('pageerror', (e) => console.error('pageerror:', e.message));
  opened.push(page);
  await page.goto(`${stack.url}/#${path}`);
  await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
  return page;
}

const axis = (name) => ({
  name,
  unit: 'mm',
  soft_limits: { min: -100000, max: 100000 },
  dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
});

/** The text of a live readout of the page. */
const readoutText = async (page, name) => (await page.locator(`[data-readout="${name}"] .dro-value`).first().textContent()).trim();

/** y's commands of one name, newest first. */
const commands = async (name) => (await rest(stack.api, 'GET', '/commands?axis=y&limit=100')).body.filter((c) => c.command === name);

before(async () => {
  desk = await launch({ width: 1280, height: 800 });
  for (const n of ['x', 'y']) {
    const r = await rest(stack.api, 'POST', '/axes', axis(n));
    assert.equal(r.status, 201, JSON.stringify(r.body));
  }
  await powerOn(stack.api, ['x', 'y']);
});

after(async () => {
  for (const p of opened) await p.close().catch(() => {});
  await desk?.close();
  await stack.stop();
});

describe('single-axis blocks', () => {
  test('y geared to x, a phasing absolute of 5 from the Phasing panel: absolute phase shift 5 shown', async () => {
    const page = await open(desk, '/axes/y/coupling');
    await page.waitForFunction(() => document.querySelector('select[name="gear-master"]')?.value === 'x');
    await page.click('button[name="gear-in"]');
    await until(async () => (await status(stack.api, 'y')).coupled, { what: 'y coupled' });
    // the phasing master follows the coupling's master
    await page.waitForFunction(() => document.querySelector('select[name="phasing-master"]')?.value === 'x');

    // a velocity under 0.01 is named at its field and nothing is sent
    await page.fill('input[name="phasing-shift"]', '5');
    await page.fill('input[name="phasing-velocity"]', '0.001');
    await page.click('button[name="phasing-absolute"]');
    const velErr = page.locator('[data-field="phasing-velocity"] .field-error');
    await velErr.waitFor();
    assert.match(await velErr.textContent(), /0\.01/);
    assert.equal((await commands('phasing-absolute')).length, 0, 'nothing sent');

    await page.fill('input[name="phasing-velocity"]', '20');
    await page.click('button[name="phasing-absolute"]');
    await until(async () => Math.abs((await readout(page, 'absolute_phase_shift')) - 5) < 1e-6, { what: 'absolute phase shift 5 shown' });
    assert.equal(await readoutText(page, 'absolute_phase_shift'), '5.0000');
    assert.equal(await page.locator('[data-field="phasing-velocity"] .field-error').count(), 0);
    const s = await status(stack.api, 'y');
    assert.equal(s.absolute_phase_shift, 5);
    assert.equal(s.phasing_active, false);
    assert.equal((await commands('phasing-absolute'))[0].state, 'done');
    await page.waitForSelector('[data-led="Phasing"][data-on="0"]');
    await picture(page, 'coupling-phasing');

    // a relative phasing of -2 from there: 3
    await page.fill('input[name="phasing-shift"]', '-2');
    await page.click('button[name="phasing-relative"]');
    await until(async () => Math.abs((await readout(page, 'absolute_phase_shift')) - 3) < 1e-6, { what: 'absolute phase shift 3 shown' });

    await page.click('button[name="gear-out"]');
    await until(async () => !(await status(stack.api, 'y')).coupled, { what: 'y decoupled' });
    await until(async () => (await status(stack.api, 'y')).state === 'standstill', { what: 'y at rest' });
    await page.close();
  });

  test('multi-master gear: coupled to x at 2, the ratio changed to 3, released', async () => {
    const page = await open(desk, '/axes/y/coupling');
    await page.waitForFunction(() => [...(document.querySelector('select[name="mm-master1"]')?.options ?? [])].some((o) => o.value === 'x'));
    await page.selectOption('select[name="mm-master1"]', 'x');
    await page.fill('input[name="mm-ratio1"]', '2');
    await page.click('button[name="mm-couple"]');
    await until(async () => (await status(stack.api, 'y')).coupled, { what: 'y coupled by gear-in-multi-master' });
    await page.waitForSelector('[data-gear-ratio="1"] td.mono:text("2.0000")');
    await page.waitForSelector('button[name="mm-release"]:not([disabled])');
    assert.equal(await page.locator('select[name="mm-master1"]').isDisabled(), true, 'the masters stay while enabled');
    const first = (await commands('gear-in-multi-master'))[0];
    assert.equal(first.final, false);

    await page.fill('input[name="mm-ratio1"]', '3');
    await page.click('button[name="mm-change"]');
    await until(async () => (await status(stack.api, 'y')).gear_ratios[0] === 3, { what: 'ratio 3 in force' });
    await page.waitForSelector('[data-gear-ratio="1"] td.mono:text("3.0000")');
    const second = (await commands('gear-in-multi-master'))[0];
    assert.notEqual(second.id, first.id);
    assert.deepEqual(second.parameters.masters, [{ master: 'x', gear_ratio: 3 }]);
    await page.waitForSelector(`button[name="mm-release"]:has-text("#${second.id}")`);

    await page.click('button[name="mm-release"]');
    await until(async () => (await rest(stack.api, 'GET', `/commands/${second.id}`)).body.final, { what: 'the multi-master command released' });
    await page.waitForSelector('button[name="mm-couple"]:not([disabled])');
    assert.equal((await status(stack.api, 'y')).coupled, true, 'released: still coupled, ratios frozen');
    await rest(stack.api, 'POST', '/axes/y/gear-out', {});
    await until(async () => (await status(stack.api, 'y')).state === 'standstill', { what: 'y decoupled at rest' });
    await page.close();
  });

  test('torque control on y: the drive in torque mode, then back to position control', async () => {
    const page = await open(desk, '/axes/y/functions');
    await page.waitForSelector('[data-testid="drive-mode-read"] b');
    assert.equal(await readoutText(page, 'drive_operation_mode'), 'position');
    // a ramp of 0 is named at its field and nothing is sent
    await page.fill('input[name="torque-torque"]', '5');
    await page.fill('input[name="torque-ramp"]', '0');
    await page.click('button[name="torque-start"]');
    await page.locator('[data-field="torque-ramp"] .field-error').waitFor();
    assert.equal((await commands('torque-control')).length, 0, 'nothing sent');
    // a limit beyond AxisVeloMax: the server's refusal at its field
    await page.fill('input[name="torque-ramp"]', '100');
    await page.fill('input[name="torque-limit-high"]', '5000');
    await page.click('button[name="torque-start"]');
    const highErr = page.locator('[data-field="torque-limit-high"] .field-error');
    await highErr.waitFor();
    assert.ok((await highErr.textContent()).trim().length > 0);

    await page.fill('input[name="torque-limit-high"]', '50');
    await page.fill('input[name="torque-limit-low"]', '-50');
    await page.click('button[name="torque-start"]');
    await until(async () => (await readoutText(page, 'drive_operation_mode')) === 'torque', { what: 'drive operation mode torque shown' });
    await page.waitForSelector('[data-led="Torque mode"][data-on="1"]');
    await page.waitForSelector('[data-led="Loop closed"][data-on="0"]');
    await until(async () => (await readout(page, 'set_torque')) === 5, { what: 'set torque 5 % shown' });
    await page.click('button[name="drive-mode-read"]');
    await page.waitForSelector('[data-testid="drive-mode-read"] b:text("torque")');
    await picture(page, 'functions-torque');

    await page.click('button[name="torque-halt"]');
    await until(async () => (await readoutText(page, 'drive_operation_mode')) === 'position', { what: 'drive operation mode position shown' });
    await page.waitForSelector('[data-led="Loop closed"][data-on="1"]');
    await until(async () => (await status(stack.api, 'y')).state === 'standstill', { what: 'y at rest' });

    // MC_WriteDriveOperationMode: velocity and back
    await page.selectOption('select[name="drive-mode"]', 'velocity');
    await page.click('button[name="drive-mode-write"]');
    await until(async () => (await readoutText(page, 'drive_operation_mode')) === 'velocity', { what: 'velocity mode shown' });
    await page.waitForSelector('[data-testid="drive-mode-read"] b:text("velocity")');
    await page.selectOption('select[name="drive-mode"]', 'position');
    await page.click('button[name="drive-mode-write"]');
    await until(async () => (await readoutText(page, 'drive_operation_mode')) === 'position', { what: 'position mode shown again' });
    await page.close();
  });

  test('position correction: #1046 set, a limiter of 0.5 shown, released; the encoder conversions', async () => {
    const page = await open(desk, '/axes/y/functions');
    await page.waitForSelector('[data-testid="pos-correction-enabled"]:text("off")');
    // a blank correction is named at its field and nothing is sent
    await page.click('button[name="limiter-start"]');
    await page.locator('[data-field="limiter-value"] .field-error').waitFor();
    assert.equal((await commands('position-correction-limiter')).length, 0, 'nothing sent');

    await page.click('button[name="enable-pos-correction"]');
    await page.waitForSelector('[data-testid="pos-correction-enabled"]:text("on")');
    assert.equal((await rest(stack.api, 'GET', '/axes/y/parameters/AxisEnablePosCorrection')).body.value, true);
    await page.fill('input[name="limiter-value"]', '0.5');
    assert.equal(await page.locator('select[name="limiter-mode"]').inputValue(), 'unlimited');
    await page.click('button[name="limiter-start"]');
    await until(async () => (await page.locator('[data-correction="limiter"] [data-value]').textContent()).trim() === '0.5000', { what: 'limiter 0.5 shown' });
    await page.waitForSelector('[data-correction="limiter"] [data-led="yes"]');
    assert.equal((await page.locator('[data-correction="total"] [data-value]').textContent()).trim(), '0.5000');
    assert.equal((await status(stack.api, 'y')).position_correction.limiter, 0.5);

    await page.click('button[name="limiter-release"]');
    await until(async () => !(await status(stack.api, 'y')).position_correction.limiter_enabled, { what: 'limiter released' });
    await page.waitForSelector('[data-correction="limiter"] [data-led="no"]');
    // released: the correction stays where it is
    assert.equal((await page.locator('[data-correction="limiter"] [data-value]').textContent()).trim(), '0.5000');

    // the encoder: count → position and back
    const count = Number(await readoutText(page, 'encoder_count'));
    assert.ok(Number.isInteger(count));
    await page.fill('input[name="convert-inc-pos"]', '1.5');
    await page.click('button[name="convert-inc"]');
    await page.locator('[data-field="convert-inc-pos"] .field-error').waitFor();
    await page.fill('input[name="convert-inc-pos"]', '100');
    await page.click('button[name="convert-inc"]');
    await page.waitForSelector('[data-testid="convert-to-pos"]:text("mm")');
    assert.equal(await page.locator('[data-field="convert-inc-pos"] .field-error').count(), 0);
    await page.fill('input[name="convert-position"]', '12');
    await page.click('button[name="convert-pos"]');
    await page.waitForSelector('[data-testid="convert-to-inc"]:text("inc")');
    await page.close();
  });

  test('both tabs fit a phone (390 px): nothing beyond the right edge', async () => {
    const phone = await launch({ width: 390, height: 844 });
    try {
      for (const [tab, ready] of [
        ['coupling', '[data-readout="absolute_phase_shift"]'],
        ['functions', '[data-testid="position-correction"]'],
      ]) {
        const page = await open(phone, `/axes/y/${tab}`);
        await page.waitForSelector(ready);
        const o = await overflowing(page);
        assert.ok(o.doc <= 0 && o.main <= 0, `${tab} scrolls sideways: ${JSON.stringify(o)}`);
        assert.deepEqual(o.wide, [], `${tab}: elements beyond the right edge`);
        await page.close();
      }
    } finally {
      await phone.close();
    }
  });
});
