//! The published snapshot copies an axis's status only when it changed since that buffer held
//! it (issue 27; an axis at rest changes only its cycle counter). What a reader sees must still be the axis's status of the published cycle,
//! in every one of the three buffers: a standing axis's cycle counter advances, a move shows
//! cycle by cycle, a slot taken by another axis shows the new one.

use std::sync::Arc;

use drives::{DriveConfig, SimBus};
use motion::{
    Axis, AxisConfig, AxisParameters, AxisState, BufferMode, Command, CommandKind, Direction,
    DriveFeedback, DriveSetpoint, Dynamics, MoveOptions, Target,
};
use server::cycle::{CycleThread, MAX_AXES, Request, Shared, Snapshot};

struct Rig {
    cycle: CycleThread,
    shared: Arc<Shared>,
    output: triple_buffer::Output<Snapshot>,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
}

impl Rig {
    /// One cycle; the snapshot it published.
    fn step(&mut self) -> Snapshot {
        self.cycle.one_cycle(&mut self.fb, &mut self.sp);
        self.output.read().clone()
    }

    fn request(&mut self, r: Request) {
        assert!(self.shared.push(r).is_ok());
    }
}

fn axis(modulo: bool) -> Box<Axis> {
    Axis::new(
        AxisConfig {
            modulo,
            parameters: AxisParameters {
                axis_encoder_modulo_value: 360.0,
                ..AxisParameters::default()
            },
            compensation_table: None,
            drive_executed: false,
        },
        0.001,
    )
}

fn insert(ticket: u64, a: Box<Axis>) -> Request {
    Request::InsertAxis {
        ticket,
        slot: 0,
        axis: a,
        drive: DriveConfig::default().build(0.001),
        require_disabled: false,
    }
}

fn command(id: u64, kind: CommandKind) -> Request {
    Request::Command(Command {
        id,
        target: Target::Axis(0),
        kind,
    })
}

fn power(id: u64, enable: bool) -> Request {
    command(
        id,
        CommandKind::Power {
            enable,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    )
}

#[test]
fn every_published_buffer_shows_the_status_of_its_cycle() {
    let shared = Arc::new(Shared::new(1_000_000));
    let (input, output) = triple_buffer::triple_buffer(&Snapshot::default());
    let mut rig = Rig {
        cycle: CycleThread::new(
            0.001,
            Box::new(SimBus::new(MAX_AXES)),
            shared.clone(),
            input,
        ),
        shared,
        output,
        fb: vec![DriveFeedback::default(); MAX_AXES],
        sp: vec![DriveSetpoint::default(); MAX_AXES],
    };
    rig.request(insert(1, axis(false)));
    rig.request(power(2, true));
    for _ in 0..50 {
        rig.step();
    }

    // Standing: nothing but the cycle counter changes, and that shows in every buffer. The
    // simulated drive's feedback is constant at standstill: the axis steps at rest, its
    // status is not copied again.
    for _ in 0..10 {
        let snap = rig.step();
        assert!(rig.cycle.kernel.axis(0).expect("axis").is_at_rest());
        let s = snap.axes[0].expect("slot 0 holds an axis");
        assert_eq!(s.state, AxisState::Standstill);
        assert_eq!(s.nc_cycle_counter, snap.cycle, "a stale cycle counter");
        assert_eq!(s.set_velocity, 0.0);
    }

    // A move: each cycle's snapshot is newer than the last (a buffer holding an older copy
    // would show a lower velocity or position).
    rig.request(command(
        3,
        CommandKind::MoveVelocity {
            velocity: 100.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    ));
    let mut last = rig.step().axes[0].expect("axis");
    let mut rising = 0;
    for _ in 0..30 {
        let snap = rig.step();
        let s = snap.axes[0].expect("axis");
        assert_eq!(s.nc_cycle_counter, snap.cycle);
        assert!(
            s.set_position > last.set_position,
            "cycle {}: set position {} after {}",
            snap.cycle,
            s.set_position,
            last.set_position
        );
        rising += usize::from(s.set_velocity > last.set_velocity);
        last = s;
    }
    assert_eq!(rising, 30, "the velocity rises in every cycle of the ramp");

    // The slot taken by another axis (powered off: the kernel may replace it) shows the new
    // axis in every buffer, although both axes' statuses changed equally often.
    rig.request(power(4, false));
    for _ in 0..20 {
        rig.step();
    }
    rig.request(insert(5, axis(true)));
    rig.step();
    for _ in 0..5 {
        let snap = rig.step();
        let s = snap.axes[0].expect("axis");
        assert!(s.op_modes.modulo, "a buffer still shows the replaced axis");
        assert_eq!(s.state, AxisState::Disabled);
        assert_eq!(s.nc_cycle_counter, snap.cycle);
    }
}
