//! The real ethercrab MainDevice against the emulated segment, in-process: discovery with the
//! SII identity, the PRE-OP CoE script (PDO mapping and assignment, mode of operation),
//! distributed clocks with SYNC0, SAFE-OP → OP, the CiA-402 enable sequence and a CSP move,
//! one setpoint per SYNC0 pulse; SDO aborts with their CiA-301 codes; a drive fault.

mod common;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use ethercat::emu::drive::{self, Cia402Emu};
use ethercat::emu::{Segment, transport};
use ethercrab::error::{Error, MailboxError};
use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{DcSync, MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, Timeouts};
use futures_lite::future::block_on;

const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
const CYCLE: Duration = Duration::from_millis(1);

fn segment(n: u32) -> Arc<Mutex<Segment>> {
    common::servos(n, true)
}

fn maindevice(
    storage: &'static PduStorage<16, MAX_PDU_DATA>,
    seg: Arc<Mutex<Segment>>,
) -> MainDevice<'static> {
    let (tx, rx, pdu_loop) = storage.try_split().expect("split once");
    transport::spawn_in_process(tx, rx, seg).expect("thread");
    MainDevice::new(
        pdu_loop,
        Timeouts {
            pdu: Duration::from_millis(200),
            ..Timeouts::default()
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 200,
            retry_behaviour: RetryBehaviour::Count(3),
        },
    )
}

// RxPDO: controlword, target position, mode. TxPDO: statusword, position, velocity, mode
// display, error code.
const RX: [u32; 3] = [0x6040_0010, 0x607A_0020, 0x6060_0008];
const TX: [u32; 5] = [
    0x6041_0010,
    0x6064_0020,
    0x606C_0020,
    0x6061_0008,
    0x603F_0010,
];

