//! The drive bus: what it is and how it is doing (`GET /bus`), SDO access to the EtherCAT
//! SubDevices for diagnostics (never through the cycle: CoE mailbox traffic from the async
//! side), and frame loss injected into the emulated segment.

use crate::service::sdo::sdo_failed;
use std::sync::Arc;
use std::sync::atomic::Ordering::Relaxed;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{Client, JsonBody};
use crate::app::AppState;
use crate::bus::BusKind;
use crate::error::{AppError, AppResult};
use crate::service::audit_entry;

/// An EtherCAT state machine state (AL status).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum AlState {
    Init,
    PreOp,
    Boot,
    SafeOp,
    Op,
    Unknown,
}

impl AlState {
    fn of(code: u8) -> AlState {
        match code & 0x0F {
            1 => AlState::Init,
            2 => AlState::PreOp,
            3 => AlState::Boot,
            4 => AlState::SafeOp,
            8 => AlState::Op,
            _ => AlState::Unknown,
        }
    }
}

/// A CiA-402 drive's process data as motiond mapped it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"mapping": "available", "output_bytes": 13, "input_bytes": 17,
    "missing_objects": ["0x60b8", "0x60b9", "0x60ba", "0x60bb", "0x60fd"], "refused": []}))]
pub struct DriveMapping {
    /// `full` (targets for CSP/CSV/CST, touch probe, digital inputs), `available` (what the
    /// drive has of the full one: its dictionary lacks `missing_objects`) or `minimal` (what
    /// a drive refusing the others takes: controlword, target, mode; statusword, position,
    /// mode display, error code).
    pub mapping: &'static str,
    /// RxPDO (outputs) and TxPDO (inputs) bytes.
    pub output_bytes: usize,
    pub input_bytes: usize,
    /// Objects of the full mapping the drive does not have (its SDO upload aborted
    /// 0x06020000): the features that need them are refused on its axis (409).
    pub missing_objects: Vec<String>,
    /// The larger mappings the drive refused, in the order tried.
    pub refused: Vec<RefusedMapping>,
}

/// A mapping a drive refused at bring-up.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"mapping": "full", "at": "PRE-OP to SAFE-OP", "al_status_code": "0x001d",
    "reason": "0x001d: Invalid Output Configuration"}))]
pub struct RefusedMapping {
    pub mapping: &'static str,
    /// `PDO mapping write` (an SDO abort) or `PRE-OP to SAFE-OP` (the drive's AL status code).
    pub at: &'static str,
    /// `0xNNNN` (ETG.1000), when refused at SAFE-OP.
    pub al_status_code: Option<String>,
    /// The AL status code with its ETG.1000 meaning, or the SDO error.
    pub reason: String,
}

/// One SubDevice of the segment.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"position": 1, "configured_address": 4097, "name": "motiond emulated servo 2",
    "vendor_id": 16714446, "product_code": 67239937, "revision": 65536, "serial": 537264129,
    "al_state": "op", "drive": {"mapping": "full", "output_bytes": 27, "input_bytes": 29, "missing_objects": [], "refused": []},
    "dc": true, "axis": "y"}))]
pub struct SubDeviceResource {
    /// Position on the segment (0 = next to motiond); a CiA-402 drive's `subdevice`.
    pub position: u16,
    pub configured_address: u16,
    pub name: String,
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
    /// As read by the latest cycle.
    pub al_state: AlState,
    /// A CiA-402 drive (device type 0x1000 profile 402), or `null`.
    pub drive: Option<DriveMapping>,
    /// Supports distributed clocks (runs SYNC0).
    pub dc: bool,
    /// The axis whose drive this is.
    pub axis: Option<String>,
}

