// The Groups page in headless Debian Chromium against the real motiond with its demo machine
// (axes x and y, group `xy`): a path of a line, an arc and a blended line entered as rows,
// planned by the server as it is entered (its length and duration, the charts of its dynamics),
// run, its live trace drawn over the plan while it runs, followed to its end; the server's 422 —
// of the plan while editing, of the run — shown at the row and field it names, and at a field of
// the group form; the page fits the window at every size. Everything waits on the page's DOM or
// the server's state, never on a fixed time.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { clippedText, launch, openPage, overflowing, picture, powerOn, rest, startStack, until } from './lib.mjs';

const stack = await startStack({ noDemo: false });
let browser;

before(async () => {
  browser = await launch({ width: 1600, height: 1000 });
});

after(async () => {
  await browser?.close();
  await stack.stop();
});

const groupStatus = async () => (await rest(stack.api, 'GET', '/groups/xy/status')).body;

/** Fills the text input named `name` (a JSON path) with `value`. */
async function fill(page, name, value) {
  await page.fill(`input[name="${name}"]`, String(value));
}

async function select(page, name, value) {
  await page.selectOption(`select[name="${name}"]`, value);
}

describe('groups page', () => {
  test('the demo group xy is listed; enabled from the page; a line, an arc and a blended line run to their end', async () => {
    await powerOn(stack.api, ['x', 'y']);
    const page = await openPage(browser, `${stack.url}/#/groups`);
    await page.click('.nav-link:text("Groups")');
    await page.waitForSelector('tr[data-group="xy"]');
    await page.click('tr[data-group="xy"] a');
    await page.waitForSelector('[data-testid="group-state"]');
    await page.waitForSelector('.group-online [data-group-state="disabled"]');

    await page.click('button[name="group-enable"]');
    await page.waitForSelector('.group-online [data-group-state="standby"]');

    // The table: cleared, then three rows entered.
    await page.click('button[name="clear-rows"]');
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[0].position[0]', 100);
    await fill(page, 'entries[0].position[1]', 0);
    await fill(page, 'entries[0].velocity', 200);
    await fill(page, 'entries[0].invoke_id', 10);
    await page.click('button[name="add-circular"]');
    // a new row after the first: buffered / none, the velocity of the row before
    assert.equal(await page.inputValue('select[name="entries[1].buffer_mode"]'), 'buffered');
    assert.equal(await page.inputValue('select[name="entries[1].transition_mode"]'), 'none');
    assert.equal(await page.inputValue('input[name="entries[1].velocity"]'), '200');
    await select(page, 'entries[1].circ_mode', 'center');
    await fill(page, 'entries[1].aux_point[0]', 100);
    await fill(page, 'entries[1].aux_point[1]', 50);
    await fill(page, 'entries[1].end_point[0]', 150);
    await fill(page, 'entries[1].end_point[1]', 50);
    await select(page, 'entries[1].path_choice', 'counter_clockwise');
    await fill(page, 'entries[1].invoke_id', 20);
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[2].position[0]', 150);
    await fill(page, 'entries[2].position[1]', 150);
    await select(page, 'entries[2].buffer_mode', 'blending_previous');
    await select(page, 'entries[2].transition_mode', 'corner_distance');
    await fill(page, 'entries[2].transition_parameters[0]', 5);
    await fill(page, 'entries[2].invoke_id', 30);
    // The preview: three segments, 100 + a quarter arc of radius 50 + 100.
    const want = 100 + (Math.PI * 50) / 2 + 100;
    await page.waitForSelector('.path-canvas[data-plane="xy"][data-segments="3"]');
    const lengthText = await page.textContent('[data-testid="preview-length"]');
    assert.match(lengthText, new RegExp(`programmed length ${want.toFixed(2)}`), lengthText);
    // The server's plan of these rows from where the group stands: the same length and duration
    // as POST /path-analysis gives, its trace drawn, its dynamics charted.
    const entries = [
      { type: 'linear', position: [100, 0], velocity: 200, invoke_id: 10 },
      { type: 'circular', circ_mode: 'center', aux_point: [100, 50, 0], end_point: [150, 50], path_choice: 'counter_clockwise', velocity: 200, buffer_mode: 'buffered', invoke_id: 20 },
      { type: 'linear', position: [150, 150], velocity: 200, buffer_mode: 'blending_previous', transition_mode: 'corner_distance', transition_parameters: [5], invoke_id: 30 },
    ];
    const planned = await rest(stack.api, 'POST', '/path-analysis', { group: 'xy', entries, start: { x: 0, y: 0 } });
    assert.equal(planned.status, 200, JSON.stringify(planned.body));
    const summary = '[data-testid="plan-summary"][data-state="ok"]';
    await page.waitForFunction(
      ([sel, length]) => Number(document.querySelector(sel)?.getAttribute('data-length')) === length,
      [summary, planned.body.length],
    );
    assert.equal(Number(await page.getAttribute(summary, 'data-duration')), planned.body.duration);
    assert.match(await page.textContent(summary), new RegExp(`planned length ${planned.body.length.toFixed(2)}, duration ${planned.body.duration.toFixed(3)} s`));
    assert.ok(Math.abs(planned.body.length - want) < 1, `${planned.body.length} vs ${want}`);
    await page.waitForSelector('.path-canvas[data-plane="xy"][data-plan]:not([data-plan="0"])');
    assert.equal(Number(await page.getAttribute('.path-canvas[data-plane="xy"]', 'data-plan')), planned.body.t.length + 1);
    const chart = '[data-testid="plan-chart"]';
    assert.equal(Number(await page.getAttribute(chart, 'data-samples')), planned.body.t.length);
    assert.equal(await page.getAttribute(chart, 'data-series'), 'path velocity,x velocity,y velocity,x acceleration,y acceleration');
    assert.equal(await page.locator(`${chart} .plan-pane canvas`).count(), 3);

    // At half speed (MC_GroupSetOverride from the slider's button), so the run is seen on its way.
    await page.click('button[name="group-override-50"]');
    await until(async () => (await groupStatus()).actual_override === 0.5, { what: 'override 50 % in effect' });
    await page.click('button[name="run-path"]');
    // On its way through the arc or the blended line: the entry and its invoke id shown, the picture taken.
    await page.waitForFunction(() => / \/ (20|30)$/.test(document.querySelector('[data-readout="entry"] .dro-value')?.textContent ?? ''));
    // The live trace over the plan, from the group's websocket topic, while it runs: on the
    // canvas and as the live path velocity in the charts.
    await page.waitForFunction(() => Number(document.querySelector('.path-canvas[data-plane="xy"]')?.getAttribute('data-trace')) > 3 && Number(document.querySelector('[data-testid="plan-chart"]')?.getAttribute('data-live')) > 3);
    assert.equal((await groupStatus()).state, 'moving');
    await page.evaluate(() => document.querySelector('.group-grid')?.scrollIntoView());
    await picture(page, 'groups');
    await page.evaluate(() => window.scrollTo(0, 0));
    // Followed to its end: the move-path command done in the group's command log, the group in standby.
    await page.waitForSelector('.main tr[data-command="move-path"][data-state="done"]', { timeout: 30000 });
    await page.waitForSelector('.group-online [data-group-state="standby"]');
    await page.waitForFunction(() => document.querySelector('[data-readout="pos-x"] .dro-value')?.textContent === '150.000' && document.querySelector('[data-readout="pos-y"] .dro-value')?.textContent === '150.000');
    const s = await groupStatus();
    assert.equal(s.state, 'standby');
    assert.ok(Math.abs(s.position.x - 150) < 1e-6 && Math.abs(s.position.y - 150) < 1e-6, JSON.stringify(s.position));
    // the live trace was drawn from the statuses read while it ran
    const traced = Number(await page.getAttribute('.path-canvas[data-plane="xy"]', 'data-trace'));
    assert.ok(traced > 5, `trace points: ${traced}`);
    await page.click('button[name="group-override-100"]');

    // The page fits the window at every size, nothing cut off.
    for (const [width, height] of [
      [1600, 1000],
      [1280, 800],
      [1024, 768],
      [390, 844],
    ]) {
      await page.setViewportSize({ width, height });
      await page.waitForFunction((w) => document.documentElement.clientWidth === w, width);
      const o = await overflowing(page);
      assert.ok(o.doc <= 0 && o.main <= 0, `groups at ${width}×${height} scrolls sideways: ${JSON.stringify(o)}`);
      assert.deepEqual(o.wide, [], `groups at ${width}×${height}: elements beyond the window's right edge`);
      assert.deepEqual(await clippedText(page), [], `groups at ${width}×${height}: text cut off`);
    }
    await page.setViewportSize({ width: 1600, height: 1000 });
    await page.close();
  });

  test("a bad velocity is refused by the server and shown at its row and field; a taken axis at the form's role", async () => {
    const page = await openPage(browser, `${stack.url}/#/groups/xy`);
    await page.waitForSelector('.group-online [data-group-state]');
    if ((await groupStatus()).state === 'disabled') {
      await page.click('button[name="group-enable"]');
    }
    await page.waitForSelector('.group-online [data-group-state="standby"]');
    const before = (await groupStatus()).position;
    await page.click('button[name="clear-rows"]');
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[0].position[0]', 200);
    await fill(page, 'entries[0].position[1]', 100);
    // An arc through three points on a line, planned while it is entered: the planner's
    // refusal (circle_invalid) at its row, nothing planned.
    await page.click('button[name="add-circular"]');
    await select(page, 'entries[1].circ_mode', 'border');
    await fill(page, 'entries[1].aux_point[0]', 300);
    await fill(page, 'entries[1].aux_point[1]', 100);
    await fill(page, 'entries[1].end_point[0]', 400);
    await fill(page, 'entries[1].end_point[1]', 100);
    await page.waitForSelector('tr[data-row="1"].row-error');
    assert.match(await page.textContent('tr[data-row="1"]'), /circle_invalid/);
    await page.waitForSelector('[data-testid="plan-summary"][data-state="refused"]');
    assert.equal(await page.locator('tr.path-row.row-error').count(), 1);
    await page.click('button[name="row-remove-1"]');
    await page.waitForSelector('[data-testid="plan-summary"][data-state="ok"]');
    assert.equal(await page.locator('tr.path-row.row-error').count(), 0);

    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[1].position[0]', 250);
    await fill(page, 'entries[1].velocity', -5);
    // marked by the plan as it is entered, and by the run's refusal
    const input = 'tr[data-row="1"] input[name="entries[1].velocity"][aria-invalid="true"]';
    await page.waitForSelector(input);
    await page.waitForSelector('[data-testid="plan-summary"][data-state="refused"]');
    await page.click('button[name="run-path"]');
    await page.waitForSelector('[data-testid="path-error"]');
    await page.waitForSelector(input);
    const msg = await page.textContent('tr[data-row="1"] td:has(input[name="entries[1].velocity"]) .field-error');
    assert.match(msg, /path_dynamics_invalid|velocity|dynamics/i, msg);
    // only that row is marked, and nothing moved
    assert.equal(await page.locator('tr.path-row.row-error').count(), 1);
    assert.deepEqual((await groupStatus()).position, before);
    assert.equal((await groupStatus()).state, 'standby');

    // The group form: a new group that takes axis x (already in xy) → 422 at that role's select.
    await page.click('button[name="new-group"]');
    await page.fill('.group-form input[name="name"] >> nth=0', 'second');
    await page.selectOption('.group-form select[data-role="x"] >> nth=0', 'x');
    await page.selectOption('.group-form select[data-role="y"] >> nth=0', '');
    await page.click('button[name="save-group"] >> nth=0');
    const field = '.group-form >> nth=0 >> label.field.has-error[data-field="axes[0].axis"]';
    await page.waitForSelector(field);
    assert.match(await page.textContent(`${field} .field-error`), /belongs to group xy/);
    assert.equal((await rest(stack.api, 'GET', '/groups/second')).status, 404);
    await page.close();
  });
  test('a blocker holds the path until released from the page; Stop ends a run on the path and is released at standstill', async () => {
    const page = await openPage(browser, `${stack.url}/#/groups/xy`);
    await page.waitForSelector('.group-online [data-group-state]');
    if ((await groupStatus()).state === 'disabled') await page.click('button[name="group-enable"]');
    await page.waitForSelector('.group-online [data-group-state="standby"]');
    await page.click('button[name="clear-rows"]');
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[0].position[0]', 50);
    await fill(page, 'entries[0].position[1]', 20);
    await page.click('button[name="add-blocker"]');
    await fill(page, 'entries[1].blocker_id', 7);
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[2].position[0]', 80);
    await fill(page, 'entries[2].position[1]', 20);
    await page.click('button[name="run-path"]');
    await page.waitForSelector('[data-blocked="1"]');
    assert.equal(await page.textContent('[data-testid="blocker-id"]'), '7');
    assert.equal((await groupStatus()).state, 'moving');
    await page.click('button[name="release-blocker"]');
    await page.waitForSelector('.main tr[data-command="move-path"][data-state="done"]');
    await page.waitForSelector('.group-online [data-group-state="standby"]');
    assert.equal((await groupStatus()).position.x, 80);

    // A long line at 50 mm/s, stopped on its way: Stopping, then back to standby (the UI's release).
    await page.click('button[name="clear-rows"]');
    await page.click('button[name="add-linear"]');
    await fill(page, 'entries[0].position[0]', 600);
    await fill(page, 'entries[0].position[1]', 20);
    await fill(page, 'entries[0].velocity', 50);
    await page.click('button[name="run-path"]');
    await page.waitForSelector('.group-online [data-group-state="moving"]');
    await page.click('button[name="group-stop"]');
    await page.waitForSelector('.main tr[data-command="stop"][data-state="done"]');
    await page.waitForSelector('.group-online [data-group-state="standby"]');
    const s = await groupStatus();
    assert.ok(s.position.x > 80 && s.position.x < 600, `stopped on the way: ${s.position.x}`);
    assert.equal(s.position.y, 20);
    await page.close();
  });
  test("the scope records the group's path velocity beside an axis: picked as a group channel, drawn, named in the legend", async () => {
    const st = await groupStatus();
    if (st.state !== 'standby') {
      await powerOn(stack.api, ['x', 'y']);
      await rest(stack.api, 'POST', '/groups/xy/enable?wait=true', {});
      await until(async () => (await groupStatus()).state === 'standby', { what: 'group standby' });
    }
    const page = await openPage(browser, `${stack.url}/#/scope`);
    await page.waitForSelector('[data-channel="0"]');
    while ((await page.locator('[data-channel]').count()) < 2) await page.click('button[name="add-channel"]');
    while ((await page.locator('[data-channel]').count()) > 2) await page.locator('[data-channel="2"] button').click();
    // The group is among the sources; its signals are the path's.
    await select(page, 'channel-0-axis', 'group:xy');
    const signals = await page.locator('select[name="channel-0-signal"] option').evaluateAll((os) => os.map((o) => o.value));
    assert.deepEqual(signals, ['path_position', 'path_velocity', 'path_acceleration', 'entry_index']);
    await select(page, 'channel-0-signal', 'path_velocity');
    await select(page, 'channel-1-axis', 'x');
    await select(page, 'channel-1-signal', 'set_position');
    await page.fill('input[name="duration_s"]', '3');
    await page.click('button[name="record"]');
    await page.waitForSelector('[data-testid="recording-state"]', { timeout: 10000 });
    const rec = (await rest(stack.api, 'GET', '/scope/recordings')).body[0];
    assert.deepEqual(
      rec.channels.map((c) => [c.group ?? c.axis, c.signal]),
      [['xy', 'path_velocity'], ['x', 'set_position']],
    );
    const x0 = (await groupStatus()).position.x;
    const r = await rest(stack.api, 'POST', '/groups/xy/move-path', {
      entries: [{ type: 'linear', position: [x0 + 50, 20], velocity: 100 }],
    });
    assert.equal(r.status, 202, JSON.stringify(r.body));
    await until(async () => (await rest(stack.api, 'GET', `/scope/recordings/${rec.id}`)).body.state === 'done', { what: 'recording done', timeout: 20000 });
    const done = (await rest(stack.api, 'GET', `/scope/recordings/${rec.id}`)).body;
    const v = done.data[0];
    assert.ok(Math.max(...v) > 99 && Math.max(...v) <= 100 + 1e-9, `the path velocity reached 100: ${Math.max(...v)}`);
    assert.equal(done.channels[0].unit, 'mm/s');
    await page.waitForSelector('[data-testid="scope-chart"] canvas', { timeout: 20000 });
    assert.match(await page.locator('[data-testid="scope-chart"]').textContent(), /xy\.path_velocity/);
    await page.close();
  });
  test('a conveyor tracking started over REST shows on the group panel: the conveyor, in sync; a static frame ends it', async () => {
    if ((await groupStatus()).state !== 'standby') {
      await powerOn(stack.api, ['x', 'y']);
      await rest(stack.api, 'POST', '/groups/xy/enable?wait=true', {});
      await until(async () => (await groupStatus()).state === 'standby', { what: 'group standby' });
    }
    await powerOn(stack.api, ['spindle']);
    const mv = await rest(stack.api, 'POST', '/axes/spindle/move-velocity?wait=true', { velocity: 20 });
    assert.equal(mv.body.outputs.in_velocity, true, JSON.stringify(mv.body));
    const page = await openPage(browser, `${stack.url}/#/groups/xy`);
    await page.waitForSelector('[data-testid="group-state"]');
    const t = await rest(stack.api, 'POST', '/groups/xy/track-conveyor-belt?wait=true', {
      conveyor: 'spindle', translation: [0, 50, 0], initial_object_position: [10], master_ref_position: 0, velocity: 100,
    });
    assert.equal(t.body.outputs.in_sync, true, JSON.stringify(t.body));
    await page.waitForSelector('[data-testid="group-tracking"][data-in-sync="1"]');
    assert.match(await page.textContent('[data-testid="group-tracking"]'), /tracking conveyor spindle · in sync/);
    const f = await rest(stack.api, 'POST', '/groups/xy/set-coordinate-transform?wait=true', { translation: [0, 0, 0], rotation: [0, 0, 0] });
    assert.equal(f.body.state, 'done', JSON.stringify(f.body));
    await page.waitForSelector('[data-testid="group-tracking"]', { state: 'detached' });
    await rest(stack.api, 'POST', '/axes/spindle/halt?wait=true', {});
    await page.close();
  });
});
