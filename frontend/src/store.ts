// A minimal observable value with a Preact hook. Live data is published at most once per
// animation frame (`batched`), so 25 Hz × N axes of updates cost one render per frame.
import { useEffect, useState } from 'preact/hooks';

type Listener = () => void;

export class Store<T> {
  private listeners = new Set<Listener>();
  private scheduled = false;

  constructor(private value: T, private readonly batched = false) {}

  get(): T {
    return this.value;
  }

  set(v: T): void {
    this.value = v;
    this.emit();
  }

  update(f: (v: T) => T): void {
    this.set(f(this.value));
  }

  /** Notify listeners (after mutating the value in place). */
  emit(): void {
    if (!this.batched) {
      this.listeners.forEach((l) => l());
      return;
    }
    if (this.scheduled) return;
    this.scheduled = true;
    const run = () => {
      this.scheduled = false;
      this.listeners.forEach((l) => l());
    };
    if (typeof requestAnimationFrame === 'function' && typeof document !== 'undefined' && !document.hidden) {
      requestAnimationFrame(run);
    } else {
      setTimeout(run, 16);
    }
  }

  subscribe(l: Listener): () => void {
    this.listeners.add(l);
    return () => this.listeners.delete(l);
  }
}

export function useStore<T>(s: Store<T>): T {
  const [, tick] = useState(0);
  const value = s.get();
  useEffect(() => {
    const off = s.subscribe(() => tick((n) => n + 1));
    // Set between the render and this effect (e.g. an answer that came first): not missed.
    if (s.get() !== value) tick((n) => n + 1);
    return off;
  }, [s]);
  return value;
}
