// The cam editor in headless Chromium against the real motiond (demo machine: axes x and y):
// live plots of the table as edited (the server's POST /cam-analysis) with its jumps and its
// errors at their rows before anything is saved; a point dragged on the position plot, undone
// and redone; the test — a cam edited and saved in the browser, y coupled to x through
// it on y's Coupling tab, x moved and y's live readout following as the cam says; an online
// change of the coupled table by the mode set in the editor; screenshots at 1600×1000 and
// 390×844 with nothing wider than the window.
// Screenshots go to target/ui-screenshots (E2E_SHOTS_DIR); with DOCS_SHOTS=1 also to
// docs/ui/cam-editor*.png.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { launch, openPage, overflowing, picture, powerOn, readout, rest, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: false });

let desk;
let phone;
const opened = [];

async function open(ctx, path) {
  const page = await openPage(ctx, `${stack.url}/#${path}`);
  opened.push(page);
  return page;
}

const point = (i, x, y, law = 'polynom5', type = 'rest') => ({ point_index: i, function_type: law, point_type: type, master_pos: x, slave_pos: y });

/** A table made over the API for a test (replaced if a test before left one under the name). */
async function table(name, points, periodic = false) {
  const old = await rest(stack.api, 'GET', `/cam-tables/${name}`);
  if (old.status === 200) assert.equal((await rest(stack.api, 'DELETE', `/cam-tables/${old.body.id}`, {})).status, 204);
  const r = await rest(stack.api, 'POST', '/cam-tables', { name, table_type: 'motion_function', periodic, points });
  assert.equal(r.status, 201, JSON.stringify(r.body));
  return r.body;
}

/** The table's value at a master position, from the server (the one source of the cam math). */
async function camAt(name, master) {
  const r = await rest(stack.api, 'GET', `/cam-tables/${name}/values?start=${master}&end=${master}&increment=1`);
  assert.equal(r.status, 200, JSON.stringify(r.body));
  return r.body.rows[0][1];
}

async function moveX(position) {
  const m = await rest(stack.api, 'POST', '/axes/x/move-absolute?wait=true', { position, velocity: 200 });
  assert.ok(m.status < 300, JSON.stringify(m.body));
  assert.equal(m.body.state, 'done', JSON.stringify(m.body));
}

const text = async (page, sel) => ((await page.locator(sel).first().textContent()) ?? '').trim();
const value = (page, name) => page.locator(`input[name="${name}"]`).inputValue();
/** Waits until input `name` shows `want` (a string, or a test of its text). */
const valueIs = (page, name, want) =>
  until(async () => {
    const v = await value(page, name);
    return (typeof want === 'function' ? want(v) : v === want) && v;
  }, { what: `${name} = ${want}`, timeout: 5000 });

before(async () => {
  desk = await launch({ width: 1600, height: 1000 });
  phone = await launch({ width: 390, height: 844 });
  const axes = (await rest(stack.api, 'GET', '/axes')).body.map((a) => a.config.name);
  for (const n of ['x', 'y']) assert.ok(axes.includes(n), `the demo machine has ${n}: ${axes}`);
  await powerOn(stack.api, ['x', 'y']);
});

after(async () => {
  for (const p of opened) await p.close().catch(() => {});
  await desk?.close();
  await phone?.close();
  await stack.stop();
});

