//! One emulated EtherCAT SubDevice controller (ESC): its 64 KiB address space (registers and
//! process RAM), the datagram commands as a real ESC executes them on the frame's way through
//! (station, broadcast and logical addressing with the FMMUs, read-multiple-write), the AL state
//! machine, the SII EEPROM interface, the mailbox SyncManagers and the distributed clock
//! registers. What sits behind the process RAM (the application) is an [`Application`].

use super::Application;

pub const REG_STATION_ADDRESS: u16 = 0x0010;
pub const REG_DL_STATUS: u16 = 0x0110;
pub const REG_AL_CONTROL: u16 = 0x0120;
pub const REG_AL_STATUS: u16 = 0x0130;
pub const REG_AL_STATUS_CODE: u16 = 0x0134;
pub const REG_SII_CONTROL: u16 = 0x0502;
pub const REG_SII_ADDRESS: u16 = 0x0504;
pub const REG_SII_DATA: u16 = 0x0508;
pub const REG_FMMU0: u16 = 0x0600;
pub const REG_SM0: u16 = 0x0800;
pub const REG_DC_PORT0_TIME: u16 = 0x0900;
pub const REG_DC_SYSTEM_TIME: u16 = 0x0910;
pub const REG_DC_RECEIVE_TIME: u16 = 0x0918;
pub const REG_DC_OFFSET: u16 = 0x0920;
pub const REG_DC_DELAY: u16 = 0x0928;
pub const REG_DC_DIFFERENCE: u16 = 0x092C;
pub const REG_DC_SYNC_ACTIVE: u16 = 0x0981;
pub const REG_DC_START_TIME: u16 = 0x0990;
pub const REG_DC_SYNC0_CYCLE: u16 = 0x09A0;

/// AL states (register 0x0130 bits 0–3).
pub const AL_INIT: u8 = 1;
pub const AL_PRE_OP: u8 = 2;
pub const AL_BOOT: u8 = 3;
pub const AL_SAFE_OP: u8 = 4;
pub const AL_OP: u8 = 8;
/// AL status bit 4: an error the MainDevice has not acknowledged.
pub const AL_ERROR: u8 = 0x10;

/// AL status codes (ETG.1000.6 table 11) the emulator sets.
pub mod al_code {
    pub const INVALID_STATE_CHANGE: u16 = 0x0011;
    pub const UNKNOWN_STATE: u16 = 0x0012;
    pub const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
    pub const INVALID_SM_OUT_CONFIG: u16 = 0x001D;
    pub const INVALID_SM_IN_CONFIG: u16 = 0x001E;
    pub const SM_WATCHDOG: u16 = 0x001B;
}

/// A SyncManager as the MainDevice configured it (registers 0x0800 + 8·n).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SmConfig {
    pub start: u16,
    pub len: u16,
    pub control: u8,
    pub enabled: bool,
}

impl SmConfig {
    /// Mailbox mode (control bits 0–1 = 2) rather than the buffered process data mode.
    pub fn is_mailbox(&self) -> bool {
        self.control & 0b11 == 0b10
    }
    /// The MainDevice writes it (control bits 2–3 = 1).
    pub fn ecat_writes(&self) -> bool {
        (self.control >> 2) & 0b11 == 1
    }
    fn covers(&self, addr: usize, len: usize) -> bool {
        self.enabled
            && self.len > 0
            && addr < self.start as usize + self.len as usize
            && addr + len > self.start as usize
    }
    fn last_byte(&self) -> usize {
        self.start as usize + self.len as usize - 1
    }
}

/// What a datagram did in one ESC, for the frame's working counter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Access {
    pub read: bool,
    pub wrote: bool,
}

pub struct Esc {
    mem: Box<[u8; 0x10000]>,
    sii: Vec<u8>,
    /// The ESC's own clock: the segment's time plus when this one was powered up.
    pub local_offset: u64,
    /// A request waits in the receive mailbox (SM0 written up to its last byte).
    mailbox_in_full: bool,
    /// A response waits in the send mailbox (SM1) until the MainDevice reads its last byte.
    mailbox_out_full: bool,
    /// How long a frame takes from port 1 through the devices behind and back (ns).
    pub downstream_round_trip: u64,
    pub app: Box<dyn Application>,
}

