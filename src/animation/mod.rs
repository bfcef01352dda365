//! Poses: where a model's animated nodes are and how much each morph target weighs at a
//! frame, evaluated without allocation into memory the caller owns ([`Pose`]), for
//! [`Renderer::draw_posed`](crate::Renderer::draw_posed) to draw every band of a frame with.
//!
//! What a frame means is Babylon.js's: a group's frame `F` between its `from` and `to` sets
//! every track of the group to its value at `F` (clamped to the track's keys, as
//! `AnimationGroup.goToFrame` does); past `to` a looping group starts again at `from`, another
//! stays at `to`. Without a group, every group of the model is set to `F` at once (what the
//! `../shared/animation` truths do). Values between keys are interpolated as in `keys`.
//! A node's matrix is Babylon's `Local = S · R · T` from its position, rotation (Euler
//! `RotationYawPitchRoll(y, x, z)`, or a quaternion as written) and scaling; its world is
//! `Local · above · World(parent)`, and a mesh linked to it is drawn at `below · World(node)`
//! (see `convert::scene::AnimationData`). Bones are nodes too (in their mesh's space): after
//! the nodes, a pose's matrices hold each skin's bone matrices, `World(bone) · inverse bind`
//! (its palette), which the vertex stage blends by each vertex's four weights.
//!
//! The camera and lights move too, where the file animates them: their tracks' values are kept
//! in the pose's weights after the morph weights (`view`), and [`Pose::camera`] and
//! [`Pose::light`] give the model's camera and lights at the frame, for the caller to build its
//! [`Camera`](crate::Camera) and [`Lights`](crate::Lights) with (as
//! [`Lights::from_model_posed`](crate::Lights::from_model_posed) does).

mod keys;
mod view;

pub use crate::format::{Aim, AnimatedCamera, AnimatedLight, Animation, Group, Morph, Node, Skin, Track, TrackTarget};

use crate::math::{Mat3, Mat4, Vec3, Vec4};

/// Why a pose could not be evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoseError {
    /// The pose's memory is too small for the model: it needs `nodes` matrices and `weights`
    /// weights ([`Pose::new`]).
    TooSmall {
        /// Matrices needed (one an animated node and one a bone of each skin).
        nodes: usize,
        /// Weights needed (one a morph target, then the animated camera's and lights' slots).
        weights: usize,
    },
    /// There is no group with that index.
    NoSuchGroup(usize),
}

impl core::fmt::Display for PoseError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            PoseError::TooSmall { nodes, weights } => {
                write!(f, "pose memory too small: the model needs {nodes} node matrices and {weights} weights")
            }
            PoseError::NoSuchGroup(g) => write!(f, "the model has no animation group {g}"),
        }
    }
}

/// The matrices (one a node, one a bone of each skin) and weights (one a morph target, and
/// the slots of an animated camera and lights) a [`Pose`] of a model with `nodes` animated
/// nodes, `bones` skin bones and `weights` weights needs: what
/// `convert::build_script_convert` writes as constants for a converted scene (and
/// [`Animation::node_count`], [`Animation::palette_count`] and [`Animation::weight_count`]
/// say at run time).
#[must_use]
pub const fn pose_memory(nodes: usize, bones: usize, weights: usize) -> (usize, usize) {
    (nodes.saturating_add(bones), weights)
}

/// A model's pose at one frame: the world matrix of each animated node, the weight of each
/// morph target and the animated camera's and lights' values, in memory the caller owns.
/// Every band of a frame draws the same pose.
#[derive(Debug)]
pub struct Pose<'s> {
    /// The animated nodes' world matrices, then the skins' bone matrices (the palette).
    nodes: &'s mut [Mat4],
    weights: &'s mut [f32],
    /// How many nodes, bone matrices and weights the last evaluation set (none: the pose is
    /// not set, a draw uses rest).
    set: (usize, usize, usize),
}

impl<'s> Pose<'s> {
    /// A pose kept in `nodes` and `weights` (sizes: [`pose_memory`]); not set until
    /// [`Pose::evaluate`].
    #[must_use]
    pub fn new(nodes: &'s mut [Mat4], weights: &'s mut [f32]) -> Self {
        Pose { nodes, weights, set: (0, 0, 0) }
    }

