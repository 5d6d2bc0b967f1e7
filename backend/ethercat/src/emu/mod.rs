//! An emulated EtherCAT segment: a chain of emulated SubDevice controllers ([`esc::Esc`]) that
//! answer the frames of the real ethercrab MainDevice — in-process through ethercrab's
//! `PduTx`/`PduRx` ([`transport`]) or on a raw socket ([`transport::serve_raw_socket`]) — each
//! with an application behind its process RAM: a CiA-402 servo drive ([`drive::Cia402Emu`])
//! with a CoE object dictionary ([`coe`]) and an SII image ([`sii`]).
//!
//! Used by `motiond --bus emulated` (a newcomer sees EtherCAT drives without hardware) and by
//! the tests of the EtherCAT bus. Written from the EtherCAT specification (ETG.1000) and
//! CiA-402, not from another emulator's code.

pub mod coe;
pub mod drive;
pub mod esc;
pub mod sii;
pub mod transport;

use std::sync::{Arc, Mutex};

use esc::{Esc, SmConfig};

/// What runs behind an ESC's process RAM and mailbox.
pub trait Application: Send {
    /// A complete mailbox request (the receive mailbox's whole buffer); the response to put
    /// in the send mailbox, if any.
    fn mailbox(&mut self, request: &[u8]) -> Option<Vec<u8>>;
    /// The MainDevice read the send mailbox.
    fn mailbox_read(&mut self) {}
    /// (start, length) of the receive and the send mailbox, as the SII tells the MainDevice.
    fn mailbox_layout(&self) -> ((u16, u16), (u16, u16));
    /// Lengths of the outputs (RxPDO) and inputs (TxPDO) the current mapping gives.
    fn process_data_sizes(&self) -> (usize, usize);
    /// The AL state changed.
    fn al_changed(&mut self, state: u8);
    /// What the application says to PRE-OP → SAFE-OP beyond the SyncManagers (an AL status
    /// code: a drive that checks its PDO mapping only now).
    fn check_safe_op(&self) -> Result<(), u16> {
        Ok(())
    }
    /// The MainDevice wrote outputs (in OP).
    fn outputs_written(&mut self, _now: u64) {}
    /// After each frame: `mem` is the ESC's memory, `sm2`/`sm3` where outputs and inputs are,
    /// `system_time` the ESC's DC system time (ns), `sync0` (start, cycle) when SYNC0 runs.
    fn step(
        &mut self,
        mem: &mut [u8],
        sm2: SmConfig,
        sm3: SmConfig,
        al_state: u8,
        system_time: u64,
        sync0: Option<(u64, u64)>,
    );
    /// Downcast for fault injection and inspection.
    fn as_any(&mut self) -> &mut dyn std::any::Any;
}

/// Disturbances of the segment itself (the drives have their own).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SegmentFaults {
    /// Frames to lose (no answer) from now on, one by one: a retry of a lost frame is a frame.
    pub drop_frames: u32,
    /// Cycles to go unanswered from now on: each frame that carries process data (LRW, LRD,
    /// LWR) with a new PDU index starts one, and it and its retries (the same index), and
    /// whatever else is sent in it, get no answer — what a user means by "lose 5 frames":
    /// five cycles without an answer, as the bus counts lost frames.
    pub silent_cycles: u32,
    /// A SubDevice (by position) that drops to SAFE-OP with an error (AL status code 0x001B,
    /// SyncManager watchdog), at the next frame.
    pub safe_op: Option<usize>,
    /// Answers to send late from now on, each `reply_delay` after its frame (what a loaded
    /// link or a slow switch does: the MainDevice has sent the frame again by then).
    pub late_replies: u32,
    pub reply_delay: std::time::Duration,
    /// Answers to send twice from now on.
    pub duplicate_replies: u32,
    /// Every so many answers, one comes `reply_delay` late (0: never): a link that is slow
    /// now and then, for as long as the segment runs.
    pub late_every: u32,
}

/// The command and PDU index of each datagram of an EtherCAT frame (after the Ethernet and
/// EtherCAT headers; stops at a datagram that does not fit).
fn datagrams(frame: &[u8]) -> impl Iterator<Item = (u8, u8)> + '_ {
    let end = frame.get(14..16).map_or(0, |h| {
        (16 + (u16::from_le_bytes([h[0], h[1]]) & 0x7FF) as usize).min(frame.len())
    });
    let mut p = Some(16);
    std::iter::from_fn(move || {
        let at = p?;
        if at + 12 > end {
            return None;
        }
        let len_flags = u16::from_le_bytes([frame[at + 6], frame[at + 7]]);
        let next = at + 12 + (len_flags & 0x7FF) as usize;
        p = (len_flags & 0x8000 != 0 && next <= end).then_some(next);
        Some((frame[at], frame[at + 1]))
    })
}

