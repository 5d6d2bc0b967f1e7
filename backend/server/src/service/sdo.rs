//! SDO failures as the API answers them (the SDO endpoints and the writes a command makes
//! first, e.g. the homing method before homing in the drive).

use ethercat::bus::SdoError;

use crate::error::AppError;

/// 409 `sdo_aborted` with the CiA-301 abort code and its meaning, 404 for a SubDevice the bus
/// does not have, 503 `sdo_failed` for a transfer that did not complete.
pub fn sdo_failed(e: SdoError, position: u16, index: u16, sub: u8) -> AppError {
    match e {
        SdoError::NoSubDevice => AppError::not_found("subdevice", &position.to_string()),
        SdoError::Abort(code) => AppError::conflict(
            "sdo_aborted",
            format!(
                "SubDevice {position} aborted the SDO transfer of {index:#06x}:{sub} with {code:#010x} ({})",
                abort_text(code)
            ),
        ),
        SdoError::Failed(why) => AppError::unavailable(
            "sdo_failed",
            format!("SDO transfer of {index:#06x}:{sub} with SubDevice {position} failed: {why}"),
        ),
    }
}

/// CiA-301's words for the abort codes a drive answers most.
fn abort_text(code: u32) -> &'static str {
    match code {
        0x0503_0000 => "toggle bit not changed",
        0x0504_0001 => "command specifier not valid or unknown",
        0x0601_0000 => "unsupported access to an object",
        0x0601_0001 => "attempt to read a write-only object",
        0x0601_0002 => "attempt to write a read-only object",
        0x0601_0003 => "subindex cannot be written, subindex 0 must be 0 for write access",
        0x0602_0000 => "the object does not exist in the object dictionary",
        0x0604_0041 => "the object cannot be mapped into the PDO",
        0x0604_0042 => "the number and length of the objects would exceed the PDO length",
        0x0607_0010 => "data type does not match, length of service parameter does not match",
        0x0609_0011 => "subindex does not exist",
        0x0609_0030 => "value range of parameter exceeded",
        0x0800_0022 => "data cannot be transferred or stored because of the present device state",
        _ => "see the drive's manual",
    }
}
