//! Per-triangle work between the vertices and the rasterizer: cull (outcodes, facing, the band's
//! rows), clip what crosses a plane (`clip`), project the clipped polygon, fan it into
//! triangles, and hand each to the fill (`fragment`) or to the wireframe and points (`line`).
//! It does not transform or light vertices (`vertex` does) or walk pixels (`raster` does).

use super::clip::{
    classify, cut, finite_varyings, ClipResult, ClipVertex, Polygon, MAX_CLIPPED, NEEDS_CLIP, NOT_FINITE,
};
use super::fragment::{fill, fill_as, Corners, LitBy, Variant};
use super::line::{line, plot};
use super::raster::{area_in_guard_band, facing, facing_in_guard_band, in_guard_band, Reject, ScreenVertex};
use super::scratch::{TransformedVertex, TriangleRows};
use super::setup::Projection;
use super::span::Diffuse;
use super::varyings::{PixelLit, VertexLit};
use super::vertex::{
    cached_corners, clip_position, coloured_light, corner_lights, flat_corner_lights, project, projected, texel,
    texel_scale, vertex_lit_screen, vertex_varyings, Projected,
};
use super::{Context, DrawSetup, Mode, Shading, Stats};
use crate::format::Material;
use crate::math::Vec4;
use crate::target::{Band, DepthBuffer, FrameColor};
use crate::texture::{Repeat565, Sampler};

/// How a sub-mesh's triangles look and which way they face: what every stage after the
/// vertices needs of the material.
pub(crate) struct Surface<'a, 'm> {
    /// The sub-mesh's material.
    pub(crate) material: &'a Material,
    /// Its texture, when it has one and textures are on.
    pub(crate) sampler: Option<&'a Sampler<'m>>,
    /// The same texture's fast form, when it has one ([`Repeat565::new`]).
    pub(crate) fast: Option<Repeat565<'m>>,
    /// The material's diffuse colour, the base of untextured triangles.
    pub(crate) color: Diffuse,
    /// The draw's transform mirrors (negative determinant): front faces wind the other way.
    pub(crate) flip: bool,
    /// The lighting of all its triangles when the surface decides it (see
    /// [`LitBy::of_surface`]); else each triangle's corners tell.
    pub(crate) lit: Option<LitBy>,
}

impl<'a, 'm> Surface<'a, 'm> {
    /// The surface of `material` with `sampler`, for draw `s`.
    pub(crate) fn new<const L: usize>(
        material: &'a Material,
        sampler: Option<&'a Sampler<'m>>,
        ctx: &Context<'_, L>,
        s: &DrawSetup<'_, L>,
    ) -> Self {
        let white = ctx.frame.grey_light && !s.arrays.has_colors();
        let lit = LitBy::of_surface(ctx, white);
        let [r, g, b, _] = material.rgba;
        Surface {
            material,
            sampler,
            fast: sampler.and_then(Repeat565::new),
            color: Diffuse([r, g, b]),
            flip: s.flip,
            lit,
        }
    }
}

/// Draws triangle `t`, of corners `idx`, and returns the rows it can touch (for
/// [`Scratch`](super::Scratch)). `learnt`: its rows when an earlier band of this frame learnt
/// them (see [`Learnt`]); `common`: [`common_cache`] (loop-invariant: a triangle loop finds it
/// once); `variant`: the fill of every triangle of `surface`, when the surface decides it (see
/// [`fragment::variant`](super::fragment::variant)).
#[inline(always)]
pub(crate) fn draw_triangle<'c, C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    (s, common): (&DrawSetup<'c, L>, Option<Common<'c>>),
    (t, idx, learnt): (u32, [u32; 3], Option<Learnt>),
    (surface, variant): (&Surface<'_, '_>, Option<Variant<C, D, L>>),
    stats: &mut Stats,
) -> TriangleRows {
    match front_end(ctx, common.map(|c| c.cache), (idx, learnt), surface, stats) {
        Front::Done(rows) => rows,
        // The common case, straight to the fill from the vertex cache.
        Front::Cached(p, area, rows) => {
            if common.is_some_and(|c| c.flat) {
                fill_flat_cached(band, ctx, (s, t), (&p, area), (surface, variant), stats);
            } else {
                fill_cached(band, ctx, Corners::Cached(&p, None), area, (surface, variant), stats);
            }
            rows
        }
        Front::Other => draw_other(band, ctx, s, t, surface, stats),
    }
}

