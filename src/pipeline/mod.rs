//! The pipeline, stage by stage, and its one entry point, [`Renderer::draw`].
//!
//! A triangle's path, one file a stage:
//!
//! 1. `mod.rs` (here): per frame and per band, the [`Context`]; per mesh, its draw (`setup.rs`:
//!    the bounding-sphere test, the transforms and the [`DrawSetup`]); per triangle, the
//!    [`Scratch`] row test that skips triangles a band cannot touch.
//! 2. `vertex.rs`: fetch, transform (f32 or fixed-point), light per vertex, project, outcode;
//!    once a frame per vertex with the vertex cache in [`Scratch`]. `triangles.rs`: a band's
//!    loops over a mesh's triangles (the first band's learns their rows).
//! 3. `primitive.rs`: cull (outcodes, facing), clip (`clip.rs`), project the clipped polygon,
//!    fan it, and hand each triangle to the fill or to `line.rs` (wireframe, points).
//! 4. `raster.rs`: triangle set-up in integers, edge walks row by row, spans with depth and
//!    varyings (exact, stepped or affine).
//! 5. `fragment.rs`: the shader variant chosen once per triangle; `span/`: the span loop
//!    that runs it (depth test, texel, light, store), the one module allowed unchecked code.
//!
//! `sort.rs` orders triangles back to front for [`DrawOrder::BackToFront`] (painter's
//! algorithm); `varyings.rs` names what a vertex carries; `scratch.rs` is the caller's memory
//! for all of it. Nothing here touches a display or a file: the caller's `Band` is the only
//! output.

mod clip;
mod fragment;
mod line;
mod posed;
mod primitive;
pub(crate) mod raster;
mod scratch;
mod setup;
mod sort;
mod span;
mod stats;
pub(crate) use span::rgb565_values;
mod triangles;
mod varyings;
mod vertex;

pub use posed::posed_position;
use scratch::DrawChunks;
pub use scratch::{Scratch, SortEntry, TransformedVertex, TriangleRows};
pub(crate) use setup::{ClipTransform, DrawSetup, Transforms};
pub use stats::Stats;

pub use clip::{clip_triangle, ClipResult, ClipVertex, GuardBand, Polygon};
pub use varyings::{MAX_VARYINGS, VARYING_FRAC};

use crate::animation::Pose;
use crate::camera::Camera;
#[cfg(feature = "fog")]
use crate::fog::{Fog, PixelFog};
use crate::format::{Material, Mesh, Model, SubMesh};
use crate::light::{Lights, PixelLights, PreparedLights};
use crate::math::{Mat4, Vec3};
use crate::target::{Band, DepthBuffer, FrameColor};
use crate::texture::{Filter, Sampler};
use primitive::Surface;
use raster::Window;

/// How surfaces are lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    /// Material colour or texture as is.
    Unlit,
    /// One light value per face, from the world-space face normal.
    Flat,
    /// Light per vertex, interpolated perspective-correctly.
    #[default]
    Gouraud,
    /// Normal (and position) interpolated per pixel, normalised, and lit per pixel.
    Phong,
}

/// What is drawn of each triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Filled triangles.
    #[default]
    Solid,
    /// Edges of the visible (not culled) triangles.
    Wireframe,
    /// Vertices of the visible triangles.
    Points,
    /// Filled triangles with their edges drawn over them (debug view).
    SolidWireframe,
}

