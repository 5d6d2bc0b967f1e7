// useStore: a value set between a component's first render and its subscription (an answer
// that came first, e.g. the session check at start) is not missed.
import { describe, expect, it } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { Store, useStore } from '../src/store';
import { mountPoint, unmount } from './dom';

describe('useStore', () => {
  it('renders a value set before its effect subscribed', async () => {
    const s = new Store<{ n: number }>({ n: 1 });
    function Show() {
      return <span>{useStore(s).n}</span>;
    }
    const root = mountPoint();
    render(<Show />, root); // not in act(): the effect that subscribes runs after the next frame
    expect(root.textContent).toBe('1');
    s.set({ n: 2 }); // nobody listens yet
    await act(async () => {
      await new Promise((r) => setTimeout(r, 150));
    });
    expect(root.textContent).toBe('2');
    act(() => s.set({ n: 3 }));
    expect(root.textContent).toBe('3');
    unmount(root);
  });
});
