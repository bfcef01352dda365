//! The animated camera and lights in the `.s3d` writer: where their slots go in a pose's
//! weights ([`ViewSlots`]), their records in the extended animation section (and the header's
//! flag that says it is extended), their tracks' stored kinds, and the way back
//! ([`read_camera_aim`], [`scene_target`]). The rest of the section is `emit_animation`'s.

use std::vec::Vec;

use super::emit::{EmitError, Out};
use super::scene::{AnimationData, CameraAim, CameraProperty, LightProperty, Scene, TrackTarget};
use crate::animation::{Aim, Animation, TrackTarget as StoredTarget};
use crate::format::layout::*;

/// Where the animated camera's and lights' slots lie in a pose's weights: after the morph
/// weights, the camera's, then each animated light's in light order.
pub(crate) struct ViewSlots {
    /// The camera's first slot, when a track moves it.
    pub(crate) camera: Option<usize>,
    /// Each light a track moves (index into `Scene::lights`, increasing) and its first slot.
    pub(crate) lights: Vec<(u16, usize)>,
    /// The weight count: morph weights and slots.
    pub(crate) end: usize,
}

impl ViewSlots {
    /// The slots of `a`'s camera and lights.
    pub(crate) fn of(a: &AnimationData) -> Self {
        let mut end: usize = a.morphs.iter().map(|m| m.targets.len()).sum();
        let moved = a.tracks.iter().any(|t| matches!(t.target, TrackTarget::Camera { .. }));
        let camera = moved.then(|| {
            end += animated_camera::SLOTS;
            end - animated_camera::SLOTS
        });
        let mut lit: Vec<u16> = a
            .tracks
            .iter()
            .filter_map(|t| match t.target {
                TrackTarget::Light { light, .. } => Some(light),
                _ => None,
            })
            .collect();
        lit.sort_unstable();
        lit.dedup();
        let lights = lit
            .into_iter()
            .map(|l| {
                end += animated_light::SLOTS;
                (l, end - animated_light::SLOTS)
            })
            .collect();
        ViewSlots { camera, lights, end }
    }

    /// Whether the section must be extended.
    pub(crate) fn any(&self) -> bool {
        self.camera.is_some() || !self.lights.is_empty()
    }
}

/// The rest values of the camera aim that are not the camera record's: rotation and distance.
fn aim_values(aim: CameraAim) -> (u16, [f32; 3], f32) {
    match aim {
        CameraAim::Target => (animated_camera::AIM_TARGET, [0.0; 3], 0.0),
        CameraAim::Direction => (animated_camera::AIM_DIRECTION, [0.0; 3], 0.0),
        CameraAim::Rotation { rotation, distance } => (animated_camera::AIM_ROTATION, rotation, distance),
    }
}

/// The aim's numbers, for the writer's finiteness check.
pub(super) fn aim_numbers(aim: CameraAim) -> [f32; 4] {
    let (_, r, d) = aim_values(aim);
    [r[0], r[1], r[2], d]
}

