//! Animations of the camera and the lights: those of the active camera (the one `camera`
//! stores) and of the lights `light` stores, their own `animations` (a group each, with
//! `autoAnimate` as for nodes) and `animationGroups` tracks naming them, as tracks of
//! [`TrackTarget::Camera`](crate::convert::scene::TrackTarget) and
//! [`TrackTarget::Light`](crate::convert::scene::TrackTarget), keys taken to world space
//! through the parent; and how the camera aims while it moves ([`CameraAim`]).
//!
//! The rules, after Babylon.js's `TargetCamera`, `ArcRotateCamera` and lights:
//!
//! - **Camera**: `position` (and its components); `target` (an `ArcRotateCamera`'s, or a
//!   whole vector, which Babylon.js's `TargetCamera.target` setter turns into `setTarget`; one
//!   component of another camera's target has no effect there: skipped, warned) and a whole
//!   `lockedTarget` vector: the camera then looks at that point; `rotation` (and components) of
//!   a camera that Babylon.js turns by it (not an `ArcRotateCamera`, no `rotationQuaternion`,
//!   no parent that turns or scales it); `fov` (keys inside 0..pi). A camera with a locked
//!   target (`lockedTargetId`) keeps looking at it: its `target` tracks are skipped.
//! - **Aim**: an `ArcRotateCamera`, a locked target or target tracks look at the target
//!   ([`CameraAim::Target`]); otherwise the camera keeps its rotation, as a `FreeCamera` does:
//!   turned by its rotation tracks when it has some ([`CameraAim::Rotation`], from the file's
//!   `rotation`, or the one `setTarget` gives for its `target`: yaw and pitch, no roll), else
//!   along its still direction ([`CameraAim::Direction`]).
//! - **Lights**: a point light's `position`, a directional or hemispheric light's `direction`
//!   (the other vector does not light: skipped, warned), `intensity`, `diffuse` (color3, and
//!   its components `r`, `g`, `b`).
//! - **Parents**: whole vectors go through the parent's world matrix (positions as points,
//!   directions and tangents as directions); one component only where the parent neither
//!   turns nor scales.
//! - Any other property (`upVector`, `alpha`, `specular`, `range`...) is skipped with a
//!   warning naming it; so are the animations of cameras other than the active one and of
//!   lights soft3d does not draw. A camera or light that moves as a *parent* does not move its
//!   children.

use std::format;
use std::string::String;
use std::vec::Vec;

use serde_json::Value;

use super::animation::{own_group, Read, Target, Track};
use super::fields::{label, list, text};
use super::track::{Curve, Owner, Property};
use super::transform::transform;
use super::{ConvertError, Reader};
use crate::convert::scene::{CameraAim, CameraProperty, LightKind, LightProperty, Matrix, IDENTITY};
use core::f32::consts::PI;

/// A light `light` stored in `Scene::lights`.
pub(super) struct StoredLight {
    /// Its node (in `Reader::nodes`).
    pub(super) node: Option<usize>,
    pub(super) kind: LightKind,
    /// Its parent's world matrix.
    pub(super) world: Matrix,
}

/// The camera `camera` stored in `Scene::camera`: what its animations need.
pub(super) struct StoredCamera {
    /// Its node (in `Reader::nodes`).
    pub(super) node: Option<usize>,
    /// Its parent's world matrix.
    pub(super) world: Matrix,
    /// An `ArcRotateCamera`: it looks at its target.
    pub(super) orbits: bool,
    /// Its target is its `lockedTargetId`'s.
    pub(super) locked: bool,
    /// It has a `rotationQuaternion` (Babylon.js turns it by that, not by `rotation`).
    pub(super) quaternion: bool,
    /// Its rotation at rest: the file's, or the one `setTarget` gives for its target.
    pub(super) rotation: [f32; 3],
    /// How far its still target lies from its eye.
    pub(super) distance: f32,
}

/// The camera and lights that were stored, for their animations.
#[derive(Default)]
pub(super) struct Stored {
    pub(super) lights: Vec<StoredLight>,
    pub(super) camera: Option<StoredCamera>,
    /// The node of the active camera when it was ignored (it looks at its own position).
    pub(super) ignored_camera: Option<usize>,
    /// The nodes of `cameras[0]` and `lights[0]` (see `Reader::node_of`).
    pub(super) cameras_at: usize,
    pub(super) lights_at: usize,
}

/// A stored camera or light a track may move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum View {
    Camera,
    /// An index into `Scene::lights`.
    Light(usize),
}

/// The Euler rotation (yaw and pitch, no roll) that Babylon.js's `setTarget` gives a camera
/// looking along `d`.
pub(super) fn rotation_towards(d: [f32; 3]) -> [f32; 3] {
    let level = libm::sqrtf(d[0] * d[0] + d[2] * d[2]);
    [libm::atan2f(-d[1], level), libm::atan2f(d[0], d[2]), 0.0]
}

