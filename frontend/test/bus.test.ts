// The bus view model (system/bus.ts): the EtherCAT figures, banners and SubDevice rows from
// `GET /bus`, the drives the Configuration page offers, and the SDO tool's parsing and display.
import { describe, expect, it } from 'vitest';
import { emulated, simulated, strictDrive, sub } from './bus-fixture';
import {
  busBanner,
  busCounters,
  busState,
  busTitle,
  cia402Unavailable,
  driveOptions,
  firstFreeDrive,
  hex,
  mappingView,
  nsAsUs,
  parseSdoAddress,
  parseSdoValue,
  refusedView,
  resetUnavailable,
  sdoPath,
  sdoView,
  sentence,
  subDeviceRows,
  txrxView,
} from '../src/system/bus';

describe('the EtherCAT bus as shown', () => {
  it('hex as TwinCAT writes it: 0x1000, 0x00FF0ACE; a negative int32 as its bit pattern', () => {
    expect(hex(0x1000, 4)).toBe('0x1000');
    expect(hex(16714446, 8)).toBe('0x00FF0ACE');
    expect(hex(-2, 8)).toBe('0xFFFFFFFE');
    expect(hex(null, 4)).toBe('—');
  });

  it('the SubDevices by position: address, identity in hex, serial, AL state with its LED, process data, DC, axis', () => {
    const rows = subDeviceRows(emulated({ subdevices: [sub(1, 'y', { al_state: 'safe_op' }), sub(0, 'x'), sub(2, null, { drive: null, dc: false })] }));
    expect(rows.map((r) => r.position)).toEqual([0, 1, 2]);
    expect(rows[0]).toEqual({
      position: 0,
      address: '0x1000',
      name: 'motiond emulated servo 1',
      vendor: '0x00FF0ACE',
      product: '0x04020001',
      revision: '0x00010000',
      serial: '539361280',
      al: { state: 'op', label: 'OP', tone: 'green' },
      mapping: 'full · 15 B out, 29 B in',
      process: { mapping: 'full', tone: 'green', bytes: '15 B out, 29 B in', missing: [], refused: [] },
      dc: true,
      axis: 'x',
    });
    expect(rows[1].al).toEqual({ state: 'safe_op', label: 'SAFE-OP', tone: 'amber' });
    expect(rows[2]).toMatchObject({ address: '0x1002', mapping: null, process: null, dc: false, axis: null });
  });

  it('a drive that refused the full mapping at SAFE-OP: the mapping taken (amber), the objects it lacks in upper-case hex, the AL status code apart from its meaning', () => {
    expect(mappingView(strictDrive())).toEqual({
      mapping: 'available',
      tone: 'amber',
      bytes: '13 B out, 17 B in',
      missing: ['0x60B8', '0x60B9', '0x60BA', '0x60BB', '0x60FD'],
      refused: [{ mapping: 'full', at: 'PRE-OP to SAFE-OP', code: '0x001D', meaning: 'Invalid Output Configuration' }],
    });
    // refused by an SDO abort of the mapping write: no AL status code, the SDO error as it is
    expect(refusedView({ mapping: 'full', at: 'PDO mapping write', al_status_code: null, reason: 'SDO abort 0x06090030: value range exceeded' })).toEqual({
      mapping: 'full',
      at: 'PDO mapping write',
      code: null,
      meaning: 'SDO abort 0x06090030: value range exceeded',
    });
    // a reason that does not start with its code is kept whole
    expect(refusedView({ mapping: 'available', at: 'PRE-OP to SAFE-OP', al_status_code: '0x001e', reason: 'Invalid Input Configuration' }).meaning).toBe('Invalid Input Configuration');
    // an older server without the fields: nothing missing, nothing refused
    expect(mappingView({ mapping: 'minimal', output_bytes: 7, input_bytes: 11 } as never)).toMatchObject({ tone: 'amber', missing: [], refused: [] });
  });

  it("motiond's TX/RX loop: running or stopped with its LED, restarts, the thread's scheduling; none on the simulated bus", () => {
    expect(txrxView(emulated())).toEqual({ running: true, label: 'running', tone: 'green', restarts: '0', thread: 'SCHED_FIFO 79, pinned to CPU 0' });
    expect(txrxView(emulated({ txrx: { running: false, restarts: 1234, thread: 'normal priority (SCHED_FIFO refused: EPERM)' } }))).toEqual({
      running: false,
      label: 'stopped',
      tone: 'red',
      restarts: '1,234',
      thread: 'normal priority (SCHED_FIFO refused: EPERM)',
    });
    expect(txrxView(simulated)).toBeNull();
  });

  it('Reset bus: not on the simulated bus, not while a reset runs, not offline, the engineer role', () => {
    const can = { busy: false, engineer: true, online: true };
    expect(resetUnavailable(emulated(), can)).toBeNull();
    expect(resetUnavailable(simulated, can)).toBe('motiond runs the simulated bus: there is no EtherCAT segment to reset');
    expect(resetUnavailable(null, can)).toBe('the bus is not read yet');
    expect(resetUnavailable(emulated(), { ...can, busy: true })).toBe('the bus is being reset');
    expect(resetUnavailable(emulated(), { ...can, online: false })).toBe('motiond is not reachable');
    expect(resetUnavailable(emulated(), { ...can, engineer: false })).toBe('resetting the bus needs the engineer role');
  });

  it('title and state', () => {
    expect(busTitle(emulated())).toBe('EtherCAT (emulated segment)');
    expect(busTitle({ kind: 'ethercat', interface: 'enp3s0' })).toBe('EtherCAT on enp3s0');
    expect(busTitle(simulated)).toBe('Simulated bus');
    expect(busState('op')).toEqual({ label: 'OP', tone: 'green' });
    expect(busState('faulted')).toEqual({ label: 'faulted', tone: 'red' });
    expect(busState('degraded').tone).toBe('amber');
  });

  it('the counters: lost, late, duplicate and malformed frames, bus faults and WKC errors since start amber when any; red what is wrong now (working counter, errors in a row at the max)', () => {
    const ok = Object.fromEntries(busCounters(emulated()).map((c) => [c.key, [c.value, c.tone]]));
    expect(ok).toEqual({
      frames: ['120,345', undefined],
      lost_frames: ['0', 'ok'],
      late_replies: ['0', 'ok'],
      duplicate_replies: ['0', 'ok'],
      malformed_frames: ['0', 'ok'],
      faults: ['0', 'ok'],
      working_counter_errors: ['0', 'ok'],
      working_counter: ['9 / 9', 'ok'],
      errors_in_row: ['0 / 3', 'ok'],
      dc_cycle_offset: ['12.3 µs', undefined],
    });
    const bad = Object.fromEntries(
      busCounters(emulated({ lost_frames: 6, faults: 1, working_counter_errors: 2, last_working_counter: 6, errors_in_row: 1 })).map((c) => [c.key, [c.value, c.tone]]),
    );
    expect(bad.lost_frames).toEqual(['6', 'warn']);
    expect(bad.faults).toEqual(['1', 'warn']);
    expect(busCounters(emulated()).map((c) => c.label).slice(1, 7)).toEqual(['Lost frames', 'Late replies', 'Duplicate replies', 'Malformed frames', 'Bus faults', 'WKC errors']);
    const disturbed = Object.fromEntries(busCounters(emulated({ late_replies: 1200, duplicate_replies: 3, malformed_frames: 1 })).map((c) => [c.key, [c.value, c.tone]]));
    expect([disturbed.late_replies, disturbed.duplicate_replies, disturbed.malformed_frames]).toEqual([
      ['1,200', 'warn'],
      ['3', 'warn'],
      ['1', 'warn'],
    ]);
    // the lost frames' title names the PDU timeout
    expect(busCounters(emulated()).find((c) => c.key === 'lost_frames')!.title).toMatch(/within the PDU timeout \(10 ms\)/);
    expect(bad.working_counter_errors).toEqual(['2', 'warn']);
    expect(bad.working_counter).toEqual(['6 / 9', 'bad']);
    expect(bad.errors_in_row).toEqual(['1 / 3', 'warn']);
    expect(busCounters(emulated({ errors_in_row: 3 })).find((c) => c.key === 'errors_in_row')!.tone).toBe('bad');
    expect(nsAsUs(null)).toBe('—');
  });

  it('a banner when faulted (the enabled EtherCAT axes stopped until reset, the bus clears itself) or degraded (which SubDevice is not in OP); none when running, also after faults', () => {
    expect(busBanner(emulated())).toBeNull();
    expect(busBanner(emulated({ faults: 2, lost_frames: 20 }))).toBeNull();
    expect(busBanner(simulated)).toBeNull();
    const f = busBanner(emulated({ state: 'faulted' }))!;
    expect(f.tone).toBe('error');
    expect(f.title).toBe('Bus faulted');
    expect(f.text).toBe(
      '3 lost frames or wrong working counters in a row: the enabled EtherCAT axes were stopped (ErrorStop 0x70A0 bus_error) and stay in ErrorStop until they are reset (MC_Reset). ' +
        'The bus clears by itself after 3 good frames in a row.',
    );
    // the server's reason leads
    expect(busBanner(emulated({ state: 'faulted', fault_reason: '3 frames lost or with a wrong working counter in a row' }))!.text).toBe(
      '3 frames lost or with a wrong working counter in a row: the enabled EtherCAT axes were stopped (ErrorStop 0x70A0 bus_error) and stay in ErrorStop until they are reset (MC_Reset). ' +
        'The bus clears by itself after 3 good frames in a row.',
    );
    // the TX/RX loop stopped: it does not clear by itself; Reset bus starts it again
    const t = busBanner(emulated({ state: 'faulted', fault_reason: 'the TX/RX loop was stopped (injected fault)', txrx: { running: false, restarts: 0, thread: 'SCHED_FIFO 79, pinned to CPU 0' } }))!;
    expect(t).toEqual({
      tone: 'error',
      title: 'Bus faulted',
      text:
        'The TX/RX loop was stopped (injected fault). No frame goes out: the enabled EtherCAT axes were stopped (ErrorStop 0x70A0 bus_error) and stay in ErrorStop until they are reset (MC_Reset). ' +
        "Reset bus (or an axis's MC_Reset) starts the TX/RX loop again and asks the SubDevices back to OP.",
    });
    expect(sentence('socket closed: EIO.')).toBe('Socket closed: EIO.');
    const d = busBanner(emulated({ state: 'degraded', subdevices: [sub(0, 'x'), sub(1, 'y', { al_state: 'safe_op' })] }))!;
    expect(d).toEqual({ tone: 'warn', title: 'Bus degraded', text: 'SubDevice 1 (motiond emulated servo 2, axis y) in SAFE-OP not in OP: its axis is stopped when enabled. Powering on or resetting the axis asks its SubDevice back to OP.',
    });
  });
});