/// Per-frame choices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Lighting.
    pub shading: Shading,
    /// Fill, edges or points.
    pub mode: Mode,
    /// Texture filtering.
    pub filter: Filter,
    /// Varyings are computed exactly every `subspan` pixels along a span and stepped linearly
    /// in between. 1 (the default) is perspective-correct at every pixel: exact, or stepped
    /// linearly only where that is provably within 1/16 texel and 1/256 of full light (plus
    /// stepping's rounding, under 2^-16 per pixel; see `raster::Setup::allow_affine`). Without
    /// `fixed_vertices`, triangles of the common variants (nearest RGB565 or untextured, no
    /// dithering) that are not affine within those bounds are worked out at every pixel in f32
    /// where their error bound allows it, whatever this says: as exact, and faster.
    pub subspan: u32,
    /// Whether textures are used (false: material colour only).
    pub textures: bool,
    /// Ordered (4x4 Bayer) dithering when the target has fewer than 8 bits per channel.
    pub dither: bool,
    /// Vertices transformed in integers ([`FixedTransform`](crate::math::FixedTransform))
    /// instead of f32: for targets without an FPU (thumbv6m, thumbv7m), where each float
    /// operation is a library call. Within 1/16 pixel of the f32 transform (see the tests).
    /// Perspective-correct varyings are then worked out in integers too (f32 otherwise, which
    /// costs fewer instructions with an FPU); both are within 1/64 texel of the exact value.
    pub fixed_vertices: bool,
    /// In which order triangles are drawn (as stored, or back to front for boards without a
    /// depth buffer).
    pub order: DrawOrder,
    /// Colour of wireframe edges in [`Mode::SolidWireframe`] (and of [`Mode::Wireframe`] and
    /// [`Mode::Points`] when `Some`; `None` uses the material colour there).
    pub wire_color: Option<[u8; 3]>,
    /// Fog over filled triangles, per pixel as Babylon.js's standard material computes it (see
    /// [`Fog`]): the scene's is [`Model::fog`](crate::Model::fog); `None` (the default): none.
    /// Fogged triangles take the general span loop (not the assembly of the common variant).
    /// With feature `fog` (a default one).
    #[cfg(feature = "fog")]
    pub fog: Option<Fog>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            shading: Shading::Gouraud,
            mode: Mode::Solid,
            filter: Filter::Nearest,
            subspan: 1,
            textures: true,
            dither: false,
            fixed_vertices: false,
            order: DrawOrder::AsStored,
            wire_color: None,
            #[cfg(feature = "fog")]
            fog: None,
        }
    }
}

/// In which order triangles are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DrawOrder {
    /// As stored, mesh by mesh: the depth buffer decides what is in front.
    #[default]
    AsStored,
    /// Painter's algorithm, for boards without RAM for a depth buffer: every triangle sorted
    /// back to front by its farthest vertex (in the [`Scratch`]'s sort entries, one a triangle
    /// counting instances; no allocation), then drawn in that order. Intersecting or cyclically
    /// overlapping triangles can show the classic painter's errors; a depth buffer does not.
    BackToFront,
}

/// Why [`Renderer::draw`] drew nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError {
    /// [`DrawOrder::BackToFront`] needs one sort entry a triangle (counting instances), and the
    /// [`Scratch`] has fewer.
    ScratchTooSmall {
        /// Entries needed (triangles of all draws).
        needed: usize,
        /// Entries given.
        given: usize,
    },
}

impl core::fmt::Display for DrawError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            DrawError::ScratchTooSmall { needed, given } => {
                write!(f, "back-to-front order needs {needed} scratch sort entries, got {given}")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for DrawError {}

/// Draws models into bands: the one way to draw. Holds what is the same for every band of a
/// frame (camera, lights, options); each [`Renderer::draw`] call draws one model into one band.
///
/// ```
/// use soft3d::{Band, Camera, Lights, Mat4, Model, RenderOptions, Renderer, Scratch, Vec3};
/// use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
/// # let bytes = soft3d::convert::emit(&soft3d::convert::Scene::cube(), &Default::default())?;
/// let model = Model::parse(&bytes)?;
/// let camera = Camera::perspective(Vec3::new(0.0, 1.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0)?;
/// let lights = Lights::<2>::from_model(&model);
/// let renderer = Renderer::new(&camera, &lights, RenderOptions::default());
/// let (mut color, mut depth) = ([Rgb565::BLACK; 32 * 8], [0u16; 32 * 8]);
/// let mut scratch = Scratch::none(); // or with row, vertex and sort memory: see `Scratch`
/// for first_row in (0..32).step_by(8) {
///     let mut band = Band::new(&mut color[..], &mut depth[..], 32, 32, first_row)?;
///     band.clear(Rgb565::BLACK);
///     let stats = renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut scratch)?;
///     // send the band to the display
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct Renderer<'f, const L: usize> {
    /// What every band of every frame draws with, worked out once (not in every band: the
    /// lights' conversions are soft-float without an FPU), and kept here, in the caller's
    /// memory, off the draw's stack.
    frame: FrameConstants<'f, L>,
}

