//! The pixels of a triangle: the shader variant chosen once per triangle (base colour, light,
//! dithering, number of varyings), whether its span loop walks the rows itself or gets runs
//! through `dyn` (see `fragments`), and where a fragment's light comes from ([`Lighting`]). It
//! does not find which pixels are covered (`raster` does) or run the per-pixel loop (`span`
//! does).

use super::primitive::Surface;
use super::raster::{facing_of, Corner, CoveredBox, Reject, ScreenVertex, Setup};
#[cfg(not(soft_float))]
use super::raster::{SmallTriangle, SMALL_BOX};
use super::scratch::TransformedVertex;
use super::span::{AnyCells, Base, Diffuse, RunCells, Shader, U16Cells};
use super::varyings::{is_texel_coordinate, PixelLit, VertexLit};
use super::vertex::{vertex_lit_varyings, VertexLight};
use super::{Context, Shading, Stats};
use crate::fixed::{Depth30, FDot16};
#[cfg(feature = "fog")]
use crate::fog::PixelFog;

use crate::light::PixelLights;
use crate::target::{Band, DepthBuffer, FrameColor};
use crate::texture::{modulate, SPREAD565, SPREAD565_HALF, WHITE_LIGHT_BIAS};

/// Where a fragment's light comes from.
pub(super) trait Lighting {
    /// Light per channel in 16.16 (1.0 = 65536) from the pixel's varyings.
    fn light<const V: usize>(&self, v: &[FDot16; V]) -> [FDot16; 3];
    /// An RGB565 texel lit at the pixel with varyings `v`, in the frame's format.
    #[inline(always)]
    fn lit_rgb565<C: FrameColor, const V: usize>(&self, texel: u16, v: &[FDot16; V]) -> C {
        C::from_lit_rgb565(texel, self.light(v))
    }
    /// Whether [`Lighting::highlight`] can be other than black.
    const HIGHLIGHT: bool = false;
    /// Colour added after lighting (specular highlight), 0..=255 per channel.
    #[inline(always)]
    fn highlight<const V: usize>(&self, _v: &[i32; V]) -> [u8; 3] {
        [0; 3]
    }
    /// What this lighting takes added to the light varying (see [`White`]): added to a
    /// triangle's corners once, carried unchanged by interpolation.
    const LIGHT_BIAS: FDot16 = 0;
    /// Whether [`Lighting::fog`] can change a colour.
    const FOG: bool = false;
    /// The lit colour `rgb` of the pixel at frame column and row `at` with depth `z`, seen
    /// through the fog (see `fog::PixelFog`); the last step of a fragment.
    #[inline(always)]
    fn fog(&self, rgb: [u8; 3], _at: (i32, i32), _z: Depth30) -> [u8; 3] {
        rgb
    }
    /// Whether [`Lighting::lit_rgb565`] is `texture::modulate565_white_with` of varying
    /// `VertexLit::LIGHT` with `[SPREAD565, SPREAD565_HALF]` (as [`White`]'s is): the span
    /// loop's assembly draws that variant itself (see `span::Run565`).
    #[cfg_attr(not(asm_runs), allow(dead_code, reason = "only the span loop's assembly asks"))]
    const WHITE_RGB565: bool = false;
}

/// Light interpolated from the vertices (unlit, flat, Gouraud).
struct Interpolated;

impl Lighting for Interpolated {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        VertexLit::light(v)
    }
}

/// [`Interpolated`] for white light: one varying for all three channels. Holds the RGB565
/// modulation's two constants (`texture::modulate565_white_with`), made opaque by `fill_with`.
struct White([u32; 2]);

impl Lighting for White {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        VertexLit::white(v).map(|l| l.wrapping_sub(Self::LIGHT_BIAS))
    }
    #[inline(always)]
    fn lit_rgb565<C: FrameColor, const V: usize>(&self, texel: u16, v: &[FDot16; V]) -> C {
        let biased = v[VertexLit::LIGHT];
        // Interpolated from vertex lights in 0..=1 (see `texture::modulate565_white`).
        debug_assert!((0..(1 << 16) + (1 << 11)).contains(&biased), "interpolated light {biased} (biased)");
        C::from_white_lit_rgb565_with(texel, biased, self.0)
    }
    /// The RGB565 modulation's rounding (see `texture::modulate565_white_with`): one addition
    /// a triangle corner instead of one a pixel.
    const LIGHT_BIAS: FDot16 = WHITE_LIGHT_BIAS;
    const WHITE_RGB565: bool = true;
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