fn put_u16(mem: &mut [u8], addr: u16, v: u16) {
    mem[addr as usize..addr as usize + 2].copy_from_slice(&v.to_le_bytes());
}
fn get_u16(mem: &[u8], addr: u16) -> u16 {
    u16::from_le_bytes([mem[addr as usize], mem[addr as usize + 1]])
}
fn get_u64(mem: &[u8], addr: u16) -> u64 {
    u64::from_le_bytes(
        mem[addr as usize..addr as usize + 8]
            .try_into()
            .expect("8 bytes"),
    )
}

impl Esc {
    /// `downstream`: another SubDevice follows on port 1 (its link is up); `dc`: it has a
    /// distributed clock unit.
    pub fn new(
        sii: Vec<u8>,
        app: Box<dyn Application>,
        local_offset: u64,
        downstream: bool,
        dc: bool,
    ) -> Esc {
        let mut mem = Box::new([0u8; 0x10000]);
        mem[0x0000] = 0x11; // ET1100-like
        mem[0x0001] = 0x02;
        mem[0x0004] = 8; // FMMUs
        mem[0x0005] = 8; // SyncManagers
        mem[0x0006] = 8; // KiB of process RAM
        mem[0x0007] = 0x0F; // ports 0 and 1 EBUS/MII
        // Support flags: DC supported, 64-bit DC, enhanced DC sync (or none of them).
        let flags = if dc {
            (1 << 2) | (1 << 3) | (1 << 8)
        } else {
            0
        };
        put_u16(&mut mem[..], 0x0008, flags);
        // DL status: port 0 linked and communicating; port 1 too when a device follows,
        // otherwise its loop is closed.
        let mut dl: u16 = (1 << 4) | (1 << 9);
        if downstream {
            dl |= (1 << 5) | (1 << 11);
        } else {
            dl |= 1 << 10;
        }
        dl |= 1 << 0; // PDI operational (EEPROM loaded)
        put_u16(&mut mem[..], REG_DL_STATUS, dl);
        mem[REG_AL_STATUS as usize] = AL_INIT;
        // SII: 8-octet reads, EEPROM idle.
        put_u16(&mut mem[..], REG_SII_CONTROL, 1 << 6);
        Esc {
            mem,
            sii,
            local_offset,
            mailbox_in_full: false,
            mailbox_out_full: false,
            downstream_round_trip: 0,
            app,
        }
    }

    /// Has a distributed clock unit (its registers 0x0900–0x09FF answer).
    pub fn has_dc(&self) -> bool {
        get_u16(&self.mem[..], 0x0008) & (1 << 2) != 0
    }

    pub fn station_address(&self) -> u16 {
        get_u16(&self.mem[..], REG_STATION_ADDRESS)
    }

    pub fn al_state(&self) -> u8 {
        self.mem[REG_AL_STATUS as usize] & 0x0F
    }

    pub fn al_status(&self) -> (u8, u16) {
        (
            self.mem[REG_AL_STATUS as usize],
            get_u16(&self.mem[..], REG_AL_STATUS_CODE),
        )
    }

    /// The ESC leaves its state for `state` with an error (what a watchdog or a local fault
    /// does); the MainDevice sees the error bit and the code in 0x0134.
    pub fn fall_to(&mut self, state: u8, code: u16) {
        self.mem[REG_AL_STATUS as usize] = state | AL_ERROR;
        put_u16(&mut self.mem[..], REG_AL_STATUS_CODE, code);
        self.app.al_changed(state);
    }

    pub fn sm(&self, n: usize) -> SmConfig {
        let base = REG_SM0 as usize + 8 * n;
        SmConfig {
            start: get_u16(&self.mem[..], base as u16),
            len: get_u16(&self.mem[..], base as u16 + 2),
            control: self.mem[base + 4],
            enabled: self.mem[base + 6] & 1 != 0,
        }
    }

    pub fn mem(&self) -> &[u8] {
        &self.mem[..]
    }

    pub fn mem_mut(&mut self) -> &mut [u8] {
        &mut self.mem[..]
    }

    fn system_time(&self, now: u64) -> u64 {
        (now + self.local_offset).wrapping_add(get_u64(&self.mem[..], REG_DC_OFFSET))
    }

