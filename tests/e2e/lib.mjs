// Harness of the browser tests: the real motiond binary on a free port with a temporary
// database, the built UI (served by motiond when it has --ui-dir, else by `vite preview`
// with a proxy to motiond), and Debian's Chromium driven by playwright-core.
import { spawn, execFileSync } from 'node:child_process';
import { copyFileSync, mkdtempSync, mkdirSync, rmSync, existsSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
export const FRONTEND = join(ROOT, 'frontend');
export const DIST = join(FRONTEND, 'dist');
/** Where screenshots go (E2E_SHOTS_DIR, else target/ui-screenshots). */
export const SHOTS = process.env.E2E_SHOTS_DIR ? resolve(process.env.E2E_SHOTS_DIR) : join(ROOT, 'target', 'ui-screenshots');
const CARGO_TARGET = process.env.CARGO_TARGET_DIR ? resolve(process.env.CARGO_TARGET_DIR) : join(ROOT, 'target');
export const MOTIOND = process.env.MOTIOND_BIN ?? join(CARGO_TARGET, 'debug', 'motiond');
export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export function freePort() {
  return new Promise((res, rej) => {
    const s = createServer();
    s.unref();
    s.on('error', rej);
    s.listen(0, '127.0.0.1', () => {
      const { port } = s.address();
      s.close(() => res(port));
    });
  });
}

/** Polls `f` until it returns a truthy value (no timing assertions: a generous deadline). */
export async function until(f, { timeout = 20000, interval = 50, what = 'condition' } = {}) {
  const end = Date.now() + timeout;
  let last;
  for (;;) {
    try {
      last = await f();
      if (last) return last;
    } catch (e) {
      last = e;
    }
    if (Date.now() > end) throw new Error(`timed out waiting for ${what} (last: ${last instanceof Error ? last.message : JSON.stringify(last)})`);
    await sleep(interval);
  }
}

export function motiondHelp() {
  try {
    return execFileSync(MOTIOND, ['serve', '--help'], { encoding: 'utf8' }) + execFileSync(MOTIOND, ['--help'], { encoding: 'utf8' });
  } catch (e) {
    return String(e.stdout ?? '');
  }
}

/** Whether this motiond serves the UI itself (`--ui-dir`). */
export const servesUi = () => /--ui-dir/.test(motiondHelp());

function spawnLogged(cmd, args, opts, name) {
  const p = spawn(cmd, args, { ...opts, stdio: ['ignore', 'pipe', 'pipe'] });
  const log = [];
  const keep = (d) => {
    log.push(String(d));
    if (log.length > 400) log.splice(0, 100);
  };
  p.stdout.on('data', keep);
  p.stderr.on('data', keep);
  p.log = () => `--- ${name} output ---\n${log.join('')}`;
  return p;
}

async function stopProcess(p) {
  if (!p || p.exitCode !== null || p.signalCode !== null) return;
  const gone = new Promise((r) => p.once('exit', r));
  p.kill('SIGTERM');
  const t = setTimeout(() => p.kill('SIGKILL'), 5000);
  await gone;
  clearTimeout(t);
}

/**
 * Starts motiond (fresh database, demo machine unless noDemo) and whatever serves the UI.
 * `env` is added to motiond's environment (e.g. MOTIOND_ADMIN_USER/MOTIOND_ADMIN_PASSWORD: the
 * first admin, so authentication is on), `args` to its command line.
 * Returns { url (the UI), api (motiond), stop() }.
 */
export async function startStack({ noDemo = true, env = {}, args: extraArgs = [] } = {}) {
  if (!existsSync(MOTIOND)) throw new Error(`${MOTIOND} missing: cargo build -p motiond, or set MOTIOND_BIN`);
  if (!existsSync(join(DIST, 'index.html'))) throw new Error(`${DIST} missing: cd frontend && npm run build`);
  const dir = mkdtempSync(join(tmpdir(), 'motiond-e2e-'));
  const port = await freePort();
  const api = `http://127.0.0.1:${port}`;
  const ownUi = servesUi();
  const args = ['serve', '--listen', `127.0.0.1:${port}`, '--db', join(dir, 'm.db')];
  if (noDemo) args.push('--no-demo');
  if (ownUi) args.push('--ui-dir', DIST);
  args.push(...extraArgs);
  const procs = [];
  const startMotiond = async () => {
    const p = spawnLogged(MOTIOND, args, { cwd: dir, env: { ...process.env, RUST_LOG: process.env.RUST_LOG ?? 'warn', ...env } }, 'motiond');
    procs.push(p);
    // With authentication on, an anonymous request is a 401: motiond answers all the same.
    await until(async () => {
      const r = await fetch(`${api}/api/v1/system`);
      return r.ok || r.status === 401;
    }, { what: 'motiond to answer', timeout: 30000 });
    return p;
  };
  let motiond = null;
  const stop = async () => {
    for (const p of procs.reverse()) await stopProcess(p);
    rmSync(dir, { recursive: true, force: true });
  };
  try {
    motiond = await startMotiond();
    let url = api;
    if (!ownUi) {
      const uiPort = await freePort();
      const vite = spawnLogged(
        process.execPath,
        [join(FRONTEND, 'node_modules', 'vite', 'bin', 'vite.js'), 'preview', '--host', '127.0.0.1', '--port', String(uiPort), '--strictPort'],
        { cwd: FRONTEND, env: { ...process.env, MOTIOND_URL: api } },
        'vite preview',
      );
      procs.push(vite);
      url = `http://127.0.0.1:${uiPort}`;
      await until(async () => (await fetch(`${url}/`)).ok, { what: 'vite preview to answer', timeout: 30000 });
    }
    /** Stops motiond (the UI server stays when it is vite preview). */
    const killMotiond = async () => {
      await stopProcess(motiond);
    };
    /** Sends a signal to motiond (SIGSTOP/SIGCONT: a server that is there but silent). */
    const signalMotiond = (sig) => {
      motiond.kill(sig);
    };
    /** Starts motiond again on the same port and database. */
    const restartMotiond = async () => {
      motiond = await startMotiond();
    };
    return { url, api, ownUi, stop, killMotiond, restartMotiond, signalMotiond, logs: () => procs.map((p) => p.log()).join('\n') };
  } catch (e) {
    const logs = procs.map((p) => p.log()).join('\n');
    await stop();
    throw new Error(`${e.message}\n${logs}`);
  }
}

/**
 * Headless Debian Chromium with a fresh user-data-dir (never a downloaded browser); `args` are
 * added to the usual ones (e.g. `--host-resolver-rules=…`).
 */
export async function launch({ width = 1280, height = 800, args = [] } = {}) {
  const profile = mkdtempSync(join(tmpdir(), 'motiond-e2e-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    viewport: { width, height },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync', ...args],
  });
  const close = async () => {
    await context.close().catch(() => {});
    rmSync(profile, { recursive: true, force: true });
  };
  return { context, close };
}

