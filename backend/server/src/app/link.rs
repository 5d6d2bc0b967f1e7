//! The async side's link to the cycle thread: a request with a ticket, answered by the
//! cycle thread's verdict (which the pump hands over), for commands, axes, faults and scope
//! configurations.

use std::collections::BTreeMap;
use std::time::Duration;

use motion::{Axis, AxisConfig, AxisParameters, AxisSlot, Command, CommandKind, Target};
use tokio::sync::oneshot;

use super::AppState;
use crate::cycle::{Reply, Request};
use crate::error::FieldError;
use crate::error::{AppError, AppResult};
use crate::model::AxisConfigDto;
use crate::params::{self, ParamValue};
use crate::scope::{NewRecording, ScopeBusy, ScopeRecording};
use drives::Drive;

/// How long the async side waits for the cycle thread's verdict.
const VERDICT_TIMEOUT: Duration = Duration::from_secs(2);
/// How long a request may wait in the queue before the cycle thread drops it undone: shorter
/// than `VERDICT_TIMEOUT` by far more than the pump's period, so that a verdict the cycle thread
/// gives always reaches its waiting requester.
const REQUEST_TTL: Duration = Duration::from_millis(1500);
/// What a drive-executed axis needs in its drive's process image: mode, mode display, the
/// position and velocity targets and the profile's dynamics.
const PROFILE_OBJECTS: [u16; 7] = [0x6060, 0x6061, 0x607A, 0x60FF, 0x6081, 0x6083, 0x6084];

impl AppState {
    pub(crate) async fn request(&self, ticket: u64, req: Request) -> AppResult<Reply> {
        let (tx, rx) = oneshot::channel();
        self.pending.lock().unwrap().insert(ticket, tx);
        // Expires well before we stop waiting: a request we answer 503 for never acts later.
        if self.shared.push_expiring(req, REQUEST_TTL).is_err() {
            self.pending.lock().unwrap().remove(&ticket);
            return Err(AppError::unavailable(
                "command_queue_full",
                "the command queue to the cycle thread is full; try again",
            ));
        }
        match tokio::time::timeout(VERDICT_TIMEOUT, rx).await {
            Ok(Ok(r)) => Ok(r),
            _ => {
                self.pending.lock().unwrap().remove(&ticket);
                Err(AppError::unavailable(
                    "cycle_unavailable",
                    "the cycle thread did not answer",
                ))
            }
        }
    }

    /// Creates a scope recording: allocates its channels, hands the new sampling configuration
    /// to the cycle thread and waits until it is in effect (the recording's first cycle).
    pub async fn create_recording(&self, r: NewRecording) -> AppResult<ScopeRecording> {
        let ticket = self.next_id();
        let (tx, rx) = oneshot::channel();
        let id = {
            let mut scope = self.scope.lock().unwrap();
            let (id, config) = scope.create(r).map_err(|e| match e {
                ScopeBusy::Channels { in_use, needed } => AppError::conflict(
                    "scope_channels_busy",
                    format!(
                        "the scope samples at most {} signals at once: {in_use} are in use by \
                         active recordings and this one needs {needed} more; cancel one or \
                         wait until it is done",
                        crate::scope::SCOPE_CHANNELS
                    ),
                ),
                ScopeBusy::Recordings => AppError::conflict(
                    "scope_busy",
                    format!(
                        "too many active recordings (at most {} recordings and {} values are \
                         kept); cancel one or wait until it is done",
                        crate::scope::MAX_RECORDINGS,
                        crate::scope::MAX_VALUES
                    ),
                ),
            })?;
            // Pushed under the scope lock so that configurations reach the cycle thread in the
            // order of their generations.
            self.pending.lock().unwrap().insert(ticket, tx);
            if self
                .shared
                .push(Request::ScopeConfig { ticket, config })
                .is_err()
            {
                self.pending.lock().unwrap().remove(&ticket);
                scope.abandon(id);
                return Err(AppError::unavailable(
                    "command_queue_full",
                    "the command queue to the cycle thread is full; try again",
                ));
            }
            id
        };
        match tokio::time::timeout(VERDICT_TIMEOUT, rx).await {
            Ok(Ok(reply)) => {
                let mut scope = self.scope.lock().unwrap();
                scope.started(id, reply.cycle);
                scope.get(id, false).ok_or_else(|| {
                    AppError::unavailable("scope_unavailable", "the recording was evicted")
                })
            }
            _ => {
                self.pending.lock().unwrap().remove(&ticket);
                self.scope.lock().unwrap().abandon(id);
                Err(AppError::unavailable(
                    "cycle_unavailable",
                    "the cycle thread did not answer",
                ))
            }
        }
    }

    /// Sends a kernel command and waits for its verdict (not tracked as a command resource).
    pub async fn kernel_command(&self, target: Target, kind: CommandKind) -> AppResult<u64> {
        let r = self.command_request(self.next_id(), target, kind).await?;
        r.result.map(|_| r.cycle).map_err(AppError::Rejected)
    }