impl<const L: usize> Lighting for &PixelLights<L> {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        let (normal, position) = PixelLit::normal_and_position(v);
        self.at(normal, position)
    }
}

/// Another lighting seen through the band's fog ([`PixelFog`]).
#[cfg(feature = "fog")]
struct Fogged<Lt> {
    inner: Lt,
    fog: Option<PixelFog>,
}

#[cfg(feature = "fog")]
impl<Lt: Lighting> Lighting for Fogged<Lt> {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        self.inner.light(v)
    }
    const HIGHLIGHT: bool = Lt::HIGHLIGHT;
    #[inline(always)]
    fn highlight<const V: usize>(&self, v: &[i32; V]) -> [u8; 3] {
        self.inner.highlight(v)
    }
    const LIGHT_BIAS: FDot16 = Lt::LIGHT_BIAS;
    const FOG: bool = true;
    #[inline(always)]
    fn fog(&self, rgb: [u8; 3], at: (i32, i32), z: Depth30) -> [u8; 3] {
        self.fog.as_ref().map_or(rgb, |f| f.blend(rgb, at, z))
    }
}

/// A triangle's corners as the front end has them: what [`fill`] takes.
#[derive(Clone, Copy)]
pub(crate) enum Corners<'a> {
    /// Projected vertices with all their varyings (clipped, or drawn without a vertex cache).
    Screen(&'a [ScreenVertex; 3]),
    /// Cached vertices (see [`TransformedVertex`]), lit by their own light varyings or, when
    /// given, by these (flat shading's).
    Cached(&'a [&'a TransformedVertex; 3], Option<&'a [VertexLight; 3]>),
}

impl Corners<'_> {
    /// The corners as the set-up of a variant of `V` varyings reads them: from the cache, only
    /// those `V` (no screen vertex built).
    fn corners<const V: usize>(self) -> [Corner<V>; 3] {
        match self {
            Corners::Screen(tri) => tri.each_ref().map(Corner::of),
            Corners::Cached(p, flat) => core::array::from_fn(|k| {
                let p = p[k];
                let light = p.corner_light(flat, k);
                let (x, y) = (i32::from(p.xy[0]), i32::from(p.xy[1]));
                Corner::new((x, y), p.z, p.inv_w, &vertex_lit_varyings(p.texel, light))
            }),
        }
    }

    /// Whether every corner's light is white (the same on all three channels).
    #[inline(always)]
    fn white(self) -> bool {
        let white = |[r, g, b]: [i32; 3]| r == g && r == b;
        match self {
            Corners::Screen(tri) => tri.iter().all(|v| white(VertexLit::light(&v.varyings))),
            Corners::Cached(p, flat) => (0..3).all(|k| {
                let [r, g, b, _] = p[k].corner_light(flat, k);
                white([r, g, b].map(i32::from))
            }),
        }
    }
}

/// One shader variant's fill of a triangle: [`fragments`] monomorphised for a base, a lighting
/// (with its number of varyings) and dithering, chosen by [`variant`] once per surface where the
/// surface decides the lighting, else once per triangle; what [`fill_as`] calls.
pub(crate) type Variant<C, D, const L: usize> =
    fn(&mut Band<'_, C, D>, &Context<'_, L>, Corners<'_>, Winding, &Surface<'_, '_>, &mut Stats) -> Result<(), Reject>;

/// Rasterizes one screen triangle with the variant its surface and corners choose (see
/// [`variant`]), so that the per-pixel loop never branches on modes.
pub(crate) fn fill<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    tri: Corners<'_>,
    area: Option<i32>,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) {
    debug_assert!(surface.lit != Some(LitBy::White) || tri.white(), "a white surface's corner is not white");
    let lit = surface.lit.unwrap_or_else(|| if tri.white() { LitBy::White } else { LitBy::Vertex });
    fill_as(variant(ctx, surface, lit), band, ctx, tri, area, surface, stats);
}

/// [`fill`] with the variant `fill` already chosen (for a surface that decides its lighting,
/// once for all its triangles: see [`variant`]).
#[inline(always)]
pub(crate) fn fill_as<C: FrameColor, D: DepthBuffer, const L: usize>(
    fill: Variant<C, D, L>,
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    tri: Corners<'_>,
    area: Option<i32>,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) {
    let winding = Winding { cull_back: surface.material.cull_back_faces, flip: surface.flip, area };
    match fill(band, ctx, tri, winding, surface, stats) {
        Ok(()) => stats.drawn += 1,
        Err(r) => stats.count_reject(r),
    }
}

