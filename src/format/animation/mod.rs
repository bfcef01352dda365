//! A model's animation section, read in place: typed views of its records ([`Animation`],
//! [`Node`], [`Track`], [`Group`], [`Morph`], [`Skin`]; the animated camera and lights are
//! `view`'s). The byte layout is `layout`'s; what a pose at a frame is, is
//! `crate::animation`'s.

use core::ops::Range;

use super::layout::*;

mod validate;
mod view;
pub use view::{Aim, AnimatedCamera, AnimatedLight};

use crate::math::{Mat4, Vec3, Vec4};

/// The animation section of a [`Model`](super::Model): every count, offset and reference in it
/// was checked by `Model::parse`.
#[derive(Clone, Copy, Debug)]
pub struct Animation<'a> {
    data: &'a [u8],
    at: usize,
}

/// An animated node (see `convert::scene::NodeData`).
#[derive(Clone, Copy, Debug)]
pub struct Node<'a> {
    data: &'a [u8],
    at: usize,
}

/// One track: what it moves and its keys.
#[derive(Clone, Copy, Debug)]
pub struct Track<'a> {
    data: &'a [u8],
    at: usize,
}

/// What a [`Track`] sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackTarget {
    /// Components `first..first + count` of a node's position.
    Position(u16),
    /// Components of a node's Euler rotation.
    Rotation(u16),
    /// Components of a node's scaling.
    Scaling(u16),
    /// A node's quaternion.
    Quaternion(u16),
    /// A morph weight (an index over every mesh's targets).
    Influence(u16),
    /// Components of the camera's position ([`Animation::camera`]).
    CameraPosition,
    /// Components of the point the camera looks at.
    CameraTarget,
    /// Components of the camera's Euler rotation ([`Aim::Rotation`]).
    CameraRotation,
    /// The camera's vertical field of view.
    CameraFov,
    /// Components of a light's position (point) or direction: the model's light with that
    /// index ([`Animation::animated_light_of`]).
    LightVector(u16),
    /// Components of a light's diffuse colour.
    LightDiffuse(u16),
    /// A light's intensity.
    LightIntensity(u16),
}

/// A group of tracks played together.
#[derive(Clone, Copy, Debug)]
pub struct Group<'a> {
    data: &'a [u8],
    at: usize,
}

/// A skinned mesh: its bones (palette) and each vertex's four bones and weights.
#[derive(Clone, Copy, Debug)]
pub struct Skin<'a> {
    data: &'a [u8],
    at: usize,
}

