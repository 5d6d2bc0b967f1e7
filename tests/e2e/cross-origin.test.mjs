// A web page of another site, opened in the engineer's browser, tries every trick to move an
// axis of the real motiond (docs/security.md): "simple" requests without a preflight (fetch
// no-cors with text/plain, form-encoded or no body; auto-submitted forms into an iframe,
// text/plain shaped as JSON), a JSON fetch (preflighted, refused), the websocket, reading the
// API; and DNS rebinding (a foreign name resolved to 127.0.0.1). Afterwards, asked from node
// without an Origin: nothing is powered, nothing moved, no command exists, nothing audited.
// The page reports when it has finished every attempt (every attempt waits for its answer),
// so nothing here waits a fixed time.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { createServer } from 'node:http';
import { freePort, launch, rest, startStack, until } from './lib.mjs';

const stack = await startStack({ noDemo: false });
const motiond = new URL(stack.api);

/** The attacker's page: every trick against motiond, results in `window.results`. */
function attackPage() {
  const M = stack.api;
  return `<!doctype html><meta charset="utf-8"><title>attacking</title>
<iframe name="sink"></iframe>
<form id="textJson" method="POST" action="${M}/api/v1/axes/y/power" target="sink" enctype="text/plain">
  <input name='{"enable": true, "pad": "' value='"}'>
</form>
<form id="urlencoded" method="POST" action="${M}/api/v1/axes/y/move-velocity" target="sink">
  <input name="velocity" value="50">
</form>
<script>
const M = ${JSON.stringify(M)};
const results = {};
async function attempt(name, f) {
  try {
    results[name] = await f();
  } catch (e) {
    results[name] = 'rejected';
  }
}
// A form posted into the iframe: answered when the iframe has loaded the response.
function submitted(form) {
  return new Promise((resolve) => {
    document.querySelector('iframe').addEventListener('load', () => resolve('answered'), { once: true });
    form.submit();
  });
}
const noCors = (path, init) => fetch(M + path, { method: 'POST', mode: 'no-cors', ...init }).then((r) => r.type);
// The websocket: if it opens, power y, move it and read its status.
function socket() {
  return new Promise((resolve) => {
    const seen = [];
    const ws = new WebSocket(M.replace('http', 'ws') + '/api/v1/ws');
    const call = (id, method, params) => ws.send(JSON.stringify({ jsonrpc: '2.0', id, method, params }));
    ws.onopen = () => { seen.push('open'); call(1, 'power', { axis: 'y', wait: true }); };
    ws.onmessage = (m) => {
      seen.push(m.data);
      const id = JSON.parse(m.data).id;
      if (id === 1) call(2, 'move-velocity', { axis: 'y', velocity: 50 });
      else if (id === 2) call(3, 'subscribe', { topic: 'axes/y/status' });
      else if (seen.length > 4) ws.close();
    };
    ws.onclose = () => resolve(seen.length ? 'opened: ' + seen.join(' | ') : 'refused');
  });
}
window.addEventListener('load', async () => {
  await attempt('no-cors text/plain', () => noCors('/api/v1/axes/y/power', { headers: { 'Content-Type': 'text/plain' }, body: '{"enable": true}' }));
  await attempt('no-cors default type', () => noCors('/api/v1/axes/y/move-velocity', { body: '{"velocity": 50}' }));
  await attempt('no-cors no body', () => noCors('/api/v1/axes/y/power'));
  await attempt('no-cors form-encoded', () => noCors('/api/v1/axes/y/move-velocity', { body: new URLSearchParams({ velocity: '50' }) }));
  await attempt('no-cors multipart', () => noCors('/api/v1/axes/spindle/power', { body: new FormData() }));
  // (no-cors allows GET, HEAD and POST only: the browser refuses these itself)
  await attempt('no-cors PUT', () => noCors('/api/v1/axes/y/parameters/AxisVeloMax', { method: 'PUT', body: '{"value": 50}' }));
  await attempt('no-cors DELETE', () => noCors('/api/v1/axes/spindle', { method: 'DELETE' }));
  await attempt('form text/plain', () => submitted(document.getElementById('textJson')));
  await attempt('form urlencoded', () => submitted(document.getElementById('urlencoded')));
  await attempt('cors json', async () => {
    const r = await fetch(M + '/api/v1/axes/y/power', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"enable": true}' });
    return 'status ' + r.status;
  });
  await attempt('cors read', async () => 'read ' + (await (await fetch(M + '/api/v1/axes')).text()));
  await attempt('websocket', socket);
  window.results = results;
  document.title = 'done';
});
</script>`;
}

let attacker;
let attackerPort;
let browser;
/** Every response motiond gave to the browser: [method, url, status]. */
const answered = [];

before(async () => {
  attackerPort = await freePort();
  attacker = createServer((req, res) => {
    res.writeHead(200, { 'content-type': 'text/html; charset=utf-8' });
    res.end(attackPage());
  });
  await new Promise((r) => attacker.listen(attackerPort, '127.0.0.1', r));
  browser = await launch({ args: ['--host-resolver-rules=MAP evil.example 127.0.0.1, MAP attacker.example 127.0.0.1'] });
  browser.context.on('response', (r) => {
    const u = new URL(r.url());
    if (u.port === motiond.port) answered.push([r.request().method(), r.url(), r.status()]);
  });
});

after(async () => {
  await browser?.close();
  await new Promise((r) => attacker?.close(r) ?? r());
  await stack.stop();
});

