//! The pipeline: model → (cull, transform, light) → clip → project → rasterize → shade.

use crate::camera::Camera;
use crate::clip::{culled, cut, finite_varyings, outcode, ClipResult, ClipVertex, Planes, Polygon, NEEDS_CLIP};
use crate::format::{Arrays, Material, Mesh, Model};
use crate::math::{normal_matrix, normalize_or_zero, FixedTransform, Mat3, Mat4, Vec3, Vec4};
use crate::raster::{
    facing, facing_of, step_varyings, Reject, ScreenVertex, Setup, Span, SpanSink, Window, MAX_VARYINGS,
};
use crate::shade::{modulate, Filter, FixedLights, Lights, PixelLights, PreparedLights, Repeat565, Sampler};
use crate::target::{Band, DepthBuffer, DepthCell, FrameColor, NoDepth, GUARD_HALF_EXTENT};

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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
    /// stepping's rounding, under 2^-16 per pixel; see `raster::Setup::allow_affine`).
    pub subspan: u32,
    /// Whether textures are used (false: material colour only).
    pub textures: bool,
    /// Ordered (4x4 Bayer) dithering when the target has fewer than 8 bits per channel.
    pub dither: bool,
    /// Vertices transformed in integers ([`FixedTransform`](crate::math::FixedTransform))
    /// instead of f32: for targets without an FPU (thumbv6m, thumbv7m), where each float
    /// operation is a library call. Within 1/16 pixel of the f32 transform (see the tests).
    pub fixed_vertices: bool,
    /// Colour of wireframe edges in [`Mode::SolidWireframe`] (and of [`Mode::Wireframe`] and
    /// [`Mode::Points`] when `Some`; `None` uses the material colour there).
    pub wire_color: Option<[u8; 3]>,
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
            wire_color: None,
        }
    }
}

/// What happened during a frame (or band), summed over all draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Triangles handed to the pipeline.
    pub triangles_submitted: u32,
    /// Triangles skipped because their mesh's bounding sphere is outside the view frustum.
    pub culled_frustum_mesh: u32,
    /// Triangles wholly outside a view plane, or with non-finite coordinates.
    pub culled_frustum: u32,
    /// Back faces culled.
    pub culled_back_face: u32,
    /// Triangles of zero area after snapping.
    pub culled_degenerate: u32,
    /// Triangles cut by the near/far/guard planes.
    pub clipped: u32,
    /// Triangles (or clipped pieces) that reached the rasterizer with pixels in this band.
    pub drawn: u32,
    /// Pixels written.
    pub pixels_written: u32,
    /// Fragments rejected by the depth test.
    pub depth_rejected: u32,
    /// Triangles skipped because they cannot touch this band: known from a [`RowCache`]
    /// before any vertex work, or found from their projected rows before lighting.
    pub outside_band: u32,
}

impl core::ops::AddAssign for Stats {
    fn add_assign(&mut self, o: Stats) {
        self.triangles_submitted += o.triangles_submitted;
        self.culled_frustum_mesh += o.culled_frustum_mesh;
        self.culled_frustum += o.culled_frustum;
        self.culled_back_face += o.culled_back_face;
        self.culled_degenerate += o.culled_degenerate;
        self.clipped += o.clipped;
        self.drawn += o.drawn;
        self.pixels_written += o.pixels_written;
        self.depth_rejected += o.depth_rejected;
        self.outside_band += o.outside_band;
    }
}

// Varying slots. Unlit/flat/Gouraud: U, V, light r, g, b. Phong: U, V, normal x, y, z,
// world position x, y, z.
const U: usize = 0;
const V_: usize = 1;
const LIGHT: usize = 2;
const NORMAL: usize = 2;
const POSITION: usize = 5;
/// Specular intensity (unlit/flat/Gouraud), added after the texture is lit.
const SPECULAR: usize = 5;

/// 1.0 in varying units.
const ONE: f32 = 65536.0;

/// Draws every mesh and instance of `model`, each placed by `transform · world` (`transform`
/// applied last, e.g. a turntable rotation), into `band`.
pub fn draw_model<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    transform: Mat4,
    camera: &Camera,
    lights: &Lights<L>,
    opts: &RenderOptions,
) -> Stats {
    draw_all(band, model, transform, &Context::new(band, camera, lights, opts), None)
}

/// Draws one mesh with the given model (local-to-world) matrix.
pub fn draw_mesh<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    mesh: &Mesh<'_>,
    world: Mat4,
    camera: &Camera,
    lights: &Lights<L>,
    opts: &RenderOptions,
) -> Stats {
    let ctx = Context::new(band, camera, lights, opts);
    draw_mesh_with(band, &ctx, model, mesh, world, (None, None))
}

/// One entry of the painter's-mode scratch list: a triangle and its sort key.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SortEntry {
    key: u32,
    draw: u16,
    triangle: u32,
}

/// The painter's-mode scratch slice is shorter than the model's triangle count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScratchTooSmall {
    /// Entries needed (triangles of all draws).
    pub needed: usize,
    /// Entries given.
    pub given: usize,
}

impl core::fmt::Display for ScratchTooSmall {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "painter's mode needs {} scratch entries, got {}", self.needed, self.given)
    }
}

