//! What a path will do, before it runs (the UI's preview, `POST /api/v1/path-analysis`): the
//! table is run in virtual time on a kernel of its own — ideal drives with the members'
//! parameters, the group's configuration — and sampled, so the preview is exactly what the
//! group would do from `start` with an override of 1. Blockers are released as they are
//! reached (a preview has no one to release them). Nothing is stored; off the cycle thread.

use super::*;
use crate::axis::AxisConfig;
use crate::drive::{DriveFeedback, DriveSetpoint};
use crate::kernel::Kernel;
use crate::params::AxisParameters;

/// One sample of the planned path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannedSample {
    /// Time since the start (s).
    pub t: f64,
    pub path_position: f64,
    pub path_velocity: f64,
    pub path_acceleration: f64,
    /// Index of the entry in the table, and whether a corner blend runs.
    pub entry: u32,
    pub in_blend: bool,
    /// Per role dimension ([X, Y, Z, C, ADDAX1..8]).
    pub position: PathPoint,
    pub velocity: PathPoint,
    pub acceleration: PathPoint,
}

/// The planned path: its samples and what it comes to.
#[derive(Clone, Debug, PartialEq)]
pub struct PathAnalysis {
    pub samples: Vec<PlannedSample>,
    /// Time until the last entry is done (s; when truncated, the time analysed), and the path
    /// length.
    pub duration: f64,
    pub length: f64,
    /// Per role dimension: the largest |velocity| and |acceleration| of the member.
    pub max_velocity: PathPoint,
    pub max_acceleration: PathPoint,
    /// The path did not end within the time analysed.
    pub truncated: bool,
}

