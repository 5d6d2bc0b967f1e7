//! The axis's encoder (spec §4.5.9, §4.5.13/14): its scaling factor and what it changes. The
//! drive reports positions in the units of the scaling the axis was built with (#1040 then,
//! [`EncoderScaling`]'s `base`); the axis reads them as `enc_k · drive + offset` with `enc_k` =
//! the encoder scaling now / `base`, and sends its setpoints through the inverse, so that the one
//! control loop of a drive that is its own encoder stays closed. MC_SetEncoderScalingFactor
//! changes `enc_k`: in absolute mode the coordinates jump with it (at rest only, the set
//! position taken along, as MC_SetPosition does); in relative mode the offset is moved so
//! that nothing jumps.

use super::*;

/// MC_SetEncoderScalingFactor's state besides `Axis::enc_k` (which every reading and setpoint
/// goes through, so it stays with the axis's core).
#[derive(Debug)]
pub(super) struct EncoderScaling {
    /// The encoder scaling (#1040) the axis was built with: the drive's positions are in it.
    base: f64,
    /// 1 / (enc_k · base): increments per unit of the reading.
    count_scale: f64,
    /// The part of `Axis::offset` that relative encoder scaling changes put there (an
    /// absolute change counts from zero again and drops it).
    offset: f64,
}

impl EncoderScaling {
    pub(super) fn new(base: f64) -> Self {
        EncoderScaling {
            base,
            count_scale: 1.0 / base,
            offset: 0.0,
        }
    }
}

impl Axis {
    /// MC_SetEncoderScalingFactor (and an online write of #1040/#1055/#1056, absolute):
    /// `write` is the parameter write that records the new factor.
    pub(super) fn set_encoder_scaling(
        &mut self,
        factor: f64,
        relative: bool,
        write: (u16, f64),
    ) -> Result<(), ErrorId> {
        if !(factor.is_finite() && (1e-12..=1e12).contains(&factor)) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let k_new = factor / self.encoder.base;
        let k_old = self.enc_k;
        let at_rest = self.job.is_none()
            && self.coupling.is_none()
            && self.set.velocity.abs() <= EPS_V
            && matches!(
                self.state(),
                AxisState::Disabled | AxisState::Standstill | AxisState::ErrorStop
            );
        if !relative && !at_rest {
            // §4.5.9: absolute mode makes the position jump — only at standstill.
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        if relative && !at_rest {
            // In motion the drive's velocity steps by v·(1/k_new − 1/k_old) (the axis's
            // velocity in its units is kept): allowed only within one cycle's acceleration.
            let step = self.set.velocity.abs() * (1.0 / k_new - 1.0 / k_old).abs();
            let bound = self.p().axis_acc * self.cycle_time / k_new;
            if step > bound {
                return Err(ErrorId::ENCODER_SCALING_STEP_TOO_LARGE);
            }
        }
        self.config.parameters.write(write.0, write.1)?;
        // The drive position the actual one was read from.
        let drive = (self.act_pos - self.offset - self.corrections.read) / k_old;
        self.enc_k = k_new;
        self.encoder.count_scale = 1.0 / (k_new * self.encoder.base);
        if relative {
            // No jump: the offset takes up what the new factor would change.
            let d = (k_old - k_new) * drive;
            self.offset += d;
            self.encoder.offset += d;
        } else {
            // Counting from the coordinate system's zero: what relative changes added to the
            // offset goes, the reading jumps to count × factor, and the coordinates (set,
            // targets, plan) move with it as with MC_SetPosition.
            let offset = self.offset - self.encoder.offset;
            let shift = (k_new - k_old) * drive - self.encoder.offset;
            self.shift_coordinates(shift);
            self.offset = offset;
            self.encoder.offset = 0.0;
        }
        Ok(())
    }

    /// Whether writing `number` (#1040 AxisEncoderScalingFactor, #1055 numerator, #1056
    /// denominator) changes the encoder scaling, and the factor it gives.
    pub(super) fn encoder_scaling_written(&self, number: u16, value: f64) -> Option<f64> {
        let p = self.p();
        let f = match number {
            1040 => value,
            1055 => value / p.axis_encoder_scaling_denominator,
            1056 => p.axis_encoder_scaling_numerator / value,
            _ => return None,
        };
        (f != p.axis_encoder_scaling_factor).then_some(f)
    }

    /// The raw encoder count (masked by #1043) of the drive position now: drive position /
    /// the scaling the axis was built with.
    pub(super) fn encoder_count(&self) -> u32 {
        // Increments = drive position / build-time factor = (reading − offsets) / (k · base):
        // one multiplication by the reciprocal kept with k (this runs every cycle). The low 32
        // bits of the count (two's complement wraps as the counter does; a cast, not a
        // floating-point remainder).
        let x = (self.act_pos - self.offset - self.corrections.read) * self.encoder.count_scale;
        let incs = (x + 0.5f64.copysign(x)) as i64; // rounded half away from zero
        (incs as u32) & self.p().axis_encoder_mask
    }
}
