//! The EtherCAT drive bus: the cycle thread's [`DriveBus`] on a segment of CiA-402 servo
//! drives through ethercrab. Bring-up ([`EthercatBus::start`], off the cycle thread): discovery
//! and identity, the PRE-OP CoE script per drive (PDO mapping and assignment, interpolation
//! period, SYNC0 mode), distributed clocks with SYNC0 at the cycle time, SAFE-OP → OP. Then one
//! `tx_rx_dc` per cycle in [`DriveBus::exchange`]: the kernel's setpoints through
//! `drives::cia402` into each drive's RxPDO, its TxPDO back into feedback. Lost frames and
//! wrong working counters are counted; `max_errors_in_row` of them in a row, or a SubDevice
//! that leaves OP, flag the axes' feedback with `bus_error` (the kernel stops them on their
//! ramp into ErrorStop, 0x70A0, latched there until MC_Reset); as many good frames in a row
//! clear the bus, and a power-on or reset edge of an axis asks its SubDevice back to OP.
//! Up to 64 SubDevices and 4 KB of process image: ethercrab sends it in as many frames as it
//! takes, and the expected working counter follows its split (`expected_working_counter`).

use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU16, AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use drives::cia402::{Cia402Drive, RxPdo, TxPdo};
use drives::{Drive, DriveBus, SimBus};
use ethercrab::subdevice_group::{DcConfiguration, HasDc, Op};
use ethercrab::{
    DcSync, MainDevice, MainDeviceConfig, PduStorage, RegisterAddress, RetryBehaviour,
    SubDeviceGroup, SubDeviceState, Timeouts,
};
use futures_lite::future::block_on;
use motion::{DriveFeedback, DriveSetpoint};

use crate::emu::Segment;
use crate::txrx::{self, LinkState, Opener, RawWire, SegmentWire, Wire};

/// SubDevices on one segment (a power of two, as ethercrab wants): 64 servos, or fewer with
/// their I/O terminals.
pub const MAX_SUBDEVICES: usize = 64;
/// Bytes of process image of the whole group: 64 drives with the full mapping (56 bytes
/// each) and room for terminals. ethercrab sends it in as many frames as it needs.
pub const MAX_PDI: usize = 4096;
const MAX_FRAMES: usize = 16;
/// Data of one frame's single PDU (an Ethernet frame carries up to 1498 bytes of PDUs):
/// ethercrab's storage adds the headers and the working counter of one PDU to it.
const PDU_PAYLOAD: usize = 1100;
const MAX_PDU_DATA: usize = PduStorage::element_size(PDU_PAYLOAD);
/// The FRMW of the reference clock's system time that ethercrab puts before the first chunk
/// of a DC group's process image: a PDU's header and working counter (12) and 8 bytes.
const DC_TIME_PDU: usize = 12 + 8;

/// The working counter of one whole exchange. ethercrab lays the process image out as all
/// SubDevices' inputs, then all their outputs, in bus order, and sends it in LRWs of at most
/// `PDU_PAYLOAD` bytes (the first one shorter by the DC time's PDU): each LRW
/// counts 1 for every SubDevice whose inputs it touches and 2 for every SubDevice whose
/// outputs it writes, so a SubDevice whose image straddles two frames counts in both.
/// `io`: (input, output) bytes of each SubDevice, in bus order.
fn expected_working_counter(io: &[(usize, usize)], dc: bool) -> u16 {
    // (start, end, weight) of every SubDevice's inputs, then outputs, in the image.
    let mut ranges = Vec::with_capacity(2 * io.len());
    let mut at = 0;
    for &(inputs, _) in io {
        ranges.push((at, at + inputs, 1u16));
        at += inputs;
    }
    for &(_, outputs) in io {
        ranges.push((at, at + outputs, 2u16));
        at += outputs;
    }
    let total = at;
    let mut wkc = 0;
    let (mut start, mut first) = (0, true);
    while start < total {
        let room = PDU_PAYLOAD - if dc && first { DC_TIME_PDU } else { 0 };
        let end = (start + room).min(total);
        wkc += ranges
            .iter()
            .filter(|&&(a, b, _)| a < b && a < end && b > start)
            .map(|r| r.2)
            .sum::<u16>();
        (start, first) = (end, false);
    }
    wkc
}

type DcGroup = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, ethercrab::DefaultLock, Op, HasDc>;
type FreeGroup = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, ethercrab::DefaultLock, Op>;

/// The group in OP: with distributed clocks (SYNC0, the usual case for servo drives), or
/// free-running when no SubDevice has a DC unit (then each exchange is a plain `tx_rx` and
/// the drives take their setpoints when the frame passes).
enum Group {
    Dc(DcGroup),
    Free(FreeGroup),
}

/// What one exchange read: working counter, AL states, and with DC the reference's time and
/// the frame's offset in the SYNC0 period.
struct Exchanged {
    working_counter: u16,
    states: heapless::Vec<SubDeviceState, MAX_SUBDEVICES>,
    dc: Option<(u64, u64)>,
}

impl Group {
    fn subdevice<'g>(
        &'g self,
        md: &'static MainDevice<'static>,
        i: usize,
    ) -> Result<
        ethercrab::SubDeviceRef<
            'static,
            ethercrab::SubDevicePdi<'g, MAX_PDI, ethercrab::DefaultLock>,
        >,
        ethercrab::error::Error,
    > {
        match self {
            Group::Dc(g) => g.subdevice(md, i),
            Group::Free(g) => g.subdevice(md, i),
        }
    }

    async fn exchange(
        &self,
        md: &'static MainDevice<'static>,
    ) -> Result<Exchanged, ethercrab::error::Error> {
        Ok(match self {
            Group::Dc(g) => {
                let r = g.tx_rx_dc(md).await?;
                Exchanged {
                    working_counter: r.working_counter,
                    states: r.subdevice_states,
                    dc: Some((
                        r.extra.dc_system_time,
                        r.extra.cycle_start_offset.as_nanos() as u64,
                    )),
                }
            }
            Group::Free(g) => {
                let r = g.tx_rx(md).await?;
                Exchanged {
                    working_counter: r.working_counter,
                    states: r.subdevice_states,
                    dc: None,
                }
            }
        })
    }
}

/// Where the frames go.
pub enum Link {
    /// A network interface (raw socket; `CAP_NET_RAW`).
    Interface(String),
    /// An emulated segment in this process.
    Emulated(Arc<Mutex<Segment>>),
}