/// Painter's algorithm for boards without RAM for a depth buffer: sorts every triangle back to
/// front by its farthest vertex (in `scratch`, one entry a triangle; no allocation), then draws
/// them in that order without depth testing. Intersecting or cyclically overlapping triangles
/// can show the classic painter's errors; a z-buffer does not.
///
/// # Errors
/// [`ScratchTooSmall`] when `scratch` has fewer entries than the model has triangles (counting
/// instances); nothing is drawn then.
pub fn draw_model_sorted<C: FrameColor, const L: usize>(
    band: &mut Band<'_, C, NoDepth>,
    model: &Model<'_>,
    transform: Mat4,
    camera: &Camera,
    lights: &Lights<L>,
    opts: &RenderOptions,
    scratch: &mut [SortEntry],
) -> Result<Stats, ScratchTooSmall> {
    let needed: usize = model.draws().map(|(m, _)| m.triangle_count() as usize).sum();
    if scratch.len() < needed || model.draws().count() > u16::MAX as usize {
        return Err(ScratchTooSmall { needed, given: scratch.len() });
    }
    let ctx = Context::new(band, camera, lights, opts);
    let vp = camera.view_projection();
    let mut n = 0;
    for (d, (mesh, world)) in model.draws().enumerate() {
        let mvp = vp * transform * world * mesh.dequantize();
        for t in 0..mesh.triangle_count() {
            let w = mesh.triangle(t).map(|i| (mvp * mesh.position_stored(i).extend(1.0)).w);
            let far = w[0].max(w[1]).max(w[2]);
            // Positive floats order like their bits; NaN and negatives sort as nearest.
            let key = if far > 0.0 { far.to_bits() } else { 0 };
            scratch[n] = SortEntry { key, draw: d as u16, triangle: t };
            n += 1;
        }
    }
    let list = &mut scratch[..n];
    list.sort_unstable_by_key(|e| core::cmp::Reverse(e.key));
    let mut stats = Stats::default();
    let mut current: Option<(u16, DrawSetup<'_>)> = None;
    for e in list.iter() {
        if current.as_ref().is_none_or(|(d, _)| *d != e.draw) {
            current = model
                .draws()
                .nth(e.draw as usize)
                .map(|(mesh, world)| (e.draw, DrawSetup::new(band, &ctx, mesh, transform * world)));
        }
        let Some((_, setup)) = &current else { continue };
        stats.triangles_submitted += 1;
        let sub = setup
            .mesh
            .submeshes()
            .find(|s| (s.first_triangle..s.first_triangle + s.triangle_count).contains(&e.triangle));
        let material = sub.and_then(|s| s.material).and_then(|m| model.material(m)).unwrap_or_default();
        let sampler = ctx.sampler(model, &setup.mesh, &material);
        let _ = draw_triangle(band, &ctx, setup, e.triangle, &material, sampler.as_ref(), None, &mut stats);
    }
    Ok(stats)
}

/// Per-frame constants shared by every draw.
struct Context<'l, const L: usize> {
    vp: Mat4,
    eye: Vec3,
    lights: &'l Lights<L>,
    vertex_lights: PreparedLights<L>,
    pixel_lights: PixelLights<L>,
    /// The specular colour in 8 bits (zero: specular off).
    specular: [u8; 3],
    /// Vertex lighting needs world positions (point lights or specular); directional and
    /// hemispheric light alone needs only normals.
    lit_by_position: bool,
    opts: RenderOptions,
    planes: Planes,
    window: Window,
    half: (f32, f32),
}

impl<'l, const L: usize> Context<'l, L> {
    fn new<C, D>(band: &Band<'_, C, D>, camera: &Camera, lights: &'l Lights<L>, opts: &RenderOptions) -> Self {
        let (w, h) = (band.width as f32, band.height as f32);
        Context {
            vp: camera.view_projection(),
            eye: camera.eye,
            lights,
            vertex_lights: lights.prepared(),
            specular: lights.specular.to_array().map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8),
            pixel_lights: PixelLights::new(lights),
            lit_by_position: lights.specular != Vec3::ZERO
                || lights.lights.iter().any(|l| l.kind == crate::format::LightKind::Point),
            opts: *opts,
            planes: Planes { gx: GUARD_HALF_EXTENT / (w * 0.5), gy: GUARD_HALF_EXTENT / (h * 0.5) },
            window: Window {
                width: band.width as i32,
                row_start: band.first_row as i32,
                row_end: band.first_row as i32 + band.rows as i32,
            },
            half: (w * 0.5, h * 0.5),
        }
    }

    fn sampler<'m>(&self, model: &Model<'m>, mesh: &Mesh<'_>, material: &Material) -> Option<Sampler<'m>> {
        material
            .texture
            .filter(|_| self.opts.textures && mesh.has_uvs())
            .and_then(|t| model.texture(t))
            .map(|t| Sampler::new(t, material.wrap_u, material.wrap_v, self.opts.filter))
    }
}

/// Per-draw constants.
struct DrawSetup<'a> {
    mvp: Mat4,
    model_q: Mat4,
    normals: Mat3,
    /// `normals` is a rotation (to 1e-6): stored unit normals stay unit, no normalising.
    rotation: bool,
    flip: bool,
    uv: ([f32; 2], [f32; 2]),
    mesh: Mesh<'a>,
    arrays: Arrays<'a>,
    /// The integer transform and the bounding sphere it maps float positions into, with
    /// [`RenderOptions::fixed_vertices`].
    fixed: Option<(FixedTransform, (Vec3, f32))>,
    /// Gouraud vertex light in integers, with [`RenderOptions::fixed_vertices`] when the lights
    /// allow it (see [`PreparedLights::fixed`]).
    fixed_lights: Option<FixedLights<MAX_FIXED_LIGHTS>>,
}