describe('the drives the Configuration page offers', () => {
  it('CiA-402 only on an EtherCAT bus (an unknown bus: the server judges)', () => {
    expect(cia402Unavailable(simulated)).toBe('motiond runs the simulated bus; start motiond with --bus ethercat --interface IFACE, or --bus emulated.');
    expect(cia402Unavailable(emulated())).toBeNull();
    expect(cia402Unavailable(null)).toBeNull();
  });

  it('the drives by position with name and user; the axis’s own position also when the bus has no drive there', () => {
    const b = emulated({ subdevices: [sub(1, 'y'), sub(0, 'x'), sub(2, null), sub(3, null, { drive: null })] });
    expect(driveOptions(b, 'x', 0)).toEqual([
      { position: 0, label: '0 · motiond emulated servo 1 — axis x', axis: 'x' },
      { position: 1, label: '1 · motiond emulated servo 2 — used by y', axis: 'y' },
      { position: 2, label: '2 · motiond emulated servo 3 — free', axis: null },
    ]);
    expect(firstFreeDrive(driveOptions(b, null, null))).toBe(2);
    expect(driveOptions(b, 'z', 7).map((o) => o.label)).toContain('7 · no CiA-402 drive there on the bus');
    expect(driveOptions(null, 'z', 7)).toEqual([{ position: 7, label: '7 · bus not read', axis: 'z' }]);
    expect(firstFreeDrive(driveOptions(emulated({ subdevices: [sub(0, 'x')] }), null, null))).toBeNull();
  });
});

