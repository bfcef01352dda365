//! One Babylon.js animation as a track: what its `property` sets, its `dataType`, rate and loop
//! behaviour, and its keys (values, packed or explicit tangents, steps), read and checked (see
//! `animation`'s module documentation for the rules); numbering targets and grouping tracks
//! is `animation`'s job.

use std::format;
use std::string::String;
use std::vec;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{count, finite, get, list, number, scalar, show, text, Res};
use crate::convert::scene::{KeyData, Loop, NodeProperty};

/// Frames a second of a track without `framePerSecond`.
pub(super) const DEFAULT_FPS: f32 = 30.0;

/// What an animation's `property` sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Property {
    /// Components `first..first + count` of a node property.
    Node { property: NodeProperty, first: u8, count: u8 },
    /// A morph target's influence.
    Influence,
    /// Components `first..first + count` of a camera's or light's property, by its Babylon.js
    /// name (one of [`VIEW_PROPERTIES`]); whether that camera or light plays it is
    /// `view_tracks`' to say.
    View { name: &'static str, first: u8, count: u8 },
}

/// Whose animation is read: a mesh's, transform node's or morph target's, or a camera's or
/// light's (their properties have other names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Owner {
    /// A mesh, transform node or morph target.
    Node,
    /// A camera or light.
    View,
}

/// The camera and light properties soft3d may play, with their number of components (1: a
/// float, 3: a vector3, or for `diffuse` a color3).
pub(super) const VIEW_PROPERTIES: [(&str, u8); 8] = [
    ("position", 3),
    ("target", 3),
    ("lockedTarget", 3),
    ("rotation", 3),
    ("fov", 1),
    ("direction", 3),
    ("diffuse", 3),
    ("intensity", 1),
];

impl Property {
    /// How many numbers a key holds.
    pub(super) fn count(self) -> usize {
        match self {
            Property::Node { count, .. } | Property::View { count, .. } => usize::from(count),
            Property::Influence => 1,
        }
    }

    /// The Babylon.js `dataType` of such a track: 0 float, 1 vector3, 2 quaternion, 4 color3.
    pub(super) fn data_type(self) -> u64 {
        match (self, self.count()) {
            (Property::View { name: "diffuse", .. }, 3) => 4,
            (_, 3) => 1,
            (_, 4) => 2,
            _ => 0,
        }
    }
}

/// A track's timing and keys.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Curve {
    pub(super) fps: f32,
    pub(super) looping: Loop,
    pub(super) keys: Vec<KeyData>,
}

/// An animation read: its property and curve, or why soft3d skips it.
pub(super) type Parsed = Result<(Property, Curve), String>;

/// A key as read: its tangents not yet paired.
struct RawKey {
    frame: f32,
    values: Vec<f32>,
    tangents: [Option<Vec<f32>>; 2],
    step: bool,
}

/// An animation's `loopBehavior` (see the module documentation), a note for a value it plays
/// as another.
pub(super) fn loop_behavior(anim: &Value, notes: &mut Vec<String>) -> Res<Loop> {
    Ok(match count(anim, "loopBehavior", Some(1))? {
        0 => Loop::Relative,
        1 => Loop::Cycle,
        2 => Loop::Constant,
        n => {
            notes.push(format!("loopBehavior {n} is played as 1 (cycle)"));
            Loop::Cycle
        }
    })
}

/// What a camera's or light's animation `property` sets; `None` for what soft3d does not play
/// (see [`VIEW_PROPERTIES`]; components x, y, z, or r, g, b of `diffuse`).
pub(super) fn view_property(name: &str) -> Option<Property> {
    let (base, component) = name.split_once('.').map_or((name, None), |(b, c)| (b, Some(c)));
    let &(name, size) = VIEW_PROPERTIES.iter().find(|(n, _)| *n == base)?;
    let Some(c) = component else {
        return Some(Property::View { name, first: 0, count: size });
    };
    let names = if name == "diffuse" { ["r", "g", "b"] } else { ["x", "y", "z"] };
    let first = names.iter().position(|&n| n == c).filter(|_| size == 3)?;
    Some(Property::View { name, first: first as u8, count: 1 })
}