/// The most lights the fixed-point vertex path evaluates in integers (more: in f32).
const MAX_FIXED_LIGHTS: usize = 8;

impl<'a> DrawSetup<'a> {
    fn new<C, D, const L: usize>(_band: &Band<'_, C, D>, ctx: &Context<'_, L>, mesh: Mesh<'a>, world: Mat4) -> Self {
        let model_q = world * mesh.dequantize();
        let normals = normal_matrix(&world);
        let (mvp, arrays, sphere) = (ctx.vp * model_q, mesh.arrays(), mesh.bounding_sphere());
        let fixed = ctx.opts.fixed_vertices.then_some(()).and_then(|()| {
            let (offset, step) = arrays.int_position_frame(sphere);
            Some((FixedTransform::new(&mvp, offset, step)?, sphere))
        });
        let rotation = crate::math::is_rotation(&normals);
        let integer_light = ctx.opts.fixed_vertices && rotation && !ctx.lit_by_position;
        DrawSetup {
            mvp,
            fixed,
            fixed_lights: integer_light.then(|| ctx.vertex_lights.fixed(&normals)).flatten(),
            model_q,
            normals,
            rotation,
            flip: Mat3::from_mat4(world).determinant() < 0.0,
            uv: mesh.uv_transform(),
            arrays,
            mesh,
        }
    }
}

fn draw_mesh_with<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    model: &Model<'_>,
    mesh: &Mesh<'_>,
    world: Mat4,
    (mut rows, mut vertices): (Option<&mut [TriangleRows]>, Option<&mut [TransformedVertex]>),
) -> Stats {
    let mut stats = Stats { triangles_submitted: mesh.triangle_count(), ..Stats::default() };
    if !sphere_visible(&ctx.vp, &world, mesh.bounding_sphere()) {
        stats.culled_frustum_mesh = mesh.triangle_count();
        if let Some(rows) = rows {
            rows.fill(TriangleRows::EMPTY);
        }
        return stats;
    }
    let setup = DrawSetup::new(band, ctx, *mesh, world);
    for sub in mesh.submeshes() {
        let material = sub.material.and_then(|m| model.material(m)).unwrap_or_default();
        let sampler = ctx.sampler(model, mesh, &material);
        let range = sub.first_triangle..sub.first_triangle + sub.triangle_count;
        let mut draw = |t: u32, stats: &mut Stats| {
            draw_triangle(band, ctx, &setup, t, &material, sampler.as_ref(), vertices.as_deref_mut(), stats)
        };
        match rows.as_deref_mut().and_then(|r| r.get_mut(range.start as usize..range.end as usize)) {
            Some(seen) => {
                let (start, end) = (ctx.window.row_start, ctx.window.row_end);
                // Counted in a local: `stats` lives in memory (the draw call borrows it).
                let mut skipped = 0;
                for (t, r) in range.zip(seen) {
                    if r.may_touch(start, end) {
                        *r = draw(t, &mut stats);
                    } else {
                        skipped += 1;
                    }
                }
                stats.outside_band += skipped;
            }
            None => range.for_each(|t| {
                draw(t, &mut stats);
            }),
        }
    }
    stats
}

/// The rows a triangle can touch, learnt in the first band that processes it (see
/// [`RowCache`]). `UNKNOWN` until then; `EMPTY` for triangles that draw nothing anywhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleRows {
    first: u16,
    last: u16,
}

impl Default for TriangleRows {
    fn default() -> Self {
        Self::UNKNOWN
    }
}

impl TriangleRows {
    /// Not yet seen this frame.
    pub const UNKNOWN: TriangleRows = TriangleRows { first: 0, last: u16::MAX };
    /// Culled: draws nothing in any band.
    pub const EMPTY: TriangleRows = TriangleRows { first: u16::MAX, last: 0 };

    fn may_touch(&self, row_start: i32, row_end: i32) -> bool {
        (self.first as i32) < row_end && (self.last as i32) >= row_start
    }

    /// Rows `floor(min_y)..=floor(max_y)` of the snapped polygon: a superset of the rows whose
    /// pixel centres it covers and of the rows its wireframe lines and points touch.
    fn of(screen: &[ScreenVertex], height: u16) -> Self {
        let ys = || screen.iter().map(|v| v.y);
        Self::of_ys(ys().min().unwrap_or(0), ys().max().unwrap_or(-1), height)
    }

    /// [`TriangleRows::of`] the lowest and highest y (28.4).
    fn of_ys(min: i32, max: i32, height: u16) -> Self {
        let (min, max) = (min >> 4, max >> 4);
        if max < 0 || min >= height as i32 {
            return Self::EMPTY;
        }
        TriangleRows { first: min.max(0) as u16, last: max.min(height as i32 - 1) as u16 }
    }
}

/// A caller-owned record of which rows each triangle of a model covers, so that when a frame is
/// drawn in bands, the bands after the first skip the triangles that cannot touch them before
/// any vertex work (4 bytes a triangle, counting instances; no allocation). Optionally it also
/// keeps every vertex transformed and lit ([`RowCache::with_vertices`], 24 bytes a vertex), so
/// that a vertex shared by several triangles, or by triangles drawn in several bands, is
/// transformed and lit once a frame.
///
/// Make a new one (or [`RowCache::reset`]) at the start of every frame — rows and vertices
/// depend on the camera, transforms and lights — then pass it to [`draw_model_cached`] for each
/// band.
pub struct RowCache<'s> {
    rows: &'s mut [TriangleRows],
    vertices: &'s mut [TransformedVertex],
}

