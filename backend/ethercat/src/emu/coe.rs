//! CANopen over EtherCAT (ETG.1000.6 §5.6, CiA-301 SDO): an object dictionary and the SDO
//! server behind the mailbox — expedited and normal upload and download, aborts with their
//! CiA-301 codes.

use std::collections::BTreeMap;

/// SDO abort codes (CiA-301 table 22).
pub mod abort {
    pub const TOGGLE: u32 = 0x0503_0000;
    pub const UNKNOWN_COMMAND: u32 = 0x0504_0001;
    pub const UNSUPPORTED_ACCESS: u32 = 0x0601_0000;
    pub const WRITE_ONLY: u32 = 0x0601_0001;
    pub const READ_ONLY: u32 = 0x0601_0002;
    pub const SUB0_NOT_ZERO: u32 = 0x0601_0003;
    pub const NO_OBJECT: u32 = 0x0602_0000;
    pub const NOT_MAPPABLE: u32 = 0x0604_0041;
    pub const PDO_TOO_LONG: u32 = 0x0604_0042;
    pub const LENGTH: u32 = 0x0607_0010;
    pub const NO_SUBINDEX: u32 = 0x0609_0011;
    pub const VALUE_RANGE: u32 = 0x0609_0030;
    pub const DEVICE_STATE: u32 = 0x0800_0022;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Ro,
    Rw,
    /// Writable in PRE-OP only (PDO mapping and assignment, CiA-301 / ETG.1020).
    RwPreOp,
}

#[derive(Clone, Debug)]
pub struct Entry {
    pub value: Vec<u8>,
    pub access: Access,
    /// May be mapped into a PDO (RxPDO if writable, TxPDO if not).
    pub mappable: bool,
    /// Strings may be written with any length up to their size.
    pub string: bool,
}

/// The object dictionary: (index, subindex) → entry.
#[derive(Clone, Debug, Default)]
pub struct Od {
    pub entries: BTreeMap<(u16, u8), Entry>,
}

impl Od {
    pub fn add(&mut self, index: u16, sub: u8, value: &[u8], access: Access, mappable: bool) {
        self.entries.insert(
            (index, sub),
            Entry {
                value: value.to_vec(),
                access,
                mappable,
                string: false,
            },
        );
    }
    pub fn add_string(&mut self, index: u16, s: &str) {
        self.entries.insert(
            (index, 0),
            Entry {
                value: s.as_bytes().to_vec(),
                access: Access::Ro,
                mappable: false,
                string: true,
            },
        );
    }
    pub fn get(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.entries.get(&(index, sub)).map(|e| e.value.as_slice())
    }
    /// Sets a value the device itself produces (status objects), keeping its width.
    pub fn set(&mut self, index: u16, sub: u8, bytes: &[u8]) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            let n = e.value.len().min(bytes.len());
            e.value[..n].copy_from_slice(&bytes[..n]);
        }
    }
    pub fn u8(&self, index: u16, sub: u8) -> u8 {
        self.get(index, sub)
            .and_then(|v| v.first().copied())
            .unwrap_or(0)
    }
    pub fn u16(&self, index: u16, sub: u8) -> u16 {
        self.get(index, sub)
            .map_or(0, |v| u16::from_le_bytes([v[0], v[1]]))
    }
    pub fn u32(&self, index: u16, sub: u8) -> u32 {
        self.get(index, sub)
            .map_or(0, |v| u32::from_le_bytes([v[0], v[1], v[2], v[3]]))
    }
    pub fn i32(&self, index: u16, sub: u8) -> i32 {
        self.u32(index, sub) as i32
    }
    pub fn i16(&self, index: u16, sub: u8) -> i16 {
        self.u16(index, sub) as i16
    }
    pub fn i8(&self, index: u16, sub: u8) -> i8 {
        self.u8(index, sub) as i8
    }
}

/// What the device allows a download to do, beyond the entry's own access.
pub trait WriteRules {
    /// `Err(abort code)` to refuse the write of `value` to (index, sub) in the current state.
    fn check_write(&self, od: &Od, index: u16, sub: u8, value: &[u8]) -> Result<(), u32>;
}

/// The reply mailbox frame for a CoE SDO service, `sdo` being the bytes after the CoE header.
fn reply(counter: u8, service: u16, sdo: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + sdo.len());
    out.extend_from_slice(&((2 + sdo.len()) as u16).to_le_bytes());
    out.extend_from_slice(&[0, 0, 0, 0x03 | (counter << 4)]);
    out.extend_from_slice(&(service << 12).to_le_bytes());
    out.extend_from_slice(sdo);
    out
}

fn abort_frame(counter: u8, index: u16, sub: u8, code: u32) -> Vec<u8> {
    let mut sdo = vec![0x80];
    sdo.extend_from_slice(&index.to_le_bytes());
    sdo.push(sub);
    sdo.extend_from_slice(&code.to_le_bytes());
    reply(counter, 3, &sdo)
}