/// `GET /bus`.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "kind": "emulated", "interface": "emulated", "cycle_time": 0.001, "state": "op",
    "frames": 120345, "lost_frames": 0, "working_counter_errors": 0, "faults": 0, "errors_in_row": 0,
    "fault_reason": null, "late_replies": 0, "duplicate_replies": 0, "malformed_frames": 0,
    "pdu_timeout": 0.01, "txrx": {"running": true, "restarts": 0, "thread": "SCHED_FIFO 79, pinned to CPU 0"},
    "max_errors_in_row": 3, "expected_working_counter": 9, "last_working_counter": 9,
    "dc_system_time_ns": 123456789000u64, "dc_cycle_offset_ns": 12000,
    "subdevices": [{"position": 0, "configured_address": 4096, "name": "motiond emulated servo 1",
        "vendor_id": 16714446, "product_code": 67239937, "revision": 65536, "serial": 537264128,
        "al_state": "op", "drive": {"mapping": "full", "output_bytes": 27, "input_bytes": 29, "missing_objects": [], "refused": []},
        "dc": true, "axis": "x"}]
}))]
pub struct BusResource {
    pub kind: BusKind,
    /// The network interface (`emulated` for the emulated segment); `null` when simulated.
    pub interface: Option<String>,
    /// Seconds between exchanges (= the SYNC0 period).
    pub cycle_time: f64,
    /// `simulated`; `op` (every SubDevice in OP, frames flowing); `degraded` (a SubDevice is not
    /// in OP: its axes are stopped); `faulted` (lost frames or wrong working counters in a row,
    /// until as many good ones in a row: every enabled EtherCAT axis was stopped and stays in
    /// ErrorStop until MC_Reset).
    pub state: &'static str,
    /// Why the bus is `faulted`: the TX/RX loop's failure (the socket's error, or an injected
    /// stop), or lost frames / wrong working counters in a row. `null` otherwise.
    pub fault_reason: Option<String>,
    pub frames: u64,
    /// Cycles whose frame got no answer, retries included (`max_errors_in_row` in a row fault
    /// the bus).
    pub lost_frames: u64,
    /// Replies that came after their frame was answered or given up, a PDU timeout or more
    /// after it was sent: counted and dropped.
    pub late_replies: u64,
    /// Replies that came twice (the same PDU index, sooner than the timeout): counted and
    /// dropped.
    pub duplicate_replies: u64,
    /// EtherCAT frames received that did not parse: counted and dropped.
    pub malformed_frames: u64,
    /// How long a frame may take to come back before it is sent again (seconds).
    pub pdu_timeout: f64,
    /// motiond's TX/RX loop; `null` when simulated.
    pub txrx: Option<TxRxResource>,
    pub working_counter_errors: u64,
    /// Times the bus faulted (`max_errors_in_row` bad frames in a row) since start.
    pub faults: u64,
    pub errors_in_row: u64,
    pub max_errors_in_row: u32,
    pub expected_working_counter: u16,
    pub last_working_counter: u16,
    /// The DC reference clock's system time at the latest exchange (ns since 2000-01-01).
    pub dc_system_time_ns: Option<u64>,
    /// Where in its SYNC0 period the latest frame reached the reference clock (ns).
    pub dc_cycle_offset_ns: Option<u64>,
    pub subdevices: Vec<SubDeviceResource>,
    /// What the engineer should know about the bus and the axes: CiA-402 drives that no axis
    /// uses (an existing database keeps its simulated axes on `--bus emulated`/`ethercat`)
    /// and how to put an axis on one. Absent when there is nothing to say.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub notice: Option<String>,
}

/// motiond's TX/RX loop (its own thread: frames out, replies in).
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"running": true, "restarts": 0, "thread": "SCHED_FIFO 79, pinned to CPU 0"}))]
pub struct TxRxResource {
    /// `false` after the loop stopped (socket error or injected): the bus is `faulted` until
    /// `POST /bus/reset` or an axis's MC_Reset starts it again.
    pub running: bool,
    /// Times it was started again.
    pub restarts: u64,
    /// What the thread got: SCHED_FIFO priority and CPU, or why not.
    pub thread: String,
}

