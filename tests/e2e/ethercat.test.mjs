// Browser tests of motiond on an emulated EtherCAT segment (`--bus emulated`): the demo axes x,
// y, spindle and feeder have CiA-402 drives on SubDevices 0, 1, 2 and 3 (feeder's drive runs its
// profile: drive-executed.test.mjs). The System page's bus (SubDevices
// in OP with identity and axis, SDO read/abort/write; lost frames fault the bus, which clears by
// itself while x stays stopped until reset; a SubDevice in SAFE-OP asked back by a power-on; a
// stopped TX/RX loop with its reason in the banner, back to OP with Reset bus; late and duplicate
// replies counted while x moves on; the mapping, PDU timeout and TX/RX thread shown), x moved
// through the Online tab on its emulated drive, x's Configuration page with its CiA-402 drive
// (saved unchanged; a taken drive refused at its field), a drive fault's own code; and on the
// default simulated bus, CiA-402 offered disabled with how to start motiond for it.
// Screenshots go to target/ui-screenshots; with DOCS_SHOTS=1 also to docs/ui/system-ethercat*.png.
// Every wait is for a condition; nothing asserts timing.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, openPage, overflowing, picture, readout, rest, shot, startStack, status, until } from './lib.mjs';

// Five lost frames in a row fault the bus (the default is 3): a machine busy with other tests
// can stall the cycle for a few milliseconds, and the faults are this file's to make.
const MAX_ERRORS = 5;
const stack = await startStack({ noDemo: false, args: ['--bus', 'emulated', '--bus-max-errors', String(MAX_ERRORS)] });

let desk;
const pages = [];

/** The bus in OP: a bus fault clears by itself once frames flow (a start on a busy machine may have lost some). */
const busInOp = () => until(async () => (await rest(stack.api, 'GET', '/bus')).body.state === 'op', { what: 'the bus in OP' });