#[derive(Clone, Debug)]
pub struct BusOptions {
    pub cycle: Duration,
    /// Lost frames or wrong working counters in a row before the bus faults its axes.
    pub max_errors_in_row: u32,
    /// How long one frame may take to come back (ethercrab has one timeout for the mailbox
    /// traffic of the bring-up and for the cyclic frames).
    pub pdu_timeout: Duration,
    /// Times a frame is sent again after a timeout before it counts as lost: the cycle thread
    /// never waits longer than (1 + retries) × `pdu_timeout` for the bus. Bring-up needs them
    /// (the first frames on a link that has just come up are lost now and then).
    pub retries: usize,
}

/// The PDU timeout for a cycle time: four cycles, at least 10 ms (the bring-up's mailbox
/// traffic on a loaded machine) and at most 30 ms (ethercrab's own default), so that a frame
/// and its two retries (3 × 30 ms) give up before the usual 100 ms SyncManager watchdog of a
/// drive trips (decision 120).
pub fn default_pdu_timeout(cycle: Duration) -> Duration {
    (cycle * 4).clamp(Duration::from_millis(10), Duration::from_millis(30))
}

impl BusOptions {
    pub fn new(cycle: Duration) -> BusOptions {
        BusOptions {
            cycle,
            max_errors_in_row: 3,
            pdu_timeout: default_pdu_timeout(cycle),
            retries: 2,
        }
    }
}

/// The objects of a drive's process data, by offset in its image (`None`: not mapped).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layout {
    pub name: &'static str,
    rx: [Option<usize>; 9],
    tx: [Option<usize>; 10],
    pub out_len: usize,
    pub in_len: usize,
    /// The drive's own 0x6081/0x6083/0x6084 as read at bring-up: sent while it runs a
    /// cyclic mode, so that a host-side axis leaves the ramps the drive uses for its halt,
    /// quick-stop and fault reactions as commissioned (a mapped object must carry a value).
    pub profile_defaults: [u32; 3],
}

// RxPDO objects in `Layout::rx` order.
const RX_OBJ: [u32; 9] = [
    0x6040_0010,
    0x607A_0020,
    0x60FF_0020,
    0x6071_0010,
    0x6060_0008,
    0x60B8_0010,
    0x6081_0020,
    0x6083_0020,
    0x6084_0020,
];
/// The profile modes' dynamics (profile velocity, acceleration, deceleration): what a
/// drive-executed axis needs beyond the cyclic modes.
const RX_PROFILE: [usize; 3] = [6, 7, 8];
// TxPDO objects in `Layout::tx` order.
const TX_OBJ: [u32; 10] = [
    0x6041_0010,
    0x6064_0020,
    0x606C_0020,
    0x6077_0010,
    0x6061_0008,
    0x603F_0010,
    0x60FD_0020,
    0x60B9_0010,
    0x60BA_0020,
    0x60BB_0020,
];

/// The mapped objects (`offsets[i]` of `objects[i]`), in the order of their offsets.
fn in_image_order(offsets: &[Option<usize>], objects: &[u32]) -> Vec<u32> {
    let mut v: Vec<(usize, u32)> = offsets
        .iter()
        .zip(objects)
        .filter_map(|(o, &obj)| o.map(|o| (o, obj)))
        .collect();
    v.sort();
    v.into_iter().map(|(_, o)| o).collect()
}

impl Layout {
    fn of(name: &'static str, rx: &[usize], tx: &[usize]) -> Layout {
        let mut l = Layout {
            name,
            ..Layout::default()
        };
        for &i in rx {
            l.rx[i] = Some(l.out_len);
            l.out_len += (RX_OBJ[i] & 0xFF) as usize / 8;
        }
        for &i in tx {
            l.tx[i] = Some(l.in_len);
            l.in_len += (TX_OBJ[i] & 0xFF) as usize / 8;
        }
        l
    }
    /// Everything motiond uses: CSP/CSV/CST targets, the profile modes' dynamics, touch
    /// probe, digital inputs.
    pub fn full() -> Layout {
        Layout::of(
            "full",
            &[0, 1, 2, 3, 4, 5, 6, 7, 8],
            &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9],
        )
    }
    /// The full mapping without the profile modes' dynamics: everything the cyclic modes
    /// use (a drive that cannot map 0x6081/0x6083/0x6084 runs host-side profiles only).
    pub fn cyclic() -> Layout {
        Layout::of(
            "cyclic",
            &[0, 1, 2, 3, 4, 5],
            &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9],
        )
    }
    /// Whether a drive-executed profile can run on this mapping: the mode, the targets and
    /// the profile's dynamics are in it.
    pub fn runs_profiles(&self) -> bool {
        [1, 2, 4]
            .iter()
            .chain(&RX_PROFILE)
            .all(|&i| self.rx[i].is_some())
    }
    /// What every CSP drive can map: controlword, target, mode; statusword, position, mode
    /// display, error code.
    pub fn minimal() -> Layout {
        Layout::of("minimal", &[0, 1, 4], &[0, 1, 4, 5])
    }
    /// What the drive has of the full mapping (`missing`: object indices it does not have),
    /// with or without the profile modes' dynamics.
    fn available(missing: &[u16], profiles: bool) -> Layout {
        let has = |obj: u32| !missing.contains(&((obj >> 16) as u16));
        let rx: Vec<usize> = (0..RX_OBJ.len())
            .filter(|&i| has(RX_OBJ[i]) && (profiles || !RX_PROFILE.contains(&i)))
            .collect();
        let tx: Vec<usize> = (0..TX_OBJ.len()).filter(|&i| has(TX_OBJ[i])).collect();
        let name = if profiles {
            "available"
        } else {
            "available_cyclic"
        };
        Layout::of(name, &rx, &tx)
    }
    /// Whether the object (by index) is in this mapping.
    pub fn maps(&self, index: u16) -> bool {
        let hit = |offsets: &[Option<usize>], objects: &[u32]| {
            offsets
                .iter()
                .zip(objects)
                .any(|(o, obj)| o.is_some() && (obj >> 16) as u16 == index)
        };
        hit(&self.rx, &RX_OBJ) || hit(&self.tx, &TX_OBJ)
    }
    /// The mappings to try, largest first: full; full for the cyclic modes only; what the
    /// drive has of each; minimal.
    fn candidates(missing: &[u16]) -> Vec<Layout> {
        let mut v: Vec<Layout> = Vec::new();
        for l in [
            Layout::full(),
            Layout::cyclic(),
            Layout::available(missing, true),
            Layout::available(missing, false),
            Layout::minimal(),
        ] {
            let has_all = l
                .rx_objects()
                .iter()
                .chain(&l.tx_objects())
                .all(|o| !missing.contains(&((o >> 16) as u16)));
            if has_all && !v.iter().any(|k| k.rx == l.rx && k.tx == l.tx) {
                v.push(l);
            }
        }
        v
    }
    fn rx_objects(&self) -> Vec<u32> {
        in_image_order(&self.rx, &RX_OBJ)
    }
    fn tx_objects(&self) -> Vec<u32> {
        in_image_order(&self.tx, &TX_OBJ)
    }

    fn encode(&self, rx: &RxPdo, out: &mut [u8]) {
        let put = |out: &mut [u8], at: Option<usize>, bytes: &[u8]| {
            if let Some(at) = at {
                out[at..at + bytes.len()].copy_from_slice(bytes);
            }
        };
        put(out, self.rx[0], &rx.controlword.to_le_bytes());
        put(out, self.rx[1], &rx.target_position.to_le_bytes());
        put(out, self.rx[2], &rx.target_velocity.to_le_bytes());
        put(out, self.rx[3], &rx.target_torque.to_le_bytes());
        put(out, self.rx[4], &rx.mode.to_le_bytes());
        put(out, self.rx[5], &rx.touch_probe_function.to_le_bytes());
        let profile = [1, 3, 6].contains(&rx.mode);
        let [v, a, d] = if profile {
            [
                rx.profile_velocity,
                rx.profile_acceleration,
                rx.profile_deceleration,
            ]
        } else {
            self.profile_defaults
        };
        put(out, self.rx[6], &v.to_le_bytes());
        put(out, self.rx[7], &a.to_le_bytes());
        put(out, self.rx[8], &d.to_le_bytes());
    }

    fn decode(&self, inp: &[u8]) -> TxPdo {
        let b = |at: Option<usize>, n: usize| -> [u8; 4] {
            let mut v = [0u8; 4];
            if let Some(at) = at {
                v[..n].copy_from_slice(&inp[at..at + n]);
            }
            v
        };
        let u16_at = |i: usize| u16::from_le_bytes(b(self.tx[i], 2)[..2].try_into().expect("2"));
        let i32_at = |i: usize| i32::from_le_bytes(b(self.tx[i], 4));
        TxPdo {
            statusword: u16_at(0),
            position_actual: i32_at(1),
            velocity_actual: i32_at(2),
            mode_display: b(self.tx[4], 1)[0] as i8,
            torque_actual: u16_at(3) as i16,
            error_code: u16_at(5),
            digital_inputs: i32_at(6) as u32,
            touch_probe_status: u16_at(7),
            touch_probe_pos_edge: i32_at(8),
            touch_probe_neg_edge: i32_at(9),
        }
    }
}

