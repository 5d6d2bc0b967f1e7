// A bus as `GET /api/v1/bus` answers it: the emulated segment of the demo machine (three
// CiA-402 drives, x and y on the first two), and the simulated bus.
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
  drive: { mapping: 'full', output_bytes: 15, input_bytes: 29 },
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
  lost_frames: 0,
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

export const simulated: BusResource = { ...emulated(), kind: 'simulated', interface: null, state: 'simulated', subdevices: [], dc_cycle_offset_ns: null };
