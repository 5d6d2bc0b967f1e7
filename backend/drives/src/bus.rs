//! The drive bus: what the cycle thread exchanges the kernel's setpoints and the drives'
//! feedback with, once per cycle, for every axis slot at once — the process image of a
//! fieldbus. The simulated bus ([`SimBus`]) is the default; the EtherCAT bus of CiA-402 drives
//! implements the same trait in its own crate (`ethercat`: this crate does no network I/O, so
//! drive logic stays testable without a network card).
//!
//! Drives are built off the cycle thread ([`DriveConfig::build`]) and attached to a slot
//! there; whatever a slot held before comes back to be freed off the thread.

use motion::{DriveFeedback, DriveSetpoint};
use serde::{Deserialize, Serialize};

use crate::cia402::{Cia402Config, Cia402Drive};
use crate::error::ConfigError;
use crate::sim::{SimDrive, SimDriveConfig, SimFault};

/// How an axis's drive is configured: an object whose `kind` names the drive (`simulated`, the
/// only one yet; CiA-402 drives on EtherCAT will be a variant beside it) and whose other
/// fields are that drive's. A configuration without `kind` is a simulated drive: axes stored
/// before drives had kinds read as they were written.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DriveConfig {
    /// The simulated servo drive (plant model, cam, index pulse, limit switches, faults).
    Simulated(SimDriveConfig),
    /// A CiA-402 servo drive on the EtherCAT bus (`--bus ethercat` or `--bus emulated`).
    Cia402(Cia402Config),
}

impl Default for DriveConfig {
    fn default() -> Self {
        DriveConfig::Simulated(SimDriveConfig::default())
    }
}

impl DriveConfig {
    /// Checks every field; errors name the field by its JSON path below the drive object.
    pub fn validate(&self) -> Result<(), Vec<ConfigError>> {
        match self {
            DriveConfig::Simulated(c) => c.validate(),
            DriveConfig::Cia402(c) => c.validate(),
        }
    }

    /// Builds the drive for a cycle time of `cycle_time_s` (off the cycle thread: it
    /// allocates).
    pub fn build(&self, cycle_time_s: f64) -> Drive {
        match self {
            DriveConfig::Simulated(c) => {
                Drive::Simulated(Box::new(SimDrive::new(c.clone(), cycle_time_s)))
            }
            DriveConfig::Cia402(c) => Drive::Cia402(Box::new(Cia402Drive::new(c.clone()))),
        }
    }
}

/// A drive object is read whole, its `kind` (anywhere in it; `simulated` when absent) chooses
/// the variant, and the variant is read from the object without `kind`. An error inside it
/// names its path below the drive: the message is `PATH` + [`PATH_SEPARATOR`] + what is wrong,
/// which the server splits to extend the field's JSON path (`drive.plant.damping`).
impl<'de> Deserialize<'de> for DriveConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        use serde_json::Value;
        let mut map = match Value::deserialize(d)? {
            Value::Object(map) => map,
            other => {
                return Err(D::Error::invalid_type(
                    unexpected(&other),
                    &"a drive configuration object",
                ));
            }
        };
        let at = |path: &str, message: &dyn core::fmt::Display| {
            D::Error::custom(format_args!("{path}{PATH_SEPARATOR}{message}"))
        };
        let kind = match map.remove("kind") {
            None => "simulated".to_string(),
            Some(Value::String(k)) => k,
            Some(_) => return Err(at("kind", &"must be a string")),
        };
        let fields = Value::Object(map);
        let read = |e: serde_path_to_error::Error<serde_json::Error>| {
            let path = e.path().to_string();
            at(if path == "." { "" } else { &path }, e.inner())
        };
        match kind.as_str() {
            "simulated" => serde_path_to_error::deserialize(&fields)
                .map(DriveConfig::Simulated)
                .map_err(read),
            "cia402" => serde_path_to_error::deserialize(&fields)
                .map(DriveConfig::Cia402)
                .map_err(read),
            other => Err(at(
                "kind",
                &format_args!(
                    "unknown variant `{other}`, expected one of {}",
                    KINDS.join(", ")
                ),
            )),
        }
    }
}