describe('cam editor', () => {
  test('live plots follow an unsaved edit; a jump is warned at its point; an invalid edit is shown at its row before save', async () => {
    // rest – motion – motion – rest, Polynom 5 throughout: no jumps
    await table('live', [point(1, 0, 0), point(2, 100, 50, 'polynom5', 'motion'), point(3, 200, 100, 'polynom5', 'motion'), point(4, 360, 0)]);
    const page = await open(desk, '/cams/live');
    await page.waitForSelector('#cam[data-version="1"] [data-analysis="current"]');
    assert.equal(await text(page, '[data-charac="slave_pos_max"]'), '100');
    assert.equal(await page.getAttribute('[data-chart="cam"]', 'data-series'), 'position,velocity,acceleration,jerk');
    await page.waitForSelector('[data-testid="cam-no-warnings"]');

    // An unsaved edit: the server analyses it, the values follow, nothing is stored.
    await page.fill('input[name="slave_pos-3"]', '130');
    await until(async () => (await text(page, '[data-charac="slave_pos_max"]')) === '130', { what: 'slave_pos_max of the edit' });
    await page.waitForSelector('#cam[data-dirty="1"] [data-analysis="current"]');
    assert.equal(await text(page, '[data-testid="cam-live"]'), 'the table as edited (not saved)');
    assert.equal(await page.getAttribute('[data-handle="2"]', 'data-slave'), '130');
    const stored = (await rest(stack.api, 'GET', '/cam-tables/live')).body;
    assert.equal(stored.version, 1);
    assert.equal(stored.points[2].slave_pos, 100, 'nothing stored');

    // POLYNOM1 from the MOTION point 2: the velocity jumps there (and again at point 3).
    await page.selectOption('select[name="function_type-2"]', 'polynom1');
    await page.waitForSelector('tr[data-point="2"].has-warning[data-warning="velocity"]');
    const warning = await text(page, '[data-testid="cam-warnings"] [data-warning-index="1"][data-quantity="velocity"]');
    assert.match(warning, /^velocity jumps from 0 to [0-9.]+ at point 2, master 100$/);
    // the value after the jump is the server's
    const server = await rest(stack.api, 'POST', '/cam-analysis?samples=2', {
      name: 'probe',
      table_type: 'motion_function',
      points: [point(1, 0, 0), point(2, 100, 50, 'polynom1', 'motion'), point(3, 200, 130, 'polynom5', 'motion'), point(4, 360, 0)],
    });
    assert.equal(server.status, 200, JSON.stringify(server.body));
    const jump = server.body.discontinuities.find((d) => d.index === 1 && d.quantity === 'velocity');
    assert.ok(jump, JSON.stringify(server.body.discontinuities));
    assert.equal(warning, `velocity jumps from 0 to ${Number(jump.after.toPrecision(4))} at point 2, master 100`);
    assert.equal(await page.locator('[data-handle="1"].warn').count(), 1, 'the handle of point 2 is marked too');
    assert.equal(await text(page, '[data-testid="cam-jumps"]'), '⚠ 2 jumps (see Warnings)', 'and said above the plot');
    // fixed: Polynom 5 again, the warning goes
    await page.selectOption('select[name="function_type-2"]', 'polynom5');
    await page.waitForSelector('[data-testid="cam-no-warnings"]');
    assert.equal(await page.locator('tr.has-warning').count(), 0);
    assert.equal(await page.locator('[data-testid="cam-jumps"]').count(), 0);

    // An invalid edit (point 3's master behind point 2's): the server's error at the row, before save.
    await page.fill('input[name="master_pos-3"]', '50');
    await page.waitForSelector('tr[data-point="3"].has-error');
    assert.match(await text(page, 'tr[data-point="3"] .field-error'), /^master_pos: master positions must rise strictly/);
    await page.waitForSelector('[data-analysis="invalid"]');
    assert.match(await text(page, '[data-testid="cam-stale-note"]'), /invalid .* the last valid state/);
    // the values shown are the last valid state's, said so
    assert.equal(await text(page, '[data-charac="slave_pos_max"]'), '130');
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/live')).body.version, 1, 'nothing stored');
    // undone: valid again
    await page.locator('input[name="master_pos-3"]').press('Control+z');
    await valueIs(page, 'master_pos-3', '200');
    await page.waitForSelector('[data-analysis="current"]');
    assert.equal(await page.locator('tr.has-error').count(), 0);
    await page.close();
  });

  test('drag a point on the position plot: its row follows, one undo restores it, redo re-applies it', async () => {
    await table('drag', [point(1, 0, 0), point(2, 100, 50, 'polynom5', 'motion'), point(3, 200, 100, 'polynom5', 'motion'), point(4, 360, 0)]);
    const page = await open(desk, '/cams/drag');
    await page.waitForSelector('[data-analysis="current"]');
    const velo = await text(page, '[data-charac="slave_velo_max"]');
    const handle = page.locator('[data-handle="1"]');
    const box = await handle.boundingBox();
    assert.ok(box, 'the handle of point 2 is on the plot');
    // drag: up and to the right in ten moves
    const [x0, y0] = [box.x + box.width / 2, box.y + box.height / 2];
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let k = 1; k <= 10; k++) await page.mouse.move(x0 + 4 * k, y0 - 3 * k);
    await page.mouse.up();
    await valueIs(page, 'master_pos-2', (v) => v !== '100');
    const [m, s] = [Number(await value(page, 'master_pos-2')), Number(await value(page, 'slave_pos-2'))];
    assert.ok(m > 100 && m < 200, `master moved right, between its neighbours: ${m}`);
    assert.ok(s > 50, `slave moved up: ${s}`);
    assert.equal(Number(await handle.getAttribute('data-master')), m);
    assert.equal(Number(await handle.getAttribute('data-slave')), s);
    // re-analysed: the values are the dragged table's
    await until(async () => (await text(page, '[data-charac="slave_velo_max"]')) !== velo, { what: 'the analysis of the dragged table' });
    await page.waitForSelector('#cam[data-dirty="1"] [data-analysis="current"]');

    // one drag is one undo step
    await page.click('button[name="undo"]');
    await valueIs(page, 'master_pos-2', '100');
    assert.equal(await value(page, 'slave_pos-2'), '50');
    await until(async () => (await text(page, '[data-charac="slave_velo_max"]')) === velo, { what: 'the analysis of the undone table' });
    assert.equal(await page.locator('button[name="undo"]').isDisabled(), true, 'the drag was the only step');
    await page.keyboard.press('Control+Shift+Z');
    await valueIs(page, 'master_pos-2', String(m));
    assert.equal(Number(await value(page, 'slave_pos-2')), s);
    await page.keyboard.press('Control+z');
    await valueIs(page, 'master_pos-2', '100');
    await page.keyboard.press('Control+y');
    await valueIs(page, 'master_pos-2', String(m));

    // the master stays strictly between its neighbours' (point 3 at 200): dragged far right
    // The plot draws the redone point a frame or two after the row: wait until the handle
    // stands still, or the drag could start where the point was (and move nothing).
    let b2 = null;
    await until(async () => {
      const before = await handle.boundingBox();
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      b2 = await handle.boundingBox();
      return before && b2 && before.x === b2.x && before.y === b2.y;
    }, { what: 'the handle drawn where the redone point is' });
    const over = await page.locator('[data-pane="position"] .u-over').boundingBox();
    await page.mouse.move(b2.x + b2.width / 2, b2.y + b2.height / 2);
    await page.mouse.down();
    await page.mouse.move(over.x + over.width - 1, b2.y + b2.height / 2, { steps: 5 });
    await page.mouse.up();
    const clamped = Number(await valueIs(page, 'master_pos-2', (v) => Number(v) > m));
    assert.ok(clamped < 200 && clamped >= 199, `clamped before point 3's master 200: ${clamped}`);
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/drag')).body.version, 1, 'nothing stored');
    await page.close();
  });

  test('a position table: made on the list page, CSV pasted (a bad row named before save), a file imported, exported, saved', async () => {
    const old = await rest(stack.api, 'GET', '/cam-tables/rows');
    if (old.status === 200) await rest(stack.api, 'DELETE', `/cam-tables/${old.body.id}`, {});
    const page = await open(desk, '/cams');
    await page.fill('input[name="cam-name"]', 'rows');
    await page.selectOption('select[name="cam-type"]', 'non_equidistant');
    await page.click('button[name="create-cam"]');
    await page.waitForURL(/#\/cams\/rows$/);
    await page.waitForSelector('#cam[data-version="1"] [data-analysis="current"]');
    assert.equal(await page.locator('[data-handle]').count(), 5, 'its rows are handles on the plot');
    // pasted: row 3 behind row 2 — the server's message at that row, nothing stored
    await page.fill('textarea[name="rows-csv"]', 'master,slave\n0,0\n90,50\n80,100\n360,0\n');
    await page.waitForSelector('[data-analysis="invalid"]');
    assert.match(await text(page, '[data-testid="cam-row-errors"] li[data-row="2"]'), /^row 3: master: master positions must rise strictly/);
    // a CSV file imported (semicolons, no header): the plot follows
    await page.setInputFiles('input[name="csv-file"]', { name: 'lift.csv', mimeType: 'text/csv', buffer: Buffer.from('0;0\n100;20\n200;60\n360;0\n') });
    await page.waitForSelector('[data-analysis="current"]');
    await until(async () => (await text(page, '[data-charac="slave_pos_max"]')) !== '100', { what: 'the imported rows analysed' });
    assert.equal(await page.locator('[data-handle]').count(), 4);
    assert.equal(await page.locator('[data-testid="cam-row-errors"]').count(), 0);
    // exported as the server will read it
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('button[name="export-csv"]')]);
    assert.equal(download.suggestedFilename(), 'rows.csv');
    assert.equal(readFileSync(await download.path(), 'utf8'), 'master,slave\n0,0\n100,20\n200,60\n360,0\n');
    await page.click('button[name="save-cam"]');
    await page.waitForSelector('#cam[data-version="2"][data-dirty="0"]');
    assert.deepEqual((await rest(stack.api, 'GET', '/cam-tables/rows')).body.rows, [[0, 0], [100, 20], [200, 60], [360, 0]]);
    await page.close();
  });

  test('the issue’s test: a cam edited and saved in the browser, y coupled to x through it on y’s Coupling tab; x moves, y’s live readout follows the cam', async () => {
    for (const n of ['x', 'y']) {
      const s = await status(stack.api, n);
      if (s.coupled) await rest(stack.api, 'POST', `/axes/${n}/cam-out`, {});
    }
    await moveX(0);
    const ym = await rest(stack.api, 'POST', '/axes/y/move-absolute?wait=true', { position: 0, velocity: 200 });
    assert.equal(ym.body.state, 'done', JSON.stringify(ym.body));
    const old = await rest(stack.api, 'GET', '/cam-tables/follow');
    if (old.status === 200) await rest(stack.api, 'DELETE', `/cam-tables/${old.body.id}`, {});

    // create and edit the cam in the browser
    const page = await open(desk, '/cams');
    await page.fill('input[name="cam-name"]', 'follow');
    await page.click('button[name="create-cam"]');
    await page.waitForURL(/#\/cams\/follow$/);
    await page.waitForSelector('#cam[data-version="1"] [data-analysis="current"]');
    assert.equal(await value(page, 'slave_pos-2'), '100');
    await page.fill('input[name="slave_pos-2"]', '80');
    await until(async () => (await text(page, '[data-charac="slave_pos_max"]')) === '80', { what: 'the live analysis of the edit' });
    await page.click('button[name="save-cam"]');
    await page.waitForSelector('#cam[data-version="2"][data-dirty="0"]');
    const saved = (await rest(stack.api, 'GET', '/cam-tables/follow')).body;
    assert.equal(saved.version, 2);
    assert.deepEqual(saved.points.map((p) => [p.master_pos, p.slave_pos]), [[0, 0], [180, 80], [360, 0]]);

    // couple y to x through it on y's Coupling tab
    await page.goto(`${stack.url}/#/axes/y/coupling`);
    await page.waitForFunction(() => document.querySelector('select[name="cam-master"]')?.value === 'x');
    await page.waitForSelector('select[name="cam-table"] option[value="follow"]', { state: 'attached' });
    await page.selectOption('select[name="cam-table"]', 'follow');
    await page.selectOption('select[name="cam-start-mode"]', 'absolute');
    await page.click('button[name="cam-in"]');
    await until(async () => {
      const s = await status(stack.api, 'y');
      return s.coupled && s.cam.active && s.cam.cam_table_id === saved.id;
    }, { what: 'y coupled through follow' });
    await page.waitForSelector('[data-led="Cam active"][data-on="1"]');
    assert.equal(await text(page, '[data-testid="coupling-master"] a'), 'x');

    // x moves; y's live readout on its page follows the cam
    for (const x of [90, 135]) {
      await moveX(x);
      const want = await camAt('follow', x);
      await until(async () => Math.abs((await readout(page, 'actual_position')) - want) < 0.05, { what: `y's live readout near ${want} (x at ${x})` });
    }
    assert.ok(Math.abs((await readout(page, 'actual_position')) - 71.71875) < 0.05, 'Polynom 5 from 0 to 80 over 180 at 135: 71.72');
    await page.close();
  });

  test('online change: with y coupled, the mode set in the editor decides when the saved table reaches y; a refusal is the server’s text', async () => {
    // (alone: couple y through follow over the API)
    let y = await status(stack.api, 'y');
    let follow = (await rest(stack.api, 'GET', '/cam-tables/follow')).body;
    if (!(y.coupled && y.cam.active && follow && y.cam.cam_table_id === follow.id)) {
      await moveX(0);
      await rest(stack.api, 'POST', '/axes/y/move-absolute?wait=true', { position: 0, velocity: 200 });
      follow = await table('follow', [point(1, 0, 0), point(2, 180, 80), point(3, 360, 0)], true);
      const c = await rest(stack.api, 'POST', '/axes/y/cam-in', { master: 'x', cam_table: 'follow' });
      assert.ok(c.status < 300, JSON.stringify(c.body));
      await moveX(135);
    }
    y = await status(stack.api, 'y');
    assert.equal(y.cam.raw_slave_stroke, 0);
    const x0 = (await status(stack.api, 'x')).actual_position;
    assert.ok(x0 < 150, `x before the activation position: ${x0}`);

    const page = await open(desk, '/cams/follow');
    await page.waitForSelector('[data-testid="cam-slaves"][data-slaves="y"]');
    assert.equal(await text(page, '[data-slave="y"] a'), 'y');
    // where y is on the table now (MC_CamInfo: the master's and the slave's cam position), and
    // the plot's axes in x's and y's units
    const marker = page.locator('.cam-marker[data-axis="y"]');
    await marker.waitFor();
    const markedAt = async () => [Number(await marker.getAttribute('data-master')), Number(await marker.getAttribute('data-slave'))];
    const camNow = (await status(stack.api, 'y')).cam;
    await until(async () => {
      const [m, sl] = await markedAt();
      return Math.abs(m - camNow.actual_master_cam_pos) < 1e-6 && Math.abs(sl - camNow.actual_slave_cam_pos) < 1e-6;
    }, { what: 'the marker at y’s cam position' });
    const units = Object.fromEntries((await rest(stack.api, 'GET', '/axes')).body.map((a) => [a.config.name, a.config.unit]));
    assert.equal(await page.getAttribute('[data-chart="cam"]', 'data-units'), `${units.x}|${units.y}`);
    // the mode: from the master axis at 150
    await page.selectOption('select[name="online-activation-mode"]', 'at_master_axis_pos');
    await page.fill('input[name="online-activation-position"]', '150');
    await page.click('button[name="apply-online-mode"]');
    await until(async () => {
      const m = (await rest(stack.api, 'GET', '/cam-tables/follow/online-change-mode')).body;
      return m.activation_mode === 'at_master_axis_pos' && m.activation_position === 150;
    }, { what: 'the mode on the server' });
    await until(async () => /^In force: at_master_axis_pos/.test(await text(page, '[data-testid="online-mode-text"]')), { what: 'the mode in force shown' });

    // a changed table: the second half ends at 20 (stroke 20); saving says it is an online change first
    const version = follow.version;
    await page.fill('input[name="slave_pos-3"]', '20');
    await page.waitForSelector('#cam[data-dirty="1"] [data-analysis="current"]');
    await page.click('button[name="save-cam"]');
    const confirm = await text(page, '[data-testid="online-change-text"]');
    assert.match(confirm, /saving is an online change\. It reaches y \(master x\) by the mode at_master_axis_pos \(activation position 150\)/);
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/follow')).body.version, version, 'not saved before the confirmation');
    await page.click('button[name="confirm-save-cam"]');
    await page.waitForSelector(`#cam[data-version="${version + 1}"]`);
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/follow')).body.slave_end, 20);
    // stored, but y runs the data it had until x reaches 150
    y = await status(stack.api, 'y');
    assert.equal(y.cam_data_queued, true, 'the new data waits for its activation');
    assert.equal(y.cam.raw_slave_stroke, 0);
    await page.waitForSelector('[data-slave="y"] [data-led="data queued"][data-on="1"]');
    await page.waitForSelector('[data-analysis="current"]');
    await picture(page, 'cam-editor');

    // a second write before the first reached y: the server's 409, as its text
    await page.fill('input[name="slave_pos-3"]', '30');
    await page.waitForSelector('[data-analysis="current"]');
    await page.click('button[name="save-cam"]');
    await page.click('button[name="confirm-save-cam"]');
    const banner = page.locator('.banner-error > span').first();
    await banner.waitFor();
    const again = await rest(stack.api, 'PUT', `/cam-tables/${follow.id}`, { id: follow.id, name: 'follow', table_type: 'motion_function', periodic: true, points: [point(1, 0, 0), point(2, 180, 80), point(3, 360, 30)] });
    assert.equal(again.status, 409);
    assert.equal((await banner.textContent()).trim(), `${again.body.title}: ${again.body.detail}`);
    assert.equal((await rest(stack.api, 'GET', '/cam-tables/follow')).body.version, version + 1);
    await page.click('.banner-error .banner-close');
    await page.click('button[name="undo"]');
    await valueIs(page, 'slave_pos-3', '20');
    await page.waitForSelector('#cam[data-dirty="0"]');

    // x passes 150: the new version is in force on y
    await moveX(170);
    await until(async () => {
      const s = await status(stack.api, 'y');
      return !s.cam_data_queued && s.cam.raw_slave_stroke === 20;
    }, { what: 'the new data in force on y' });
    await page.waitForSelector('[data-slave="y"] [data-led="data queued"][data-on="0"]');
    await moveX(270);
    const want = await camAt('follow', 270);
    assert.ok(Math.abs(want - 50) < 1e-6, `the new table at 270: ${want}`);
    await until(async () => Math.abs((await status(stack.api, 'y')).actual_position - want) < 0.05, { what: `y at ${want}, the new table's value (the old one's: 40)` });
    // the marker went along: at master 270 on the table, at its value there
    await until(async () => {
      const [m, sl] = await markedAt();
      return Math.abs(m - 270) < 1e-6 && Math.abs(sl - want) < 1e-6;
    }, { what: 'the marker at master 270' });
    await picture(page, 'cam-editor-coupled');
    await page.close();
  });

  test('the editor at 1600×1000 and 390×844 (a jump warned): screenshots, nothing wider than the window', async () => {
    await table('shots', [point(1, 0, 0), point(2, 100, 50, 'polynom5', 'motion'), point(3, 200, 100, 'polynom5', 'motion'), point(4, 360, 0)]);
    for (const [ctx, name] of [
      [desk, 'cam-editor-warnings'],
      [phone, 'cam-editor-phone'],
    ]) {
      const page = await open(ctx, '/cams/shots');
      await page.waitForSelector('[data-analysis="current"]');
      await page.waitForSelector('[data-handle="1"]');
      // with a jump to warn of: the warnings, the marked row and the dashed line are seen too
      await page.selectOption('select[name="function_type-2"]', 'polynom1');
      await page.waitForSelector('tr[data-point="2"].has-warning');
      const o = await overflowing(page);
      assert.ok(o.doc <= 0 && o.main <= 0, `${name} scrolls sideways: ${JSON.stringify(o)}`);
      assert.deepEqual(o.wide, [], `${name}: elements beyond the right edge`);
      await picture(page, name);
      await page.close();
    }
  });
});
