//! Per-vertex work: fetch a vertex, transform it (f32, or integers on FPU-less targets), light
//! it (Gouraud), project it to the screen (snapped position, depth, `1/w`, outcode) and build the
//! varyings a triangle carries to its pixels. With a vertex cache ([`Scratch::with_vertices`](
//! super::Scratch::with_vertices)) each vertex is done once a frame. It does not decide what is
//! culled or clipped (`primitive` does).

use super::clip::{outcode, ClipVertex, NEEDS_CLIP, NOT_FINITE};
use super::raster::ScreenVertex;
use super::scratch::{TransformedVertex, UNKNOWN_INV_W};
use super::setup::Projection;
use super::varyings::{ClipVaryings, PixelLit, ScreenVaryings, VertexLit, MAX_VARYINGS};
use super::{ClipTransform, Context, DrawSetup, Shading, Transforms};
use crate::fixed::{fdot4_floor, FDot16, FDot4, FDOT16_ONE};
use crate::math::{
    normalize_or_zero, offset_add, times_power_of_two, u16_times, FixedTransform, Mat4, Vec3, Vec4, F32,
};
use crate::texture::Sampler;

mod integer;

/// Light (red, green, blue) and specular intensity reaching a vertex, 0..=65535 for 0..=1
/// (the varyings' 16.16 scale, with 1.0 itself saturated: the pixel loop clamps light to
/// 65535 anyway). Specular has 8 bits (a multiple of 257): it only ever scales an 8-bit
/// highlight colour.
pub(crate) type VertexLight = [u16; 4];

/// Quantizes light values in 0..=1 (red, green, blue, specular) to [`VertexLight`]. Light
/// outside 0..=1 (or NaN) quantizes as if clamped to it first: to 0 or 65535, as the rounding
/// `x · 65536 + 0.5` is monotonic and the integer clamp takes what it gives below 0 or above
/// 65535 (NaN converts to 0).
pub(crate) fn quantize_light([r, g, b, specular]: [f32; 4]) -> VertexLight {
    // Saturating, as `as u16` would, in integer code without an FPU.
    let [r, g, b] = [r, g, b].map(|x| crate::math::to_i32(x * FDOT16_ONE + 0.5).clamp(0, 0xffff) as u16);
    [r, g, b, crate::math::to_i32(specular * 255.0 + 0.5).clamp(0, 255) as u16 * 257]
}

/// What the unclipped path needs of a clip-space vertex: its snapped screen position (28.4),
/// depth (0..=1) and `1/w`, meaningful when `1/w` is positive and finite, and its
/// [`outcode`]. Triangles that need clipping transform their vertices again.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Projected {
    pub(crate) x: FDot4,
    pub(crate) y: FDot4,
    pub(crate) z: f32,
    pub(crate) inv_w: f32,
    pub(crate) outcode: u8,
}

impl Projected {
    /// Inlined: into `fill_cache`'s loop above all (out of line there: +28k instructions in
    /// the Cortex-M4F reference frame).
    #[inline(always)]
    pub(crate) fn new(p: &Projection, clip: Vec4) -> Self {
        let xy = project_xy(clip, p.half);
        Projected { x: xy.x, y: xy.y, z: depth(clip, xy.inv_w), inv_w: xy.inv_w, outcode: outcode(clip, &p.guard) }
    }

    /// This vertex on the screen, carrying `varyings`.
    #[inline(always)]
    pub(crate) fn screen_vertex(&self, varyings: ScreenVaryings) -> ScreenVertex {
        ScreenVertex { x: self.x, y: self.y, z: self.z, inv_w: self.inv_w, varyings }
    }
}

/// Vertex `i` in clip space.
#[inline(always)]
pub(crate) fn clip_position<const L: usize>(s: &DrawSetup<'_, L>, i: u32) -> Vec4 {
    match &s.transforms().clip {
        ClipTransform::Fixed(t, sphere) => t.apply(s.arrays.position_int(i, *sphere)),
        ClipTransform::Float(mvp) => float_clip_position::<L, true>(s, mvp, i),
    }
}

/// [`clip_position`] with the f32 transform `mvp` (morphed when `M`: see
/// [`Arrays::position_as`](crate::format::Arrays::position_as)).
#[inline(always)]
fn float_clip_position<const L: usize, const M: bool>(s: &DrawSetup<'_, L>, mvp: &Mat4, i: u32) -> Vec4 {
    *mvp * s.arrays.position_as::<M>(i).extend(1.0)
}