/// A line of emulated SubDevices, in bus order.
pub struct Segment {
    pub escs: Vec<Esc>,
    clock: Box<dyn FnMut() -> u64 + Send>,
    pub faults: SegmentFaults,
    /// Frames answered and lost, for the tests.
    pub frames: u64,
    pub lost: u64,
    /// Answers sent (for `late_every`).
    answers: u64,
    /// The PDU index of the silent cycle's process-data frame (its retries are lost too).
    silent_index: Option<u8>,
}

/// Per-device propagation (ns) through an ESC, for the DC port receive times.
const HOP_NS: u64 = 120;

/// The Ethernet type of EtherCAT.
pub const ETHERTYPE: u16 = 0x88A4;

impl Segment {
    /// `clock`: the segment's time in ns (monotonic; virtual in deterministic tests).
    pub fn new(
        apps: Vec<(Vec<u8>, Box<dyn Application>)>,
        clock: Box<dyn FnMut() -> u64 + Send>,
    ) -> Segment {
        Segment::with_dc(apps, clock, true)
    }

    /// As [`Segment::new`]; `dc` false: ESCs without a distributed clock unit (free-run).
    pub fn with_dc(
        apps: Vec<(Vec<u8>, Box<dyn Application>)>,
        clock: Box<dyn FnMut() -> u64 + Send>,
        dc: bool,
    ) -> Segment {
        let n = apps.len();
        let escs = apps
            .into_iter()
            .enumerate()
            .map(|(i, (sii, app))| {
                // Each device was powered up at a different time: its own clock differs.
                let mut esc = Esc::new(
                    sii,
                    app,
                    1_000_000 * (i as u64 + 1) + 777 * i as u64,
                    i + 1 < n,
                    dc,
                );
                esc.downstream_round_trip = 2 * HOP_NS * (n - i - 1) as u64;
                esc
            })
            .collect();
        Segment {
            escs,
            clock,
            faults: SegmentFaults::default(),
            frames: 0,
            lost: 0,
            answers: 0,
            silent_index: None,
        }
    }

    /// Shared by a transport and whoever injects faults or looks inside.
    pub fn shared(self) -> Arc<Mutex<Segment>> {
        Arc::new(Mutex::new(self))
    }

