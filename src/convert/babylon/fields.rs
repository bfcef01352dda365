//! The JSON field readers of the `.babylon` reader: typed access to one field of a JSON object
//! (`floats`, `vector`, `flag`, `text`...), each returning the field's problem as a message
//! naming the field, and [`Ctx`], which turns such a message into a [`ConvertError`] naming the
//! object at fault.
//!
//! This module knows nothing of Babylon.js semantics (meshes, materials, transforms): it only
//! reads and checks JSON values.

use std::borrow::ToOwned;
use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use serde_json::Value;

use super::ConvertError;

pub(super) type Res<T> = Result<T, String>;

/// The object (`mesh "Suzanne"`) that field errors are reported against.
pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
    pub(super) what: String,
}

impl Ctx<'_> {
    pub(super) fn err(&self, message: impl Into<String>) -> ConvertError {
        ConvertError::Invalid { file: self.file.to_owned(), context: self.what.clone(), message: message.into() }
    }
}

/// `obj[key]`, with a missing key and `null` alike.
pub(super) fn get<'v>(obj: &'v Value, key: &str) -> Option<&'v Value> {
    obj.get(key).filter(|v| !v.is_null())
}

/// A short description of a JSON value for messages.
pub(super) fn show(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => format!("{:?}", s.chars().take(24).collect::<String>()),
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}

pub(super) fn finite(v: &Value) -> Option<f32> {
    v.as_f64().map(|x| x as f32).filter(|x| x.is_finite())
}

pub(super) fn whole(v: &Value) -> Option<u64> {
    v.as_u64().or_else(|| {
        let x = v.as_f64()?;
        (x >= 0.0 && x.fract() == 0.0 && x < 1.8e19).then_some(x as u64)
    })
}

/// The elements of an array field, or `&[]` when it is missing or null.
pub(super) fn list<'v>(obj: &'v Value, key: &str) -> Res<&'v [Value]> {
    match get(obj, key) {
        None => Ok(&[]),
        Some(Value::Array(a)) => Ok(a),
        Some(v) => Err(format!("{key}: expected an array, found {}", show(v))),
    }
}

/// Maps the elements of an array field with `f`, naming the first bad element.
pub(super) fn array<T>(obj: &Value, key: &str, what: &str, f: impl Fn(&Value) -> Option<T>) -> Res<Option<Vec<T>>> {
    let Some(v) = get(obj, key) else {
        return Ok(None);
    };
    let a = v.as_array().ok_or_else(|| format!("{key}: expected an array, found {}", show(v)))?;
    let bad = |(i, x): (usize, &Value)| format!("{key}[{i}]: expected {what}, found {}", show(x));
    a.iter().enumerate().map(|(i, x)| f(x).ok_or_else(|| bad((i, x)))).collect::<Res<_>>().map(Some)
}

pub(super) fn floats(obj: &Value, key: &str) -> Res<Option<Vec<f32>>> {
    array(obj, key, "a finite number", finite)
}

pub(super) fn uints(obj: &Value, key: &str) -> Res<Option<Vec<u32>>> {
    array(obj, key, "an index below 2^32", |x| whole(x).and_then(|n| u32::try_from(n).ok()))
}

/// A fixed-size numeric field (`position`, `diffuse`...); extra elements are ignored.
pub(super) fn vector<const N: usize>(obj: &Value, key: &str) -> Res<Option<[f32; N]>> {
    let Some(v) = floats(obj, key)? else {
        return Ok(None);
    };
    let short = || format!("{key}: expected {N} numbers, found {}", v.len());
    v.get(..N).and_then(|s| <[f32; N]>::try_from(s).ok()).map(Some).ok_or_else(short)
}

pub(super) fn scalar(obj: &Value, key: &str, default: f32) -> Res<f32> {
    get(obj, key)
        .map_or(Ok(default), |v| finite(v).ok_or_else(|| format!("{key}: expected a finite number, found {}", show(v))))
}

/// An optional finite number.
pub(super) fn number(obj: &Value, key: &str) -> Res<Option<f32>> {
    get(obj, key)
        .map(|v| finite(v).ok_or_else(|| format!("{key}: expected a finite number, found {}", show(v))))
        .transpose()
}

/// The numbers an animation key's `values` starts with: a number alone, or the leading numbers
/// of an array (Babylon.js packs tangents and the interpolation after the value), each finite.
pub(super) fn leading_floats(obj: &Value, key: &str) -> Res<Vec<f32>> {
    let bad = |what: String, v: &Value| format!("{what}: expected a finite number, found {}", show(v));
    match get(obj, key) {
        None => Ok(Vec::new()),
        Some(Value::Array(a)) => a
            .iter()
            .take_while(|x| x.is_number())
            .enumerate()
            .map(|(i, x)| finite(x).ok_or_else(|| bad(format!("{key}[{i}]"), x)))
            .collect(),
        Some(v) => finite(v).map(|x| std::vec![x]).ok_or_else(|| bad(key.to_owned(), v)),
    }
}

pub(super) fn count(obj: &Value, key: &str, default: Option<u64>) -> Res<u64> {
    match get(obj, key) {
        None => default.ok_or_else(|| format!("{key}: missing")),
        Some(v) => whole(v).ok_or_else(|| format!("{key}: expected a whole number >= 0, found {}", show(v))),
    }
}

/// A boolean field; old exporters write `1.0`/`0.0`.
pub(super) fn flag(obj: &Value, key: &str, default: bool) -> Res<bool> {
    match get(obj, key) {
        None => Ok(default),
        Some(Value::Bool(b)) => Ok(*b),
        Some(v) => finite(v).map(|x| x != 0.0).ok_or_else(|| format!("{key}: expected a boolean, found {}", show(v))),
    }
}

/// A string field; ids may be written as numbers.
pub(super) fn text(obj: &Value, key: &str) -> Res<Option<String>> {
    match get(obj, key) {
        None => Ok(None),
        Some(Value::String(s)) => Ok(Some(s.clone())),
        Some(Value::Number(n)) => Ok(Some(n.to_string())),
        Some(v) => Err(format!("{key}: expected a string, found {}", show(v))),
    }
}

/// `kind "name"` for messages, from `name`, else `id`, else the array position.
pub(super) fn label(obj: &Value, kind: &str, array: &str, i: usize) -> String {
    match text(obj, "name").ok().flatten().or_else(|| text(obj, "id").ok().flatten()) {
        Some(name) => format!("{kind} {name:?}"),
        None => format!("{array}[{i}]"),
    }
}
