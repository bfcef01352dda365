//! Lights: point, directional and hemispheric lights (others are skipped with a warning, as
//! are disabled ones), their position or direction (or the 2013 `data` field) taken to world
//! space through their parent, colour and intensity.
//!
//! The parent's world matrix comes from `node`; the camera is read by `camera`; what the
//! lights' animations need is kept for `view_tracks`.

use std::format;
use std::string::String;

use super::fields::{flag, get, label, list, scalar, show, vector, whole};
use super::transform::transform;
use super::view_tracks::StoredLight;
use super::{ConvertError, Reader};
use crate::convert::scene::{LightData, LightKind};

impl Reader<'_> {
    /// Appends the scene's supported, enabled lights to `Scene::lights`.
    pub(super) fn read_lights(&mut self) -> Result<(), ConvertError> {
        let lights = list(self.root, "lights").map_err(|m| self.ctx("scene").err(m))?;
        for (i, l) in lights.iter().enumerate() {
            let cx = self.ctx(label(l, "light", "lights", i));
            let e = |m: String| cx.err(m);
            let kind = match get(l, "type").and_then(whole) {
                Some(0) => LightKind::Point,
                Some(1) => LightKind::Directional,
                Some(3) => LightKind::Hemispheric,
                _ => {
                    let t = get(l, "type").map_or("missing".into(), show);
                    self.warn(format!("{}: light type {t} is not supported, skipped", cx.what));
                    continue;
                }
            };
            if !flag(l, "isEnabled", true).map_err(e)? {
                self.warn(format!("{}: disabled, skipped", cx.what));
                continue;
            }
            let data = vector(l, "data").map_err(e)?; // 2013 files: position or direction
            let (key, w, default) = match kind {
                LightKind::Point => ("position", 1., [0.; 3]),
                LightKind::Directional => ("direction", 0., [0., -1., 0.]),
                LightKind::Hemispheric => ("direction", 0., [0., 1., 0.]),
            };
            let vector3 = vector(l, key).map_err(e)?.or(data).unwrap_or(default);
            let parent = self.parent(l, &cx.what)?;
            let world = self.parent_world(parent)?;
            let node = self.node_of("lights", i);
            self.view.lights.push(StoredLight { node, kind, world });
            self.scene.lights.push(LightData {
                kind,
                vector: transform(&world, vector3, w),
                diffuse: vector(l, "diffuse").map_err(e)?.unwrap_or([1.; 3]),
                intensity: scalar(l, "intensity", 1.).map_err(e)?,
            });
        }
        Ok(())
    }
}