/// Drives on the bus that no axis uses, and how to put an axis on one (`None`: none, or
/// the simulated bus). Logged at start-up and shown in `GET /bus`.
pub fn idle_drives_notice(s: &AppState) -> Option<String> {
    let (st, _) = s.info.bus.ethercat.as_ref()?;
    let (used, simulated): (Vec<u16>, Vec<String>) = {
        let reg = s.registry.read().unwrap();
        let used = reg
            .axes
            .values()
            .filter_map(|a| match &a.config.drive {
                drives::DriveConfig::Cia402(c) => Some(c.subdevice),
                _ => None,
            })
            .collect();
        let simulated = reg
            .axes
            .values()
            .filter(|a| !matches!(a.config.drive, drives::DriveConfig::Cia402(_)))
            .map(|a| a.name.clone())
            .collect();
        (used, simulated)
    };
    let idle: Vec<String> = st
        .subdevices
        .iter()
        .filter(|d| d.drive.is_some() && !used.contains(&d.position))
        .map(|d| d.position.to_string())
        .collect();
    if idle.is_empty() {
        return None;
    }
    let axes = if simulated.is_empty() {
        "no axis".to_owned()
    } else {
        format!(
            "the axes {} are simulated (made on the simulated bus)",
            simulated.join(", ")
        )
    };
    Some(format!(
        "the CiA-402 drive(s) at SubDevice position {} drive no axis: {axes}. Put an axis on a \
         drive with PUT /api/v1/axes/{{axis}} and \"drive\": {{\"kind\": \"cia402\", \"subdevice\": N, \
         \"increments_per_unit\": …}} (the UI's Configuration page, Drive), or start on a new \
         database, where the demo axes are put on the drives",
        idle.join(", ")
    ))
}

pub fn bus_resource(s: &AppState) -> BusResource {
    let h = &s.info.bus;
    let Some((st, _)) = &h.ethercat else {
        return BusResource {
            kind: h.kind,
            interface: None,
            cycle_time: s.info.cycle_time_s,
            state: "simulated",
            fault_reason: None,
            frames: 0,
            lost_frames: 0,
            late_replies: 0,
            duplicate_replies: 0,
            malformed_frames: 0,
            pdu_timeout: 0.0,
            txrx: None,
            working_counter_errors: 0,
            faults: 0,
            errors_in_row: 0,
            max_errors_in_row: 0,
            expected_working_counter: 0,
            last_working_counter: 0,
            dc_system_time_ns: None,
            dc_cycle_offset_ns: None,
            subdevices: Vec::new(),
            notice: None,
        };
    };
    let axes: Vec<(u16, String)> = s
        .registry
        .read()
        .unwrap()
        .axes
        .values()
        .filter_map(|a| match &a.config.drive {
            drives::DriveConfig::Cia402(c) => Some((c.subdevice, a.name.clone())),
            _ => None,
        })
        .collect();
    let subdevices: Vec<SubDeviceResource> = st
        .subdevices
        .iter()
        .zip(&st.al_states)
        .map(|(d, al)| SubDeviceResource {
            position: d.position,
            configured_address: d.configured_address,
            name: d.name.clone(),
            vendor_id: d.vendor_id,
            product_code: d.product_code,
            revision: d.revision,
            serial: d.serial,
            al_state: AlState::of(al.load(Relaxed)),
            drive: d.drive.map(|l| DriveMapping {
                mapping: l.name,
                output_bytes: l.out_len,
                input_bytes: l.in_len,
                missing_objects: d
                    .missing_objects
                    .iter()
                    .map(|i| format!("{i:#06x}"))
                    .collect(),
                refused: d
                    .refused
                    .iter()
                    .map(|r| RefusedMapping {
                        mapping: r.mapping,
                        at: r.at,
                        al_status_code: r.al_status_code.map(|c| format!("{c:#06x}")),
                        reason: r.reason.clone(),
                    })
                    .collect(),
            }),
            dc: d.dc,
            axis: axes
                .iter()
                .find(|(p, _)| *p == d.position)
                .map(|(_, n)| n.clone()),
        })
        .collect();
    let link = &st.link;
    let fault_reason = link.fault().or_else(|| {
        st.faulted.load(Relaxed).then(|| {
            format!(
                "{} frames lost or with a wrong working counter in a row",
                st.max_errors_in_row
            )
        })
    });
    let state = if st.faulted.load(Relaxed) || !link.alive() {
        "faulted"
    } else if subdevices.iter().any(|d| d.al_state != AlState::Op) {
        "degraded"
    } else {
        "op"
    };
    BusResource {
        kind: h.kind,
        interface: Some(st.interface.clone()),
        cycle_time: st.cycle_ns as f64 * 1e-9,
        state,
        fault_reason,
        frames: st.frames.load(Relaxed),
        lost_frames: st.lost_frames.load(Relaxed),
        late_replies: link.late.load(Relaxed),
        duplicate_replies: link.duplicate.load(Relaxed),
        malformed_frames: link.malformed.load(Relaxed),
        pdu_timeout: st.pdu_timeout.as_secs_f64(),
        txrx: Some(TxRxResource {
            running: link.alive(),
            restarts: link.restarts.load(Relaxed),
            thread: link.realtime(),
        }),
        working_counter_errors: st.working_counter_errors.load(Relaxed),
        faults: st.faults.load(Relaxed),
        errors_in_row: st.errors_in_row.load(Relaxed),
        max_errors_in_row: st.max_errors_in_row,
        expected_working_counter: st.expected_working_counter,
        last_working_counter: st.last_working_counter.load(Relaxed),
        dc_system_time_ns: Some(st.dc_system_time.load(Relaxed)),
        dc_cycle_offset_ns: Some(st.dc_cycle_offset.load(Relaxed)),
        subdevices,
        notice: idle_drives_notice(s),
    }
}

