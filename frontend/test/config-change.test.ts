// What a configuration save does, in words (the server's ConfigChange), and which fields run
// with or keep other values than the configured ones.
import { describe, expect, it } from 'vitest';
import {
  type ConfigChange,
  changeRows,
  changeSummary,
  differingFields,
  lostOnlineValues,
  positionText,
  rebuildBlockedText,
  sameValue,
  sideText,
  sideValues,
} from '../src/config/change';
import type { ParameterResource } from '../src/api/types';

const change = (c: Partial<ConfigChange> = {}): ConfigChange => ({
  dry_run: true,
  rebuild: false,
  rebuild_reasons: [],
  parameters: [],
  persistent_discarded: [],
  ...c,
});
const slow = { name: 'AxisVeloManSlow', number: 1001, configured: 10, online: 10, new: 20 };
const vmax = { name: 'AxisVeloMax', number: 1003, configured: 500, online: 650, new: 700 };
const vmaxPersistent = { name: 'AxisVeloMax', number: 1003, configured: 500, online: 650, new: 800 };

describe('changeSummary', () => {
  it('a dry run without rebuild: what is written online, and that nothing is reset', () => {
    expect(changeSummary(change({ parameters: [slow] }))).toEqual({
      tone: 'ok',
      headline: 'This save changes 1 parameter online; nothing is reset.',
      persistent: null,
    });
    expect(changeSummary(change({ parameters: [slow, vmax] })).headline).toBe('This save changes 2 parameters online; nothing is reset.');
    expect(changeSummary(change()).headline).toBe('This save changes no parameter; nothing is reset.');
  });

  it('a dry run with rebuild: the reasons, the position now and what is lost', () => {
    const s = changeSummary(change({ rebuild: true, rebuild_reasons: ['unit changed', 'drive changed'] }), { unit: 'mm', position: 199.99999999 });
    expect(s.tone).toBe('warn');
    expect(s.headline).toBe('The axis will be re-created (unit changed, drive changed): its position (now 200 mm), homed state and online values are lost.');
    // position unknown (stale status): not guessed
    expect(changeSummary(change({ rebuild: true, rebuild_reasons: ['modulo changed'] }), { unit: 'mm', position: null }).headline).toBe(
      'The axis will be re-created (modulo changed): its position, homed state and online values are lost.',
    );
  });

  it('the persistent values a save gives up, before and after', () => {
    const c = change({ parameters: [vmax], persistent_discarded: [vmaxPersistent] });
    expect(changeSummary(c).persistent).toBe('1 persistent value will be discarded (AxisVeloMax 800): the configured value replaces it.');
    expect(changeSummary({ ...c, dry_run: false }).persistent).toBe('1 persistent value discarded (AxisVeloMax 800).');
  });

  it('the answer of the real save says what happened', () => {
    expect(changeSummary(change({ dry_run: false, parameters: [slow] })).headline).toBe('Saved. 1 parameter changed online; nothing was reset.');
    expect(changeSummary(change({ dry_run: false })).headline).toBe('Saved. No parameter changed; nothing was reset.');
    const r = changeSummary(change({ dry_run: false, rebuild: true, rebuild_reasons: ['unit changed'] }));
    expect(r).toMatchObject({ tone: 'warn', headline: 'Saved. The axis was re-created (unit changed): its position, homed state and online values were reset.' });
  });
});

describe('changeRows', () => {
  it('configured → new, the online value only where it differs', () => {
    expect(changeRows([slow, vmax, { name: 'AxisEnMaxSoftPosLimit', number: 1018, configured: true, online: true, new: false }])).toEqual([
      { name: 'AxisVeloManSlow', number: 1001, configured: '10', next: '20', online: null },
      { name: 'AxisVeloMax', number: 1003, configured: '500', next: '700', online: '650' },
      { name: 'AxisEnMaxSoftPosLimit', number: 1018, configured: 'true', next: 'false', online: null },
    ]);
  });
});

const p = (number: number, name: string, value: number, configured: number | null, persistent?: number, extra: Partial<ParameterResource> = {}) =>
  ({ number, name, storage: number, read_only: false, group: 'dynamics', value, configured_value: configured, persistent_value: persistent, ...extra }) as ParameterResource;

