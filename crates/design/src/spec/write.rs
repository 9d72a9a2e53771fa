//! Writing a [`DesignSpec`] back out as a design file that reads in to the same design.
//!
//! The spec types serialise to the file's form; a few pieces live here:
//!
//! * [`Tagged`] turns the externally tagged form that serde derives for an enum
//!   (`{ polyharmonic = { order = 2, a = 1.0 } }`) into the file's tagged table
//!   (`{ kind = "polyharmonic", order = 2, a = 1.0 }`): the inverse of `deserialize_tagged`.
//!   Every enum chosen by `kind` or `type` goes through it;
//! * small predicates for `skip_serializing_if` that compare floats bit for bit, so that a
//!   skipped key always reads back as the very same value (`-0.0` is written, `0.0` is not);
//! * [`write_design`]: serialisation through `toml_edit`, every float in its shortest
//!   round-trip form (`1e300`, `5e-324`, `-0.0`), and a layout like the example files
//!   (`[curves.rim]` tables, `[[patches]]`, condition lists one entry a line).

use super::locate::key_path;
use super::types::{DesignSpec, SolverSpec, V3};
use crate::{Error, Result};
use serde::ser::{self, Impossible, SerializeMap, Serializer};
use serde::Serialize;
use toml_edit::{Array, DocumentMut, Item, Table, Value};

/// Writes `spec` as the text of a design file: [`super::parse_design`] reads it back to a spec
/// equal to `spec`, every float bit for bit, and writing that spec again gives the same text.
///
/// Refused, with the place of the value: NaN and infinite numbers (a design file cannot hold
/// them) and integers above `i64::MAX` (TOML integers are 64-bit signed).
pub fn write_design(spec: &DesignSpec) -> Result<String> {
    let mut value = spec
        .serialize(toml_edit::ser::ValueSerializer::new())
        .map_err(|e| {
            // The only failure of the spec types: an integer beyond TOML's range. Find it
            // through JSON, which holds every u64, to name its place.
            let place = serde_json::to_value(spec)
                .ok()
                .and_then(|v| out_of_range(&v, ""))
                .unwrap_or_default();
            Error::invalid(format!("cannot be written as TOML: {e}")).at(&place)
        })?;
    normalise(&mut value, "")?;
    let root = match Item::Value(value).into_table() {
        Ok(table) => table,
        Err(_) => return Err(Error::invalid("a design must serialise to a table")),
    };
    let mut doc = DocumentMut::from(root);
    layout(doc.as_table_mut());
    Ok(doc.to_string())
}

// ---------------------------------------------------------------------------------------------
// Tagged tables.

/// Serialises `value`, an enum of struct variants with serde's default (externally tagged)
/// representation, as one flat table whose key `tag` names the variant:
/// `{ circle = { radius = 1.0 } }` becomes `{ type = "circle", radius = 1.0 }`.
pub(crate) struct Tagged<'a, T: ?Sized> {
    pub(crate) tag: &'static str,
    pub(crate) value: &'a T,
}

impl<T: Serialize + ?Sized> Serialize for Tagged<'_, T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        self.value.serialize(TagSerializer {
            tag: self.tag,
            inner: serializer,
        })
    }
}

/// `serialize_with` for an enum chosen by `kind`.
pub(crate) fn serialize_kind<T: Serialize, S: Serializer>(
    value: &T,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    Tagged { tag: "kind", value }.serialize(s)
}

/// `serialize_with` for an enum chosen by `type`.
pub(crate) fn serialize_type<T: Serialize, S: Serializer>(
    value: &T,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    Tagged { tag: "type", value }.serialize(s)
}

/// `serialize_with` for an optional enum chosen by `kind` (with `skip_serializing_if =
/// "Option::is_none"`).
pub(crate) fn serialize_kind_option<T: Serialize, S: Serializer>(
    value: &Option<T>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    match value {
        Some(value) => serialize_kind(value, s),
        None => s.serialize_none(),
    }
}

/// The serializer behind [`Tagged`]: accepts only enum variants and writes each as a map that
/// starts with `tag = "<variant>"`, followed by the variant's fields.
struct TagSerializer<S> {
    tag: &'static str,
    inner: S,
}

