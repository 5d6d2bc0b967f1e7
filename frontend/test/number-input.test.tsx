// A number field whose text is not a number: said in words beside the field ("enter a number"),
// never sent — before, "abc" went to the server as null and serde's "invalid type: null,
// expected f64" came back.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { useState } from 'preact/hooks';
import { act } from 'preact/test-utils';
import { mountPoint, unmount, enter } from './dom';
import { ApiError, NotSentError, nonFiniteFields } from '../src/api/problem';
import { api } from '../src/api/client';
import { Field, NumberInput, fieldsOf, isNumberText, parseNum } from '../src/ui/shared/common';

afterEach(() => vi.unstubAllGlobals());

describe('the REST client sends no number that is not one', () => {
  it('names the JSON paths of NaN and infinite numbers', () => {
    expect(nonFiniteFields({ velocity: NaN, position: 1, masters: [{ master: 'x', gear_ratio: 1 }, { master: 'y', gear_ratio: Infinity }], o: { a: { b: NaN } } })).toEqual([
      'velocity',
      'masters[1].gear_ratio',
      'o.a.b',
    ]);
    expect(nonFiniteFields({ a: null, b: 'abc', c: [1, 2] })).toEqual([]);
  });

  it('refuses the request before fetch: a 422 made here with "enter a number" at the field', async () => {
    const fetch = vi.fn(async () => new Response('{}', { status: 200 }));
    vi.stubGlobal('fetch', fetch);
    const move = (position: number) => api.POST('/api/v1/axes/{axis}/move-absolute', { params: { path: { axis: 'x' } }, body: { position, velocity: 10 } });
    const e = await move(parseNum('abc')).catch((x) => x);
    expect(e).toBeInstanceOf(NotSentError);
    expect(e).toBeInstanceOf(ApiError);
    expect((e as ApiError).status).toBe(422);
    expect(fieldsOf(e)).toEqual({ position: 'enter a number' });
    await expect(api.PUT('/api/v1/axes/{axis}/parameters/{parameter}', { params: { path: { axis: 'x', parameter: '1001' } }, body: { value: NaN } })).rejects.toBeInstanceOf(NotSentError);
    expect(fetch).not.toHaveBeenCalled();
    await move(parseNum('1,5'));
    expect(fetch).toHaveBeenCalledTimes(1);
  });

  it('what a number is', () => {
    expect(['1', '-2.5', '1,5', ' 3 ', '1e3', '0x10'].map(isNumberText)).toEqual([true, true, true, true, true, true]);
    expect(['', 'abc', '-', '1.2.3', 'Infinity', 'NaN'].map(isNumberText)).toEqual([false, false, false, false, false, false]);
  });
});

function Form() {
  const [v, setV] = useState('');
  return (
    <Field label="Velocity" name="velocity">
      <NumberInput name="velocity" value={v} onValue={setV} />
    </Field>
  );
}

describe('NumberInput', () => {
  it('says "enter a number" beside the field once it is left with a text that is not a number', () => {
    const root = mountPoint();
    act(() => render(<Form />, root));
    const input = root.querySelector('input[name="velocity"]') as HTMLInputElement;
    const said = () => root.querySelector('[data-field="velocity"] .num-error')?.textContent ?? null;
    act(() => void input.dispatchEvent(new FocusEvent('focus')));
    enter(input, '-');
    expect(said()).toBe(null); // typing on the way to "-5": nothing flickers
    enter(input, 'abc');
    expect(input.getAttribute('aria-invalid')).toBe('true');
    act(() => void input.dispatchEvent(new FocusEvent('blur')));
    expect(said()).toBe('enter a number');
    enter(input, '12');
    expect(said()).toBe(null);
    expect(input.getAttribute('aria-invalid')).toBe(null);
    enter(input, '');
    expect(said()).toBe(null);
    unmount(root);
  });
});