/// One SubDevice as found at bring-up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SubDeviceInfo {
    pub position: u16,
    pub configured_address: u16,
    pub name: String,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
    /// A CiA-402 drive (0x1000 device type profile 402) with its process data layout.
    pub drive: Option<Layout>,
    pub dc: bool,
    /// Objects of the full mapping the drive does not have (SDO upload aborted 0x06020000).
    pub missing_objects: Vec<u16>,
    /// The mappings the drive refused before the one it took, in order.
    pub refused: Vec<Refusal>,
}

/// A mapping a drive refused at bring-up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// `full`, `cyclic`, `available`, `available_cyclic` or `minimal`.
    pub mapping: &'static str,
    /// `PDO mapping write` (an SDO abort) or `PRE-OP to SAFE-OP` (the AL status code).
    pub at: &'static str,
    pub al_status_code: Option<u16>,
    /// The AL status code's ETG.1000 meaning, or the SDO error.
    pub reason: String,
}

/// An AL status code with its ETG.1000 meaning (`0x001d: Invalid Output Configuration`).
pub fn al_status_text(code: u16) -> String {
    let c = ethercrab::AlStatusCode::from(code);
    c.to_string()
}

/// What the bus shares with the rest of motiond (the bus page, metrics): written by the
/// cycle thread with atomics, read anywhere.
pub struct BusStatus {
    pub subdevices: Vec<SubDeviceInfo>,
    /// AL state of each SubDevice as the last exchange read it (ethercrab's code: 1 INIT,
    /// 2 PRE-OP, 4 SAFE-OP, 8 OP).
    pub al_states: Vec<AtomicU8>,
    pub frames: AtomicU64,
    pub lost_frames: AtomicU64,
    pub working_counter_errors: AtomicU64,
    pub errors_in_row: AtomicU64,
    pub expected_working_counter: u16,
    pub last_working_counter: AtomicU16,
    pub faulted: AtomicBool,
    /// Times the bus faulted (N bad frames in a row) since start.
    pub faults: AtomicU64,
    /// DC system time of the reference clock at the last exchange (ns since 2000).
    pub dc_system_time: AtomicU64,
    /// Where in its SYNC0 period the last frame reached the reference clock (ns).
    pub dc_cycle_offset: AtomicU64,
    pub interface: String,
    /// The TX/RX loop: late, duplicate and malformed replies, whether it runs, why not.
    pub link: Arc<LinkState>,
    pub pdu_timeout: Duration,
    pub cycle_ns: u64,
    pub max_errors_in_row: u32,
}

/// SDO access to the bus's SubDevices from the async side (never the PDI).
#[derive(Clone, Copy)]
pub struct SdoAccess {
    md: &'static MainDevice<'static>,
    group: &'static Group,
}

#[derive(Debug, PartialEq, Eq)]
pub enum SdoError {
    NoSubDevice,
    /// The CoE abort code the SubDevice answered.
    Abort(u32),
    /// No mailbox, a timeout or another transport error.
    Failed(String),
}