describe('SDO', () => {
  it('the address as typed: hex with 0x or decimal; the subindex whole', () => {
    expect(parseSdoAddress('0x1018', '1')).toEqual({ index: '0x1018', sub: 1, errors: {} });
    expect(parseSdoAddress(' 4120 ', '0x01')).toEqual({ index: '4120', sub: 1, errors: {} });
    expect(parseSdoAddress('', '').errors).toEqual({ index: 'required', sub: 'required' });
    expect(parseSdoAddress('1018h', '1.5').errors).toEqual({ index: 'hex like 0x1018, or decimal', sub: 'a whole number ≥ 0' });
    expect(sdoPath(2, '0x1018', 1)).toBe('/bus/subdevices/2/sdo/0x1018/1');
  });

  it('a value to write: decimal or 0x hex with a sign; anything else is none', () => {
    expect(parseSdoValue('20000')).toBe(20000);
    expect(parseSdoValue('0x4E20')).toBe(20000);
    expect(parseSdoValue('-3')).toBe(-3);
    expect(parseSdoValue('-0x10')).toBe(-16);
    expect(parseSdoValue('')).toBeNull();
    expect(parseSdoValue('1.5')).toBeNull();
    expect(parseSdoValue('ten')).toBeNull();
  });

  it('an answer: the address, the integer in hex as wide as the object, unsigned, signed, text, the bytes as sent', () => {
    expect(sdoView({ position: 0, index: '0x1018', sub: 1, bytes: [206, 10, 255, 0], hex: 'ce0aff00', unsigned: 16714446, signed: 16714446, text: null })).toEqual({
      address: '0x1018:01',
      bytes: 'ce 0a ff 00',
      value: '0x00FF0ACE',
      unsigned: '16714446',
      signed: '16714446',
      text: null,
    });
    expect(sdoView({ position: 0, index: '0x60c2', sub: 2, bytes: [253], hex: 'fd', unsigned: 253, signed: -3, text: null })).toMatchObject({ address: '0x60C2:02', value: '0xFD', signed: '-3' });
    const name = [...'motiond emulated servo 1'].map((c) => c.charCodeAt(0));
    const v = sdoView({ position: 0, index: '0x1008', sub: 0, bytes: name, hex: '', unsigned: null, signed: null, text: 'motiond emulated servo 1' });
    expect(v).toMatchObject({ value: null, unsigned: null, signed: null, text: 'motiond emulated servo 1' });
  });
});