    /// Copies `len` bytes at `addr` into `out`, as the ESC's registers read at `now`.
    pub fn read(&mut self, addr: u16, out: &mut [u8], now: u64) {
        let a = addr as usize;
        let end = (a + out.len()).min(0x10000);
        // Registers whose value is the time they are read.
        if a < REG_DC_SYSTEM_TIME as usize + 8 && end > REG_DC_SYSTEM_TIME as usize {
            let t = self.system_time(now).to_le_bytes();
            self.mem[REG_DC_SYSTEM_TIME as usize..REG_DC_SYSTEM_TIME as usize + 8]
                .copy_from_slice(&t);
        }
        for i in 0..8 {
            let sm = self.sm(i);
            let status = REG_SM0 as usize + 8 * i + 5;
            if (a..end).contains(&status) {
                let full = match i {
                    0 => self.mailbox_in_full,
                    1 => self.mailbox_out_full,
                    _ => false,
                };
                self.mem[status] = if sm.is_mailbox() && full { 1 << 3 } else { 0 };
            }
        }
        out[..end - a].copy_from_slice(&self.mem[a..end]);
        // Reading the send mailbox's last byte empties it.
        let sm1 = self.sm(1);
        if self.mailbox_out_full
            && sm1.is_mailbox()
            && sm1.covers(a, end - a)
            && end > sm1.last_byte()
        {
            self.mailbox_out_full = false;
            self.app.mailbox_read();
        }
    }

    /// Writes `data` at `addr` and lets the ESC react (AL control, SII, DC, mailbox).
    pub fn write(&mut self, addr: u16, data: &[u8], now: u64) {
        let a = addr as usize;
        let end = (a + data.len()).min(0x10000);
        let data = &data[..end - a];
        let touches = |reg: u16, width: usize| a < reg as usize + width && end > reg as usize;
        // A write to the receive mailbox while a request is pending is refused by the ESC.
        let sm0 = self.sm(0);
        if sm0.is_mailbox() && sm0.covers(a, data.len()) && self.mailbox_in_full {
            return;
        }
        // Registers that are not plain memory.
        let keep_status = touches(REG_AL_STATUS, 2) || touches(REG_AL_STATUS_CODE, 2);
        let saved_status = (
            self.mem[REG_AL_STATUS as usize],
            get_u16(&self.mem[..], REG_AL_STATUS_CODE),
        );
        self.mem[a..end].copy_from_slice(data);
        if keep_status {
            self.mem[REG_AL_STATUS as usize] = saved_status.0;
            put_u16(&mut self.mem[..], REG_AL_STATUS_CODE, saved_status.1);
        }
        if touches(REG_DC_PORT0_TIME, 1) {
            // Latch the receive times of the frame: port 0 now, port 1 when it comes back.
            let t = now + self.local_offset;
            let back = t + self.app_round_trip();
            self.mem[0x0900..0x0904].copy_from_slice(&(t as u32).to_le_bytes());
            self.mem[0x0904..0x0908].copy_from_slice(&(back as u32).to_le_bytes());
            self.mem[0x0908..0x0910].fill(0);
            self.mem[0x0918..0x0920].copy_from_slice(&t.to_le_bytes());
        }
        if touches(REG_DC_SYSTEM_TIME, 8) && data.len() >= 4 {
            // A time written to 0x0910 (FRMW from the reference clock) is compared with the
            // own system time; the difference steers the own clock (taken at once here).
            let mut written = [0u8; 8];
            let n = (end - REG_DC_SYSTEM_TIME as usize).min(8);
            written[..n].copy_from_slice(
                &self.mem[REG_DC_SYSTEM_TIME as usize..REG_DC_SYSTEM_TIME as usize + n],
            );
            let written = u64::from_le_bytes(written);
            let delay = u32::from_le_bytes(self.mem[0x0928..0x092C].try_into().expect("4")) as u64;
            let own = self.system_time(now);
            let diff = written.wrapping_add(delay).wrapping_sub(own);
            let offset = get_u64(&self.mem[..], REG_DC_OFFSET).wrapping_add(diff);
            self.mem[0x0920..0x0928].copy_from_slice(&offset.to_le_bytes());
            self.mem[0x092C..0x0930].fill(0);
        }
        if touches(REG_SII_CONTROL, 2) {
            self.sii_command();
        }
        if touches(REG_AL_CONTROL, 1) {
            self.al_control();
        }
        // The receive mailbox is full once its last byte is written.
        let sm0 = self.sm(0);
        if sm0.is_mailbox() && sm0.covers(a, data.len()) && end > sm0.last_byte() {
            let request = self.mem[sm0.start as usize..=sm0.last_byte()].to_vec();
            self.mailbox_in_full = true;
            let sm1 = self.sm(1);
            if let Some(response) = self.app.mailbox(&request) {
                if sm1.is_mailbox() && sm1.len > 0 {
                    let n = response.len().min(sm1.len as usize);
                    let s = sm1.start as usize;
                    self.mem[s..s + sm1.len as usize].fill(0);
                    self.mem[s..s + n].copy_from_slice(&response[..n]);
                    self.mailbox_out_full = true;
                }
            }
            // The application took the request out of the mailbox at once.
            self.mailbox_in_full = false;
        }
    }

