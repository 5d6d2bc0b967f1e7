//! Read-type blocks of one axis that answer from its latest status and configuration without
//! a kernel command: MC_ConvertIncPosToPos, MC_ConvertPosToIncPos, MC_ReadAxisComponents.
//! Shared by their REST endpoints and websocket methods.

use motion::ErrorId;

use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::*;

/// The latest status of an axis with its encoder mask (#1043).
fn status_and_mask(s: &AppState, axis: &str) -> AppResult<(u64, motion::AxisStatus, u32)> {
    let (slot, mask) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (e.slot, e.params.axis_encoder_mask)
    };
    let (cycle, status) = s.status(slot);
    Ok((cycle, status.unwrap_or_default(), mask))
}

/// MC_ConvertIncPosToPos (§4.5.13).
pub fn convert_inc_pos_to_pos(
    s: &AppState,
    axis: &str,
    q: &IncPosQuery,
) -> AppResult<PositionConversion> {
    let (cycle, st, mask) = status_and_mask(s, axis)?;
    let position = motion::functions::convert_inc_pos_to_pos(&st, q.inc_pos, mask);
    Ok(PositionConversion {
        position,
        inc_pos: q.inc_pos & mask,
        cycle,
        encoder_count: st.encoder_count,
        actual_position: st.actual_position,
        encoder_scaling_factor: st.encoder_scaling_factor,
    })
}

/// MC_ConvertPosToIncPos (§4.5.14): 422 at `position` when it is too far from the actual one.
pub fn convert_pos_to_inc_pos(
    s: &AppState,
    axis: &str,
    q: &PositionQuery,
) -> AppResult<PositionConversion> {
    let (cycle, st, mask) = status_and_mask(s, axis)?;
    if !(q.position.is_finite() && q.position.abs() <= MAX_MAGNITUDE) {
        return Err(AppError::refused(
            "position",
            ErrorId::PARAMETER_NOT_CORRECT,
            "must be a number from -1e12 to 1e12",
        ));
    }
    let inc_pos =
        motion::functions::convert_pos_to_inc_pos(&st, q.position, mask).map_err(|id| {
            AppError::refused(
                "position",
                id,
                format!(
                    "{} (actual position {}, encoder count {}, counter mask {mask:#x})",
                    id.text(),
                    st.actual_position,
                    st.encoder_count
                ),
            )
        })?;
    Ok(PositionConversion {
        position: q.position,
        inc_pos,
        cycle,
        encoder_count: st.encoder_count,
        actual_position: st.actual_position,
        encoder_scaling_factor: st.encoder_scaling_factor,
    })
}

/// MC_ReadAxisComponents (§4.2.3): the encoder, controller and drive of the axis. motiond
/// gives an axis one of each, all numbered with the axis id (ST_AxisComponents' ID arrays then
/// hold one entry each).
pub fn read_axis_components(s: &AppState, axis: &str) -> AppResult<AxisComponents> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(axis)
        .ok_or_else(|| AppError::not_found("axis", axis))?;
    let id = e.id;
    let (drive, controller) = match &e.config.drive {
        drives::DriveConfig::Simulated(_) => (
            DriveComponent {
                id,
                kind: "simulated".into(),
                subdevice: None,
                operation_mode: "csp".into(),
            },
            ControllerComponent {
                id,
                kind: "in_drive".into(),
            },
        ),
        drives::DriveConfig::Cia402(c) => (
            DriveComponent {
                id,
                kind: "cia402".into(),
                subdevice: Some(c.subdevice),
                operation_mode: format!("{:?}", c.mode).to_lowercase(),
            },
            ControllerComponent {
                id,
                // CSP closes the position loop in the drive; for CSV and CST motiond closes it.
                kind: if matches!(c.mode, drives::cia402::Cia402Mode::Csp) {
                    "in_drive".into()
                } else {
                    "motiond".into()
                },
            },
        ),
    };
    Ok(AxisComponents {
        encoder_ids: vec![id],
        controller_ids: vec![id],
        drive_ids: vec![id],
        encoder: EncoderComponent {
            id,
            kind: "drive_feedback".into(),
            scaling_factor: e.params.axis_encoder_scaling_factor,
            mask: e.params.axis_encoder_mask,
        },
        controller,
        drive,
        active_control_loop: 0,
    })
}

/// MC_ReadDriveOperationMode (§4.5.1): what the drive reports in the latest cycle.
pub fn read_drive_operation_mode(
    s: &AppState,
    axis: &str,
) -> AppResult<DriveOperationModeResource> {
    let (cycle, st, _) = status_and_mask(s, axis)?;
    Ok(DriveOperationModeResource {
        drive_operation_mode: st.drive_operation_mode,
        code: st.drive_operation_mode.code(),
        cycle,
    })
}