impl<'s> RowCache<'s> {
    /// A cache over `rows` (contents are reset).
    pub fn new(rows: &'s mut [TriangleRows]) -> Self {
        Self::with_vertices(rows, &mut [])
    }

    /// A cache over `rows` and `vertices` (contents are reset): one entry a triangle and one a
    /// vertex, counting instances (see [`Model::draw_counts`]).
    /// A draw whose entries do not all fit is drawn without them.
    pub fn with_vertices(rows: &'s mut [TriangleRows], vertices: &'s mut [TransformedVertex]) -> Self {
        let mut cache = RowCache { rows, vertices };
        cache.reset();
        cache
    }

    /// Forgets everything (call at the start of a frame).
    pub fn reset(&mut self) {
        self.rows.fill(TriangleRows::UNKNOWN);
        self.vertices.fill(TransformedVertex::UNKNOWN);
    }
}

/// Light (red, green, blue) and specular intensity reaching a vertex, 0..=65535 for 0..=1
/// (the varyings' 16.16 scale, with 1.0 itself saturated: the pixel loop clamps light to
/// 65535 anyway). Specular has 8 bits (a multiple of 257): it only ever scales an 8-bit
/// highlight colour.
type VertexLight = [u16; 4];

/// Quantizes light values in 0..=1 (red, green, blue, specular) to [`VertexLight`].
fn quantize_light([r, g, b, specular]: [f32; 4]) -> VertexLight {
    // Saturating, as `as u16` would, in integer code without an FPU.
    let [r, g, b] = [r, g, b].map(|x| crate::math::to_i32(x * ONE + 0.5).clamp(0, 0xffff) as u16);
    [r, g, b, crate::math::to_i32(specular * 255.0 + 0.5).clamp(0, 255) as u16 * 257]
}

/// A vertex projected and lit, computed once a frame (see [`RowCache`]): a [`Projected`] and
/// a [`VertexLight`] in 24 bytes.
#[derive(Clone, Copy, Debug)]
pub struct TransformedVertex {
    xy: [i32; 2],
    z: f32,
    inv_w: f32,
    light: [u16; 3],
    /// [`VertexLight`]'s specular / 257.
    specular: u8,
    outcode: u8,
}

const _: () = assert!(core::mem::size_of::<TransformedVertex>() == 24);

/// What the unclipped path needs of a clip-space vertex: its snapped screen position (28.4),
/// depth (0..=1) and `1/w`, meaningful when `1/w` is positive and finite, and its
/// [`outcode`]. Triangles that need clipping transform their vertices again.
#[derive(Clone, Copy, Debug)]
struct Projected {
    x: i32,
    y: i32,
    z: f32,
    inv_w: f32,
    outcode: u8,
}

impl Projected {
    fn new<const L: usize>(ctx: &Context<'_, L>, clip: Vec4) -> Self {
        let xy = project_xy(clip, ctx.half);
        Projected { x: xy.x, y: xy.y, z: depth(clip, xy.inv_w), inv_w: xy.inv_w, outcode: outcode(clip, &ctx.planes) }
    }

    /// In front of the eye, with a usable (positive, finite) `1/w`.
    #[inline(always)]
    fn in_front(&self) -> bool {
        crate::math::is_positive_finite(self.inv_w)
    }

    fn screen_vertex(&self, varyings: [i32; MAX_VARYINGS]) -> ScreenVertex {
        ScreenVertex { x: self.x, y: self.y, z: self.z, inv_w: self.inv_w, varyings }
    }
}

impl Default for TransformedVertex {
    fn default() -> Self {
        Self::UNKNOWN
    }
}

/// The `1/w` of a vertex not transformed yet this frame: +0, so that the empty cache is all zero
/// bytes (`.bss`, not flash). A vertex whose `1/w` really is +0 (an infinite `w`) is simply
/// transformed again at each use, with the same result.
const UNKNOWN_INV_W: u32 = 0;

impl TransformedVertex {
    /// Not yet transformed this frame.
    pub const UNKNOWN: TransformedVertex = TransformedVertex {
        xy: [0; 2],
        z: 0.0,
        inv_w: f32::from_bits(UNKNOWN_INV_W),
        light: [0; 3],
        specular: 0,
        outcode: 0,
    };

    fn new(p: Projected, [r, g, b, specular]: VertexLight) -> Self {
        let (xy, z, inv_w, outcode) = ([p.x, p.y], p.z, p.inv_w, p.outcode);
        TransformedVertex { xy, z, inv_w, light: [r, g, b], specular: (specular / 257) as u8, outcode }
    }

    fn projected(&self) -> Projected {
        Projected { x: self.xy[0], y: self.xy[1], z: self.z, inv_w: self.inv_w, outcode: self.outcode }
    }

    fn vertex_light(&self) -> VertexLight {
        let [r, g, b] = self.light;
        [r, g, b, self.specular as u16 * 257]
    }
}

/// [`draw_model`] for frames drawn in bands: triangles that [`RowCache`] knows cannot touch
/// this band are skipped without being transformed. Pixels are identical to [`draw_model`]'s.
/// A cache shorter than the model's triangle count only covers the first triangles.
pub fn draw_model_cached<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    transform: Mat4,
    camera: &Camera,
    lights: &Lights<L>,
    opts: &RenderOptions,
    cache: &mut RowCache<'_>,
) -> Stats {
    draw_all(band, model, transform, &Context::new(band, camera, lights, opts), Some(cache))
}