/// The fields of a struct variant, written into the tagged map.
pub(crate) struct TaggedFields<M> {
    map: M,
}

impl<M: SerializeMap> ser::SerializeStructVariant for TaggedFields<M> {
    type Ok = M::Ok;
    type Error = M::Error;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> std::result::Result<(), M::Error> {
        self.map.serialize_entry(key, value)
    }
    fn end(self) -> std::result::Result<M::Ok, M::Error> {
        self.map.end()
    }
}

impl<S: Serializer> TagSerializer<S> {
    fn refuse<T>(&self, what: &str) -> std::result::Result<T, S::Error> {
        Err(ser::Error::custom(format!(
            "a table tagged by `{}` must be an enum of struct variants, not {what}",
            self.tag
        )))
    }
}

impl<S: Serializer> Serializer for TagSerializer<S> {
    type Ok = S::Ok;
    type Error = S::Error;
    type SerializeSeq = Impossible<S::Ok, S::Error>;
    type SerializeTuple = Impossible<S::Ok, S::Error>;
    type SerializeTupleStruct = Impossible<S::Ok, S::Error>;
    type SerializeTupleVariant = Impossible<S::Ok, S::Error>;
    type SerializeMap = Impossible<S::Ok, S::Error>;
    type SerializeStruct = Impossible<S::Ok, S::Error>;
    type SerializeStructVariant = TaggedFields<S::SerializeMap>;

    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        len: usize,
    ) -> std::result::Result<Self::SerializeStructVariant, S::Error> {
        let mut map = self.inner.serialize_map(Some(len + 1))?;
        map.serialize_entry(self.tag, variant)?;
        Ok(TaggedFields { map })
    }

    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> std::result::Result<S::Ok, S::Error> {
        let mut map = self.inner.serialize_map(Some(1))?;
        map.serialize_entry(self.tag, variant)?;
        map.end()
    }

    fn serialize_bool(self, _: bool) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a boolean")
    }
    fn serialize_i8(self, _: i8) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_i16(self, _: i16) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_i32(self, _: i32) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_i64(self, _: i64) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_u8(self, _: u8) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_u16(self, _: u16) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_u32(self, _: u32) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_u64(self, _: u64) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an integer")
    }
    fn serialize_f32(self, _: f32) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a number")
    }
    fn serialize_f64(self, _: f64) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a number")
    }
    fn serialize_char(self, _: char) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a character")
    }
    fn serialize_str(self, _: &str) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a string")
    }
    fn serialize_bytes(self, _: &[u8]) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("bytes")
    }
    fn serialize_none(self) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("None")
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("an option")
    }
    fn serialize_unit(self) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("()")
    }
    fn serialize_unit_struct(self, _: &'static str) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a unit struct")
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: &T,
    ) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a newtype struct")
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> std::result::Result<S::Ok, S::Error> {
        self.refuse("a newtype variant")
    }
    fn serialize_seq(self, _: Option<usize>) -> std::result::Result<Self::SerializeSeq, S::Error> {
        self.refuse("a sequence")
    }
    fn serialize_tuple(self, _: usize) -> std::result::Result<Self::SerializeTuple, S::Error> {
        self.refuse("a tuple")
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Self::SerializeTupleStruct, S::Error> {
        self.refuse("a tuple struct")
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Self::SerializeTupleVariant, S::Error> {
        self.refuse("a tuple variant")
    }
    fn serialize_map(self, _: Option<usize>) -> std::result::Result<Self::SerializeMap, S::Error> {
        self.refuse("a map")
    }
    fn serialize_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Self::SerializeStruct, S::Error> {
        self.refuse("a struct")
    }
}

// ---------------------------------------------------------------------------------------------
// Keys left out when they hold the reader's default (floats compared bit for bit).

pub(crate) fn is_false(b: &bool) -> bool {
    !*b
}
pub(crate) fn is_true(b: &bool) -> bool {
    *b
}
pub(crate) fn is_zero_usize(n: &usize) -> bool {
    *n == 0
}
/// `+0.0` only: `-0.0` is written so that it reads back as `-0.0`.
pub(crate) fn is_zero(x: &f64) -> bool {
    x.to_bits() == 0
}
pub(crate) fn is_zero3(v: &V3) -> bool {
    v.iter().all(is_zero)
}
/// The circle's default normal `[0, 0, 1]`.
pub(crate) fn is_z_axis(v: &V3) -> bool {
    is_zero(&v[0]) && is_zero(&v[1]) && v[2].to_bits() == 1f64.to_bits()
}
/// For `#[schemars(skip_serializing_if = "never")]` beside a skipping serde attribute: the
/// schema still lists the key's default, which the writer leaves out of the file.
pub(crate) fn never<T>(_: &T) -> bool {
    false
}
pub(crate) fn is_default_solver(s: &SolverSpec) -> bool {
    *s == SolverSpec::default()
}

/// `solver`: the method's name alone when every other option is at its default, the table
/// otherwise.
pub(crate) fn serialize_solver<S: Serializer>(
    solver: &SolverSpec,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    let method_only = SolverSpec {
        method: solver.method,
        ..SolverSpec::default()
    };
    if *solver == method_only {
        solver.method.serialize(s)
    } else {
        solver.serialize(s)
    }
}

// ---------------------------------------------------------------------------------------------
// Numbers and layout.

/// Refuses non-finite numbers (with their place) and gives every float its shortest round-trip
/// text: `toml_edit` itself writes `1e300` as 301 digits and `5e-324` as 324 decimals.
fn normalise(value: &mut Value, place: &str) -> Result<()> {
    match value {
        Value::Float(f) => {
            let x = *f.value();
            if !x.is_finite() {
                return Err(Error::invalid(format!("must be finite (got {x})")).at(place));
            }
            *value = float_value(x);
        }
        Value::Array(items) => {
            for (i, item) in items.iter_mut().enumerate() {
                normalise(item, &format!("{place}[{i}]"))?;
            }
        }
        Value::InlineTable(table) => {
            for (k, item) in table.iter_mut() {
                let p = if place.is_empty() {
                    key_path(&k)
                } else {
                    format!("{place}.{}", key_path(&k))
                };
                normalise(item, &p)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// The place of the first integer above `i64::MAX` in `value` (the serialised spec).
fn out_of_range(value: &serde_json::Value, place: &str) -> Option<String> {
    match value {
        serde_json::Value::Number(n) if n.is_u64() && n.as_i64().is_none() => {
            Some(place.to_string())
        }
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, item)| out_of_range(item, &format!("{place}[{i}]"))),
        serde_json::Value::Object(map) => map.iter().find_map(|(k, item)| {
            let p = if place.is_empty() {
                key_path(k)
            } else {
                format!("{place}.{}", key_path(k))
            };
            out_of_range(item, &p)
        }),
        _ => None,
    }
}

/// A finite float as a TOML value in ryu's shortest round-trip form (`0.1`, `1e300`, `-0.0`,
/// `2.0`): always a float in TOML, never an integer.
fn float_value(x: f64) -> Value {
    let mut buf = ryu::Buffer::new();
    let text = buf.format_finite(x);
    match text.parse::<Value>() {
        Ok(mut v) if matches!(&v, Value::Float(f) if f.value().to_bits() == x.to_bits()) => {
            v.decor_mut().clear();
            v
        }
        // Not expected; the default form is exact too, only longer.
        _ => Value::from(x),
    }
}

/// Top-level keys written as `[section]` tables.
const SECTIONS: [&str; 8] = [
    "operator", "solver", "output", "dynamic", "optimize", "blend", "spline", "shell",
];
/// Top-level arrays written as `[[name]]` tables.
const ARRAYS_OF_TABLES: [&str; 9] = [
    "patches",
    "parametric",
    "nurbs",
    "nsided",
    "network",
    "patchwork",
    "disk",
    "spine",
    "parameters",
];
/// Sub-tables of sections written as `[section.key]` tables.
const SUBSECTIONS: [(&str, &str); 5] = [
    ("dynamic", "x"),
    ("dynamic", "y"),
    ("dynamic", "z"),
    ("blend", "start"),
    ("blend", "end"),
];

/// Lays the serialised document out like the example files: sections and `[curves.<name>]` as
/// tables, `[[patches]]` and `[[parametric]]` as arrays of tables, everything inside them inline,
/// and lists of tables or arrays (conditions, control points, nets) one entry a line.
fn layout(root: &mut Table) {
    for key in SECTIONS {
        to_table(root, key);
    }
    for (section, key) in SUBSECTIONS {
        if let Some(Item::Table(t)) = root.get_mut(section) {
            to_table(t, key);
        }
    }
    if to_table(root, "curves") {
        if let Some(Item::Table(curves)) = root.get_mut("curves") {
            curves.set_implicit(true);
            let names: Vec<String> = curves.iter().map(|(k, _)| k.to_string()).collect();
            for name in names {
                to_table(curves, &name);
            }
        }
    }
    for key in ARRAYS_OF_TABLES {
        if let Some(item) = root.get_mut(key) {
            let taken = std::mem::take(item);
            *item = match taken.into_array_of_tables() {
                Ok(a) => Item::ArrayOfTables(a),
                Err(other) => other,
            };
        }
    }
    one_entry_a_line(root);
}

/// Turns the inline table at `key` into a standard table; false if there is none.
fn to_table(table: &mut Table, key: &str) -> bool {
    let Some(item) = table.get_mut(key) else {
        return false;
    };
    if !matches!(item, Item::Value(Value::InlineTable(_))) {
        return matches!(item, Item::Table(_));
    }
    let taken = std::mem::take(item);
    *item = match taken.into_table() {
        Ok(t) => Item::Table(t),
        Err(other) => other,
    };
    true
}

/// In every standard table, arrays of two or more tables or arrays get one entry a line.
fn one_entry_a_line(table: &mut Table) {
    for (_, item) in table.iter_mut() {
        match item {
            Item::Table(t) => one_entry_a_line(t),
            Item::ArrayOfTables(a) => a.iter_mut().for_each(one_entry_a_line),
            Item::Value(Value::Array(a)) => spread(a),
            _ => {}
        }
    }
}

fn spread(a: &mut Array) {
    let compound = |v: &Value| matches!(v, Value::Array(_) | Value::InlineTable(_));
    if a.len() < 2 || !a.iter().all(compound) {
        return;
    }
    for v in a.iter_mut() {
        v.decor_mut().set_prefix("\n  ");
        v.decor_mut().set_suffix("");
    }
    a.set_trailing_comma(true);
    a.set_trailing("\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{OperatorSpec, TransformStep};

    #[test]
    fn tagged_flattens_the_variant_into_the_tag() {
        let op = OperatorSpec::Polyharmonic { order: 3, a: 0.5 };
        let value = serde_json::to_value(Tagged {
            tag: "kind",
            value: &op,
        })
        .unwrap();
        assert_eq!(
            value,
            serde_json::json!({ "kind": "polyharmonic", "order": 3, "a": 0.5 })
        );
        // Only enums of struct variants have a tagged form.
        let step = TransformStep::Translate([0.0; 3]);
        let e = serde_json::to_value(Tagged {
            tag: "kind",
            value: &step,
        });
        assert!(e.is_err());
    }

    #[test]
    fn the_schema_keeps_the_defaults_the_writer_leaves_out() {
        let schema: serde_json::Value = serde_json::from_str(&crate::spec::json_schema()).unwrap();
        let defs = &schema["definitions"];
        let default = |def: &str, key: &str| defs[def]["properties"][key]["default"].clone();
        assert_eq!(default("SolverSpec", "modes"), 12);
        assert_eq!(default("SolverSpec", "remainder"), true);
        assert_eq!(default("SolverSpec", "samples"), 0);
        assert_eq!(default("ConditionSpec", "derivative"), 0);
        assert_eq!(default("BlendSpec", "periodic"), false);
        assert_eq!(default("SplineSpec", "exact"), false);
        assert_eq!(default("OptimizeSpec", "spontaneous_curvature"), 0.0);
        assert_eq!(default("DynamicSpec", "check_positivity"), false);
        let circle = crate::spec::schema::curve_variants(&schema)
            .into_iter()
            .find(|v| v["properties"]["type"]["enum"][0] == "circle")
            .unwrap();
        assert_eq!(
            circle["properties"]["normal"]["default"],
            serde_json::json!([0.0, 0.0, 1.0])
        );
    }
}