impl SdoAccess {
    fn map(e: ethercrab::error::Error) -> SdoError {
        match e {
            ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Aborted {
                code,
                ..
            }) => SdoError::Abort(u32::from(code)),
            other => SdoError::Failed(other.to_string()),
        }
    }
    /// Up to 4 bytes (expedited or normal upload; longer values are cut to what the
    /// mailbox carries).
    pub async fn read(&self, position: u16, index: u16, sub: u8) -> Result<Vec<u8>, SdoError> {
        let sd = self
            .group
            .subdevice(self.md, position as usize)
            .map_err(|_| SdoError::NoSubDevice)?;
        let v: heapless::Vec<u8, 64> = sd.sdo_read(index, sub).await.map_err(Self::map)?;
        Ok(v.to_vec())
    }
    pub async fn write(
        &self,
        position: u16,
        index: u16,
        sub: u8,
        value: &[u8],
    ) -> Result<(), SdoError> {
        let sd = self
            .group
            .subdevice(self.md, position as usize)
            .map_err(|_| SdoError::NoSubDevice)?;
        let r = match value.len() {
            1 => sd.sdo_write(index, sub, value[0]).await,
            2 => {
                sd.sdo_write(index, sub, u16::from_le_bytes([value[0], value[1]]))
                    .await
            }
            4 => {
                sd.sdo_write(index, sub, u32::from_le_bytes(value.try_into().expect("4")))
                    .await
            }
            n => {
                return Err(SdoError::Failed(format!(
                    "{n} bytes: an SDO write is 1, 2 or 4 bytes"
                )));
            }
        };
        r.map_err(Self::map)
    }
}

/// The bus from the async side: a reset after a fault, and stopping the TX/RX loop (a test's
/// fault). Blocking calls: run them off the async runtime's threads.
#[derive(Clone)]
pub struct BusControl {
    md: &'static MainDevice<'static>,
    group: &'static Group,
    status: Arc<BusStatus>,
}

impl BusControl {
    /// Starts a stopped TX/RX loop again and asks every SubDevice that is not in OP back to
    /// OP (acknowledging its error), until all are in OP as the cycle reads them; how long it
    /// took. `Err` says what is still in the way after `within`.
    pub fn reset(&self, within: Duration) -> Result<Duration, String> {
        let started = Instant::now();
        let st = &*self.status;
        let poll = Duration::from_millis(2).max(Duration::from_nanos(st.cycle_ns));
        if !st.link.alive() {
            st.link.request_restart();
            while !st.link.alive() {
                if started.elapsed() > within {
                    return Err(st
                        .link
                        .fault()
                        .unwrap_or_else(|| "the TX/RX loop did not start again".into()));
                }
                std::thread::sleep(poll);
            }
        }
        let mut asked = None::<Instant>;
        loop {
            // AL state 0: not read since the loop came back.
            let pending: Vec<usize> = st
                .al_states
                .iter()
                .enumerate()
                .filter(|(_, a)| a.load(Relaxed) != 8)
                .map(|(i, _)| i)
                .collect();
            // In OP, and the bus clear (as many good frames in a row as it takes to fault).
            if pending.is_empty() && !st.faulted.load(Relaxed) {
                return Ok(started.elapsed());
            }
            if started.elapsed() > within {
                let i = pending[0];
                let code = self
                    .group
                    .subdevice(self.md, i)
                    .ok()
                    .and_then(|sd| block_on(sd.status()).ok());
                return Err(format!(
                    "SubDevice {i} ({}) did not come back to OP{}",
                    st.subdevices.get(i).map_or("", |s| s.name.as_str()),
                    code.map_or(String::new(), |(state, code)| format!(
                        ": it is in {state} with AL status code {code}"
                    ))
                ));
            }
            let read = pending.iter().all(|&i| st.al_states[i].load(Relaxed) != 0);
            if read && asked.is_none_or(|t| t.elapsed() > Duration::from_millis(200)) {
                for &i in &pending {
                    if let Ok(sd) = self.group.subdevice(self.md, i) {
                        let _ = block_on(sd.register_write(RegisterAddress::AlControl, 0x18u16));
                    }
                }
                asked = Some(Instant::now());
            }
            std::thread::sleep(poll);
        }
    }

    /// Stops the TX/RX loop as a failing socket would (fault injection).
    pub fn kill_loop(&self) {
        self.status.link.kill();
    }
}

pub struct EthercatBus {
    md: &'static MainDevice<'static>,
    group: &'static Group,
    status: Arc<BusStatus>,
    /// Axes with simulated drives run beside the EtherCAT ones (a machine half commissioned).
    sim: SimBus,
    sim_feedback: Vec<DriveFeedback>,
    /// The drive of each axis slot.
    slots: Vec<Option<Box<Cia402Drive>>>,
    /// Slot → SubDevice position, for the slots with a drive.
    layouts: Vec<Option<Layout>>,
    faulted: bool,
    errors_in_row: u32,
    good_in_row: u32,
    max_errors_in_row: u32,
    /// Per slot: enable and fault_reset of the last setpoint (their edges ask for OP).
    last_requests: Vec<(bool, bool)>,
    /// The TX/RX loop was asked to start again: ask OP once frames flow.
    op_after_restart: bool,
}

fn leak<T>(t: T) -> &'static T {
    Box::leak(Box::new(t))
}

/// Stack of the bring-up thread (only what it touches is ever committed).
const BRING_UP_STACK: usize = 64 << 20;

/// The 0x60C2 interpolation period (value, index) of a cycle.
fn interpolation_period(cycle: Duration) -> (u8, i8) {
    let us = cycle.as_micros() as u64;
    if us % 1000 == 0 && us / 1000 <= 255 {
        ((us / 1000) as u8, -3)
    } else if us <= 255 {
        (us as u8, -6)
    } else {
        ((us / 100).min(255) as u8, -4)
    }
}

/// ethercrab's timeouts for a bus with these options. Its EEPROM wait bounds a whole loop of
/// frames that poll the EEPROM until it is not busy (ethercrab's own default, 10 ms, is shorter
/// than one frame with its retries), and the EEPROM is read only while the segment is brought
/// up, never in the cycle. So the bound is generous: at least 500 ms, and more than a frame
/// with all its retries. With (retries + 2) frames as the bound, 40 ms at a 1 ms cycle, a
/// loaded 2-core machine ended the bring-up of 64 emulated drives with "timeout: EEPROM"
/// (`tests/bus.rs`); a long bound only delays the report of an EEPROM that stays busy.
fn bring_up_timeouts(opts: &BusOptions) -> Timeouts {
    Timeouts {
        pdu: opts.pdu_timeout,
        eeprom: (opts.pdu_timeout * (opts.retries as u32 + 2)).max(Duration::from_millis(500)),
        ..Timeouts::default()
    }
}