/// Every draw of `model`, with the cache's slice for each mesh's triangles when there is one.
fn draw_all<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    model: &Model<'_>,
    transform: Mat4,
    ctx: &Context<'_, L>,
    mut cache: Option<&mut RowCache<'_>>,
) -> Stats {
    let mut stats = Stats::default();
    let (mut triangles, mut vertices) = (0usize, 0usize);
    for (mesh, world) in model.draws() {
        let (nt, nv) = (mesh.triangle_count() as usize, mesh.vertex_count() as usize);
        let caches = match cache.as_mut() {
            Some(c) => (c.rows.get_mut(triangles..triangles + nt), c.vertices.get_mut(vertices..vertices + nv)),
            None => (None, None),
        };
        stats += draw_mesh_with(band, ctx, model, &mesh, transform * world, caches);
        triangles += nt;
        vertices += nv;
    }
    stats
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

/// Draws triangle `t` and returns the rows it can touch (for [`RowCache`]).
#[allow(clippy::too_many_arguments)]
fn draw_triangle<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_>,
    t: u32,
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    vertices: Option<&mut [TransformedVertex]>,
    stats: &mut Stats,
) -> TriangleRows {
    match front_end(ctx, s, (t, vertices), material, sampler, band.height, stats) {
        Front::Done(rows) => rows,
        Front::Inside(screen, known) => draw_polygon(band, ctx, s.flip, &screen, known, material, sampler, stats),
        Front::Clipped(tri) => draw_clipped(band, ctx, s.flip, &tri, material, sampler, stats),
    }
}

/// What the per-triangle front end leaves to draw.
enum Front {
    /// Nothing to draw in this band; the rows it can touch (for [`RowCache`]).
    Done(TriangleRows),
    /// Projected, wholly inside the clipping planes, with what [`facing`] and
    /// [`TriangleRows::of`] said when known.
    Inside([ScreenVertex; 3], (Option<i64>, Option<TriangleRows>)),
    /// Crosses a clipping plane: cut it first.
    Clipped([ClipVertex; 3]),
}

/// Fetch, transform, cull, light and classify triangle `t`. Not inlined: its temporaries
/// leave the stack before the rasterizer runs.
#[inline(never)]
fn front_end<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_>,
    (t, vertices): (u32, Option<&mut [TransformedVertex]>),
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    height: u16,
    stats: &mut Stats,
) -> Front {
    let idx = s.arrays.triangle(t);
    let fresh = |i: u32| Projected::new(ctx, clip_position(s, i));
    let (p, cache) = match vertices {
        Some(cache) => {
            (idx.map(|i| cached(ctx, s, cache, i).map_or_else(|| fresh(i), TransformedVertex::projected)), Some(cache))
        }
        None => (idx.map(fresh), None),
    };
    let codes = p.map(|p| p.outcode);
    if culled(codes) {
        stats.culled_frustum += 1;
        return Front::Done(TriangleRows::EMPTY);
    }
    // Back faces are rejected before any lighting when the triangle is wholly in front of the
    // eye: projection keeps the winding, and the snapped positions are the ones the rasterizer
    // gets below, so the decision is the same one it would make.
    let (mut area, mut known_rows) = (None, None);
    if p.iter().all(Projected::in_front) {
        match facing_of(p.map(|p| (p.x, p.y, p.inv_w)), material.cull_back_faces, s.flip) {
            Err(Reject::BackFace) => {
                stats.culled_back_face += 1;
                return Front::Done(TriangleRows::EMPTY);
            }
            // Kept for the rasterizer if the triangle is drawn unclipped (same positions).
            Ok(a) => area = Some(a),
            Err(_) => {}
        }
        // Rows of the unclipped triangle: a superset of what clipping leaves. A triangle that
        // cannot touch this band is not lit, clipped or set up here (a row cache learns its
        // rows for the later bands).
        let rows = TriangleRows::of_ys(p[0].y.min(p[1].y).min(p[2].y), p[0].y.max(p[1].y).max(p[2].y), height);
        if !rows.may_touch(ctx.window.row_start, ctx.window.row_end) {
            stats.outside_band += 1;
            return Front::Done(rows);
        }
        known_rows = Some(rows);
    }
    let lights = cache.map(|c| {
        idx.map(|i| c.get(i as usize).map_or_else(|| vertex_light(ctx, s, i), TransformedVertex::vertex_light))
    });
    let varyings = vertex_varyings(ctx, s, &idx, lights, sampler);
    // Light and specular come from 16-bit integers: only the others can be non-finite.
    let maybe_not_finite = if ctx.opts.shading == Shading::Phong { MAX_VARYINGS } else { LIGHT };
    if !finite_varyings(&varyings, maybe_not_finite) {
        stats.culled_frustum += 1;
        return Front::Done(TriangleRows::EMPTY);
    }
    if (codes[0] | codes[1] | codes[2]) & NEEDS_CLIP == 0 {
        // Saturating casts: huge UVs clamp instead of wrapping.
        let screen = core::array::from_fn(|k| p[k].screen_vertex(varyings[k].map(crate::math::to_i32)));
        return Front::Inside(screen, (area, known_rows));
    }
    Front::Clipped(core::array::from_fn(|k| ClipVertex { pos: clip_position(s, idx[k]), varyings: varyings[k] }))
}

