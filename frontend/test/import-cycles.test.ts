// @vitest-environment node
// No import cycles in the UI's code (issue 23: `ui/coupling ↔ ui/coupling-blocks` was one): the
// relative import/export-from statements of every .ts/.tsx under src/ form no loop. A failure
// names each loop as a path, e.g. `ui/axis/coupling.tsx → ui/axis/coupling-blocks.tsx → ui/axis/coupling.tsx`.
import { describe, expect, it } from 'vitest';
import { fileURLToPath } from 'node:url';
import { findCycles, importGraph, relativeImports, type Graph } from './import-graph';

const SRC = fileURLToPath(new URL('../src', import.meta.url));

describe('the import graph of src/', () => {
  it('has no cycle', () => {
    const g = importGraph(SRC);
    // The graph is read at all: every module, and the imports among them.
    expect(g.size).toBeGreaterThan(50);
    expect(g.get('main.tsx')).toContain('ui/shell/root.tsx');
    const cycles = findCycles(g);
    expect(cycles, `import cycles under src/:\n  ${cycles.join('\n  ')}`).toEqual([]);
  });
});

describe('what the check reads and finds', () => {
  it('import, import type, side-effect import and export … from; not a dynamic import, a package or a comment', () => {
    const text = [
      "import { a } from './a';",
      "import type { B } from '../b';",
      "import './c.css';",
      'import {',
      '  d,',
      "} from './d';",
      "export { e } from './e';",
      "export * from './f';",
      "import { h } from 'preact/hooks';",
      "// import { x } from './commented';",
      "const lazy = () => import('./lazy');",
    ].join('\n');
    expect(relativeImports('m.ts', text)).toEqual(['./a', '../b', './c.css', './d', './e', './f']);
  });

  it('names every loop by a path through it, shortest first from its first module', () => {
    const g: Graph = new Map([
      ['ui/a.tsx', new Set(['ui/b.tsx', 'store.ts'])],
      ['ui/b.tsx', new Set(['ui/c.tsx'])],
      ['ui/c.tsx', new Set(['ui/a.tsx'])],
      ['store.ts', new Set<string>()],
      ['x.ts', new Set(['y.ts'])],
      ['y.ts', new Set(['x.ts'])],
      ['self.ts', new Set(['self.ts'])],
    ]);
    expect(findCycles(g)).toEqual(['self.ts → self.ts', 'ui/a.tsx → ui/b.tsx → ui/c.tsx → ui/a.tsx', 'x.ts → y.ts → x.ts']);
    expect(findCycles(new Map([['a.ts', new Set(['b.ts'])], ['b.ts', new Set<string>()]]))).toEqual([]);
  });
});