fn unexpected(v: &serde_json::Value) -> serde::de::Unexpected<'_> {
    use serde::de::Unexpected;
    use serde_json::Value;
    match v {
        Value::Null => Unexpected::Unit,
        Value::Bool(b) => Unexpected::Bool(*b),
        Value::Number(_) => Unexpected::Other("a number"),
        Value::String(s) => Unexpected::Str(s),
        Value::Array(_) => Unexpected::Seq,
        Value::Object(_) => Unexpected::Map,
    }
}

/// Separates the path below a drive object from the message in a drive's read error.
pub const PATH_SEPARATOR: char = '\u{1f}';

/// The kinds of drive there are, as `kind` names them.
const KINDS: &[&str] = &["simulated", "cia402"];

/// The schema: one of the drive objects, each with its `kind` in front (optional for the
/// simulated drive, which is the default).
#[cfg(feature = "schema")]
impl utoipa::PartialSchema for DriveConfig {
    fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
        use utoipa::openapi::RefOr;
        use utoipa::openapi::schema::{Object, OneOf, Schema, SchemaType, Type};
        let with_kind = |mut schema: RefOr<Schema>, kind: &str, required: bool, about: &str| {
            if let RefOr::T(Schema::Object(o)) = &mut schema {
                let tag = Object::builder()
                    .schema_type(SchemaType::Type(Type::String))
                    .enum_values(Some([kind]))
                    .default((!required).then(|| kind.into()))
                    .description(Some(about))
                    .build();
                let mut properties = std::mem::take(&mut o.properties);
                o.properties.insert("kind".into(), tag.into());
                o.properties.append(&mut properties);
                if required {
                    o.required.insert(0, "kind".into());
                }
            }
            schema
        };
        let sim = with_kind(
            <SimDriveConfig as utoipa::PartialSchema>::schema(),
            "simulated",
            false,
            "A simulated servo drive (the default): a model of a drive, times in seconds, \
             positions in the axis's units.",
        );
        let cia402 = with_kind(
            <Cia402Config as utoipa::PartialSchema>::schema(),
            "cia402",
            true,
            "A CiA-402 servo drive on the EtherCAT bus (`--bus ethercat` or `--bus emulated`).",
        );
        OneOf::builder()
            .item(sim)
            .item(cia402)
            .description(Some(
                "An axis's drive: `kind` and that drive's fields — `simulated` (the default when \
                 `kind` is left out) or `cia402`.",
            ))
            .into()
    }
}

#[cfg(feature = "schema")]
impl utoipa::ToSchema for DriveConfig {
    fn schemas(
        schemas: &mut Vec<(
            String,
            utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>,
        )>,
    ) {
        <SimDriveConfig as utoipa::ToSchema>::schemas(schemas);
        <Cia402Config as utoipa::ToSchema>::schemas(schemas);
    }
}

/// A drive ready to be attached to a bus slot.
pub enum Drive {
    Simulated(Box<SimDrive>),
    Cia402(Box<Cia402Drive>),
}

impl core::fmt::Debug for Drive {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Drive::Simulated(_) => f.write_str("Drive::Simulated"),
            Drive::Cia402(_) => f.write_str("Drive::Cia402"),
        }
    }
}

/// What a bus could not do for a slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BusError {
    /// No drive is attached to the slot.
    NoDrive,
    /// The bus or the drive in the slot cannot do this (e.g. fault injection into a real
    /// drive).
    Unsupported,
}

/// The process image exchange of all axis slots. Implementations must not allocate, lock or
/// block in [`DriveBus::exchange`]: it runs on the real-time cycle thread.
pub trait DriveBus: Send {
    /// Number of slots (fixed at construction).
    fn slots(&self) -> usize;