/// What a node's or morph target's animation `property` sets; `None` for what soft3d does not
/// play.
pub(super) fn property(name: &str) -> Option<Property> {
    if name == "influence" {
        return Some(Property::Influence);
    }
    let (base, component) = name.split_once('.').map_or((name, None), |(b, c)| (b, Some(c)));
    let (property, size) = match base {
        "position" => (NodeProperty::Position, 3),
        "rotation" => (NodeProperty::Rotation, 3),
        "scaling" => (NodeProperty::Scaling, 3),
        "rotationQuaternion" => (NodeProperty::RotationQuaternion, 4),
        _ => return None,
    };
    match component {
        None => Some(Property::Node { property, first: 0, count: size }),
        // One component of a quaternion is not a rotation on its own: not played.
        Some(_) if property == NodeProperty::RotationQuaternion => None,
        Some(c) => {
            let first = ["x", "y", "z", "w"].iter().position(|&n| n == c).filter(|&k| k < usize::from(size))?;
            Some(Property::Node { property, first: first as u8, count: 1 })
        }
    }
}

/// The name of a Babylon.js `dataType`, for messages.
fn type_name(data_type: u64) -> &'static str {
    match data_type {
        0 => "float",
        1 => "vector3",
        2 => "quaternion",
        3 => "matrix",
        4 => "color3",
        5 => "vector2",
        6 => "size",
        7 => "color4",
        _ => "unknown",
    }
}

/// Reads an animation object of `owner`: `Err` for a field of the wrong type (the message
/// starts with the field), `Ok(Err(reason))` when soft3d skips it, and `notes` for what it
/// changes.
pub(super) fn parse_animation(anim: &Value, owner: Owner, notes: &mut Vec<String>) -> Res<Parsed> {
    let Some(name) = text(anim, "property")? else {
        return Ok(Err("no property".into()));
    };
    let found = match owner {
        Owner::Node => property(&name),
        Owner::View => view_property(&name),
    };
    let Some(property) = found else {
        return Ok(Err(format!("property {name:?} is not played by soft3d")));
    };
    let data_type = count(anim, "dataType", Some(property.data_type()))?;
    if data_type != property.data_type() {
        let kind = type_name(data_type);
        return Ok(Err(format!("dataType {data_type} ({kind}) for property {name:?} is not played by soft3d")));
    }
    let fps = scalar(anim, "framePerSecond", DEFAULT_FPS)?;
    if fps <= 0.0 {
        return Ok(Err(format!("framePerSecond {fps} is not positive")));
    }
    let looping = loop_behavior(anim, notes)?;
    let quaternion = matches!(property, Property::Node { count: 4, .. });
    let keys = keys(anim, property.count(), quaternion, notes)?;
    if keys.is_empty() {
        return Ok(Err("no keys".into()));
    }
    Ok(Ok((property, Curve { fps, looping, keys })))
}

/// The keys of an animation, by frame, their tangents paired (see the module documentation).
fn keys(anim: &Value, count: usize, quaternion: bool, notes: &mut Vec<String>) -> Res<Vec<KeyData>> {
    let raw = list(anim, "keys")?.iter().enumerate().map(|(i, key)| {
        if !key.is_object() {
            return Err(format!("keys[{i}]: expected an object, found {}", show(key)));
        }
        raw_key(key, count, quaternion).map_err(|m| format!("keys[{i}].{m}"))
    });
    let mut raw = raw.collect::<Res<Vec<RawKey>>>()?;
    if raw.windows(2).any(|w| w[1].frame < w[0].frame) {
        raw.sort_by(|a, b| a.frame.total_cmp(&b.frame));
        notes.push("keys are not in frame order: sorted by frame".into());
    }
    // A key with one tangent keeps an empty other: the spans it starts or ends without a pair
    // are linear, as Babylon.js draws them.
    let keys = raw.into_iter().map(|key| {
        let [tin, tout] = key.tangents;
        let tangents = match (tin, tout) {
            (None, None) => None,
            (a, b) => Some((a.unwrap_or_default(), b.unwrap_or_default())),
        };
        KeyData { frame: key.frame, values: key.values, tangents, step: key.step }
    });
    Ok(keys.collect())
}

/// One key (see the module documentation); messages start with the field.
fn raw_key(key: &Value, count: usize, quaternion: bool) -> Res<RawKey> {
    let frame = number(key, "frame")?.ok_or_else(|| String::from("frame: missing"))?;
    let items = match get(key, "values") {
        Some(Value::Array(a)) => a.as_slice(),
        Some(v) if count == 1 && v.is_number() => core::slice::from_ref(v),
        Some(v) => return Err(format!("values: expected an array, found {}", show(v))),
        None => return Err("values: missing".into()),
    };
    if items.len() < count {
        return Err(format!("values: expected {count} numbers, found {}", items.len()));
    }
    let (value, rest) = items.split_at(count);
    let values = numbers(value, 0)?;
    let [mut tin, mut tout, mut interpolation] =
        if quaternion { packed_quaternion(rest)? } else { packed(rest, count)? };
    for (slot, name) in [(&mut tin, "inTangent"), (&mut tout, "outTangent")] {
        if let Some(v) = get(key, name) {
            *slot = Some(tangent(v, count).map_err(|m| format!("{name}{m}"))?);
        }
    }
    if let Some(v) = get(key, "interpolation") {
        let x = finite(v).ok_or_else(|| format!("interpolation: expected a number, found {}", show(v)))?;
        interpolation = Some(vec![x]);
    }
    let step = interpolation.is_some_and(|i| i.first() == Some(&1.0));
    Ok(RawKey { frame, values, tangents: [tin, tout], step })
}

