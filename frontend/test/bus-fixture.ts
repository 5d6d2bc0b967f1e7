// A bus as `GET /api/v1/bus` answers it: the emulated segment of the demo machine (three
// CiA-402 drives, x and y on the first two), a drive that refused the full mapping at SAFE-OP,
// and the simulated bus.
import type { BusResource, SubDeviceResource } from '../src/api/types';

export const sub = (position: number, axis: string | null, p: Partial<SubDeviceResource> = {}): SubDeviceResource => ({
  position,
  configured_address: 0x1000 + position,
  name: `motiond emulated servo ${position + 1}`,
  vendor_id: 0xff0ace,
  product_code: 0x04020001,
  revision: 0x00010000,
  serial: 539361280 + position,
  al_state: 'op',
  drive: { mapping: 'full', output_bytes: 15, input_bytes: 29, missing_objects: [], refused: [] },
  dc: true,
  axis,
  ...p,
});

export const emulated = (p: Partial<BusResource> = {}): BusResource => ({
  kind: 'emulated',
  interface: 'emulated',
  cycle_time: 0.001,
  state: 'op',
  frames: 120345,
  fault_reason: null,
  lost_frames: 0,
  late_replies: 0,
  duplicate_replies: 0,
  malformed_frames: 0,
  pdu_timeout: 0.01,
  txrx: { running: true, restarts: 0, thread: 'SCHED_FIFO 79, pinned to CPU 0' },
  working_counter_errors: 0,
  faults: 0,
  errors_in_row: 0,
  max_errors_in_row: 3,
  expected_working_counter: 9,
  last_working_counter: 9,
  dc_system_time_ns: 123456789000,
  dc_cycle_offset_ns: 12345,
  subdevices: [sub(1, 'y'), sub(0, 'x'), sub(2, null)],
  ...p,
});

export const simulated: BusResource = { ...emulated(), kind: 'simulated', interface: null, state: 'simulated', subdevices: [], dc_cycle_offset_ns: null, txrx: null };

/** A drive like many not written by motiond's authors: no touch probe or digital inputs; it refused the full mapping at SAFE-OP. */
export const strictDrive = (): NonNullable<SubDeviceResource['drive']> => ({
  mapping: 'available',
  output_bytes: 13,
  input_bytes: 17,
  missing_objects: ['0x60b8', '0x60b9', '0x60ba', '0x60bb', '0x60fd'],
  refused: [{ mapping: 'full', at: 'PRE-OP to SAFE-OP', al_status_code: '0x001d', reason: '0x001d: Invalid Output Configuration' }],
});