#[utoipa::path(get, path = "/api/v1/bus", tag = "bus",
    summary = "The drive bus: kind, state, frame and working-counter figures, DC, the SubDevices with identity and AL state",
    responses((status = 200, description = "The bus", body = BusResource)))]
pub async fn bus(State(s): State<Arc<AppState>>) -> Json<BusResource> {
    Json(bus_resource(&s))
}

/// An object's value as read by SDO upload.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"position": 0, "index": "0x1018", "sub": 1, "bytes": [206, 10, 255, 0],
    "hex": "ce0aff00", "unsigned": 16714446, "signed": 16714446, "text": null}))]
pub struct SdoValue {
    pub position: u16,
    /// `0xIIII`.
    pub index: String,
    pub sub: u8,
    /// As the SubDevice sent them (little endian).
    pub bytes: Vec<u8>,
    pub hex: String,
    /// The bytes as an unsigned and a signed little-endian integer (1 to 8 bytes).
    pub unsigned: Option<u64>,
    pub signed: Option<i64>,
    /// The bytes as text, when they are printable ASCII (names, versions).
    pub text: Option<String>,
}

/// `PUT …/sdo/{index}/{sub}`: an integer written with the object's size.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"value": 8, "size": 1}))]
pub struct SdoWrite {
    /// Written little endian in `size` bytes (negative values in two's complement).
    #[schema(minimum = -2147483648_i64, maximum = 4294967295_i64)]
    pub value: i64,
    /// 1, 2 or 4 bytes (SDO download expedited).
    #[schema(minimum = 1, maximum = 4)]
    pub size: u8,
}

fn index_of(s: &str) -> AppResult<u16> {
    s.strip_prefix("0x")
        .or_else(|| s.strip_prefix("0X"))
        .filter(|h| (1..=4).contains(&h.len()))
        .and_then(|h| u16::from_str_radix(h, 16).ok())
        .ok_or_else(|| AppError::field("index", "an object index in hex: 0x0000–0xFFFF"))
}

/// The path's SubDevice position and subindex: beyond their range there is no such one (404).
fn sdo_path(position: &str, index: &str, sub: &str) -> AppResult<(u16, u16, u8)> {
    let position = position
        .parse::<u16>()
        .map_err(|_| AppError::not_found("subdevice", position))?;
    let index = index_of(index)?;
    let sub = sub
        .parse::<u8>()
        .map_err(|_| AppError::not_found("subindex", sub))?;
    Ok((position, index, sub))
}

