//! The raw-socket tier: the real MainDevice's `tx_rx_task` (the path motiond uses on a real
//! NIC) on one end of a veth pair, the emulated segment on a raw socket on the other, inside a
//! network namespace this test makes (root, or `CAP_SYS_ADMIN` + `CAP_NET_RAW`). Skipped with a
//! message where network namespaces are not permitted.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use ethercat::emu::drive::{self, Cia402Emu, Plant};
use ethercat::emu::sii::Identity;
use ethercat::emu::{Segment, transport};
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, Timeouts};
use futures_lite::future::block_on;

/// Moves the calling thread into a new network namespace with a veth pair `ecA`–`ecB`, both
/// up. `Err` says why it cannot.
fn private_veth() -> Result<(), String> {
    // SAFETY: unshare affects only this thread (network namespaces are per task).
    if unsafe { libc::unshare(libc::CLONE_NEWNET) } != 0 {
        return Err(format!(
            "unshare(CLONE_NEWNET): {}",
            std::io::Error::last_os_error()
        ));
    }
    for args in [
        &["link", "add", "ecA", "type", "veth", "peer", "name", "ecB"][..],
        &["link", "set", "ecA", "up"],
        &["link", "set", "ecB", "up"],
    ] {
        let out = std::process::Command::new("ip")
            .args(args)
            .output()
            .map_err(|e| format!("ip: {e}"))?;
        if !out.status.success() {
            return Err(format!(
                "ip {}: {}",
                args.join(" "),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    Ok(())
}

/// Under CI (`CI` set) a test that cannot run fails; elsewhere it says SKIPPED and adds a line
/// to `MOTIOND_SKIPPED_LOG` (test-all's summary). The same rule as `tests/common::cannot_run`.
fn cannot_run(why: &str) {
    if std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0") {
        panic!("veth test cannot run here and CI is set: {why}");
    }
    println!("SKIPPED veth::the_maindevice_on_a_veth_pair: {why}");
    if let Ok(path) = std::env::var("MOTIOND_SKIPPED_LOG") {
        use std::io::Write;
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
        {
            let _ = writeln!(f, "veth::the_maindevice_on_a_veth_pair: {why}");
        }
    }
}

#[test]
fn the_maindevice_on_a_veth_pair_reads_the_emulated_identity_and_moves_the_drive() {
    static STORAGE: PduStorage<16, { PduStorage::element_size(1100) }> = PduStorage::new();
    // Everything that opens a socket runs on this thread, inside the namespace.
    let t = std::thread::spawn(|| {
        if let Err(why) = private_veth() {
            cannot_run(&format!(
                "the raw-socket tier needs a network namespace: {why}"
            ));
            return;
        }
        let start = Instant::now();
        let id = Identity {
            vendor_id: 0xACE,
            product_code: 0x0402_0001,
            revision: 1,
            serial: 7,
            name: "veth servo".into(),
        };
        let seg = Segment::new(
            vec![drive::servo(id, Plant::default())],
            Box::new(move || start.elapsed().as_nanos() as u64),
        )
        .shared();
        let stop = Arc::new(AtomicBool::new(false));
        let server =
            transport::serve_raw_socket("ecB", seg.clone(), stop.clone()).expect("emulator socket");
        let (tx, rx, pdu_loop) = STORAGE.try_split().expect("split once");
        let task = ethercrab::std::tx_rx_task("ecA", tx, rx).expect("MainDevice socket");
        std::thread::spawn(move || block_on(task));
        let md = MainDevice::new(
            pdu_loop,
            Timeouts {
                pdu: Duration::from_millis(200),
                ..Timeouts::default()
            },
            MainDeviceConfig {
                dc_static_sync_iterations: 100,
                retry_behaviour: RetryBehaviour::Count(5),
            },
        );
        run(&md, &seg);
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        server.join().unwrap();
    });
    t.join().expect("the test thread");
}

fn run(md: &MainDevice<'static>, seg: &Arc<Mutex<Segment>>) {
    block_on(async {
        let group = md
            .init_single_group::<2, 32>(ethercrab::std::ethercat_now)
            .await
            .expect("init over veth");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(sd.name(), "veth servo");
        assert_eq!(
            sd.sdo_read::<u32>(0x1018, 1).await.unwrap(),
            0xACE,
            "0x1018 over the wire"
        );
        assert_eq!(sd.sdo_read::<u32>(0x1018, 4).await.unwrap(), 7);
        // The drive's default mapping: controlword + target out, statusword + position in.
        let group = group.into_op(md).await.expect("OP");
        let mut reached = false;
        for _ in 0..5000 {
            group.tx_rx(md).await.expect("cycle");
            let sd = group.subdevice(md, 0).unwrap();
            let mut io = sd.io_raw_mut();
            let sw = u16::from_le_bytes([io.inputs()[0], io.inputs()[1]]);
            let pos = i32::from_le_bytes(io.inputs()[2..6].try_into().unwrap());
            let cw: u16 = match sw & 0x6F {
                0x27 | 0x23 => 0x0F,
                0x21 => 0x07,
                _ => 0x06,
            };
            let target = if sw & 0x6F == 0x27 { 2_000 } else { pos };
            io.outputs()[0..2].copy_from_slice(&cw.to_le_bytes());
            io.outputs()[2..6].copy_from_slice(&target.to_le_bytes());
            if sw & 0x6F == 0x27 && (pos - 2_000).abs() <= 1 {
                reached = true;
                break;
            }
            std::thread::sleep(Duration::from_micros(500));
        }
        assert!(
            reached,
            "the drive follows CSP setpoints sent over the veth pair"
        );
        let mut s = seg.lock().unwrap();
        assert!(s.frames > 100);
        assert!((s.app::<Cia402Emu>(0).unwrap().position - 2_000.0).abs() <= 1.0);
    });
}