    /// Propagation of a frame through the devices behind this one and back (ns).
    fn app_round_trip(&self) -> u64 {
        self.downstream_round_trip
    }

    /// Lets the application run after a frame passed: it reads the outputs from and writes the
    /// inputs into the process RAM behind SM2 and SM3, at the ESC's system time.
    pub fn step_application(&mut self, now: u64) {
        let system_time = self.system_time(now);
        let sync0 = if self.mem[REG_DC_SYNC_ACTIVE as usize] & 0b11 == 0b11 {
            let start = get_u64(&self.mem[..], REG_DC_START_TIME);
            let cycle = u32::from_le_bytes(self.mem[0x09A0..0x09A4].try_into().expect("4")) as u64;
            (cycle > 0).then_some((start, cycle))
        } else {
            None
        };
        let (sm2, sm3) = (self.sm(2), self.sm(3));
        let state = self.al_state();
        self.app
            .step(&mut self.mem[..], sm2, sm3, state, system_time, sync0);
    }

    fn sii_command(&mut self) {
        let ctl = get_u16(&self.mem[..], REG_SII_CONTROL);
        let read = ctl & (1 << 8) != 0;
        let write = ctl & (1 << 9) != 0;
        let word = u32::from_le_bytes(self.mem[0x0504..0x0508].try_into().expect("4")) as usize;
        if read {
            for i in 0..8 {
                self.mem[REG_SII_DATA as usize + i] =
                    self.sii.get(word * 2 + i).copied().unwrap_or(0xFF);
            }
        }
        if write {
            // The SII is read-only here: the write error bit.
            put_u16(&mut self.mem[..], REG_SII_CONTROL, (1 << 6) | (1 << 14));
            return;
        }
        // Done at once: busy and command bits cleared, 8-octet reads.
        put_u16(&mut self.mem[..], REG_SII_CONTROL, 1 << 6);
    }

    fn al_control(&mut self) {
        let ctl = self.mem[REG_AL_CONTROL as usize];
        let requested = ctl & 0x0F;
        let ack = ctl & 0x10 != 0;
        let (status, code) = self.al_status();
        let current = status & 0x0F;
        if status & AL_ERROR != 0 && !ack {
            // An error stays until it is acknowledged; only a step down is taken.
            if requested < current && matches!(requested, AL_INIT | AL_PRE_OP | AL_SAFE_OP) {
                self.set_al(requested, status & AL_ERROR, code);
            }
            return;
        }
        let ok = |to: u8| -> Result<(), u16> {
            match (current, to) {
                (_, AL_INIT) => Ok(()),
                (AL_INIT, AL_PRE_OP) | (AL_PRE_OP, AL_PRE_OP) => self.check_mailbox(),
                (AL_INIT, AL_BOOT) | (AL_BOOT, AL_BOOT) => Ok(()),
                (AL_SAFE_OP | AL_OP, AL_PRE_OP) => Ok(()),
                (AL_PRE_OP | AL_SAFE_OP, AL_SAFE_OP) | (AL_OP, AL_SAFE_OP) => {
                    self.check_process_data()
                }
                (AL_SAFE_OP | AL_OP, AL_OP) => Ok(()),
                (_, AL_PRE_OP | AL_SAFE_OP | AL_OP) => Err(al_code::INVALID_STATE_CHANGE),
                _ => Err(al_code::UNKNOWN_STATE),
            }
        };
        match ok(requested) {
            Ok(()) => self.set_al(requested, 0, 0),
            Err(code) => self.set_al(current, AL_ERROR, code),
        }
    }