    /// Sets the pose of `animation` at `frame` of group `group` (every group when `None`; see
    /// the module documentation). Tracks of other groups stay at rest.
    ///
    /// # Errors
    /// [`PoseError::TooSmall`] when the memory cannot hold the model's nodes and weights,
    /// [`PoseError::NoSuchGroup`] for a group past the last (the pose is then not set).
    pub fn evaluate(&mut self, animation: &Animation<'_>, frame: f32, group: Option<usize>) -> Result<(), PoseError> {
        let (n, w) = (animation.node_count(), animation.weight_count());
        let (matrices, _) = pose_memory(n, animation.palette_count(), w);
        self.set = (0, 0, 0);
        if self.nodes.len() < matrices || self.weights.len() < w {
            return Err(PoseError::TooSmall { nodes: matrices, weights: w });
        }
        if let Some(g) = group.filter(|&g| g >= animation.group_count()) {
            return Err(PoseError::NoSuchGroup(g));
        }
        self.rest(animation);
        self.rest_view(animation);
        let groups = group.map_or(0..animation.group_count(), |g| g..g + 1);
        for g in groups.filter_map(|g| animation.group(g)) {
            let at = group_frame(&g, frame);
            for t in g.tracks().filter_map(|t| animation.track(t)) {
                let value = track_value(&t, g.range(), at);
                if !self.apply_view(animation, &t, value) {
                    self.apply(&t, value);
                }
            }
        }
        self.aim_camera(animation);
        self.compose(animation);
        self.bone_matrices(animation);
        self.set = (n, animation.palette_count(), w);
        Ok(())
    }

    /// Every node at rest (its position, rotation and scaling kept in its matrix's columns
    /// until [`Pose::compose`]) and every weight at its default.
    fn rest(&mut self, animation: &Animation<'_>) {
        for (slot, node) in self.nodes.iter_mut().zip((0..animation.node_count()).filter_map(|i| animation.node(i))) {
            let (rotation, quaternion) = node.rotation();
            let flag = if quaternion { 1.0 } else { 0.0 };
            *slot =
                Mat4::from_cols(node.position().extend(0.0), rotation, node.scaling().extend(0.0), Vec4::splat(flag));
        }
        for m in (0..animation.morph_count()).filter_map(|i| animation.morph_at(i)) {
            for (t, w) in m.weights().enumerate() {
                if let Some(slot) = self.weights.get_mut(w) {
                    *slot = m.default_influence(t);
                }
            }
        }
    }

    /// Sets what `track` moves to `value`.
    fn apply(&mut self, track: &Track<'_>, value: Vec4) {
        let (column, node) = match track.target() {
            TrackTarget::Influence(w) => {
                if let Some(slot) = self.weights.get_mut(w as usize) {
                    *slot = value.x;
                }
                return;
            }
            TrackTarget::Position(n) => (0, n),
            TrackTarget::Rotation(n) | TrackTarget::Quaternion(n) => (1, n),
            TrackTarget::Scaling(n) => (2, n),
            // The camera's and lights' (`apply_view`).
            _ => return,
        };
        let Some(slot) = self.nodes.get_mut(node as usize) else { return };
        // Babylon.js ignores `rotation` while a node has a `rotationQuaternion`.
        if matches!(track.target(), TrackTarget::Rotation(_)) && slot.w_axis.x != 0.0 {
            return;
        }
        let first = track.first_component();
        let col = slot.col_mut(column);
        for c in 0..track.component_count() {
            col[first + c] = value[c];
        }
        if let TrackTarget::Quaternion(_) = track.target() {
            slot.w_axis = Vec4::splat(1.0);
        }
    }

    /// Each node's matrix from its position, rotation and scaling, then its world matrix (a
    /// node comes after its parent).
    fn compose(&mut self, animation: &Animation<'_>) {
        for i in 0..animation.node_count() {
            let Some(node) = animation.node(i) else { continue };
            let parent = node.parent().and_then(|p| self.nodes.get(p).copied()).unwrap_or(Mat4::IDENTITY);
            if let Some(slot) = self.nodes.get_mut(i) {
                *slot = parent * node.above() * local_matrix(slot);
            }
        }
    }

    /// Each skin's bone matrices, after the nodes: `World(bone node) · inverse bind` (glam's
    /// order for Babylon's `inverse bind · World`).
    fn bone_matrices(&mut self, animation: &Animation<'_>) {
        let n = animation.node_count();
        for skin in (0..animation.skin_count()).filter_map(|i| animation.skin_at(i)) {
            for (b, slot) in skin.palette().enumerate() {
                let world = skin.bone_node(b).and_then(|node| self.nodes.get(node).copied()).unwrap_or(Mat4::IDENTITY);
                if let Some(m) = self.nodes.get_mut(n + slot) {
                    *m = world * skin.inverse_bind(b);
                }
            }
        }
    }