/// `items` as finite numbers (`start` is the index of the first in `values`, for messages).
fn numbers(items: &[Value], start: usize) -> Res<Vec<f32>> {
    let bad = |i: usize, x: &Value| format!("values[{}]: expected a finite number, found {}", start + i, show(x));
    items.iter().enumerate().map(|(i, x)| finite(x).ok_or_else(|| bad(i, x))).collect()
}

/// The packed tangents and interpolation after a float's or vector's value: in, out (each
/// `null`, a number or an array of `count`) and the interpolation (as a one-number vector).
fn packed(rest: &[Value], count: usize) -> Res<[Option<Vec<f32>>; 3]> {
    let slot = |k: usize| -> Res<Option<Vec<f32>>> {
        let at = count + k;
        match rest.get(k) {
            None | Some(Value::Null) => Ok(None),
            Some(v) if k == 2 => numbers(core::slice::from_ref(v), at).map(Some),
            Some(v) => tangent(v, count).map(Some).map_err(|m| format!("values[{at}]{m}")),
        }
    };
    Ok([slot(0)?, slot(1)?, slot(2)?])
}

/// The packed tangents and interpolation after a quaternion: 4 numbers in (all zero: none),
/// 4 out, then the interpolation.
fn packed_quaternion(rest: &[Value]) -> Res<[Option<Vec<f32>>; 3]> {
    let quad = |k: usize| -> Res<Option<Vec<f32>>> {
        let Some(items) = rest.get(4 * k..4 * k + 4) else {
            return Ok(None);
        };
        let q = numbers(items, 4 + 4 * k)?;
        Ok(q.iter().any(|&x| x != 0.0).then_some(q))
    };
    let interpolation = match rest.get(8) {
        None | Some(Value::Null) => None,
        Some(v) => Some(numbers(core::slice::from_ref(v), 12)?),
    };
    Ok([quad(0)?, quad(1)?, interpolation])
}