#[test]
fn ethercrab_brings_two_emulated_drives_to_op_with_dc_and_moves_one_in_csp() {
    static STORAGE: PduStorage<16, MAX_PDU_DATA> = PduStorage::new();
    let seg = segment(2);
    let md = maindevice(&STORAGE, seg.clone());
    block_on(async {
        let mut group = md
            .init_single_group::<4, 64>(ethercrab::std::ethercat_now)
            .await
            .expect("init");
        assert_eq!(group.len(), 2);
        for (i, mut sd) in group.iter_mut(&md).enumerate() {
            let id = sd.identity();
            assert_eq!(
                (id.vendor_id, id.product_id, id.revision, id.serial),
                (0xACE, 0x0402_0001, 0x0001_0000 + i as u32, 1000 + i as u32)
            );
            assert_eq!(sd.name(), format!("motiond servo {i}"));
            sd.sdo_write_array(0x1600, RX).await.expect("RxPDO mapping");
            sd.sdo_write_array(0x1A00, TX).await.expect("TxPDO mapping");
            sd.sdo_write_array(0x1C12, [0x1600u16])
                .await
                .expect("RxPDO assignment");
            sd.sdo_write_array(0x1C13, [0x1A00u16])
                .await
                .expect("TxPDO assignment");
            sd.sdo_write(0x6060, 0, 8i8).await.expect("CSP");
            sd.sdo_write(0x1C32, 1, 2u16).await.expect("SYNC0");
            assert_eq!(
                sd.sdo_read::<u32>(0x1018, 4).await.unwrap(),
                1000 + i as u32
            );
            assert_eq!(
                sd.sdo_read::<u32>(0x1000, 0).await.unwrap(),
                0x0002_0192,
                "a CiA-402 drive"
            );
            sd.set_dc_sync(DcSync::Sync0);
        }
        let group = group.into_pre_op_pdi(&md).await.expect("PRE-OP with PDI");
        for sd in group.iter(&md) {
            let io = sd.io_raw();
            assert_eq!(
                (io.inputs().len(), io.outputs().len()),
                (13, 7),
                "sizes from the CoE mapping"
            );
        }
        for _ in 0..50 {
            group.tx_rx_sync_system_time(&md).await.expect("DC sync");
        }
        let group = group
            .configure_dc_sync(
                &md,
                DcConfiguration {
                    start_delay: Duration::from_millis(5),
                    sync0_period: CYCLE,
                    sync0_shift: Duration::ZERO,
                },
            )
            .await
            .expect("DC");
        let group = group.into_safe_op(&md).await.expect("SAFE-OP");
        let group = group.request_into_op(&md).await.expect("OP requested");
        let mut op = false;
        for _ in 0..500 {
            let r = group.tx_rx_dc(&md).await.expect("cycle");
            if r.all_op() {
                op = true;
                break;
            }
            std::thread::sleep(r.extra.next_cycle_wait.min(CYCLE));
        }
        assert!(op, "the group reaches OP");

        // Enable drive 0 (shutdown → switch on → enable operation) and move it 50 000
        // increments in CSP; drive 1 stays disabled.
        let mut target = 0i32;
        let mut enabled_at = None;
        let mut wkc = Vec::new();
        for cycle in 0..3000 {
            let r = group.tx_rx_dc(&md).await.expect("cycle");
            wkc.push(r.working_counter);
            let sd = group.subdevice(&md, 0).unwrap();
            let mut io = sd.io_raw_mut();
            let i = io.inputs();
            let sw = u16::from_le_bytes([i[0], i[1]]);
            let actual = i32::from_le_bytes(i[2..6].try_into().unwrap());
            let cw: u16 = match sw & 0x6F {
                0x27 => 0x0F,
                0x23 => 0x0F,
                0x21 => 0x07,
                _ if sw & 0x4F == 0x40 => 0x06,
                _ => 0x06,
            };
            if sw & 0x6F == 0x27 && enabled_at.is_none() {
                enabled_at = Some(cycle);
                target = actual;
            }
            if enabled_at.is_some() && target < 50_000 {
                target = (target + 100).min(50_000);
            }
            let o = io.outputs();
            o[0..2].copy_from_slice(&cw.to_le_bytes());
            o[2..6].copy_from_slice(&target.to_le_bytes());
            o[6] = 8;
            drop(io);
            if target == 50_000 && (actual - 50_000).abs() <= 1 {
                break;
            }
            std::thread::sleep(r.extra.next_cycle_wait.min(CYCLE));
        }
        assert!(enabled_at.is_some(), "operation enabled");
        let mut s = seg.lock().unwrap();
        let d0 = s.app::<Cia402Emu>(0).unwrap();
        assert_eq!(d0.state, drive::State::OperationEnabled);
        assert!(
            (d0.position - 50_000.0).abs() <= 1.0,
            "the drive reached the target: {}",
            d0.position
        );
        assert!(d0.setpoints_taken > 0);
        assert_eq!(
            s.app::<Cia402Emu>(1).unwrap().state,
            drive::State::SwitchOnDisabled
        );
        drop(s);
        // LRW: each drive reads (+1) and writes (+2).
        assert!(
            wkc.iter().all(|w| *w == 6),
            "working counters {:?}",
            &wkc[..wkc.len().min(10)]
        );
    });
}

#[test]
fn sdo_errors_are_cia301_aborts_and_a_mapping_must_be_valid() {
    static STORAGE: PduStorage<16, MAX_PDU_DATA> = PduStorage::new();
    let seg = segment(1);
    let md = maindevice(&STORAGE, seg);
    block_on(async {
        let group = md
            .init_single_group::<2, 64>(ethercrab::std::ethercat_now)
            .await
            .expect("init");
        let sd = group.subdevice(&md, 0).unwrap();
        let abort_of = |r: Result<(), Error>| match r {
            Err(Error::Mailbox(MailboxError::Aborted { code, .. })) => u32::from(code),
            other => panic!("expected an abort, got {other:?}"),
        };
        assert_eq!(
            abort_of(sd.sdo_write(0x2000, 0, 1u8).await),
            0x0602_0000,
            "no such object"
        );
        assert_eq!(
            abort_of(sd.sdo_write(0x6041, 0, 1u16).await),
            0x0601_0002,
            "read only"
        );
        assert_eq!(
            abort_of(sd.sdo_write(0x6060, 0, 4i8).await),
            0x0609_0030,
            "profile torque is not offered"
        );
        sd.sdo_write(0x6060, 0, 1i8)
            .await
            .expect("profile position is");
        sd.sdo_write(0x6098, 0, 34i8)
            .await
            .expect("homing method 34 is");
        assert_eq!(
            abort_of(sd.sdo_write(0x6098, 0, 19i8).await),
            0x0609_0030,
            "homing method 19 is not offered"
        );
        assert_eq!(
            abort_of(sd.sdo_write(0x1600, 1, 0x6041_0010u32).await),
            0x0601_0003,
            "sub 0 first"
        );
        sd.sdo_write(0x1600, 0, 0u8).await.unwrap();
        sd.sdo_write(0x1600, 1, 0x6041_0010u32).await.unwrap();
        assert_eq!(
            abort_of(sd.sdo_write(0x1600, 0, 1u8).await),
            0x0604_0041,
            "a TxPDO object in an RxPDO"
        );
        assert_eq!(sd.sdo_read::<u8>(0x1018, 0).await.unwrap(), 4);
    });
}

