// services.ts against a fetch double: the held MC_Stop is asked of the server at click time;
// the MC_Power override is learnt from the axis's power commands.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { findHeldStop, loadPowerCommand, logCommand, powerOverride, powerOverrides } from '../src/services';
import type { CommandResource } from '../src/api/types';

const cmd = (id: number, command: string, state: CommandResource['state'], final: boolean, parameters: object = {}, axis = 'x') =>
  ({ id, axis, command, state, final, parameters, outputs: { error_id: 0 }, last_cycle: id, submitted_at: '' }) as unknown as CommandResource;

let asked: string[];
function serve(byQuery: (url: string) => CommandResource[]) {
  asked = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (url: string) => {
      asked.push(url);
      return new Response(JSON.stringify(byQuery(url)), { status: 200 });
    }),
  );
}
beforeEach(() => powerOverrides.set(new Map()));
afterEach(() => vi.unstubAllGlobals());

describe('release of a stop', () => {
  it('asks the server for the axis’s stop that still holds the lock (ramping: active)', async () => {
    serve((u) => (u.includes('state=active') ? [cmd(9, 'move-velocity', 'active', false), cmd(8, 'stop', 'active', false)] : []));
    expect(await findHeldStop('x')).toBe(8);
    expect(asked[0]).toBe('/api/v1/commands?axis=x&state=active&limit=500');
  });

  it('at standstill the held stop is done but not final; a released (final) one is not taken', async () => {
    serve((u) => (u.includes('state=done') ? [cmd(12, 'stop', 'done', true), cmd(11, 'stop', 'done', false), cmd(10, 'reset', 'done', true)] : []));
    expect(await findHeldStop('x')).toBe(11);
  });

  it('null when the server knows none', async () => {
    serve(() => [cmd(3, 'stop', 'done', true)]);
    expect(await findHeldStop('x')).toBeNull();
  });
});

describe('power override', () => {
  it('100 (the server’s default) until a power command is known', () => {
    expect(powerOverride('x')).toBe(100);
  });

  it('that of the newest power command of the axis', () => {
    logCommand(cmd(5, 'power', 'active', false, { enable: true, override_percent: 40 }));
    logCommand(cmd(4, 'power', 'done', true, { enable: true, override_percent: 70 })); // older
    logCommand(cmd(6, 'power', 'active', false, { enable: true, override_percent: 20 }, 'y'));
    expect(powerOverride('x')).toBe(40);
    expect(powerOverride('y')).toBe(20);
    logCommand(cmd(7, 'power', 'active', false, { enable: true }));
    expect(powerOverride('x')).toBe(100);
  });

  it('is looked up on the server when the log does not have it', async () => {
    serve(() => [cmd(30, 'move-absolute', 'done', true), cmd(2, 'power', 'active', false, { override_percent: 60 })]);
    await loadPowerCommand('x');
    expect(asked[0]).toBe('/api/v1/commands?axis=x&limit=500');
    expect(powerOverride('x')).toBe(60);
  });
});
