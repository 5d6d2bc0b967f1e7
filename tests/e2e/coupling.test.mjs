// The axis Coupling and Functions tabs in headless Chromium against the real motiond: y geared
// to x at 1:2 from y's Coupling tab follows x's move (live readout and coupled state naming
// master x), GearOut decouples it; x's reversing sequence from the Functions tab runs its
// cycles and ends with the count.
// Screenshots go to target/ui-screenshots; with DOCS_SHOTS=1 also to docs/ui/coupling*.png
// and docs/ui/functions.png.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { launch, picture, powerOn, readout, rest, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: true });

let desk;
let phone;
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
  dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
});

before(async () => {
  desk = await launch({ width: 1280, height: 800 });
  phone = await launch({ width: 390, height: 844 });
  for (const n of ['x', 'y']) {
    const r = await rest(stack.api, 'POST', '/axes', axis(n));
    assert.equal(r.status, 201, JSON.stringify(r.body));
  }
  await powerOn(stack.api, ['x', 'y']);
});

after(async () => {
  for (const p of opened) await p.close().catch(() => {});
  await desk?.close();
  await phone?.close();
  await stack.stop();
});

describe('coupling and functions tabs', () => {
  test('GearIn 1:2 from y\'s Coupling tab: y follows x to 50, coupled to master x; GearOut decouples', async () => {
    const page = await open(desk, '/axes/y/coupling');
    await page.waitForFunction(() => document.querySelector('select[name="gear-master"]')?.value === 'x');
    // the tab is marked active
    assert.match(await page.locator('a.tab[data-tab="coupling"]').getAttribute('class'), /active/);
    await page.fill('input[name="ratio-numerator"]', '1');
    await page.fill('input[name="ratio-denominator"]', '2');
    await page.click('button[name="gear-in"]');
    await until(async () => (await status(stack.api, 'y')).coupled, { what: 'y coupled' });
    const master = page.locator('[data-testid="coupling-master"] a');
    await master.waitFor();
    assert.equal((await master.textContent()).trim(), 'x');
    assert.equal(await master.getAttribute('href'), '#/axes/x/coupling');
    await page.waitForSelector('[data-led="Coupled"][data-on="1"]');
    await page.waitForSelector('[data-led="InGear"][data-on="1"]');
    assert.equal((await page.locator('[data-testid="coupling-ratio"]').textContent()).trim(), '0.500000');

    const m = await rest(stack.api, 'POST', '/axes/x/move-absolute?wait=true', { position: 100, velocity: 200 });
    assert.ok(m.status < 300, JSON.stringify(m.body));
    assert.equal(m.body.state, 'done', JSON.stringify(m.body));
    await until(async () => Math.abs((await readout(page, 'actual_position')) - 50) < 0.05, { what: "y's live readout near 50" });
    await picture(page, 'coupling');

    const small = await open(phone, '/axes/y/coupling');
    await small.locator('[data-testid="coupling-master"] a').waitFor();
    const fits = await small.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    assert.ok(fits <= 0, `the tab fits the phone (${fits} px too wide)`);
    await picture(small, 'coupling-phone');
    await small.close();

    await page.click('button[name="gear-out"]');
    await until(async () => !(await status(stack.api, 'y')).coupled, { what: 'y decoupled' });
    await page.waitForSelector('[data-led="Coupled"][data-on="0"]');
    assert.equal(await page.locator('[data-testid="coupling-master"] a').count(), 0);
    await page.close();
  });

  test('a refused GearIn shows the server\'s message at its field', async () => {
    const page = await open(desk, '/axes/y/coupling');
    await page.waitForFunction(() => document.querySelector('select[name="gear-master"]')?.value === 'x');
    await page.fill('input[name="ratio-denominator"]', '0');
    await page.click('button[name="gear-in"]');
    const err = page.locator('[data-field="ratio-denominator"] .field-error');
    await err.waitFor();
    assert.ok((await err.textContent()).trim().length > 0);
    assert.equal((await status(stack.api, 'y')).coupled, false);
    await page.close();
  });

  test('y cam-coupled to x: the Coupling tab names the cam coupling, no multi-master table of "Master1 x, ratio 0"', async () => {
    const t = await rest(stack.api, 'POST', '/cam-tables', {
      name: 'kind',
      table_type: 'motion_function',
      periodic: true,
      points: [
        { point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
        { point_index: 2, function_type: 'polynom5', point_type: 'rest', master_pos: 180, slave_pos: 40 },
        { point_index: 3, function_type: 'polynom5', point_type: 'rest', master_pos: 360, slave_pos: 0 },
      ],
    });
    assert.equal(t.status, 201, JSON.stringify(t.body));
    for (const [n, p] of [['x', 0], ['y', 0]]) await rest(stack.api, 'POST', `/axes/${n}/move-absolute?wait=true`, { position: p, velocity: 200 });
    const c = await rest(stack.api, 'POST', '/axes/y/cam-in', { master: 'x', cam_table: 'kind' });
    assert.ok(c.status < 300, JSON.stringify(c.body));
    await until(async () => (await status(stack.api, 'y')).cam?.active, { what: 'y cam-coupled' });
    const y = await status(stack.api, 'y');
    assert.deepEqual(y.gear_ratios, [0, 0, 0, 0], 'what the status says of a cam slave');
    await rest(stack.api, 'POST', '/axes/x/move-absolute?wait=true', { position: 90, velocity: 200 });
    const page = await open(desk, '/axes/y/coupling');
    await page.waitForSelector('[data-testid="coupling-kind"][data-kind="cam"]');
    assert.equal(await page.locator('[data-testid="coupling-kind"]').textContent(), `cam table ${t.body.id} (MC_CamIn)`);
    await page.waitForSelector('[data-testid="mm-in-force"][data-kind="cam"]');
    assert.equal((await page.locator('[data-testid="mm-in-force"]').textContent()).trim(), `Coupled to x by cam table ${t.body.id} (MC_CamIn): not a multi-master gear.`);
    assert.equal(await page.locator('[data-testid="gear-ratios"]').count(), 0, 'no multi-master table');
    assert.equal(await page.locator('[data-testid="coupling-ratio"]').count(), 0, 'no gear ratio for a cam');
    await picture(page, 'coupling-cam');
    await rest(stack.api, 'POST', '/axes/y/cam-out', {});
    await until(async () => !(await status(stack.api, 'y')).coupled, { what: 'y decoupled' });
    await page.waitForSelector('[data-testid="mm-in-force"][data-kind="none"]');
    await rest(stack.api, 'POST', '/axes/y/halt', {});
    await until(async () => (await status(stack.api, 'y')).state === 'standstill', { what: 'y at rest' });
    await page.close();
  });

  test('a blank field shows what the axis uses now (the parameter\'s value, its number in the tooltip), and follows a change', async () => {
    const value = async (axis, n) => (await rest(stack.api, 'GET', `/axes/${axis}/parameters/${n}`)).body.value;
    const page = await open(desk, '/axes/x/functions');
    const search = page.locator('input[name="home-search-velocity"]');
    await until(async () => (await search.getAttribute('placeholder')) === String(await value('x', 1012)), { what: 'the search velocity #1012 as placeholder' });
    assert.match(await search.getAttribute('title'), /#1012 AxisCalibrationVelocityForward, now \d+/);
    assert.equal(await page.getAttribute('input[name="home-sync-velocity"]', 'placeholder'), String(await value('x', 1013)));
    assert.equal(await page.getAttribute('input[name="home-position"]', 'placeholder'), String(await value('x', 1075)));
    assert.equal(await page.getAttribute('input[name="backlash-value"]', 'placeholder'), String(await value('x', 1036)));
    assert.equal((await page.locator('select[name="home-search-direction"] option[value=""]').textContent()).trim(), 'axis: positive');
    // changed online (another client): the placeholder follows
    const was = await value('x', 1012);
    assert.ok((await rest(stack.api, 'PUT', '/axes/x/parameters/1012', { value: 42 })).status < 300);
    await until(async () => (await search.getAttribute('placeholder')) === '42', { what: 'the placeholder to follow #1012' });
    await rest(stack.api, 'PUT', '/axes/x/parameters/1012', { value: was });
    // the Coupling tab's blocks: the axis's acceleration, deceleration and jerk
    await page.click('[data-tab="coupling"]');
    for (const [name, n] of [['phasing-acceleration', 1004], ['phasing-deceleration', 1005], ['phasing-jerk', 1006], ['mm-acceleration', 1004]]) {
      await until(async () => (await page.getAttribute(`input[name="${name}"]`, 'placeholder')) === String(await value('x', n)), { what: `${name}: #${n} as placeholder` });
    }
    await page.close();
  });

  test('x\'s reversing sequence between 10 and 30, 2 repeats, ends with the count 2', async () => {
    const page = await open(desk, '/axes/x/functions');
    await page.fill('input[name="rev-position1"]', '10');
    await page.fill('input[name="rev-position2"]', '30');
    await page.fill('input[name="rev-velocity"]', '100');
    await page.fill('input[name="rev-dwell"]', '0.1');
    await page.fill('input[name="rev-repeats"]', '2');
    await page.click('button[name="rev-start"]');
    await page.waitForSelector('[data-testid="reversing-status"][data-state="running"]');
    await page.waitForSelector('[data-testid="reversing-status"][data-state="finished"]', { timeout: 30000 });
    assert.equal((await page.locator('[data-testid="reversing-count"]').textContent()).trim(), '2');
    const s = await status(stack.api, 'x');
    assert.ok(Math.abs(s.actual_position - 30) < 0.05, `x ends at position 2: ${s.actual_position}`);
    // four waited moves were made: 10, 30, 10, 30
    const cmds = (await rest(stack.api, 'GET', '/commands?axis=x&limit=50')).body.filter((c) => c.command === 'move-absolute');
    assert.deepEqual(cmds.map((c) => c.parameters.position).reverse().slice(-4), [10, 30, 10, 30]);
    await page.waitForFunction(() => document.querySelector('[data-testid="homing-phase"]')?.textContent === 'idle');
    await picture(page, 'functions');
    await page.close();
  });
});