/// A mesh's morph targets.
#[derive(Clone, Copy, Debug)]
pub struct Morph<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Animation<'a> {
    /// The section at `at` of `data`, which [`Animation::validate`] accepted (in `Model::parse`).
    pub(super) fn validated(data: &'a [u8], at: u32) -> Self {
        Animation { data, at: at as usize }
    }

    pub(super) fn count(&self, field: Range<usize>) -> usize {
        u16_at(self.data, self.at + field.start) as usize
    }

    /// Number of animated nodes.
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.count(animation::NODE_COUNT)
    }

    /// Number of weights a pose holds: every morphed mesh's targets, then the slots of the
    /// animated camera and lights (see [`AnimatedCamera::slots`]).
    #[must_use]
    pub fn weight_count(&self) -> usize {
        self.count(animation::WEIGHT_COUNT)
    }

    /// Number of tracks.
    #[must_use]
    pub fn track_count(&self) -> usize {
        self.count(animation::TRACK_COUNT)
    }

    /// Number of groups.
    #[must_use]
    pub fn group_count(&self) -> usize {
        self.count(animation::GROUP_COUNT)
    }

    /// Number of morphed meshes.
    #[must_use]
    pub fn morph_count(&self) -> usize {
        self.count(animation::MORPH_COUNT)
    }

    /// Number of skinned meshes.
    #[must_use]
    pub fn skin_count(&self) -> usize {
        self.count(animation::SKIN_COUNT)
    }

    /// Number of bone matrices in a pose's palette (every skin's bones).
    #[must_use]
    pub fn palette_count(&self) -> usize {
        self.count(animation::PALETTE_COUNT)
    }

    /// Skinned mesh `i` of [`Animation::skin_count`].
    #[must_use]
    pub fn skin_at(&self, i: usize) -> Option<Skin<'a>> {
        let at = self.record(animation::SKINS, animation::SKIN_COUNT, skin::LEN, i)?;
        Some(Skin { data: self.data, at })
    }

    /// The skin of mesh `mesh`, if it has one.
    #[must_use]
    pub fn skin_of(&self, mesh: usize) -> Option<Skin<'a>> {
        (0..self.skin_count()).filter_map(|i| self.skin_at(i)).find(|s| s.mesh() == mesh)
    }

    /// Number of meshes linked to animated nodes.
    #[must_use]
    pub fn link_count(&self) -> usize {
        self.count(animation::LINK_COUNT)
    }

    fn record(&self, table: Range<usize>, count: Range<usize>, len: usize, i: usize) -> Option<usize> {
        (i < self.count(count)).then(|| u32_at(self.data, self.at + table.start) as usize + i * len)
    }

    /// Node `i`.
    #[must_use]
    pub fn node(&self, i: usize) -> Option<Node<'a>> {
        let at = self.record(animation::NODES, animation::NODE_COUNT, node::LEN, i)?;
        Some(Node { data: self.data, at })
    }

    /// Track `i`.
    #[must_use]
    pub fn track(&self, i: usize) -> Option<Track<'a>> {
        let at = self.record(animation::TRACKS, animation::TRACK_COUNT, track::LEN, i)?;
        Some(Track { data: self.data, at })
    }

    /// Group `i`.
    #[must_use]
    pub fn group(&self, i: usize) -> Option<Group<'a>> {
        let at = self.record(animation::GROUPS, animation::GROUP_COUNT, group::LEN, i)?;
        Some(Group { data: self.data, at })
    }

    /// The group named `name`.
    #[must_use]
    pub fn group_named(&self, name: &str) -> Option<usize> {
        (0..self.group_count()).find(|&g| self.group(g).is_some_and(|g| g.name() == name))
    }

    /// Morphed mesh `i` of [`Animation::morph_count`].
    #[must_use]
    pub fn morph_at(&self, i: usize) -> Option<Morph<'a>> {
        let at = self.record(animation::MORPHS, animation::MORPH_COUNT, morph::LEN, i)?;
        Some(Morph { data: self.data, at })
    }

    /// The morph targets of mesh `mesh`, if it has some.
    #[must_use]
    pub fn morph_of(&self, mesh: usize) -> Option<Morph<'a>> {
        (0..self.morph_count()).filter_map(|i| self.morph_at(i)).find(|m| m.mesh() == mesh)
    }

    /// The node mesh `mesh` follows and the `below` matrix between them, if it follows one.
    #[must_use]
    pub fn link_of(&self, mesh: usize) -> Option<(usize, Mat4)> {
        (0..self.link_count()).find_map(|i| {
            let at = self.record(animation::LINKS, animation::LINK_COUNT, link::LEN, i)?;
            (u16_at(self.data, at + link::MESH.start) as usize == mesh).then(|| {
                (u16_at(self.data, at + link::NODE.start) as usize, affine_at(self.data, at + link::BELOW.start))
            })
        })
    }
}