impl<'f, const L: usize> Renderer<'f, L> {
    /// A renderer for one frame (or many: nothing here changes between frames unless you
    /// change it).
    #[must_use]
    pub fn new(camera: &'f Camera, lights: &'f Lights<L>, options: RenderOptions) -> Self {
        Renderer { frame: FrameConstants::new(camera, lights, options) }
    }

    /// Lets this draw use `scratch`'s rows and vertices if they are its own (see
    /// [`Scratch::claim`]). Not inlined: the owner's record stays off the draw's stack frame.
    #[inline(never)]
    fn claim(&self, scratch: &mut Scratch<'_>, model: &Model<'_>, transform: &Mat4) {
        scratch.claim(self.owner(model, transform));
    }

    /// What a [`Scratch`]'s rows and vertices computed by this draw depend on: the frame's
    /// constants (digested once, see [`FrameConstants::digest`]), the model and the transform.
    fn owner(&self, model: &Model<'_>, transform: &Mat4) -> scratch::Owner {
        let mut d = scratch::Digest::resume(self.frame.digest);
        d.word(model.bytes().as_ptr() as usize as u32).word(model.bytes().len() as u32);
        d.floats(&transform.to_cols_array());
        scratch::Owner(d.finish())
    }

    /// The options it draws with.
    #[must_use]
    pub fn options(&self) -> &RenderOptions {
        &self.frame.opts
    }

    /// Draws every mesh and instance of `model`, each placed by `transform · world`
    /// (`transform` applied last, e.g. a turntable rotation), into `band`.
    ///
    /// `scratch` is the caller's memory for speed and for sorting (see [`Scratch`]):
    /// [`Scratch::none`] draws correctly with none. A frame drawn in bands of any height is
    /// bit-identical to the frame drawn whole, with or without scratch memory; start each frame
    /// with [`Scratch::new_frame`].
    ///
    /// # Errors
    /// [`DrawError::ScratchTooSmall`] with [`DrawOrder::BackToFront`] when the scratch has
    /// fewer sort entries than the model has triangles (nothing is drawn then).
    pub fn draw<C: FrameColor, D: DepthBuffer>(
        &self,
        band: &mut Band<'_, C, D>,
        model: &Model<'_>,
        transform: Mat4,
        scratch: &mut Scratch<'_>,
    ) -> Result<Stats, DrawError> {
        match self.frame.opts.order {
            DrawOrder::AsStored => Ok(self.draw_as_stored(band, model, transform, scratch)),
            DrawOrder::BackToFront => self.draw_sorted(band, model, transform, scratch),
        }
    }

    /// [`Renderer::draw`] with `model` in `pose` (see [`crate::animation`]): meshes that
    /// follow animated nodes are placed by them, morph targets weigh as the pose says. A pose
    /// that is not set, or a model without animation, draws the model at rest. Draw every band
    /// of a frame with the same pose.
    ///
    /// # Errors
    /// As [`Renderer::draw`].
    pub fn draw_posed<C: FrameColor, D: DepthBuffer>(
        &self,
        band: &mut Band<'_, C, D>,
        model: &Model<'_>,
        pose: &Pose<'_>,
        transform: Mat4,
        scratch: &mut Scratch<'_>,
    ) -> Result<Stats, DrawError> {
        let Some(animation) = model.animation() else {
            return self.draw(band, model, transform, scratch);
        };
        let posed = posed::Posed { pose, animation };
        let frame =
            FrameConstants { posed: Some(posed), digest: posed.digest(self.frame.digest), ..self.frame.clone() };
        Renderer { frame }.draw(band, model, transform, scratch)
    }