/// The variant that fills a triangle of `surface` lit `lit` (see [`LitBy::of_surface`]): its
/// base (the fast texture, the sampler, or the material's colour), lighting and dithering.
pub(crate) fn variant<C: FrameColor, D: DepthBuffer, const L: usize>(
    ctx: &Context<'_, L>,
    surface: &Surface<'_, '_>,
    lit: LitBy,
) -> Variant<C, D, L> {
    // Formats that ignore the position take the plain path (the same pixels).
    let dither = ctx.opts.dither && C::DITHERS;
    #[cfg(feature = "fog")]
    if ctx.frame.fog.is_some() {
        return fogged_variant(surface, lit, dither);
    }
    // One monomorphised loop per base, lighting (with its number of varyings) and dithering.
    macro_rules! with_lighting {
        ($base:ty) => {
            match (lit, dither) {
                (LitBy::White, false) => fragments::<C, D, $base, WhiteLight, L, { VertexLit::WHITE_LEN }, false>,
                (LitBy::White, true) => fragments::<C, D, $base, WhiteLight, L, { VertexLit::WHITE_LEN }, true>,
                (LitBy::Vertex, false) => fragments::<C, D, $base, Interpolated, L, { VertexLit::COLOR_LEN }, false>,
                (LitBy::Vertex, true) => fragments::<C, D, $base, Interpolated, L, { VertexLit::COLOR_LEN }, true>,
                (LitBy::VertexAndSpecular, false) => {
                    fragments::<C, D, $base, Specular, L, { VertexLit::SPECULAR_LEN }, false>
                }
                (LitBy::VertexAndSpecular, true) => {
                    fragments::<C, D, $base, Specular, L, { VertexLit::SPECULAR_LEN }, true>
                }
                (LitBy::Pixel, false) => fragments::<C, D, $base, PerPixel, L, { PixelLit::LEN }, false>,
                (LitBy::Pixel, true) => fragments::<C, D, $base, PerPixel, L, { PixelLit::LEN }, true>,
            }
        };
    }
    match (surface.fast.is_some(), surface.sampler.is_some()) {
        (true, _) => with_lighting!(FastTexture),
        (false, true) => with_lighting!(SampledTexture),
        (false, false) => with_lighting!(MaterialColor),
    }
}

#[cfg(feature = "fog")]
/// [`variant`] with fog: the general span loop (the sampler or the material's colour, light
/// per channel), each lighting [`Fogged`]; white light is lit as any vertex light is.
fn fogged_variant<C: FrameColor, D: DepthBuffer, const L: usize>(
    surface: &Surface<'_, '_>,
    lit: LitBy,
    dither: bool,
) -> Variant<C, D, L> {
    macro_rules! with_lighting {
        ($base:ty) => {
            match (lit, dither) {
                (LitBy::White | LitBy::Vertex, false) => {
                    fragments::<C, D, $base, FoggedBy<Interpolated>, L, { VertexLit::COLOR_LEN }, false>
                }
                (LitBy::White | LitBy::Vertex, true) => {
                    fragments::<C, D, $base, FoggedBy<Interpolated>, L, { VertexLit::COLOR_LEN }, true>
                }
                (LitBy::VertexAndSpecular, false) => {
                    fragments::<C, D, $base, FoggedBy<Specular>, L, { VertexLit::SPECULAR_LEN }, false>
                }
                (LitBy::VertexAndSpecular, true) => {
                    fragments::<C, D, $base, FoggedBy<Specular>, L, { VertexLit::SPECULAR_LEN }, true>
                }
                (LitBy::Pixel, false) => fragments::<C, D, $base, FoggedBy<PerPixel>, L, { PixelLit::LEN }, false>,
                (LitBy::Pixel, true) => fragments::<C, D, $base, FoggedBy<PerPixel>, L, { PixelLit::LEN }, true>,
            }
        };
    }
    if surface.sampler.is_some() {
        with_lighting!(SampledTexture)
    } else {
        with_lighting!(MaterialColor)
    }
}