impl Node<'_> {
    /// The nearest animated ancestor (a lower index).
    #[must_use]
    pub fn parent(&self) -> Option<usize> {
        let p = u16_at(self.data, self.at + node::PARENT.start);
        (p != NONE).then_some(p as usize)
    }

    /// The still nodes between it and its parent (a glam matrix: column-vector convention).
    #[must_use]
    pub fn above(&self) -> Mat4 {
        affine_at(self.data, self.at + node::ABOVE.start)
    }

    /// Position at rest.
    #[must_use]
    pub fn position(&self) -> Vec3 {
        vec3_at(self.data, self.at + node::POSITION.start)
    }

    /// Rotation at rest: Euler angles (x, y, z, 0) or a quaternion (x, y, z, w).
    #[must_use]
    pub fn rotation(&self) -> (Vec4, bool) {
        let at = self.at + node::ROTATION.start;
        let v = vec3_at(self.data, at).extend(f32_at(self.data, at + 12));
        (v, u16_at(self.data, self.at + node::FLAGS.start) & node::FLAG_QUATERNION != 0)
    }

    /// Scaling at rest.
    #[must_use]
    pub fn scaling(&self) -> Vec3 {
        vec3_at(self.data, self.at + node::SCALING.start)
    }
}

impl Track<'_> {
    /// What it moves.
    #[must_use]
    pub fn target(&self) -> TrackTarget {
        let t = u16_at(self.data, self.at + track::TARGET.start);
        match u8_at(self.data, self.at + track::KIND) {
            track::KIND_POSITION => TrackTarget::Position(t),
            track::KIND_ROTATION => TrackTarget::Rotation(t),
            track::KIND_SCALING => TrackTarget::Scaling(t),
            track::KIND_QUATERNION => TrackTarget::Quaternion(t),
            track::KIND_CAMERA_POSITION => TrackTarget::CameraPosition,
            track::KIND_CAMERA_TARGET => TrackTarget::CameraTarget,
            track::KIND_CAMERA_ROTATION => TrackTarget::CameraRotation,
            track::KIND_CAMERA_FOV => TrackTarget::CameraFov,
            track::KIND_LIGHT_VECTOR => TrackTarget::LightVector(t),
            track::KIND_LIGHT_DIFFUSE => TrackTarget::LightDiffuse(t),
            track::KIND_LIGHT_INTENSITY => TrackTarget::LightIntensity(t),
            _ => TrackTarget::Influence(t),
        }
    }

    /// The first component it sets.
    #[must_use]
    pub fn first_component(&self) -> usize {
        u8_at(self.data, self.at + track::FIRST) as usize
    }

    /// How many components a key holds (1 to 4).
    #[must_use]
    pub fn component_count(&self) -> usize {
        u8_at(self.data, self.at + track::COUNT) as usize
    }

    /// Babylon.js's loop behaviour: 0 relative, 1 cycle, 2 constant.
    #[must_use]
    pub fn loop_mode(&self) -> u8 {
        u8_at(self.data, self.at + track::FLAGS) & track::LOOP_MASK
    }

    /// Whether keys carry Hermite tangents.
    #[must_use]
    pub fn has_tangents(&self) -> bool {
        u8_at(self.data, self.at + track::FLAGS) & track::FLAG_TANGENTS != 0
    }

    /// Frames a second.
    #[must_use]
    pub fn fps(&self) -> f32 {
        f32_at(self.data, self.at + track::FPS.start)
    }

    /// Number of keys (>= 1).
    #[must_use]
    pub fn key_count(&self) -> usize {
        u32_at(self.data, self.at + track::KEY_COUNT.start) as usize
    }

    fn key_len(&self) -> usize {
        key::VALUES + 4 * self.component_count() * if self.has_tangents() { 3 } else { 1 }
    }

    /// Where key `k` lies (past the data for a key beyond the last: it reads as zeros).
    fn key_at(&self, k: usize) -> usize {
        if k >= self.key_count() {
            return usize::MAX;
        }
        u32_at(self.data, self.at + track::KEYS.start) as usize + k * self.key_len()
    }

    /// Key `k`'s frame.
    #[must_use]
    pub fn frame(&self, k: usize) -> f32 {
        f32_at(self.data, self.key_at(k).saturating_add(key::FRAME.start))
    }

    /// Whether key `k` holds its value until the next key.
    #[must_use]
    pub fn is_step(&self, k: usize) -> bool {
        self.key_flags(k) & key::FLAG_STEP != 0
    }

    /// Whether key `k` has an in tangent (in a track with tangents: see
    /// [`Track::has_tangents`]).
    #[must_use]
    pub fn has_in_tangent(&self, k: usize) -> bool {
        self.has_tangents() && self.key_flags(k) & key::FLAG_NO_IN_TANGENT == 0
    }

    /// Whether key `k` has an out tangent.
    #[must_use]
    pub fn has_out_tangent(&self, k: usize) -> bool {
        self.has_tangents() && self.key_flags(k) & key::FLAG_NO_OUT_TANGENT == 0
    }

    fn key_flags(&self, k: usize) -> u32 {
        u32_at(self.data, self.key_at(k).saturating_add(key::FLAGS.start))
    }

    /// Key `k`'s value (`set` 0), in tangent (1) or out tangent (2), components beyond
    /// [`Track::component_count`] zero.
    #[must_use]
    pub fn value(&self, k: usize, set: usize) -> Vec4 {
        let n = self.component_count();
        let at = self.key_at(k).saturating_add(key::VALUES + 4 * n * set.min(2));
        Vec4::from_array(core::array::from_fn(
            |c| if c < n { f32_at(self.data, at.saturating_add(4 * c)) } else { 0.0 },
        ))
    }
}