    /// [`DrawOrder::AsStored`]'s draw.
    #[inline(always)]
    fn draw_as_stored<C: FrameColor, D: DepthBuffer>(
        &self,
        band: &mut Band<'_, C, D>,
        model: &Model<'_>,
        transform: Mat4,
        scratch: &mut Scratch<'_>,
    ) -> Stats {
        let ctx = Context::new(band, &self.frame);
        self.claim(scratch, model, &transform);
        draw_all(band, model, &transform, &ctx, scratch)
    }

    /// [`DrawOrder::BackToFront`]'s draw (see [`Renderer::draw_as_stored`]).
    #[inline(never)]
    fn draw_sorted<C: FrameColor, D: DepthBuffer>(
        &self,
        band: &mut Band<'_, C, D>,
        model: &Model<'_>,
        transform: Mat4,
        scratch: &mut Scratch<'_>,
    ) -> Result<Stats, DrawError> {
        let ctx = Context::new(band, &self.frame);
        sort::draw_back_to_front(band, model, transform, &ctx, scratch)
    }
}

/// What every band of every frame draws with (a [`Renderer`] holds it).
#[derive(Clone, Debug)]
pub(crate) struct FrameConstants<'l, const L: usize> {
    /// The camera's view-projection matrix.
    pub(crate) vp: Mat4,
    pub(crate) eye: Vec3,
    pub(crate) lights: &'l Lights<L>,
    pub(crate) vertex_lights: PreparedLights<L>,
    /// The lights per pixel: for Phong shading, the only one that reads them.
    pub(crate) pixel_lights: PixelLights<L>,
    /// The specular colour in 8 bits (zero: specular off).
    pub(crate) specular: [u8; 3],
    /// Vertex lighting needs world positions (point lights or specular); directional and
    /// hemispheric light alone needs only normals.
    pub(crate) lit_by_position: bool,
    /// The ambient light and every light's colour are grey (the same on all three channels),
    /// so every vertex-lit corner without a vertex colour is lit white: each channel's light
    /// comes from the same operations on the same values.
    pub(crate) grey_light: bool,
    pub(crate) opts: RenderOptions,
    /// The digest of what a [`Scratch`]'s rows and vertices depend on that every draw with
    /// these constants shares (see [`Renderer::owner`]): made once, not once a band.
    digest: u64,
    /// The pose every draw of [`Renderer::draw_posed`] draws with (`None`: the model at rest).
    pub(crate) posed: Option<posed::Posed<'l>>,
    /// The options' fog with the camera's inverse projection (see [`PixelFog::frame`]).
    #[cfg(feature = "fog")]
    pub(crate) fog: Option<(Fog, Mat4)>,
}

impl<'l, const L: usize> FrameConstants<'l, L> {
    fn new(camera: &Camera, lights: &'l Lights<L>, opts: RenderOptions) -> Self {
        let vp = camera.view_projection();
        FrameConstants {
            digest: Self::digest(&vp, lights, &opts),
            vp,
            eye: camera.eye,
            lights,
            vertex_lights: lights.prepared(),
            specular: lights.specular.to_array().map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8),
            pixel_lights: if opts.shading == Shading::Phong {
                PixelLights::new(lights)
            } else {
                PixelLights::default()
            },
            lit_by_position: lights.specular != Vec3::ZERO
                || lights.lights.iter().any(|l| l.kind == crate::format::LightKind::Point),
            grey_light: is_grey(lights.ambient) && lights.lights.iter().all(|l| is_grey(l.diffuse)),
            #[cfg(feature = "fog")]
            fog: opts.fog.and_then(|f| PixelFog::frame(&f, &camera.projection)),
            opts,
            posed: None,
        }
    }
}