    /// One exchange per cycle, after the kernel's step: `setpoints[slot]` go to the drives,
    /// and `feedback[slot]` receives what they answer, for the next cycle's step (a drive
    /// answers the previous cycle's setpoint, as on a fieldbus). A slot without a drive reads
    /// [`DriveFeedback::default`] (not ready).
    fn exchange(&mut self, setpoints: &[DriveSetpoint], feedback: &mut [DriveFeedback]);

    /// Puts `drive` into `slot`; returns what the slot held (to be freed off the cycle
    /// thread), or the drive itself when the bus cannot take it.
    fn attach(&mut self, slot: usize, drive: Drive) -> Result<Option<Drive>, Drive>;

    /// Empties `slot`; returns the drive it held.
    fn detach(&mut self, slot: usize) -> Option<Drive>;

    /// The bus's simulated drives, whose faults go through the simulated bus's own door
    /// ([`SimBus::inject`]): the simulated bus itself, or the simulated axes another bus
    /// carries besides its own drives; `None` for a bus without any. (A bus of real or
    /// emulated drives has its own door, in its own crate.)
    fn simulated(&mut self) -> Option<&mut SimBus> {
        None
    }

    /// A bus with a clock of its own (EtherCAT distributed clocks): how far (ns) the last
    /// exchange was from the phase of the bus's cycle it should have in (positive: late). The
    /// cycle thread moves its next deadline by a share of it, so that exactly one exchange
    /// falls in each SYNC0 period; `None` for a bus that follows the cycle thread.
    fn sync_error_ns(&self) -> Option<i64> {
        None
    }
}

/// How much (ns) the cycle thread moves its next deadline for a bus's sync error: an eighth
/// of the error, at most a twentieth of the period per cycle (a slow, jitter-damping follow of
/// the reference clock; a big error is taken over many cycles, never by skipping one).
pub fn sync_correction_ns(error_ns: i64, period_ns: u64) -> i64 {
    let max = (period_ns / 20) as i64;
    (-error_ns / 8).clamp(-max, max)
}

/// The simulated bus: one [`SimDrive`] per occupied slot, stepped by the exchange.
/// Deterministic, no clock, no allocation after construction.
pub struct SimBus {
    drives: Vec<Option<Box<SimDrive>>>,
}

impl SimBus {
    /// Injects a fault or disturbance into the simulated drive of `slot`.
    pub fn inject(&mut self, slot: usize, fault: SimFault) -> Result<(), BusError> {
        match self.drives.get_mut(slot).and_then(|d| d.as_deref_mut()) {
            Some(d) => {
                d.inject(fault);
                Ok(())
            }
            None => Err(BusError::NoDrive),
        }
    }

    pub fn new(slots: usize) -> SimBus {
        SimBus {
            drives: (0..slots).map(|_| None).collect(),
        }
    }

    /// The simulated drive in `slot`, if any.
    pub fn drive(&self, slot: usize) -> Option<&SimDrive> {
        self.drives.get(slot).and_then(|d| d.as_deref())
    }
}

impl DriveBus for SimBus {
    fn slots(&self) -> usize {
        self.drives.len()
    }

    fn exchange(&mut self, setpoints: &[DriveSetpoint], feedback: &mut [DriveFeedback]) {
        for ((d, sp), fb) in self.drives.iter_mut().zip(setpoints).zip(feedback) {
            *fb = match d {
                Some(d) => {
                    d.apply(sp);
                    d.feedback()
                }
                None => DriveFeedback::default(),
            };
        }
    }

    fn attach(&mut self, slot: usize, drive: Drive) -> Result<Option<Drive>, Drive> {
        let Some(place) = self.drives.get_mut(slot) else {
            return Err(drive);
        };
        // A CiA-402 drive needs an EtherCAT bus.
        let Drive::Simulated(d) = drive else {
            return Err(drive);
        };
        Ok(place.replace(d).map(Drive::Simulated))
    }

