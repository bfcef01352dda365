//! How a pose moves a mesh's vertices as [`Arrays`](super::Arrays) reads them
//! ([`Deforming`]): its morph targets' deltas with their weights, then its skin's blend of
//! bone matrices (Babylon.js's order: morph, then skin). Cold and out of line: still meshes
//! only test that there is none.

use super::animation::{weight_of, Morph, Skin, WEIGHT_ONE};
use super::layout::NORMAL_ONE;
use crate::math::{normalize_or_zero, Mat4, Vec3};

/// A pose's deformation of one mesh.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Deforming<'a> {
    /// Its morph targets and their weights (one a target).
    pub(crate) morph: Option<(Morph<'a>, &'a [f32])>,
    /// Its skin, with the pose's bone matrices (one a bone) and the mesh's dequantization
    /// (scale, offset): a skinned position is in local units, not stored ones.
    pub(crate) skin: Option<(Skin<'a>, &'a [Mat4], (Vec3, Vec3))>,
}

impl Deforming<'_> {
    /// The weighted sum of vertex `i`'s position (or normal) deltas; targets weighing 0 skipped.
    fn morph_sum(&self, i: u32, normal: bool) -> Vec3 {
        let Some((morph, weights)) = self.morph else { return Vec3::ZERO };
        let mut sum = Vec3::ZERO;
        for (t, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                sum += morph.delta(t, i, normal) * w;
            }
        }
        sum
    }

    /// Vertex `i`'s blend of bone matrices, `Σ wₖ · palette[bone k]`: the bone's own matrix
    /// for a vertex that one bone moves alone (all of a rigid character's), no sum.
    fn blend(&self, i: u32) -> Option<Mat4> {
        let (skin, palette, _) = self.skin?;
        let (bones, weights) = skin.stored_influences(i);
        let bone = |k: usize| palette.get(usize::from(bones[k])).copied();
        if weights == [WEIGHT_ONE, 0, 0, 0] {
            return bone(0);
        }
        let mut m = Mat4::ZERO;
        for (k, &w) in weights.iter().enumerate() {
            if w != 0 {
                m += bone(k)? * weight_of(w);
            }
        }
        Some(m)
    }

    /// Vertex `i` at stored position `p`, deformed: in stored units when only morphed, in local
    /// units when skinned (its draw's transforms then dequantize nothing).
    #[cold]
    #[inline(never)]
    pub(crate) fn position(&self, p: Vec3, i: u32) -> Vec3 {
        let p = p + self.morph_sum(i, false);
        match self.skin {
            Some((_, _, (scale, offset))) => {
                let local = offset + p * scale;
                self.blend(i).map_or(local, |m| m.transform_point3(local))
            }
            None => p,
        }
    }

    /// Vertex `i`'s normal `n`, deformed and normalised (as Babylon.js's shader does).
    #[cold]
    #[inline(never)]
    pub(crate) fn normal(&self, n: Vec3, i: u32) -> Vec3 {
        let moved = self.morph.is_some_and(|(m, _)| m.has_normals());
        let n = if moved { normalize_or_zero(n + self.morph_sum(i, true)) } else { n };
        match self.blend(i) {
            Some(m) => normalize_or_zero(m.transform_vector3(n)),
            None => n,
        }
    }

    /// A unit normal quantized as stored ([`NORMAL_ONE`] for 1, rounded).
    #[cold]
    #[inline(never)]
    pub(crate) fn normal_q(&self, n: Vec3) -> [i16; 3] {
        let n = n * NORMAL_ONE;
        [n.x, n.y, n.z].map(|c| crate::math::to_i32(c + if c < 0.0 { -0.5 } else { 0.5 }) as i16)
    }
}
