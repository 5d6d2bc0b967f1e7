//! A JSON object written member by member against the version written before it (issue 27):
//! each top-level member's value is first walked into a *print* — its values as bytes, with
//! nothing formatted or escaped — and a member whose print equals the previous version's is
//! copied from that version's text instead of being written again. A moving axis changes
//! six or seven of its status's 77 members a cycle, so the floats and keys of the other
//! seventy (the cam block alone is 1.7 KB) are formatted once, not at every tick.
//!
//! Equal prints mean equal JSON: a print records every call serde makes with every argument
//! serde_json's output depends on (a value's exact bits, a string's bytes; the name of a
//! struct, of its fields or of an enum's variant by its address, which is the same for the
//! same name of the same type — a different address only makes a member count as changed;
//! serde_json writes a struct of one special name, its `RawValue`, raw). The text is exactly
//! what `serde_json::to_string` writes for the whole object (tests).

use serde::ser::{self, Serialize};

/// A top-level member `"key":value`: where it starts, where its value starts (after the
/// colon), where it ends, in the object's text.
pub type Member = (u32, u32, u32);

/// An object's JSON text and its members, with the cycle at which each member last changed.
/// `T`: the text as written (`String`), or shared (`Arc<String>`: the feed's versions).
pub struct Written<T = String> {
    /// The cycle it was written at.
    pub cycle: u64,
    pub json: T,
    pub members: Vec<Member>,
    /// For each member, the cycle of the version in which its value (or key) last differed
    /// from the version before at the same place. (Only what changed since `shape_since` is
    /// known from it: a member copied across a change of the other members keeps its older
    /// cycle.)
    pub since: Vec<u64>,
    /// The cycle since which every version has had these members (keys in this order).
    pub shape_since: u64,
}

impl<T> Written<T>
where
    T: std::ops::Deref,
    T::Target: AsRef<str>,
{
    fn text(&self) -> &str {
        (*self.json).as_ref()
    }

    /// This object as the one the next is written against (`prints`: those `write` made with
    /// it).
    pub fn before<'a>(&'a self, prints: &'a Prints) -> Before<'a> {
        Before {
            cycle: self.cycle,
            json: self.text(),
            members: &self.members,
            since: &self.since,
            shape_since: self.shape_since,
            prints,
        }
    }

    /// Member `i`'s key with its colon (`"key":`).
    pub fn key(&self, i: usize) -> &str {
        let (start, value, _) = self.members[i];
        &self.text()[start as usize..value as usize]
    }

    /// Member `i`'s value.
    pub fn value(&self, i: usize) -> &str {
        let (_, value, end) = self.members[i];
        &self.text()[value as usize..end as usize]
    }

    /// Member `i`, key and value.
    pub fn member(&self, i: usize) -> &str {
        let (start, _, end) = self.members[i];
        &self.text()[start as usize..end as usize]
    }
}

impl Written {
    /// The same object, its text shared as it was written (not copied).
    pub fn shared(self) -> Written<std::sync::Arc<String>> {
        Written {
            cycle: self.cycle,
            json: std::sync::Arc::new(self.json),
            members: self.members,
            since: self.since,
            shape_since: self.shape_since,
        }
    }
}

/// The prints of the last object written (kept for the next one: only the newest is needed).
#[derive(Default)]
pub struct Prints {
    bytes: Vec<u8>,
    /// A changed member as serde_json writes it (kept here to be reused).
    scratch: Vec<u8>,
    /// Where member i's print ends in `bytes` (it starts where member i − 1's ends).
    ends: Vec<u32>,
}

impl Prints {
    fn member(&self, i: usize) -> Option<&[u8]> {
        let end = *self.ends.get(i)? as usize;
        let start = if i == 0 { 0 } else { self.ends[i - 1] as usize };
        Some(&self.bytes[start..end])
    }
}

/// The version written before, and its prints.
pub struct Before<'a> {
    pub cycle: u64,
    pub json: &'a str,
    pub members: &'a [Member],
    pub since: &'a [u64],
    pub shape_since: u64,
    pub prints: &'a Prints,
}