/// Serves one mailbox request: CoE SDO requests get their response or abort; anything else
/// (other protocols, SDO information) gets an abort or nothing, as a device without them.
pub fn serve(
    od: &mut Od,
    rules: &dyn WriteRules,
    request: &[u8],
    mailbox_len: usize,
) -> Option<Vec<u8>> {
    if request.len() < 16 {
        return None;
    }
    let len = u16::from_le_bytes([request[0], request[1]]) as usize;
    let kind = request[5] & 0x0F;
    let counter = (request[5] >> 4) & 0x07;
    if kind != 3 || len < 10 {
        return None;
    }
    let service = u16::from_le_bytes([request[6], request[7]]) >> 12;
    let cmd = request[8];
    let index = u16::from_le_bytes([request[9], request[10]]);
    let sub = request[11];
    if service != 2 {
        return Some(abort_frame(counter, index, sub, abort::UNKNOWN_COMMAND));
    }
    if cmd & 0x10 != 0 {
        // Complete access is not offered (the SII's CoE details say so).
        return Some(abort_frame(counter, index, sub, abort::UNSUPPORTED_ACCESS));
    }
    match cmd >> 5 {
        // Initiate download.
        1 => {
            let expedited = cmd & 0x02 != 0;
            let sized = cmd & 0x01 != 0;
            let data: Vec<u8> = if expedited {
                let n = if sized {
                    4 - ((cmd >> 2) & 0x03) as usize
                } else {
                    4
                };
                request[12..12 + n].to_vec()
            } else {
                let size = u32::from_le_bytes(request[12..16].try_into().expect("4")) as usize;
                let avail = (len + 6).min(request.len()).saturating_sub(16);
                if size > avail {
                    // Segmented downloads are not offered: objects here fit the mailbox.
                    return Some(abort_frame(counter, index, sub, abort::UNKNOWN_COMMAND));
                }
                request[16..16 + size].to_vec()
            };
            let code = download(od, rules, index, sub, &data);
            Some(match code {
                Ok(()) => {
                    let mut sdo = vec![0x60];
                    sdo.extend_from_slice(&index.to_le_bytes());
                    sdo.push(sub);
                    sdo.extend_from_slice(&[0; 4]);
                    reply(counter, 3, &sdo)
                }
                Err(code) => abort_frame(counter, index, sub, code),
            })
        }
        // Initiate upload.
        2 => {
            let Some(entry) = od.entries.get(&(index, sub)) else {
                let code = if od.entries.keys().any(|(i, _)| *i == index) {
                    abort::NO_SUBINDEX
                } else {
                    abort::NO_OBJECT
                };
                return Some(abort_frame(counter, index, sub, code));
            };
            let v = &entry.value;
            let mut sdo = Vec::new();
            if v.len() <= 4 && !entry.string {
                sdo.push(0x40 | (((4 - v.len()) as u8) << 2) | 0x03);
                sdo.extend_from_slice(&index.to_le_bytes());
                sdo.push(sub);
                let mut d = [0u8; 4];
                d[..v.len()].copy_from_slice(v);
                sdo.extend_from_slice(&d);
            } else {
                if 16 + v.len() > mailbox_len {
                    return Some(abort_frame(counter, index, sub, abort::UNKNOWN_COMMAND));
                }
                sdo.push(0x41);
                sdo.extend_from_slice(&index.to_le_bytes());
                sdo.push(sub);
                sdo.extend_from_slice(&(v.len() as u32).to_le_bytes());
                sdo.extend_from_slice(v);
            }
            Some(reply(counter, 3, &sdo))
        }
        4 => None,
        _ => Some(abort_frame(counter, index, sub, abort::UNKNOWN_COMMAND)),
    }
}

fn download(
    od: &mut Od,
    rules: &dyn WriteRules,
    index: u16,
    sub: u8,
    data: &[u8],
) -> Result<(), u32> {
    let Some(entry) = od.entries.get(&(index, sub)) else {
        return Err(if od.entries.keys().any(|(i, _)| *i == index) {
            abort::NO_SUBINDEX
        } else {
            abort::NO_OBJECT
        });
    };
    if entry.access == Access::Ro {
        return Err(abort::READ_ONLY);
    }
    let width = entry.value.len();
    // A shorter expedited value of an integer is zero-extended (a u8 written to a u16).
    if data.len() > width && data[width..].iter().any(|b| *b != 0)
        || entry.string && data.len() > width
    {
        return Err(abort::LENGTH);
    }
    rules.check_write(od, index, sub, data)?;
    let entry = od.entries.get_mut(&(index, sub)).expect("checked");
    let n = width.min(data.len());
    entry.value[..n].copy_from_slice(&data[..n]);
    entry.value[n..].fill(0);
    Ok(())
}