/// Vertex `i` in world space.
pub(crate) fn world_position<const L: usize>(s: &DrawSetup<'_, L>, i: u32) -> Vec3 {
    world_position_as::<L, true>(s, i)
}

/// [`world_position`], morphed when `M`.
#[inline(always)]
fn world_position_as<const L: usize, const M: bool>(s: &DrawSetup<'_, L>, i: u32) -> Vec3 {
    s.transforms().model_q.transform_point3(s.arrays.position_as::<M>(i))
}

/// Vertex `i`'s world-space unit normal.
#[inline(always)]
pub(crate) fn world_normal<const L: usize>(s: &DrawSetup<'_, L>, i: u32) -> Vec3 {
    world_normal_as::<L, true>(s, i)
}

/// [`world_normal`], morphed when `M`.
#[inline(always)]
fn world_normal_as<const L: usize, const M: bool>(s: &DrawSetup<'_, L>, i: u32) -> Vec3 {
    let t = s.transforms();
    let n = t.normals * s.arrays.normal_as::<M>(i);
    if t.rotation {
        n
    } else {
        normalize_or_zero(n)
    }
}

/// Gouraud light of vertex `i` (zero for the other shadings, which do not use it).
#[inline(always)]
pub(crate) fn vertex_light<const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'_, L>, i: u32) -> VertexLight {
    if ctx.opts.shading != Shading::Gouraud {
        return [0; 4];
    }
    if let Some(lights) = &s.transforms().fixed_lights {
        let [r, g, b] = lights.at(s.arrays.normal_q(i));
        return [r, g, b, 0];
    }
    float_vertex_light::<L, true>(ctx, s, i)
}

/// [`vertex_light`] of a Gouraud-lit vertex without the integer lights.
#[inline(always)]
fn float_vertex_light<const L: usize, const M: bool>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    i: u32,
) -> VertexLight {
    let n = world_normal_as::<L, M>(s, i);
    // Directional and hemispheric light need no position.
    let p = if ctx.frame.lit_by_position { world_position_as::<L, M>(s, i) } else { Vec3::ZERO };
    // Clamped by the quantization.
    let l = ctx.frame.vertex_lights.unclamped_at(p, n);
    quantize_light([l.x, l.y, l.z, specular(ctx, p, n)])
}

/// [`Lights::specular_at`](crate::light::Lights::specular_at), skipped (0) without specular.
#[inline(always)]
fn specular<const L: usize>(ctx: &Context<'_, L>, p: Vec3, n: Vec3) -> f32 {
    // Without point lights or specular, specular is off: what `specular_at` would find.
    if ctx.frame.lit_by_position {
        ctx.frame.lights.specular_at(p, n, ctx.frame.eye)
    } else {
        0.0
    }
}

/// The light of unlit corners (and of Phong's, which light per pixel instead): full white.
const WHITE: VertexLight = [u16::MAX, u16::MAX, u16::MAX, 0];

/// Vertex `i` transformed and projected, not lit: for triangles drawn without the vertex cache.
/// Not inlined: it runs for the rare triangles that need clipping, and for draws without a
/// cache.
#[inline(never)]
pub(crate) fn projected<const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'_, L>, i: u32) -> Projected {
    match &s.transforms().clip {
        ClipTransform::Fixed(t, sphere) => fixed_projected(ctx, s, (t, sphere), i),
        ClipTransform::Float(mvp) => {
            Projected::new(&s.transforms().projection, float_clip_position::<L, true>(s, mvp, i))
        }
    }
}

/// Vertex `i` projected with the integer transform `t` and bounding sphere `sphere`: in
/// integers from the transform's exact sums where it is inside the view volume
/// ([`integer::project`]), else in f32 from its clip-space position. Every path that projects
/// a vertex of such a draw comes here (see `integer`).
#[inline(always)]
fn fixed_projected<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    (t, sphere): (&FixedTransform, &(Vec3, f32)),
    i: u32,
) -> Projected {
    let q = s.arrays.position_int(i, *sphere);
    integer::project(t.sums(q), t.exponents(), ctx.half_16)
        .unwrap_or_else(|| Projected::new(&s.transforms().projection, t.apply(q)))
}

/// The Gouraud light of corners `idx` (see [`vertex_light`]). Not inlined, as [`projected`].
#[inline(never)]
fn vertex_lights<const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'_, L>, idx: &[u32; 3]) -> [VertexLight; 3] {
    idx.map(|i| vertex_light(ctx, s, i))
}

