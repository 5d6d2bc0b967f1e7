//! Which parts of an axis a step touches: steps N axes (velocity or positioning jobs, ideal
//! drives) into their constant phase, or lets them stand (at rest), prints where each axis
//! lies, then steps ten cycles between two reads of a marker. `scripts/bench/axis_lines.py`
//! runs it under valgrind's lackey and maps the accesses between the markers to offsets in
//! `Axis` (the spans of `backend/motion/src/axis/prefetch.rs` come from it).
//!
//!     axis_lines [AXES] [velocity|positioning|standing]

use motion::*;

static MARKER: [u64; 8] = [0; 8];

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(16, |a| a.parse().expect("AXES"));
    let load = args.next().unwrap_or_else(|| "velocity".into());
    let mut k = Kernel::new(0.001, n);
    for i in 0..n {
        let parameters = AxisParameters {
            axis_max_pos_lag_value: 1e6,
            ..AxisParameters::default()
        };
        let config = AxisConfig {
            parameters,
            ..AxisConfig::default()
        };
        k.insert_axis(i as u16, Axis::new(config, 0.001)).unwrap();
    }
    let mut fb = vec![DriveFeedback::default(); n];
    let mut sp = vec![DriveSetpoint::default(); n];
    let mut events: Vec<CommandEvent> = Vec::new();
    let mut id = 0;
    let mut submit = |k: &mut Kernel, axis: u16, kind: CommandKind, events: &mut Vec<_>| {
        id += 1;
        let target = Target::Axis(axis);
        let verdict = k.submit(Command { id, target, kind }, events);
        // A refused command would leave the axis standing: the trace would be of the wrong step.
        assert!(matches!(verdict, Verdict::Accepted), "{verdict:?}");
    };
    let step = |k: &mut Kernel,
                fb: &mut [DriveFeedback],
                sp: &mut [DriveSetpoint],
                events: &mut Vec<_>| {
        k.step(fb, sp, events);
        for (s, f) in sp.iter().zip(fb.iter_mut()) {
            f.ready = true;
            f.enabled = s.enable;
            f.actual_position = s.position;
            f.actual_velocity = s.velocity;
        }
        events.clear();
    };
    for a in 0..n as u16 {
        let power = CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        };
        submit(&mut k, a, power, &mut events);
    }
    for _ in 0..10 {
        step(&mut k, &mut fb, &mut sp, &mut events);
    }
    for a in (0..n as u16).filter(|_| load != "standing") {
        let kind = if load == "positioning" {
            CommandKind::MoveAbsolute(Positioning {
                position: 1e7,
                velocity: 100.0,
                dynamics: Dynamics::default(),
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            })
        } else {
            CommandKind::MoveVelocity {
                velocity: 100.0,
                dynamics: Dynamics::default(),
                direction: Direction::Positive,
                buffer_mode: BufferMode::Aborting,
                options: MoveOptions::default(),
            }
        };
        submit(&mut k, a, kind, &mut events);
    }
    // Past the acceleration phase (or at rest).
    for _ in 0..2000 {
        step(&mut k, &mut fb, &mut sp, &mut events);
    }
    for a in 0..n as u16 {
        let at = k.axis(a).expect("inserted") as *const Axis as usize;
        eprintln!("axis {at:x} {}", std::mem::size_of::<Axis>());
    }
    eprintln!("marker {:x}", MARKER.as_ptr() as usize);
    std::hint::black_box(unsafe { std::ptr::read_volatile(&MARKER[0]) });
    for _ in 0..10 {
        step(&mut k, &mut fb, &mut sp, &mut events);
    }
    std::hint::black_box(unsafe { std::ptr::read_volatile(&MARKER[0]) });
}
