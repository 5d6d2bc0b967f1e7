// Browser tests of the System page (#/system) against the real motiond with its demo axes:
// cycle timing and its distributions, the bus, the audit log with its filters, and the
// configuration's download and import (a diff first; 409 and 422 shown; the change applied).
// Every wait is for a condition; nothing asserts timing.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launch, loginCookie, picture, rest, startStack, status, until } from './lib.mjs';

const stack = await startStack({ noDemo: false });
const CLIENT = 'e2e-system';
const as = { 'x-client-id': CLIENT };

let browser;
let page;
const dir = mkdtempSync(join(tmpdir(), 'motiond-e2e-system-'));

before(async () => {
  browser = await launch({ width: 1280, height: 800 });
  page = await browser.context.newPage();
  page.on('pageerror', (e) => console.error('pageerror:', e.message));
  await page.goto(`${stack.url}/#/system`);
  await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
});

after(async () => {
  await browser?.close();
  await stack.stop();
  rmSync(dir, { recursive: true, force: true });
});

const text = (sel, p = page) => p.locator(sel).first().textContent({ timeout: 10000 });
const num = (s) => Number(String(s).replace(/[^0-9.\-]/g, ''));

/** Enables an axis over the API; returns the power command's id (DELETE it to disable). */
async function powerOn(axis) {
  const r = await rest(stack.api, 'POST', `/axes/${axis}/power`, {}, as);
  assert.equal(r.status, 202, JSON.stringify(r.body));
  await until(async () => (await status(stack.api, axis)).power_status, { what: `${axis} enabled` });
  return r.body.id;
}

async function powerOff(axis, id) {
  const r = await rest(stack.api, 'DELETE', `/commands/${id}`, undefined, as);
  assert.ok(r.status < 300, JSON.stringify(r.body));
  await until(async () => !(await status(stack.api, axis)).power_status, { what: `${axis} disabled` });
}