impl EthercatBus {
    /// Brings the segment up to OP (blocking; off the cycle thread). `slots`: the number of
    /// axis slots.
    pub fn start(link: Link, opts: &BusOptions, slots: usize) -> Result<EthercatBus, String> {
        let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> = leak(PduStorage::new());
        let (tx, rx, pdu_loop) = storage
            .try_split()
            .map_err(|_| "PDU storage split twice".to_string())?;
        // motiond's own TX/RX loop (never ethercrab's `tx_rx_task`: a late reply ends that).
        let (interface, wire, reopen): (String, Box<dyn Wire>, Opener) = match link {
            Link::Interface(iface) => {
                let wire = RawWire::open(&iface)
                    .map_err(|e| format!("cannot open {iface} (CAP_NET_RAW needed): {e}"))?;
                let again = iface.clone();
                let reopen: Opener =
                    Box::new(move || Ok(Box::new(RawWire::open(&again)?) as Box<dyn Wire>));
                (iface, Box::new(wire), reopen)
            }
            Link::Emulated(segment) => {
                let again = segment.clone();
                let reopen: Opener =
                    Box::new(
                        move || Ok(Box::new(SegmentWire::new(again.clone())) as Box<dyn Wire>),
                    );
                (
                    "emulated".to_string(),
                    Box::new(SegmentWire::new(segment)),
                    reopen,
                )
            }
        };
        let link =
            txrx::spawn(tx, rx, wire, reopen, opts.pdu_timeout).map_err(|e| e.to_string())?;
        let md: &'static MainDevice<'static> = leak(MainDevice::new(
            pdu_loop,
            bring_up_timeouts(opts),
            MainDeviceConfig {
                dc_static_sync_iterations: 1000,
                retry_behaviour: RetryBehaviour::Count(opts.retries),
            },
        ));
        // On its own thread: ethercrab's group of 64 SubDevices moves by value through the
        // bring-up's typestates, more than a test or tokio thread's 2 MB of stack.
        let bring_up_opts = opts.clone();
        let (group, infos) = std::thread::Builder::new()
            .name("ethercat-bring-up".into())
            .stack_size(BRING_UP_STACK)
            .spawn(move || block_on(bring_up(md, &bring_up_opts)).map(|(g, i)| (leak(g), i)))
            .map_err(|e| format!("cannot start the bring-up: {e}"))?
            .join()
            .map_err(|p| {
                let why = p
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                format!("the EtherCAT bring-up panicked: {why}")
            })??;
        let group: &'static Group = group;
        let io: Vec<(usize, usize)> = (0..infos.len())
            .map(|i| {
                let sd = group.subdevice(md, i).expect("found at bring-up");
                let io = sd.io_raw();
                (io.inputs().len(), io.outputs().len())
            })
            .collect();
        let expected = expected_working_counter(&io, matches!(group, Group::Dc(_)));
        let status = Arc::new(BusStatus {
            al_states: infos.iter().map(|_| AtomicU8::new(8)).collect(),
            subdevices: infos,
            frames: AtomicU64::new(0),
            lost_frames: AtomicU64::new(0),
            working_counter_errors: AtomicU64::new(0),
            errors_in_row: AtomicU64::new(0),
            expected_working_counter: expected,
            last_working_counter: AtomicU16::new(expected),
            faulted: AtomicBool::new(false),
            faults: AtomicU64::new(0),
            dc_system_time: AtomicU64::new(0),
            dc_cycle_offset: AtomicU64::new(0),
            interface,
            link,
            pdu_timeout: opts.pdu_timeout,
            cycle_ns: opts.cycle.as_nanos() as u64,
            max_errors_in_row: opts.max_errors_in_row.max(1),
        });
        Ok(EthercatBus {
            md,
            group,
            status,
            sim: SimBus::new(slots),
            sim_feedback: vec![DriveFeedback::default(); slots],
            slots: (0..slots).map(|_| None).collect(),
            layouts: vec![None; slots],
            faulted: false,
            errors_in_row: 0,
            good_in_row: 0,
            max_errors_in_row: opts.max_errors_in_row.max(1),
            last_requests: vec![(false, false); slots],
            op_after_restart: false,
        })
    }

    pub fn status(&self) -> Arc<BusStatus> {
        self.status.clone()
    }

    pub fn control(&self) -> BusControl {
        BusControl {
            md: self.md,
            group: self.group,
            status: self.status.clone(),
        }
    }

    pub fn sdo(&self) -> SdoAccess {
        SdoAccess {
            md: self.md,
            group: self.group,
        }
    }

    /// Asks every SubDevice that is not in OP to go there (AL control), acknowledging its
    /// error. One blocking round trip per such SubDevice; only on MC_Reset.
    fn request_op(&self) {
        for (i, st) in self.status.al_states.iter().enumerate() {
            if st.load(Relaxed) != 8 {
                if let Ok(sd) = self.group.subdevice(self.md, i) {
                    let _ = block_on(sd.register_write(RegisterAddress::AlControl, 0x18u16));
                }
            }
        }
    }
}

/// Why one bring-up attempt ended: a drive refused SAFE-OP with its mapping (try again with
/// its next smaller one), or anything else.
enum Attempt {
    /// The SubDevice at this position and every mapping it refused so far (the last at
    /// SAFE-OP).
    Refused(usize, Vec<Refusal>),
    Failed(String),
}

impl From<String> for Attempt {
    fn from(s: String) -> Attempt {
        Attempt::Failed(s)
    }
}

/// Discovery, PDO mapping negotiated per drive, DC, SAFE-OP, OP: a drive that refuses SAFE-OP
/// with its mapping (AL status code 0x001D/0x001E, as ETG.1000 allows a drive that took the
/// mapping writes) gets its next smaller mapping and the segment is brought up again.
async fn bring_up(
    md: &'static MainDevice<'static>,
    opts: &BusOptions,
) -> Result<(Group, Vec<SubDeviceInfo>), String> {
    let mut refused: Vec<Vec<Refusal>> = vec![Vec::new(); MAX_SUBDEVICES];
    // At most one attempt per mapping motiond has.
    for _ in 0..5 {
        match bring_up_once(md, opts, &refused).await {
            Ok(r) => return Ok(r),
            Err(Attempt::Refused(position, r)) => refused[position] = r,
            Err(Attempt::Failed(why)) => return Err(why),
        }
    }
    Err("the drives refused every mapping motiond has".into())
}

