//! A pose as the draws of a frame see it ([`Renderer::draw_posed`](super::Renderer::draw_posed)):
//! the world matrix of each mesh that follows an animated node, and the morph targets'
//! weights that the vertex stage adds to a mesh's positions and normals. It does not evaluate
//! poses (`crate::animation` does).

use super::scratch::Digest;
use crate::animation::{Animation, Pose};
use crate::format::{Deforming, Model, WorldAt};
use crate::math::{Mat4, Vec3};

/// A set pose of a model's animation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Posed<'p> {
    pub(crate) pose: &'p Pose<'p>,
    pub(crate) animation: Animation<'p>,
}

impl<'p> Posed<'p> {
    /// The world matrix of mesh `mesh` in this pose, when it follows an animated node.
    pub(crate) fn mesh_world(&self, mesh: usize) -> Option<Mat4> {
        let (node, below) = self.animation.link_of(mesh)?;
        Some(self.pose.node_world(node)? * below)
    }

    /// How the pose moves mesh `mesh`'s vertices (morph targets, skin), when it does.
    pub(crate) fn deforming(&self, model: &Model<'p>, mesh: usize) -> Option<Deforming<'p>> {
        let morph = self.animation.morph_of(mesh).and_then(|m| Some((m, self.pose.weights().get(m.weights())?)));
        let skin = self.animation.skin_of(mesh).and_then(|s| {
            let palette = self.pose.palette().get(s.palette())?;
            Some((s, palette, model.mesh(mesh)?.dequantization()))
        });
        (morph.is_some() || skin.is_some()).then_some(Deforming { morph, skin })
    }

    /// Mixes the pose into `digest` (a scratch's rows and vertices depend on it).
    pub(crate) fn digest(&self, digest: u64) -> u64 {
        let mut d = Digest::resume(digest);
        d.floats(self.pose.weights());
        for m in self.pose.palette() {
            d.floats(&m.to_cols_array());
        }
        for node in 0..self.animation.node_count() {
            if let Some(m) = self.pose.node_world(node) {
                d.floats(&m.to_cols_array());
            }
        }
        d.finish()
    }
}

/// The world matrix of draw `d` of `model` (at `world`, see `Model::placed_draw`), posed
/// when `posed` moves it.
pub(crate) fn draw_world(posed: Option<&Posed<'_>>, model: &Model<'_>, d: usize, world: WorldAt) -> Mat4 {
    let moved = posed.filter(|_| d < model.mesh_count()).and_then(|p| p.mesh_world(d));
    moved.unwrap_or_else(|| model.world(world))
}

/// Vertex `i` of mesh `mesh` as a posed draw reads it (morph deltas, then the skin's blend of
/// bone matrices: `format::deform`), in the mesh's local units before its world matrix (what
/// `Transforms::new` multiplies); `None` when `pose` does not deform that mesh. For the tests'
/// float reference only (`testing`): the vertex stage's own results are not public.
#[must_use]
pub fn posed_position(model: &Model<'_>, pose: &Pose<'_>, mesh: usize, i: u32) -> Option<Vec3> {
    let posed = Posed { pose, animation: model.animation()? };
    let deforming = posed.deforming(model, mesh)?;
    let m = model.mesh(mesh)?;
    let p = m.arrays().morphed(&deforming).position_stored(i);
    // A skinned position is in local units already; a morphed one in stored units.
    Some(if deforming.skin.is_some() { p } else { m.dequantize().transform_point3(p) })
}