/// Fills a triangle from the vertex cache: with the surface's variant when it decides one.
#[inline(always)]
fn fill_cached<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    tri: Corners<'_>,
    area: i32,
    (surface, variant): (&Surface<'_, '_>, Option<Variant<C, D, L>>),
    stats: &mut Stats,
) {
    match variant {
        Some(variant) => fill_as(variant, band, ctx, tri, Some(area), surface, stats),
        None => fill(band, ctx, tri, Some(area), surface, stats),
    }
}

/// [`fill_cached`] lit by triangle `t`'s face light. Out of line: the corners' flat lights,
/// which Gouraud draws (the common case) never need, stay out of the triangle loops' frames
/// (thumbv6m core stack, 8 bands: -40 bytes; Cortex-M4F: -7.6k instructions a frame).
#[inline(never)]
fn fill_flat_cached<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    (s, t): (&DrawSetup<'_, L>, u32),
    (p, area): (&[&TransformedVertex; 3], i32),
    surface: (&Surface<'_, '_>, Option<Variant<C, D, L>>),
    stats: &mut Stats,
) {
    let flat = flat_corner_lights(ctx, s, &s.arrays.triangle(t));
    fill_cached(band, ctx, Corners::Cached(p, Some(&flat)), area, surface, stats);
}

/// The rows of a triangle that an earlier band of this frame learnt (see
/// [`Scratch`](super::Scratch)), not empty and touching this band: that band found it in front
/// of the eye and inside the view, facing the viewer and not degenerate (see [`cull`]), and a
/// filled triangle of cached corners is not tested for that again.
#[derive(Clone, Copy)]
pub(crate) struct Learnt(pub(crate) TriangleRows);

/// What the front end of the common case leaves to draw: small, as it lives in the frame of
/// every triangle's loop.
enum Front<'c> {
    /// Nothing to draw in this band; the rows it can touch (for [`Scratch`](super::Scratch)).
    Done(TriangleRows),
    /// To fill from the vertex cache, in the guard band with no clipping: its corners, its area
    /// (from [`facing`]) and rows.
    Cached([&'c TransformedVertex; 3], i32, TriangleRows),
    /// Not the common case: [`draw_other`] does it all.
    Other,
}

/// The common case's front end: a filled triangle whose corners are cached and need no
/// clipping, culled and tested against the band here (or not again, when `learnt`); every
/// other triangle is [`Front::Other`]. Inlined into the triangle loop: a call per triangle
/// cost more (20k instructions on the reference frame) than its temporaries cost in stack.
#[inline(always)]
fn front_end<'c, const L: usize>(
    ctx: &Context<'_, L>,
    common: Option<&'c [TransformedVertex]>,
    (idx, learnt): ([u32; 3], Option<Learnt>),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Front<'c> {
    let Some(p) = common.and_then(|cache| unclipped_corners(cache, &idx)) else {
        return Front::Other;
    };
    let xy = p.map(|p| (i32::from(p.xy[0]), i32::from(p.xy[1])));
    if let Some(Learnt(rows)) = learnt {
        // The tests below passed in the band that learnt its rows (the same corners).
        debug_assert!(cached_tests(ctx, (p, xy, true), surface, &mut Stats::default()).is_ok_and(|k| k.1 == rows));
        return Front::Cached(p, area_in_guard_band(xy), rows);
    }
    match cached_tests(ctx, (p, xy, true), surface, stats) {
        Ok((Some(area), rows)) => Front::Cached(p, area, rows),
        Ok((None, _)) => Front::Other,
        Err(rows) => Front::Done(rows),
    }
}

/// What the common case of [`front_end`] reads: the draw's vertex cache, and whether its
/// triangles are flat shaded (lit by their faces, not their corners). A triangle loop that
/// knows the shading says it here, once, not the triangle's draw.
#[derive(Clone, Copy)]
pub(crate) struct Common<'c> {
    /// The draw's vertex cache.
    pub(crate) cache: &'c [TransformedVertex],
    /// Whether the draw is flat shaded.
    pub(crate) flat: bool,
}

/// The common case of draw `s` (see [`Common`]): when it has a vertex cache and the mode is
/// [`Mode::Solid`] (else every triangle is [`Front::Other`]).
#[inline(always)]
pub(crate) fn common_cache<'c, const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'c, L>) -> Option<Common<'c>> {
    let flat = ctx.opts.shading == Shading::Flat;
    s.vertices.filter(|_| ctx.opts.mode == Mode::Solid).map(|cache| Common { cache, flat })
}