/// Asks every SubDevice for SAFE-OP and waits until all are there, or one refuses with an AL
/// status code: (position, code). Before ethercrab's own transition, which would only time out.
async fn safe_op_refusal<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    md: &'static MainDevice<'static>,
    subdevices: &[ethercrab::SubDeviceRef<'_, S>],
) -> Result<Option<(usize, u16)>, ethercrab::error::Error> {
    for sd in subdevices {
        sd.register_write(RegisterAddress::AlControl, 0x04u16)
            .await?;
    }
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        let mut all = true;
        for (i, sd) in subdevices.iter().enumerate() {
            let status: u16 = sd.register_read(RegisterAddress::AlStatus).await?;
            if status & 0x10 != 0 {
                let code: u16 = sd.register_read(RegisterAddress::AlStatusCode).await?;
                return Ok(Some((i, code)));
            }
            all &= status & 0x0F == 4;
        }
        if all || Instant::now() > deadline {
            return Ok(None);
        }
        let _ = md;
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// SAFE-OP asked of every SubDevice: `Ok` when all are there; a drive that refuses it with a
/// smaller mapping left is `Refused` (acknowledged and back in PRE-OP for the next attempt);
/// any other refusal names the SubDevice, the transition and the AL status code.
async fn into_safe_op_checked<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    md: &'static MainDevice<'static>,
    subdevices: Vec<ethercrab::SubDeviceRef<'_, S>>,
    infos: &[SubDeviceInfo],
) -> Result<(), Attempt> {
    let Some((i, code)) = safe_op_refusal(md, &subdevices)
        .await
        .map_err(|e| Attempt::Failed(format!("PRE-OP to SAFE-OP: {e}")))?
    else {
        return Ok(());
    };
    let _ = subdevices[i]
        .register_write(RegisterAddress::AlControl, 0x12u16)
        .await;
    let info = &infos[i];
    let text = al_status_text(code);
    if let Some(l) = info.drive {
        let candidates = Layout::candidates(&info.missing_objects);
        let at = candidates.iter().position(|c| c.name == l.name);
        if let Some(next) = at.and_then(|k| candidates.get(k + 1)) {
            tracing::warn!(
                "EtherCAT SubDevice {i} ({}) refused PRE-OP to SAFE-OP with its {} mapping: AL status code {text}; trying the {} mapping",
                info.name,
                l.name,
                next.name
            );
            let mut refused = info.refused.clone();
            refused.push(Refusal {
                mapping: l.name,
                at: "PRE-OP to SAFE-OP",
                al_status_code: Some(code),
                reason: text,
            });
            return Err(Attempt::Refused(i, refused));
        }
    }
    Err(Attempt::Failed(format!(
        "SubDevice {i} ({}): PRE-OP to SAFE-OP refused with AL status code {text}{}",
        info.name,
        info.drive.map_or(String::new(), |l| format!(
            " (with the {} mapping, the smallest motiond has)",
            l.name
        ))
    )))
}

async fn bring_up_once(
    md: &'static MainDevice<'static>,
    opts: &BusOptions,
    refused: &[Vec<Refusal>],
) -> Result<(Group, Vec<SubDeviceInfo>), Attempt> {
    let e = |what: &str| {
        let what = what.to_string();
        move |err: ethercrab::error::Error| format!("{what}: {err}")
    };
    let mut group = md
        .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercrab::std::ethercat_now)
        .await
        .map_err(e("EtherCAT discovery"))?;
    let mut infos = Vec::new();
    for (position, mut sd) in group.iter_mut(md).enumerate() {
        let id = sd.identity();
        let mut info = SubDeviceInfo {
            position: position as u16,
            configured_address: sd.configured_address(),
            name: sd.name().to_string(),
            vendor_id: id.vendor_id,
            product_code: id.product_id,
            revision: id.revision,
            serial: id.serial,
            drive: None,
            dc: sd.dc_support().any(),
            missing_objects: Vec::new(),
            refused: Vec::new(),
        };
        let device_type = sd.sdo_read::<u32>(0x1000, 0).await.unwrap_or(0);
        if device_type & 0xFFFF == 402 {
            // What the drive has of the full mapping (SDO upload; 0x06020000: no such object),
            // and the values of the profile dynamics it has (sent while it runs cyclically).
            let mut missing = Vec::new();
            let mut defaults = [0u32; 3];
            for obj in RX_OBJ.iter().chain(&TX_OBJ) {
                let index = (obj >> 16) as u16;
                let r = sd.sdo_read::<heapless::Vec<u8, 64>>(index, 0).await;
                match r {
                    Err(ethercrab::error::Error::Mailbox(
                        ethercrab::error::MailboxError::Aborted { code, .. },
                    )) => {
                        if u32::from(code) == 0x0602_0000 && !missing.contains(&index) {
                            missing.push(index);
                        }
                    }
                    Ok(v) => {
                        if let Some(k) = [0x6081, 0x6083, 0x6084].iter().position(|&i| i == index) {
                            let mut b = [0u8; 4];
                            let n = v.len().min(4);
                            b[..n].copy_from_slice(&v[..n]);
                            defaults[k] = u32::from_le_bytes(b);
                        }
                    }
                    Err(_) => {}
                }
            }
            missing.sort_unstable();
            let needed: Vec<String> = Layout::minimal()
                .rx_objects()
                .iter()
                .chain(&Layout::minimal().tx_objects())
                .map(|o| (o >> 16) as u16)
                .filter(|i| missing.contains(i))
                .map(|i| format!("{i:#06x}"))
                .collect();
            if !needed.is_empty() {
                return Err(Attempt::Failed(format!(
                    "SubDevice {position} ({}): a CiA-402 drive without {} (needed for CSP)",
                    info.name,
                    needed.join(", ")
                )));
            }
            info.missing_objects = missing.clone();
            info.refused = refused.get(position).cloned().unwrap_or_default();
            let skip = info.refused.len();
            let mut chosen = None;
            let mut last_err = String::new();
            for layout in Layout::candidates(&missing).into_iter().skip(skip) {
                let r = async {
                    sd.sdo_write(0x1C12, 0, 0u8).await?;
                    sd.sdo_write(0x1C13, 0, 0u8).await?;
                    sd.sdo_write_array(0x1600, layout.rx_objects()).await?;
                    sd.sdo_write_array(0x1A00, layout.tx_objects()).await?;
                    sd.sdo_write_array(0x1C12, [0x1600u16]).await?;
                    sd.sdo_write_array(0x1C13, [0x1A00u16]).await?;
                    Ok::<(), ethercrab::error::Error>(())
                }
                .await;
                match r {
                    Ok(()) => {
                        chosen = Some(layout);
                        break;
                    }
                    Err(err) => {
                        last_err = err.to_string();
                        info.refused.push(Refusal {
                            mapping: layout.name,
                            at: "PDO mapping write",
                            al_status_code: None,
                            reason: last_err.clone(),
                        });
                    }
                }
            }
            let Some(layout) = chosen else {
                return Err(Attempt::Failed(format!(
                    "SubDevice {position} ({}): the drive refused every PDO mapping: {}",
                    info.name,
                    info.refused
                        .iter()
                        .map(|r| format!("{} at {}: {}", r.mapping, r.at, r.reason))
                        .collect::<Vec<_>>()
                        .join("; ")
                )));
            };
            let _ = last_err;
            let layout = Layout {
                profile_defaults: defaults,
                ..layout
            };
            // Optional objects: a drive without them keeps its own settings.
            let (value, index) = interpolation_period(opts.cycle);
            let _ = sd.sdo_write(0x60C2, 1, value).await;
            let _ = sd.sdo_write(0x60C2, 2, index).await;
            if info.dc {
                let _ = sd.sdo_write(0x1C32, 1, 2u16).await;
                let _ = sd.sdo_write(0x1C32, 2, opts.cycle.as_nanos() as u32).await;
            }
            info.drive = Some(layout);
        }
        if info.dc {
            sd.set_dc_sync(DcSync::Sync0);
        }
        infos.push(info);
    }
    let group = group
        .into_pre_op_pdi(md)
        .await
        .map_err(e("PRE-OP with process data"))?;
    for (i, info) in infos.iter().enumerate() {
        if let Some(l) = info.drive {
            let sd = group.subdevice(md, i).map_err(e("SubDevice"))?;
            let io = sd.io_raw();
            if io.outputs().len() != l.out_len || io.inputs().len() != l.in_len {
                return Err(Attempt::Failed(format!(
                    "SubDevice {i} ({}): process data of {}/{} bytes, its mapping says {}/{}",
                    info.name,
                    io.outputs().len(),
                    io.inputs().len(),
                    l.out_len,
                    l.in_len
                )));
            }
        }
    }
    let deadline = Instant::now() + Duration::from_secs(10);
    if !infos.iter().any(|i| i.dc) {
        // No DC unit on the segment: free-running process data.
        into_safe_op_checked(md, group.iter(md).collect(), &infos).await?;
        let group = group.into_safe_op(md).await.map_err(e("SAFE-OP"))?;
        let group = group.request_into_op(md).await.map_err(e("OP request"))?;
        loop {
            let r = group.tx_rx(md).await.map_err(e("cycle towards OP"))?;
            if r.all_op() {
                break;
            }
            if Instant::now() > deadline {
                return Err(Attempt::Failed(
                    "the SubDevices did not reach OP within 10 s".into(),
                ));
            }
            std::thread::sleep(opts.cycle);
        }
        return Ok((Group::Free(group), infos));
    }
    // Distributed clocks: align the SubDevices' clocks, then SYNC0 at the cycle time.
    let started = Instant::now();
    for _ in 0..200 {
        group
            .tx_rx_sync_system_time(md)
            .await
            .map_err(e("DC alignment"))?;
        if started.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    let group = group
        .configure_dc_sync(
            md,
            DcConfiguration {
                start_delay: Duration::from_millis(20),
                sync0_period: opts.cycle,
                sync0_shift: Duration::ZERO,
            },
        )
        .await
        .map_err(e("DC SYNC0"))?;
    into_safe_op_checked(md, group.iter(md).collect(), &infos).await?;
    let group = group.into_safe_op(md).await.map_err(e("SAFE-OP"))?;
    let group = group.request_into_op(md).await.map_err(e("OP request"))?;
    loop {
        let r = group.tx_rx_dc(md).await.map_err(e("cycle towards OP"))?;
        if r.all_op() {
            break;
        }
        if Instant::now() > deadline {
            return Err(Attempt::Failed(
                "the SubDevices did not reach OP within 10 s".into(),
            ));
        }
        std::thread::sleep(r.extra.next_cycle_wait.min(opts.cycle));
    }
    Ok((Group::Dc(group), infos))
}

