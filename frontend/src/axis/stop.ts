// The Online tab's Stop (F6) as TwinCAT XAE's: MC_Stop decelerates the axis, and once it stands
// (the stop `done`) the UI releases it (DELETE /commands/{id}: the falling edge of Execute), so
// the axis is back in Standstill and takes the next command (F9 Home). A stop from the REST API
// or another client keeps its PLCopen lock until it is released; only the UI's own is followed
// here. No UI code, no global state: services.ts wires it to the command log and the REST client.

/** What this needs to know of a command. */
export interface StopState {
  state: string;
  final: boolean;
}

export interface StopFollowApi {
  /** The command as the server has it now (GET /commands/{id}). */
  read(id: number): Promise<StopState>;
  /** Calls `on` with every new state of the command the command log sees; returns the unsubscribe. */
  watch(id: number, on: (s: StopState) => void): () => void;
  /** Releases the command (DELETE /commands/{id}). */
  release(id: number): Promise<void>;
}

/**
 * Releases the stop `id` once it is done (the axis at standstill). Resolves `released`, or
 * `ended` when the stop became final otherwise (an error aborted it, another client released
 * it) and there was nothing to release. The command log's events are the signal; the server
 * is asked every `pollMs` too, in case an event is missed (a socket lost meanwhile).
 */
export function releaseWhenDone(id: number, api: StopFollowApi, pollMs = 1000): Promise<'released' | 'ended'> {
  return new Promise((resolve, reject) => {
    let over = false;
    let timer: ReturnType<typeof setInterval> | null = null;
    let unwatch: () => void = () => {};
    const finish = (f: () => void) => {
      if (over) return;
      over = true;
      unwatch();
      if (timer) clearInterval(timer);
      f();
    };
    const seen = (s: StopState) => {
      if (over) return;
      if (s.final) finish(() => resolve('ended'));
      else if (s.state === 'done') finish(() => api.release(id).then(() => resolve('released'), reject));
    };
    unwatch = api.watch(id, seen);
    if (over) unwatch();
    const ask = () => api.read(id).then(seen, () => {});
    timer = setInterval(ask, pollMs);
    void ask();
  });
}