/// `value` (an object: a struct or a map with string keys) at `cycle` as JSON, its members
/// that are unchanged since `before` copied from `before`'s text; its prints go to `prints`
/// (cleared first; not `before`'s: the caller keeps two and swaps them). `None` for anything
/// else (also for some values serde_json writes as objects: an object in `Some`, a variant,
/// a map with keys that are not strings). A `before` of the same or a later cycle is not used
/// (its members' cycles would say nothing about this one).
pub fn write(
    cycle: u64,
    value: &impl Serialize,
    before: Option<Before<'_>>,
    prints: &mut Prints,
) -> Option<Written> {
    prints.bytes.clear();
    prints.ends.clear();
    let before = before.filter(|b| b.cycle < cycle);
    // `before`'s prints are its own (they are paired by the caller).
    debug_assert!(
        before.as_ref().is_none_or(
            |b| b.prints.ends.len() == b.members.len() && b.since.len() == b.members.len()
        )
    );
    let mut top = Top {
        cycle,
        print: Print {
            bytes: std::mem::take(&mut prints.bytes),
        },
        ends: std::mem::take(&mut prints.ends),
        out: String::with_capacity(before.as_ref().map_or(5 * 1024, |b| b.json.len() + 64)),
        members: Vec::with_capacity(before.as_ref().map_or(96, |b| b.members.len())),
        since: Vec::with_capacity(before.as_ref().map_or(96, |b| b.members.len())),
        same_shape: before.is_some(),
        before,
        member_start: 0,
        run: None,
        scratch: std::mem::take(&mut prints.scratch),
    };
    let ok = value.serialize(&mut top).is_ok();
    prints.bytes = std::mem::take(&mut top.print.bytes);
    prints.scratch = std::mem::take(&mut top.scratch);
    prints.ends = std::mem::take(&mut top.ends);
    if !ok {
        prints.bytes.clear();
        prints.ends.clear();
        return None;
    }
    let same_shape = top.same_shape
        && top
            .before
            .as_ref()
            .is_some_and(|b| b.members.len() == top.members.len());
    let shape_since = match &top.before {
        Some(b) if same_shape => b.shape_since,
        _ => cycle,
    };
    Some(Written {
        cycle,
        json: top.out,
        members: top.members,
        since: top.since,
        shape_since,
    })
}

/// Not an object, or a value serde_json would not write.
#[derive(Debug)]
pub struct NotWritten;

impl std::fmt::Display for NotWritten {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("not a JSON object")
    }
}

impl std::error::Error for NotWritten {}

impl ser::Error for NotWritten {
    fn custom<T: std::fmt::Display>(_: T) -> Self {
        NotWritten
    }
}

impl From<serde_json::Error> for NotWritten {
    fn from(_: serde_json::Error) -> Self {
        NotWritten
    }
}

/// The outermost object: its members, each printed, then copied or written.
struct Top<'a> {
    cycle: u64,
    print: Print,
    ends: Vec<u32>,
    /// (Text: what is copied is text already, a member written is checked once.)
    out: String,
    members: Vec<Member>,
    since: Vec<u64>,
    before: Option<Before<'a>>,
    /// So far every key is the one `before` has at the same place.
    same_shape: bool,
    /// Where the member being written begins in the prints.
    member_start: usize,
    /// Unchanged members not copied yet: `before`'s text from .0 to .1.
    run: Option<(usize, usize)>,
    /// A changed member as serde_json writes it.
    scratch: Vec<u8>,
}

fn at(x: usize) -> Result<u32, NotWritten> {
    u32::try_from(x).map_err(|_| NotWritten)
}