describe('the System page', () => {
  test('cycle timing in µs, the real-time grants, the distributions, overruns over time, the bus', async () => {
    await page.waitForSelector('.nav-link.active[href="#/system"]');
    const sys = (await rest(stack.api, 'GET', '/system')).body;
    await page.waitForSelector('[data-testid="timing"] tr[data-metric="wakeup_latency"] td[data-q="p50_us"]');
    for (const metric of ['wakeup_latency', 'compute', 'period']) {
      for (const q of ['p50_us', 'p90_us', 'p99_us', 'p999_us', 'max_us', 'mean_us']) {
        const t = await text(`[data-testid="timing"] tr[data-metric="${metric}"] td[data-q="${q}"]`);
        assert.match(t, /^\d+\.\d+$/, `${metric} ${q}: ${t}`);
      }
    }
    // The period is about the cycle time (a loose bound: this is no timing test).
    const period = num(await text('tr[data-metric="period"] td[data-q="p50_us"]'));
    assert.ok(period > sys.cycle_time * 1e6 * 0.5 && period < sys.cycle_time * 1e6 * 2, `period p50 ${period} µs`);
    assert.equal(await text('[data-kpi="cycle_time"] .kpi-value'), `${sys.cycle_time * 1000} ms`);
    // The clock it runs on: the default, real time (not flagged).
    const clk = (await rest(stack.api, 'GET', '/clock')).body;
    assert.equal(clk.mode, 'real');
    assert.equal(await text('[data-kpi="clock"] .kpi-value'), 'real');
    assert.ok(!(await page.getAttribute('[data-kpi="clock"]', 'class')).includes('kpi-warn'));
    // polled: the cycle count goes up
    const cycles = num(await text('[data-kpi="cycles"] .kpi-value'));
    assert.ok(cycles > 0);
    await until(async () => num(await text('[data-kpi="cycles"] .kpi-value')) > cycles, { what: 'the cycle count to be polled again' });
    assert.match(await text('[data-testid="sys-facts"]'), new RegExp(`motiond ${sys.version}`));
    // real-time grants as LEDs, on as the server says
    for (const [led, on] of [['SCHED_FIFO', sys.realtime.sched_fifo], ['mlockall', sys.realtime.mlockall], ['cpu_dma_latency 0', sys.realtime.cpu_dma_latency_zero]]) {
      assert.equal(await page.getAttribute(`[data-testid="realtime"] [data-led="${led}"]`, 'data-on'), on ? '1' : '0', led);
    }
    // distributions from /metrics?buckets=fine: bars, with the quantile marks
    for (const h of ['wakeup_latency', 'compute']) {
      await page.waitForSelector(`[data-testid="hist-${h}"] svg rect.hist-bar`);
      assert.ok(Number(await page.getAttribute(`[data-testid="hist-${h}"]`, 'data-count')) > 0);
      assert.equal(await page.locator(`[data-testid="hist-${h}"] [data-mark="p99"]`).count(), 1);
    }
    // a window of the last 10 s: the difference of two scrapes, fewer cycles than since start
    await page.click('button[name="hist-window-10"]');
    await until(async () => Number(await page.getAttribute('[data-testid="hist-compute"]', 'data-count')) > 0, { what: 'a 10 s window', timeout: 30000 });
    const windowed = Number(await page.getAttribute('[data-testid="hist-compute"]', 'data-count'));
    assert.ok(windowed < num(await text('[data-kpi="cycles"] .kpi-value')), `${windowed} cycles in 10 s`);
    await page.click('button[name="hist-window-all"]');
    // overruns over time: one point per poll
    await until(async () => Number(await page.getAttribute('[data-testid="overrun-chart"]', 'data-points')) >= 3, { what: 'three polls in the chart' });
    // the bus: the simulated drives of the demo axes
    assert.equal(await text('[data-testid="bus-title"]'), 'Simulated bus: 3 axes');
    assert.deepEqual(await page.locator('[data-bus="simulated"] tr[data-axis]').evaluateAll((rows) => rows.map((r) => [r.dataset.axis, r.querySelector('[data-drive-kind]').textContent])), [
      ['x', 'simulated'],
      ['y', 'simulated'],
      ['spindle', 'simulated'],
    ]);
    await picture(page, 'system');
  });

  test('the audit log lists a command sent through the API; the filters narrow the list', async () => {
    const id = await powerOn('y');
    // The newest entries come every 5 s: the command shows up by itself.
    const row = `tr[data-action="command.power"]:has(.audit-client:text-is("${CLIENT}"))`;
    await page.waitForSelector(row, { timeout: 20000 });
    assert.equal(await text(`${row} .audit-target`), 'y');
    assert.equal(await text(`${row} .audit-outcome`), 'accepted');
    assert.equal(await text(`${row} .audit-cmd`), String(id));
    await powerOff('y', id);
    // the release too (Refresh asks at once)
    await page.click('button[name="audit-refresh"]');
    await page.waitForSelector(`tr[data-action="command.release"]:has(.audit-client:text-is("${CLIENT}"))`, { timeout: 20000 });

    const rows = page.locator('[data-testid="audit"] tr[data-audit-id]');
    const all = await rows.count();
    assert.ok(all >= 5, `${all} entries (3 axes created, power, release)`);
    await page.fill('input[name="audit-action"]', 'command.power');
    await until(async () => (await rows.count()) < all, { what: 'the filter to narrow the list' });
    const actions = await rows.evaluateAll((r) => r.map((x) => x.dataset.action));
    assert.ok(actions.length >= 1 && actions.every((a) => a.startsWith('command.power')), actions.join());
    assert.match(await text('[data-testid="audit-count"]'), new RegExp(`^${actions.length} of \\d+ loaded$`));
    // and the target: y's, not another axis's
    await page.fill('input[name="audit-target"]', 'x');
    await page.waitForSelector('[data-testid="audit"] tr.audit-empty');
    await page.fill('input[name="audit-target"]', 'y');
    await page.waitForSelector(row);
    await page.selectOption('select[name="audit-outcome"]', '!failures');
    await page.waitForSelector('[data-testid="audit"] tr.audit-empty');
    await page.click('button[name="audit-clear"]');
    await until(async () => (await rows.count()) >= all, { what: 'the filters cleared' });
    // a row's detail opens
    await page.locator('tr[data-action="axis.create"] details summary').first().click();
    assert.match(await text('tr[data-action="axis.create"] details[open] pre'), /"dynamics"/);
  });

  test('download, change and import the configuration: a diff first, 409 and 422 shown, then the change applied', async () => {
    const [dl] = await Promise.all([page.waitForEvent('download'), page.click('button[name="config-download"]')]);
    assert.match(dl.suggestedFilename(), /^motiond-config-\d{4}-\d\d-\d\d\.json$/);
    const doc = JSON.parse(readFileSync(await dl.path(), 'utf8'));
    assert.deepEqual(doc, (await rest(stack.api, 'GET', '/config')).body, 'the download is GET /config');
    const x = doc.axes.find((a) => a.config.name === 'x');
    const before = x.config.dynamics.max_velocity;
    assert.notEqual(before, 444);
    x.config.dynamics.max_velocity = 444;
    const file = join(dir, 'changed.json');
    writeFileSync(file, JSON.stringify(doc, null, 2));

    // With x enabled: the diff, then motiond's 409 at it.
    const power = await powerOn('x');
    await page.setInputFiles('input[name="config-file"]', file);
    await page.waitForSelector('[data-testid="import-diff"]');
    const changed = '[data-diff-item="x"][data-diff-kind="changed"] tr[data-path="dynamics.max_velocity"]';
    assert.equal(await text(`${changed} .diff-path`), 'dynamics.max_velocity');
    assert.equal((await text(`${changed} .diff-vals`)).replace(/\s+/g, ' ').trim(), `${before} → 444`);
    assert.equal(await text('[data-testid="diff-summary"]'), '1 changed (1 field), 0 added, 0 removed');
    for (const other of ['y', 'spindle']) assert.equal(await page.locator(`[data-diff-item="${other}"]`).count(), 0, `${other} unchanged`);
    assert.equal((await rest(stack.api, 'GET', '/config')).body.axes.find((a) => a.config.name === 'x').config.dynamics.max_velocity, before, 'nothing imported yet');
    await picture(page, 'system-import-diff');
    await page.click('button[name="import-confirm"]');
    await page.waitForSelector('[data-testid="import-problem"][data-status="409"]');
    assert.match(await text('[data-testid="import-problem"]'), /All axes must be disabled before an import\. axis 'x' is not disabled/);
    await powerOff('x', power);

    // An invalid file: the 422's field errors by axis name.
    const bad = structuredClone(doc);
    bad.axes.find((a) => a.config.name === 'y').config.dynamics.max_velocity = -1;
    const badFile = join(dir, 'bad.json');
    writeFileSync(badFile, JSON.stringify(bad));
    await page.click('button[name="import-cancel"]');
    await page.setInputFiles('input[name="config-file"]', badFile);
    await page.waitForSelector('[data-diff-item="y"] tr[data-path="dynamics.max_velocity"]');
    await page.click('button[name="import-confirm"]');
    await page.waitForSelector('[data-testid="import-problem"][data-status="422"]');
    const errors = await page.locator('[data-testid="import-errors"] li').allTextContents();
    assert.ok(errors.includes("axis 'y': dynamics.max_velocity: must be a finite number > 0"), errors.join(' | '));

    // The good file, all axes disabled: imported.
    await page.click('button[name="import-cancel"]');
    await page.setInputFiles('input[name="config-file"]', file);
    await page.waitForSelector(changed);
    await page.click('button[name="import-confirm"]');
    await page.waitForSelector('[data-testid="import-done"]');
    assert.match(await text('[data-testid="import-done"]'), /Imported changed\.json: 3 axes, 0 cam tables/);
    const now = (await rest(stack.api, 'GET', '/config')).body;
    assert.equal(now.axes.find((a) => a.config.name === 'x').config.dynamics.max_velocity, 444);
    // the import is in the audit log
    await page.click('button[name="audit-refresh"]');
    await page.waitForSelector('tr[data-action="config.import"]', { timeout: 20000 });
  });

  test('on a phone (390 × 844) nothing is wider than the screen', async () => {
    const phone = await launch({ width: 390, height: 844 });
    try {
      const p = await phone.context.newPage();
      p.on('pageerror', (e) => console.error('pageerror:', e.message));
      await p.goto(`${stack.url}/#/system`);
      await p.waitForSelector('[data-testid="timing"] tr[data-metric="period"]');
      await p.waitForSelector('[data-testid="hist-compute"] svg');
      await p.waitForSelector('tr[data-audit-id]');
      await p.waitForSelector('[data-bus="simulated"] tr[data-axis]');
      const wide = await p.evaluate(() => {
        const W = document.documentElement.clientWidth;
        const out = [];
        for (const el of document.querySelectorAll('body *')) {
          const r = el.getBoundingClientRect();
          if ((r.width || r.height) && (r.right > W + 0.5 || r.left < -0.5)) out.push(`${el.tagName.toLowerCase()}.${[...el.classList].join('.')}`);
        }
        return out;
      });
      assert.deepEqual(wide, []);
      await picture(p, 'system-phone');
    } finally {
      await phone.close();
    }
  });
});

