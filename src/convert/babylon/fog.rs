//! The scene's fog: `fogMode` (1 exp, 2 exp2, 3 linear; 0 or none: no fog), `fogColor`,
//! `fogDensity`, `fogStart` and `fogEnd`, with Babylon.js's `Scene` defaults for those missing
//! (colour (0.2, 0.2, 0.3), density 0.1, start 0, end 1000), as its loader reads them.

use std::format;
use std::string::String;
use std::vec::Vec;

use super::fields::{get, label, list, scalar, show, vector, whole};
use super::{ConvertError, Reader};
use crate::convert::scene::FogData;

impl Reader<'_> {
    /// Sets `Scene::fog` from the root's fog fields.
    pub(super) fn read_fog(&mut self) -> Result<(), ConvertError> {
        let cx = self.ctx("scene");
        let e = |m: String| cx.err(m);
        let mode = match get(self.root, "fogMode") {
            None | Some(serde_json::Value::Null) => return Ok(()),
            Some(v) => match whole(v) {
                Some(0) => return Ok(()),
                Some(m @ 1..=3) => m as u8,
                _ => return Err(e(format!("fogMode {} is not 0 (none), 1 (exp), 2 (exp2) or 3 (linear)", show(v)))),
            },
        };
        let fog = FogData {
            mode,
            color: vector(self.root, "fogColor").map_err(e)?.unwrap_or([0.2, 0.2, 0.3]),
            density: scalar(self.root, "fogDensity", 0.1).map_err(e)?,
            start: scalar(self.root, "fogStart", 0.0).map_err(e)?,
            end: scalar(self.root, "fogEnd", 1000.0).map_err(e)?,
        };
        if fog.density < 0.0 {
            return Err(e(format!("fogDensity {} is negative", fog.density)));
        }
        self.scene.fog = Some(fog);
        self.warn_meshes_without_fog()
    }

    /// Warns about meshes that opt out of fog (`applyFog: false`): soft3d fogs every mesh.
    fn warn_meshes_without_fog(&mut self) -> Result<(), ConvertError> {
        let meshes = list(self.root, "meshes").map_err(|m| self.ctx("scene").err(m))?;
        let names: Vec<String> = meshes
            .iter()
            .enumerate()
            .filter(|(_, m)| get(m, "applyFog").and_then(serde_json::Value::as_bool) == Some(false))
            .map(|(i, m)| label(m, "mesh", "meshes", i))
            .collect();
        if !names.is_empty() {
            self.warn(format!(
                "{}: applyFog false is not kept by soft3d yet: fogged like every mesh",
                names.join(", ")
            ));
        }
        Ok(())
    }
}