/// Cuts a triangle that crosses a clipping plane and draws what is left. Not inlined: the
/// polygon buffers stay off the stack of the common, unclipped path.
#[inline(never)]
fn draw_clipped<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    flip: bool,
    tri: &[ClipVertex; 3],
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    stats: &mut Stats,
) -> TriangleRows {
    let mut poly = Polygon::new();
    if cut(tri, &ctx.planes, &mut poly) == ClipResult::Outside {
        stats.culled_frustum += 1;
        return TriangleRows::EMPTY;
    }
    stats.clipped += 1;
    let screen: heapless::Vec<ScreenVertex, { crate::clip::MAX_CLIPPED }> =
        poly.iter().map(|v| project(v, ctx.half)).collect();
    draw_polygon(band, ctx, flip, &screen, (None, None), material, sampler, stats)
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
#[allow(clippy::too_many_arguments)]
fn draw_polygon<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    flip: bool,
    screen: &[ScreenVertex],
    (area, rows): (Option<i64>, Option<TriangleRows>),
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    stats: &mut Stats,
) -> TriangleRows {
    // One facing decision for the whole (convex) polygon, the same in every band.
    let mut facing_result = area.ok_or(Reject::Empty);
    if area.is_none() {
        fan_triangle(screen, 1, |tri| facing_result = facing(tri, material.cull_back_faces, flip));
    }
    let area = match facing_result {
        Ok(a) => a,
        Err(r) => {
            if r == Reject::BackFace || screen.len() == 3 {
                count_reject(r, stats);
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
            fan_triangle(screen, k, |tri| fill(band, ctx, flip, tri, known, material, sampler, stats));
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

fn count_reject(r: Reject, stats: &mut Stats) {
    match r {
        Reject::BackFace => stats.culled_back_face += 1,
        Reject::Degenerate => stats.culled_degenerate += 1,
        Reject::Empty => {}
        Reject::OutsideGuardBand => stats.culled_frustum += 1,
    }
}

/// Vertex `i` in clip space.
fn clip_position(s: &DrawSetup<'_>, i: u32) -> Vec4 {
    match &s.fixed {
        Some((t, sphere)) => t.apply(s.arrays.position_int(i, *sphere)),
        None => s.mvp * s.arrays.position_stored(i).extend(1.0),
    }
}

/// Vertex `i` in world space.
fn world_position(s: &DrawSetup<'_>, i: u32) -> Vec3 {
    s.model_q.transform_point3(s.arrays.position_stored(i))
}

/// Vertex `i`'s world-space unit normal.
fn world_normal(s: &DrawSetup<'_>, i: u32) -> Vec3 {
    let n = s.normals * s.arrays.normal(i);
    if s.rotation {
        n
    } else {
        normalize_or_zero(n)
    }
}

/// Gouraud light of vertex `i` (zero for the other shadings, which do not use it).
fn vertex_light<const L: usize>(ctx: &Context<'_, L>, s: &DrawSetup<'_>, i: u32) -> VertexLight {
    if ctx.opts.shading != Shading::Gouraud {
        return [0; 4];
    }
    if let Some(lights) = &s.fixed_lights {
        let [r, g, b] = lights.at(s.arrays.normal_q(i));
        return [r, g, b, 0];
    }
    let n = world_normal(s, i);
    // Directional and hemispheric light need no position.
    let p = if ctx.lit_by_position { world_position(s, i) } else { Vec3::ZERO };
    let l = ctx.vertex_lights.at(p, n);
    quantize_light([l.x, l.y, l.z, ctx.lights.specular_at(p, n, ctx.eye)])
}

/// Vertex `i` in the frame's cache, transformed and lit on first use (`None` beyond the cache).
fn cached<'c, const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_>,
    cache: &'c mut [TransformedVertex],
    i: u32,
) -> Option<&'c TransformedVertex> {
    let v = cache.get_mut(i as usize)?;
    if v.inv_w.to_bits() == UNKNOWN_INV_W {
        *v = TransformedVertex::new(Projected::new(ctx, clip_position(s, i)), vertex_light(ctx, s, i));
    }
    Some(v)
}

/// The triangle's varyings for the shading mode (see the slot constants). `gouraud`: the
/// vertices' [`vertex_light`]s when already known.
fn vertex_varyings<const L: usize>(
    ctx: &Context<'_, L>,
    s: &DrawSetup<'_>,
    idx: &[u32; 3],
    gouraud: Option<[VertexLight; 3]>,
    sampler: Option<&Sampler<'_>>,
) -> [[f32; MAX_VARYINGS]; 3] {
    let shading = ctx.opts.shading;
    let world = || idx.map(|i| world_position(s, i));
    // Light and specular per vertex (unlit, flat, Gouraud) or nothing (Phong lights per pixel).
    let lit: [VertexLight; 3] = match shading {
        Shading::Unlit | Shading::Phong => [[u16::MAX, u16::MAX, u16::MAX, 0]; 3],
        Shading::Flat => {
            // Face normal from the world-space triangle. Front faces wind counter-clockwise as
            // seen (y up), and with +z pointing away from the viewer that makes
            // (p2-p0) x (p1-p0) point towards the viewer, i.e. outward.
            let p = world();
            let mut n = normalize_or_zero((p[2] - p[0]).cross(p[1] - p[0]));
            if s.flip {
                n = -n;
            }
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            let l = ctx.vertex_lights.at(centre, n);
            [quantize_light([l.x, l.y, l.z, ctx.lights.specular_at(centre, n, ctx.eye)]); 3]
        }
        Shading::Gouraud => gouraud.unwrap_or_else(|| idx.map(|i| vertex_light(ctx, s, i))),
    };
    let phong_world = if shading == Shading::Phong { world() } else { [Vec3::ZERO; 3] };
    let tex_size = sampler.map_or((0.0, 0.0), |sm| (sm.width() as f32 * ONE, sm.height() as f32 * ONE));
    core::array::from_fn(|k| {
        let uv = s.arrays.uv_q(idx[k]);
        let (o, sc) = s.uv;
        let mut varyings = [0.0; MAX_VARYINGS];
        varyings[U] = (o[0] + uv[0] as f32 * sc[0]) * tex_size.0;
        varyings[V_] = (o[1] + uv[1] as f32 * sc[1]) * tex_size.1;
        if shading == Shading::Phong {
            let n = world_normal(s, idx[k]);
            varyings[NORMAL..NORMAL + 3].copy_from_slice(&(n * ONE).to_array());
            varyings[POSITION..POSITION + 3].copy_from_slice(&(phong_world[k] * ONE).to_array());
        } else {
            let c = s.arrays.color(idx[k]);
            for ch in 0..3 {
                // White (no vertex colours) scales by exactly 1: skip the division.
                let scale = if c[ch] == 255 { 1.0 } else { c[ch] as f32 / 255.0 };
                varyings[LIGHT + ch] = lit[k][ch] as f32 * scale;
            }
            varyings[SPECULAR] = lit[k][3] as f32;
        }
        varyings
    })
}

/// Clip space to screen: viewport mapping, 1/16-pixel snapping, fixed-point varyings.
fn project(v: &ClipVertex, half: (f32, f32)) -> ScreenVertex {
    let xy = project_xy(v.pos, half);
    // Saturating casts: huge UVs clamp instead of wrapping.
    ScreenVertex { z: depth(v.pos, xy.inv_w), varyings: v.varyings.map(crate::math::to_i32), ..xy }
}

/// Depth (0..=1, near to far) of a clip-space point whose `1/w` is `inv_w`.
#[inline]
fn depth(clip: Vec4, inv_w: f32) -> f32 {
    ((clip.z * inv_w + 1.0) * 0.5).clamp(0.0, 1.0)
}

/// The snapped screen position (28.4) and `1/w` of a clip-space point; no depth or varyings.
fn project_xy(pos: Vec4, (hw, hh): (f32, f32)) -> ScreenVertex {
    let inv_w = 1.0 / pos.w;
    let x = (pos.x * inv_w + 1.0) * hw;
    let y = (1.0 - pos.y * inv_w) * hh;
    let snap = |p: f32| crate::math::floor_to_i32(p * 16.0);
    ScreenVertex { x: snap(x), y: snap(y), z: 0.0, inv_w, varyings: [0; MAX_VARYINGS] }
}

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
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3];
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
        [v[LIGHT], v[LIGHT + 1], v[LIGHT + 2]]
    }
}

