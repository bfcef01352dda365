//! What a scene has that soft3d does not draw yet: one warning a feature, naming how many
//! objects use it and the first few of them, so that nothing is dropped without a word.
//!
//! A key counts when its value is not the default: not absent, `null`, `false`, zero or
//! negative (exporters write `-1` for "no skeleton"), empty, or all zeros (a black colour).
//! Features soft3d does draw (or approximates, such as `autoAnimate`'s first frame) are read
//! by the other modules; those it skips with a reason of their own (spot lights, hidden
//! meshes) are warned about there.

use std::format;
use std::string::String;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{get, label};
use super::Reader;

/// A feature soft3d does not draw: the keys that carry it (in the scene object, `""`, or in
/// each object of an array) and what a viewer sees instead.
struct Feature {
    name: &'static str,
    keys: &'static [(&'static str, &'static str)],
    instead: &'static str,
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
        name: "skeletons",
        keys: &[("", "skeletons"), ("meshes", "skeletonId")],
        instead: "skinned meshes are drawn in their bind pose",
    },
    Feature {
        name: "morph targets",
        keys: &[("", "morphTargetManagers"), ("meshes", "morphTargetManagerId")],
        instead: "meshes are drawn in their base shape",
    },
    Feature {
        name: "animations",
        keys: &[
            ("", "animations"),
            ("meshes", "animations"),
            ("transformNodes", "animations"),
            ("cameras", "animations"),
            ("lights", "animations"),
            ("materials", "animations"),
        ],
        instead: "not played: autoAnimate nodes are drawn at their first frame, the rest as they stand",
    },
    Feature {
        name: "material maps other than the diffuse texture",
        keys: MATERIAL_MAPS,
        instead: "surfaces are drawn with their diffuse colour or texture alone",
    },
    Feature {
        name: "emissive material colours",
        keys: &[("materials", "emissive"), ("materials", "emissiveColor")],
        instead: "surfaces are lit by the scene's lights alone",
    },
    // A material's `ambient` colour is multiplied by this: black (the default) leaves it
    // without effect.
    Feature {
        name: "ambient light",
        keys: &[("", "ambientColor")],
        instead: "surfaces are lit by the scene's lights alone",
    },
    Feature { name: "billboards", keys: &[("meshes", "billboardMode")], instead: "drawn facing their own way" },
    Feature {
        name: "levels of detail",
        keys: &[("meshes", "lodMeshIds")],
        instead: "the full mesh is drawn at every distance",
    },
    Feature { name: "second texture coordinates", keys: &[("meshes", "uvs2")], instead: "unused" },
    Feature {
        name: "per-mesh light lists",
        keys: &[("lights", "excludedMeshesIds"), ("lights", "includedOnlyMeshesIds")],
        instead: "every light lights every mesh",
    },
    Feature { name: "shadows", keys: &[("", "shadowGenerators")], instead: "no shadows are cast" },
    Feature { name: "fog", keys: &[("", "fogMode")], instead: "no fog" },
    Feature { name: "particle systems", keys: &[("", "particleSystems")], instead: "not drawn" },
    Feature { name: "sprites", keys: &[("", "spriteManagers")], instead: "not drawn" },
    Feature { name: "lens flares", keys: &[("", "lensFlareSystems")], instead: "not drawn" },
    Feature {
        name: "post-processes and effect layers",
        keys: &[("", "postProcesses"), ("", "effectLayers")],
        instead: "not applied",
    },
    Feature {
        name: "environment and reflection probes",
        keys: &[("", "environmentTexture"), ("", "reflectionProbes")],
        instead: "no reflections",
    },
    Feature {
        name: "physics",
        keys: &[("", "physicsEnabled"), ("meshes", "physicsImpostor")],
        instead: "nothing moves",
    },
    Feature { name: "actions", keys: &[("", "actions"), ("meshes", "actions")], instead: "not run" },
    Feature { name: "sounds", keys: &[("", "sounds")], instead: "not played" },
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
                    if get(obj, key).is_some_and(set) {
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
            self.warn(format!("{} are not drawn by soft3d yet ({named}): {}", feature.name, feature.instead));
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
