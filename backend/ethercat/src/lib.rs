//! motiond's EtherCAT: CiA-402 servo drives on an EtherCAT segment through ethercrab (pinned
//! exactly), and an emulated segment ([`emu`]) that the real MainDevice drives without
//! hardware. This is the only crate of motiond's drives with network I/O; the CiA-402 logic
//! itself (`drives::cia402`) stays free of it.

pub mod bus;
pub mod emu;
pub mod raw;
pub mod txrx;

pub use ethercrab;