    /// Sends kernel command `id` and waits for the cycle thread's reply, whatever its verdict.
    pub(crate) async fn command_request(
        &self,
        id: u64,
        target: Target,
        kind: CommandKind,
    ) -> AppResult<Reply> {
        let command = Command { id, target, kind };
        self.request(id, Request::Command(command)).await
    }

    /// Sends MC_MovePath `id` with its table (built and checked off the cycle thread) and
    /// waits for the cycle thread's reply, whatever its verdict.
    pub(crate) async fn path_request(
        &self,
        id: u64,
        group: motion::group::GroupId,
        table: Box<motion::group::PathTable>,
        prepared: Option<Box<motion::group::PreparedPath>>,
    ) -> AppResult<Reply> {
        self.request(
            id,
            Request::MovePath {
                command: id,
                group,
                table,
                prepared,
            },
        )
        .await
    }

    /// Hands a ready group to the cycle thread; 409 `group_state_invalid` while the group in
    /// that slot is enabled or in error.
    pub async fn install_group(
        &self,
        id: motion::group::GroupId,
        group: Box<motion::group::Group>,
    ) -> AppResult<()> {
        self.ticketed(|ticket| Request::InsertGroup { ticket, id, group })
            .await
            .map(drop)
    }

    /// Takes a group out of the cycle thread (with `require_disabled`: 409
    /// `group_state_invalid` while it is enabled or in error).
    pub async fn uninstall_group(
        &self,
        id: motion::group::GroupId,
        require_disabled: bool,
    ) -> AppResult<()> {
        self.ticketed(|ticket| Request::RemoveGroup {
            ticket,
            id,
            require_disabled,
        })
        .await?;
        self.scope.lock().unwrap().group_removed(id as AxisSlot);
        Ok(())
    }

    /// Hands a ready axis to the cycle thread.
    pub async fn install_axis(
        &self,
        slot: AxisSlot,
        axis: Box<Axis>,
        drive: Drive,
        require_disabled: bool,
    ) -> AppResult<()> {
        self.ticketed(|ticket| Request::InsertAxis {
            ticket,
            slot,
            axis,
            drive,
            require_disabled,
        })
        .await
        .map(drop)
    }

    /// Hands a built cam to the cycle thread under its table id; 409 `cam_table_in_use` while
    /// an axis is coupled through that table.
    pub async fn install_cam(
        &self,
        id: u32,
        cam: std::sync::Arc<motion::cam::Cam>,
    ) -> AppResult<()> {
        self.ticketed(|ticket| Request::InsertCam { ticket, id, cam })
            .await
            .map(drop)
            .map_err(in_use)
    }

    /// New data for table `id`: in place at once when nothing is coupled through it, else an
    /// online change that reaches the slaves as `change` says.
    pub async fn change_cam(
        &self,
        id: u32,
        cam: std::sync::Arc<motion::cam::Cam>,
        change: motion::cam::OnlineChange,
    ) -> AppResult<()> {
        self.ticketed(|ticket| Request::ChangeCam {
            ticket,
            id,
            cam,
            change,
        })
        .await
        .map(drop)
        .map_err(change_pending)
    }

    /// 409 `cam_change_pending` while data written earlier has not reached all slaves.
    pub async fn probe_cam_change(&self, id: u32) -> AppResult<()> {
        self.ticketed(|ticket| Request::ProbeCamChange { ticket, id })
            .await
            .map(drop)
            .map_err(change_pending)
    }

    /// DELETEQUEUEDDATA for table `id`.
    pub async fn drop_cam_data(&self, id: u32) -> AppResult<()> {
        self.ticketed(|ticket| Request::DropCamData { ticket, id })
            .await
            .map(drop)
    }

    /// Takes a cam out of the cycle thread; 409 `cam_table_in_use` while it is coupled.
    pub async fn uninstall_cam(&self, id: u32) -> AppResult<()> {
        self.ticketed(|ticket| Request::RemoveCam { ticket, id })
            .await
            .map(drop)
            .map_err(in_use)
    }

    /// Takes an axis out of the cycle thread.
    pub async fn uninstall_axis(&self, slot: AxisSlot, require_disabled: bool) -> AppResult<()> {
        self.ticketed(|ticket| Request::RemoveAxis {
            ticket,
            slot,
            require_disabled,
        })
        .await?;
        // The pump hands the smaller sampling configuration over.
        self.scope.lock().unwrap().axis_removed(slot);
        Ok(())
    }

    /// Releases a command (the falling edge of Execute/Enable) and audits it.
    /// Hands a fault or disturbance to the simulated drive of a slot.
    pub async fn inject_fault(
        &self,
        slot: AxisSlot,
        fault: crate::sim::SimFault,
    ) -> AppResult<u64> {
        self.ticketed(|ticket| Request::InjectFault {
            ticket,
            slot,
            fault,
        })
        .await
    }

