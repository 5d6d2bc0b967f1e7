//! Blocks an axis does not use cost a moving axis the test of one bit per cycle (issue 27),
//! not the reading of their state. Each block's per-cycle check reads its own state — the
//! correction sources, the cam queues, the phasing, the superposition, the touch probe, the
//! external setpoint generator, MC_OverrideFilter's waiting value, MC_WriteDriveOperationMode's
//! wait — and each of those lies on cache lines of its own: on a moving axis that used none
//! of them the checks were about a fifth of the lines its step touched. So a block found idle
//! at the end of a full step is marked in one bit, and the next steps skip its check and its
//! part of the status until the axis is woken.
//!
//! One block is also started by the drive: a drive that reports torque mode unasked is timed
//! (§5.7.1's danger note) whatever the marks say, and that drops the drive-mode mark
//! (`a_drive_in_torque_mode_is_seen_with_every_block_marked_idle` in `kernel.rs`).
//!
//! Why that is exact: a block goes from idle to in use only through a command or a call from
//! outside the step (every `pub` `&mut self` method calls [`Axis::wake`], which clears the
//! marks); inside the step an idle block only stays idle. A coupling started inside the step
//! (a buffered MC_CamIn taking over) is not covered by a mark: the cam part of the status is
//! skipped only while the axis runs no cam. The status keeps what the last full status update
//! wrote for an idle block, which is what it would write again.
//!
//! So a block that is ever to start from inside the step (say, a buffered command that
//! arms it when the job before it ends) must clear its mark there (`Idle::forget`).
//!
//! Debug builds hold the claim: every status update with a mark set asserts that the block is
//! idle and that its part of the status is what the full update would write
//! (`idle_blocks_wake_with_their_command` in `kernel.rs`' tests, and every other test).

use super::*;

/// The blocks found idle (a bit each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Idle(u16);

impl Idle {
    /// No correction source commanded: the total correction stays what it is.
    pub(super) const CORRECTIONS: u16 = 1;
    /// Nothing cam-related queued or waiting, and the status's cam info settled.
    pub(super) const CAM: u16 = 1 << 1;
    /// No phasing running or engaged, no phase shift.
    pub(super) const PHASING: u16 = 1 << 2;
    /// No MC_MoveSuperImposed running.
    pub(super) const SUPERPOSITION: u16 = 1 << 3;
    /// No MC_TouchProbe armed.
    pub(super) const PROBE: u16 = 1 << 4;
    /// The external setpoint generator is not enabled.
    pub(super) const EXT: u16 = 1 << 5;
    /// The status's operation modes and encoder scaling factor are the parameters' (they
    /// change only with a parameter write, a submit).
    pub(super) const CONFIG: u16 = 1 << 6;
    /// No MC_OverrideFilter value waits for its quiet time.
    pub(super) const OVERRIDE_FILTER: u16 = 1 << 7;
    /// No MC_WriteDriveOperationMode waits for the drive, and no drive left in torque mode is
    /// being timed (the step still looks whenever the drive reports torque mode).
    pub(super) const DRIVE_MODE: u16 = 1 << 8;
    const COUNT: u32 = 9;
    const ALL: u16 = (1 << Idle::COUNT) - 1;

    pub(super) fn has(self, bit: u16) -> bool {
        self.0 & bit != 0
    }

    /// Block `bit` is to be looked at again after this step.
    pub(super) fn forget(&mut self, bit: u16) {
        self.0 &= !bit;
    }
}

impl Axis {
    /// Block `bit` was found idle and nothing woke the axis since.
    pub(super) fn idle(&self, bit: u16) -> bool {
        self.idle.has(bit)
    }

    /// The marks, for tests.
    #[cfg(test)]
    pub(crate) fn idle_marks(&self) -> u16 {
        self.idle.0
    }

    /// Something from outside the step: every block is looked at again.
    pub(super) fn forget_idle(&mut self) {
        self.idle = Idle::default();
    }

    /// Whether block `bit` is idle now (what a mark claims).
    fn is_idle(&self, bit: u16) -> bool {
        match bit {
            Idle::CORRECTIONS => {
                let c = &self.corrections;
                // The total is what was sent: no source moves it any more.
                c.settled() && c.total().to_bits() == c.sent.to_bits()
            }
            Idle::CAM => {
                self.cam.nothing_queued() && !self.cam.waits_for_coupling() && self.cam.idle_info
            }
            Idle::PHASING => self.phasing.unused(),
            Idle::SUPERPOSITION => self.superposition.running.is_none(),
            Idle::PROBE => self.probe.is_none(),
            Idle::EXT => !self.ext.enabled,
            Idle::CONFIG => true,
            Idle::OVERRIDE_FILTER => self.override_filter.settled(),
            Idle::DRIVE_MODE => self.torque.settled(),
            _ => unreachable!("one block at a time"),
        }
    }

    /// After a full step: marks the blocks not yet marked that are idle now. A block in use
    /// is looked at every cycle (it pays for itself); an idle one once.
    pub(super) fn settle_idle(&mut self) {
        if self.idle.0 == Idle::ALL {
            return;
        }
        let mut idle = self.idle.0;
        for bit in (0..Idle::COUNT).map(|i| 1 << i) {
            if idle & bit == 0 && self.is_idle(bit) {
                idle |= bit;
            }
        }
        self.idle.0 = idle;
    }

    /// Debug builds, after a status update: every mark is true, and the status parts it
    /// skipped are what the full update writes.
    #[cfg(debug_assertions)]
    pub(super) fn check_idle(&self) {
        for bit in (0..Idle::COUNT).map(|i| 1 << i) {
            assert!(
                !self.idle(bit) || self.is_idle(bit),
                "block {bit:#x} marked idle is in use: {self:?}"
            );
        }
        let s = &self.status;
        if self.idle(Idle::CORRECTIONS) {
            assert_eq!(s.position_correction, self.correction_status());
        }
        if self.idle(Idle::PHASING) {
            let (active, absolute, covered) = self.phasing_status();
            assert_eq!(
                (
                    s.phasing_active,
                    s.absolute_phase_shift,
                    s.covered_phase_shift
                ),
                (active, absolute, covered)
            );
        }
        if self.idle(Idle::SUPERPOSITION) {
            assert!(!s.compensating && s.superimposed_distance == 0.0);
        }
        if self.idle(Idle::EXT) {
            assert!(!s.ext_setpoint_gen_enabled);
        }
        if self.idle(Idle::CONFIG) {
            let p = &self.config.parameters;
            assert_eq!(s.op_modes, self.op_modes());
            assert_eq!(
                s.encoder_scaling_factor.to_bits(),
                p.axis_encoder_scaling_factor.to_bits()
            );
        }
    }
}