/// A tangent: a number (for one-number values) or an array of `count` finite numbers; the
/// message starts after the field's name.
fn tangent(v: &Value, count: usize) -> Res<Vec<f32>> {
    let expected = || format!(": expected {count} finite numbers, found {}", show(v));
    match v {
        Value::Array(a) if a.len() == count => a.iter().map(finite).collect::<Option<_>>().ok_or_else(expected),
        Value::Number(_) if count == 1 => finite(v).map(|x| vec![x]).ok_or_else(expected),
        _ => Err(expected()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn parse(anim: &Value) -> (Res<Parsed>, Vec<String>) {
        let mut notes = Vec::new();
        (parse_animation(anim, Owner::Node, &mut notes), notes)
    }

    #[test]
    fn properties_and_components() {
        let node = |property, first, count| Some(Property::Node { property, first, count });
        assert_eq!(property("position"), node(NodeProperty::Position, 0, 3));
        assert_eq!(property("scaling.z"), node(NodeProperty::Scaling, 2, 1));
        // One component of a quaternion is no rotation on its own (the format stores whole ones).
        assert_eq!(property("rotationQuaternion.w"), None);
        assert_eq!(property("rotationQuaternion"), node(NodeProperty::RotationQuaternion, 0, 4));
        assert_eq!(property("rotation.w"), None);
        assert_eq!(property("_matrix"), None);
        assert_eq!(property("position.x.y"), None);
        assert_eq!(property("influence"), Some(Property::Influence));
    }

    #[test]
    fn camera_and_light_properties() {
        let view = |name, first, count| Some(Property::View { name, first, count });
        assert_eq!(view_property("fov"), view("fov", 0, 1));
        assert_eq!(view_property("position.z"), view("position", 2, 1));
        assert_eq!(view_property("diffuse.g"), view("diffuse", 1, 1));
        assert_eq!(view_property("diffuse.y"), None);
        assert_eq!(view_property("fov.x"), None);
        assert_eq!(view_property("upVector"), None);
        assert_eq!(view_property("specular"), None);
        assert_eq!(view("diffuse", 0, 3).map(Property::data_type), Some(4));
        assert_eq!(view("direction", 0, 3).map(Property::data_type), Some(1));
        assert_eq!(view("intensity", 0, 1).map(Property::data_type), Some(0));
    }

    #[test]
    fn packed_tangents_and_steps_are_read() {
        let anim = json!({"property": "position", "dataType": 1, "keys": [
            {"frame": 0, "values": [1, 2, 3, null, [4, 5, 6]]},
            {"frame": 10, "values": [7, 8, 9, [1, 1, 1], null, 1]},
        ]});
        let (Ok(Ok((_, curve))), notes) = parse(&anim) else { panic!() };
        assert_eq!(curve.fps, DEFAULT_FPS);
        assert_eq!(curve.looping, Loop::Cycle);
        // A missing tangent stays missing (empty): Babylon.js interpolates that span linearly.
        assert_eq!(curve.keys[0].tangents, Some((vec![], vec![4., 5., 6.])));
        assert_eq!(curve.keys[1].tangents, Some((vec![1.; 3], vec![])));
        assert!(curve.keys[1].step && !curve.keys[0].step);
        assert!(notes.is_empty(), "{notes:?}");

        let quat = json!({"property": "rotationQuaternion", "dataType": 2, "keys": [
            {"frame": 0, "values": [0, 0, 0, 1, 0, 0, 0, 0, 0.5, 0, 0, 0, 1]},
            {"frame": 5, "values": [0, 0, 0, 1], "inTangent": [1, 0, 0, 0], "outTangent": [0, 1, 0, 0]},
        ]});
        let (Ok(Ok((_, curve))), notes) = parse(&quat) else { panic!() };
        assert_eq!(curve.keys[0].tangents, Some((vec![], vec![0.5, 0., 0., 0.])));
        assert!(curve.keys[0].step);
        assert_eq!(curve.keys[1].tangents, Some((vec![1., 0., 0., 0.], vec![0., 1., 0., 0.])));
        assert!(notes.is_empty(), "{notes:?}");
    }

    #[test]
    fn floats_may_be_bare_numbers_and_keys_are_sorted() {
        let anim = json!({"property": "position.y", "framePerSecond": 24, "loopBehavior": 2, "keys": [
            {"frame": 5, "values": 2.5}, {"frame": 1, "values": [1, 0.5, 0.25, 0]},
        ]});
        let (Ok(Ok((property, curve))), notes) = parse(&anim) else { panic!() };
        assert_eq!(property, Property::Node { property: NodeProperty::Position, first: 1, count: 1 });
        assert_eq!((curve.fps, curve.looping), (24., Loop::Constant));
        let frames: Vec<f32> = curve.keys.iter().map(|k| k.frame).collect();
        assert_eq!(frames, [1., 5.]);
        assert_eq!(curve.keys[0].tangents, Some((vec![0.5], vec![0.25])));
        assert_eq!(curve.keys[1].values, [2.5]);
        assert_eq!(notes, ["keys are not in frame order: sorted by frame"]);
    }

    #[test]
    fn skipped_and_malformed_animations() {
        let skip = |anim: Value| match parse(&anim).0 {
            Ok(Err(reason)) => reason,
            other => panic!("{other:?}"),
        };
        assert!(skip(json!({"property": "_matrix", "dataType": 3, "keys": []})).contains("\"_matrix\""));
        assert!(skip(json!({"property": "rotation", "dataType": 2, "keys": []})).contains("dataType 2 (quaternion)"));
        assert_eq!(skip(json!({"property": "scaling", "keys": []})), "no keys");
        assert!(skip(json!({"property": "scaling", "framePerSecond": 0, "keys": []})).contains("not positive"));
        let error = |anim: Value| parse(&anim).0.err().unwrap_or_default();
        let frame = error(json!({"property": "position", "keys": [{"frame": 0, "values": [0, 0, 0]},
            {"frame": "2", "values": [0, 0, 0]}]}));
        assert_eq!(frame, "keys[1].frame: expected a finite number, found \"2\"");
        let short = error(json!({"property": "position", "keys": [{"frame": 0, "values": [0, 0]}]}));
        assert_eq!(short, "keys[0].values: expected 3 numbers, found 2");
        let tangent = error(json!({"property": "scaling", "keys": [{"frame": 0, "values": [1, 1, 1, 5]}]}));
        assert_eq!(tangent, "keys[0].values[3]: expected 3 finite numbers, found 5");
    }
}