export async function shot(page, name) {
  mkdirSync(SHOTS, { recursive: true });
  const path = join(SHOTS, `${name}.png`);
  await page.screenshot({ path, fullPage: false });
  return path;
}

/** A screenshot for the test's record (`shot`), and for docs/ui/ when asked (DOCS_SHOTS=1). */
export async function picture(page, name) {
  const path = await shot(page, name);
  if (process.env.DOCS_SHOTS === '1') {
    const docs = join(ROOT, 'docs', 'ui');
    mkdirSync(docs, { recursive: true });
    copyFileSync(path, join(docs, `${name}.png`));
  }
  return path;
}

/** A new page of a launched browser at `url`, once its socket is open (script errors logged). */
export async function openPage({ context }, url) {
  const page = await context.newPage();
  page.on('pageerror', (e) => console.error('pageerror:', e.message));
  await page.goto(url);
  await page.waitForSelector('[data-conn="open"]', { timeout: 20000 });
  return page;
}

/**
 * REST helper against motiond (anything but a GET is declared JSON, as motiond requires);
 * `headers` are added (a session `cookie`, `authorization`, `x-client-id` …).
 */
export async function rest(api, method, path, body, headers = {}) {
  const r = await fetch(`${api}/api/v1${path}`, {
    method,
    headers: { ...(method === 'GET' ? {} : { 'content-type': 'application/json' }), ...headers },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  const text = await r.text();
  let json = null;
  try {
    json = text ? JSON.parse(text) : null;
  } catch {
    json = text;
  }
  return { status: r.status, body: json };
}

/** Logs in over the API; returns the session cookie (`motiond_session=…`) to send as `cookie`. */
export async function loginCookie(api, name, password) {
  const r = await fetch(`${api}/api/v1/auth/login`, {
    method: 'POST',
    headers: { 'content-type': 'application/json' },
    body: JSON.stringify({ name, password }),
  });
  if (r.status !== 200) throw new Error(`login of ${name}: ${r.status} ${await r.text()}`);
  const set = r.headers.getSetCookie?.() ?? [r.headers.get('set-cookie')];
  const c = set.find((h) => h && h.startsWith('motiond_session='));
  if (!c) throw new Error(`login of ${name}: no session cookie (${set})`);
  return c.split(';')[0];
}

export const status = async (api, axis) => (await rest(api, 'GET', `/axes/${axis}/status`)).body.status;

/**
 * What sticks out of the window on the right: the sideways scroll of the document and of `.main`,
 * and every visible element of `.main` and of the header whose box ends beyond the window's
 * right edge — except inside a container that scrolls or clips sideways itself (`.table-scroll`,
 * the phone's header links), whose own box is checked instead.
 */
export async function overflowing(page) {
  // Charts follow their pane's width through a ResizeObserver, a frame or more after the
  // window changed: the layout is measured until it fits (at most 5 s), and the last
  // measurement is what the caller asserts on.
  const deadline = Date.now() + 5000;
  for (;;) {
    const o = await measureOverflow(page);
    if ((o.doc <= 0 && o.main <= 0 && o.wide.length === 0) || Date.now() > deadline) return o;
    await new Promise((r) => setTimeout(r, 50));
  }
}

function measureOverflow(page) {
  return page.evaluate(() => {
    const W = document.documentElement.clientWidth;
    const main = document.querySelector('.main');
    const roots = [main, document.querySelector('.topbar')].filter(Boolean);
    const clipped = (el, root) => {
      for (let p = el.parentElement; p && p !== root; p = p.parentElement) {
        if (getComputedStyle(p).overflowX !== 'visible') return true;
      }
      return false;
    };
    const name = (el) => `${el.tagName.toLowerCase()}${el.id ? '#' + el.id : ''}${[...el.classList].map((c) => '.' + c).join('')}${el.getAttribute('name') ? `[name=${el.getAttribute('name')}]` : ''}`;
    const wide = [];
    for (const root of roots)
      for (const el of root.querySelectorAll('*')) {
        const r = el.getBoundingClientRect();
        if (!(r.width > 0 && r.height > 0) || r.right <= W + 0.5) continue;
        if (getComputedStyle(el).visibility === 'hidden' || clipped(el, root)) continue;
        wide.push(`${name(el)} ends at ${Math.round(r.right)} > ${W}`);
      }
    return { doc: document.documentElement.scrollWidth - window.innerWidth, main: main ? main.scrollWidth - main.clientWidth : 0, wide };
  });
}

/**
 * Text cut off inside its own box — what `overflowing` cannot see, because the box itself fits
 * the window: a label, table cell, heading, tag or button whose text is wider than the box
 * (`scrollWidth > clientWidth`, also behind an ellipsis), a select whose chosen option does not
 * fit (measured on a copy holding only that option, arrow and padding included), a text input
 * whose value — or placeholder while empty — is wider than its content box. Elements of `.main`,
 * the header and a floating banner; hidden ones, boxes that scroll sideways themselves and the
 * one-line preview of a closed disclosure (`<summary>`, all of it shown when opened) are not
 * counted. Returns one line per cut element.
 */
export async function clippedText(page) {
  return page.evaluate(() => {
    const roots = [document.querySelector('.main'), document.querySelector('.topbar'), ...document.querySelectorAll('.banner-float')].filter(Boolean);
    const TEXT = 'label, .field-label, th, td, dt, dd, h2, h3, h4, button, .btn, .tag, .led, .kpi-label, .kpi-value, .dro-label, .dro-value, .seg-btn, .tab, summary, caption, .setup-name';
    const name = (el) => {
      const cls = [...el.classList].slice(0, 2).map((c) => '.' + c).join('');
      const n = el.getAttribute('name') ?? el.closest('[name]')?.getAttribute('name');
      return `${el.tagName.toLowerCase()}${cls}${n ? `[name=${n}]` : ''}`;
    };
    const visible = (el) => {
      const r = el.getBoundingClientRect();
      if (!(r.width > 0 && r.height > 0)) return false;
      const cs = getComputedStyle(el);
      return cs.visibility !== 'hidden' && cs.display !== 'none';
    };
    const ctx = document.createElement('canvas').getContext('2d');
    const textWidth = (el, text) => {
      const cs = getComputedStyle(el);
      ctx.font = `${cs.fontStyle} ${cs.fontWeight} ${cs.fontSize} ${cs.fontFamily}`;
      return ctx.measureText(text).width;
    };
    const cut = [];
    for (const root of roots) {
      for (const el of root.querySelectorAll(TEXT)) {
        if (!visible(el)) continue;
        const cs = getComputedStyle(el);
        if (cs.display === 'inline' || cs.overflowX === 'auto' || cs.overflowX === 'scroll') continue;
        if (el.tagName === 'SUMMARY' && !el.parentElement.open) continue;
        const text = el.textContent.trim();
        if (!text) continue;
        if (el.scrollWidth > el.clientWidth + 1) cut.push(`${name(el)} "${text.slice(0, 40)}": ${el.scrollWidth} > ${el.clientWidth} px`);
      }
      for (const el of root.querySelectorAll('select')) {
        if (!visible(el) || el.selectedIndex < 0) continue;
        const copy = document.createElement('select');
        copy.className = el.className;
        copy.style.cssText = 'position:absolute;left:0;top:0;width:auto;min-width:0;max-width:none;visibility:hidden';
        copy.appendChild(el.options[el.selectedIndex].cloneNode(true));
        el.parentElement.appendChild(copy);
        const need = copy.getBoundingClientRect().width;
        copy.remove();
        const has = el.getBoundingClientRect().width;
        if (need > has + 0.5) cut.push(`${name(el)} "${el.options[el.selectedIndex].textContent.trim().slice(0, 40)}": needs ${Math.ceil(need)} > ${Math.floor(has)} px`);
      }
      for (const el of root.querySelectorAll('input:not([type]), input[type="text"], input[type="search"], input[type="password"]')) {
        if (!visible(el)) continue;
        const cs = getComputedStyle(el);
        const text = el.value || el.placeholder;
        if (!text || el.type === 'password') continue;
        const room = el.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight);
        const need = textWidth(el, text);
        if (need > room + 1) cut.push(`${name(el)} "${text.slice(0, 40)}": ${Math.ceil(need)} > ${Math.floor(room)} px`);
      }
    }
    return cut;
  });
}

/** Enables the axes (MC_Power) and waits until each one is. */
export async function powerOn(api, names) {
  for (const n of names) {
    const p = await rest(api, 'POST', `/axes/${n}/power`, {});
    if (p.status !== 202) throw new Error(`power ${n}: ${p.status} ${JSON.stringify(p.body)}`);
  }
  for (const n of names) await until(async () => (await status(api, n)).power_status, { what: `${n} enabled` });
}

/** A readout of the online tab as a number. */
export async function readout(page, name) {
  const t = await page.locator(`[data-readout="${name}"] .dro-value`).first().textContent();
  return Number(t);
}