/// Where a variant's base comes from: which [`Base`] a surface gives it (by reference: a copy
/// a triangle is a `memcpy` call on some targets).
trait BaseOf {
    /// The base, borrowing the model for `'m`.
    type Base<'m>: Base;
    /// The base of `surface`, `None` when it has none of this kind (never, for the variant
    /// [`variant`] picks for it).
    fn of<'a, 'm>(surface: &'a Surface<'a, 'm>) -> Option<&'a Self::Base<'m>>;
}

/// The surface's texture in its fast form ([`Surface::fast`]).
struct FastTexture;

impl BaseOf for FastTexture {
    type Base<'m> = crate::texture::Repeat565<'m>;
    #[inline(always)]
    fn of<'a, 'm>(surface: &'a Surface<'a, 'm>) -> Option<&'a Self::Base<'m>> {
        surface.fast.as_ref()
    }
}

/// The surface's texture through its sampler.
struct SampledTexture;

impl BaseOf for SampledTexture {
    type Base<'m> = crate::texture::Sampler<'m>;
    #[inline(always)]
    fn of<'a, 'm>(surface: &'a Surface<'a, 'm>) -> Option<&'a Self::Base<'m>> {
        surface.sampler
    }
}

/// The material's diffuse colour ([`Surface::color`]).
struct MaterialColor;

impl BaseOf for MaterialColor {
    type Base<'m> = Diffuse;
    #[inline(always)]
    fn of<'a, 'm>(surface: &'a Surface<'a, 'm>) -> Option<&'a Diffuse> {
        Some(&surface.color)
    }
}

/// Where a variant's [`Lighting`] comes from: what the draw's context gives it.
trait LightOf<const L: usize> {
    /// The lighting, borrowing the context for `'c`.
    type Lighting<'c>: Lighting;
    /// The tolerance of varyings other than texture coordinates (see
    /// [`LitBy::affine_tolerance_light`]).
    const TOLERANCE: u32 = 1 << 8;
    /// The lighting of `ctx`'s triangles.
    fn of<'c>(ctx: &'c Context<'_, L>) -> Self::Lighting<'c>;
}

/// [`White`].
struct WhiteLight;

impl<const L: usize> LightOf<L> for WhiteLight {
    type Lighting<'c> = White;
    #[inline(always)]
    fn of(_: &Context<'_, L>) -> White {
        // Opaque on Armv7-M: the span loop loads the two (one `ldrd`) instead of building
        // each from two halves at every pixel, as it would with them in sight. Without an
        // FPU (Armv6-M, RISC-V) in sight: each is one literal load there, where the opaque
        // pair costs a load of its address and one of each.
        #[cfg(not(soft_float))]
        return White(core::hint::black_box([SPREAD565, SPREAD565_HALF]));
        #[cfg(soft_float)]
        return White([SPREAD565, SPREAD565_HALF]);
    }
}

impl<const L: usize> LightOf<L> for Interpolated {
    type Lighting<'c> = Interpolated;
    #[inline(always)]
    fn of(_: &Context<'_, L>) -> Interpolated {
        Interpolated
    }
}

impl<const L: usize> LightOf<L> for Specular {
    type Lighting<'c> = Specular;
    #[inline(always)]
    fn of(ctx: &Context<'_, L>) -> Specular {
        Specular(ctx.frame.specular)
    }
}

/// Phong: the context's [`PixelLights`].
struct PerPixel;

impl<const L: usize> LightOf<L> for PerPixel {
    type Lighting<'c> = &'c PixelLights<L>;
    const TOLERANCE: u32 = 1 << 4;
    #[inline(always)]
    fn of<'c>(ctx: &'c Context<'_, L>) -> &'c PixelLights<L> {
        &ctx.frame.pixel_lights
    }
}

/// [`Fogged`] `Lk`: the band's fog over another lighting.
#[cfg(feature = "fog")]
struct FoggedBy<Lk>(core::marker::PhantomData<Lk>);

#[cfg(feature = "fog")]
impl<const L: usize, Lk: LightOf<L>> LightOf<L> for FoggedBy<Lk> {
    type Lighting<'c> = Fogged<Lk::Lighting<'c>>;
    const TOLERANCE: u32 = Lk::TOLERANCE;
    #[inline(always)]
    fn of<'c>(ctx: &'c Context<'_, L>) -> Self::Lighting<'c> {
        let size = (ctx.window.width as u16, ctx.height);
        Fogged { inner: Lk::of(ctx), fog: ctx.frame.fog.as_ref().map(|f| PixelFog::new(f, size)) }
    }
}

/// What decides whether and which way a triangle faces: whether back faces are culled, whether
/// the draw's transform mirrors, and the area [`facing`](super::raster::facing) already gave
/// for these very positions, when known.
#[derive(Clone, Copy)]
pub(crate) struct Winding {
    cull_back: bool,
    flip: bool,
    area: Option<i32>,
}

/// Which [`Lighting`] a triangle uses (and so how many varyings it interpolates).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LitBy {
    /// White light per vertex: U, V, light.
    White,
    /// Light per vertex: U, V, light red, green, blue.
    Vertex,
    /// The same plus a specular intensity.
    VertexAndSpecular,
    /// Phong: normal and position per pixel.
    Pixel,
}

impl LitBy {
    /// The lighting of every triangle of a surface, when the surface decides it: Phong,
    /// specular, or (with `white`: grey lights and no vertex colours, see
    /// `Context::grey_light`) white vertex light; `None` when each triangle's corners decide
    /// (white or coloured vertex light).
    pub(crate) fn of_surface<const L: usize>(ctx: &Context<'_, L>, white: bool) -> Option<LitBy> {
        if ctx.opts.shading == Shading::Phong {
            Some(LitBy::Pixel)
        } else if ctx.frame.specular != [0; 3] {
            Some(LitBy::VertexAndSpecular)
        } else {
            white.then_some(LitBy::White)
        }
    }
}

/// The tolerances of all `V` varyings: 1/16 texel for texture coordinates, `other` for the rest.
fn affine_tolerance<const V: usize>(other: u32) -> [u32; V] {
    core::array::from_fn(|k| if is_texel_coordinate(k) { 1 << 12 } else { other })
}

/// `$body` with `$shader` bound to `band`'s [`Shader`] for base `base` and lighting `lighting`
/// (dithering: `dither`): its value; returns `Err(Reject::Empty)` from the function when a plain
/// `u16` depth buffer is shorter than the band. Plain `u16` depths are indexed directly (their length checked here,
/// once); any other buffer through its `cells`. A macro: the shader's type differs between the
/// two, and `$body` is made for each.
macro_rules! with_shader {
    ($band:expr, $base:expr, $lighting:expr, $dither:ident, |$shader:ident| $body:expr) => {{
        let band = $band;
        let (area, pixels, color) = (band.area(), band.color.len(), &mut *band.color);
        macro_rules! shader {
            ($depth:expr) => {
                Shader::<C, _, _, _, $dither>::new((area, color, $depth), $base, $lighting)
            };
        }
        match band.depth.as_u16() {
            Some(values) => {
                let $shader = shader!(U16Cells::new(values, pixels).ok_or(Reject::Empty)?);
                $body
            }
            None => {
                let $shader = shader!(AnyCells(&mut band.depth));
                $body
            }
        }
    }};
}

// Not inlined: each variant's `Setup` gets its own frame instead of all of them sharing (and
// enlarging) the caller's. The corners are built here, in the variant's own form, for the same
// reason (in the caller's frame they would all be there at once).
#[inline(never)]
fn fragments<C, D, K, Lk, const L: usize, const V: usize, const DITHER: bool>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    tri: Corners<'_>,
    winding: Winding,
    surface: &Surface<'_, '_>,
    stats: &mut Stats,
) -> Result<(), Reject>
where
    C: FrameColor,
    D: DepthBuffer,
    K: BaseOf,
    Lk: LightOf<L>,
{
    let (base, lighting) = (K::of(surface).ok_or(Reject::Empty)?, &Lk::of(ctx));
    let (window, subspan, fpu) = (&ctx.window, ctx.opts.subspan, !ctx.opts.fixed_vertices);
    let mut tri = tri.corners::<V>();
    let bias = <Lk::Lighting<'_> as Lighting>::LIGHT_BIAS;
    if bias != 0 {
        for c in &mut tri {
            c.v[VertexLit::LIGHT] = c.v[VertexLit::LIGHT].wrapping_add(bias);
        }
    }
    let tri = &tri;
    let area = match winding.area {
        Some(area) => area,
        None => facing_of(tri.each_ref().map(|c| (c.x, c.y, c.inv_w)), winding.cull_back, winding.flip)?,
    };
    let bbox = CoveredBox::of(tri, window).ok_or(Reject::Empty)?;
    // Small triangles with f32 perspective pixel by pixel, where an FPU makes a pixel's exact
    // varyings cheap (see `raster::small`); for the variants whose span loop walks its rows
    // (flash: one more copy of the span loop for each of those only).
    #[cfg(not(soft_float))]
    if K::Base::WALK_ROWS && !DITHER && fpu && bbox.frame_pixels() <= SMALL_BOX {
        return small_fragments::<C, D, _, _, V, DITHER>(band, (tri, &bbox, area), (base, lighting), stats);
    }
    let mut setup = Setup::<V>::in_box(tri, &bbox, area, fpu);
    let tolerance = affine_tolerance::<V>(Lk::TOLERANCE);
    let z = z_of(tri);
    count(
        stats,
        with_shader!(band, base, lighting, DITHER, |shader| draw(shader, &mut setup, z, subspan, &tolerance, fpu)),
    );
    Ok(())
}