impl Top<'_> {
    /// The member whose key and value have just been printed (from `member_start`): copied
    /// from `before` when its print is the same there, else written.
    /// `key`: the member's key, when serde gave it with the value (else it is read back from
    /// the print).
    fn member<K: ?Sized + Serialize, T: ?Sized + Serialize>(
        &mut self,
        key: Option<&K>,
        value: &T,
    ) -> Result<(), NotWritten> {
        let i = self.members.len();
        let end = self.print.bytes.len();
        self.ends.push(at(end)?);
        let print = &self.print.bytes[self.member_start..end];
        let same = self
            .before
            .as_ref()
            .filter(|b| b.prints.member(i) == Some(print));
        if let Some(b) = same {
            // Copied when the run of unchanged members ends (one copy per run, the commas
            // between them included); where it will be is known now.
            let (s, v, e) = b.members[i];
            let (s, v, e) = (s as usize, v as usize, e as usize);
            let from = match &mut self.run {
                Some((from, to)) => {
                    *to = e;
                    *from
                }
                None => {
                    if i > 0 {
                        self.out.push(',');
                    }
                    self.run = Some((s, e));
                    s
                }
            };
            let here = |x: usize| at(self.out.len() + (x - from));
            self.members.push((here(s)?, here(v)?, here(e)?));
            self.since.push(b.since[i]);
            return Ok(());
        }
        self.copy_run();
        if i > 0 {
            self.out.push(',');
        }
        let start = self.out.len();
        // The key is the print's first string (see `SerializeMap::serialize_key`). Written
        // into `scratch`, checked as text once (not each of serde_json's small writes).
        self.scratch.clear();
        match key {
            Some(key) => serde_json::to_writer(&mut self.scratch, key)?,
            None => {
                let key = print_str(&self.print.bytes[self.member_start..end]).ok_or(NotWritten)?;
                serde_json::to_writer(&mut self.scratch, key)?
            }
        }
        let key_len = self.scratch.len();
        if let Some(b) = &self.before {
            let same_key = b.members.get(i).is_some_and(|&(s, v, _)| {
                b.json.as_bytes()[s as usize..v as usize - 1] == self.scratch[..]
            });
            self.same_shape &= same_key;
        }
        self.scratch.push(b':');
        serde_json::to_writer(&mut self.scratch, value)?;
        self.out
            .push_str(std::str::from_utf8(&self.scratch).map_err(|_| NotWritten)?);
        self.members
            .push((at(start)?, at(start + key_len + 1)?, at(self.out.len())?));
        self.since.push(self.cycle);
        Ok(())
    }
}

/// The string a print begins with (a key).
fn print_str(print: &[u8]) -> Option<&str> {
    let (&tag, rest) = print.split_first()?;
    if tag != STR || rest.len() < 8 {
        return None;
    }
    let len = u64::from_le_bytes(rest[..8].try_into().ok()?) as usize;
    std::str::from_utf8(rest.get(8..8 + len)?).ok()
}

impl<'t> ser::SerializeMap for &mut Top<'t> {
    type Ok = ();
    type Error = NotWritten;

    fn serialize_key<T: ?Sized + Serialize>(&mut self, key: &T) -> Result<(), NotWritten> {
        self.member_start = self.print.bytes.len();
        key.serialize(&mut self.print)?;
        // serde_json writes only string keys as they are; anything else is not ours to copy.
        match self.print.bytes.get(self.member_start) {
            Some(&STR) => Ok(()),
            _ => Err(NotWritten),
        }
    }

    fn serialize_value<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NotWritten> {
        value.serialize(&mut self.print)?;
        self.member(None::<&str>, value)
    }

    // What serde's flatten calls: the key at hand, not read back from the print.
    fn serialize_entry<K: ?Sized + Serialize, V: ?Sized + Serialize>(
        &mut self,
        key: &K,
        value: &V,
    ) -> Result<(), NotWritten> {
        ser::SerializeMap::serialize_key(self, key)?;
        value.serialize(&mut self.print)?;
        self.member(Some(key), value)
    }

    fn end(self) -> Result<(), NotWritten> {
        self.close()
    }
}

impl<'t> ser::SerializeStruct for &mut Top<'t> {
    type Ok = ();
    type Error = NotWritten;

    fn serialize_field<T: ?Sized + Serialize>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), NotWritten> {
        self.member_start = self.print.bytes.len();
        self.print.str(key);
        value.serialize(&mut self.print)?;
        self.member(Some(key), value)
    }

    fn end(self) -> Result<(), NotWritten> {
        self.close()
    }
}

impl Top<'_> {
    fn open(&mut self) {
        self.out.push('{');
    }

    fn copy_run(&mut self) {
        if let (Some((from, to)), Some(b)) = (self.run.take(), &self.before) {
            self.out.push_str(&b.json[from..to]);
        }
    }

    fn close(&mut self) -> Result<(), NotWritten> {
        self.copy_run();
        self.out.push('}');
        Ok(())
    }
}