/// Whether `m` neither turns nor scales (its 3x3 part is the identity).
fn only_moves(m: &Matrix) -> bool {
    m[..12] == IDENTITY[..12]
}

/// Components `first..first + count` of a point (`w` 1) or direction (`w` 0) in `curve`'s
/// keys, taken through `world` (tangents as directions); why not, when one component alone
/// cannot be.
fn to_world(curve: &mut Curve, world: &Matrix, w: f32, (first, count): (u8, u8)) -> Result<(), String> {
    if *world == IDENTITY {
        return Ok(());
    }
    let through = |v: &mut Vec<f32>, w: f32| {
        if let [x, y, z] = v[..] {
            *v = transform(world, [x, y, z], w).to_vec();
        }
    };
    if count == 3 {
        for key in &mut curve.keys {
            through(&mut key.values, w);
            if let Some((i, o)) = &mut key.tangents {
                through(i, 0.0);
                through(o, 0.0);
            }
        }
        return Ok(());
    }
    if !only_moves(world) {
        return Err("one component of a vector that the parent turns or scales is not played".into());
    }
    let offset = w * world[12 + usize::from(first)];
    for v in curve.keys.iter_mut().flat_map(|k| k.values.iter_mut()) {
        *v += offset;
    }
    Ok(())
}

impl<'a> Reader<'a> {
    /// The node of `cameras[i]` (`array` "cameras") or `lights[i]` (`node` adds them in order,
    /// after the meshes and transform nodes).
    pub(super) fn node_of(&self, array: &str, i: usize) -> Option<usize> {
        let first = if array == "cameras" { self.view.cameras_at } else { self.view.lights_at };
        Some(first + i).filter(|&n| n < self.nodes.len())
    }

    /// The stored camera or light drawn from node `node`.
    pub(super) fn view_of_node(&self, node: usize) -> Option<View> {
        if self.view.camera.as_ref().is_some_and(|c| c.node == Some(node)) {
            return Some(View::Camera);
        }
        self.view.lights.iter().position(|l| l.node == Some(node)).map(View::Light)
    }

    /// The stored camera or light with `id` (by `id`, then `name`); `Err` with the reason
    /// for a camera or light that is not stored, `Ok(None)` for anything else.
    pub(super) fn view_named(&self, id: &str) -> Result<Option<View>, String> {
        let Some(node) = self.ids.get(id).or_else(|| self.names.get(id)).copied() else { return Ok(None) };
        let n = &self.nodes[node];
        match self.view_of_node(node) {
            Some(view) => Ok(Some(view)),
            None if n.movable => Ok(None),
            None => {
                let kind = if n.what.starts_with("camera") { "camera" } else { "light" };
                Err(format!("{}: {}: its animations are not played", n.what, self.not_played(kind, Some(node))))
            }
        }
    }

    /// Reads the `animations` of the stored camera and lights, each one's in a group of its
    /// own; warns about those of other cameras and lights.
    pub(super) fn read_view_tracks(&mut self, read: &mut Read) -> Result<(), ConvertError> {
        let root = self.root;
        for (array, kind) in [("cameras", "camera"), ("lights", "light")] {
            for (i, obj) in list(root, array).map_err(|m| self.ctx("scene").err(m))?.iter().enumerate() {
                let what = label(obj, kind, array, i);
                let node = self.node_of(array, i);
                let view = node.and_then(|n| self.view_of_node(n));
                let animations = list(obj, "animations").map_err(|m| self.ctx(what.clone()).err(m))?;
                match view {
                    Some(view) => self.read_own_view_tracks(obj, view, &what, read)?,
                    None if animations.is_empty() => {}
                    None => {
                        let why = self.not_played(kind, node);
                        self.warn(format!("{what}: {why}: its animations are not played"));
                    }
                }
            }
        }
        Ok(())
    }

    /// Reads `obj`'s own animations, the stored camera's or light's (`view`), into `read`.
    fn read_own_view_tracks(
        &mut self,
        obj: &Value,
        view: View,
        what: &str,
        read: &mut Read,
    ) -> Result<(), ConvertError> {
        let cx = self.ctx(what);
        let mut own = Vec::new();
        for (k, anim) in list(obj, "animations").map_err(|m| cx.err(m))?.iter().enumerate() {
            let at = format!("animations[{k}]");
            let here = super::animation::named(what, &at, anim);
            let Some((property, mut curve)) = self.animation(anim, Owner::View, &here, &at, &cx)? else {
                continue;
            };
            match self.view_target(view, property, &mut curve) {
                Ok(target) => {
                    read.tracks.push(Track { target, curve });
                    own.push(read.tracks.len() - 1);
                }
                Err(reason) => self.warn(format!("{here}: {reason}, skipped")),
            }
        }
        if !own.is_empty() {
            let name = text(obj, "name").ok().flatten().or_else(|| text(obj, "id").ok().flatten());
            read.groups.push(own_group(obj, name.unwrap_or_default(), own).map_err(|m| cx.err(m))?);
        }
        Ok(())
    }