/// [`fragments`] for a small triangle (with f32 perspective, on targets with an FPU): its
/// pixels one by one (see [`SmallTriangle`]), with no planes or row walks. Out of line: in the
/// frame of the row walks and their span loops, its values would take their registers.
#[cfg(not(soft_float))]
#[inline(never)]
fn small_fragments<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    band: &mut Band<'_, C, D>,
    (tri, bbox, area): (&[Corner<V>; 3], &CoveredBox, i32),
    (base, lighting): (&B, &Lt),
    stats: &mut Stats,
) -> Result<(), Reject> {
    let small = SmallTriangle::<V>::new(tri, bbox, area);
    let counts = with_shader!(band, base, lighting, DITHER, |shader| draw_pixels(shader, &small));
    count(stats, counts);
    Ok(())
}

/// Adds a triangle's pixels written, depth-rejected and runs to `stats` (saturating: a draw of
/// many large triangles can write more than 2^32 pixels).
#[inline(always)]
fn count(stats: &mut Stats, (written, rejected, runs): (u32, u32, u32)) {
    stats.pixels_written = stats.pixels_written.saturating_add(written);
    stats.depth_rejected = stats.depth_rejected.saturating_add(rejected);
    stats.runs = stats.runs.saturating_add(runs);
}

/// The depths of a triangle's corners.
#[inline(always)]
fn z_of<const V: usize>(tri: &[Corner<V>; 3]) -> [f32; 3] {
    tri.each_ref().map(|v| v.z)
}

