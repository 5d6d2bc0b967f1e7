// Development helper: screenshots of every page against a running stack.
// node tests/e2e/shoot.mjs [width height]
import { startStack, launch, shot, rest, until, sleep } from './lib.mjs';

const [w, h] = [Number(process.argv[2] ?? 1280), Number(process.argv[3] ?? 800)];
const stack = await startStack({ noDemo: false });
const { context, close } = await launch({ width: w, height: h });
try {
  const page = await context.newPage();
  page.on('console', (m) => m.type() === 'error' && console.log('console:', m.text()));
  page.on('pageerror', (e) => console.log('pageerror:', e.message));
  await page.goto(stack.url + '/#/');
  await page.waitForSelector('[data-conn="open"]');
  await sleep(800);
  await shot(page, `dev-overview-${w}`);
  await rest(stack.api, 'POST', '/axes/x/power', {});
  await page.goto(stack.url + '/#/axes/x');
  await sleep(500);
  await rest(stack.api, 'POST', '/axes/x/move-absolute', { position: 300, velocity: 200 });
  await sleep(700);
  await shot(page, `dev-online-${w}`);
  await page.goto(stack.url + '/#/axes/x/parameters');
  await sleep(800);
  await shot(page, `dev-parameters-${w}`);
  await page.goto(stack.url + '/#/axes/y/config');
  await sleep(500);
  await shot(page, `dev-config-${w}`);
  await page.goto(stack.url + '/#/scope');
  await sleep(800);
  await shot(page, `dev-scope-${w}`);
} finally {
  await close();
  await stack.stop();
}