/// [`Interpolated`] for white light: one varying for all three channels.
struct White;

impl Lighting for White {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        [v[LIGHT]; 3]
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
        modulate(self.0, [v[SPECULAR]; 3])
    }
}

impl<const L: usize> Lighting for PixelLights<L> {
    #[inline(always)]
    fn light<const V: usize>(&self, v: &[i32; V]) -> [i32; 3] {
        self.at([v[NORMAL], v[NORMAL + 1], v[NORMAL + 2]], [v[POSITION], v[POSITION + 1], v[POSITION + 2]])
    }
}

/// Rasterizes one screen triangle, choosing the monomorphised inner loop once per triangle so
/// the per-pixel loop never branches on modes.
#[allow(clippy::too_many_arguments)]
fn fill<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    flip: bool,
    tri: &[ScreenVertex; 3],
    area: Option<i64>,
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    stats: &mut Stats,
) {
    let r = match (sampler, sampler.and_then(Repeat565::new)) {
        (_, Some(fast)) => fill_with(band, ctx, (flip, area), tri, material, &fast, stats),
        (Some(t), None) => fill_with(band, ctx, (flip, area), tri, material, t, stats),
        (None, _) => {
            let diffuse = Diffuse([material.rgba[0], material.rgba[1], material.rgba[2]]);
            fill_with(band, ctx, (flip, area), tri, material, &diffuse, stats)
        }
    };
    match r {
        Ok(()) => stats.drawn += 1,
        Err(r) => count_reject(r, stats),
    }
}

