//! The pixels of a triangle: the shader variant chosen once per triangle (base colour, light,
//! dithering, number of varyings) and the span loop that runs it (depth test, texel, light,
//! store). It does not find which pixels are covered (`raster` does).

use super::primitive::Surface;
use super::raster::{step_varyings, Reject, ScreenVertex, Setup, Span, SpanSink, Window};
use super::varyings::{is_texel_coordinate, texel_coordinates, PixelLit, VertexLit};
use super::{Context, Shading, Stats};
use crate::fixed::FDot16;

use crate::light::PixelLights;
use crate::target::{Band, BandArea, DepthBuffer, DepthCell, FrameColor};
use crate::texture::{modulate, Repeat565, Sampler};

/// Where a fragment's unlit colour comes from.
trait Base: Copy {
    /// The colour at texel coordinates `(u, v)`, or `None` for a cut-out texel.
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]>;

    /// That colour lit by `light` (16.16 per channel) in the frame's format.
    #[inline(always)]
    fn lit<C: FrameColor>(&self, u: i32, v: i32, light: [i32; 3]) -> Option<C> {
        self.base(u, v).map(|rgb| C::from_rgb888(modulate(rgb, light)))
    }
}

/// Untextured: the material's diffuse colour.
#[derive(Clone, Copy)]
struct Diffuse([u8; 3]);

impl Base for Diffuse {
    #[inline]
    fn base(&self, _: i32, _: i32) -> Option<[u8; 3]> {
        Some(self.0)
    }
}

impl Base for Repeat565<'_> {
    #[inline(always)]
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]> {
        Some(self.sample(u, v))
    }

    /// Straight from the RGB565 texel (RGB565 frames never widen it to 8 bits).
    #[inline(always)]
    fn lit<C: FrameColor>(&self, u: i32, v: i32, light: [i32; 3]) -> Option<C> {
        Some(C::from_lit_rgb565(self.texel(u, v), light))
    }
}

impl Base for Sampler<'_> {
    #[inline(always)]
    fn base(&self, u: i32, v: i32) -> Option<[u8; 3]> {
        let t = self.sample(u, v);
        (t[3] >= 128).then_some([t[0], t[1], t[2]])
    }
}

/// Where a fragment's light comes from.
trait Lighting {
    /// Light per channel in 16.16 (1.0 = 65536) from the pixel's varyings.
    fn light<const V: usize>(&self, v: &[FDot16; V]) -> [FDot16; 3];
    /// Whether [`Lighting::highlight`] can be other than black.
    const HIGHLIGHT: bool = false;
    /// Colour added after lighting (specular highlight), 0..=255 per channel.
    #[inline(always)]
    fn highlight<const V: usize>(&self, _v: &[i32; V]) -> [u8; 3] {
        [0; 3]
    }
}

/// Light interpolated from the vertices (unlit, flat, Gouraud).
struct Interpolated;

impl Lighting for Interpolated {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        VertexLit::light(v)
    }
}

/// [`Interpolated`] for white light: one varying for all three channels.
struct White;

impl Lighting for White {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        VertexLit::white(v)
    }
}

/// [`Interpolated`] plus an interpolated specular intensity of this colour.
struct Specular([u8; 3]);

impl Lighting for Specular {
    const HIGHLIGHT: bool = true;
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        Interpolated.light(v)
    }
    #[inline(always)]
    fn highlight<const V: usize>(&self, v: &[i32; V]) -> [u8; 3] {
        modulate(self.0, [v[VertexLit::SPECULAR]; 3])
    }
}

impl<const L: usize> Lighting for PixelLights<L> {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        let (normal, position) = PixelLit::normal_and_position(v);
        self.at(normal, position)
    }
}

/// Rasterizes one screen triangle, choosing the monomorphised inner loop once per triangle so
/// the per-pixel loop never branches on modes.
pub(crate) fn fill<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    tri: &[ScreenVertex; 3],
    area: Option<i64>,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) {
    let (material, sampler) = (surface.material, surface.sampler);
    let winding = Winding { cull_back: material.cull_back_faces, flip: surface.flip, area };
    let r = match (sampler, sampler.and_then(Repeat565::new)) {
        (_, Some(fast)) => fill_with(band, ctx, winding, tri, &fast, stats),
        (Some(t), None) => fill_with(band, ctx, winding, tri, t, stats),
        (None, _) => {
            let diffuse = Diffuse([material.rgba[0], material.rgba[1], material.rgba[2]]);
            fill_with(band, ctx, winding, tri, &diffuse, stats)
        }
    };
    match r {
        Ok(()) => stats.drawn += 1,
        Err(r) => stats.count_reject(r),
    }
}

