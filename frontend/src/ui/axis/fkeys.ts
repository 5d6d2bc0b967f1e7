// TwinCAT's function keys of the axis Online tab: F1 −−, F2 −, F3 +, F4 ++ (held like the
// jog buttons), F5 start the selected move, F6 stop, F8 reset, F9 home. Installed only while
// the Online tab is shown; they work with the focus in a text field too (they type nothing).
// With Ctrl, Alt, Meta or Shift they are left to the browser (Ctrl+F5, Alt+F4, …).

export type JogKey = 'fast-backward' | 'slow-backward' | 'slow-forward' | 'fast-forward';
export type FunctionAction = 'start' | 'stop' | 'reset' | 'home';

export const JOG_KEYS: Record<string, JogKey> = { F1: 'fast-backward', F2: 'slow-backward', F3: 'slow-forward', F4: 'fast-forward' };
export const ACTION_KEYS: Record<string, FunctionAction> = { F5: 'start', F6: 'stop', F8: 'reset', F9: 'home' };

/** The key of a jog button or an action, for titles: `keyOf('stop')` → 'F6'. */
export function keyOf(what: JogKey | FunctionAction): string {
  const all: Record<string, string> = { ...JOG_KEYS, ...ACTION_KEYS };
  return Object.keys(all).find((k) => all[k] === what) ?? '';
}

export interface FunctionKeyHandlers {
  /** Whether commands can be sent now (socket open). */
  enabled(): boolean;
  jog(key: JogKey): void;
  /** Let go of the jog a function key started. */
  release(reason: string): void;
  action(a: FunctionAction): void;
}

/**
 * Listens for the function keys on `target` (the window); `handlers()` is asked on every key
 * so that it sees the page's current state. Returns the uninstaller.
 */
export function installFunctionKeys(target: EventTarget, handlers: () => FunctionKeyHandlers): () => void {
  let held: string | null = null;
  const down = (ev: Event) => {
    const e = ev as KeyboardEvent;
    if (e.ctrlKey || e.altKey || e.metaKey || e.shiftKey) return;
    const jog = JOG_KEYS[e.key];
    const action = ACTION_KEYS[e.key];
    if (!jog && !action) return;
    e.preventDefault(); // no help page, no reload, no caret browsing
    if (e.repeat) return;
    const h = handlers();
    if (!h.enabled()) return;
    if (jog) {
      held = e.key;
      h.jog(jog);
    } else {
      h.action(action);
    }
  };
  const up = (ev: Event) => {
    const e = ev as KeyboardEvent;
    if (!JOG_KEYS[e.key] && !ACTION_KEYS[e.key]) return;
    e.preventDefault();
    if (held === e.key) {
      held = null;
      handlers().release('key released');
    }
  };
  target.addEventListener('keydown', down);
  target.addEventListener('keyup', up);
  return () => {
    target.removeEventListener('keydown', down);
    target.removeEventListener('keyup', up);
    if (held) handlers().release('left the Online tab');
    held = null;
  };
}
