// Browser tests of an axis whose drive runs the profile (TwinCAT Drive Motion Control, issue 25)
// on the emulated EtherCAT segment (`--bus emulated`): the demo's feeder (linear mm, 0–500) on
// emulated drive 3 with `profile: "drive"` and `homing_method: 1`. Its axis page says the drive
// executes the profile; the Online tab offers the moves (no jerk, no inching, no override), homes
// in the drive and moves it there; the Coupling tab's blocks are disabled with the reason and
// none reaches the server; the Functions tab's torque, correction and encoder blocks likewise;
// its Configuration page shows profile `drive` and homing method 1, and saves them unchanged.
// Screenshots go to target/ui-screenshots (with DOCS_SHOTS=1 also docs/ui/axis-drive-executed*.png).
// Every wait is for a condition; nothing asserts timing.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { clippedText, launch, openPage, overflowing, picture, readout, rest, startStack, status, until } from './lib.mjs';

const NOT_OFFERED = 'not offered when the drive runs the profile (Drive Motion Control)';
const stack = await startStack({ noDemo: false, args: ['--bus', 'emulated'] });

let desk;
const pages = [];

before(async () => {
  desk = await launch({ width: 1600, height: 1000 });
  await until(async () => (await rest(stack.api, 'GET', '/bus')).body.state === 'op', { what: 'the bus in OP' });
});

after(async () => {
  for (const p of pages) await p.close().catch(() => {});
  await desk?.close();
  await stack.stop();
});

async function open(path, browser = desk) {
  const page = await openPage(browser, `${stack.url}/#${path}`);
  pages.push(page);
  return page;
}

const text = async (page, sel) => ((await page.locator(sel).first().textContent({ timeout: 10000 })) ?? '').trim();
/** The commands of an axis the server knows (newest first). */
const commands = async (axis) => (await rest(stack.api, 'GET', `/commands?axis=${axis}&limit=500`)).body.map((c) => c.command);