impl DriveBus for EthercatBus {
    fn slots(&self) -> usize {
        self.slots.len()
    }

    /// The frame should reach the reference clock half a SYNC0 period after the pulse: the
    /// drives latch their outputs at SYNC0, so half a period of margin either side.
    fn sync_error_ns(&self) -> Option<i64> {
        let period = self.status.cycle_ns as i64;
        let offset = self.status.dc_cycle_offset.load(Relaxed) as i64;
        let dc = matches!(self.group, Group::Dc(_));
        (dc && period > 0 && self.errors_in_row == 0).then(|| {
            let e = offset - period / 2;
            // Wrapped into (−period/2, period/2].
            if e > period / 2 { e - period } else { e }
        })
    }

    fn exchange(&mut self, setpoints: &[DriveSetpoint], feedback: &mut [DriveFeedback]) {
        self.sim.exchange(setpoints, &mut self.sim_feedback);
        // A SubDevice out of OP is asked back when one of its axes powers on or resets (an
        // edge of enable or fault_reset): the engineer's "try again".
        let mut want_op = false;
        for (((drive, layout), sp), last) in self
            .slots
            .iter_mut()
            .zip(&self.layouts)
            .zip(setpoints)
            .zip(self.last_requests.iter_mut())
        {
            let (Some(d), Some(l)) = (drive, layout) else {
                continue;
            };
            let request = (sp.enable, sp.fault_reset);
            if (request.0 && !last.0) || (request.1 && !last.1) {
                let position = d.config().subdevice as usize;
                want_op |= self
                    .status
                    .al_states
                    .get(position)
                    .is_some_and(|a| a.load(Relaxed) != 8);
            }
            *last = request;
            if let Ok(sd) = self.group.subdevice(self.md, d.config().subdevice as usize) {
                let mut io = sd.io_raw_mut();
                l.encode(&d.outputs(sp), io.outputs());
            }
        }
        let st = &*self.status;
        let link_up = st.link.alive();
        if !link_up {
            // The TX/RX loop stopped: nothing to wait for, the AL states are unknown, the bus
            // faults at once. An axis's power-on or reset edge starts the loop again.
            for a in &st.al_states {
                a.store(0, Relaxed);
            }
            if want_op {
                st.link.request_restart();
                self.op_after_restart = true;
                want_op = false;
            }
            if !self.faulted {
                self.faulted = true;
                st.faulted.store(true, Relaxed);
                st.faults.fetch_add(1, Relaxed);
            }
        } else {
            st.frames.fetch_add(1, Relaxed);
        }
        let good = link_up
            && match txrx::block_on_spinning(
                self.group.exchange(self.md),
                st.link.runs_apart_from_caller(),
            ) {
                Ok(r) => {
                    st.last_working_counter.store(r.working_counter, Relaxed);
                    if let Some((time, offset)) = r.dc {
                        st.dc_system_time.store(time, Relaxed);
                        st.dc_cycle_offset.store(offset, Relaxed);
                    }
                    for (a, s) in st.al_states.iter().zip(&r.states) {
                        a.store(
                            match s {
                                SubDeviceState::Other(v) => *v,
                                s => u8::from(*s),
                            },
                            Relaxed,
                        );
                    }
                    let ok = r.working_counter == st.expected_working_counter;
                    if !ok {
                        st.working_counter_errors.fetch_add(1, Relaxed);
                    }
                    ok
                }
                Err(_) => {
                    st.lost_frames.fetch_add(1, Relaxed);
                    false
                }
            };
        // Back after a restart: the SubDevices that left OP meanwhile (SyncManager watchdog)
        // are asked back.
        if good && self.op_after_restart {
            self.op_after_restart = false;
            want_op |= st.al_states.iter().any(|a| a.load(Relaxed) != 8);
        }
        // Hysteresis: N bad frames in a row fault the bus, N good ones in a row clear it. The
        // axes that were enabled are latched in ErrorStop by the kernel until MC_Reset; a bus
        // fault with no axis enabled leaves nothing to latch.
        if good {
            self.errors_in_row = 0;
            self.good_in_row = self.good_in_row.saturating_add(1);
            if self.faulted && self.good_in_row >= self.max_errors_in_row {
                self.faulted = false;
                st.faulted.store(false, Relaxed);
            }
        } else {
            self.good_in_row = 0;
            self.errors_in_row += 1;
            if self.errors_in_row >= self.max_errors_in_row && !self.faulted {
                self.faulted = true;
                st.faulted.store(true, Relaxed);
                st.faults.fetch_add(1, Relaxed);
            }
        }
        st.errors_in_row.store(self.errors_in_row as u64, Relaxed);
        if want_op && link_up {
            self.request_op();
        }
        for (slot, ((drive, layout), fb)) in self
            .slots
            .iter_mut()
            .zip(&self.layouts)
            .zip(feedback.iter_mut())
            .enumerate()
        {
            let (Some(d), Some(l)) = (drive, layout) else {
                // A simulated drive, or none (not ready).
                *fb = self.sim_feedback[slot];
                continue;
            };
            let position = d.config().subdevice as usize;
            let tx = match self.group.subdevice(self.md, position) {
                Ok(sd) => l.decode(sd.io_raw().inputs()),
                Err(_) => TxPdo::default(),
            };
            *fb = d.feedback(&tx);
            let al = st.al_states.get(position).map_or(0, |a| a.load(Relaxed));
            // The drive's last answer, flagged: the kernel stops on its ramp into ErrorStop
            // with bus_error, as far as the drive still takes setpoints.
            fb.bus_error = self.faulted || al != 8;
        }
    }

