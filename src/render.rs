//! The pipeline: model → (cull, transform, light) → clip → project → rasterize → shade.

use crate::camera::Camera;
use crate::clip::{clip_triangle, ClipResult, ClipVertex, Planes, Polygon};
use crate::format::{Material, Mesh, Model};
use crate::math::{normal_matrix, normalize_or_zero, Mat3, Mat4, Vec3, Vec4};
use crate::raster::{Reject, ScreenVertex, Setup, Window, MAX_VARYINGS};
use crate::shade::{modulate, Filter, Lights, Sampler};
use crate::target::{Band, DepthBuffer, FrameColor, GUARD_HALF_EXTENT};

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
    /// in between; 1 (the default) is exact perspective correction at every pixel.
    pub subspan: u32,
    /// Whether textures are used (false: material colour only).
    pub textures: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self { shading: Shading::Gouraud, mode: Mode::Solid, filter: Filter::Nearest, subspan: 1, textures: true }
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
    }
}

// Varying slots.
const U: usize = 0;
const V: usize = 1;
const LIGHT: usize = 2; // 2, 3, 4: red, green, blue light (times vertex colour)

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
    let mut stats = Stats::default();
    for (mesh, world) in model.draws() {
        stats += draw_mesh(band, model, &mesh, transform * world, camera, lights, opts);
    }
    stats
}

/// Per-draw constants.
struct DrawSetup<'a> {
    mvp: Mat4,
    model_q: Mat4,
    normals: Mat3,
    flip: bool,
    planes: Planes,
    window: Window,
    half: (f32, f32),
    uv: ([f32; 2], [f32; 2]),
    mesh: Mesh<'a>,
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
    let mut stats = Stats { triangles_submitted: mesh.triangle_count(), ..Stats::default() };
    let vp = camera.view_projection();
    if !sphere_visible(&vp, &world, mesh.bounding_sphere()) {
        stats.culled_frustum_mesh = mesh.triangle_count();
        return stats;
    }
    let (w, h) = (band.width as f32, band.height as f32);
    let model_q = world * mesh.dequantize();
    let setup = DrawSetup {
        mvp: vp * model_q,
        model_q,
        normals: normal_matrix(&world),
        flip: Mat3::from_mat4(world).determinant() < 0.0,
        planes: Planes { gx: GUARD_HALF_EXTENT / (w * 0.5), gy: GUARD_HALF_EXTENT / (h * 0.5) },
        window: Window {
            width: band.width as i32,
            row_start: band.first_row as i32,
            row_end: band.first_row as i32 + band.rows as i32,
        },
        half: (w * 0.5, h * 0.5),
        uv: mesh.uv_transform(),
        mesh: *mesh,
    };
    for sub in mesh.submeshes() {
        let material = sub.material.and_then(|m| model.material(m)).unwrap_or_default();
        let sampler = material
            .texture
            .filter(|_| opts.textures && mesh.has_uvs())
            .and_then(|t| model.texture(t))
            .map(|t| Sampler::new(t, material.wrap_u, material.wrap_v, opts.filter));
        let first = sub.first_triangle;
        for t in first..first + sub.triangle_count {
            draw_triangle(band, &setup, t, &material, sampler.as_ref(), lights, opts, &mut stats);
        }
    }
    stats
}

/// Whether a local-space bounding sphere, placed by `world`, may be inside the view frustum.
fn sphere_visible(vp: &Mat4, world: &Mat4, (centre, radius): (Vec3, f32)) -> bool {
    let c = world.transform_point3(centre);
    let scale = [world.x_axis, world.y_axis, world.z_axis].iter().map(|a| a.truncate().length()).fold(0.0f32, f32::max);
    let r = radius * scale;
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
        // A NaN anywhere makes this comparison false: draw, and let clipping cull per triangle.
        !(p.truncate().dot(c) + p.w < -r * n)
    })
}

#[allow(clippy::too_many_arguments)]
fn draw_triangle<C: FrameColor, D: DepthBuffer, const L: usize>(
    band: &mut Band<'_, C, D>,
    s: &DrawSetup<'_>,
    t: u32,
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    lights: &Lights<L>,
    opts: &RenderOptions,
    stats: &mut Stats,
) {
    let idx = s.mesh.triangle(t);
    let qv = idx.map(|i| s.mesh.position_stored(i).extend(1.0));
    let clip = qv.map(|p| s.mvp * p);
    if crate::clip::outside_view(clip) || !clip.iter().all(|c| c.is_finite()) {
        stats.culled_frustum += 1;
        return;
    }
    let lit = vertex_light(s, &idx, &qv, lights, opts.shading);
    let tex_size = sampler.map_or((0.0, 0.0), |sm| (sm.width() as f32 * ONE, sm.height() as f32 * ONE));
    let tri: [ClipVertex; 3] = core::array::from_fn(|k| {
        let uv = s.mesh.uv_q(idx[k]);
        let (o, sc) = s.uv;
        let mut varyings = [0.0; MAX_VARYINGS];
        varyings[U] = (o[0] + uv[0] as f32 * sc[0]) * tex_size.0;
        varyings[V] = (o[1] + uv[1] as f32 * sc[1]) * tex_size.1;
        let c = s.mesh.color(idx[k]);
        for ch in 0..3 {
            varyings[LIGHT + ch] = lit[k][ch] * (c[ch] as f32 / 255.0) * ONE;
        }
        ClipVertex { pos: clip[k], varyings }
    });
    let mut poly = Polygon::new();
    match clip_triangle(&tri, &s.planes, &mut poly) {
        ClipResult::Outside => {
            stats.culled_frustum += 1;
            return;
        }
        ClipResult::Inside => {
            let _ = poly.extend_from_slice(&tri);
        }
        ClipResult::Clipped => stats.clipped += 1,
    }
    let screen: heapless::Vec<ScreenVertex, { crate::clip::MAX_CLIPPED }> =
        poly.iter().map(|v| project(v, s.half)).collect();
    match opts.mode {
        Mode::Solid => {
            for k in 1..screen.len() - 1 {
                let tri = [screen[0], screen[k], screen[k + 1]];
                fill(band, s, &tri, material, sampler, opts, stats);
            }
        }
        Mode::Wireframe | Mode::Points => {
            // Cull as a filled triangle would, then draw the outline or corners.
            let tri = [screen[0], screen[1], screen[2]];
            if let Err(r) = Setup::<0>::new(
                &tri,
                &Window { width: band.width as i32, row_start: 0, row_end: band.height as i32 },
                material.cull_back_faces,
                s.flip,
            ) {
                if r != Reject::Empty {
                    count_reject(r, stats);
                    return;
                }
            }
            stats.drawn += 1;
            let color = C::from_rgb888([material.rgba[0], material.rgba[1], material.rgba[2]]);
            for k in 0..screen.len() {
                if opts.mode == Mode::Points {
                    plot(band, &screen[k], color, stats);
                } else {
                    line(band, &screen[k], &screen[(k + 1) % screen.len()], color, stats);
                }
            }
        }
    }
}