describe('feeder: the drive runs its profile', () => {
  test('the demo machine has feeder on emulated drive 3 with the profile in the drive and homing method 1', async () => {
    const c = (await rest(stack.api, 'GET', '/axes/feeder')).body.config;
    assert.deepEqual([c.drive.kind, c.drive.subdevice, c.drive.profile, c.drive.homing_method], ['cia402', 3, 'drive', 1]);
    assert.equal((await status(stack.api, 'feeder')).drive_executed, true);
    assert.equal((await status(stack.api, 'x')).drive_executed, false);
  });

  test('Online tab: the notice beside the state; moves offered without jerk, no inching, no override; homed in the drive and moved there', async () => {
    const page = await open('/axes/feeder');
    const notice = page.locator('[data-testid="drive-executed"]');
    await notice.waitFor();
    assert.equal((await notice.textContent()).trim(), 'the drive executes the profile (Drive Motion Control)');
    // the moves of Drive Motion Control (feeder is linear: no modulo move)
    assert.deepEqual(await page.locator('[data-move]').evaluateAll((b) => b.map((e) => e.dataset.move)), ['move-absolute', 'move-relative', 'move-velocity']);
    assert.equal(await page.isDisabled('input[name="jerk"]'), true);
    assert.equal(await page.isDisabled('input[name="stop-jerk"]'), true);
    assert.equal(await page.locator('button[name="inch-forward"]').count(), 0);
    assert.equal(await text(page, '[data-testid="inching-not-offered"]'), `Inching (one step per click) is ${NOT_OFFERED}: hold a jog button.`);
    assert.equal(await page.isDisabled('input[name="override"]'), true);
    assert.equal(await page.isDisabled('button[name="override-50"]'), true);
    // homing in the drive: default says so, drive-based is offered
    assert.deepEqual(
      await page.locator('select[name="home-mode"] option').evaluateAll((o) => o.map((e) => [e.value, e.textContent.trim(), e.disabled])),
      [
        ['default', 'default: in the drive (method 1)', false],
        ['drive_based', 'in the drive (drive-based)', false],
        ['direct', 'direct: set the position here', false],
        ['force_calibration', 'force calibration: mark as homed', false],
        ['reset_calibration', 'reset calibration: mark as not homed', false],
      ],
    );

    await page.click('button[name="power-set"]');
    await page.waitForSelector('[data-led="Enabled"][data-on="1"]', { timeout: 10000 });
    await page.fill('input[name="home-position"]', '0');
    await page.click('button[name="home-btn"]');
    await page.waitForSelector('[data-led="Homed"][data-on="1"]', { timeout: 20000 });
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="home"][data-state="done"]', { timeout: 20000 });

    await page.click('[data-move="move-absolute"]');
    await page.fill('input[name="position"]', '120');
    await page.fill('input[name="velocity"]', '100');
    await page.click('button[name="start"]');
    await until(async () => Math.abs((await readout(page, 'actual_position')) - 120) < 0.01, { what: 'the feeder readout to reach 120' });
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="move-absolute"][data-state="done"]', { timeout: 20000 });
    // the drive itself ran it: its position actual value (0x6064) in increments (1000 per mm)
    const actual = (await rest(stack.api, 'GET', '/bus/subdevices/3/sdo/0x6064/0')).body.signed;
    assert.ok(Math.abs(actual - 120000) <= 10, `0x6064 of SubDevice 3: ${actual}`);
    // the move went without jerk (0: the drive's profile has none)
    const move = (await rest(stack.api, 'GET', '/commands?axis=feeder&limit=500')).body.find((c) => c.command === 'move-absolute');
    assert.equal(move.parameters.jerk ?? 0, 0);
    assert.equal(move.state, 'done');
    await until(async () => (await status(stack.api, 'feeder')).state === 'standstill', { what: 'feeder at standstill' });
    await picture(page, 'axis-drive-executed');
    assert.deepEqual(await overflowing(page), { doc: 0, main: 0, wide: [] });
    assert.deepEqual(await clippedText(page), []);
    await page.close();
  });

  test('Coupling tab: gear, cam, phasing, superposition disabled with the reason; none reaches the server', async () => {
    const page = await open('/axes/feeder/coupling');
    await page.waitForSelector('[data-testid="coupling-not-offered"]');
    assert.match(await text(page, '[data-testid="coupling-not-offered"]'), new RegExp(`^Gear, cam, multi-master gear, phasing and superposition are ${NOT_OFFERED.replace(/[()]/g, '\\$&')}:`));
    for (const b of ['gear-in', 'gear-out', 'gear-in-dyn', 'cam-in', 'move-superimposed', 'phasing-absolute', 'mm-couple']) {
      assert.equal(await page.isDisabled(`button[name="${b}"]`), true, b);
    }
    assert.equal(await page.isDisabled('input[name="ratio-numerator"]'), true);
    assert.deepEqual(await clippedText(page), []);
    // a click forced onto the disabled button sends nothing either: no request from the page
    // before one it makes afterwards (requests are reported in the order they are made)
    const posted = [];
    page.on('request', (r) => posted.push(`${r.method()} ${new URL(r.url()).pathname}`));
    await page.locator('button[name="gear-in"]').click({ force: true });
    await page.evaluate(() => fetch('/api/v1/system?after-click').then((r) => r.ok));
    assert.ok(posted.includes('GET /api/v1/system'), `the page's requests: ${posted}`);
    assert.deepEqual(posted.filter((r) => r.startsWith('POST')), []);
    // and the server never saw a coupling command of feeder
    const sent = await commands('feeder');
    assert.ok(!sent.some((c) => /gear|cam|phasing|superimposed/.test(c)), `feeder's commands: ${sent}`);
    // a host-side CiA-402 axis has them
    const x = await open('/axes/x/coupling');
    await x.waitForSelector('button[name="gear-in"]');
    assert.equal(await x.isDisabled('button[name="gear-in"]'), false);
    assert.equal(await x.locator('[data-testid="coupling-not-offered"]').count(), 0);
    await x.close();
    await page.close();
  });

  test('Functions tab: torque control, drive mode write, corrections and encoder scaling disabled with the reason; the reversing sequence and homing offered', async () => {
    const page = await open('/axes/feeder/functions');
    await page.waitForSelector('[data-testid="not-offered"]');
    assert.deepEqual(await page.locator('[data-testid="not-offered"]').allTextContents(), [
      `MC_TorqueControl and MC_WriteDriveOperationMode: ${NOT_OFFERED}.`,
      `MC_SetEncoderScalingFactor: ${NOT_OFFERED}.`,
      `The limiter, backlash and table compensation: ${NOT_OFFERED}.`,
    ]);
    for (const b of ['torque-start', 'drive-mode-write', 'encoder-scaling-set', 'limiter-start', 'backlash-start', 'table-start']) assert.equal(await page.isDisabled(`button[name="${b}"]`), true, b);
    for (const b of ['rev-start', 'home-start', 'drive-mode-read']) assert.equal(await page.isDisabled(`button[name="${b}"]`), false, b);
    // homing in the drive: motiond's referencing options are not its inputs
    assert.equal(await page.inputValue('select[name="home-mode"]'), 'default');
    assert.equal(await page.isDisabled('select[name="home-reference-mode"]'), true);
    assert.match(await text(page, '[data-testid="drive-homing"]'), /^Homing in the drive: the drive homes in its homing mode with method 1 · negative limit switch \+ index pulse/);
    assert.equal((await page.locator('select[name="home-mode"] option:checked').textContent()).trim(), 'default: in the drive');
    assert.deepEqual(await clippedText(page), []);
    await page.close();
  });

  test('Configuration page: profile `drive` and homing method 1; saved unchanged', async () => {
    const page = await open('/axes/feeder/config');
    await page.waitForSelector('select[name="drive.subdevice"] option[value="3"]', { state: 'attached' });
    assert.equal(await page.inputValue('select[name="drive.kind"]'), 'cia402');
    assert.equal(await page.inputValue('select[name="drive.subdevice"]'), '3');
    assert.equal(await page.inputValue('select[name="drive.profile"]'), 'drive');
    assert.equal((await page.locator('select[name="drive.profile"] option:checked').textContent()).trim(), 'the drive (Drive Motion Control)');
    assert.equal(await page.inputValue('select[name="drive.homing_method"]'), '1');
    assert.equal((await page.locator('select[name="drive.homing_method"] option:checked').textContent()).trim(), '1 · negative limit switch + index pulse');
    assert.match(await text(page, '[data-field="drive.profile"] .field-hint'), /^the drive runs profile position, velocity and homing/);
    const before = (await rest(stack.api, 'GET', '/axes/feeder')).body.config;
    await page.click('button[name="save"]');
    const panel = page.locator('[data-testid="save-panel"]');
    await panel.waitFor();
    assert.equal(await panel.getAttribute('data-rebuild'), '0');
    await page.click('button[name="confirm-save"]');
    await page.locator('[data-testid="save-result"]').waitFor({ timeout: 10000 });
    assert.deepEqual((await rest(stack.api, 'GET', '/axes/feeder')).body.config, before);
    await picture(page, 'axis-drive-executed-config');
    await page.close();

    // x's drive: motiond runs the profile, with the drive's own homing method
    const x = await open('/axes/x/config');
    await x.waitForSelector('select[name="drive.profile"]');
    assert.equal(await x.inputValue('select[name="drive.profile"]'), 'host');
    assert.equal(await x.inputValue('select[name="drive.homing_method"]'), '');
    await x.close();
  });

  test('on a phone (390 × 844) the notice and the Online tab fit', async () => {
    const phone = await launch({ width: 390, height: 844 });
    try {
      const page = await openPage(phone, `${stack.url}/#/axes/feeder`);
      await page.waitForSelector('[data-testid="drive-executed"]');
      await page.waitForSelector('[data-testid="inching-not-offered"]');
      assert.deepEqual(await overflowing(page), { doc: 0, main: 0, wide: [] });
      assert.deepEqual(await clippedText(page), []);
      await picture(page, 'axis-drive-executed-phone');
    } finally {
      await phone.close();
    }
  });
});