impl<const L: usize> FrameConstants<'_, L> {
    /// The digest of the camera's matrix `vp`, the lights and the options (see
    /// [`FrameConstants::digest`](#structfield.digest)).
    fn digest(vp: &Mat4, l: &Lights<L>, o: &RenderOptions) -> u64 {
        let mut d = scratch::Digest::new();
        d.floats(&vp.to_cols_array());
        let wire = o.wire_color.map_or(1 << 24, |[r, g, b]| u32::from_le_bytes([r, g, b, 0]));
        let flags = [o.textures, o.dither, o.fixed_vertices].iter().fold(0, |f, &b| f << 1 | u32::from(b));
        d.word(o.shading as u32).word(o.mode as u32).word(o.filter as u32).word(o.order as u32);
        d.word(o.subspan).word(wire).word(flags);
        d.floats(&l.ambient.to_array()).floats(&l.specular.to_array()).floats(&[l.shininess]);
        for x in &l.lights {
            d.word(x.kind as u32).floats(&x.vector.to_array()).floats(&x.diffuse.to_array()).floats(&[x.intensity]);
        }
        d.finish()
    }
}

/// What a band's draws share: the frame's constants and the band's place in the frame.
pub(crate) struct Context<'l, const L: usize> {
    pub(crate) frame: &'l FrameConstants<'l, L>,
    /// The frame's options (a copy: read in every triangle, and constants to the compiler
    /// when the caller's are).
    pub(crate) opts: RenderOptions,
    pub(crate) window: Window,
    /// Half the frame's width and height times 16 (in 1/16 pixels): eight times its width and
    /// height (the integer projection's; the f32 one's are in [`Projection`](setup::Projection)).
    pub(crate) half_16: [i32; 2],
    /// The frame's height in pixels.
    pub(crate) height: u16,
}

impl<'l, const L: usize> Context<'l, L> {
    pub(crate) fn new<C, D>(band: &Band<'_, C, D>, frame: &'l FrameConstants<'l, L>) -> Self {
        Context {
            frame,
            opts: frame.opts,
            window: Window {
                width: band.width as i32,
                row_start: band.first_row as i32,
                row_end: band.first_row as i32 + band.rows as i32,
            },
            half_16: [8 * i32::from(band.width), 8 * i32::from(band.height)],
            height: band.height,
        }
    }

    pub(crate) fn sampler<'m>(&self, model: &Model<'m>, mesh: &Mesh<'_>, material: &Material) -> Option<Sampler<'m>> {
        material
            .texture
            .filter(|_| self.opts.textures && mesh.has_uvs())
            .and_then(|t| model.texture(t))
            .map(|t| Sampler::new(t, material.wrap_u, material.wrap_v, self.opts.filter))
    }
}

/// Whether colour `c` is grey: the same on all three channels (not NaN).
fn is_grey(c: Vec3) -> bool {
    c.x == c.y && c.x == c.z
}