describe('the System page with authentication on', () => {
  let secured;
  let ctx;
  before(async () => {
    secured = await startStack({ noDemo: false, env: { MOTIOND_ADMIN_USER: 'anna', MOTIOND_ADMIN_PASSWORD: 'secret-pass-1' } });
    ctx = await launch({ width: 1280, height: 800 });
  });
  after(async () => {
    await ctx?.close();
    await secured?.stop();
  });

  test('an operator sees the timing; the audit log shows motiond’s 403; Import is for engineers', async () => {
    const cookie = await loginCookie(secured.api, 'anna', 'secret-pass-1');
    const made = await rest(secured.api, 'POST', '/users', { name: 'otto', role: 'operator', password: 'otto-pass-123' }, { cookie });
    assert.equal(made.status, 201, JSON.stringify(made.body));
    const refused = await rest(secured.api, 'GET', '/audit', undefined, { cookie: await loginCookie(secured.api, 'otto', 'otto-pass-123') });
    assert.equal(refused.status, 403);

    const p = await ctx.context.newPage();
    p.on('pageerror', (e) => console.error('pageerror:', e.message));
    await p.goto(`${secured.url}/#/system`);
    await p.waitForSelector('[data-page="login"]');
    await p.fill('input[name="name"]', 'otto');
    await p.fill('input[name="password"]', 'otto-pass-123');
    await p.click('button[name="login"]');
    await p.waitForSelector('[data-testid="timing"] tr[data-metric="compute"] td[data-q="p99_us"]', { timeout: 20000 });
    await p.waitForSelector('[data-testid="hist-compute"] svg');
    const banner = await text('[data-testid="audit-forbidden"]', p);
    assert.ok(banner.startsWith('The audit log needs the engineer role. motiond says: '), banner);
    assert.ok(banner.endsWith(refused.body.detail), `${banner} / ${refused.body.detail}`);
    assert.equal(await p.locator('[data-testid="audit"]').count(), 0);
    assert.equal(await p.isDisabled('button[name="config-import"]'), true);
    assert.equal(await p.isDisabled('button[name="config-download"]'), false);
    await p.close();
  });
});
