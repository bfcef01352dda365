//! What a scene has that soft3d does not draw or play yet: one warning a feature, naming how
//! many objects use it and the first few of them, so that nothing is dropped without a word.
//!
//! A key counts when its value is not the default: not absent, `null`, `false`, zero or
//! negative, empty, or all zeros (a black colour); a `skeletonId` counts from 0 (exporters
//! write `-1` for "no skeleton"). Features soft3d does draw or play (node animations, morph
//! targets, skeletons) are read by the other modules; those it skips with a reason of their own (spot
//! lights, hidden meshes, animated properties and data types it does not play) are warned
//! about there.

use std::format;
use std::string::String;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{get, label};
use super::Reader;

/// A feature soft3d does not draw (or play): the keys that carry it (in the scene object,
/// `""`, or in each object of an array) and what a viewer sees instead.
struct Feature {
    name: &'static str,
    /// What soft3d does not do with it: "drawn" or "played".
    verb: &'static str,
    keys: &'static [(&'static str, &'static str)],
    instead: &'static str,
}

impl Feature {
    /// A feature soft3d does not draw.
    const fn drawn(name: &'static str, keys: &'static [(&'static str, &'static str)], instead: &'static str) -> Self {
        Feature { name, verb: "drawn", keys, instead }
    }
}

const MATERIAL_MAPS: &[(&str, &str)] = &[
    ("materials", "bumpTexture"),
    ("materials", "emissiveTexture"),
    ("materials", "specularTexture"),
    ("materials", "reflectionTexture"),
    ("materials", "refractionTexture"),
    ("materials", "lightmapTexture"),
    ("materials", "opacityTexture"),
    ("materials", "ambientTexture"),
    ("materials", "metallicTexture"),
    ("materials", "reflectivityTexture"),
    ("materials", "microSurfaceTexture"),
];

const FEATURES: &[Feature] = &[
    Feature {
        name: "animations of the scene and of materials",
        verb: "played",
        keys: &[("", "animations"), ("materials", "animations")],
        instead: "what they animate stays as the file sets it",
    },
    Feature::drawn(
        "material maps other than the diffuse texture",
        MATERIAL_MAPS,
        "surfaces are drawn with their diffuse colour or texture alone",
    ),
    Feature::drawn(
        "emissive material colours",
        &[("materials", "emissive"), ("materials", "emissiveColor")],
        "surfaces are lit by the scene's lights alone",
    ),
    // A material's `ambient` colour is multiplied by this: black (the default) leaves it
    // without effect.
    Feature::drawn("ambient light", &[("", "ambientColor")], "surfaces are lit by the scene's lights alone"),
    Feature::drawn("billboards", &[("meshes", "billboardMode")], "drawn facing their own way"),
    Feature::drawn("levels of detail", &[("meshes", "lodMeshIds")], "the full mesh is drawn at every distance"),
    Feature::drawn("second texture coordinates", &[("meshes", "uvs2")], "unused"),
    Feature::drawn(
        "per-mesh light lists",
        &[("lights", "excludedMeshesIds"), ("lights", "includedOnlyMeshesIds")],
        "every light lights every mesh",
    ),
    Feature::drawn("shadows", &[("", "shadowGenerators")], "no shadows are cast"),
    Feature::drawn("particle systems", &[("", "particleSystems")], "not drawn"),
    Feature::drawn("sprites", &[("", "spriteManagers")], "not drawn"),
    Feature::drawn("lens flares", &[("", "lensFlareSystems")], "not drawn"),
    Feature::drawn("post-processes and effect layers", &[("", "postProcesses"), ("", "effectLayers")], "not applied"),
    Feature::drawn(
        "environment and reflection probes",
        &[("", "environmentTexture"), ("", "reflectionProbes")],
        "no reflections",
    ),
    Feature::drawn("physics", &[("", "physicsEnabled"), ("meshes", "physicsImpostor")], "nothing moves"),
    Feature::drawn("actions", &[("", "actions"), ("meshes", "actions")], "not run"),
    Feature::drawn("sounds", &[("", "sounds")], "not played"),
];

/// How many of the first users of a feature a warning names.
const NAMED: usize = 3;

impl Reader<'_> {
    /// Warns once for each feature of [`FEATURES`] the scene uses.
    pub(super) fn warn_unsupported(&mut self) {
        for feature in FEATURES {
            let mut users: Vec<String> = Vec::new();
            for &(array, key) in feature.keys {
                if array.is_empty() {
                    if get(self.root, key).is_some_and(set) {
                        users.push(format!("the scene's {key}"));
                    }
                    continue;
                }
                let objects = get(self.root, array).and_then(Value::as_array).map_or(&[][..], Vec::as_slice);
                for (i, obj) in objects.iter().enumerate() {
                    if get(obj, key).is_some_and(|v| if key == "skeletonId" { skeleton(v) } else { set(v) }) {
                        users.push(format!("{}'s {key}", label(obj, kind(array), array, i)));
                    }
                }
            }
            if users.is_empty() {
                continue;
            }
            let more = users.len().saturating_sub(NAMED);
            let mut named = users[..users.len().min(NAMED)].join(", ");
            if more > 0 {
                named += &format!(" and {more} more");
            }
            let (name, verb, instead) = (feature.name, feature.verb, feature.instead);
            self.warn(format!("{name} are not {verb} by soft3d yet ({named}): {instead}"));
        }
    }
}

/// The object kind of `array`'s entries, for messages.
fn kind(array: &str) -> &'static str {
    match array {
        "meshes" => "mesh",
        "transformNodes" => "transform node",
        "cameras" => "camera",
        "lights" => "light",
        _ => "material",
    }
}

/// Whether a `skeletonId` names a skeleton (0 is the first; exporters write -1 for none).
fn skeleton(v: &Value) -> bool {
    v.as_f64().is_some_and(|x| x >= 0.0) || v.as_str().is_some_and(|s| !s.is_empty())
}

/// Whether `v` is set to something other than a default (see the module documentation).
fn set(v: &Value) -> bool {
    match v {
        Value::Null => false,
        Value::Bool(b) => *b,
        Value::Number(n) => n.as_f64().is_some_and(|x| x > 0.0),
        Value::String(s) => !s.is_empty(),
        Value::Array(a) => !a.is_empty() && !a.iter().all(|x| x.as_f64() == Some(0.0)),
        Value::Object(o) => !o.is_empty(),
    }
}
