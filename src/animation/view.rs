//! The camera and lights of a pose: their tracks' values kept in the pose's weights after the
//! morph weights (each animated camera or light record names its slots), set to rest, moved
//! by tracks, the camera's target aimed ([`Aim`]), and read back as the model's camera and
//! lights at that frame ([`Pose::camera`], [`Pose::light`]).

use super::{euler_matrix, Pose};
use crate::format::layout::{animated_camera as cam, animated_light as lit};
use crate::format::{Aim, Animation, Light, SceneCamera, Track, TrackTarget};
use crate::math::{Vec3, Vec4};

/// `v` written into `slots` from `at` on (what does not fit is left out).
fn put(slots: &mut [f32], at: usize, v: &[f32]) {
    for (slot, &x) in slots.iter_mut().skip(at).zip(v) {
        *slot = x;
    }
}

/// Three slots from `at` as a vector (zero past the end).
fn vec3(slots: &[f32], at: usize) -> Vec3 {
    let c = |k: usize| slots.get(at + k).copied().unwrap_or(0.0);
    Vec3::new(c(0), c(1), c(2))
}

impl Pose<'_> {
    /// The animated camera's and lights' slots at rest.
    pub(super) fn rest_view(&mut self, animation: &Animation<'_>) {
        if let Some(c) = animation.camera() {
            if let Some(slots) = self.weights.get_mut(c.slots()) {
                put(slots, cam::SLOT_POSITION, &c.position().to_array());
                put(slots, cam::SLOT_TARGET, &c.target().to_array());
                put(slots, cam::SLOT_FOV, &[c.fov()]);
                put(slots, cam::SLOT_ROTATION, &c.rotation().to_array());
            }
        }
        for l in (0..animation.animated_light_count()).filter_map(|i| animation.animated_light(i)) {
            if let Some(slots) = self.weights.get_mut(l.slots()) {
                put(slots, lit::SLOT_VECTOR, &l.vector().to_array());
                put(slots, lit::SLOT_DIFFUSE, &l.diffuse().to_array());
                put(slots, lit::SLOT_INTENSITY, &[l.intensity()]);
            }
        }
    }

    /// Sets what a camera or light track moves to `value`; false for another track.
    pub(super) fn apply_view(&mut self, animation: &Animation<'_>, track: &Track<'_>, value: Vec4) -> bool {
        let camera = || animation.camera().map(|c| c.slots().start);
        let light = |l: u16| animation.animated_light_of(l as usize).map(|l| l.slots().start);
        let first = match track.target() {
            TrackTarget::CameraPosition => camera().map(|s| s + cam::SLOT_POSITION),
            TrackTarget::CameraTarget => camera().map(|s| s + cam::SLOT_TARGET),
            TrackTarget::CameraFov => camera().map(|s| s + cam::SLOT_FOV),
            TrackTarget::CameraRotation => camera().map(|s| s + cam::SLOT_ROTATION),
            TrackTarget::LightVector(l) => light(l).map(|s| s + lit::SLOT_VECTOR),
            TrackTarget::LightDiffuse(l) => light(l).map(|s| s + lit::SLOT_DIFFUSE),
            TrackTarget::LightIntensity(l) => light(l).map(|s| s + lit::SLOT_INTENSITY),
            _ => return false,
        };
        if let Some(first) = first {
            // At most three components, each within its property (`Model::parse` checked).
            let values = &value.to_array()[..track.component_count().min(3)];
            if let Some(slots) = self.weights.get_mut(first + track.first_component()..) {
                put(slots, 0, values);
            }
        }
        true
    }

    /// The point the animated camera looks at, from where its tracks put it ([`Aim`]).
    pub(super) fn aim_camera(&mut self, animation: &Animation<'_>) {
        let Some(c) = animation.camera() else { return };
        let Some(slots) = self.weights.get_mut(c.slots()) else { return };
        let position = vec3(slots, cam::SLOT_POSITION);
        let target = match c.aim() {
            Aim::Target => return,
            Aim::Direction => position + (c.target() - c.position()),
            Aim::Rotation => {
                let forward = euler_matrix(vec3(slots, cam::SLOT_ROTATION)).z_axis;
                position + forward * c.distance()
            }
        };
        put(slots, cam::SLOT_TARGET, &target.to_array());
    }

    /// The model's camera at this pose: `still` (the model's own, [`Model::camera`](crate::Model::camera))
    /// with the position, target and field of view its tracks give; `still` itself when the
    /// pose is not set or no track moves the camera. Near and far are `still`'s.
    #[must_use]
    pub fn camera(&self, animation: &Animation<'_>, still: SceneCamera) -> SceneCamera {
        let Some(slots) = animation.camera().and_then(|c| self.weights().get(c.slots())) else { return still };
        SceneCamera {
            position: vec3(slots, cam::SLOT_POSITION),
            target: vec3(slots, cam::SLOT_TARGET),
            fov: slots.get(cam::SLOT_FOV).copied().unwrap_or(still.fov),
            ..still
        }
    }

    /// The model's light `light` at this pose: `still` (the model's own,
    /// [`Model::light`](crate::Model::light)) with the position or direction, diffuse colour
    /// and intensity its tracks give; `still` itself when the pose is not set or no track
    /// moves that light.
    #[must_use]
    pub fn light(&self, animation: &Animation<'_>, light: usize, still: Light) -> Light {
        let slots = animation.animated_light_of(light).and_then(|l| self.weights().get(l.slots()));
        let Some(slots) = slots else { return still };
        Light {
            vector: vec3(slots, lit::SLOT_VECTOR),
            diffuse: vec3(slots, lit::SLOT_DIFFUSE),
            intensity: slots.get(lit::SLOT_INTENSITY).copied().unwrap_or(still.intensity),
            ..still
        }
    }
}
