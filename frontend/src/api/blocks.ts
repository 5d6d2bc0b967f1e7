// The function blocks as types: a block is `POST /api/v1/axes/{axis}/<name>` answered with the
// command resource (MC_MoveAbsolute is `move-absolute`, MC_GearIn `gear-in` …), its body and
// query those of that operation in the OpenAPI document. `postBlock(axis, 'halt', body)` is
// checked by tsc: a name that is no block, a field the block does not have, a body of another
// block, a missing required field.
import { api, type Answer, type Init, type Operation, type PostPath } from './client';
import type { CommandResource } from './types';

type AxisPost = Extract<PostPath, `/api/v1/axes/{axis}/${string}`>;
type BlockOperation<N extends string> = Operation<Extract<AxisPost, `/api/v1/axes/{axis}/${N}`>, 'post'>;

/** The names of the blocks (`move-absolute`, `gear-in`, `halt` …). */
export type BlockName = {
  [P in AxisPost]: Answer<Operation<P, 'post'>> extends CommandResource ? (P extends `/api/v1/axes/{axis}/${infer N}` ? N : never) : never;
}[AxisPost];

/** The body of block `N`. */
export type BlockBody<N extends BlockName> = NonNullable<Init<BlockOperation<N>>['body']>;
/** The query of block `N`: `wait` (hold the answer until the command is final or at its milestone), `timeout_ms`. */
export type BlockQuery<N extends BlockName> = NonNullable<NonNullable<Init<BlockOperation<N>>['params']>['query']>;

export interface BlockOptions<N extends BlockName> {
  query?: BlockQuery<N>;
  signal?: AbortSignal;
}

/** Sends block `name` to `axis`: the command resource, or the server's refusal as ApiError. */
export function postBlock<N extends BlockName>(axis: string, name: N, body: BlockBody<N>, options: BlockOptions<N> = {}): Promise<CommandResource> {
  // The path is built from the name, so tsc cannot pair it with the body here; the signature does.
  const post = api.POST as unknown as (path: string, init: object) => Promise<CommandResource>;
  return post(`/api/v1/axes/{axis}/${name}`, { params: { path: { axis }, query: options.query }, body, signal: options.signal });
}