pub(crate) fn draw_mesh_with<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    model: &Model<'_>,
    mesh: &Mesh<'_>,
    place: impl Fn() -> Mat4 + Copy,
    ((mut rows, mut vertices, chunks), unclipped): (Caches<'_>, Option<bool>),
    stats: &mut Stats,
) -> Option<bool> {
    stats.triangles_submitted = stats.triangles_submitted.saturating_add(mesh.triangle_count());
    // Every triangle fills from a vertex cache that holds all the draw's vertices, none needing
    // clipping, in these modes: with neither the draw's matrix nor its transforms (matrix
    // products: soft-float without an FPU), but for flat shading's face light.
    let from_cache = ctx.opts.mode == Mode::Solid && ctx.opts.shading != Shading::Flat;
    // A band after the first whose draw found its vertices `unclipped` (and whether its
    // transform mirrors), when they are in the cache (filled this frame, for this model,
    // options and transform: the scratch's owner): nothing to work out. Any other works them
    // out, at the top of the draw (not under a triangle, where the stack is deeper).
    let filled = vertices.as_deref().is_some_and(vertex::is_filled);
    let (flip, filled_now) = match unclipped.filter(|_| filled && from_cache) {
        Some(flip) => (flip, false),
        None => {
            // `unclipped`: an earlier band of this frame found the mesh in view (the same
            // test, for the same camera and transform).
            let caches = (rows.as_deref_mut(), vertices.as_deref_mut(), chunks);
            let view = (place, unclipped.is_none());
            match transform_and_draw(band, ctx, model, (mesh, view), caches, from_cache, stats) {
                Transformed::Drawn(filled_unclipped) => return filled_unclipped,
                Transformed::Filled(flip) => (flip, true),
                Transformed::OutOfView => {
                    stats.culled_frustum_mesh = stats.culled_frustum_mesh.saturating_add(mesh.triangle_count());
                    if let Some(rows) = rows {
                        rows.fill(TriangleRows::EMPTY);
                    }
                    return None;
                }
            }
        }
    };
    let mut setup = DrawSetup::without_transforms(*mesh, flip);
    setup.vertices = vertices.map(|v| &*v);
    setup.chunks = chunks;
    draw_submeshes(band, ctx, model, &setup, rows, stats);
    filled_now.then_some(flip)
}

/// What [`transform_and_draw`] did.
enum Transformed {
    /// Nothing: the mesh is out of view (see [`Transforms::placement`]).
    OutOfView,
    /// It drew the mesh; whether it filled the vertex cache with no vertex needing clipping, and
    /// then whether the transform mirrors.
    Drawn(Option<bool>),
    /// It filled the vertex cache with no vertex needing clipping, in a mode whose triangles
    /// all fill from it: the caller draws them, without the transforms; whether the transform
    /// mirrors.
    Filled(bool),
}

/// The transforms of `mesh` placed by `place()`, unless it is out of view (tested with
/// `test_view`), the vertex cache filled with them, and the draw, unless every triangle fills
/// from that cache (`from_cache` and none needs clipping): then the caller draws it. Not
/// inlined: the transforms live in this frame, which the common draw from the cache does not
/// have under its rasterizer (the deepest stack).
#[inline(never)]
fn transform_and_draw<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    model: &Model<'_>,
    (mesh, (place, test_view)): (&Mesh<'_>, (impl FnOnce() -> Mat4, bool)),
    (rows, cache, chunks): Caches<'_>,
    from_cache: bool,
    stats: &mut Stats,
) -> Transformed {
    let Some((world, flip)) = Transforms::placement(ctx, mesh, place, test_view) else {
        return Transformed::OutOfView;
    };
    let deforming = ctx.frame.posed.as_ref().and_then(|p| p.deforming(model, mesh.mesh_index()));
    let transforms = Transforms::new(ctx, mesh, &world, deforming.as_ref());
    // The cache holds one set of texel coordinates, and nothing Phong needs.
    let scale = uniform_texel_scale(ctx, model, mesh).filter(|_| ctx.opts.shading != Shading::Phong);
    let mut setup = DrawSetup::new(*mesh, &transforms, flip);
    if let Some(deforming) = &deforming {
        setup.arrays = setup.arrays.morphed(deforming);
    }
    let mut filled_unclipped = false;
    if let Some((cache, scale)) = cache.zip(scale) {
        filled_unclipped = vertex::fill_cache(ctx, (&setup, &transforms), cache, scale);
        if filled_unclipped && from_cache {
            return Transformed::Filled(flip);
        }
        setup.vertices = Some(cache);
    }
    setup.chunks = chunks;
    draw_submeshes(band, ctx, model, &setup, rows, stats);
    Transformed::Drawn(filled_unclipped.then_some(flip))
}