/// Fills a draw's vertex cache, every vertex transformed, projected and lit with texel
/// coordinates for the texel scale `scale` ([`texel_scale`]), unless this frame already did
/// (its first vertex is known). All at once rather than on first use: the loops keep the
/// matrices and lights at hand (positions in one, light in another, so that each has registers
/// enough), and a triangle's corners are then plain loads. A first vertex whose `1/w` really
/// is +0 only makes every band fill it again, with the same results. Whether it filled it now
/// with no vertex that needs clipping (or is not finite). Not inlined: its frame is gone before
/// the triangles are drawn (the deepest stack).
#[inline(never)]
pub(crate) fn fill_cache<const L: usize>(
    ctx: &Context<'_, L>,
    (s, t): (&DrawSetup<'_, L>, &Transforms<L>),
    cache: &mut [TransformedVertex],
    scale: (f32, f32),
) -> bool {
    if is_filled(cache) {
        return false;
    }
    // The draw's transforms `t` as an argument, which LLVM knows no write to the cache
    // changes: read through `s`, they would be loaded again after every vertex's writes
    // (Cortex-M4F reference frame: +12k instructions).
    let s = &s.with_transforms(t);
    // A still mesh's loops without the morph's test (see `Arrays::position_as`).
    if s.arrays.is_morphed() {
        fill_morphed(ctx, (s, t), cache, scale)
    } else {
        fill_all::<L, false>(ctx, (s, t), cache, scale)
    }
}

/// [`fill_cache`] of a morphed mesh. Not inlined: a second copy of the loops.
#[inline(never)]
fn fill_morphed<const L: usize>(
    ctx: &Context<'_, L>,
    st: (&DrawSetup<'_, L>, &Transforms<L>),
    cache: &mut [TransformedVertex],
    scale: (f32, f32),
) -> bool {
    fill_all::<L, true>(ctx, st, cache, scale)
}

/// [`fill_cache`]'s loops for draw `s` with its transforms `t`, morphed when `M`.
#[inline(always)]
fn fill_all<const L: usize, const M: bool>(
    ctx: &Context<'_, L>,
    (s, t): (&DrawSetup<'_, L>, &Transforms<L>),
    cache: &mut [TransformedVertex],
    scale: (f32, f32),
) -> bool {
    // One loop per case, its tests made once: the loops keep more of the matrices in registers.
    match &t.clip {
        ClipTransform::Fixed(fixed, sphere) => fill_fixed_positions(ctx, s, (fixed, sphere), cache, scale),
        ClipTransform::Float(mvp) => {
            fill_positions(s, cache, scale, |i| Projected::new(&t.projection, float_clip_position::<L, M>(s, mvp, i)))
        }
    }
    match ctx.opts.shading {
        Shading::Unlit => fill_light(cache, |i| coloured_light(s, i, WHITE)),
        Shading::Gouraud => match &t.fixed_lights {
            // One light (the common case) with no loop over the lights at each vertex.
            Some(lights) => match lights.one() {
                Some(one) => fill_fixed_light::<L, M>(s, cache, |n| one.at(n)),
                None => fill_fixed_light::<L, M>(s, cache, |n| lights.at(n)),
            },
            None => fill_light(cache, |i| coloured_light(s, i, float_vertex_light::<L, M>(ctx, s, i))),
        },
        Shading::Flat | Shading::Phong => fill_light(cache, |i| coloured_light(s, i, [0; 4])),
    }
    cache.iter().fold(0, |o, v| o | v.outcode) & (NEEDS_CLIP | NOT_FINITE) == 0
}

/// Whether `cache` was filled this frame (see [`fill_cache`]).
#[inline(always)]
pub(crate) fn is_filled(cache: &[TransformedVertex]) -> bool {
    cache.first().is_some_and(|v| v.inv_w.to_bits() != UNKNOWN_INV_W)
}

/// [`fill_cache`]'s positions with the integer transform. Out of line: its integer projection
/// would otherwise share a frame (and registers) with the f32 loop beside it.
#[inline(never)]
fn fill_fixed_positions<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    fixed: (&FixedTransform, &(Vec3, f32)),
    cache: &mut [TransformedVertex],
    scale: (f32, f32),
) {
    fill_positions(s, cache, scale, |i| fixed_projected(ctx, s, fixed, i));
}

/// [`fill_cache`]'s positions, with `projected` giving a vertex's projection.
#[inline(always)]
fn fill_positions<const L: usize>(
    s: &DrawSetup<'_, L>,
    cache: &mut [TransformedVertex],
    scale: (f32, f32),
    projected: impl Fn(u32) -> Projected,
) {
    let texels = TexelConversion::new(s, scale);
    for (i, v) in (0u32..).zip(cache.iter_mut()) {
        *v = TransformedVertex::new(projected(i), texels.cached(s, i));
    }
}

/// [`fill_cache`]'s light varyings, with `light` giving a vertex's: the corner light of the
/// shadings that light per vertex or not at all (zero for flat and Phong, which light
/// otherwise), times its colour.
#[inline(always)]
fn fill_light(cache: &mut [TransformedVertex], light: impl Fn(u32) -> VertexLight) {
    for (i, v) in (0u32..).zip(cache.iter_mut()) {
        v.set_light(light(i));
    }
}

/// [`fill_light`] with Gouraud light in integers, `at` giving a stored normal's light.
#[inline(always)]
fn fill_fixed_light<const L: usize, const M: bool>(
    s: &DrawSetup<'_, L>,
    cache: &mut [TransformedVertex],
    at: impl Fn([i16; 3]) -> [u16; 3],
) {
    fill_light(cache, |i| {
        let [r, g, b] = at(s.arrays.normal_q_as::<M>(i));
        coloured_light(s, i, [r, g, b, 0])
    });
}

/// The corners `idx` in a filled cache (see [`fill_cache`]); `None` when one is beyond it (a
/// draw gets its mesh's whole cache or none, and `Model::parse` refuses indices beyond the
/// vertices, so only if either changes).
#[inline(always)]
pub(crate) fn cached_corners<'c>(cache: &'c [TransformedVertex], idx: &[u32; 3]) -> Option<[&'c TransformedVertex; 3]> {
    let [a, b, c] = idx.map(|i| cache.get(i as usize));
    Some([a?, b?, c?])
}

/// `light` times vertex `i`'s colour, as the varyings carry it: red, green and blue scaled (see
/// [`coloured_fixed`]), specular as is.
#[inline(always)]
pub(crate) fn coloured_light<const L: usize>(s: &DrawSetup<'_, L>, i: u32, light: VertexLight) -> VertexLight {
    if !s.arrays.has_colors() {
        return light;
    }
    let c = s.arrays.color(i);
    // At most the light itself (a colour channel is at most 1): within u16.
    let [r, g, b] = [0, 1, 2].map(|ch| coloured_fixed(light[ch], c[ch]) as u16);
    [r, g, b, light[3]]
}

/// The light (and specular) of each corner for the vertex-lit shadings: per vertex (Gouraud),
/// per face (flat) or full white (unlit, and Phong, which lights per pixel instead); not
/// yet times the vertex colours.
#[inline(always)]
pub(crate) fn corner_lights<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    idx: &[u32; 3],
) -> [VertexLight; 3] {
    match ctx.opts.shading {
        Shading::Unlit | Shading::Phong => [WHITE; 3],
        Shading::Flat => [face_light(ctx, s, idx); 3],
        Shading::Gouraud => vertex_lights(ctx, s, idx),
    }
}