    /// Restarts the following-error peak hold of a slot; the cycle it counts from.
    pub async fn reset_following_error_peak(&self, slot: AxisSlot) -> AppResult<u64> {
        self.ticketed(|ticket| Request::ResetFollowingErrorPeak { ticket, slot })
            .await
    }

    /// A request that only needs its verdict and the cycle it takes effect in.
    async fn ticketed(&self, make: impl FnOnce(u64) -> Request) -> AppResult<u64> {
        let ticket = self.next_id();
        let r = self.request(ticket, make(ticket)).await?;
        r.result.map(|_| r.cycle).map_err(AppError::Rejected)
    }

    /// Builds the kernel's axis and drive for a configuration plus its persistent overlay.
    /// A CiA-402 drive needs an EtherCAT bus with a CiA-402 drive at its position that no other
    /// axis drives.
    pub fn check_drive_on_bus(
        &self,
        id: i64,
        drive: &drives::DriveConfig,
    ) -> Result<(), Vec<FieldError>> {
        let drives::DriveConfig::Cia402(c) = drive else {
            return Ok(());
        };
        let err = |field: &str, message: String| {
            Err(vec![FieldError {
                field: field.into(),
                message,
            }])
        };
        let bus = &self.info.bus;
        if bus.ethercat.is_none() {
            return err(
                "drive.kind",
                "a cia402 drive needs an EtherCAT bus: motiond runs the simulated bus \
                 (start it with --bus ethercat --interface IFACE, or --bus emulated)"
                    .into(),
            );
        }
        let drives = bus.drive_positions();
        if !drives.contains(&c.subdevice) {
            return err(
                "drive.subdevice",
                format!(
                    "no CiA-402 drive at position {} of the segment (drives at {:?})",
                    c.subdevice, drives
                ),
            );
        }
        // The profile modes' mode, targets and dynamics travel in the process data (decision
        // 166): a drive that could not map them runs host-side profiles only.
        if c.profile == drives::cia402::ProfileSide::Drive {
            let missing = bus.unmapped(c.subdevice, &PROFILE_OBJECTS);
            if !missing.is_empty() {
                let list: Vec<String> = missing.iter().map(|i| format!("0x{i:04X}")).collect();
                return err(
                    "drive.profile",
                    format!(
                        "the drive at position {} cannot run the profile: its process image lacks {} \
                         (it refused to map them); use profile host",
                        c.subdevice,
                        list.join(", ")
                    ),
                );
            }
        }
        let taken =
            self.registry
                .read()
                .unwrap()
                .axes
                .values()
                .find_map(|a| match &a.config.drive {
                    drives::DriveConfig::Cia402(o) if o.subdevice == c.subdevice && a.id != id => {
                        Some(a.name.clone())
                    }
                    _ => None,
                });
        if let Some(other) = taken {
            return err(
                "drive.subdevice",
                format!("the drive at position {} is axis {other}'s", c.subdevice),
            );
        }
        Ok(())
    }

    pub fn build_axis(
        &self,
        id: i64,
        config: &AxisConfigDto,
        persistent: &BTreeMap<u16, ParamValue>,
    ) -> Result<(AxisParameters, Box<Axis>, Drive), Vec<FieldError>> {
        let ct = self.info.cycle_time_s;
        let mut p = config.to_parameters(id, ct)?;
        self.check_drive_on_bus(id, &config.drive)?;
        for (n, v) in persistent {
            if let Err(e) = params::set(&mut p, *n, *v) {
                tracing::warn!(
                    "axis {}: persistent parameter {n} not applied: {}",
                    config.name,
                    e.text()
                );
            }
        }
        let axis = Axis::new(
            AxisConfig {
                modulo: config.modulo.is_some(),
                parameters: p.clone(),
                compensation_table: config.position_compensation_table.clone(),
                drive_executed: matches!(
                    &config.drive,
                    drives::DriveConfig::Cia402(c) if c.profile == drives::cia402::ProfileSide::Drive
                ),
            },
            ct,
        );
        let drive = config.drive.build(ct);
        Ok((p, axis, drive))
    }
}

fn in_use(e: AppError) -> AppError {
    match e {
        AppError::Rejected(id) if id == motion::ErrorId::CAM_TABLE_IN_USE => AppError::conflict(
            "cam_table_in_use",
            "the cam table is coupled (or a coupling through it waits): decouple its slaves (cam-out) first",
        ),
        e => e,
    }
}

fn change_pending(e: AppError) -> AppError {
    match e {
        AppError::Rejected(id) if id == motion::ErrorId::CAM_TABLE_IN_USE => AppError::conflict(
            "cam_change_pending",
            "data written to this cam table earlier has not reached all its slaves yet (see cam_data_queued \
             in their status); write again once it has, or drop it with the online-change mode delete_queued_data",
        ),
        e => e,
    }
}