    /// The application of device `n` as a `T`.
    pub fn app<T: 'static>(&mut self, n: usize) -> Option<&mut T> {
        self.escs.get_mut(n)?.app.as_any().downcast_mut::<T>()
    }

    /// Passes an Ethernet frame through the segment; the frame that comes back (source MAC
    /// with the locally administered bit, as the first real SubDevice sets it), or `None` when
    /// it is not EtherCAT or is lost.
    /// How the transport sends the answer just made: after what delay, in how many copies
    /// (the reply faults, one answer each).
    pub fn reply_plan(&mut self) -> (std::time::Duration, usize) {
        let mut plan = (std::time::Duration::ZERO, 1);
        self.answers += 1;
        if self.faults.late_every > 0 && self.answers % u64::from(self.faults.late_every) == 0 {
            plan.0 = self.faults.reply_delay;
        }
        if self.faults.late_replies > 0 {
            self.faults.late_replies -= 1;
            plan.0 = self.faults.reply_delay;
        }
        if self.faults.duplicate_replies > 0 {
            self.faults.duplicate_replies -= 1;
            plan.1 = 2;
        }
        plan
    }

    pub fn process(&mut self, frame: &[u8]) -> Option<Vec<u8>> {
        if frame.len() < 16 || u16::from_be_bytes([frame[12], frame[13]]) != ETHERTYPE {
            return None;
        }
        let header = u16::from_le_bytes([frame[14], frame[15]]);
        if header >> 12 != 1 {
            return None;
        }
        let now = (self.clock)();
        if let Some(n) = self.faults.safe_op.take() {
            if let Some(esc) = self.escs.get_mut(n) {
                esc.fall_to(esc::AL_SAFE_OP, esc::al_code::SM_WATCHDOG);
            }
        }
        if self.faults.drop_frames > 0 {
            self.faults.drop_frames -= 1;
            self.lost += 1;
            return None;
        }
        // The PDU index of the frame's process-data datagram (LRD, LWR, LRW), if it has one.
        let index = datagrams(frame)
            .find(|&(cmd, _)| matches!(cmd, 10..=12))
            .map(|(_, index)| index);
        let process_data = index.is_some();
        let retry = process_data && self.silent_index.is_some() && self.silent_index == index;
        if retry || self.faults.silent_cycles > 0 {
            if process_data && !retry {
                self.faults.silent_cycles -= 1;
                self.silent_index = index;
            }
            self.lost += 1;
            return None;
        }
        self.silent_index = None;
        let mut out = frame.to_vec();
        out[6] |= 0x02;
        let end = (16 + (header & 0x7FF) as usize).min(out.len());
        let mut p = 16;
        while p + 12 <= end {
            let len_flags = u16::from_le_bytes([out[p + 6], out[p + 7]]);
            let dlen = (len_flags & 0x7FF) as usize;
            if p + 12 + dlen > end {
                break;
            }
            let (head, rest) = out[p..p + 12 + dlen].split_at_mut(10);
            let (data, wkc) = rest.split_at_mut(dlen);
            let mut w = u16::from_le_bytes([wkc[0], wkc[1]]);
            self.datagram(head, data, &mut w, now);
            wkc.copy_from_slice(&w.to_le_bytes());
            p += 12 + dlen;
            if len_flags & 0x8000 == 0 {
                break;
            }
        }
        for esc in &mut self.escs {
            esc.step_application(now);
        }
        self.frames += 1;
        Some(out)
    }

    fn datagram(&mut self, head: &mut [u8], data: &mut [u8], wkc: &mut u16, now: u64) {
        let cmd = head[0];
        let adp = u16::from_le_bytes([head[2], head[3]]);
        let ado = u16::from_le_bytes([head[4], head[5]]);
        let logical = u32::from_le_bytes([head[2], head[3], head[4], head[5]]);
        let mut position = adp;
        let mut scratch = vec![0u8; data.len()];
        // Registers of a DC unit do not exist (and count nothing) in an ESC without one.
        let dc_register = (0x0900..0x0A00).contains(&ado) && cmd < 10 || cmd == 14;
        for esc in &mut self.escs {
            let by_position = position == 0;
            position = position.wrapping_add(1);
            if dc_register && !esc.has_dc() {
                continue;
            }
            let by_station = esc.station_address() == adp;
            match cmd {
                // APRD, FPRD
                1 | 4 if (cmd == 1 && by_position) || (cmd == 4 && by_station) => {
                    esc.read(ado, data, now);
                    *wkc += 1;
                }
                // APWR, FPWR
                2 | 5 if (cmd == 2 && by_position) || (cmd == 5 && by_station) => {
                    esc.write(ado, data, now);
                    *wkc += 1;
                }
                // APRW, FPRW
                3 | 6 if (cmd == 3 && by_position) || (cmd == 6 && by_station) => {
                    esc.read(ado, &mut scratch, now);
                    esc.write(ado, data, now);
                    data.copy_from_slice(&scratch);
                    *wkc += 3;
                }
                // BRD: every device ORs its value in.
                7 => {
                    esc.read(ado, &mut scratch, now);
                    for (d, s) in data.iter_mut().zip(&scratch) {
                        *d |= s;
                    }
                    *wkc += 1;
                }
                // BWR
                8 => {
                    esc.write(ado, data, now);
                    *wkc += 1;
                }
                // BRW
                9 => {
                    esc.read(ado, &mut scratch, now);
                    esc.write(ado, data, now);
                    for (d, s) in data.iter_mut().zip(&scratch) {
                        *d |= s;
                    }
                    *wkc += 3;
                }
                // LRD, LWR, LRW
                10..=12 => {
                    let a = esc.logical(logical, data, cmd != 11, cmd != 10, now);
                    *wkc += match cmd {
                        10 => u16::from(a.read),
                        11 => u16::from(a.wrote),
                        _ => u16::from(a.read) + 2 * u16::from(a.wrote),
                    };
                }
                // ARMW, FRMW: the addressed device reads, all others write what it read.
                13 | 14 => {
                    let addressed = if cmd == 13 { by_position } else { by_station };
                    if addressed {
                        esc.read(ado, data, now);
                    } else {
                        esc.write(ado, data, now);
                    }
                    *wkc += 1;
                }
                _ => {}
            }
        }
        if matches!(cmd, 1..=3 | 13) {
            head[2..4].copy_from_slice(&position.to_le_bytes());
        }
    }
}