/// [`fill`] for one base colour source: picks the lighting and dithering variant.
fn fill_with<C: FrameColor, D: DepthBuffer, B: Base, const L: usize>(
    band: &mut Band<'_, C, D>,
    ctx: &Context<'_, L>,
    flip: (bool, Option<i64>),
    tri: &[ScreenVertex; 3],
    material: &Material,
    base: &B,
    stats: &mut Stats,
) -> Result<(), Reject> {
    let cull = material.cull_back_faces;
    let specular = ctx.specular;
    let pl = &ctx.pixel_lights;
    let white =
        || tri.iter().all(|v| v.varyings[LIGHT] == v.varyings[LIGHT + 1] && v.varyings[LIGHT] == v.varyings[LIGHT + 2]);
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
        (LitBy::White, false) => fragments::<_, _, _, _, 3, false>(band, raster, tri, cull, flip, base, &White, stats),
        (LitBy::White, true) => fragments::<_, _, _, _, 3, true>(band, raster, tri, cull, flip, base, &White, stats),
        (LitBy::Vertex, false) => {
            fragments::<_, _, _, _, 5, false>(band, raster, tri, cull, flip, base, &Interpolated, stats)
        }
        (LitBy::Vertex, true) => {
            fragments::<_, _, _, _, 5, true>(band, raster, tri, cull, flip, base, &Interpolated, stats)
        }
        (LitBy::VertexAndSpecular, false) => {
            fragments::<_, _, _, _, 6, false>(band, raster, tri, cull, flip, base, &Specular(specular), stats)
        }
        (LitBy::VertexAndSpecular, true) => {
            fragments::<_, _, _, _, 6, true>(band, raster, tri, cull, flip, base, &Specular(specular), stats)
        }
        (LitBy::Pixel, false) => {
            fragments::<_, _, _, _, MAX_VARYINGS, false>(band, raster, tri, cull, flip, base, pl, stats)
        }
        (LitBy::Pixel, true) => {
            fragments::<_, _, _, _, MAX_VARYINGS, true>(band, raster, tri, cull, flip, base, pl, stats)
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
    width: usize,
    rows: usize,
    first_row: i32,
    base: &'s B,
    lighting: &'s Lt,
    written: u32,
    rejected: u32,
}

impl<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool> SpanSink<V>
    for Shader<'_, '_, C, D, B, Lt, DITHER>
{
    #[inline(never)]
    fn span(&mut self, s: &Span<V>) {
        let len = s.len as usize;
        // The run must lie on one row of this band (the rasterizer guarantees it); checked
        // anyway, in u32, where nothing can overflow (width and rows are at most 1536).
        let (row, x) = ((s.y - self.first_row) as u32 as usize, s.x as u32 as usize);
        if row >= self.rows || x >= self.width || len > self.width - x {
            return;
        }
        let start = row * self.width + x;
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
        return base.lit(v[U], v[V_], light);
    }
    let rgb = modulate(base.base(v[U], v[V_])?, light);
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
    core::array::from_fn(|k| if k == U || k == V_ { 1 << 12 } else { other })
}

// Not inlined: each variant's `Setup` gets its own frame instead of all of them sharing (and
// enlarging) the caller's.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn fragments<C: FrameColor, D: DepthBuffer, B: Base, Lt: Lighting, const V: usize, const DITHER: bool>(
    band: &mut Band<'_, C, D>,
    (window, subspan, tolerance): (&Window, u32, u32),
    tri: &[ScreenVertex; 3],
    cull_back: bool,
    (flip, area): (bool, Option<i64>),
    base: &B,
    lighting: &Lt,
    stats: &mut Stats,
) -> Result<(), Reject> {
    let mut setup = match area {
        Some(area) => Setup::<V>::with_area(tri, window, area)?,
        None => Setup::<V>::new(tri, window, cull_back, flip)?,
    };
    setup.allow_affine(affine_tolerance::<V>(tolerance));
    let mut shader = Shader::<C, D, B, Lt, DITHER> {
        width: band.width as usize,
        rows: band.rows as usize,
        first_row: band.first_row as i32,
        color: &mut *band.color,
        depth: &mut band.depth,
        base,
        lighting,
        written: 0,
        rejected: 0,
    };
    setup.for_each_span(subspan, &mut shader);
    stats.pixels_written += shader.written;
    stats.depth_rejected += shader.rejected;
    Ok(())
}

/// Writes one pixel at integer pixel `(x, y)` if it is in the band and passes depth.
fn put<C: FrameColor, D: DepthBuffer>(band: &mut Band<'_, C, D>, x: i32, y: i32, z: u32, c: C, stats: &mut Stats) {
    let row = y - band.first_row as i32;
    if x < 0 || x >= band.width as i32 || row < 0 || row >= band.rows as i32 {
        return;
    }
    let i = row as usize * band.width as usize + x as usize;
    if !band.depth.passes(i, z) {
        stats.depth_rejected += 1;
        return;
    }
    if let Some(px) = band.color.get_mut(i) {
        *px = c;
        band.depth.store(i, z);
        stats.pixels_written += 1;
    }
}

fn depth_q30(z: f32) -> u32 {
    ((z * (1u32 << 30) as f32) as u32).min(1 << 30)
}

fn plot<C: FrameColor, D: DepthBuffer>(band: &mut Band<'_, C, D>, p: &ScreenVertex, c: C, stats: &mut Stats) {
    put(band, p.x >> 4, p.y >> 4, depth_q30(p.z), c, stats);
}

/// Bresenham line between pixel centres, endpoints in canonical order so that an edge shared
/// by two triangles lights the same pixels, walked whole in every band so bands agree.
fn line<C: FrameColor, D: DepthBuffer>(
    band: &mut Band<'_, C, D>,
    a: &ScreenVertex,
    b: &ScreenVertex,
    c: C,
    stats: &mut Stats,
) {
    let (a, b) = if (a.x, a.y) <= (b.x, b.y) { (a, b) } else { (b, a) };
    let (x0, y0, x1, y1) = (a.x >> 4, a.y >> 4, b.x >> 4, b.y >> 4);
    let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
    let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
    let steps = dx.max(-dy).max(1) as f32;
    let (mut x, mut y, mut err) = (x0, y0, dx + dy);
    let mut k = 0.0;
    loop {
        let z = a.z + (b.z - a.z) * (k / steps);
        put(band, x, y, depth_q30(z), c, stats);
        if x == x1 && y == y1 {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
        k += 1.0;
    }
}
