//! A request whose requester stopped waiting (and answered 503) is dropped undone by the cycle
//! thread: a command the client was told failed must never start later.

use std::sync::Arc;
use std::sync::atomic::Ordering::Relaxed;
use std::time::Duration;

use drives::{DriveConfig, SimBus};
use motion::{
    Axis, AxisConfig, AxisParameters, Command, CommandKind, DriveFeedback, DriveSetpoint, Target,
};
use server::cycle::{CycleThread, MAX_AXES, Request, Shared, Snapshot};

#[test]
fn an_expired_request_is_dropped_undone_and_a_live_one_acts() {
    let ct = 0.001;
    let shared = Arc::new(Shared::new(1_000_000));
    let (input, _output) = triple_buffer::triple_buffer(&Snapshot::default());
    let mut cycle = CycleThread::new(ct, Box::new(SimBus::new(MAX_AXES)), shared.clone(), input);
    let mut fb = vec![DriveFeedback::default(); MAX_AXES];
    let mut sp = vec![DriveSetpoint::default(); MAX_AXES];
    let insert = |ticket: u64, slot: u16| Request::InsertAxis {
        ticket,
        slot,
        axis: Axis::new(
            AxisConfig {
                modulo: false,
                parameters: AxisParameters::default(),
                compensation_table: None,
                drive_executed: false,
            },
            ct,
        ),
        drive: DriveConfig::default().build(ct),
        require_disabled: false,
    };
    let power = |id: u64| {
        Request::Command(Command {
            id,
            target: Target::Axis(0),
            kind: CommandKind::Power {
                enable: true,
                enable_positive: true,
                enable_negative: true,
                override_percent: 100.0,
                buffer_mode: motion::BufferMode::Aborting,
            },
        })
    };
    assert!(shared.push(insert(1, 0)).is_ok());
    cycle.one_cycle(&mut fb, &mut sp);
    assert_eq!(
        shared.replies.pop().map(|r| (r.ticket, r.result)),
        Some((1, Ok(())))
    );

    // Queued with no time to live: by the drain it has expired.
    assert!(shared.push_expiring(power(10), Duration::ZERO).is_ok());
    assert!(shared.push_expiring(insert(11, 1), Duration::ZERO).is_ok());
    std::thread::sleep(Duration::from_millis(2));
    for _ in 0..20 {
        cycle.one_cycle(&mut fb, &mut sp);
    }
    assert!(
        shared.replies.pop().is_none(),
        "an expired request was answered"
    );
    assert_eq!(shared.stats.requests_expired.load(Relaxed), 2);
    assert_eq!(
        shared.events.pop().map(|e| e.command),
        None,
        "the power acted"
    );
    let garbage = std::iter::from_fn(|| shared.garbage.pop()).count();
    assert_eq!(
        garbage, 2,
        "the expired insert's axis and drive go back to be freed"
    );

    // The same request in time acts.
    assert!(
        shared
            .push_expiring(power(12), Duration::from_secs(60))
            .is_ok()
    );
    cycle.one_cycle(&mut fb, &mut sp);
    assert_eq!(
        shared.replies.pop().map(|r| (r.ticket, r.result)),
        Some((12, Ok(())))
    );
    assert_eq!(shared.stats.requests_expired.load(Relaxed), 2);
}