/// Fault injection: a drive fault shows in the statusword (fault bit) with its 0x603F code,
/// readable by SDO too, and a fault reset (controlword bit 7 edge) clears it; lost frames are
/// a timeout of that exchange (no retries in OP) and the next exchange works again.
#[test]
fn an_injected_drive_fault_and_lost_frames_are_seen_by_the_maindevice() {
    static STORAGE: PduStorage<16, MAX_PDU_DATA> = PduStorage::new();
    let seg = segment(1);
    let (tx, rx, pdu_loop) = STORAGE.try_split().expect("split once");
    transport::spawn_in_process(tx, rx, seg.clone()).expect("thread");
    let md = MainDevice::new(
        pdu_loop,
        Timeouts {
            pdu: Duration::from_millis(500),
            ..Timeouts::default()
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 10,
            retry_behaviour: RetryBehaviour::None,
        },
    );
    block_on(async {
        let group = md
            .init_single_group::<2, 32>(ethercrab::std::ethercat_now)
            .await
            .expect("init");
        let group = group.into_op(&md).await.expect("OP");
        let exchange = |cw: u16| {
            let group = &group;
            let md = &md;
            async move {
                group.tx_rx(md).await?;
                let sd = group.subdevice(md, 0).unwrap();
                let mut io = sd.io_raw_mut();
                let sw = u16::from_le_bytes([io.inputs()[0], io.inputs()[1]]);
                io.outputs()[0..2].copy_from_slice(&cw.to_le_bytes());
                Ok::<u16, Error>(sw)
            }
        };
        let mut sw = 0;
        for _ in 0..50 {
            sw = exchange(0x06).await.expect("cycle");
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(sw & 0x6F, 0x21, "ready to switch on: {sw:#06x}");
        seg.lock()
            .unwrap()
            .app::<Cia402Emu>(0)
            .unwrap()
            .inject_fault(0x2310);
        for _ in 0..20 {
            sw = exchange(0x06).await.expect("cycle");
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(sw & 0x4F, 0x08, "fault: {sw:#06x}");
        let sd = group.subdevice(&md, 0).unwrap();
        assert_eq!(
            sd.sdo_read::<u16>(0x603F, 0).await.unwrap(),
            0x2310,
            "the drive's error code"
        );
        for cw in [0x00, 0x80, 0x80, 0x06, 0x06, 0x06] {
            sw = exchange(cw).await.expect("cycle");
            std::thread::sleep(Duration::from_millis(2));
        }
        assert_eq!(
            sw & 0x6F,
            0x21,
            "fault reset, then shutdown: ready to switch on: {sw:#06x}"
        );
        assert_eq!(sw & 0x08, 0, "no fault bit: {sw:#06x}");

        let lost_before = seg.lock().unwrap().lost;
        seg.lock().unwrap().faults.drop_frames = 1;
        assert!(
            matches!(exchange(0x06).await, Err(Error::Timeout(_))),
            "a lost frame is a timeout"
        );
        assert_eq!(seg.lock().unwrap().lost, lost_before + 1);
        exchange(0x06).await.expect("the next cycle answers");
    });
}