fn sdo_access(s: &AppState) -> AppResult<ethercat::bus::SdoAccess> {
    s.info
        .bus
        .ethercat
        .as_ref()
        .map(|(_, a)| *a)
        .ok_or_else(|| {
            AppError::conflict(
                "bus_not_ethercat",
                "motiond runs the simulated bus: SDOs need --bus ethercat or --bus emulated",
            )
        })
}

fn value_of(position: u16, index: u16, sub: u8, bytes: Vec<u8>) -> SdoValue {
    let (unsigned, signed) = if (1..=8).contains(&bytes.len()) {
        let mut b = [0u8; 8];
        b[..bytes.len()].copy_from_slice(&bytes);
        let u = u64::from_le_bytes(b);
        let bits = 8 * bytes.len() as u32;
        let s = if bits == 64 {
            u as i64
        } else {
            ((u << (64 - bits)) as i64) >> (64 - bits)
        };
        (Some(u), Some(s))
    } else {
        (None, None)
    };
    let text = (!bytes.is_empty() && bytes.iter().all(|b| b.is_ascii_graphic() || *b == b' '))
        .then(|| String::from_utf8_lossy(&bytes).into_owned());
    SdoValue {
        position,
        index: format!("{index:#06x}"),
        sub,
        hex: bytes.iter().map(|b| format!("{b:02x}")).collect(),
        bytes,
        unsigned,
        signed,
        text,
    }
}

#[utoipa::path(get, path = "/api/v1/bus/subdevices/{position}/sdo/{index}/{sub}", tag = "bus",
    summary = "Read an object of a SubDevice by SDO upload (CoE), for diagnostics",
    description = "From the async side through the mailbox; the cycle is not touched. 409 `sdo_aborted` carries the \
CiA-301 abort code the SubDevice answered; 409 `bus_not_ethercat` on the simulated bus.",
    params(("position" = u16, Path, description = "SubDevice position on the segment", example = 0),
        ("index" = String, Path, description = "object index in hex, `0x1018`", example = "0x1018", pattern = "^0[xX][0-9a-fA-F]{1,4}$"),
        ("sub" = u8, Path, description = "subindex", example = 1)),
    responses((status = 200, description = "The value", body = SdoValue), super::errors::SdoErrors))]
pub async fn sdo_read(
    State(s): State<Arc<AppState>>,
    Path((position, index, sub)): Path<(String, String, String)>,
) -> AppResult<Json<SdoValue>> {
    let (position, index, sub) = sdo_path(&position, &index, &sub)?;
    let sdo = sdo_access(&s)?;
    let bytes = sdo
        .read(position, index, sub)
        .await
        .map_err(|e| sdo_failed(e, position, index, sub))?;
    Ok(Json(value_of(position, index, sub, bytes)))
}

#[utoipa::path(put, path = "/api/v1/bus/subdevices/{position}/sdo/{index}/{sub}", tag = "bus",
    summary = "Write an object of a SubDevice by SDO download (CoE); answers the value read back",
    description = "For commissioning and diagnostics; audited. A drive refuses what its state does not allow (e.g. the \
PDO mapping outside PRE-OP: 409 `sdo_aborted` with 0x08000022).",
    params(("position" = u16, Path, description = "SubDevice position on the segment", example = 0),
        ("index" = String, Path, description = "object index in hex, `0x6065`", example = "0x6065", pattern = "^0[xX][0-9a-fA-F]{1,4}$"),
        ("sub" = u8, Path, description = "subindex", example = 0)),
    request_body = SdoWrite,
    responses((status = 200, description = "Written; the value read back", body = SdoValue), super::errors::SdoWriteErrors))]