/// The light varyings of flat-lit triangle `idx`'s corners: its face light times each
/// corner's colour.
#[inline(always)]
pub(crate) fn flat_corner_lights<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    idx: &[u32; 3],
) -> [VertexLight; 3] {
    let light = face_light(ctx, s, idx);
    idx.map(|i| coloured_light(s, i, light))
}

/// The flat light of triangle `idx`. Not inlined: the common (Gouraud) path stays small.
#[inline(never)]
fn face_light<const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'_, L>, idx: &[u32; 3]) -> VertexLight {
    // Face normal from the world-space triangle. Front faces wind counter-clockwise as seen
    // (y up), and with +z pointing away from the viewer that makes (p2-p0) x (p1-p0) point
    // towards the viewer, i.e. outward.
    let p = idx.map(|i| world_position(s, i));
    let mut n = normalize_or_zero((p[2] - p[0]).cross(p[1] - p[0]));
    if s.flip {
        n = -n;
    }
    let centre = (p[0] + p[1] + p[2]) / 3.0;
    // Clamped by the quantization.
    let l = ctx.frame.vertex_lights.unclamped_at(centre, n);
    quantize_light([l.x, l.y, l.z, specular(ctx, centre, n)])
}

/// The size of `sampler`'s texture in [`FDot16`](crate::fixed::FDot16) texels (zero without
/// one): what [`texel`] scales texture coordinates by.
pub(crate) fn texel_scale(sampler: Option<&Sampler<'_>>) -> (f32, f32) {
    sampler.map_or((0.0, 0.0), |sm| (sm.width() as f32 * FDOT16_ONE, sm.height() as f32 * FDOT16_ONE))
}