    fn set_al(&mut self, state: u8, error: u8, code: u16) {
        let before = self.al_state();
        self.mem[REG_AL_STATUS as usize] = state | error;
        put_u16(&mut self.mem[..], REG_AL_STATUS_CODE, code);
        if state != before {
            if state <= AL_PRE_OP {
                self.mailbox_in_full = false;
                self.mailbox_out_full = false;
            }
            self.app.al_changed(state);
        }
    }

    fn check_mailbox(&self) -> Result<(), u16> {
        let (rx, tx) = self.app.mailbox_layout();
        let (sm0, sm1) = (self.sm(0), self.sm(1));
        if rx.0 == 0 {
            return Ok(());
        }
        if sm0.start != rx.0
            || sm0.len != rx.1
            || !sm0.is_mailbox()
            || !sm0.ecat_writes()
            || sm1.start != tx.0
            || sm1.len != tx.1
            || !sm1.is_mailbox()
            || sm1.ecat_writes()
            || !sm0.enabled
            || !sm1.enabled
        {
            return Err(al_code::INVALID_MAILBOX_CONFIG);
        }
        Ok(())
    }

    fn check_process_data(&self) -> Result<(), u16> {
        self.app.check_safe_op()?;
        let (out_len, in_len) = self.app.process_data_sizes();
        let (sm2, sm3) = (self.sm(2), self.sm(3));
        if out_len > 0 && (!sm2.enabled || sm2.len as usize != out_len || !sm2.ecat_writes()) {
            return Err(al_code::INVALID_SM_OUT_CONFIG);
        }
        if in_len > 0 && (!sm3.enabled || sm3.len as usize != in_len || sm3.ecat_writes()) {
            return Err(al_code::INVALID_SM_IN_CONFIG);
        }
        Ok(())
    }

    /// A logical datagram through this ESC's FMMUs: reads (ESC → frame) for read FMMUs and
    /// writes (frame → ESC) for write FMMUs, byte-wise. `read_allowed`/`write_allowed` by the
    /// command (LRD, LWR, LRW).
    pub fn logical(
        &mut self,
        logical: u32,
        data: &mut [u8],
        read_allowed: bool,
        write_allowed: bool,
        now: u64,
    ) -> Access {
        let mut acc = Access::default();
        let len = data.len() as u64;
        let start = logical as u64;
        // Process data is only exchanged from SAFE-OP on (outputs only in OP).
        let state = self.al_state();
        for i in 0..8 {
            let base = REG_FMMU0 as usize + 16 * i;
            let m = &self.mem[base..base + 16];
            if m[12] & 1 == 0 {
                continue;
            }
            let fl = u32::from_le_bytes(m[0..4].try_into().expect("4")) as u64;
            let flen = u16::from_le_bytes([m[4], m[5]]) as u64;
            let phys = u16::from_le_bytes([m[8], m[9]]) as u64;
            let (is_read, is_write) = (m[11] & 1 != 0, m[11] & 2 != 0);
            let lo = fl.max(start);
            let hi = (fl + flen).min(start + len);
            if lo >= hi {
                continue;
            }
            let (d0, p0, n) = (
                (lo - start) as usize,
                (phys + lo - fl) as usize,
                (hi - lo) as usize,
            );
            if is_read && read_allowed && state >= AL_SAFE_OP {
                data[d0..d0 + n].copy_from_slice(&self.mem[p0..p0 + n]);
                acc.read = true;
            }
            if is_write && write_allowed && state >= AL_SAFE_OP {
                if state == AL_OP {
                    self.mem[p0..p0 + n].copy_from_slice(&data[d0..d0 + n]);
                    self.app.outputs_written(now);
                }
                acc.wrote = true;
            }
        }
        acc
    }
}