pub async fn sdo_write(
    State(s): State<Arc<AppState>>,
    Path((position, index, sub)): Path<(String, String, String)>,
    client: Client,
    JsonBody(w, _): JsonBody<SdoWrite>,
) -> AppResult<Json<SdoValue>> {
    let (position, index, sub) = sdo_path(&position, &index, &sub)?;
    if !matches!(w.size, 1 | 2 | 4) {
        return Err(AppError::field("size", "1, 2 or 4 bytes"));
    }
    let bits = 8 * u32::from(w.size);
    let (min, max) = (-(1i64 << (bits - 1)), (1i64 << bits) - 1);
    if !(min..=max).contains(&w.value) {
        return Err(AppError::field(
            "value",
            &format!("does not fit {} bytes ({min}..{max})", w.size),
        ));
    }
    let sdo = sdo_access(&s)?;
    let bytes = (w.value as u64).to_le_bytes()[..w.size as usize].to_vec();
    let r = sdo.write(position, index, sub, &bytes).await;
    s.audit(audit_entry(
        &client.0,
        "bus.sdo_write",
        &format!("subdevice {position}"),
        serde_json::json!({"index": format!("{index:#06x}"), "sub": sub, "value": w.value, "size": w.size,
            "result": match &r { Ok(()) => "written".to_string(), Err(e) => format!("{e:?}") }})
        .to_string(),
    ));
    r.map_err(|e| sdo_failed(e, position, index, sub))?;
    let back = sdo
        .read(position, index, sub)
        .await
        .map_err(|e| sdo_failed(e, position, index, sub))?;
    Ok(Json(value_of(position, index, sub, back)))
}

/// Disturbances of the emulated segment (at least one).
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"lose_frames": 5}))]
pub struct BusFault {
    /// The next cycles to go unanswered: each cycle's frame is lost with its retries, so the
    /// bus counts that many lost frames; `max_errors_in_row` (3) in a row fault the bus
    /// (`5` stops the axes on it with bus_error 0x70A0).
    #[serde(default)]
    #[schema(minimum = 1, maximum = 100000)]
    pub lose_frames: Option<u32>,
    /// A SubDevice (by position) drops to SAFE-OP with an error (AL status code 0x001B,
    /// SyncManager watchdog), as a drive whose frames came late does: its axis stops.
    #[serde(default)]
    #[schema(minimum = 0, maximum = 65535)]
    pub safe_op: Option<u16>,
    /// The next answers of the segment to come back late, each `reply_delay_ms` after its
    /// frame: motiond has sent the frame again by then, so one copy answers it and the other
    /// is counted in `late_replies` and dropped.
    #[serde(default)]
    #[schema(minimum = 1, maximum = 100000)]
    pub late_replies: Option<u32>,
    /// The delay of a late answer (ms; default one and a half PDU timeouts).
    #[serde(default)]
    #[schema(minimum = 1, maximum = 1000)]
    pub reply_delay_ms: Option<u32>,
    /// The next answers to come back twice (counted in `duplicate_replies` and dropped).
    #[serde(default)]
    #[schema(minimum = 1, maximum = 100000)]
    pub duplicate_replies: Option<u32>,
    /// Stops motiond's TX/RX loop as a failing socket would (any EtherCAT bus, not only the
    /// emulated one): the bus faults with the reason, every axis on it goes to ErrorStop
    /// (bus_error 0x70A0) until `POST /bus/reset` or MC_Reset.
    #[serde(default)]
    pub stop_txrx: Option<bool>,
}

#[utoipa::path(post, path = "/api/v1/bus/faults", tag = "bus",
    summary = "Disturb the bus: lost, late or duplicate answers or a SubDevice dropped to SAFE-OP (--bus emulated only); stop the TX/RX loop (any EtherCAT bus)",
    request_body = BusFault,
    responses((status = 204, description = "The disturbance is under way"), super::errors::BusFaultErrors))]