/// The corners `idx` from a draw's vertex cache `cache`, when it has them all and none needs
/// clipping or is not finite (see [`TransformedVertex::new`]).
#[inline(always)]
fn unclipped_corners<'c>(cache: &'c [TransformedVertex], idx: &[u32; 3]) -> Option<[&'c TransformedVertex; 3]> {
    let p = cached_corners(cache, idx)?;
    ((p[0].outcode | p[1].outcode | p[2].outcode) & (NEEDS_CLIP | NOT_FINITE) == 0).then_some(p)
}

/// The view, facing and band tests of a triangle whose corners `p` (at `xy`) are cached, finite
/// and need no clipping: the cache vouches that they are in the guard band with positive
/// finite `1/w`s (see [`TransformedVertex::new`]), to be `filled` or not. What [`cull`] says.
#[inline(always)]
fn cached_tests<const L: usize>(
    ctx: &Context<'_, L>,
    (p, xy, filled): ([&TransformedVertex; 3], [(i32, i32); 3], bool),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Result<(Option<i32>, TriangleRows), TriangleRows> {
    if classify(p.map(|p| p.outcode)) == ClipResult::Outside {
        stats.culled_frustum += 1;
        return Err(TriangleRows::EMPTY);
    }
    let facing = facing_in_guard_band(xy, surface.material.cull_back_faces, surface.flip);
    cull(ctx, facing, (xy.map(|p| p.1), filled), stats)
}

/// Draws triangle `t` when it is not the common case of [`front_end`]: drawn without the vertex
/// cache, crossing a clipping plane, or in another mode than [`Mode::Solid`]. Not inlined: the
/// screen vertices and polygons stay off the common path's stack.
#[inline(never)]
fn draw_other<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    t: u32,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> TriangleRows {
    match other_front(ctx, s, t, surface, stats) {
        Other::Done(rows) => rows,
        // A filled triangle whose facing and rows the front end found (what `draw_polygon`
        // would do with them, without its other cases).
        Other::Inside(tri, (Some(area), Some(rows))) if ctx.opts.mode == Mode::Solid => {
            fill(band, ctx, Corners::Screen(&tri), Some(area), surface, stats);
            rows
        }
        Other::Inside(tri, known) => draw_polygon(band, ctx, &tri, known, surface, stats),
        Other::Clipped(tri, corners) => {
            draw_clipped(band, ctx, (&tri, &corners, &s.transforms().projection), surface, stats)
        }
    }
}

/// What [`other_front`] leaves to draw.
enum Other {
    /// Nothing to draw in this band; the rows it can touch (for [`Scratch`](super::Scratch)).
    Done(TriangleRows),
    /// Projected, wholly inside the clipping planes, with what [`facing`] and
    /// [`TriangleRows::of`] said when known.
    Inside([ScreenVertex; 3], (Option<i32>, Option<TriangleRows>)),
    /// Crosses a clipping plane: cut it first. With its corners projected.
    Clipped([ClipVertex; 3], [Projected; 3]),
}

/// Fetch, cull, light and classify triangle `t` for [`draw_other`]: from the vertex cache when
/// its corners are there and need no clipping ([`cached_screen`]), else transformed here
/// ([`full_varyings`]).
#[inline(always)]
fn other_front<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    t: u32,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Other {
    let idx = s.arrays.triangle(t);
    // Cached corners whose triangle needs no clipping; else fresh ones.
    if let Some(p) = s.vertices.and_then(|cache| unclipped_corners(cache, &idx)) {
        return cached_screen(ctx, s, (&idx, p), surface, stats);
    }
    let p = idx.map(|i| projected(ctx, s, i));
    let class = classify(p.map(|p| p.outcode));
    if class == ClipResult::Outside {
        stats.culled_frustum += 1;
        return Other::Done(TriangleRows::EMPTY);
    }
    let mut known = (None, None);
    if w_ok(p.map(|p| p.inv_w)) {
        let xy = p.map(|p| (p.x, p.y));
        let facing = if in_guard_band(xy) {
            facing_in_guard_band(xy, surface.material.cull_back_faces, surface.flip)
        } else {
            Err(Reject::OutsideGuardBand)
        };
        match cull(ctx, facing, (xy.map(|p| p.1), false), stats) {
            Ok((area, rows)) => known = (area, Some(rows)),
            Err(rows) => return Other::Done(rows),
        }
    }
    full_varyings(ctx, s, (&idx, &p, class), known, surface, stats)
}

/// [`other_front`] of a triangle whose corners `p` (indices `idx`) are cached, finite and need
/// no clipping: tested as [`front_end`] does, then made screen vertices.
#[inline(always)]
fn cached_screen<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    (idx, p): (&[u32; 3], [&TransformedVertex; 3]),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Other {
    let xy = p.map(|p| (i32::from(p.xy[0]), i32::from(p.xy[1])));
    let known = match cached_tests(ctx, (p, xy, ctx.opts.mode == Mode::Solid), surface, stats) {
        Ok((area, rows)) => (area, Some(rows)),
        Err(rows) => return Other::Done(rows),
    };
    let flat = (ctx.opts.shading == Shading::Flat).then(|| flat_corner_lights(ctx, s, idx));
    // Not `p.map(..)`: an out-of-line call here.
    Other::Inside(core::array::from_fn(|k| p[k].screen_vertex(p[k].corner_light(flat.as_ref(), k))), known)
}

/// Whether every corner's `1/w` is positive and finite: the triangle is wholly in front of the
/// eye, and its projected positions mean something.
#[inline(always)]
fn w_ok(inv_w: [f32; 3]) -> bool {
    inv_w.iter().all(|&w| crate::math::is_positive_finite(w))
}

/// The back-face and band tests of a triangle wholly in front of the eye, whose corners'
/// snapped positions have the y coordinates `ys` and whose [`facing`] (or why the rasterizer
/// would refuse it) is `facing`: its area (when the rasterizer will take it) and rows, or the
/// rows to return when it is done here. Back faces and degenerate triangles are rejected before any lighting:
/// projection keeps the winding, and the snapped positions are the ones the rasterizer gets,
/// so the decision is the same one it would make.
#[inline(always)]
fn cull<const L: usize>(
    ctx: &Context<'_, L>,
    facing: Result<i32, Reject>,
    (ys, filled): ([i32; 3], bool),
    stats: &mut Stats,
) -> Result<(Option<i32>, TriangleRows), TriangleRows> {
    let area = match facing {
        // Nothing to draw in any band (see `draw_polygon`): said once, so that rows learnt
        // here vouch for a front face of some area (see `Learnt`).
        Err(r @ (Reject::BackFace | Reject::Degenerate)) => {
            stats.count_reject(r);
            return Err(TriangleRows::EMPTY);
        }
        // Kept for the rasterizer if the triangle is drawn unclipped (same positions).
        Ok(a) => Some(a),
        Err(_) => None,
    };
    // Rows of the unclipped triangle: a superset of what clipping leaves; for a triangle
    // `filled` unclipped, only the rows of its pixel centres. A triangle that cannot touch this
    // band is not lit, clipped or set up here (a row cache learns its rows
    // for the later bands).
    let (min, max) = (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]));
    let rows =
        if filled { TriangleRows::of_centres(min, max, ctx.height) } else { TriangleRows::of_ys(min, max, ctx.height) };
    if !rows.may_touch(ctx.window.row_start, ctx.window.row_end) {
        stats.outside_band += 1;
        return Err(rows);
    }
    Ok((area, rows))
}

