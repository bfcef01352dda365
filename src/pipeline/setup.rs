//! What one draw of a mesh works with: its transforms (the model-view-projection matrix or its
//! integer form, the normal matrix, the integer lights) made once a draw, and the per-draw
//! constants every stage reads ([`DrawSetup`]). It does not transform vertices (`vertex` does)
//! or draw (`triangles` does).

use super::scratch::DrawChunks;
use super::{Context, TransformedVertex};
use crate::format::{Arrays, Mesh};
use crate::light::FixedLights;
use crate::math::{normal_matrix, FixedTransform, Mat3, Mat4, Vec3};

/// Per-draw constants.
pub(crate) struct DrawSetup<'a, const L: usize> {
    /// The draw's transforms; `None` where every triangle fills from the vertex cache, which
    /// needs none (see `draw_mesh_with`). Borrowed: they live in the frame that made them
    /// (`transform_and_draw`), not in the frame that draws from the cache.
    transforms: Option<&'a Transforms<L>>,
    pub(crate) flip: bool,
    pub(crate) uv: ([f32; 2], [f32; 2]),
    pub(crate) mesh: Mesh<'a>,
    pub(crate) arrays: Arrays<'a>,
    /// The draw's filled vertex cache, when it has one (see `vertex::fill_cache`).
    pub(crate) vertices: Option<&'a [TransformedVertex]>,
    /// The summaries of its rows in the scratch, when made (see `triangles::draw_touching`).
    pub(crate) chunks: Option<DrawChunks<'a>>,
}

/// What a draw transforms and lights vertices with: matrices, and their integer forms.
pub(crate) struct Transforms<const L: usize> {
    pub(crate) clip: ClipTransform,
    pub(crate) model_q: Mat4,
    pub(crate) normals: Mat3,
    /// `normals` is a rotation (to 1e-6): stored unit normals stay unit, no normalising.
    pub(crate) rotation: bool,
    /// Gouraud vertex light in integers, whenever the lights allow it (see
    /// [`PreparedLights::fixed`]) and the normal matrix is a rotation; on every target, as it
    /// costs fewer instructions than f32 even with an FPU.
    pub(crate) fixed_lights: Option<FixedLights<L>>,
}

/// How a draw's vertices reach clip space: one of two, never both (stack: the draw's frame lives
/// on under the rasterizer).
pub(crate) enum ClipTransform {
    /// The model-view-projection matrix, in f32.
    Float(Mat4),
    /// The integer transform and the bounding sphere it maps float positions into, with
    /// [`RenderOptions::fixed_vertices`].
    Fixed(FixedTransform, (Vec3, f32)),
}

impl<const L: usize> Transforms<L> {
    /// What [`DrawSetup::transforms`] gives a draw that has none (it never asks: see there).
    const NONE: Self = Transforms {
        clip: ClipTransform::Float(Mat4::IDENTITY),
        model_q: Mat4::IDENTITY,
        normals: Mat3::IDENTITY,
        rotation: true,
        fixed_lights: None,
    };

    /// The transforms of `mesh` placed by `world`.
    fn new(ctx: &Context<'_, L>, mesh: &Mesh<'_>, world: &Mat4) -> Self {
        let model_q = *world * mesh.dequantize();
        let normals = normal_matrix(world);
        let (mvp, sphere) = (ctx.frame.vp * model_q, mesh.bounding_sphere());
        let fixed = ctx.opts.fixed_vertices.then_some(()).and_then(|()| {
            let (offset, step) = mesh.arrays().int_position_frame(sphere);
            FixedTransform::new(&mvp, offset, step)
        });
        let clip = match fixed {
            Some(fixed) => ClipTransform::Fixed(fixed, sphere),
            None => ClipTransform::Float(mvp),
        };
        let rotation = crate::math::is_rotation(&normals);
        let integer_light = rotation && !ctx.frame.lit_by_position;
        Transforms {
            clip,
            fixed_lights: integer_light.then(|| ctx.frame.vertex_lights.fixed(&normals)).flatten(),
            model_q,
            normals,
            rotation,
        }
    }
}

impl<const L: usize> Transforms<L> {
    /// The transforms of `mesh` placed by `place()` (`transform · world`), and whether that
    /// mirrors. Not inlined, and the matrix made here: it and its temporaries stay out of the
    /// caller's frame.
    #[inline(never)]
    pub(crate) fn placed(ctx: &Context<'_, L>, mesh: &Mesh<'_>, place: impl FnOnce() -> Mat4) -> (Self, bool) {
        let world = place();
        (Transforms::new(ctx, mesh, &world), Mat3::from_mat4(world).determinant() < 0.0)
    }
}

impl<'a, const L: usize> DrawSetup<'a, L> {
    /// The draw of `mesh` with `transforms`, whose transform mirrors when `flip`.
    #[inline(always)]
    pub(crate) fn new(mesh: Mesh<'a>, transforms: &'a Transforms<L>, flip: bool) -> Self {
        Self::with(Some(transforms), mesh, flip)
    }

    /// [`DrawSetup::new`] without the transforms, for a band that fills every triangle from the
    /// vertex cache and so needs none (see `draw_mesh_with`); `flip`: whether the draw's
    /// transform mirrors, as `new` found it.
    #[inline(always)]
    pub(crate) fn without_transforms(mesh: Mesh<'a>, flip: bool) -> Self {
        Self::with(None, mesh, flip)
    }

    /// This draw with `transforms`, its own borrowed anew (see `vertex::fill_cache`).
    #[inline(always)]
    pub(crate) fn with_transforms<'b>(&self, transforms: &'b Transforms<L>) -> DrawSetup<'b, L>
    where
        'a: 'b,
    {
        DrawSetup { transforms: Some(transforms), ..*self }
    }

    #[inline(always)]
    fn with(transforms: Option<&'a Transforms<L>>, mesh: Mesh<'a>, flip: bool) -> Self {
        DrawSetup {
            transforms,
            flip,
            uv: mesh.uv_transform(),
            arrays: mesh.arrays(),
            mesh,
            vertices: None,
            chunks: None,
        }
    }

    /// The draw's transforms. A setup made without them is never asked: it draws only
    /// triangles whose corners are all in the vertex cache and none needs clipping (and if it
    /// were, the identity is no panic).
    #[inline]
    pub(crate) fn transforms(&self) -> &Transforms<L> {
        debug_assert!(self.transforms.is_some(), "transforms asked of a draw made without them");
        self.transforms.unwrap_or(&Transforms::NONE)
    }
}