/// Vertex `i`'s texel coordinates (u, v) in f32, scaled by [`texel_scale`].
#[inline(always)]
pub(crate) fn texel<const L: usize>(s: &DrawSetup<'_, L>, i: u32, (width, height): (f32, f32)) -> [f32; 2] {
    let (uv, (o, sc)) = (s.arrays.uv_q(i), s.uv);
    // In `F32`: once per vertex, but library calls without an FPU (but for a power-of-two
    // size, the usual texture).
    let at = |k: usize, size: f32| times_power_of_two(offset_add(o[k], u16_times(uv[k], sc[k])), size);
    [at(0, width), at(1, height)]
}

/// How [`fill_positions`] converts a mesh's texel coordinates for the cache: with the texel
/// scale (see [`texel_scale`]) and, without an FPU, the factors of the integer step taken
/// apart once for all the mesh's vertices.
#[derive(Clone, Copy)]
struct TexelConversion {
    scale: (f32, f32),
    /// Where the offset is +0 (the usual case) and the sizes powers of two, the exact integer
    /// step's factors for `u` and `v` ([`U16Scale`]: the same integers as the float path).
    #[cfg(soft_float)]
    exact: Option<[crate::math::U16Scale; 2]>,
}

impl TexelConversion {
    /// The conversion of draw `s`'s texel coordinates with texel scale `scale`.
    #[inline(always)]
    fn new<const L: usize>(s: &DrawSetup<'_, L>, scale: (f32, f32)) -> Self {
        #[cfg(soft_float)]
        {
            let (o, sc) = s.uv;
            let factors =
                |k: usize, size: f32| (o[k].to_bits() == 0).then(|| crate::math::U16Scale::new(sc[k], size)).flatten();
            let exact = factors(0, scale.0).zip(factors(1, scale.1)).map(|(u, v)| [u, v]);
            TexelConversion { scale, exact }
        }
        #[cfg(not(soft_float))]
        {
            let _ = s;
            TexelConversion { scale }
        }
    }

    /// Vertex `i`'s texel coordinates as the cache keeps them: [`texel`] converted to 16.16
    /// (saturating), and whether both were finite; without an FPU, in one integer step where
    /// [`TexelConversion::exact`] allows it.
    // Left to the compiler with an FPU (Cortex-M4F reference frame -1.8k instructions), inlined
    // without one (thumbv6m +30k otherwise): measured, as register allocation decides it.
    #[cfg_attr(soft_float, inline(always))]
    fn cached<const L: usize>(&self, s: &DrawSetup<'_, L>, i: u32) -> ([FDot16; 2], bool) {
        #[cfg(soft_float)]
        if let Some([u, v]) = self.exact {
            let uv = s.arrays.uv_q(i);
            if let (Some(u), Some(v)) = (u.times_to_i32(uv[0]), v.times_to_i32(uv[1])) {
                return ([u, v], true);
            }
        }
        let t = texel(s, i, self.scale);
        (t.map(crate::math::to_i32), t[0].is_finite() & t[1].is_finite())
    }
}

/// One light channel times the vertex colour's channel `c` (255 for 1).
#[inline(always)]
fn coloured(light: u16, c: u8) -> f32 {
    // White (no vertex colours) scales by exactly 1: skip the division.
    if c == 255 {
        light as f32
    } else {
        light as f32 * (c as f32 / 255.0)
    }
}

/// [`coloured`] converted to fixed point: for white, the light itself, which is what the float
/// product converts to (a 16-bit integer is exact in f32), without float operations (as for
/// meshes without vertex colours, which are white).
#[inline(always)]
fn coloured_fixed(light: u16, c: u8) -> i32 {
    if c == 255 {
        i32::from(light)
    } else {
        crate::math::to_i32(coloured(light, c))
    }
}

/// The varyings of an unclipped, vertex-lit corner, converted as [`project`] converts them:
/// texel coordinates (saturating), light varyings ([`coloured_light`]), specular; the slots no
/// vertex-lit variant reads stay zero. `texel`: the corner's [`texel`], already checked finite.
#[inline(always)]
pub(crate) fn vertex_lit_screen(texel: [f32; 2], light: VertexLight) -> ScreenVaryings {
    vertex_lit_varyings(texel.map(crate::math::to_i32), light)
}