pub async fn inject_bus_fault(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(f, raw): JsonBody<BusFault>,
) -> AppResult<StatusCode> {
    for (field, v) in [
        ("lose_frames", f.lose_frames),
        ("late_replies", f.late_replies),
        ("duplicate_replies", f.duplicate_replies),
    ] {
        if v.is_some_and(|n| !(1..=100_000).contains(&n)) {
            return Err(AppError::field(field, "1..100000"));
        }
    }
    if f.reply_delay_ms.is_some_and(|n| !(1..=1000).contains(&n)) {
        return Err(AppError::field("reply_delay_ms", "1..1000"));
    }
    let stop = f.stop_txrx == Some(true);
    let segment_faults = f.lose_frames.is_some()
        || f.safe_op.is_some()
        || f.late_replies.is_some()
        || f.duplicate_replies.is_some();
    if !segment_faults && !stop {
        return Err(AppError::field(
            "body",
            "give lose_frames, safe_op, late_replies, duplicate_replies or stop_txrx",
        ));
    }
    if stop && s.info.bus.control.is_none() {
        return Err(AppError::conflict(
            "bus_not_ethercat",
            "motiond runs the simulated bus: there is no TX/RX loop to stop",
        ));
    }
    if segment_faults {
        let Some(seg) = &s.info.bus.segment else {
            return Err(AppError::conflict(
                "bus_not_emulated",
                "only the emulated segment (--bus emulated) takes injected faults",
            ));
        };
        let mut seg = seg.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(n) = f.safe_op {
            if n as usize >= seg.escs.len() {
                return Err(AppError::not_found("subdevice", &n.to_string()));
            }
            seg.faults.safe_op = Some(n as usize);
        }
        seg.faults.silent_cycles += f.lose_frames.unwrap_or(0);
        if let Some(n) = f.late_replies {
            let timeout = s
                .info
                .bus
                .ethercat
                .as_ref()
                .map_or(std::time::Duration::from_millis(10), |(st, _)| {
                    st.pdu_timeout
                });
            seg.faults.late_replies += n;
            seg.faults.reply_delay = f.reply_delay_ms.map_or(timeout * 3 / 2, |ms| {
                std::time::Duration::from_millis(u64::from(ms))
            });
        }
        seg.faults.duplicate_replies += f.duplicate_replies.unwrap_or(0);
    }
    if stop {
        if let Some(c) = &s.info.bus.control {
            c.kill_loop();
        }
    }
    s.audit(audit_entry(&client.0, "bus.fault", "bus", raw.to_string()));
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/bus/reset", tag = "bus",
    summary = "Bring the EtherCAT segment back to OP after a fault, without restarting motiond",
    description = "Starts a stopped TX/RX loop again and asks every SubDevice that is not in OP back to OP \
(acknowledging its AL error); answers when all are in OP as the cycle reads them (within 10 s). The axes that \
the fault stopped stay in ErrorStop until their MC_Reset. Audited. 503 `bus_reset_failed` says what is still in \
the way (the SubDevice, its AL state and AL status code, or the link's error).",
    responses((status = 200, description = "The segment is in OP again; the bus as it is now", body = BusResource),
        super::errors::BusResetErrors))]
pub async fn reset_bus(
    State(s): State<Arc<AppState>>,
    client: Client,
) -> AppResult<Json<BusResource>> {
    let Some(control) = s.info.bus.control.clone() else {
        return Err(AppError::conflict(
            "bus_not_ethercat",
            "motiond runs the simulated bus: there is no EtherCAT segment to reset",
        ));
    };
    let r = tokio::task::spawn_blocking(move || control.reset(std::time::Duration::from_secs(10)))
        .await
        .map_err(|e| AppError::unavailable("bus_reset_failed", e.to_string()))?;
    s.audit(audit_entry(
        &client.0,
        "bus.reset",
        "bus",
        serde_json::json!({"result": match &r { Ok(t) => format!("op after {} ms", t.as_millis()), Err(e) => e.clone() }})
            .to_string(),
    ));
    match r {
        Ok(took) => {
            tracing::info!(
                "EtherCAT bus reset: every SubDevice in OP after {} ms",
                took.as_millis()
            );
            Ok(Json(bus_resource(&s)))
        }
        Err(why) => {
            tracing::warn!("EtherCAT bus reset failed: {why}");
            Err(AppError::unavailable("bus_reset_failed", why))
        }
    }
}