    fn detach(&mut self, slot: usize) -> Option<Drive> {
        self.drives
            .get_mut(slot)
            .and_then(|d| d.take())
            .map(Drive::Simulated)
    }

    fn simulated(&mut self) -> Option<&mut SimBus> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_object_names_its_kind_and_reads_without_one_as_simulated() {
        let sim = DriveConfig::Simulated(SimDriveConfig {
            dead_time: 0.002,
            ..SimDriveConfig::default()
        });
        let written = serde_json::to_value(&sim).unwrap();
        assert_eq!(written["kind"], "simulated");
        let read: DriveConfig = serde_json::from_value(written.clone()).unwrap();
        assert_eq!(read, sim);
        // Stored before drives had kinds; and `kind` wherever it stands.
        let legacy: DriveConfig = serde_json::from_str(r#"{"dead_time": 0.002}"#).unwrap();
        assert_eq!(legacy, sim);
        let last: DriveConfig =
            serde_json::from_str(r#"{"dead_time": 0.002, "kind": "simulated"}"#).unwrap();
        assert_eq!(last, sim);
        let empty: DriveConfig = serde_json::from_str("{}").unwrap();
        assert_eq!(empty, DriveConfig::default());
    }

    /// The cycle follows a bus clock slowly: an eighth of the error, never more than a
    /// twentieth of the period in one cycle; a steady error is worked off over cycles.
    #[test]
    fn the_sync_correction_is_a_damped_share_of_the_error() {
        assert_eq!(sync_correction_ns(0, 1_000_000), 0);
        assert_eq!(
            sync_correction_ns(80_000, 1_000_000),
            -10_000,
            "late: wake earlier"
        );
        assert_eq!(sync_correction_ns(-80_000, 1_000_000), 10_000);
        assert_eq!(sync_correction_ns(499_999, 1_000_000), -50_000, "clamped");
        // A constant phase error of 400 µs is down to a tenth of it within 25 cycles.
        let mut e: i64 = 400_000;
        for _ in 0..25 {
            e += sync_correction_ns(e, 1_000_000);
        }
        assert!(e.abs() < 40_000, "{e}");
    }

    #[test]
    fn a_cia402_drive_reads_with_its_kind_anywhere() {
        let c: DriveConfig = serde_json::from_str(
            r#"{"subdevice": 1, "increments_per_unit": 1000, "kind": "cia402"}"#,
        )
        .unwrap();
        let DriveConfig::Cia402(c) = c else {
            panic!("{c:?}")
        };
        assert_eq!((c.subdevice, c.increments_per_unit), (1, 1000.0));
        let written = serde_json::to_value(DriveConfig::Cia402(c)).unwrap();
        assert_eq!(written["kind"], "cia402");
        // Errors inside name their path below the drive.
        let e = serde_json::from_str::<DriveConfig>(r#"{"kind": "cia402", "subdevice": -1}"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&format!("subdevice{PATH_SEPARATOR}")), "{e}");
        let e = serde_json::from_str::<DriveConfig>(r#"{"plant": {"kind": "pt9"}}"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&format!("plant.kind{PATH_SEPARATOR}")), "{e}");
    }

    #[test]
    fn an_unknown_kind_or_field_is_refused() {
        let e = serde_json::from_str::<DriveConfig>(r#"{"kind": "servo"}"#).unwrap_err();
        assert!(e.to_string().contains("unknown variant `servo`"), "{e}");
        let e = serde_json::from_str::<DriveConfig>(r#"{"kind": "cia402"}"#).unwrap_err();
        assert!(e.to_string().contains("missing field"), "{e}");
        let e = serde_json::from_str::<DriveConfig>(r#"{"dead_tme": 0.1}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `dead_tme`"), "{e}");
        let e = serde_json::from_str::<DriveConfig>("[]").unwrap_err();
        assert!(e.to_string().contains("drive configuration object"), "{e}");
    }
}