/// The rest of [`front_end`] for triangles drawn without the vertex cache: corners `idx`
/// projected to `p` and classified as `class`, whose facing and rows are `known` when found.
/// Lights the corners and builds their varyings; a triangle that needs clipping is left to
/// [`draw_clipped`]. Not inlined: the common, cached path keeps a small stack frame.
#[inline(never)]
fn full_varyings<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_, L>,
    (idx, p, class): (&[u32; 3], &[Projected; 3], ClipResult),
    known: (Option<i32>, Option<TriangleRows>),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Other {
    let scale = texel_scale(surface.sampler);
    let phong = ctx.opts.shading == Shading::Phong;
    if class == ClipResult::Inside && !phong {
        // The common case, straight to fixed point: light and specular come from 16-bit
        // integers, so only the texel coordinates can be non-finite.
        let texels = idx.map(|i| texel(s, i, scale));
        if !finite_varyings(&texels, 2) {
            stats.culled_frustum += 1;
            return Other::Done(TriangleRows::EMPTY);
        }
        let light = corner_lights(ctx, s, idx);
        let tri = core::array::from_fn(|k| {
            p[k].screen_vertex(vertex_lit_screen(texels[k], coloured_light(s, idx[k], light[k])))
        });
        return Other::Inside(tri, known);
    }
    let varyings = vertex_varyings(ctx, s, idx, scale);
    let maybe_not_finite = if phong { PixelLit::LEN } else { VertexLit::LIGHT };
    if !finite_varyings(&varyings, maybe_not_finite) {
        stats.culled_frustum += 1;
        return Other::Done(TriangleRows::EMPTY);
    }
    if class == ClipResult::Inside {
        // Saturating casts: huge UVs clamp instead of wrapping.
        let tri = core::array::from_fn(|k| p[k].screen_vertex(varyings[k].map(crate::math::to_i32)));
        return Other::Inside(tri, known);
    }
    Other::Clipped(core::array::from_fn(|k| ClipVertex { pos: clip_position(s, idx[k]), varyings: varyings[k] }), *p)
}