/// Anything but an object at the top is not written here.
macro_rules! not_an_object {
    ($($name:ident($($arg:ty),*);)*) => {
        $(fn $name(self, $(_: $arg),*) -> Result<(), NotWritten> {
            Err(NotWritten)
        })*
    };
}

impl<'a, 't> ser::Serializer for &'a mut Top<'t> {
    type Ok = ();
    type Error = NotWritten;
    type SerializeSeq = ser::Impossible<(), NotWritten>;
    type SerializeTuple = ser::Impossible<(), NotWritten>;
    type SerializeTupleStruct = ser::Impossible<(), NotWritten>;
    type SerializeTupleVariant = ser::Impossible<(), NotWritten>;
    type SerializeMap = Self;
    type SerializeStruct = Self;
    type SerializeStructVariant = ser::Impossible<(), NotWritten>;

    not_an_object! {
        serialize_bool(bool); serialize_i8(i8); serialize_i16(i16); serialize_i32(i32);
        serialize_i64(i64); serialize_i128(i128); serialize_u8(u8); serialize_u16(u16);
        serialize_u32(u32); serialize_u64(u64); serialize_u128(u128); serialize_f32(f32);
        serialize_f64(f64); serialize_char(char); serialize_str(&str); serialize_bytes(&[u8]);
        serialize_none(); serialize_unit(); serialize_unit_struct(&'static str);
        serialize_unit_variant(&'static str, u32, &'static str);
    }

    fn serialize_some<T: ?Sized + Serialize>(self, _: &T) -> Result<(), NotWritten> {
        Err(NotWritten)
    }

    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), NotWritten> {
        // serde_json writes a newtype as what it wraps.
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), NotWritten> {
        Err(NotWritten)
    }

    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, NotWritten> {
        Err(NotWritten)
    }

    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, NotWritten> {
        Err(NotWritten)
    }

    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, NotWritten> {
        Err(NotWritten)
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, NotWritten> {
        Err(NotWritten)
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Self, NotWritten> {
        self.open();
        Ok(self)
    }

    fn serialize_struct(self, name: &'static str, _: usize) -> Result<Self, NotWritten> {
        // serde_json writes its `RawValue` (a struct of this name) raw, not as an object.
        if name == RAW_VALUE {
            return Err(NotWritten);
        }
        self.open();
        Ok(self)
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, NotWritten> {
        Err(NotWritten)
    }
}

/// The name of serde_json's `RawValue` struct (serde_json's `raw_value` feature, which axum
/// turns on): written as the text it holds.
const RAW_VALUE: &str = "$serde_json::private::RawValue";

// The print's tags: each value begins with one; a sequence, map or struct ends with END, which
// begins no value, so a print reads back one way only.
const END: u8 = 0;
const BOOL: u8 = 1;
const INT: u8 = 2;
const UINT: u8 = 3;
const INT128: u8 = 4;
const F32: u8 = 5;
const F64: u8 = 6;
const CHAR: u8 = 7;
const STR: u8 = 8;
const BYTES: u8 = 9;
const NONE: u8 = 10;
const SOME: u8 = 11;
const UNIT: u8 = 12;
const UNIT_STRUCT: u8 = 13;
const UNIT_VARIANT: u8 = 14;
const NEWTYPE: u8 = 15;
const NEWTYPE_VARIANT: u8 = 16;
const SEQ: u8 = 17;
const TUPLE_VARIANT: u8 = 18;
const MAP: u8 = 19;
const STRUCT: u8 = 20;
const STRUCT_VARIANT: u8 = 21;
const FIELD: u8 = 22;
const SKIPPED: u8 = 23;
const UINT128: u8 = 24;

/// A value's print: its serde calls as bytes.
struct Print {
    bytes: Vec<u8>,
}

impl Print {
    fn tag(&mut self, tag: u8, payload: &[u8]) {
        self.bytes.push(tag);
        self.bytes.extend_from_slice(payload);
    }

    /// A tag and eight bytes (most values: one copy, one capacity check).
    fn tag8(&mut self, tag: u8, payload: [u8; 8]) {
        let mut b = [tag; 9];
        b[1..].copy_from_slice(&payload);
        self.bytes.extend_from_slice(&b);
    }

    fn str(&mut self, s: &str) {
        self.tag8(STR, (s.len() as u64).to_le_bytes());
        self.bytes.extend_from_slice(s.as_bytes());
    }

    /// A name serde gives as `&'static str` (a field, a variant): by its address and length.
    fn name(&mut self, name: &'static str) {
        let mut b = [0; 12];
        b[..8].copy_from_slice(&(name.as_ptr() as usize as u64).to_le_bytes());
        b[8..].copy_from_slice(&(name.len() as u32).to_le_bytes());
        self.bytes.extend_from_slice(&b);
    }

    fn variant(&mut self, tag: u8, index: u32, variant: &'static str) {
        self.tag(tag, &index.to_le_bytes());
        self.name(variant);
    }
}

/// Serializer methods that hand a narrower integer to the method for the widest.
macro_rules! widen {
    ($($name:ident($ty:ty) => $wide:ident;)*) => {
        $(fn $name(self, v: $ty) -> Result<(), NotWritten> {
            self.$wide(v.into())
        })*
    };
}

impl ser::Serializer for &mut Print {
    type Ok = ();
    type Error = NotWritten;
    type SerializeSeq = Self;
    type SerializeTuple = Self;
    type SerializeTupleStruct = Self;
    type SerializeTupleVariant = Self;
    type SerializeMap = Self;
    type SerializeStruct = Self;
    type SerializeStructVariant = Self;

    fn serialize_bool(self, v: bool) -> Result<(), NotWritten> {
        self.tag(BOOL, &[v as u8]);
        Ok(())
    }

    // Narrower integers as the widest of their sign (serde_json writes them alike).
    widen! {
        serialize_i8(i8) => serialize_i64; serialize_i16(i16) => serialize_i64;
        serialize_i32(i32) => serialize_i64; serialize_u8(u8) => serialize_u64;
        serialize_u16(u16) => serialize_u64; serialize_u32(u32) => serialize_u64;
    }

    fn serialize_i64(self, v: i64) -> Result<(), NotWritten> {
        self.tag8(INT, v.to_le_bytes());
        Ok(())
    }

    fn serialize_i128(self, v: i128) -> Result<(), NotWritten> {
        self.tag(INT128, &v.to_le_bytes());
        Ok(())
    }

    fn serialize_u64(self, v: u64) -> Result<(), NotWritten> {
        self.tag8(UINT, v.to_le_bytes());
        Ok(())
    }

    fn serialize_u128(self, v: u128) -> Result<(), NotWritten> {
        // Its own tag: a u128 and an i128 of the same bits are written differently.
        self.tag(UINT128, &v.to_le_bytes());
        Ok(())
    }

    fn serialize_f32(self, v: f32) -> Result<(), NotWritten> {
        self.tag(F32, &v.to_bits().to_le_bytes());
        Ok(())
    }

    fn serialize_f64(self, v: f64) -> Result<(), NotWritten> {
        self.tag8(F64, v.to_bits().to_le_bytes());
        Ok(())
    }

    fn serialize_char(self, v: char) -> Result<(), NotWritten> {
        self.tag(CHAR, &u32::from(v).to_le_bytes());
        Ok(())
    }

    fn serialize_str(self, v: &str) -> Result<(), NotWritten> {
        self.str(v);
        Ok(())
    }

    fn serialize_bytes(self, v: &[u8]) -> Result<(), NotWritten> {
        self.tag(BYTES, &(v.len() as u64).to_le_bytes());
        self.bytes.extend_from_slice(v);
        Ok(())
    }

    fn serialize_none(self) -> Result<(), NotWritten> {
        self.bytes.push(NONE);
        Ok(())
    }

    fn serialize_some<T: ?Sized + Serialize>(self, value: &T) -> Result<(), NotWritten> {
        self.bytes.push(SOME);
        value.serialize(self)
    }

    fn serialize_unit(self) -> Result<(), NotWritten> {
        self.bytes.push(UNIT);
        Ok(())
    }

    fn serialize_unit_struct(self, name: &'static str) -> Result<(), NotWritten> {
        self.bytes.push(UNIT_STRUCT);
        self.name(name);
        Ok(())
    }

    fn serialize_unit_variant(
        self,
        _: &'static str,
        index: u32,
        variant: &'static str,
    ) -> Result<(), NotWritten> {
        self.variant(UNIT_VARIANT, index, variant);
        Ok(())
    }

    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        name: &'static str,
        value: &T,
    ) -> Result<(), NotWritten> {
        self.bytes.push(NEWTYPE);
        self.name(name);
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        index: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), NotWritten> {
        self.variant(NEWTYPE_VARIANT, index, variant);
        value.serialize(self)
    }

    fn serialize_seq(self, _: Option<usize>) -> Result<Self, NotWritten> {
        self.bytes.push(SEQ);
        Ok(self)
    }

    fn serialize_tuple(self, _: usize) -> Result<Self, NotWritten> {
        self.bytes.push(SEQ);
        Ok(self)
    }

    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self, NotWritten> {
        self.bytes.push(SEQ);
        Ok(self)
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        index: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Self, NotWritten> {
        self.variant(TUPLE_VARIANT, index, variant);
        Ok(self)
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Self, NotWritten> {
        self.bytes.push(MAP);
        Ok(self)
    }

    fn serialize_struct(self, name: &'static str, _: usize) -> Result<Self, NotWritten> {
        // The name too: serde_json writes a struct of one name (its `RawValue`) raw.
        self.bytes.push(STRUCT);
        self.name(name);
        Ok(self)
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        index: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Self, NotWritten> {
        self.variant(STRUCT_VARIANT, index, variant);
        Ok(self)
    }
}

/// Sequences, tuples and tuple variants: their elements, then END.
macro_rules! print_elements {
    ($($trait:ident :: $method:ident),*) => {
        $(impl ser::$trait for &mut Print {
            type Ok = ();
            type Error = NotWritten;

            fn $method<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NotWritten> {
                value.serialize(&mut **self)
            }

            fn end(self) -> Result<(), NotWritten> {
                self.bytes.push(END);
                Ok(())
            }
        })*
    };
}

print_elements!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

impl ser::SerializeMap for &mut Print {
    type Ok = ();
    type Error = NotWritten;

    fn serialize_key<T: ?Sized + Serialize>(&mut self, key: &T) -> Result<(), NotWritten> {
        key.serialize(&mut **self)
    }

    fn serialize_value<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NotWritten> {
        value.serialize(&mut **self)
    }

    fn end(self) -> Result<(), NotWritten> {
        self.bytes.push(END);
        Ok(())
    }
}

/// Structs and struct variants: each field by its name, then END.
macro_rules! print_fields {
    ($($trait:ident),*) => {
        $(impl ser::$trait for &mut Print {
            type Ok = ();
            type Error = NotWritten;

            fn serialize_field<T: ?Sized + Serialize>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> Result<(), NotWritten> {
                self.bytes.push(FIELD);
                self.name(key);
                value.serialize(&mut **self)
            }

            fn skip_field(&mut self, key: &'static str) -> Result<(), NotWritten> {
                self.bytes.push(SKIPPED);
                self.name(key);
                Ok(())
            }

            fn end(self) -> Result<(), NotWritten> {
                self.bytes.push(END);
                Ok(())
            }
        })*
    };
}

print_fields!(SerializeStruct, SerializeStructVariant);

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{Value, json};

    /// Writes each value against the one before, as the feed does, and checks that every
    /// text is exactly serde_json's and that the members are marked where they are.
    fn chain<T: Serialize>(values: &[T]) -> Vec<Written> {
        let (mut prints, mut spare) = (Prints::default(), Prints::default());
        let mut out: Vec<Written> = Vec::new();
        for (c, v) in values.iter().enumerate() {
            let cycle = 10 * (c as u64 + 1);
            let before = out.last().map(|w| w.before(&prints));
            let w = write(cycle, v, before, &mut spare).unwrap();
            std::mem::swap(&mut prints, &mut spare);
            assert_eq!(w.json, serde_json::to_string(v).unwrap(), "cycle {cycle}");
            let whole: serde_json::Map<String, Value> = serde_json::from_str(&w.json).unwrap();
            assert_eq!(w.members.len(), whole.len());
            assert_eq!(w.since.len(), whole.len());
            for (i, &(s, v, e)) in w.members.iter().enumerate() {
                let key: String =
                    serde_json::from_str(&w.json[s as usize..v as usize - 1]).unwrap();
                let value: Value = serde_json::from_str(&w.json[v as usize..e as usize]).unwrap();
                assert_eq!(whole[&key], value, "member {key} at cycle {cycle}");
                // One after the other, a comma between them, nothing else around them.
                let after = if i == 0 { 1 } else { w.members[i - 1].2 + 1 };
                assert_eq!(s, after, "member {key} at cycle {cycle}");
            }
            let last = w.members.last().map_or(1, |m| m.2);
            assert_eq!(last as usize + 1, w.json.len());
            out.push(w);
        }
        out
    }

    /// The cycles at which each member last changed, by key.
    fn since(w: &Written) -> Vec<(String, u64)> {
        w.members
            .iter()
            .zip(&w.since)
            .map(|(&(s, v, _), &c)| {
                (
                    serde_json::from_str(&w.json[s as usize..v as usize - 1]).unwrap(),
                    c,
                )
            })
            .collect()
    }

    #[test]
    fn members_are_copied_while_their_values_stay_and_written_when_they_change() {
        let w = chain(&[
            json!({"p": 1.5, "s": "standstill", "n": {"x": [1, {"y": null}]}, "k": true, "e": "q\\\"\u{1}"}),
            json!({"p": 2.5, "s": "standstill", "n": {"x": [1, {"y": null}]}, "k": true, "e": "q\\\"\u{1}"}),
            json!({"p": 2.5, "s": "moving", "n": {"x": [1, {"y": 0}]}, "k": true, "e": "q\\\"\u{1}"}),
            json!({"p": 2.5, "s": "moving", "n": {"x": [1, {"y": 0}]}, "k": true, "e": "q\\\"\u{1}"}),
        ]);
        let at = |c: u64| {
            vec![
                ("e".into(), 10),
                ("k".into(), 10),
                ("n".into(), c),
                ("p".into(), 20),
                ("s".into(), c),
            ]
        };
        let sorted = |w: &Written| {
            let mut s = since(w);
            s.sort();
            s
        };
        assert_eq!(
            sorted(&w[0]),
            vec![
                ("e".into(), 10),
                ("k".into(), 10),
                ("n".into(), 10),
                ("p".into(), 10),
                ("s".into(), 10)
            ]
        );
        assert_eq!(sorted(&w[1]), at(10));
        assert_eq!(sorted(&w[2]), at(30));
        assert_eq!(sorted(&w[3]), at(30));
        assert!(w.iter().all(|w| w.shape_since == 10));
    }

    #[test]
    fn another_shape_starts_again() {
        let w = chain(&[
            json!({"a": 1, "b": 2}),
            json!({"a": 1, "c": 2}),
            json!({"a": 1, "c": 2, "d": 3}),
            json!({"a": 1, "c": 2, "d": 4}),
            json!({}),
            json!({"a": 1}),
            // Keys serde_json escapes are never taken as the same (a raw `a\"` is not the
            // escaped `a"`), and a value under another key is written again.
            json!({"a\"": 1}),
            json!({"a\\\"": 1}),
            json!({"a\\\"": 1}),
            json!({"b": 1}),
        ]);
        let shapes: Vec<u64> = w.iter().map(|w| w.shape_since).collect();
        assert_eq!(shapes, [10, 20, 30, 30, 50, 60, 70, 80, 80, 100]);
        // A member copied where the keys before it changed keeps its own cycle.
        assert_eq!(since(&w[1])[0], ("a".into(), 10));
        assert_eq!(
            since(&w[3]),
            vec![("a".into(), 10), ("c".into(), 20), ("d".into(), 40)]
        );
    }

    #[test]
    fn values_that_print_alike_are_written_alike() {
        // Bits, not values: -0.0 is written differently from 0.0; a string and a number of
        // the same text differ; None and unit, Some(x) and x differ.
        #[derive(serde::Serialize)]
        struct S {
            f: f64,
            o: Option<Option<i32>>,
            v: Vec<String>,
            t: (u8, char),
            e: E,
        }
        #[derive(serde::Serialize)]
        enum E {
            A,
            B(i64),
            C { x: u64 },
        }
        let s = |f: f64, o, v: &[&str], e| S {
            f,
            o,
            v: v.iter().map(|x| x.to_string()).collect(),
            t: (1, 'x'),
            e,
        };
        let w = chain(&[
            s(0.0, None, &[], E::A),
            s(-0.0, Some(None), &[""], E::B(0)),
            s(-0.0, Some(Some(0)), &["", ""], E::C { x: 0 }),
            s(
                f64::NAN,
                Some(Some(0)),
                &["a,b\u{e9}\u{1F600}\n"],
                E::C { x: 1 },
            ),
            s(f64::INFINITY, Some(Some(0)), &["a", "b"], E::C { x: 1 }),
        ]);
        let changed = |i: usize| -> Vec<String> {
            since(&w[i])
                .into_iter()
                .filter(|(_, c)| *c == 10 * (i as u64 + 1))
                .map(|(k, _)| k)
                .collect()
        };
        assert_eq!(changed(1), ["f", "o", "v", "e"]);
        assert_eq!(changed(2), ["o", "v", "e"]);
        assert_eq!(changed(3), ["f", "v", "e"]);
        // NaN and infinity are both null to serde_json, but not the same value.
        assert_eq!(changed(4), ["f", "v"]);
    }

    /// serde_json writes its `RawValue` raw: a struct of that name is not taken for another
    /// struct of the same fields, nor written as an object at the top.
    #[test]
    fn a_raw_value_is_written_raw() {
        use serde_json::value::RawValue;
        struct Named(&'static str, &'static str);
        impl Serialize for Named {
            fn serialize<S: ser::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                use ser::SerializeStruct;
                let mut st = s.serialize_struct(self.0, 1)?;
                st.serialize_field(RAW_VALUE, self.1)?;
                st.end()
            }
        }
        #[derive(serde::Serialize)]
        struct S {
            n: Named,
            r: Box<RawValue>,
        }
        let raw = |t: &str| RawValue::from_string(t.into()).unwrap();
        let w = chain(&[
            S {
                n: Named("W", "1"),
                r: raw("[1, 2]"),
            },
            S {
                n: Named(RAW_VALUE, "1"),
                r: raw("[1, 2]"),
            },
            S {
                n: Named("W", "1"),
                r: raw("[1,2]"),
            },
        ]);
        assert_eq!(w[1].json, r#"{"n":1,"r":[1, 2]}"#);
        let mut prints = Prints::default();
        assert!(write(1, &raw(r#"{"a":1}"#), None, &mut prints).is_none());
    }

    #[test]
    fn only_objects_with_string_keys_are_written() {
        let mut prints = Prints::default();
        for v in [json!([1, {"a": 2}]), json!(1), json!("a"), json!(null)] {
            assert!(write(1, &v, None, &mut prints).is_none(), "{v}");
        }
        let mut m = std::collections::BTreeMap::new();
        m.insert(1, 2);
        assert!(write(1, &m, None, &mut prints).is_none());
        assert!(prints.bytes.is_empty() && prints.ends.is_empty());
        assert_eq!(write(1, &json!({}), None, &mut prints).unwrap().json, "{}");
    }

    #[test]
    fn a_live_status_is_written_as_serde_json_writes_it() {
        let live = |p: f64, master: Option<&str>, offset: f64| {
            let mut status = motion::AxisStatus {
                set_position: p,
                ..Default::default()
            };
            status.cam.cams[1].slave_offset = offset;
            crate::model::LiveStatus {
                status,
                master: master.map(Into::into),
            }
        };
        let w = chain(&[
            live(12.5, None, 0.0),
            live(12.75, Some("x\"y"), 0.0),
            live(13.0, Some("x\"y"), -0.25),
            live(13.0, Some("x\"y"), -0.25),
        ]);
        let changed = |i: usize| -> Vec<String> {
            since(&w[i])
                .into_iter()
                .filter(|(_, c)| *c == 10 * (i as u64 + 1))
                .map(|(k, _)| k)
                .collect()
        };
        assert_eq!(changed(1), ["set_position", "master"]);
        assert_eq!(changed(2), ["set_position", "cam"]);
        assert!(changed(3).is_empty());
        assert_eq!(w[3].json, w[2].json);
    }
}