/// Writes the extended part of the section at `section` (the header's flag, the animated
/// camera record and the animated light table) when `slots` has any.
pub(super) fn emit_view(out: &mut Out, section: usize, scene: &Scene, slots: &ViewSlots) -> Result<(), EmitError> {
    if !slots.any() {
        return Ok(());
    }
    out.put_u16(header::FLAGS.start, header::FLAG_EXTENDED_ANIMATION);
    if let Some(first) = slots.camera {
        let c = scene.camera.as_ref().ok_or_else(|| EmitError("animation: camera tracks, but no camera".into()))?;
        let (aim, rotation, distance) = aim_values(scene.animation.camera_aim);
        if distance < 0.0 {
            return Err(EmitError("animation: the camera's aim distance is negative".into()));
        }
        let at = out.reserve(animated_camera::LEN);
        out.put_u32(section + animation::CAMERA.start, at as u32);
        out.put_u16(at + animated_camera::AIM.start, aim);
        out.put_u16(at + animated_camera::FIRST_SLOT.start, slot(first)?);
        out.put_f32s(at + animated_camera::POSITION.start, &c.position);
        out.put_f32s(at + animated_camera::TARGET.start, &c.target);
        out.put_f32s(at + animated_camera::FOV.start, &[c.fov]);
        out.put_f32s(at + animated_camera::ROTATION.start, &rotation);
        out.put_f32s(at + animated_camera::DISTANCE.start, &[distance]);
    }
    let n = u16::try_from(slots.lights.len()).map_err(|_| EmitError("too many animated lights".into()))?;
    let table = out.reserve(animated_light::LEN * slots.lights.len());
    out.put_u16(section + animation::LIGHT_COUNT.start, n);
    out.put_u32(section + animation::LIGHTS.start, table as u32);
    for (k, &(light, first)) in slots.lights.iter().enumerate() {
        let l = scene
            .lights
            .get(usize::from(light))
            .ok_or_else(|| EmitError(std::format!("animation: tracks of light {light}, which does not exist")))?;
        let at = table + k * animated_light::LEN;
        out.put_u16(at + animated_light::LIGHT.start, light);
        out.put_u16(at + animated_light::FIRST_SLOT.start, slot(first)?);
        out.put_f32s(at + animated_light::VECTOR.start, &l.vector);
        out.put_f32s(at + animated_light::DIFFUSE.start, &l.diffuse);
        out.put_f32s(at + animated_light::INTENSITY.start, &[l.intensity]);
    }
    Ok(())
}

/// A first slot as stored.
fn slot(first: usize) -> Result<u16, EmitError> {
    u16::try_from(first).map_err(|_| EmitError("animation: too many weights (morph targets and slots)".into()))
}

/// The stored kind, first component, count and target of a camera or light track (`None` for
/// another track).
pub(super) fn track_fields(target: TrackTarget) -> Option<(u8, u8, u8, u16)> {
    Some(match target {
        TrackTarget::Camera { property, first, count } => {
            let kind = match property {
                CameraProperty::Position => track::KIND_CAMERA_POSITION,
                CameraProperty::Target => track::KIND_CAMERA_TARGET,
                CameraProperty::Rotation => track::KIND_CAMERA_ROTATION,
                CameraProperty::Fov => track::KIND_CAMERA_FOV,
            };
            (kind, first, count, 0)
        }
        TrackTarget::Light { light, property, first, count } => {
            let kind = match property {
                LightProperty::Vector => track::KIND_LIGHT_VECTOR,
                LightProperty::Diffuse => track::KIND_LIGHT_DIFFUSE,
                LightProperty::Intensity => track::KIND_LIGHT_INTENSITY,
            };
            (kind, first, count, light)
        }
        _ => return None,
    })
}

/// The scene's target of a stored camera or light track (`None` for another).
pub(super) fn scene_target(target: StoredTarget, first: u8, count: u8) -> Option<TrackTarget> {
    let camera = |property| Some(TrackTarget::Camera { property, first, count });
    let light = |light, property| Some(TrackTarget::Light { light, property, first, count });
    match target {
        StoredTarget::CameraPosition => camera(CameraProperty::Position),
        StoredTarget::CameraTarget => camera(CameraProperty::Target),
        StoredTarget::CameraRotation => camera(CameraProperty::Rotation),
        StoredTarget::CameraFov => camera(CameraProperty::Fov),
        StoredTarget::LightVector(l) => light(l, LightProperty::Vector),
        StoredTarget::LightDiffuse(l) => light(l, LightProperty::Diffuse),
        StoredTarget::LightIntensity(l) => light(l, LightProperty::Intensity),
        _ => None,
    }
}

/// The camera's aim as stored (the default when the camera does not move).
pub(super) fn read_camera_aim(a: &Animation<'_>) -> CameraAim {
    match a.camera() {
        Some(c) => match c.aim() {
            Aim::Target => CameraAim::Target,
            Aim::Direction => CameraAim::Direction,
            Aim::Rotation => CameraAim::Rotation { rotation: c.rotation().to_array(), distance: c.distance() },
        },
        None => CameraAim::default(),
    }
}