    fn attach(&mut self, slot: usize, drive: Drive) -> Result<Option<Drive>, Drive> {
        let d = match drive {
            Drive::Cia402(d) => d,
            sim => {
                // The slot's EtherCAT drive (if any) comes back with it.
                let old = self.detach(slot);
                return self.sim.attach(slot, sim).map(|o| o.or(old));
            }
        };
        let Some(layout) = self
            .status
            .subdevices
            .get(d.config().subdevice as usize)
            .and_then(|s| s.drive)
        else {
            return Err(Drive::Cia402(d));
        };
        if slot >= self.slots.len() {
            return Err(Drive::Cia402(d));
        }
        self.layouts[slot] = Some(layout);
        let old_sim = self.sim.detach(slot);
        Ok(self.slots[slot].replace(d).map(Drive::Cia402).or(old_sim))
    }

    fn detach(&mut self, slot: usize) -> Option<Drive> {
        if let Some(l) = self.layouts.get_mut(slot) {
            *l = None;
        }
        match self.slots.get_mut(slot).and_then(Option::take) {
            Some(d) => Some(Drive::Cia402(d)),
            None => self.sim.detach(slot),
        }
    }

    /// The simulated axes this bus carries besides its EtherCAT drives (a drive of the
    /// emulated segment takes its faults through the emulator's door, `emu::drive::Input`).
    fn simulated(&mut self) -> Option<&mut SimBus> {
        Some(&mut self.sim)
    }
}

#[cfg(test)]
mod tests {
    use super::{BusOptions, Duration, bring_up_timeouts, expected_working_counter};

    /// The EEPROM's wait outlasts a frame with all its retries, several times over, and a
    /// machine that holds the bring-up's threads off for tens of milliseconds.
    #[test]
    fn the_eeprom_wait_outlasts_a_frame_and_its_retries() {
        for cycle_us in [250, 1000, 4000, 10_000] {
            let opts = BusOptions::new(Duration::from_micros(cycle_us));
            let t = bring_up_timeouts(&opts);
            assert_eq!(t.pdu, opts.pdu_timeout);
            let frame_with_retries = opts.pdu_timeout * (opts.retries as u32 + 1);
            assert!(t.eeprom > frame_with_retries * 4, "{cycle_us} µs: {t:?}");
            assert!(
                t.eeprom >= Duration::from_millis(500),
                "{cycle_us} µs: {t:?}"
            );
        }
    }

    #[test]
    fn a_subdevice_whose_image_straddles_two_frames_counts_in_both() {
        // Two drives of the full mapping (29 bytes in, 27 out): one frame, 3 each.
        assert_eq!(expected_working_counter(&[(29, 27); 2], true), 6);
        // 64 of them: 1856 bytes of inputs, then 1728 of outputs, in LRWs of 1100 bytes.
        // Inputs of drive 37 ([1073, 1102)) straddle the first frame's end, outputs of
        // drives 12 ([2180, 2207)) and 53 ([3287, 3314)) the second's and the third's.
        assert_eq!(
            expected_working_counter(&[(29, 27); 64], false),
            64 + 1 + 2 * (64 + 2)
        );
        // With DC the first LRW is 20 bytes shorter (1080): drive 37's inputs still straddle,
        // the second frame ends exactly between drives 11 and 12, drive 52 straddles the third.
        assert_eq!(
            expected_working_counter(&[(29, 27); 64], true),
            64 + 1 + 2 * (64 + 1)
        );
        // A coupler without process data counts nowhere.
        assert_eq!(
            expected_working_counter(&[(0, 0), (2, 0), (0, 1)], false),
            3
        );
    }
}