/// The varyings of a vertex-lit corner from its texel coordinates (16.16) and light varyings.
#[inline(always)]
pub(crate) fn vertex_lit_varyings(texel: [FDot16; 2], light: VertexLight) -> ScreenVaryings {
    let mut v = [0; MAX_VARYINGS];
    v[VertexLit::U] = texel[0];
    v[VertexLit::V] = texel[1];
    for ch in 0..3 {
        v[VertexLit::LIGHT + ch] = i32::from(light[ch]);
    }
    v[VertexLit::SPECULAR] = i32::from(light[3]);
    v
}

/// The triangle's varyings for the shading mode (see the slot constants), in f32 for clipping.
/// `scale`: [`texel_scale`].
pub(crate) fn vertex_varyings<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    idx: &[u32; 3],
    scale: (f32, f32),
) -> [ClipVaryings; 3] {
    let phong = ctx.opts.shading == Shading::Phong;
    let lit = if phong { [[0; 4]; 3] } else { corner_lights(ctx, s, idx) };
    core::array::from_fn(|k| {
        let mut varyings = [0.0; MAX_VARYINGS];
        varyings[VertexLit::U..=VertexLit::V].copy_from_slice(&texel(s, idx[k], scale));
        if phong {
            let n = world_normal(s, idx[k]);
            varyings[PixelLit::NORMAL..PixelLit::NORMAL + 3].copy_from_slice(&(n * FDOT16_ONE).to_array());
            let p = world_position(s, idx[k]) * FDOT16_ONE;
            varyings[PixelLit::POSITION..PixelLit::POSITION + 3].copy_from_slice(&p.to_array());
        } else {
            let c = s.arrays.color(idx[k]);
            for ch in 0..3 {
                varyings[VertexLit::LIGHT + ch] = coloured(lit[k][ch], c[ch]);
            }
            varyings[VertexLit::SPECULAR] = lit[k][3] as f32;
        }
        varyings
    })
}

/// Clip space to screen: viewport mapping, 1/16-pixel snapping, fixed-point varyings.
pub(crate) fn project(v: &ClipVertex, half: (f32, f32)) -> ScreenVertex {
    let xy = project_xy(v.pos, half);
    // Saturating casts: huge UVs clamp instead of wrapping.
    ScreenVertex { z: depth(v.pos, xy.inv_w), varyings: v.varyings.map(crate::math::to_i32), ..xy }
}

/// Depth (0..=1, near to far) of a clip-space point whose `1/w` is `inv_w`.
#[inline]
pub(crate) fn depth(clip: Vec4, inv_w: f32) -> f32 {
    let z = F32(times_power_of_two((F32(clip.z) * F32(inv_w) + F32(1.0)).0, 0.5));
    // `f32::clamp` in `F32` comparisons: NaN stays NaN.
    let z = if z < F32(0.0) { F32(0.0) } else { z };
    if z > F32(1.0) {
        1.0
    } else {
        z.0
    }
}

/// The snapped screen position (28.4) and `1/w` of a clip-space point; no depth or varyings.
pub(crate) fn project_xy(pos: Vec4, (hw, hh): (f32, f32)) -> ScreenVertex {
    // In `F32`: once per vertex, but library calls without an FPU.
    let (one, inv_w) = (F32(1.0), F32(1.0) / F32(pos.w));
    let x = (F32(pos.x) * inv_w + one) * F32(hw);
    let y = (one - F32(pos.y) * inv_w) * F32(hh);
    let snap = |p: F32| fdot4_floor(p.0);
    ScreenVertex { x: snap(x), y: snap(y), z: 0.0, inv_w: inv_w.0, varyings: [0; MAX_VARYINGS] }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Light is quantized as if clamped to 0..=1 first, so the light sums need no clamp.
    #[test]
    fn quantizing_clamps_light() {
        let special = [0.0, -0.0, 1.0, -1.0, 0.5, 1.0 + f32::EPSILON, -f32::MIN_POSITIVE, f32::MAX, f32::MIN];
        let specials = special.into_iter().chain([f32::INFINITY, f32::NEG_INFINITY, f32::NAN]);
        let steps = (0..=40_000).map(|k| k as f32 / 10_000.0 - 2.0);
        for x in specials.chain(steps).chain((0..=65_536).map(|k| k as f32 / 65_536.0 + 1.0 / 131_072.0)) {
            let c = crate::math::clamp01(x);
            assert_eq!(quantize_light([x, x, x, 0.0]), quantize_light([c, c, c, 0.0]), "{x}");
        }
    }
}
