// A group's blocks as types: `POST /api/v1/groups/{group}/<name>` answered with the command
// resource (MC_GroupEnable is `enable`, MC_MovePath `move-path` …), body and query those of the
// operation in the OpenAPI document, so `postGroupBlock(group, 'move-path', body)` is checked by
// tsc as `postBlock` is for an axis's (api/blocks.ts). No UI code, no global state.
import { api, type Answer, type Init, type Operation, type PostPath } from '../api/client';
import type { CommandResource } from '../api/types';

type GroupPost = Extract<PostPath, `/api/v1/groups/{group}/${string}`>;
type GroupOperation<N extends string> = Operation<Extract<GroupPost, `/api/v1/groups/{group}/${N}`>, 'post'>;

/** The names of the group blocks (`enable`, `move-path`, `halt` …). */
export type GroupBlockName = {
  [P in GroupPost]: Answer<Operation<P, 'post'>> extends CommandResource ? (P extends `/api/v1/groups/{group}/${infer N}` ? N : never) : never;
}[GroupPost];

/** The body of group block `N`. */
export type GroupBlockBody<N extends GroupBlockName> = NonNullable<Init<GroupOperation<N>>['body']>;

/** Sends group block `name` to `group`: the command resource, or the server's refusal as ApiError. */
export function postGroupBlock<N extends GroupBlockName>(group: string, name: N, body: GroupBlockBody<N>, signal?: AbortSignal): Promise<CommandResource> {
  const post = api.POST as unknown as (path: string, init: object) => Promise<CommandResource>;
  return post(`/api/v1/groups/{group}/${name}`, { params: { path: { group } }, body, signal });
}
