// Mounting components in the happy-dom document for the DOM-level tests.
import { render } from 'preact';
import { act } from 'preact/test-utils';

/** A fresh element in the document to render into. */
export function mountPoint(): HTMLElement {
  const root = document.createElement('div');
  document.body.appendChild(root);
  return root;
}

/** Unmounts what was rendered into `root` (its effects cleaned up) and removes it. */
export function unmount(root: HTMLElement): void {
  act(() => render(null, root));
  root.remove();
}
