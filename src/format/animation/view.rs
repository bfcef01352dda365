//! The animated camera and lights of an extended animation section: their records
//! ([`AnimatedCamera`], [`AnimatedLight`]: rest values and where a pose keeps theirs) and how a
//! moving camera aims ([`Aim`]). What a pose makes of them is `crate::animation`'s.

use core::ops::Range;

use super::super::layout::*;
use super::Animation;
use crate::math::Vec3;

/// How the point an animated camera looks at follows it (Babylon.js: an `ArcRotateCamera` or a
/// locked target keeps looking at its target; a `FreeCamera` keeps its rotation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aim {
    /// At its target slots: a fixed point, or where target tracks put it.
    Target,
    /// Along a fixed direction: `position + (rest target - rest position)`.
    Direction,
    /// By its rotation: `position + distance · forward(rotation)`, forward being `(0, 0, 1)`
    /// turned by Babylon's `RotationYawPitchRoll(y, x, z)`.
    Rotation,
}

impl Aim {
    /// The aim stored as `code` (`None` for an unknown code).
    pub(crate) fn from_code(code: u16) -> Option<Self> {
        match code {
            animated_camera::AIM_TARGET => Some(Aim::Target),
            animated_camera::AIM_DIRECTION => Some(Aim::Direction),
            animated_camera::AIM_ROTATION => Some(Aim::Rotation),
            _ => None,
        }
    }
}

/// The model's camera as tracks move it: its rest values and where a pose keeps its slots.
#[derive(Clone, Copy, Debug)]
pub struct AnimatedCamera<'a> {
    pub(super) data: &'a [u8],
    pub(super) at: usize,
}

/// One of the model's lights as tracks move it: its rest values and where a pose keeps its
/// slots.
#[derive(Clone, Copy, Debug)]
pub struct AnimatedLight<'a> {
    pub(super) data: &'a [u8],
    pub(super) at: usize,
}

impl<'a> Animation<'a> {
    /// Whether the section is extended (camera and light animation: the header's flag).
    pub(super) fn extended(&self) -> bool {
        u16_at(self.data, header::FLAGS.start) & header::FLAG_EXTENDED_ANIMATION != 0
    }

    /// The offset field `field` of the extended section (0 when not extended).
    pub(super) fn extended_u32(&self, field: Range<usize>) -> usize {
        if self.extended() {
            u32_at(self.data, self.at + field.start) as usize
        } else {
            0
        }
    }

    /// The camera, when tracks move it.
    #[must_use]
    pub fn camera(&self) -> Option<AnimatedCamera<'a>> {
        let at = self.extended_u32(animation::CAMERA);
        (at != 0).then_some(AnimatedCamera { data: self.data, at })
    }

    /// Number of lights that tracks move.
    #[must_use]
    pub fn animated_light_count(&self) -> usize {
        if self.extended() {
            self.count(animation::LIGHT_COUNT)
        } else {
            0
        }
    }

    /// Animated light `i` of [`Animation::animated_light_count`] (in increasing light order).
    #[must_use]
    pub fn animated_light(&self, i: usize) -> Option<AnimatedLight<'a>> {
        (i < self.animated_light_count()).then(|| AnimatedLight {
            data: self.data,
            at: self.extended_u32(animation::LIGHTS) + i * animated_light::LEN,
        })
    }

    /// The record of the model's light `light`, when tracks move it.
    #[must_use]
    pub fn animated_light_of(&self, light: usize) -> Option<AnimatedLight<'a>> {
        // Records are in increasing light order: a binary search.
        let (mut lo, mut hi) = (0, self.animated_light_count());
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            let record = self.animated_light(mid)?;
            match record.light().cmp(&light) {
                core::cmp::Ordering::Equal => return Some(record),
                core::cmp::Ordering::Less => lo = mid + 1,
                core::cmp::Ordering::Greater => hi = mid,
            }
        }
        None
    }
}

/// The slots `first..first + count` from the u16 at `at`.
fn slots(data: &[u8], at: usize, count: usize) -> Range<usize> {
    let first = u16_at(data, at) as usize;
    first..first + count
}

impl AnimatedCamera<'_> {
    /// How the point looked at follows the camera.
    #[must_use]
    pub fn aim(&self) -> Aim {
        Aim::from_code(u16_at(self.data, self.at + animated_camera::AIM.start)).unwrap_or(Aim::Target)
    }

    /// Its slots in a pose's weights: position x, y, z, target x, y, z, fov, rotation x, y, z.
    #[must_use]
    pub fn slots(&self) -> Range<usize> {
        slots(self.data, self.at + animated_camera::FIRST_SLOT.start, animated_camera::SLOTS)
    }

    /// Eye position at rest.
    #[must_use]
    pub fn position(&self) -> Vec3 {
        vec3_at(self.data, self.at + animated_camera::POSITION.start)
    }

    /// The point looked at, at rest.
    #[must_use]
    pub fn target(&self) -> Vec3 {
        vec3_at(self.data, self.at + animated_camera::TARGET.start)
    }

    /// Vertical field of view at rest, radians.
    #[must_use]
    pub fn fov(&self) -> f32 {
        f32_at(self.data, self.at + animated_camera::FOV.start)
    }

    /// Euler rotation (x, y, z) at rest ([`Aim::Rotation`]).
    #[must_use]
    pub fn rotation(&self) -> Vec3 {
        vec3_at(self.data, self.at + animated_camera::ROTATION.start)
    }

    /// How far ahead of the eye the target lies ([`Aim::Rotation`]).
    #[must_use]
    pub fn distance(&self) -> f32 {
        f32_at(self.data, self.at + animated_camera::DISTANCE.start)
    }
}

impl AnimatedLight<'_> {
    /// The model's light it moves (an index for [`Model::light`](crate::Model::light)).
    #[must_use]
    pub fn light(&self) -> usize {
        u16_at(self.data, self.at + animated_light::LIGHT.start) as usize
    }

    /// Its slots in a pose's weights: vector x, y, z, diffuse r, g, b, intensity.
    #[must_use]
    pub fn slots(&self) -> Range<usize> {
        slots(self.data, self.at + animated_light::FIRST_SLOT.start, animated_light::SLOTS)
    }

    /// Position (point light) or direction at rest.
    #[must_use]
    pub fn vector(&self) -> Vec3 {
        vec3_at(self.data, self.at + animated_light::VECTOR.start)
    }

    /// Diffuse colour at rest.
    #[must_use]
    pub fn diffuse(&self) -> Vec3 {
        vec3_at(self.data, self.at + animated_light::DIFFUSE.start)
    }

    /// Intensity at rest.
    #[must_use]
    pub fn intensity(&self) -> f32 {
        f32_at(self.data, self.at + animated_light::INTENSITY.start)
    }
}