/// What decides whether and which way a triangle faces: whether back faces are culled, whether
/// the draw's transform mirrors, and the area [`facing`](super::raster::facing) already gave
/// for these very positions, when known.
#[derive(Clone, Copy)]
struct Winding {
    cull_back: bool,
    flip: bool,
    area: Option<i64>,
}

/// [`fill`] for one base colour source: picks the lighting and dithering variant.
fn fill_with<C: FrameColor, D: DepthBuffer, B: Base, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    winding: Winding,
    tri: &[ScreenVertex; 3],
    base: &B,
    stats: &mut Stats,
) -> Result<(), Reject> {
    let specular = ctx.specular;
    let pl = &ctx.pixel_lights;
    let white = || {
        tri.iter().all(|v| {
            let light = VertexLit::light(&v.varyings);
            light[0] == light[1] && light[0] == light[2]
        })
    };
    let lit = if ctx.opts.shading == Shading::Phong {
        LitBy::Pixel
    } else if specular != [0; 3] {
        LitBy::VertexAndSpecular
    } else if white() {
        LitBy::White
    } else {
        LitBy::Vertex
    };
    let raster = (&ctx.window, ctx.opts.subspan, lit.affine_tolerance_light());
    match (lit, ctx.opts.dither) {
        (LitBy::White, false) => {
            fragments::<_, _, _, _, { VertexLit::WHITE_LEN }, false>(band, raster, tri, winding, base, &White, stats)
        }
        (LitBy::White, true) => {
            fragments::<_, _, _, _, { VertexLit::WHITE_LEN }, true>(band, raster, tri, winding, base, &White, stats)
        }
        (LitBy::Vertex, false) => fragments::<_, _, _, _, { VertexLit::COLOR_LEN }, false>(
            band,
            raster,
            tri,
            winding,
            base,
            &Interpolated,
            stats,
        ),
        (LitBy::Vertex, true) => fragments::<_, _, _, _, { VertexLit::COLOR_LEN }, true>(
            band,
            raster,
            tri,
            winding,
            base,
            &Interpolated,
            stats,
        ),
        (LitBy::VertexAndSpecular, false) => fragments::<_, _, _, _, { VertexLit::SPECULAR_LEN }, false>(
            band,
            raster,
            tri,
            winding,
            base,
            &Specular(specular),
            stats,
        ),
        (LitBy::VertexAndSpecular, true) => fragments::<_, _, _, _, { VertexLit::SPECULAR_LEN }, true>(
            band,
            raster,
            tri,
            winding,
            base,
            &Specular(specular),
            stats,
        ),
        (LitBy::Pixel, false) => {
            fragments::<_, _, _, _, { PixelLit::LEN }, false>(band, raster, tri, winding, base, pl, stats)
        }
        (LitBy::Pixel, true) => {
            fragments::<_, _, _, _, { PixelLit::LEN }, true>(band, raster, tri, winding, base, pl, stats)
        }
    }
}

/// Which [`Lighting`] a triangle uses (and so how many varyings it interpolates).
#[derive(Clone, Copy)]
enum LitBy {
    /// White light per vertex: U, V, light.
    White,
    /// Light per vertex: U, V, light red, green, blue.
    Vertex,
    /// The same plus a specular intensity.
    VertexAndSpecular,
    /// Phong: normal and position per pixel.
    Pixel,
}

/// The per-pixel work for one triangle: depth test, base colour (alpha test), light, store.
struct Shader<'b, 's, C, D, B, Lt, const DITHER: bool> {
    color: &'b mut [C],
    depth: &'b mut D,
    area: BandArea,
    base: &'s B,
    lighting: &'s Lt,
    written: u32,
    rejected: u32,
    runs: u32,
}