impl<'a> Group<'a> {
    /// Its name.
    #[must_use]
    pub fn name(&self) -> &'a str {
        let start = u32_at(self.data, self.at + group::NAME.start) as usize;
        let len = u16_at(self.data, self.at + group::NAME_LEN.start) as usize;
        self.data.get(start..start + len).and_then(|b| core::str::from_utf8(b).ok()).unwrap_or("")
    }

    /// First and last frame.
    #[must_use]
    pub fn range(&self) -> (f32, f32) {
        (f32_at(self.data, self.at + group::FROM.start), f32_at(self.data, self.at + group::TO.start))
    }

    /// Whether it plays again from the first frame after the last.
    #[must_use]
    pub fn loops(&self) -> bool {
        u8_at(self.data, self.at + group::FLAGS) & group::FLAG_LOOP != 0
    }

    /// Its tracks (indices for [`Animation::track`]).
    pub fn tracks(&self) -> impl Iterator<Item = usize> + 'a {
        let (d, start) = (self.data, u32_at(self.data, self.at + group::TRACKS.start) as usize);
        let n = u16_at(d, self.at + group::TRACK_COUNT.start) as usize;
        (0..n).map(move |k| u16_at(d, start + 2 * k) as usize)
    }
}

impl<'a> Morph<'a> {
    /// The mesh it morphs.
    #[must_use]
    pub fn mesh(&self) -> usize {
        u16_at(self.data, self.at + morph::MESH.start) as usize
    }

    /// Number of targets (>= 1).
    #[must_use]
    pub fn target_count(&self) -> u16 {
        u16_at(self.data, self.at + morph::TARGET_COUNT.start)
    }

    /// Its targets' weights in a pose: `first..first + target_count`.
    #[must_use]
    pub fn weights(&self) -> Range<usize> {
        let first = u16_at(self.data, self.at + morph::FIRST_WEIGHT.start) as usize;
        first..first + self.target_count() as usize
    }

    /// Whether its targets move normals too.
    #[must_use]
    pub fn has_normals(&self) -> bool {
        u16_at(self.data, self.at + morph::FLAGS.start) & morph::FLAG_NORMALS != 0
    }

    /// Where target `t`'s record lies (past the data beyond the last target: zeros).
    fn target_at(&self, t: usize) -> usize {
        if t >= self.target_count() as usize {
            return usize::MAX;
        }
        u32_at(self.data, self.at + morph::TARGETS.start) as usize + t * morph_target::LEN
    }

    /// Target `t`'s influence at rest.
    #[must_use]
    pub fn default_influence(&self, t: usize) -> f32 {
        f32_at(self.data, self.target_at(t).saturating_add(morph_target::INFLUENCE.start))
    }

