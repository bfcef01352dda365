//! The camera: the active one (`activeCameraID`, or the legacy `activeCamera`, else the first),
//! its target (`target`, else the world position of `lockedTargetId`, else the origin for an
//! `ArcRotateCamera`, else `position` + the rotated +z axis), field of view and clip planes,
//! taken to world space through its parent.
//!
//! World matrices come from `node`; lights are read by `light`; what the camera's animations
//! need is kept for `view_tracks`.

use std::format;
use std::string::String;

use super::fields::{label, list, scalar, show, text, vector};
use super::transform::{transform, Trs};
use super::view_tracks::{rotation_towards, StoredCamera};
use super::{ConvertError, Reader};
use crate::convert::scene::CameraData;

impl Reader<'_> {
    /// Sets `Scene::camera` from the active camera, if the scene has any.
    pub(super) fn read_camera(&mut self) -> Result<(), ConvertError> {
        let scx = self.ctx("scene");
        let cameras = list(self.root, "cameras").map_err(|m| scx.err(m))?;
        let active = match text(self.root, "activeCameraID").map_err(|m| scx.err(m))? {
            Some(id) => Some(id),
            None => text(self.root, "activeCamera").map_err(|m| scx.err(m))?,
        };
        let found = active
            .as_deref()
            .and_then(|id| cameras.iter().position(|c| text(c, "id").ok().flatten().as_deref() == Some(id)));
        if let (Some(id), None, false) = (&active, found, cameras.is_empty()) {
            self.warn(format!("active camera {id:?} not found, the first camera used"));
        }
        let Some(i) = found.or((!cameras.is_empty()).then_some(0)) else {
            return Ok(());
        };
        let c = &cameras[i];
        let cx = self.ctx(label(c, "camera", "cameras", i));
        let e = |m: String| cx.err(m);
        if !c.is_object() {
            return Err(cx.err(format!("expected an object, found {}", show(c))));
        }
        let position = vector(c, "position").map_err(e)?.unwrap_or([0.; 3]);
        let file_target = vector(c, "target").map_err(e)?;
        let orbits = text(c, "type").map_err(e)?.as_deref() == Some("ArcRotateCamera");
        let mut locked = false;
        let target = match (file_target, text(c, "lockedTargetId").map_err(e)?) {
            (Some(t), _) => t,
            (None, Some(id)) if self.ids.contains_key(&id) => {
                locked = true;
                let w = self.world(self.ids[&id])?;
                [w[12], w[13], w[14]]
            }
            _ if orbits => [0.; 3],
            _ => {
                let forward = transform(&Trs::read(c, Trs::IDENTITY).map_err(e)?.rotation_matrix(), [0., 0., 1.], 0.);
                core::array::from_fn(|k| position[k] + forward[k])
            }
        };
        // The rotation a `FreeCamera` turns by: its `target`'s (`setTarget`), else its own.
        let rotation = match file_target {
            Some(t) => rotation_towards(core::array::from_fn(|k| t[k] - position[k])),
            None => vector(c, "rotation").map_err(e)?.unwrap_or([0.; 3]),
        };
        let parent = self.parent(c, &cx.what)?;
        let world = self.parent_world(parent)?;
        let (position, target) = (transform(&world, position, 1.), transform(&world, target, 1.));
        let distance = libm::sqrtf((0..3).map(|k| (target[k] - position[k]) * (target[k] - position[k])).sum());
        let quaternion = vector::<4>(c, "rotationQuaternion").map_err(e)?.is_some();
        let node = self.node_of("cameras", i);
        let stored = StoredCamera { node, world, orbits, locked, quaternion, rotation, distance };
        if position == target {
            // Nowhere to look: Babylon.js would draw nothing either.
            self.warn(format!(
                "{}: its position is its target, so it was ignored (the fitted camera is used)",
                cx.what
            ));
            self.view.ignored_camera = stored.node;
            return Ok(());
        }
        let near = scalar(c, "minZ", 1.).map_err(e)?;
        let mut far = scalar(c, "maxZ", 10000.).map_err(e)?;
        if far == 0.0 {
            // Babylon.js's infinite far plane: ours reaches just past the farthest vertex.
            far = self.scene_reach(position).max(near * 2.0);
            self.warn(format!(
                "{}: maxZ 0 (an infinite far plane) drawn with the far plane at {far}, past the whole scene",
                cx.what
            ));
        }
        let fov = scalar(c, "fov", 0.8).map_err(e)?;
        self.scene.camera = Some(CameraData { position, target, fov, near, far });
        self.view.camera = Some(stored);
        Ok(())
    }

    /// The distance from `eye` to the scene's farthest vertex (meshes and instances in world
    /// space), with 1% to spare.
    fn scene_reach(&self, eye: [f32; 3]) -> f32 {
        let placed = self.scene.meshes.iter().map(|m| (m, &m.world));
        let instances =
            self.scene.instances.iter().filter_map(|i| Some((self.scene.meshes.get(usize::from(i.mesh))?, &i.world)));
        let farthest = placed
            .chain(instances)
            .flat_map(|(m, world)| m.positions.iter().map(move |&p| transform(world, p, 1.)))
            .map(|p| (0..3).map(|k| (p[k] - eye[k]) * (p[k] - eye[k])).sum::<f32>())
            .fold(0.0f32, f32::max);
        libm::sqrtf(farthest) * 1.01
    }
}