    /// What a track of `property` moves on the stored camera or light `view`, its keys taken to
    /// world space; why soft3d skips it (see the module documentation).
    pub(super) fn view_target(&self, view: View, property: Property, curve: &mut Curve) -> Result<Target, String> {
        let Property::View { name, first, count } = property else {
            return Err("not a property of cameras or lights".into());
        };
        match view {
            View::Camera => self.camera_target(name, (first, count), curve),
            View::Light(light) => self.light_target(light, name, (first, count), curve),
        }
    }

    fn camera_target(&self, name: &str, (first, count): (u8, u8), curve: &mut Curve) -> Result<Target, String> {
        let Some(c) = &self.view.camera else { return Err("no camera is stored".into()) };
        let property = match name {
            "position" => CameraProperty::Position,
            "target" if c.locked => {
                return Err(
                    "the camera looks at its locked target (lockedTargetId): target tracks have no effect".into()
                )
            }
            "target" if !c.orbits && count != 3 => return Err(
                "one component of this camera's target has no effect in Babylon.js (its target follows its rotation)"
                    .into(),
            ),
            "lockedTarget" if count != 3 => return Err("one component of lockedTarget is not played".into()),
            "target" | "lockedTarget" => CameraProperty::Target,
            "rotation" if c.orbits => {
                return Err("an ArcRotateCamera turns by alpha and beta, which soft3d does not play".into())
            }
            "rotation" if c.quaternion => {
                return Err("the camera has a rotationQuaternion, which Babylon.js turns it by instead".into())
            }
            "rotation" if !only_moves(&c.world) => {
                return Err("the rotation of a camera whose parent turns or scales it is not played".into())
            }
            "rotation" => CameraProperty::Rotation,
            "fov" if !curve.keys.iter().all(|k| k.values.first().is_some_and(|&v| v > 0.0 && v < PI)) => {
                return Err("a field of view outside 0 to pi".into())
            }
            "fov" => CameraProperty::Fov,
            _ => return Err(format!("a camera's {name} is not played")),
        };
        if matches!(property, CameraProperty::Position | CameraProperty::Target) {
            to_world(curve, &c.world, 1.0, (first, count))?;
        }
        Ok(Target::Camera { property, first, count })
    }

    fn light_target(&self, light: usize, name: &str, fc: (u8, u8), curve: &mut Curve) -> Result<Target, String> {
        let Some(l) = self.view.lights.get(light) else { return Err("no such light is stored".into()) };
        let point = l.kind == LightKind::Point;
        let property = match name {
            "position" if point => LightProperty::Vector,
            "direction" if !point => LightProperty::Vector,
            "position" => return Err("a directional or hemispheric light's position does not light it".into()),
            "direction" => return Err("a point light's direction does not light it".into()),
            "intensity" => LightProperty::Intensity,
            "diffuse" => LightProperty::Diffuse,
            _ => return Err(format!("a light's {name} is not played")),
        };
        if property == LightProperty::Vector {
            to_world(curve, &l.world, if point { 1.0 } else { 0.0 }, fc)?;
        }
        let light = u16::try_from(light).map_err(|_| String::from("more than 65536 lights"))?;
        Ok(Target::Light { light, property, first: fc.0, count: fc.1 })
    }

    /// How the camera aims, given every track read (see the module documentation): the
    /// default when no track moves it.
    pub(super) fn camera_aim(&self, tracks: &[Track]) -> CameraAim {
        let moves = |p: Option<CameraProperty>| {
            tracks
                .iter()
                .any(|t| matches!(t.target, Target::Camera { property, .. } if p.is_none_or(|p| p == property)))
        };
        let Some(c) = self.view.camera.as_ref().filter(|_| moves(None)) else { return CameraAim::default() };
        if c.orbits || c.locked || moves(Some(CameraProperty::Target)) {
            CameraAim::Target
        } else if moves(Some(CameraProperty::Rotation)) {
            CameraAim::Rotation { rotation: c.rotation, distance: c.distance }
        } else {
            CameraAim::Direction
        }
    }
}

impl Reader<'_> {
    /// Why the animations of the camera or light (`kind`) at `node` are not played.
    fn not_played(&self, kind: &str, node: Option<usize>) -> &'static str {
        if kind != "camera" {
            "a light soft3d does not draw"
        } else if node.is_some() && node == self.view.ignored_camera {
            "the active camera, ignored"
        } else {
            "not the active camera"
        }
    }
}