fn count_reject(r: Reject, stats: &mut Stats) {
    match r {
        Reject::BackFace => stats.culled_back_face += 1,
        Reject::Degenerate => stats.culled_degenerate += 1,
        Reject::Empty => {}
    }
}

/// Light (0..=1 per channel) at each vertex of triangle `idx` for the shading mode.
fn vertex_light<const L: usize>(
    s: &DrawSetup<'_>,
    idx: &[u32; 3],
    qv: &[Vec4; 3],
    lights: &Lights<L>,
    shading: Shading,
) -> [Vec3; 3] {
    let world = |k: usize| (s.model_q * qv[k]).truncate();
    match shading {
        Shading::Unlit => [Vec3::ONE; 3],
        Shading::Flat => {
            let p = [world(0), world(1), world(2)];
            // Face normal from the world-space triangle. Front faces wind counter-clockwise as
            // seen (y up), and with +z pointing away from the viewer that makes
            // (p2-p0) x (p1-p0) point towards the viewer, i.e. outward.
            let mut n = normalize_or_zero((p[2] - p[0]).cross(p[1] - p[0]));
            if s.flip {
                n = -n;
            }
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            [lights.at(centre, n); 3]
        }
        Shading::Gouraud => core::array::from_fn(|k| {
            let n = normalize_or_zero(s.normals * s.mesh.normal(idx[k]));
            lights.at(world(k), n)
        }),
    }
}

/// Clip space to screen: viewport mapping, 1/16-pixel snapping, fixed-point varyings.
fn project(v: &ClipVertex, (hw, hh): (f32, f32)) -> ScreenVertex {
    let inv_w = 1.0 / v.pos.w;
    let x = (v.pos.x * inv_w + 1.0) * hw;
    let y = (1.0 - v.pos.y * inv_w) * hh;
    let snap = |p: f32| crate::math::floor(p * 16.0) as i32;
    ScreenVertex {
        x: snap(x),
        y: snap(y),
        z: ((v.pos.z * inv_w + 1.0) * 0.5).clamp(0.0, 1.0),
        inv_w,
        // Saturating casts: huge UVs clamp instead of wrapping.
        varyings: v.varyings.map(|a| a as i32),
    }
}

#[allow(clippy::too_many_arguments)]
fn fill<C: FrameColor, D: DepthBuffer>(
    band: &mut Band<'_, C, D>,
    s: &DrawSetup<'_>,
    tri: &[ScreenVertex; 3],
    material: &Material,
    sampler: Option<&Sampler<'_>>,
    opts: &RenderOptions,
    stats: &mut Stats,
) {
    let setup = match Setup::<5>::new(tri, &s.window, material.cull_back_faces, s.flip) {
        Ok(setup) => setup,
        Err(r) => return count_reject(r, stats),
    };
    stats.drawn += 1;
    let width = band.width as usize;
    let first_row = band.first_row as i32;
    let diffuse = [material.rgba[0], material.rgba[1], material.rgba[2]];
    let (color, depth) = (&mut *band.color, &mut band.depth);
    setup.for_each_pixel(opts.subspan, |x, y, z, v| {
        let i = (y - first_row) as usize * width + x as usize;
        if !depth.passes(i, z) {
            stats.depth_rejected += 1;
            return;
        }
        let base = match sampler {
            Some(sm) => {
                let t = sm.sample(v[U], v[V]);
                if t[3] < 128 {
                    return; // cut-out: neither colour nor depth
                }
                [t[0], t[1], t[2]]
            }
            None => diffuse,
        };
        let rgb = modulate(base, [v[LIGHT], v[LIGHT + 1], v[LIGHT + 2]]);
        if let Some(px) = color.get_mut(i) {
            *px = C::from_rgb888(rgb);
            depth.store(i, z);
            stats.pixels_written += 1;
        }
    });
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
    (z * (1u32 << 30) as f32) as u32
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
