//! The drive bus: what the cycle thread exchanges the kernel's setpoints and the drives'
//! feedback with, once per cycle, for every axis slot at once — the process image of a
//! fieldbus. The simulated bus ([`SimBus`]) is the only implementation today; an EtherCAT bus
//! of CiA-402 drives will implement the same trait in its own crate (this crate does no
//! network I/O, so drive logic stays testable without a network card).
//!
//! Drives are built off the cycle thread ([`DriveConfig::build`]) and attached to a slot
//! there; whatever a slot held before comes back to be freed off the thread.

use motion::{DriveFeedback, DriveSetpoint};
use serde::{Deserialize, Serialize};

use crate::sim::{FieldError, SimDrive, SimDriveConfig, SimFault};

/// How an axis's drive is configured: an object whose `kind` names the drive (`simulated`, the
/// only one yet; CiA-402 drives on EtherCAT will be a variant beside it) and whose other
/// fields are that drive's. A configuration without `kind` is a simulated drive: axes stored
/// before drives had kinds read as they were written.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DriveConfig {
    /// The simulated servo drive (plant model, cam, index pulse, limit switches, faults).
    Simulated(SimDriveConfig),
}

impl Default for DriveConfig {
    fn default() -> Self {
        DriveConfig::Simulated(SimDriveConfig::default())
    }
}

impl DriveConfig {
    /// Checks every field; errors name the field by its JSON path below the drive object.
    pub fn validate(&self) -> Result<(), Vec<FieldError>> {
        match self {
            DriveConfig::Simulated(c) => c.validate(),
        }
    }

    /// Builds the drive for a cycle time of `cycle_time_s` (off the cycle thread: it
    /// allocates).
    pub fn build(&self, cycle_time_s: f64) -> Drive {
        match self {
            DriveConfig::Simulated(c) => {
                Drive::Simulated(Box::new(SimDrive::new(c.clone(), cycle_time_s)))
            }
        }
    }
}

/// Reads the object's fields in place (no buffering), so that an error inside a drive's fields
/// keeps its JSON path (`drive.plant.damping`) for whoever tracks it.
impl<'de> Deserialize<'de> for DriveConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Object;
        impl<'de> serde::de::Visitor<'de> for Object {
            type Value = DriveConfig;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("a drive configuration object")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<DriveConfig, A::Error> {
                let fields = serde::de::value::MapAccessDeserializer::new(WithoutKind(map));
                SimDriveConfig::deserialize(fields).map(DriveConfig::Simulated)
            }
        }
        d.deserialize_map(Object)
    }
}

/// The kinds of drive there are, as `kind` names them.
const KINDS: &[&str] = &["simulated"];

/// A drive object's fields without its `kind` (checked on the way: with a single kind, the
/// fields that follow are that kind's wherever `kind` stands).
struct WithoutKind<A>(A);

impl<'de, A: serde::de::MapAccess<'de>> serde::de::MapAccess<'de> for WithoutKind<A> {
    type Error = A::Error;

    fn next_key_seed<K: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        use serde::de::{Error, IntoDeserializer};
        loop {
            let Some(key) = self.0.next_key::<String>()? else {
                return Ok(None);
            };
            if key != "kind" {
                return seed.deserialize(key.into_deserializer()).map(Some);
            }
            let kind: String = self.0.next_value()?;
            if !KINDS.contains(&kind.as_str()) {
                return Err(A::Error::unknown_variant(&kind, KINDS));
            }
        }
    }

    fn next_value_seed<V: serde::de::DeserializeSeed<'de>>(
        &mut self,
        seed: V,
    ) -> Result<V::Value, A::Error> {
        self.0.next_value_seed(seed)
    }
}

/// The schema: the simulated drive's object with `kind` in front (a `oneOf` over the kinds
/// once there is more than one).
#[cfg(feature = "schema")]
impl utoipa::PartialSchema for DriveConfig {
    fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
        use utoipa::openapi::RefOr;
        use utoipa::openapi::schema::{Object, Schema, SchemaType, Type};
        let mut schema = <SimDriveConfig as utoipa::PartialSchema>::schema();
        if let RefOr::T(Schema::Object(o)) = &mut schema {
            let kind = Object::builder()
                .schema_type(SchemaType::Type(Type::String))
                .enum_values(Some(KINDS.iter().copied()))
                .default(Some("simulated".into()))
                .description(Some(
                    "The kind of drive; `simulated` (the default) is the only one yet.",
                ))
                .build();
            let mut properties = std::mem::take(&mut o.properties);
            o.properties.insert("kind".into(), kind.into());
            o.properties.append(&mut properties);
            o.description = Some(
                "An axis's drive: `kind` and that drive's fields. A simulated drive: a model of \
                 a servo drive (times in seconds, positions in the axis's units)."
                    .into(),
            );
        }
        schema
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
    }
}

/// A drive ready to be attached to a bus slot.
pub enum Drive {
    Simulated(Box<SimDrive>),
}

impl core::fmt::Debug for Drive {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Drive::Simulated(_) => f.write_str("Drive::Simulated"),
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

    /// Injects a fault or disturbance into the drive of `slot` (simulated drives only).
    fn inject(&mut self, slot: usize, fault: SimFault) -> Result<(), BusError> {
        let _ = (slot, fault);
        Err(BusError::Unsupported)
    }
}

/// The simulated bus: one [`SimDrive`] per occupied slot, stepped by the exchange.
/// Deterministic, no clock, no allocation after construction.
pub struct SimBus {
    drives: Vec<Option<Box<SimDrive>>>,
}

impl SimBus {
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
        let Drive::Simulated(d) = drive;
        Ok(place.replace(d).map(Drive::Simulated))
    }

    fn detach(&mut self, slot: usize) -> Option<Drive> {
        self.drives
            .get_mut(slot)
            .and_then(|d| d.take())
            .map(Drive::Simulated)
    }

    fn inject(&mut self, slot: usize, fault: SimFault) -> Result<(), BusError> {
        match self.drives.get_mut(slot).and_then(|d| d.as_deref_mut()) {
            Some(d) => {
                d.inject(fault);
                Ok(())
            }
            None => Err(BusError::NoDrive),
        }
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

    #[test]
    fn an_unknown_kind_or_field_is_refused() {
        let e = serde_json::from_str::<DriveConfig>(r#"{"kind": "cia402"}"#).unwrap_err();
        assert!(e.to_string().contains("unknown variant `cia402`"), "{e}");
        let e = serde_json::from_str::<DriveConfig>(r#"{"dead_tme": 0.1}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `dead_tme`"), "{e}");
        let e = serde_json::from_str::<DriveConfig>("[]").unwrap_err();
        assert!(e.to_string().contains("drive configuration object"), "{e}");
    }
}