/// Runs `table` from `start` (machine coordinates) for a group with `config` whose members have
/// `axes` (role, parameters) and whose entries are read in `frame` (MC_SetCoordinateTransform),
/// for at most `max_seconds`, keeping at most `max_samples` samples (evenly decimated; the last
/// one is always kept; memory stays within twice that however long the path runs). The failing
/// entry's index, field and error when the group would refuse the path.
#[allow(clippy::too_many_arguments)] // the preview's whole situation, each given once by its caller
pub fn analyse_path(
    config: &GroupConfig,
    axes: &[(GroupRole, AxisParameters)],
    start: PathPoint,
    frame: CoordTransform,
    table: &PathTable,
    cycle_time: f64,
    max_seconds: f64,
    max_samples: usize,
) -> Result<PathAnalysis, (usize, &'static str, ErrorId)> {
    let mut kernel = Kernel::new(cycle_time, axes.len());
    let mut events: Vec<crate::command::CommandEvent> = Vec::new();
    let mut id = 0;
    let mut submit = |k: &mut Kernel, target: Target, kind: CommandKind, events: &mut Vec<_>| {
        id += 1;
        k.submit(crate::command::Command { id, target, kind }, events)
    };
    for (slot, (role, parameters)) in axes.iter().enumerate() {
        let mut p = parameters.clone();
        // The preview moves ideal drives: no following error, no limit switches.
        p.axis_en_position_lag_monitoring = false;
        let config = AxisConfig {
            modulo: false,
            parameters: p,
            compensation_table: None,
            drive_executed: false,
        };
        let _ = kernel.insert_axis(slot as u16, Axis::new(config, cycle_time));
        let power = CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        };
        submit(&mut kernel, Target::Axis(slot as u16), power, &mut events);
        let at = CommandKind::SetPosition {
            position: start[role.dim()],
            relative: false,
            clear_position_lag: true,
            clear_position_offset: false,
        };
        submit(&mut kernel, Target::Axis(slot as u16), at, &mut events);
    }
    let _ = kernel.insert_group(0, Group::new(*config, cycle_time));
    for (slot, (role, _)) in axes.iter().enumerate() {
        let add = CommandKind::AddAxisToGroup {
            axis: slot as u16,
            role: *role,
        };
        submit(&mut kernel, Target::Group(0), add, &mut events);
    }
    submit(
        &mut kernel,
        Target::Group(0),
        CommandKind::GroupEnable,
        &mut events,
    );
    let n = axes.len();
    let mut sp = vec![DriveSetpoint::default(); n];
    let mut fb = vec![DriveFeedback::default(); n];
    let mut step = |k: &mut Kernel, sp: &mut Vec<DriveSetpoint>, events: &mut Vec<_>| {
        for (f, s) in fb.iter_mut().zip(sp.iter()) {
            *f = DriveFeedback {
                ready: true,
                enabled: s.enable,
                actual_position: s.position,
                actual_velocity: s.velocity,
                ..DriveFeedback::default()
            };
        }
        k.step(&fb, sp, events);
    };
    for _ in 0..1000 {
        if kernel
            .group_status(0)
            .is_some_and(|s| s.state == GroupState::Standby)
        {
            break;
        }
        step(&mut kernel, &mut sp, &mut events);
    }
    if kernel
        .group_status(0)
        .is_none_or(|s| s.state != GroupState::Standby)
    {
        return Err((0, "group", ErrorId::GROUP_CONFIG_INVALID));
    }
    if !frame.is_identity() {
        let set = CommandKind::SetCoordinateTransform { transform: frame };
        if let Verdict::Rejected(e) = submit(&mut kernel, Target::Group(0), set, &mut events) {
            return Err((0, "frame", e));
        }
    }
    let ctx = kernel.path_context(0).expect("inserted above");
    // Refusals name their entry as a prepared path does.
    let prepared = prepare_path(
        &ctx,
        table,
        kernel.group_status(0).expect("there").queue_end,
    )?;
    events.clear();
    let path_id = 1 << 40;
    match kernel.submit_prepared_path(path_id, 0, table, Some(&prepared), &mut events) {
        Verdict::Accepted => {}
        Verdict::Rejected(e) => return Err((0, "entries", e)),
    }
    let cycles = (max_seconds / cycle_time).ceil() as usize;
    let keep = max_samples.max(2);
    // Every `every`-th cycle is kept; when twice `keep` are, every other one goes and the
    // stride doubles, so a long path costs no more memory than a short one.
    let mut all = Vec::with_capacity(2 * keep + 1);
    let mut every = 1usize;
    let mut last = None;
    // The entry reached: the status's index goes back to 0 once the path is done.
    let mut entry = 0;
    let mut max_velocity = [0.0; MAX_PATH_DIMS];
    let mut max_acceleration = [0.0; MAX_PATH_DIMS];
    let mut done = false;
    let mut duration = 0.0;
    for c in 1..=cycles {
        step(&mut kernel, &mut sp, &mut events);
        let s = kernel.group_status(0).expect("there");
        if s.blocked {
            let release = CommandKind::ReleaseBlocker {
                blocker_id: s.blocker_id,
            };
            submit(&mut kernel, Target::Group(0), release, &mut events);
        }
        let mut velocity = [0.0; MAX_PATH_DIMS];
        let mut acceleration = [0.0; MAX_PATH_DIMS];
        for (slot, (role, _)) in axes.iter().enumerate() {
            if let Some(a) = kernel.status(slot as u16) {
                let d = role.dim();
                velocity[d] = a.set_velocity;
                acceleration[d] = a.set_acceleration;
                max_velocity[d] = f64::max(max_velocity[d], a.set_velocity.abs());
                max_acceleration[d] = f64::max(max_acceleration[d], a.set_acceleration.abs());
            }
        }
        entry = u32::max(entry, s.entry_index);
        let sample = PlannedSample {
            t: c as f64 * cycle_time,
            path_position: s.path_position,
            path_velocity: s.path_velocity,
            path_acceleration: s.path_acceleration,
            entry,
            in_blend: s.in_blending_segment,
            position: s.position,
            velocity,
            acceleration,
        };
        last = Some(sample);
        if (c - 1) % every == 0 {
            all.push(sample);
            if all.len() >= 2 * keep {
                all = all.into_iter().step_by(2).collect();
                every *= 2;
            }
        }
        done = events
            .iter()
            .any(|e| e.command == path_id && (e.outputs.done || e.outputs.error));
        events.clear();
        if done {
            duration = c as f64 * cycle_time;
            break;
        }
    }
    let length = last.map_or(0.0, |s| s.path_position);
    if !done {
        // Truncated: the time analysed.
        duration = last.map_or(0.0, |s| s.t);
    }
    let mut samples = if all.len() < keep {
        all
    } else {
        let every = all.len().div_ceil(keep - 1);
        all.into_iter().step_by(every).collect()
    };
    if let Some(last) = last {
        if samples.last() != Some(&last) {
            samples.push(last);
        }
    }
    Ok(PathAnalysis {
        samples,
        duration,
        length,
        max_velocity,
        max_acceleration,
        truncated: !done,
    })
}