describe('side-by-side values', () => {
  it('only the values that differ from the configured one', () => {
    expect(sideValues(p(1003, 'AxisVeloMax', 650, 500, 800))).toEqual({ online: '650', persistent: '800' });
    expect(sideValues(p(1003, 'AxisVeloMax', 800, 500, 800))).toEqual({ online: '800', persistent: '800' });
    expect(sideValues(p(1003, 'AxisVeloMax', 650, 500))).toEqual({ online: '650', persistent: null });
    // a persistent value equal to the configured one, in force: nothing to say
    expect(sideValues(p(1003, 'AxisVeloMax', 500, 500, 500))).toBeNull();
    expect(sideValues(p(1003, 'AxisVeloMax', 500, 500))).toBeNull();
    // float noise is no difference
    expect(sideValues(p(1001, 'AxisVeloManSlow', 0.1 + 0.2, 0.3))).toBeNull();
    expect(sideValues(p(1001, 'AxisVeloManSlow', 1, null))).toBeNull();
    expect(sideValues(undefined)).toBeNull();
  });

  it('as text', () => {
    expect(sideText({ online: '650', persistent: '800' })).toBe('online 650 · persistent 800');
    expect(sideText({ online: null, persistent: '800' })).toBe('persistent 800');
    expect(sideText({ online: '650', persistent: null })).toBe('online 650');
    expect(sideText(null)).toBe('');
  });

  it('which configuration fields differ, by field path', () => {
    const m = new Map(
      [
        p(1003, 'AxisVeloMax', 650, 500, 800),
        p(1004, 'AxisAcc', 2500, 2500),
        p(1001, 'AxisVeloManSlow', 10, 10, 12),
        p(1019, 'AxisMaxSoftPosLimit', 900, 1000),
        p(1014, 'AxisJogIncrementForward', 5, 1), // no configuration field
      ].map((x) => [x.number, x]),
    );
    expect(differingFields(m)).toEqual({
      'dynamics.max_velocity': { online: '650', persistent: '800' },
      'dynamics.jog_velocity_slow': { online: null, persistent: '12' },
      'soft_limits.max': { online: '900', persistent: null },
    });
    expect(differingFields(null)).toEqual({});
  });

  it('sameValue compares what the UI shows', () => {
    expect(sameValue(1, 1)).toBe(true);
    expect(sameValue(0.1 + 0.2, 0.3)).toBe(true);
    expect(sameValue(1, 2)).toBe(false);
    expect(sameValue(true, true)).toBe(true);
    expect(sameValue(true, 1)).toBe(false);
    expect(sameValue(null, undefined)).toBe(false);
  });
});

describe('lostOnlineValues', () => {
  const params = [
    p(1003, 'AxisVeloMax', 650, 500, 800),
    p(9, 'MaxVelocityAppl', 650, 500, 800, { storage: 1003 }), // an alias: once, under its entry
    p(1014, 'AxisJogIncrementForward', 2, 1, 2),
    p(1015, 'AxisJogIncrementBackward', 3, 1),
    p(1004, 'AxisAcc', 2000, 2500, 2200),
    p(1, 'CommandedPosition', 200, null, undefined, { group: 'status', read_only: true, storage: 0 }),
  ];

  it('the online values that differ from what the re-created axis starts with', () => {
    expect(lostOnlineValues(params, change({ rebuild: true }))).toEqual([
      { name: 'AxisVeloMax', number: 1003, online: '650', after: '800', from: 'persistent' },
      { name: 'AxisAcc', number: 1004, online: '2000', after: '2200', from: 'persistent' },
      { name: 'AxisJogIncrementBackward', number: 1015, online: '3', after: '1', from: 'configured' },
    ]);
  });

  it('a parameter the save changes is listed with the changes, not here; a discarded persistent value does not come back', () => {
    const c = change({ rebuild: true, parameters: [vmax], persistent_discarded: [vmaxPersistent, { name: 'AxisAcc', number: 1004, configured: 2500, online: 2000, new: 2200 }] });
    expect(lostOnlineValues(params, c).map((l) => [l.name, l.after, l.from])).toEqual([
      ['AxisAcc', '2500', 'configured'],
      ['AxisJogIncrementBackward', '1', 'configured'],
    ]);
  });

  it('nothing without a rebuild, or without the parameters', () => {
    expect(lostOnlineValues(params, change())).toEqual([]);
    expect(lostOnlineValues(null, change({ rebuild: true }))).toEqual([]);
  });
});

describe('rebuildBlockedText and positionText', () => {
  const label = (s: string) => ({ standstill: 'Standstill', error_stop: 'ErrorStop', disabled: 'Disabled' })[s] ?? s;
  it('blocks a rebuild of an enabled axis or one not Disabled; an unknown status is the server’s to judge', () => {
    expect(rebuildBlockedText({ state: 'standstill', power_status: true }, label)).toBe('Save is blocked: re-creating the axis needs it disabled, and it is enabled.');
    expect(rebuildBlockedText({ state: 'error_stop', power_status: false }, label)).toBe(
      'Save is blocked: re-creating the axis needs it Disabled, and it is in ErrorStop (reset it).',
    );
    expect(rebuildBlockedText({ state: 'disabled', power_status: false }, label)).toBeNull();
    expect(rebuildBlockedText(null, label)).toBeNull();
  });

  it('positions to 3 decimals with the unit', () => {
    expect(positionText(200.00004, 'mm')).toBe('200 mm');
    expect(positionText(-12.3456, 'deg')).toBe('-12.346 deg');
    expect(positionText(Number.NaN, 'mm')).toBeNull();
    expect(positionText(null, 'mm')).toBeNull();
  });
});