    /// Target `t`'s delta of vertex `i`: position (stored units) or normal (`normal`), zero
    /// out of range.
    #[must_use]
    pub fn delta(&self, t: usize, i: u32, normal: bool) -> Vec3 {
        if normal && !self.has_normals() {
            return Vec3::ZERO;
        }
        let at = self.target_at(t);
        let (scale, table) = if normal {
            (morph_target::NORMAL_SCALE, morph_target::NORMALS)
        } else {
            (morph_target::POSITION_SCALE, morph_target::POSITIONS)
        };
        if at == usize::MAX {
            return Vec3::ZERO;
        }
        // Saturating: past the deltas (an index beyond the vertices) reads zeros.
        let d = (u32_at(self.data, at + table.start) as usize)
            .saturating_add((i as usize).saturating_mul(morph_target::DELTA_LEN));
        let c = |k: usize| i16_at(self.data, d.saturating_add(k)) as f32;
        Vec3::new(c(0), c(2), c(4)) * f32_at(self.data, at + scale.start)
    }
}

impl Skin<'_> {
    /// The mesh it skins.
    #[must_use]
    pub fn mesh(&self) -> usize {
        u16_at(self.data, self.at + skin::MESH.start) as usize
    }

    /// Number of bones (>= 1).
    #[must_use]
    pub fn bone_count(&self) -> usize {
        u16_at(self.data, self.at + skin::BONE_COUNT.start) as usize
    }

    /// Its bones' matrices in a pose's palette: `first..first + bone_count`.
    #[must_use]
    pub fn palette(&self) -> Range<usize> {
        let first = u16_at(self.data, self.at + skin::FIRST_SLOT.start) as usize;
        first..first + self.bone_count()
    }

    fn bone_at(&self, b: usize) -> Option<usize> {
        (b < self.bone_count()).then(|| u32_at(self.data, self.at + skin::BONES.start) as usize + b * skin::BONE_LEN)
    }

    /// Bone `b`'s node (an index for [`Animation::node`]), `None` past the last bone.
    #[must_use]
    pub fn bone_node(&self, b: usize) -> Option<usize> {
        self.bone_at(b).map(|at| u16_at(self.data, at + skin::BONE_NODE.start) as usize)
    }

    /// Bone `b`'s inverse bind matrix (identity past the last bone).
    #[must_use]
    pub fn inverse_bind(&self, b: usize) -> Mat4 {
        self.bone_at(b).map_or(Mat4::IDENTITY, |at| affine_at(self.data, at + skin::BONE_INVERSE_BIND.start))
    }

    /// Vertex `i`'s four bones and weights (zero weights past the last vertex).
    #[must_use]
    pub fn influences(&self, i: u32) -> ([u8; 4], [f32; 4]) {
        let (bones, weights) = self.stored_influences(i);
        (bones, weights.map(weight_of))
    }

    /// Vertex `i`'s four bones and weights as stored ([`WEIGHT_ONE`] for 1), read at once.
    #[inline]
    pub(crate) fn stored_influences(&self, i: u32) -> ([u8; 4], [u16; 4]) {
        let at = (u32_at(self.data, self.at + skin::VERTICES.start) as usize)
            .saturating_add((i as usize).saturating_mul(skin::VERTEX_LEN));
        let v: [u8; skin::VERTEX_LEN] = bytes_at(self.data, at);
        let weights = core::array::from_fn(|k| u16::from_le_bytes([v[4 + 2 * k], v[5 + 2 * k]]));
        ([v[0], v[1], v[2], v[3]], weights)
    }
}

/// A stored skin weight for 1.
pub(crate) const WEIGHT_ONE: u16 = u16::MAX;

/// A stored skin weight as a number (`WEIGHT_ONE` is 1).
#[inline]
pub(crate) fn weight_of(q: u16) -> f32 {
    f32::from(q) / f32::from(WEIGHT_ONE)
}