    /// The world matrix of animated node `node`, when the pose is set.
    #[must_use]
    pub fn node_world(&self, node: usize) -> Option<Mat4> {
        (node < self.set.0).then(|| self.nodes.get(node).copied()).flatten()
    }

    /// The skins' bone matrices (a skin's are [`Skin::palette`] of these), when the pose is
    /// set (empty otherwise).
    #[must_use]
    pub fn palette(&self) -> &[Mat4] {
        self.nodes.get(self.set.0..self.set.0 + self.set.1).unwrap_or(&[])
    }

    /// The weights (morph weights, then the camera's and lights' slots), when the pose is set
    /// (empty otherwise).
    #[must_use]
    pub fn weights(&self) -> &[f32] {
        self.weights.get(..self.set.2).unwrap_or(&[])
    }
}

/// `frame` within `group`'s range and the times the group has gone round to reach it: wrapped
/// when it loops, else clamped (and 0).
fn group_frame(group: &Group<'_>, frame: f32) -> (f32, f32) {
    let (from, to) = group.range();
    let length = to - from;
    if frame > to && group.loops() && length > 0.0 {
        let repeats = crate::math::floor_to_i32((frame - from) / length) as f32;
        (from + crate::math::fmod(frame - from, length), repeats)
    } else {
        (frame.clamp(from, to.max(from)), 0.0)
    }
}

/// Babylon.js's loop behaviours (`Animation.ANIMATIONLOOPMODE_*`, as [`Track::loop_mode`]).
const LOOP_RELATIVE: u8 = 0;
const LOOP_CONSTANT: u8 = 2;

/// `track`'s value at `(frame, repeats)` of a group's `(from, to)` (see [`group_frame`]), as
/// Babylon.js's `RuntimeAnimation` plays it once the group has gone round: a cycling track
/// starts again, a constant one holds its value at `to`, a relative one starts again from
/// where the last round ended (its value plus `repeats` times the change over the range).
fn track_value(track: &Track<'_>, (from, to): (f32, f32), (frame, repeats): (f32, f32)) -> Vec4 {
    let quaternion = matches!(track.target(), TrackTarget::Quaternion(_));
    let at = |f: f32| keys::value_at(track, f, quaternion);
    match track.loop_mode() {
        LOOP_CONSTANT if repeats > 0.0 => at(to),
        LOOP_RELATIVE if repeats > 0.0 => at(frame) + (at(to) - at(from)) * repeats,
        _ => at(frame),
    }
}

/// `Local = S · R · T` (Babylon, row vectors) as a glam matrix, from a node's columns as
/// [`Pose::rest`] keeps them.
fn local_matrix(trs: &Mat4) -> Mat4 {
    let rotation =
        if trs.w_axis.x != 0.0 { quaternion_matrix(trs.y_axis) } else { euler_matrix(trs.y_axis.truncate()) };
    let s = trs.z_axis;
    Mat4::from_cols(
        (rotation.x_axis * s.x).extend(0.0),
        (rotation.y_axis * s.y).extend(0.0),
        (rotation.z_axis * s.z).extend(0.0),
        trs.x_axis.truncate().extend(1.0),
    )
}

/// Babylon's `RotationYawPitchRoll(y, x, z)` (row vectors: `Rz · Rx · Ry`) as a glam matrix.
fn euler_matrix(angles: Vec3) -> Mat3 {
    Mat3::from_rotation_y(angles.y) * Mat3::from_rotation_x(angles.x) * Mat3::from_rotation_z(angles.z)
}

/// Babylon's `Matrix.FromQuaternion` (the quaternion as written, not normalised) as a glam
/// matrix.
fn quaternion_matrix(q: Vec4) -> Mat3 {
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, xw, yw, zw) = (x * y, x * z, y * z, x * w, y * w, z * w);
    Mat3::from_cols(
        Vec3::new(1.0 - 2.0 * (yy + zz), 2.0 * (xy + zw), 2.0 * (xz - yw)),
        Vec3::new(2.0 * (xy - zw), 1.0 - 2.0 * (zz + xx), 2.0 * (yz + xw)),
        Vec3::new(2.0 * (xz + yw), 2.0 * (yz - xw), 1.0 - 2.0 * (yy + xx)),
    )
}