/// Draws every sub-mesh of draw `setup`, with `rows` its triangles' rows in the scratch when
/// it has them.
#[inline(always)]
fn draw_submeshes<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    model: &Model<'_>,
    setup: &DrawSetup<'_, L>,
    mut rows: Option<&mut [TriangleRows]>,
    stats: &mut Stats,
) {
    for sub in setup.mesh.submeshes() {
        let (first, count) = (sub.first_triangle as usize, sub.triangle_count as usize);
        let seen = rows.as_deref_mut().and_then(|r| r.get_mut(first..first.saturating_add(count)));
        draw_submesh(band, ctx, model, setup, &sub, seen, stats);
    }
}

/// Draws sub-mesh `sub` of draw `setup`, with `seen` its triangles' rows in the scratch when it
/// has them. Not inlined: its surface and their temporaries stay out of the draw's frame.
#[inline(never)]
fn draw_submesh<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    model: &Model<'_>,
    setup: &DrawSetup<'_, L>,
    sub: &SubMesh,
    seen: Option<&mut [TriangleRows]>,
    stats: &mut Stats,
) {
    let material = material_of(model, sub);
    let sampler = ctx.sampler(model, &setup.mesh, &material);
    let surface = Surface::new(&material, sampler.as_ref(), ctx, setup);
    let range = sub.first_triangle..sub.first_triangle + sub.triangle_count;
    let variant = surface.lit.map(|lit| fragment::variant(ctx, &surface, lit));
    triangles::draw_range(band, ctx, setup, (range, seen), (&surface, variant), stats);
}

/// A draw's rows and vertices in the scratch (see [`Scratch::for_draw`]).
type Caches<'s> = (Option<&'s mut [TriangleRows]>, Option<&'s mut [TransformedVertex]>, Option<DrawChunks<'s>>);

/// The material sub-mesh `sub` draws with (the default one when it has none).
fn material_of(model: &Model<'_>, sub: &SubMesh) -> Material {
    sub.material.and_then(|m| model.material(m)).unwrap_or_default()
}

/// The texel scale ([`texel_scale`](vertex::texel_scale)) all of `mesh`'s sub-meshes draw with,
/// `None` when they differ.
fn uniform_texel_scale<const L: usize>(ctx: &Context<'_, L>, model: &Model<'_>, mesh: &Mesh<'_>) -> Option<(f32, f32)> {
    let mut scales = mesh.submeshes().map(|sub| {
        let material = material_of(model, &sub);
        vertex::texel_scale(ctx.sampler(model, mesh, &material).as_ref())
    });
    let first = scales.next().unwrap_or((0.0, 0.0));
    scales.all(|s| s == first).then_some(first)
}

/// Every draw of `model`, with the scratch's rows and vertices for each mesh when they fit.
fn draw_all<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    transform: &Mat4,
    ctx: &Context<'_, L>,
    scratch: &mut Scratch<'_>,
) -> Stats {
    let mut stats = Stats::default();
    let (mut triangles, mut vertices) = (0usize, 0usize);
    // The world matrix read where it is needed, not held here while the draw runs (stack).
    for d in 0..model.draw_count() {
        let Some((mesh, world)) = model.placed_draw(d) else { continue };
        let (nt, nv) = (mesh.triangle_count() as usize, mesh.vertex_count() as usize);
        let unclipped = scratch.unclipped(d);
        let caches = scratch.for_draw(triangles..triangles.saturating_add(nt), vertices..vertices.saturating_add(nv));
        let place = || *transform * posed::draw_world(ctx.frame.posed.as_ref(), model, d, world);
        let filled_unclipped = draw_mesh_with(band, ctx, model, &mesh, place, (caches, unclipped), &mut stats);
        if let Some(flip) = filled_unclipped {
            scratch.set_unclipped(d, flip);
        }
        // Saturating (instances can pass `usize::MAX` on a 32-bit target): a range beyond the
        // scratch draws without it.
        triangles = triangles.saturating_add(nt);
        vertices = vertices.saturating_add(nv);
    }
    scratch.summarise_rows(triangles, ctx.window.row_start <= 0 && ctx.window.row_end >= i32::from(ctx.height));
    stats
}
