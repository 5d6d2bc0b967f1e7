// Development helper: screenshots of every page against a running stack.
// node tests/e2e/shoot.mjs [width height]
// Each picture is taken once the page shows what it is for (its content, live values), never
// after a fixed wait.
import { startStack, launch, shot, rest, until } from './lib.mjs';

const [w, h] = [Number(process.argv[2] ?? 1280), Number(process.argv[3] ?? 800)];
const stack = await startStack({ noDemo: false });
const { context, close } = await launch({ width: w, height: h });
/** Every live indicator of the page says "live" (values have arrived). */
const live = (page) => page.waitForFunction(() => [...document.querySelectorAll('.main .live-ind[data-live]')].every((e) => e.dataset.live === 'live'));
try {
  const page = await context.newPage();
  page.on('console', (m) => m.type() === 'error' && console.log('console:', m.text()));
  page.on('pageerror', (e) => console.log('pageerror:', e.message));
  await page.goto(stack.url + '/#/');
  await page.waitForSelector('[data-conn="open"]');
  await page.waitForSelector('.main [data-axis="x"] [data-col="actual_position"]:text-matches("[0-9]")');
  await shot(page, `dev-overview-${w}`);
  await rest(stack.api, 'POST', '/axes/x/power', {});
  await page.goto(stack.url + '/#/axes/x');
  await page.waitForSelector('[data-led="Enabled"][data-on="1"]');
  await live(page);
  await rest(stack.api, 'POST', '/axes/x/move-absolute', { position: 300, velocity: 200 });
  // moving: the page shows a set position on the way
  await until(async () => Number(await page.locator('[data-readout="set_position"] .dro-value').textContent()) > 50, { what: 'x on its way' });
  await shot(page, `dev-online-${w}`);
  await page.goto(stack.url + '/#/axes/x/parameters');
  await page.waitForSelector('tr[data-param="AxisVeloMax"]');
  await shot(page, `dev-parameters-${w}`);
  await page.goto(stack.url + '/#/axes/y/config');
  await page.waitForSelector('select[name="drive.plant.kind"]');
  await shot(page, `dev-config-${w}`);
  // the Groups page while a path runs (the demo group xy: a line, a quarter arc, a blended line)
  await rest(stack.api, 'POST', '/axes/y/power', {});
  await until(async () => (await rest(stack.api, 'GET', '/axes/x/status')).body.status.state === 'standstill', { what: 'x at rest' });
  await rest(stack.api, 'POST', '/groups/xy/enable', {});
  await until(async () => (await rest(stack.api, 'GET', '/groups/xy/status')).body.state === 'standby', { what: 'group xy in standby' });
  await page.goto(stack.url + '/#/groups/xy');
  await page.waitForSelector('.group-online [data-group-state="standby"]');
  await page.click('button[name="run-path"]');
  await page.waitForSelector('.main tr[data-command="move-path"][data-state="done"]', { timeout: 30000 });
  await shot(page, `dev-groups-${w}`);
  await page.goto(stack.url + '/#/scope');
  await page.waitForSelector('[data-channel="0"]');
  await shot(page, `dev-scope-${w}`);
} finally {
  await close();
  await stack.stop();
}