before(async () => {
  desk = await launch({ width: 1600, height: 1000 });
  await busInOp();
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
const num = (s) => Number(String(s).replace(/[^0-9.\-]/g, ''));
const cells = (page, position) =>
  page.locator(`[data-testid="subdevices"] tr[data-subdevice="${position}"]`).evaluate((tr) => Object.fromEntries([...tr.querySelectorAll('[data-col]')].map((td) => [td.dataset.col, td.textContent.trim()])));

/** x enabled at standstill: powered on if it is not. */
async function xEnabled() {
  if (!(await status(stack.api, 'x')).power_status) assert.equal((await rest(stack.api, 'POST', '/axes/x/power', {})).status, 202);
  await until(async () => {
    const s = await status(stack.api, 'x');
    return s.power_status && s.state === 'standstill';
  }, { what: 'x enabled at standstill' });
}

/** Text cut off inside the bus panel: a figure, label, fact or button narrower than its text. */
const clippedText = (page) =>
  page.locator('#bus').evaluate((bus) =>
    [...bus.querySelectorAll('.kpi-label, .kpi-value, .bus-fact, .btn, .mapping-fact, [data-led]')]
      .filter((el) => el.getBoundingClientRect().width > 0 && el.scrollWidth > el.clientWidth + 1)
      .map((el) => `${el.className} "${el.textContent.trim()}" ${el.scrollWidth} > ${el.clientWidth}`),
  );

/** Opens the SDO tool of a SubDevice (once) and reads or writes an object with it. */
async function sdo(page, position, { index, sub, value, size }) {
  const tool = page.locator(`tr[data-sdo-for="${position}"] [data-testid="sdo-tool"]`);
  if (!(await tool.count())) await page.click(`tr[data-subdevice="${position}"] button[name="sdo-open"]`);
  await tool.waitFor();
  await tool.locator('input[name="sdo-index"]').fill(index);
  await tool.locator('input[name="sdo-sub"]').fill(String(sub));
  const answers = Number(await tool.getAttribute('data-answers'));
  if (value === undefined) {
    await tool.locator('button[name="sdo-read"]').click();
  } else {
    await tool.locator('input[name="sdo-value"]').fill(String(value));
    await tool.locator('select[name="sdo-size"]').selectOption(String(size));
    await tool.locator('button[name="sdo-write"]').click();
  }
  // this request's answer (a result, the server's refusal, or its field errors)
  await page.waitForSelector(`tr[data-sdo-for="${position}"] [data-testid="sdo-tool"][data-answers="${answers + 1}"]`);
  return tool;
}

describe('motiond on an emulated EtherCAT segment', () => {
  test('the System page shows the bus in OP and its 4 SubDevices with names, identity and axes, read again every second', async () => {
    const bus = (await rest(stack.api, 'GET', '/bus')).body;
    assert.equal(bus.kind, 'emulated');
    const page = await open('/system');
    await page.waitForSelector('[data-testid="subdevices"] tr[data-subdevice="3"]');
    assert.equal(await text(page, '[data-testid="bus-title"]'), 'EtherCAT (emulated segment)');
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    assert.equal(await text(page, '[data-testid="bus-state"] [data-led]'), 'OP');
    assert.equal(await page.locator('[data-testid="bus-banner"]').count(), 0);
    const rows = [];
    for (const p of [0, 1, 2, 3]) rows.push(await cells(page, p));
    assert.deepEqual(
      rows.map((r) => [r.position, r.name, r.al, r.axis, r.address, r.vendor]),
      [
        ['0', 'motiond emulated servo 1', 'OP', 'x', '0x1000', '0x00FF0ACE'],
        ['1', 'motiond emulated servo 2', 'OP', 'y', '0x1001', '0x00FF0ACE'],
        ['2', 'motiond emulated servo 3', 'OP', 'spindle', '0x1002', '0x00FF0ACE'],
        ['3', 'motiond emulated servo 4', 'OP', 'feeder', '0x1003', '0x00FF0ACE'],
      ],
    );
    assert.equal(rows[0].mapping, `${bus.subdevices[0].drive.mapping} · ${bus.subdevices[0].drive.output_bytes} B out, ${bus.subdevices[0].drive.input_bytes} B in`);
    assert.equal(rows[0].serial, String(bus.subdevices[0].serial));
    assert.equal(await page.getAttribute('tr[data-subdevice="1"] [data-col="axis"] a', 'href'), '#/axes/y');
    // the working counter as expected; the frame count polled
    assert.equal(await text(page, '[data-kpi="working_counter"] .kpi-value'), `${bus.expected_working_counter} / ${bus.expected_working_counter}`);
    // the bus faults since start beside the lost frames and WKC errors
    assert.deepEqual(await page.locator('[data-testid="bus-counters"] .kpi-label').allTextContents(), [
      'Frames',
      'Lost frames',
      'Late replies',
      'Duplicate replies',
      'Malformed frames',
      'Bus faults',
      'WKC errors',
      'WKC last / expected',
      'Errors in a row / max',
      'DC cycle offset',
    ]);
    // the PDU timeout, motiond's TX/RX loop and its thread as the server reports them
    assert.equal(await text(page, '[data-testid="bus-pdu-timeout"] b'), `${Number((bus.pdu_timeout * 1000).toPrecision(4))} ms`);
    assert.equal(await page.getAttribute('[data-testid="bus-txrx"]', 'data-running'), '1');
    assert.equal(await text(page, '[data-testid="bus-txrx"] [data-led]'), 'running');
    assert.equal(await text(page, '[data-testid="bus-txrx-thread"] b'), bus.txrx.thread);
    // the emulated drives take the full mapping: nothing missing, nothing refused, no row under them
    assert.deepEqual(bus.subdevices.map((d) => [d.drive.mapping, d.drive.missing_objects.length, d.drive.refused.length]), [['full', 0, 0], ['full', 0, 0], ['full', 0, 0], ['full', 0, 0]]);
    assert.equal(await page.locator('tr[data-mapping-for]').count(), 0);
    assert.equal(await page.locator('[data-testid="bus-notice"]').count(), bus.notice ? 1 : 0);
    assert.equal(await page.isDisabled('button[name="bus-reset"]'), false);
    const frames = num(await text(page, '[data-kpi="frames"] .kpi-value'));
    assert.ok(frames > 0);
    await until(async () => num(await text(page, '[data-kpi="frames"] .kpi-value')) > frames, { what: 'the bus to be read again' });
    // the demo axes all have CiA-402 drives: no simulated section
    assert.equal(await page.locator('[data-bus="simulated"]').count(), 0);
    // the axis link leads to its page
    await page.click('tr[data-subdevice="1"] [data-col="axis"] a');
    await page.waitForURL(/#\/axes\/y$/);
    await page.waitForSelector('[data-readout="actual_position"]');
    await page.close();
  });

  test('SDO: 0x1018:01 is the vendor 0x00FF0ACE; 0x2000:0 aborts with 0x06020000; a write of 0x6065 is read back', async () => {
    const page = await open('/system');
    await page.waitForSelector('[data-testid="subdevices"] tr[data-subdevice="0"]');
    let tool = await sdo(page, 0, { index: '0x1018', sub: '01' });
    assert.equal(await tool.locator('[data-testid="sdo-result"]').getAttribute('data-kind'), 'read');
    assert.equal(await text(tool, '[data-sdo="address"]'), '0x1018:01');
    assert.equal(await text(tool, '[data-sdo="value"]'), '0x00FF0ACE');
    assert.equal(await text(tool, '[data-sdo="unsigned"]'), '16714446');
    assert.equal(await text(tool, '[data-sdo="bytes"]'), 'ce 0a ff 00');

    tool = await sdo(page, 0, { index: '0x2000', sub: 0 });
    const abort = await text(tool, '[data-testid="sdo-error"]');
    assert.match(abort, /0x06020000/);
    assert.match(abort, /the object does not exist in the object dictionary/);
    assert.equal(await tool.locator('[data-testid="sdo-result"]').count(), 0);

    // the following error window (0x6065, u32): written and read back, then set back
    const before = (await rest(stack.api, 'GET', '/bus/subdevices/0/sdo/0x6065/0')).body.unsigned;
    tool = await sdo(page, 0, { index: '0x6065', sub: 0, value: '20000', size: 4 });
    assert.equal(await tool.locator('[data-testid="sdo-result"]').getAttribute('data-kind'), 'written');
    assert.equal(await text(tool, '[data-sdo="unsigned"]'), '20000');
    assert.equal((await rest(stack.api, 'GET', '/bus/subdevices/0/sdo/0x6065/0')).body.unsigned, 20000);
    // a value too big for its size: the server's 422 at the value field
    tool = await sdo(page, 0, { index: '0x6065', sub: 0, value: '300', size: 1 });
    assert.equal(await tool.locator('[data-testid="sdo-result"]').count(), 0);
    assert.match(await text(page, 'tr[data-sdo-for="0"] [data-field="value"] .field-error'), /does not fit 1 bytes/);
    assert.equal((await rest(stack.api, 'PUT', '/bus/subdevices/0/sdo/0x6065/0', { value: before, size: 4 })).status, 200);

    // closed and opened afresh, the vendor read again, for the picture of the page
    await tool.locator('button[name="sdo-close"]').click();
    await tool.waitFor({ state: 'detached' });
    tool = await sdo(page, 0, { index: '0x1018', sub: 1 });
    assert.equal(await tool.locator('input[name="sdo-value"]').inputValue(), '');
    await page.locator('#bus').evaluate((el) => el.scrollIntoView());
    const o = await overflowing(page);
    assert.ok(o.doc <= 0 && o.main <= 0, JSON.stringify(o));
    assert.deepEqual(o.wide, []);
    assert.deepEqual(await clippedText(page), []);
    await picture(page, 'system-ethercat');
    await page.close();
  });

  test('on a phone (390 × 844) the bus fits the screen: the secondary columns give way', async () => {
    const phone = await launch({ width: 390, height: 844 });
    try {
      const page = await openPage(phone, `${stack.url}/#/system`);
      await page.waitForSelector('[data-testid="subdevices"] tr[data-subdevice="2"]');
      await sdo(page, 0, { index: '0x1018', sub: 1 });
      await page.locator('#bus').evaluate((el) => el.scrollIntoView());
      const o = await overflowing(page);
      assert.ok(o.doc <= 0 && o.main <= 0, JSON.stringify(o));
      assert.deepEqual(o.wide, []);
      // the SubDevice table needs no sideways scrolling of its own
      const t = await page.locator('#bus .table-fit').first().evaluate((el) => el.scrollWidth - el.clientWidth);
      assert.ok(t <= 0, `the SubDevice table scrolls sideways by ${t} px`);
      assert.deepEqual(await clippedText(page), []);
      // name, state and axis stay
      assert.deepEqual(Object.entries(await cells(page, 0)).filter(([k]) => ['name', 'al', 'axis'].includes(k)).map(([, v]) => v), ['motiond emulated servo 1', 'OP', 'x']);
      await picture(page, 'system-ethercat-phone');
    } finally {
      await phone.close();
    }
  });

  test('x powered and moved from its Online tab: the emulated drive follows to the target', async () => {
    const page = await open('/axes/x');
    await page.click('button[name="power-set"]');
    await page.waitForSelector('[data-led="Enabled"][data-on="1"]', { timeout: 10000 });
    await page.click('[data-move="move-absolute"]');
    await page.fill('input[name="position"]', '100');
    await page.fill('input[name="velocity"]', '200');
    await page.click('button[name="start"]');
    await until(async () => Math.abs((await readout(page, 'actual_position')) - 100) < 0.01, { what: 'the x readout to reach 100' });
    await page.waitForSelector('[data-testid="command-log"] tr[data-command="move-absolute"][data-state="done"]');
    // the drive itself is there: its position actual value (0x6064) in increments (1000 per mm)
    const actual = (await rest(stack.api, 'GET', '/bus/subdevices/0/sdo/0x6064/0')).body.signed;
    assert.ok(Math.abs(actual - 100000) <= 10, `0x6064 of SubDevice 0: ${actual}`);
    await page.close();
  });

  test("x's Configuration page shows its CiA-402 drive on SubDevice 0; saving it unchanged resets nothing", async () => {
    const page = await open('/axes/x/config');
    await page.waitForSelector('select[name="drive.subdevice"] option[value="2"]', { state: 'attached' });
    assert.equal(await page.inputValue('select[name="drive.kind"]'), 'cia402');
    assert.equal(await page.inputValue('select[name="drive.subdevice"]'), '0');
    assert.equal(await page.locator('select[name="drive.subdevice"] option:checked').textContent(), '0 · motiond emulated servo 1 — axis x');
    assert.equal(await page.locator('select[name="drive.subdevice"] option[value="1"]').textContent(), '1 · motiond emulated servo 2 — used by y');
    assert.equal(await page.inputValue('input[name="drive.increments_per_unit"]'), '1000');
    assert.equal(await page.inputValue('select[name="drive.mode"]'), 'csp');
    // no simulated drive's fields
    assert.equal(await page.locator('select[name="drive.plant.kind"]').count(), 0);
    const before = (await rest(stack.api, 'GET', '/axes/x')).body.config;
    await page.click('button[name="save"]');
    const panel = page.locator('[data-testid="save-panel"]');
    await panel.waitFor();
    assert.equal(await panel.getAttribute('data-rebuild'), '0');
    assert.equal(await text(page, '[data-testid="save-headline"]'), 'This save changes no parameter; nothing is reset.');
    await page.click('button[name="confirm-save"]');
    const result = page.locator('[data-testid="save-result"]');
    await result.waitFor({ timeout: 10000 });
    assert.match(await result.textContent(), /Saved\. No parameter changed; nothing was reset\./);
    assert.deepEqual((await rest(stack.api, 'GET', '/axes/x')).body.config, before);
    const s = await status(stack.api, 'x');
    assert.ok(s.power_status && Math.abs(s.actual_position - 100) < 0.01, `x still enabled at 100: ${JSON.stringify([s.power_status, s.actual_position])}`);
    await page.close();
  });

  test('a new axis on a drive another axis has: refused by the server at the SubDevice field', async () => {
    const page = await open('/new-axis');
    await page.fill('input[name="name"]', 'z');
    await page.selectOption('select[name="drive.kind"]', 'cia402');
    await page.waitForSelector('select[name="drive.subdevice"] option[value="1"]', { state: 'attached' });
    // every drive is used: none is chosen for the new axis
    assert.equal(await page.inputValue('select[name="drive.subdevice"]'), '');
    await page.selectOption('select[name="drive.subdevice"]', '1');
    await page.click('button[name="save"]');
    const error = page.locator('[data-field="drive.subdevice"] .field-error');
    await error.waitFor({ timeout: 10000 });
    assert.equal((await error.textContent()).trim(), "the drive at position 1 is axis y's");
    assert.equal((await rest(stack.api, 'GET', '/axes/z')).status, 404, 'nothing was created');
    await page.close();
  });

  test("a drive fault: the Online tab shows the drive's own code 0x2310; Reset clears it", async (t) => {
    const page = await open('/axes/x');
    await page.waitForSelector('[data-led="Enabled"][data-on="1"]');
    const f = await rest(stack.api, 'POST', '/axes/x/simulation/fault', { kind: 'drive_fault', code: 8976 });
    assert.ok(f.status < 300, JSON.stringify(f.body));
    const banner = page.locator('[data-testid="axis-error"]');
    await banner.waitFor({ timeout: 10000 });
    assert.match((await banner.textContent()).replace(/\s+/g, ' '), /Axis in error · 0x7010 drive_fault — drive fault — drive code 0x2310/);
    assert.equal(await text(page, '[data-testid="axis-drive-code"]'), 'drive code 0x2310');
    assert.equal(await text(page, '[data-testid="drive-error-code"]'), 'drive error code 0x2310');
    assert.equal(await page.getAttribute('[data-led="Drive fault"]', 'data-on'), '1');
    await shot(page, 'online-drive-code');
    // Reset (MC_Reset): its fault-reset edge reaches the drive in one cycle's frame; on a busy
    // machine the emulated drive can miss that one frame (it takes one setpoint per SYNC0
    // pulse) and fault again, as a real drive would — then Reset is pressed again, as a user
    // would, at most three times.
    let presses = 0;
    let after;
    do {
      presses++;
      const c0 = (await rest(stack.api, 'GET', '/axes/x/status')).body.cycle;
      await banner.locator('button[name="reset-error"]').click();
      // the outcome: enabled at standstill (the drive walked its state machine back to
      // Operation enabled; Disabled on the way), or in ErrorStop again past the reset's grace
      after = await until(async () => {
        const r = (await rest(stack.api, 'GET', '/axes/x/status')).body;
        const s = r.status;
        return r.cycle > c0 + 50 && ((s.state === 'standstill' && s.power_status) || s.state === 'error_stop') && s;
      }, { what: 'x enabled at standstill, or in ErrorStop again, after the reset' });
    } while (after.state === 'error_stop' && presses < 3);
    assert.equal(after.state, 'standstill', `x after ${presses} resets: ${JSON.stringify([after.state, after.error_id, after.drive_error_code])}`);
    assert.equal(after.drive_error_code, 0);
    if (presses > 1) t.diagnostic(`the drive missed ${presses - 1} fault reset(s)`);
    await banner.waitFor({ state: 'detached', timeout: 10000 });
    assert.equal(await page.locator('[data-testid="drive-error-code"]').count(), 0);
    await page.close();
  });

  test('lost frames fault the bus: x stopped with bus_error; the bus back in OP by itself while x stays in ErrorStop until reset', async () => {
    // x enabled (it is since its Online tab powered it)
    await xEnabled();
    const page = await open('/system');
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    const b0 = (await rest(stack.api, 'GET', '/bus')).body;
    assert.equal(b0.state, 'op');
    // each exchange tries a frame 3 times: 30 lost frames are about 10 lost exchanges, > MAX_ERRORS
    const r = await rest(stack.api, 'POST', '/bus/faults', { lose_frames: 30 });
    assert.equal(r.status, 204, JSON.stringify(r.body));
    // the page counts the fault and the lost frames (the faulted state itself lasts a few cycles: not awaited)
    await until(async () => num(await text(page, '[data-kpi="faults"] .kpi-value')) >= b0.faults + 1, { what: 'the bus fault counted' });
    await until(async () => num(await text(page, '[data-kpi="lost_frames"] .kpi-value')) >= b0.lost_frames + 5, { what: 'the lost frames counted' });
    assert.match(await page.getAttribute('[data-kpi="faults"]', 'class'), /kpi-warn/);
    // x was enabled: the bus stopped it with bus_error
    await until(async () => {
      const s = await status(stack.api, 'x');
      return s.state === 'error_stop' && s.error_id === 0x70a0;
    }, { what: 'x in ErrorStop with bus_error' });
    // the bus clears by itself once frames flow; x stays in ErrorStop (the kernel's latch)
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]', { timeout: 10000 });
    assert.equal(await page.locator('[data-testid="bus-banner"]').count(), 0);
    assert.equal(await page.locator('[data-testid="bus-counters"] .kpi-bad').count(), 0);
    const stopped = await status(stack.api, 'x');
    assert.deepEqual([stopped.state, stopped.error_id], ['error_stop', 0x70a0]);
    await page.locator('#bus').evaluate((el) => el.scrollIntoView());
    await shot(page, 'system-ethercat-after-fault');
    // MC_Reset: x back to standstill
    const reset = await rest(stack.api, 'POST', '/axes/x/reset', {});
    assert.equal(reset.status, 202, JSON.stringify(reset.body));
    await until(async () => (await status(stack.api, 'x')).state === 'standstill', { what: 'x at standstill after the reset' });
    await page.close();
  });

  test("a SubDevice in SAFE-OP: the row's LED and the bus degraded; y's power-on asks it back to OP", async (t) => {
    await busInOp();
    assert.equal((await status(stack.api, 'y')).power_status, false, 'y disabled');
    const page = await open('/system');
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    const r = await rest(stack.api, 'POST', '/bus/faults', { safe_op: 1 });
    assert.equal(r.status, 204, JSON.stringify(r.body));
    await page.waitForSelector('[data-testid="bus-state"][data-state="degraded"]', { timeout: 10000 });
    await page.waitForSelector('tr[data-subdevice="1"][data-al="safe_op"]');
    assert.equal(await text(page, 'tr[data-subdevice="1"] [data-col="al"]'), 'SAFE-OP');
    assert.equal(await text(page, 'tr[data-subdevice="0"] [data-col="al"]'), 'OP');
    assert.equal(await page.getAttribute('[data-testid="bus-banner"]', 'data-tone'), 'warn');
    assert.match(await text(page, '[data-testid="bus-banner"]'), /^Bus degraded\. SubDevice 1 \(motiond emulated servo 2, axis y\) in SAFE-OP not in OP/);
    // y's power-on edge asks its SubDevice back to OP
    const power = await rest(stack.api, 'POST', '/axes/y/power', {});
    assert.equal(power.status, 202, JSON.stringify(power.body));
    await page.waitForSelector('tr[data-subdevice="1"][data-al="op"]', { timeout: 10000 });
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]', { timeout: 10000 });
    assert.equal(await page.locator('[data-testid="bus-banner"]').count(), 0);
    // the power-on came while the SubDevice was still in SAFE-OP: y may have been stopped with
    // bus_error on the way — then a reset (the SubDevice in OP now) brings it to standstill
    let y = await until(async () => {
      const s = await status(stack.api, 'y');
      return (s.power_status && s.state === 'standstill') || s.state === 'error_stop' ? s : null;
    }, { what: 'y enabled, or stopped' });
    if (y.state === 'error_stop') {
      assert.equal(y.error_id, 0x70a0, `y stopped with ${y.error_id}`);
      t.diagnostic('y was stopped with bus_error by its power-on into a SubDevice in SAFE-OP: reset');
      assert.equal((await rest(stack.api, 'POST', '/axes/y/reset', {})).status, 202);
      y = await until(async () => {
        const s = await status(stack.api, 'y');
        return s.power_status && s.state === 'standstill' ? s : null;
      }, { what: 'y at standstill after the reset' });
    }
    assert.equal((await rest(stack.api, 'GET', '/bus')).body.subdevices.find((d) => d.position === 1).al_state, 'op');
    // switched off again
    assert.ok((await rest(stack.api, 'DELETE', `/commands/${power.body.id}`)).status < 300);
    await until(async () => !(await status(stack.api, 'y')).power_status, { what: 'y disabled' });
    await page.close();
  });

  test('the TX/RX loop stopped: the bus faulted with its reason in the banner, x stopped; Reset bus brings it back to OP, restarts 1', async () => {
    await busInOp();
    // x enabled at standstill (powered since its Online tab, reset after the lost frames)
    await xEnabled();
    const page = await open('/system');
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    await page.waitForSelector('[data-testid="bus-txrx"][data-running="1"]');
    const b0 = (await rest(stack.api, 'GET', '/bus')).body;
    assert.equal(b0.txrx.restarts, 0);
    assert.equal(await text(page, '[data-testid="bus-txrx-restarts"] b'), '0');
    const r = await rest(stack.api, 'POST', '/bus/faults', { stop_txrx: true });
    assert.equal(r.status, 204, JSON.stringify(r.body));
    // faulted, and the page says why: the server's reason, the loop stopped, what to do
    await page.waitForSelector('[data-testid="bus-state"][data-state="faulted"]', { timeout: 10000 });
    await page.waitForSelector('[data-testid="bus-txrx"][data-running="0"]');
    const b1 = (await rest(stack.api, 'GET', '/bus')).body;
    assert.equal(b1.state, 'faulted');
    assert.ok(b1.fault_reason, 'the server gives a reason');
    const banner = page.locator('[data-testid="bus-banner"]');
    await until(async () => ((await banner.textContent()) ?? '').includes(b1.fault_reason.slice(1)), { what: "the server's fault reason in the banner" });
    assert.equal(await banner.getAttribute('data-tone'), 'error');
    assert.match(await banner.textContent(), /^Bus faulted\. /);
    assert.match(await banner.textContent(), /Reset bus \(or an axis's MC_Reset\) starts the TX\/RX loop again/);
    assert.equal(await text(page, '[data-testid="bus-txrx"] [data-led]'), 'stopped');
    await until(async () => {
      const s = await status(stack.api, 'x');
      return s.state === 'error_stop' && s.error_id === 0x70a0;
    }, { what: 'x in ErrorStop with bus_error' });
    await page.locator('#bus').evaluate((el) => el.scrollIntoView());
    await shot(page, 'system-ethercat-txrx-stopped');
    // Reset bus: disabled while it runs, then the bus it answered: OP, the loop running, 1 restart
    const t0 = Date.now();
    await page.click('button[name="bus-reset"]');
    const result = page.locator('[data-testid="bus-reset-result"]');
    await result.waitFor({ timeout: 15000 });
    const took = Date.now() - t0;
    assert.equal(await result.getAttribute('data-ok'), '1', await result.textContent());
    assert.match(await result.textContent(), /^Bus reset: every SubDevice in OP again\./);
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    await page.waitForSelector('[data-testid="bus-txrx"][data-running="1"]');
    assert.equal(await text(page, '[data-testid="bus-txrx-restarts"] b'), '1');
    assert.equal(await page.locator('[data-testid="bus-banner"]').count(), 0);
    assert.equal(await page.isDisabled('button[name="bus-reset"]'), false);
    const b2 = (await rest(stack.api, 'GET', '/bus')).body;
    assert.deepEqual([b2.state, b2.fault_reason, b2.txrx.running, b2.txrx.restarts], ['op', null, true, 1]);
    console.log(`# reset bus: OP again, answered in ${took} ms (click to result)`);
    // x stays in ErrorStop until its own reset (MC_Reset), then stands still, enabled
    assert.equal((await status(stack.api, 'x')).state, 'error_stop');
    assert.equal((await rest(stack.api, 'POST', '/axes/x/reset', {})).status, 202);
    await xEnabled();
    await page.close();
  });

  test('late and duplicate replies: counted on the page and dropped while x moves on to its target; the bus stays in OP', async () => {
    await busInOp();
    const s0 = await status(stack.api, 'x');
    assert.ok(s0.power_status && s0.state === 'standstill', JSON.stringify([s0.power_status, s0.state]));
    const page = await open('/system');
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    const b0 = (await rest(stack.api, 'GET', '/bus')).body;
    const target = s0.actual_position > 50 ? 0 : 100;
    // a move of about 5 s, the burst while it runs
    const m = await rest(stack.api, 'POST', '/axes/x/move-absolute', { position: target, velocity: 20 });
    assert.equal(m.status, 202, JSON.stringify(m.body));
    await until(async () => (await status(stack.api, 'x')).state === 'discrete_motion', { what: 'x moving' });
    const f = await rest(stack.api, 'POST', '/bus/faults', { late_replies: 20, duplicate_replies: 200 });
    assert.equal(f.status, 204, JSON.stringify(f.body));
    const kpi = async (k) => num(await text(page, `[data-kpi="${k}"] .kpi-value`));
    await until(async () => (await kpi('late_replies')) > b0.late_replies && (await kpi('duplicate_replies')) > b0.duplicate_replies, {
      what: 'the late and duplicate replies counted on the page',
    });
    // x still moving (not stopped by the bus) while they were counted
    const during = await status(stack.api, 'x');
    assert.equal(during.state, 'discrete_motion', JSON.stringify([during.state, during.error_id]));
    assert.match(await page.getAttribute('[data-kpi="late_replies"]', 'class'), /kpi-warn/);
    assert.match(await page.getAttribute('[data-kpi="duplicate_replies"]', 'class'), /kpi-warn/);
    await page.locator('#bus').evaluate((el) => el.scrollIntoView());
    await shot(page, 'system-ethercat-late-replies');
    // x arrives; the bus never faulted and stays in OP
    const done = await until(async () => {
      const s = await status(stack.api, 'x');
      return (s.state === 'error_stop' || (s.state === 'standstill' && Math.abs(s.actual_position - target) < 0.01)) && s;
    }, { timeout: 30000, what: `x at ${target}` });
    assert.equal(done.state, 'standstill', `x: ${JSON.stringify([done.state, done.error_id])}`);
    const b1 = (await rest(stack.api, 'GET', '/bus')).body;
    assert.equal(b1.state, 'op');
    assert.equal(b1.faults, b0.faults, 'the bus did not fault');
    assert.ok(b1.txrx.running);
    assert.ok(b1.late_replies > b0.late_replies && b1.duplicate_replies > b0.duplicate_replies, JSON.stringify(b1));
    await page.waitForSelector('[data-testid="bus-state"][data-state="op"]');
    console.log(`# late ${b1.late_replies - b0.late_replies}, duplicate ${b1.duplicate_replies - b0.duplicate_replies}, lost frames ${b1.lost_frames - b0.lost_frames}, malformed ${b1.malformed_frames - b0.malformed_frames}`);
    await page.close();
  });
});

describe('on the default simulated bus', () => {
  let sim;
  before(async () => {
    sim = await startStack({ noDemo: false });
  });
  after(async () => {
    await sim?.stop();
  });

  test('the Configuration page offers CiA-402 disabled, with how to start motiond for it', async () => {
    const page = await openPage(desk, `${sim.url}/#/axes/x/config`);
    pages.push(page);
    await page.waitForSelector('[data-testid="cia402-unavailable"]');
    assert.equal(await page.inputValue('select[name="drive.kind"]'), 'simulated');
    assert.equal(await page.locator('select[name="drive.kind"] option[value="cia402"]').isDisabled(), true);
    assert.equal(
      await text(page, '[data-testid="cia402-unavailable"]'),
      'CiA-402 is not offered: motiond runs the simulated bus; start motiond with --bus ethercat --interface IFACE, or --bus emulated.',
    );
    // the simulated drive's fields as before
    assert.equal(await page.inputValue('select[name="drive.plant.kind"]'), 'pt2');
    // the server agrees: a CiA-402 drive is refused at drive.kind
    const x = (await rest(sim.api, 'GET', '/axes/x')).body.config;
    const refused = await rest(sim.api, 'POST', '/axes', { ...x, name: 'z', drive: { kind: 'cia402', subdevice: 0, increments_per_unit: 1000 } });
    assert.equal(refused.status, 422, JSON.stringify(refused.body));
    assert.deepEqual(refused.body.errors.map((e) => e.field), ['drive.kind']);
    // the System page: the simulated bus, its axes, no SubDevices
    await page.goto(`${sim.url}/#/system`);
    await page.waitForSelector('[data-bus="simulated"] tr[data-axis]');
    assert.equal(await text(page, '[data-testid="bus-title"]'), 'Simulated bus: 3 axes');
    assert.equal(await page.locator('[data-testid="subdevices"]').count(), 0);
    // no segment to reset: Reset bus disabled, and the server agrees
    assert.equal(await page.isDisabled('button[name="bus-reset"]'), true);
    assert.equal(await page.getAttribute('button[name="bus-reset"]', 'title'), 'motiond runs the simulated bus: there is no EtherCAT segment to reset');
    const refusedReset = await rest(sim.api, 'POST', '/bus/reset', {});
    assert.equal(refusedReset.status, 409, JSON.stringify(refusedReset.body));
    assert.equal(refusedReset.body.code, 'bus_not_ethercat');
  });
});