impl<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool> SpanSink<V>
    for Shader<'_, '_, C, D, B, Lt, DITHER>
{
    #[inline(never)]
    fn span(&mut self, s: &Span<V>) {
        let len = s.len as usize;
        // The run must lie on one row of this band (the rasterizer guarantees it); checked
        // anyway.
        let Some(start) = self.area.run_start(s.x, s.y, len) else {
            return;
        };
        let (Some(colors), Some(cells)) = (self.color.get_mut(start..start + len), self.depth.cells(start, len)) else {
            return;
        };
        let (mut z, mut v) = (s.z, s.v);
        // Local copies: the loop keeps them in registers instead of reloading through `self`.
        let base = *self.base;
        let (mut rejected, mut cut) = (0, 0);
        for (k, (px, mut cell)) in colors.iter_mut().zip(cells).enumerate() {
            if !cell.passes(z) {
                rejected += 1;
                // A cut-out texel writes neither colour nor depth.
            } else if let Some(c) = lit_fragment::<C, B, Lt, V, DITHER>(&base, self.lighting, &v, (s.x + k as i32, s.y))
            {
                *px = c;
                cell.store(z);
            } else {
                cut += 1;
            }
            z = z.wrapping_add_signed(s.dz);
            step_varyings(&mut v, &s.dv);
        }
        self.written += s.len - rejected - cut;
        self.rejected += rejected;
        self.runs += 1;
    }
}

/// The lit colour of the fragment with varyings `v` at `(x, y)`, or `None` where the texture
/// cuts it out.
#[inline(always)]
fn lit_fragment<C: FrameColor, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    base: &B,
    lighting: &Lt,
    v: &[i32; V],
    (x, y): (i32, i32),
) -> Option<C> {
    let light = lighting.light(v);
    if !DITHER && !Lt::HIGHLIGHT {
        // Straight to the frame's format (RGB565 stays RGB565).
        let (u, tv) = texel_coordinates(v);
        return base.lit(u, tv, light);
    }
    let (u, tv) = texel_coordinates(v);
    let rgb = modulate(base.base(u, tv)?, light);
    let extra = lighting.highlight(v);
    let rgb: [u8; 3] = core::array::from_fn(|c| rgb[c].saturating_add(extra[c]));
    Some(if DITHER { C::from_rgb888_dithered(rgb, x as u32, y as u32) } else { C::from_rgb888(rgb) })
}

impl LitBy {
    /// How far affine varyings other than texture coordinates may be from perspective-correct
    /// ones (see `Setup::allow_affine`): 1/256 for light (an 8-bit step; a quarter of RGB565's
    /// finest); 1/4096 for Phong's normals and positions, as per-pixel lighting magnifies
    /// their errors.
    fn affine_tolerance_light(self) -> u32 {
        match self {
            LitBy::Pixel => 1 << 4,
            _ => 1 << 8,
        }
    }
}

/// The tolerances of all `V` varyings: 1/16 texel for texture coordinates, `other` for the rest.
fn affine_tolerance<const V: usize>(other: u32) -> [u32; V] {
    core::array::from_fn(|k| if is_texel_coordinate(k) { 1 << 12 } else { other })
}

// Not inlined: each variant's `Setup` gets its own frame instead of all of them sharing (and
// enlarging) the caller's.
#[inline(never)]
fn fragments<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    band: &mut Band<'_, C, D>,
    (window, subspan, tolerance): (&Window, u32, u32),
    tri: &[ScreenVertex; 3],
    winding: Winding,
    base: &B,
    lighting: &Lt,
    stats: &mut Stats,
) -> Result<(), Reject> {
    let mut setup = match winding.area {
        Some(area) => Setup::<V>::with_area(tri, window, area)?,
        None => Setup::<V>::new(tri, window, winding.cull_back, winding.flip)?,
    };
    setup.allow_affine(affine_tolerance::<V>(tolerance));
    let mut shader = Shader::<C, D, B, Lt, DITHER> {
        area: band.area(),
        color: &mut *band.color,
        depth: &mut band.depth,
        base,
        lighting,
        written: 0,
        rejected: 0,
        runs: 0,
    };
    setup.for_each_span(subspan, &mut shader);
    stats.pixels_written += shader.written;
    stats.depth_rejected += shader.rejected;
    stats.runs += shader.runs;
    Ok(())
}