/// Cuts a triangle that crosses a clipping plane and draws what is left. `corners`: its
/// corners projected as in every other triangle (see [`projected`]), where the polygon keeps
/// them: with the integer transform that projection is not [`project`]'s, and a shared vertex
/// must land on the same spot in each triangle. Not inlined: the polygon buffers stay off the
/// stack of the common, unclipped path.
#[inline(never)]
fn draw_clipped<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    (tri, corners, projection): (&[ClipVertex; 3], &[Projected; 3], &Projection),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> TriangleRows {
    let mut poly = Polygon::new();
    if cut(tri, &projection.guard, &mut poly) == ClipResult::Outside {
        stats.culled_frustum += 1;
        return TriangleRows::EMPTY;
    }
    stats.clipped += 1;
    // A corner the polygon kept is a copy of it (`cut` copies the vertices inside a plane);
    // a point clipping made that is the same point bit for bit gets its projection too.
    let same = |a: Vec4, b: Vec4| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits);
    let screen: heapless::Vec<ScreenVertex, { MAX_CLIPPED }> = poly
        .iter()
        .map(|v| match tri.iter().position(|c| same(c.pos, v.pos)) {
            Some(k) => corners[k].screen_vertex(v.varyings.map(crate::math::to_i32)),
            None => project(v, projection.half),
        })
        .collect();
    draw_polygon(band, ctx, &screen, (None, None), surface, stats)
}

/// Fan triangle `k` (1..len-1) of a convex polygon: the polygon itself when it is a triangle
/// (no copy).
#[inline(always)]
fn fan_triangle(screen: &[ScreenVertex], k: usize, f: impl FnOnce(&[ScreenVertex; 3])) {
    match <&[ScreenVertex; 3]>::try_from(screen) {
        Ok(tri) => f(tri),
        Err(_) => f(&[screen[0], screen[k], screen[k + 1]]),
    }
}

/// Draws a projected convex polygon (3 or more vertices) in the current mode and returns the
/// rows it can touch. `known`: what [`facing`] and [`TriangleRows::of`] gave for these very
/// positions, when known.
fn draw_polygon<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    screen: &[ScreenVertex],
    (area, rows): (Option<i32>, Option<TriangleRows>),
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> TriangleRows {
    let (material, flip) = (surface.material, surface.flip);
    // One facing decision for the whole (convex) polygon, the same in every band.
    let mut facing_result = area.ok_or(Reject::Empty);
    if area.is_none() {
        fan_triangle(screen, 1, |tri| facing_result = facing(tri, material.cull_back_faces, flip));
    }
    let area = match facing_result {
        Ok(a) => a,
        Err(r) => {
            if r == Reject::BackFace || screen.len() == 3 {
                stats.count_reject(r);
                return TriangleRows::EMPTY;
            }
            0
        }
    };
    let mode = ctx.opts.mode;
    if matches!(mode, Mode::Solid | Mode::SolidWireframe) {
        for k in 1..screen.len() - 1 {
            // A triangle's area is the polygon's; fan pieces get their own.
            let known = (screen.len() == 3).then_some(area);
            fan_triangle(screen, k, |tri| fill(band, ctx, Corners::Screen(tri), known, surface, stats));
        }
    }
    if matches!(mode, Mode::Wireframe | Mode::Points | Mode::SolidWireframe) {
        if mode != Mode::SolidWireframe {
            stats.drawn += 1;
        }
        let rgb = ctx.opts.wire_color.unwrap_or([material.rgba[0], material.rgba[1], material.rgba[2]]);
        let color = C::from_rgb888(rgb);
        for k in 0..screen.len() {
            if mode == Mode::Points {
                plot(band, &screen[k], color, stats);
            } else {
                line(band, &screen[k], &screen[(k + 1) % screen.len()], color, stats);
            }
        }
    }
    rows.unwrap_or_else(|| TriangleRows::of(screen, band.height))
}