/// Draws `setup`'s pixels with `shader`: its span loop walks the rows itself for the variants
/// small targets draw with (flash: one copy per variant); the rest call it through `dyn` once
/// per run. Affine varyings where they are within tolerance (integer steps: the cheapest
/// pixels); else, with f32 perspective, the triangles whose bound allows it get perspective at
/// each pixel. The pixels written, depth-rejected, and the runs.
#[inline(always)]
fn draw<C: FrameColor, R: RunCells, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    mut shader: Shader<'_, '_, C, R, B, Lt, DITHER>,
    setup: &mut Setup<V>,
    z: [f32; 3],
    subspan: u32,
    tolerance: &[u32; V],
    fpu: bool,
) -> (u32, u32, u32) {
    let walk = B::WALK_ROWS && !DITHER;
    setup.allow_affine(*tolerance);
    if let Some(rows) = setup.affine_rows(z).filter(|_| walk) {
        shader.draw_affine_rows(rows);
        return (shader.written, shader.rejected, shader.runs);
    }
    let pixel = fpu && walk && !setup.is_affine();
    if !(pixel && shader.draw_pixel_rows(setup, z, tolerance)) {
        match if walk { setup.walked_rows(subspan, z) } else { None } {
            Some(rows) => shader.draw_rows(rows),
            None => setup.for_each_span(subspan, &mut shader),
        }
    }
    (shader.written, shader.rejected, shader.runs)
}

/// Draws the pixels of a small triangle one by one (see [`SmallTriangle::for_each_pixel`]) with
/// `shader`: the pixels written, depth-rejected, and the runs (one a pixel).
#[cfg(not(soft_float))]
#[inline(always)]
fn draw_pixels<C: FrameColor, R: RunCells, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    mut shader: Shader<'_, '_, C, R, B, Lt, DITHER>,
    small: &SmallTriangle<V>,
) -> (u32, u32, u32) {
    let base = *shader.base;
    small.for_each_pixel(|x, y, z, v| shader.pixel(&base, (x, y), z, || v.get()));
    (shader.written, shader.rejected, shader.runs)
}
