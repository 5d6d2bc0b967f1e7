// Merging a subscription's `update` notifications: the server sends the full object first,
// then only the fields that changed, each stamped with the kernel cycle.

export interface Update<T> {
  cycle: number;
  full: boolean;
  data: Partial<T>;
}

export class DeltaMerger<T extends object> {
  private data: T | null = null;
  private lastCycle = -1;
  private awaitingFull = true;

  /** The merged object (the last known one while stale). */
  get value(): T | null {
    return this.data;
  }

  get cycle(): number {
    return this.lastCycle;
  }

  /** True until the first full object after a (re)subscription has arrived. */
  get stale(): boolean {
    return this.awaitingFull;
  }

  /**
   * A new subscription was sent (first subscribe, resubscribe, reconnect): deltas are
   * meaningless until the next full object. The last value is kept for display (stale).
   * `newConnection` also forgets the cycle (a restarted server counts from 0 again).
   */
  reset(newConnection = false): void {
    this.awaitingFull = true;
    if (newConnection) this.lastCycle = -1;
  }

  /** Applies an update; returns whether the value changed. */
  apply(u: Update<T>): boolean {
    if (u.full) {
      // A full object older than what we hold can only be a leftover of an earlier
      // subscription; while awaiting a full one after a reconnect, any cycle is accepted.
      if (!this.awaitingFull && u.cycle < this.lastCycle) return false;
      this.data = { ...(u.data as T) };
      this.lastCycle = u.cycle;
      this.awaitingFull = false;
      return true;
    }
    if (this.awaitingFull || this.data === null) return false; // no base to apply it to
    if (u.cycle < this.lastCycle) return false; // out of order: older than what we show
    this.data = { ...this.data, ...u.data };
    this.lastCycle = u.cycle;
    return true;
  }
}