/** Opens the attack page at `origin` and returns what each attempt got once all are done. */
async function attackFrom(origin) {
  const page = await browser.context.newPage();
  await page.goto(`${origin}/`);
  await page.waitForFunction(() => document.title === 'done', null, { timeout: 60000 });
  const results = await page.evaluate(() => window.results);
  await page.close();
  return results;
}

/** motiond as seen from node (no Origin): nothing powered, moved, commanded or audited. */
async function assertUntouched(what) {
  for (const axis of ['x', 'y', 'spindle']) {
    const r = await rest(stack.api, 'GET', `/axes/${axis}/status`);
    assert.equal(r.status, 200, `${what}: ${axis} still exists`);
    const s = r.body.status;
    assert.equal(s.power_status, false, `${what}: ${axis} powered`);
    assert.equal(s.state, 'disabled', `${what}: ${axis}`);
    assert.equal(s.set_position, 0, `${what}: ${axis} moved`);
    assert.equal(s.set_velocity, 0, `${what}: ${axis} moving`);
  }
  assert.deepEqual((await rest(stack.api, 'GET', '/commands')).body, [], `${what}: a command exists`);
  const velo = (await rest(stack.api, 'GET', '/axes/y/parameters/AxisVeloMax')).body;
  assert.equal(velo.value, 500, `${what}: parameter written`);
  const audit = (await rest(stack.api, 'GET', '/audit?limit=1000')).body;
  const foreign = audit.filter((row) => !((row.action === 'axis.create' || row.action === 'group.create') && row.client_id === 'demo'));
  assert.deepEqual(foreign, [], `${what}: audited`);
}

/** What every attempt must have got: sent blind and refused, or not even sent. */
function assertRefused(results, what) {
  assert.deepEqual(Object.keys(results).length, 12, `${what}: ${JSON.stringify(results)}`);
  for (const [name, r] of Object.entries(results)) {
    if (name.startsWith('no-cors')) assert.equal(r, /PUT|DELETE/.test(name) ? 'rejected' : 'opaque', `${what} ${name}`);
    if (name.startsWith('form')) assert.equal(r, 'answered', `${what} ${name}`);
  }
  assert.equal(results['cors json'], 'rejected', `${what}: the preflight must fail`);
  assert.equal(results['cors read'], 'rejected', `${what}: a foreign page must not read the API`);
  assert.equal(results.websocket, 'refused', `${what}: websocket`);
}

/**
 * Opens the attack page at `origin`: every attempt refused, the blind requests answered by
 * motiond itself with 403 (not merely never sent; Chromium sends Origin with every POST, so
 * the 403 comes before the 415), and motiond untouched.
 */
async function attackIsRefused(origin) {
  answered.length = 0;
  const results = await attackFrom(origin);
  assertRefused(results, origin);
  // (Playwright may report an iframe's response on another session, after the page's "done")
  const blind = () => answered.filter(([method]) => method !== 'GET' && method !== 'OPTIONS');
  await until(() => blind().length >= 7, { what: `7 answers to blind requests: ${JSON.stringify(answered)}` });
  const changes = blind();
  assert.equal(changes.length, 7, JSON.stringify(answered));
  for (const [method, url, status] of changes) assert.equal(status, 403, `${method} ${url}`);
  await assertUntouched(origin);
}

describe('a page of another site', () => {
  test('cannot power, move or change anything (cross-site: http://evil.example)', async () => {
    await attackIsRefused(`http://evil.example:${attackerPort}`);
  });

  test('cannot either from another port of the same machine (same-site: http://127.0.0.1)', async () => {
    await attackIsRefused(`http://127.0.0.1:${attackerPort}`);
  });

  test('DNS rebinding: a foreign name resolved to 127.0.0.1 gets 421 and nothing usable', async () => {
    const page = await browser.context.newPage();
    const rebound = `http://attacker.example:${motiond.port}`;
    // (the fragment first: from / it would be a same-document navigation without a response)
    for (const path of ['/#/axes/y', '/', '/openapi.json', '/api/v1/axes']) {
      const r = await page.goto(rebound + path);
      assert.equal(r.status(), 421, path);
      assert.equal(JSON.parse(await r.text()).code, 'misdirected_request', path);
    }
    // Script of the rebound origin: same-origin as far as the browser knows.
    const got = await page.evaluate(async () => {
      const post = await fetch('/api/v1/axes/y/power', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"enable": true}' });
      const read = await fetch('/api/v1/axes/y/status');
      const ws = await new Promise((resolve) => {
        const s = new WebSocket(`ws://${location.host}/api/v1/ws`);
        s.onopen = () => { s.close(); resolve('opened'); };
        s.onclose = () => resolve('refused');
      });
      return { post: [post.status, (await post.json()).code], read: [read.status, (await read.json()).code], ws };
    });
    assert.deepEqual(got, { post: [421, 'misdirected_request'], read: [421, 'misdirected_request'], ws: 'refused' });
    await page.close();
    await assertUntouched('DNS rebinding');
  });

  test('while the server’s own page still works (same origin)', async () => {
    const page = await browser.context.newPage();
    await page.goto(`${stack.api}/`);
    const status = await page.evaluate(async () => {
      const r = await fetch('/api/v1/axes/spindle/power', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}' });
      return r.status;
    });
    assert.equal(status, 202);
    await page.close();
    const commands = (await rest(stack.api, 'GET', '/commands?axis=spindle')).body;
    assert.deepEqual(commands.map((c) => c.command), ['power']);
  });
});
