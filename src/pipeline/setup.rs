//! What one draw of a mesh works with: its transforms (the model-view-projection matrix or its
//! integer form, the normal matrix, the integer lights) made once a draw, and the per-draw
//! constants every stage reads ([`DrawSetup`]). It does not transform vertices (`vertex` does)
//! or draw (`triangles` does).

use super::scratch::DrawChunks;
use super::{Context, GuardBand, TransformedVertex};
use crate::format::{Arrays, Deforming, Mesh};
use crate::light::FixedLights;
use crate::math::{normal_matrix, FixedTransform, Mat3, Mat4, Vec3};
use crate::target::GUARD_HALF_EXTENT;

/// Per-draw constants.
pub(crate) struct DrawSetup<'a, const L: usize> {
    /// The draw's transforms; `None` where every triangle fills from the vertex cache, which
    /// needs none (see `draw_mesh_with`). Borrowed: they live in the frame that made them
    /// (`transform_and_draw`, or the back-to-front draw's), not in the frame that draws from
    /// the cache.
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
    /// [`PreparedLights::fixed`](crate::light::PreparedLights::fixed)) and the normal matrix is
    /// a rotation; on every target, as it
    /// costs fewer instructions than f32 even with an FPU.
    pub(crate) fixed_lights: Option<FixedLights<L>>,
    /// Where clip space lands on the frame.
    pub(crate) projection: Projection,
}

/// Where clip space lands on the band's frame: half its width and height in pixels, and the
/// guard band in NDC units. With the transforms: only a draw that projects vertices needs it
/// (two divisions, soft-float without an FPU: not made in a band that draws from the vertex
/// cache).
#[derive(Clone, Copy)]
pub(crate) struct Projection {
    pub(crate) half: (f32, f32),
    pub(crate) guard: GuardBand,
}

impl Projection {
    /// The projection of `ctx`'s frame.
    fn of<const L: usize>(ctx: &Context<'_, L>) -> Self {
        let (w, h) = (ctx.window.width as f32, f32::from(ctx.height));
        Projection {
            half: (w * 0.5, h * 0.5),
            guard: GuardBand { gx: GUARD_HALF_EXTENT / (w * 0.5), gy: GUARD_HALF_EXTENT / (h * 0.5) },
        }
    }
}

/// How a draw's vertices reach clip space: one of two, never both (stack: the draw's frame lives
/// on under the rasterizer).
pub(crate) enum ClipTransform {
    /// The model-view-projection matrix, in f32.
    Float(Mat4),
    /// The integer transform and the bounding sphere it maps float positions into, with
    /// [`RenderOptions::fixed_vertices`](super::RenderOptions::fixed_vertices).
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
        projection: Projection { half: (1.0, 1.0), guard: GuardBand { gx: 1.0, gy: 1.0 } },
    };

    /// The transforms of `mesh` placed by `world` (see [`Transforms::placement`]); a mesh a
    /// pose deforms always in f32 (its positions move beyond the integer transform's sphere),
    /// a skinned one from local units (its arrays give them so). Not inlined: its matrix
    /// temporaries stay out of the caller's frame.
    #[inline(never)]
    pub(crate) fn new(ctx: &Context<'_, L>, mesh: &Mesh<'_>, world: &Mat4, deform: Option<&Deforming<'_>>) -> Self {
        let morphed = deform.is_some();
        let model_q = match deform.and_then(|d| d.skin) {
            Some(_) => *world,
            None => dequantized(world, mesh.dequantization()),
        };
        let normals = normal_matrix(world);
        let (mvp, sphere) = (ctx.frame.vp * model_q, mesh.bounding_sphere());
        let fixed = (ctx.opts.fixed_vertices && !morphed).then_some(()).and_then(|()| {
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
            projection: Projection::of(ctx),
        }
    }
}

impl<const L: usize> Transforms<L> {
    /// The world matrix of `mesh` placed by `place()` (`transform · world`), and whether it
    /// mirrors; with `test_view`, `None` when the mesh's bounding sphere is out of view (see
    /// [`sphere_visible`]). The matrix made once for the view test and the transforms
    /// ([`Transforms::new`]; soft-float without an FPU: a product is about 4,000 instructions
    /// on Armv6-M). Not inlined, and the transforms made by the caller, not here: their frames
    /// side by side, not one under the other (the stack).
    #[inline(never)]
    pub(crate) fn placement(
        ctx: &Context<'_, L>,
        mesh: &Mesh<'_>,
        place: impl FnOnce() -> Mat4,
        test_view: bool,
    ) -> Option<(Mat4, bool)> {
        let world = place();
        // A skinned mesh's bones move its vertices anywhere: its rest sphere proves nothing.
        let skinned = ctx.frame.posed.as_ref().is_some_and(|p| p.animation.skin_of(mesh.mesh_index()).is_some());
        if test_view && !skinned && !sphere_visible(&ctx.frame.vp, &world, mesh.bounding_sphere()) {
            return None;
        }
        Some((world, Mat3::from_mat4(world).determinant() < 0.0))
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
    /// transform mirrors, as [`Transforms::placement`] found it.
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

/// `world · dequantize` for a mesh's dequantization (scale and offset): the product's columns
/// without its multiplications by zero, the same values as the whole product for a finite
/// `world` (but for the
/// sign of a zero).
fn dequantized(world: &Mat4, (scale, offset): (Vec3, Vec3)) -> Mat4 {
    Mat4::from_cols(
        world.x_axis * scale.x,
        world.y_axis * scale.y,
        world.z_axis * scale.z,
        world.x_axis * offset.x + world.y_axis * offset.y + world.z_axis * offset.z + world.w_axis,
    )
}

/// Whether a local-space bounding sphere, placed by `world`, may be inside the view frustum.
fn sphere_visible(vp: &Mat4, world: &Mat4, (centre, radius): (Vec3, f32)) -> bool {
    let c = world.transform_point3(centre);
    let r = radius * crate::math::max_axis_scale(world);
    let rows = [vp.row(0), vp.row(1), vp.row(2), vp.row(3)];
    let planes = [
        rows[3] + rows[0],
        rows[3] - rows[0],
        rows[3] + rows[1],
        rows[3] - rows[1],
        rows[3] + rows[2],
        rows[3] - rows[2],
    ];
    planes.iter().all(|p| {
        let n = p.truncate().length();
        // A NaN anywhere makes `outside` false: draw, and let clipping cull per triangle.
        let outside = p.truncate().dot(c) + p.w < -r * n;
        !outside
    })
}
