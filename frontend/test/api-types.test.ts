// What tsc refuses of a call to the API (checked by `tsc --noEmit` in `npm run build`, which
// compiles test/ too): each `@ts-expect-error` below must meet an error, or tsc fails with
// "Unused '@ts-expect-error' directive" — so a client that stopped checking bodies against their
// block would fail the build. The calls are compiled, never run.
import { describe, expect, expectTypeOf, it } from 'vitest';
import { api } from '../src/api/client';
import { postBlock, type BlockBody, type BlockName } from '../src/api/blocks';
import { command } from '../src/services';
import type { CommandResource, MoveBody } from '../src/api/types';

function refused(move: MoveBody) {
  // @ts-expect-error a field the block does not have (MC_Halt has no position)
  void command('x', 'halt', { position: 1 });
  // @ts-expect-error a field name misspelt
  void command('x', 'move-absolute', { position: 1, velocty: 2 });
  // @ts-expect-error a required field missing (MC_MoveAbsolute needs its velocity)
  void command('x', 'move-absolute', { position: 1 });
  // @ts-expect-error a body sent to the wrong block: MC_MoveAbsolute's body to MC_GearIn
  void command('x', 'gear-in', move);
  // @ts-expect-error a field of the wrong type
  void postBlock('x', 'set-override', { velocity_factor: '50%' });
  // @ts-expect-error a name that is no block
  void command('x', 'move-absolut', { position: 1, velocity: 2 });
  // @ts-expect-error a query parameter the block does not take
  void command('x', 'halt', {}, { query: { wiat: true } });
  // @ts-expect-error the same through the client itself: a field MC_Halt does not have
  void api.POST('/api/v1/axes/{axis}/halt', { params: { path: { axis: 'x' } }, body: { position: 1 } });
  // @ts-expect-error a path the API does not have
  void api.GET('/api/v1/axis');
  // @ts-expect-error a path parameter missing
  void api.GET('/api/v1/axes/{axis}/parameters');
  // @ts-expect-error a body for a read
  void api.GET('/api/v1/axes', { body: {} });
}

function accepted(move: MoveBody) {
  void command('x', 'halt', {});
  void command('x', 'move-absolute', move, { query: { wait: true, timeout_ms: 20000 } });
  void command('x', 'move-velocity', { velocity: 5, direction: 'positive' });
  void api.PUT('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis: 'x', parameter: 'AxisVeloMax' } }, body: { value: 600 } });
}

describe('the client as tsc sees it', () => {
  it('a block answers its command resource; a read its resource', () => {
    expectTypeOf(command<'halt'>).returns.toEqualTypeOf<Promise<CommandResource>>();
    // The block's body is MoveBody of the schema (structurally: openapi-fetch's Writable<> wraps it).
    expectTypeOf<BlockBody<'move-absolute'>>().toExtend<MoveBody>();
    expectTypeOf<MoveBody>().toExtend<BlockBody<'move-absolute'>>();
    expectTypeOf<'move-absolute' | 'gear-in' | 'halt' | 'stop' | 'power'>().toExtend<BlockName>();
    expectTypeOf<'status/following-error-peak/reset'>().not.toExtend<BlockName>();
    expectTypeOf(api.GET<'/api/v1/axes'>).returns.resolves.toBeArray();
    expect([typeof refused, typeof accepted]).toEqual(['function', 'function']);
  });
});
