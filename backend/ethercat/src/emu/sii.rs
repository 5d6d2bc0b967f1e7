//! SII EEPROM images (ETG.1000.6 §5.4, ETG.2010): the identity words, the standard mailbox, and
//! the categories a MainDevice reads — strings, general (name, CoE details), FMMU usage and
//! SyncManagers.

/// Identity of an emulated SubDevice (also object 0x1018).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Identity {
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
    pub name: String,
}

/// Where the mailboxes and process data SyncManagers sit in the ESC's RAM.
pub const MBOX_OUT_START: u16 = 0x1000;
pub const MBOX_IN_START: u16 = 0x1080;
pub const MBOX_LEN: u16 = 128;
pub const PDO_OUT_START: u16 = 0x1100;
pub const PDO_IN_START: u16 = 0x1180;

/// Mailbox protocol flag: CoE.
const PROTO_COE: u16 = 0x04;

fn category(out: &mut Vec<u8>, kind: u16, mut data: Vec<u8>) {
    if data.len() % 2 == 1 {
        data.push(0);
    }
    out.extend_from_slice(&kind.to_le_bytes());
    out.extend_from_slice(&((data.len() / 2) as u16).to_le_bytes());
    out.extend_from_slice(&data);
}

/// The image of a CiA-402 servo drive with a CoE mailbox: SM0/SM1 mailboxes, SM2 outputs,
/// SM3 inputs (their lengths come from the CoE PDO assignment), FMMU 0 outputs, 1 inputs,
/// 2 mailbox status.
pub fn servo_drive(id: &Identity) -> Vec<u8> {
    let mut words = [0u16; 0x40];
    words[0x08] = id.vendor_id as u16;
    words[0x09] = (id.vendor_id >> 16) as u16;
    words[0x0A] = id.product_code as u16;
    words[0x0B] = (id.product_code >> 16) as u16;
    words[0x0C] = id.revision as u16;
    words[0x0D] = (id.revision >> 16) as u16;
    words[0x0E] = id.serial as u16;
    words[0x0F] = (id.serial >> 16) as u16;
    // Standard mailbox: receive (MainDevice → SubDevice), send, protocols.
    words[0x18] = MBOX_OUT_START;
    words[0x19] = MBOX_LEN;
    words[0x1A] = MBOX_IN_START;
    words[0x1B] = MBOX_LEN;
    words[0x1C] = PROTO_COE;
    words[0x3E] = 7; // 8 kbit EEPROM, minus one
    words[0x3F] = 1; // version
    let mut out: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();

    // Strings: 1 = the device name, 2 = its group.
    let mut strings = vec![2u8];
    for s in [id.name.as_str(), "Drives"] {
        let b = s.as_bytes();
        strings.push(b.len().min(255) as u8);
        strings.extend_from_slice(&b[..b.len().min(255)]);
    }
    category(&mut out, 10, strings);

    // General: group string 2, image 0, order 1, name 1; CoE: SDO, SDO info, PDO assign and
    // configuration; ports 0 and 1 used.
    let mut general = vec![0u8; 32];
    general[0] = 2;
    general[2] = 1;
    general[3] = 1;
    general[5] = 0x01 | 0x02 | 0x04 | 0x08;
    general[14..16].copy_from_slice(&0x0011u16.to_le_bytes());
    category(&mut out, 30, general);

    // FMMU usage.
    category(&mut out, 40, vec![1, 2, 3, 0xFF]);

    // SyncManagers: start, length, control, reserved, enable, type.
    let mut sms = Vec::new();
    for (start, len, control, kind) in [
        (MBOX_OUT_START, MBOX_LEN, 0x26u8, 1u8),
        (MBOX_IN_START, MBOX_LEN, 0x22, 2),
        (PDO_OUT_START, 0, 0x64, 3),
        (PDO_IN_START, 0, 0x20, 4),
    ] {
        sms.extend_from_slice(&start.to_le_bytes());
        sms.extend_from_slice(&len.to_le_bytes());
        sms.extend_from_slice(&[control, 0, 1, kind]);
    }
    category(&mut out, 41, sms);
    out.extend_from_slice(&0xFFFFu16.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out.resize(1024, 0xFF);
    out
}
