//! Host benchmark (criterion): wall-clock time per frame of soft3d on the development machine,
//! side by side with two peer software renderers drawing the same Suzanne frame: `euc` 0.5 and
//! `embedded-3dgfx` 0.7.
//!
//! `cargo bench --bench host` (about a minute). Every frame is: clear colour, clear depth, draw,
//! into buffers allocated once outside the timing loop (RGB565 colour, `u16` depth for soft3d;
//! RGB565 colour, `f32` depth for euc; RGB565 colour, `u32` depth for embedded-3dgfx). At the end a table of per-frame medians is printed; the
//! medians are those of criterion's samples (each sample's time / its iteration count), recorded
//! by the routines below as criterion runs them, so they equal criterion's reported medians.
//!
//! Scenes:
//! 1. the reference Suzanne frame (`soft3d::testing::reference`), textured Gouraud, 240x240 and 640x480;
//! 2. Suzanne flat-shaded, untextured, 240x240 and 640x480;
//! 3. the teapot asset, Phong, scene lights, 640x480;
//! 4. fill rate: three full-screen quads (6 triangles) drawn back to front, 640x480;
//! 5. triangle rate: UV spheres of ~1k, ~10k and ~100k triangles, Gouraud, untextured, 640x480;
//! 6. the reference frame at 240x240 in 8 bands of 240x30 (with and without a `Scratch`)
//!    versus 1 band;
//!
//! soft3d draws through `Renderer::draw` with a `Scratch` holding every triangle's rows and
//! every transformed vertex (scratch allocated once), as a frame-drawing application would;
//! scene 6 also shows 8 bands drawn with `Scratch::none()`, without any cache.
//! 7. euc 0.5 rendering the same Suzanne mesh (same triangles, matrices, texture, lights).
//! 8. embedded-3dgfx 0.7 rendering the same Suzanne mesh (same triangles, camera, model yaw and
//!    texture; its own textured Gouraud lighting, see [`E3dFrame`]).
//!
//! Side effects (once, outside the timing): `out/bench-soft3d.png`, `out/bench-euc.png` and
//! `out/bench-embedded-3dgfx.png`, the three renderers' 240x240 Suzanne frames.

use std::convert::Infallible;
use std::f32::consts::PI;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, SamplingMode};
use embedded_3dgfx::engine::K3dengine;
use embedded_3dgfx::pipeline::command_buffer::CommandBuffer;
use embedded_3dgfx::pipeline::rasterize::texture::{Texture, TextureManager};
use embedded_3dgfx::pipeline::renderer::FrameCtx;
use embedded_3dgfx::pipeline::vertex::mesh::{Geometry, K3dMesh, RenderMode};
use embedded_3dgfx::{ZDepth, Z_MAX_VALUE};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
use embedded_graphics_core::Pixel;
use euc::buffer::Buffer2d;
use euc::rasterizer::{BackfaceCullingEnabled, Triangles};
use euc::{Pipeline, Target};
use soft3d::convert::scene::{MaterialData, MeshData, Scene, SubMeshData, TextureData, IDENTITY};
use soft3d::convert::{emit, EmitOptions};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::math::{normal_matrix, normalize_or_zero, Mat3, Mat4, Vec3};
use soft3d::testing::reference;
use soft3d::{
    Band, Camera, FrameColor, Lights, Model, RenderOptions, Scratch, Shading, Stats, TransformedVertex, TriangleRows,
};

const SAMPLE_SIZE: usize = 20;
const MEASUREMENT: Duration = Duration::from_secs(2);
const WARM_UP: Duration = Duration::from_millis(700);

/// Texture size of the reference frame's conversion (the QEMU firmware's: 128 texels).
const REFERENCE_TEXTURE: u32 = 128;

fn asset(rel: &str) -> String {
    format!("{}/assets/{rel}", env!("CARGO_MANIFEST_DIR"))
}

/// Suzanne as the reference frame converts it: UV origin at the top, 128-texel texture, exact
/// f32 positions. Returns the converted scene too (euc draws from it).
fn suzanne() -> (Scene, Vec<u8>) {
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(REFERENCE_TEXTURE), ..Default::default() };
    let (scene, _) = read_babylon_file(asset("suzanne/monkey.babylon").as_ref(), &opts).expect("Suzanne converts");
    let bytes = emit(&scene, &EmitOptions { float_positions: true, ..Default::default() }).expect("emit Suzanne");
    (scene, bytes)
}

fn teapot() -> Vec<u8> {
    let (scene, _) = read_babylon_file(asset("teapot/teapot.babylon").as_ref(), &ConvertOptions::default())
        .expect("teapot converts");
    emit(&scene, &EmitOptions::default()).expect("emit teapot")
}

/// A scene of one mesh with one material.
fn one_mesh_scene(mesh: MeshData, material: MaterialData, textures: Vec<TextureData>) -> Scene {
    Scene { meshes: vec![mesh], materials: vec![material], textures, ..Default::default() }
}

/// A UV sphere of radius 1 at the origin with `slices` x `stacks` quads (the pole rows are
/// triangles): `slices · (2 · stacks - 2)` triangles, counter-clockwise seen from outside.
fn sphere(slices: u32, stacks: u32) -> Vec<u8> {
    let mut positions = Vec::new();
    for i in 0..=stacks {
        let theta = PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = 2.0 * PI * j as f32 / slices as f32;
            positions.push([theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()]);
        }
    }
    let at = |i: u32, j: u32| i * (slices + 1) + j;
    let mut indices = Vec::new();
    for i in 0..stacks {
        for j in 0..slices {
            // a above b, d right of a (seen from outside, y up): a b c and a c d are CCW.
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i != stacks - 1 {
                indices.extend([a, b, c]);
            }
            if i != 0 {
                indices.extend([a, c, d]);
            }
        }
    }
    let count = indices.len() as u32;
    let mesh = MeshData {
        name: "sphere".into(),
        world: IDENTITY,
        normals: positions.clone(),
        positions,
        uvs: None,
        colors: None,
        indices,
        submeshes: vec![SubMeshData { material: Some(0), index_start: 0, index_count: count }],
    };
    let material = MaterialData { name: "orange".into(), diffuse: [0.9, 0.6, 0.3], ..Default::default() };
    emit(&one_mesh_scene(mesh, material, vec![]), &EmitOptions::default()).expect("emit sphere")
}

/// Three textured quads (6 triangles) facing the reference camera, each a little larger than a
/// `aspect`-shaped frame, stored far to near so that every fragment passes the depth test:
/// 3 writes per pixel.
fn fill_quads(aspect: f32, texture: TextureData) -> Vec<u8> {
    let (mut positions, mut normals, mut uvs, mut indices) = (vec![], vec![], vec![], vec![]);
    for (k, z) in [2.0f32, 1.0, 0.0].into_iter().enumerate() {
        // The reference camera is at z = -4 with a vertical field of view of 0.8 rad.
        let h = (4.0 + z) * (0.4f32).tan() * 1.05;
        let w = h * aspect;
        let base = positions.len() as u32;
        positions.extend([[-w, -h, z], [w, -h, z], [w, h, z], [-w, h, z]]);
        normals.extend([[0.0, 0.0, -1.0]; 4]);
        let s = 2.0 + k as f32;
        uvs.extend([[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]]);
        indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    let mesh = MeshData {
        name: "quads".into(),
        world: IDENTITY,
        positions,
        normals,
        uvs: Some(uvs),
        colors: None,
        indices,
        submeshes: vec![SubMeshData { material: Some(0), index_start: 0, index_count: 18 }],
    };
    let material = MaterialData { name: "textured".into(), texture: Some(0), ..Default::default() };
    emit(&one_mesh_scene(mesh, material, vec![texture]), &EmitOptions::default()).expect("emit quads")
}

/// A whole-frame colour and depth buffer for soft3d, and the memory of its [`Scratch`].
struct Frame {
    width: u16,
    height: u16,
    color: Vec<Rgb565>,
    depth: Vec<u16>,
    rows_seen: Vec<TriangleRows>,
    vertices_seen: Vec<TransformedVertex>,
}

/// Everything one soft3d frame needs besides the buffers.
struct Job<'m, const L: usize> {
    model: Model<'m>,
    transform: Mat4,
    camera: Camera,
    lights: Lights<L>,
    opts: RenderOptions,
}

impl Frame {
    fn new(width: u16, height: u16) -> Self {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![Rgb565::BLACK; n],
            depth: vec![0; n],
            rows_seen: Vec::new(),
            vertices_seen: Vec::new(),
        }
    }

    /// One frame in bands of `rows` rows (the last band may be shorter) with plain
    /// No scratch: clear and draw each.
    fn render_uncached<const L: usize>(&mut self, job: &Job<'_, L>, rows: u16) -> Stats {
        let chunk = rows as usize * self.width as usize;
        let mut stats = Stats::default();
        for (k, (c, z)) in self.color.chunks_mut(chunk).zip(self.depth.chunks_mut(chunk)).enumerate() {
            let mut band = Band::new(c, z, self.width, self.height, k as u16 * rows).expect("band fits the frame");
            band.clear(Rgb565::BLACK);
            stats += soft3d::Renderer::new(&job.camera, &job.lights, job.opts)
                .draw(&mut band, &job.model, job.transform, &mut soft3d::Scratch::none())
                .unwrap();
        }
        stats
    }

    /// Like [`Frame::render_uncached`], with a [`Scratch`] of every triangle's rows and every
    /// transformed vertex (reset at the start of the frame): each vertex is transformed and
    /// lit once, and later bands skip triangles that cannot touch them.
    fn render<const L: usize>(&mut self, job: &Job<'_, L>, rows: u16) -> Stats {
        let (triangles, vertices) = job.model.draw_counts();
        self.rows_seen.resize(triangles, TriangleRows::UNKNOWN);
        self.vertices_seen.resize(vertices, TransformedVertex::UNKNOWN);
        let mut cache = Scratch::none().with_rows(&mut self.rows_seen).with_vertices(&mut self.vertices_seen);
        let chunk = rows as usize * self.width as usize;
        let mut stats = Stats::default();
        for (k, (c, z)) in self.color.chunks_mut(chunk).zip(self.depth.chunks_mut(chunk)).enumerate() {
            let mut band = Band::new(c, z, self.width, self.height, k as u16 * rows).expect("band fits the frame");
            band.clear(Rgb565::BLACK);
            let (m, t, cam, l, o) = (&job.model, job.transform, &job.camera, &job.lights, &job.opts);
            stats += soft3d::Renderer::new(cam, l, *o).draw(&mut band, m, t, &mut cache).unwrap();
        }
        stats
    }

    fn covered(&self) -> usize {
        self.depth.iter().filter(|&&d| d != u16::MAX).count()
    }
}

/// euc's view of the converted Suzanne mesh: indexed positions, normals and UVs; per-vertex
/// (Gouraud) light from the same [`Lights`]; nearest, repeating texture lookup per pixel.
struct EucSuzanne<'a> {
    mvp: Mat4,
    world: Mat4,
    normal_matrix: Mat3,
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    uvs: &'a [[f32; 2]],
    lights: &'a Lights<1>,
    /// RGB texels, row 0 = bottom row of the image (v = 0).
    texels: &'a [[u8; 3]],
    tex_size: (usize, usize),
}

impl Pipeline for EucSuzanne<'_> {
    type Vertex = u32;
    /// (texel u, texel v), (light r, g, b).
    type VsOut = ((f32, f32), (f32, f32, f32));
    type Pixel = Rgb565;

    #[inline(always)]
    fn vert(&self, &i: &u32) -> ([f32; 4], Self::VsOut) {
        let i = i as usize;
        let p = Vec3::from(self.positions[i]);
        let clip = self.mvp * p.extend(1.0);
        let n = normalize_or_zero(self.normal_matrix * Vec3::from(self.normals[i]));
        let light = self.lights.at(self.world.transform_point3(p), n);
        let uv = self.uvs[i];
        let (w, h) = self.tex_size;
        (clip.to_array(), ((uv[0] * w as f32, uv[1] * h as f32), (light.x, light.y, light.z)))
    }

    #[inline(always)]
    fn frag(&self, &((u, v), (r, g, b)): &Self::VsOut) -> Rgb565 {
        let (w, h) = self.tex_size;
        let i = (u.floor() as i32).rem_euclid(w as i32) as usize;
        let j = (v.floor() as i32).rem_euclid(h as i32) as usize;
        let t = self.texels[j * w + i];
        let m = |c: u8, l: f32| (c as f32 * l.clamp(0.0, 1.0) + 0.5) as u8;
        Rgb565::from_rgb888([m(t[0], r), m(t[1], g), m(t[2], b)])
    }
}

/// euc's colour and depth buffers plus the Suzanne data it draws.
struct EucFrame<'a> {
    color: Buffer2d<Rgb565>,
    depth: Buffer2d<f32>,
    pipeline: EucSuzanne<'a>,
    indices: &'a [u32],
}

impl EucFrame<'_> {
    fn render(&mut self) {
        self.color.clear(Rgb565::BLACK);
        self.depth.clear(1.0);
        self.pipeline.draw::<Triangles<'_, Buffer2d<f32>, BackfaceCullingEnabled>, _>(
            self.indices,
            &mut self.color,
            Some(&mut self.depth),
        );
    }

    fn covered(&self) -> usize {
        self.depth.as_ref().iter().filter(|&&d| d != 1.0).count()
    }
}

/// The Suzanne texture as RGB rows from the bottom (v = 0), as soft3d addresses it.
fn texels_from_bottom(t: &TextureData) -> Vec<[u8; 3]> {
    let (w, h) = (t.width as usize, t.height as usize);
    (0..h)
        .rev()
        .flat_map(|row| (0..w).map(move |col| (row * w + col) * 4))
        .map(|at| [t.rgba[at], t.rgba[at + 1], t.rgba[at + 2]])
        .collect()
}

/// Capacity of embedded-3dgfx's command buffer: one depth clear plus one command per front-facing
/// Suzanne triangle (968 triangles in all).
const E3D_COMMANDS: usize = 1024;

/// A small in-memory `DrawTarget` for embedded-3dgfx, which hands its rasterizers' pixels to
/// `draw_iter` one at a time.
struct E3dTarget {
    width: u32,
    height: u32,
    pixels: Vec<Rgb565>,
}

impl OriginDimensions for E3dTarget {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for E3dTarget {
    type Color = Rgb565;
    type Error = Infallible;

    #[inline]
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb565>>>(&mut self, pixels: I) -> Result<(), Infallible> {
        let (w, h) = (self.width as i32, self.height as i32);
        for Pixel(p, c) in pixels {
            if (0..w).contains(&p.x) && (0..h).contains(&p.y) {
                self.pixels[(p.y * w + p.x) as usize] = c;
            }
        }
        Ok(())
    }
}

/// The Suzanne data as embedded-3dgfx's `Geometry` takes it, built once outside the timing.
struct E3dSuzanne {
    faces: Vec<[usize; 3]>,
    /// One outward unit normal per face (embedded-3dgfx culls and lights only with these).
    face_normals: Vec<[f32; 3]>,
}

impl E3dSuzanne {
    fn new(mesh: &MeshData) -> Self {
        let faces: Vec<[usize; 3]> =
            mesh.indices.chunks_exact(3).map(|t| [t[0] as usize, t[1] as usize, t[2] as usize]).collect();
        // The winding of the converted (left-handed) mesh is not the right-handed one
        // `Geometry::calculate_face_normal` assumes: orient each face normal by its vertex normals.
        let face_normals = faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| mesh.positions[i]);
                let n = Geometry::calculate_face_normal(&a, &b, &c);
                let sum = f.iter().fold(Vec3::ZERO, |s, &i| s + Vec3::from(mesh.normals[i]));
                if Vec3::from(n).dot(sum) < 0.0 {
                    n.map(|x| -x)
                } else {
                    n
                }
            })
            .collect();
        E3dSuzanne { faces, face_normals }
    }
}

/// embedded-3dgfx 0.7 drawing the Suzanne frame: `RenderMode::TexturedGouraud` through
/// `record` + `execute_with_textures` (its perspective-correct, nearest, repeating texture
/// lookup, modulated by per-vertex light), z-buffered (`u32` depth), back faces culled by the
/// face normals.
///
/// embedded-3dgfx's camera is right-handed (`look_at_rh`) and soft3d's (Babylon's) left-handed,
/// so the model matrix is soft3d's world matrix followed by a mirror of x: the same camera
/// (eye (0, 0, -4), target the origin, vertical field of view 0.8 rad, near 0.1, far 100) then
/// sees the same picture, and the light direction is mirrored likewise. Its lighting model is
/// fixed: `white · (n · l) + 0.1 · white` per vertex, quantized to RGB565, with `l` = the
/// reference light's direction (towards the light) scaled by its intensity 0.8. So it has
/// ambient 0.1 where the reference lights have 0.2, and a white material of 31/32 (red,
/// blue) and 63/64 (green).
struct E3dFrame<'a> {
    engine: K3dengine,
    mesh: K3dMesh<'a>,
    textures: TextureManager<1>,
    commands: Box<CommandBuffer<E3D_COMMANDS>>,
    target: E3dTarget,
    depth: Vec<ZDepth>,
}

impl<'a> E3dFrame<'a> {
    fn new(
        (w, h): (u16, u16),
        mesh: &'a MeshData,
        data: &'a E3dSuzanne,
        world: Mat4,
        uvs: &'a [[f32; 2]],
        texture: Texture,
    ) -> Self {
        let mut engine = K3dengine::new(w, h);
        engine.camera.set_position(nalgebra::Point3::new(0.0, 0.0, -4.0));
        engine.camera.set_target(nalgebra::Point3::origin());
        engine.camera.set_fovy(0.8);
        engine.camera.set_near_far(0.1, 100.0);

        let mut textures = TextureManager::<1>::new();
        let texture_id = textures.add_texture(texture).expect("room for one texture");
        let geometry = Geometry {
            vertices: &mesh.positions,
            faces: &data.faces,
            colors: &[],
            lines: &[],
            normals: &data.face_normals,
            vertex_normals: &mesh.normals,
            uvs,
            texture_id: Some(texture_id),
        };
        // The reference light: direction (0.5, -0.5, 1), intensity 0.8. Towards the light,
        // mirrored in x like the model; embedded-3dgfx negates z of the vector it is given.
        let towards = -Vec3::new(0.5, -0.5, 1.0).normalize() * 0.8;
        let mirrored = Vec3::new(-towards.x, towards.y, towards.z);
        let mut e3d_mesh = K3dMesh::new(geometry);
        e3d_mesh.set_render_mode(RenderMode::TexturedGouraud(nalgebra::Vector3::new(
            mirrored.x,
            mirrored.y,
            -mirrored.z,
        )));
        let mirror_x = nalgebra::Matrix4::new_nonuniform_scaling(&nalgebra::Vector3::new(-1.0, 1.0, 1.0));
        e3d_mesh.model_matrix = mirror_x * nalgebra::Matrix4::from_column_slice(&world.to_cols_array());

        let n = w as usize * h as usize;
        E3dFrame {
            engine,
            mesh: e3d_mesh,
            textures,
            commands: Box::new(CommandBuffer::new()),
            target: E3dTarget { width: w as u32, height: h as u32, pixels: vec![Rgb565::BLACK; n] },
            depth: vec![Z_MAX_VALUE; n],
        }
    }

    /// Clear colour, then record (which queues the depth clear) and execute.
    fn render(&mut self) {
        self.target.pixels.fill(Rgb565::BLACK);
        self.engine.record(core::iter::once(&self.mesh), &mut self.commands, None).expect("record");
        let mut ctx = FrameCtx {
            zbuffer: &mut self.depth,
            width: self.target.width as usize,
            height: self.target.height as usize,
        };
        self.engine
            .execute_with_textures(&mut self.target, &mut ctx, &self.commands, &self.textures, None)
            .expect("execute");
    }

    fn covered(&self) -> usize {
        self.depth.iter().filter(|&&d| d != Z_MAX_VALUE).count()
    }
}

fn save_png(name: &str, width: u16, pixels: &[Rgb565]) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("out");
    std::fs::create_dir_all(&dir).expect("create out/");
    let bytes: Vec<u8> = pixels.iter().flat_map(|c| c.to_rgb888()).collect();
    let height = (pixels.len() / width as usize) as u32;
    let img = image::RgbImage::from_raw(width as u32, height, bytes).expect("image size");
    img.save(dir.join(name)).expect("write PNG");
    println!("wrote out/{name}");
}

/// Runs one benchmark and returns the median of criterion's per-iteration sample times (ms), or
/// `None` when the benchmark was filtered out.
fn bench(group: &mut BenchmarkGroup<'_, WallTime>, id: &str, mut frame: impl FnMut()) -> Option<f64> {
    let mut samples = Vec::new();
    group.bench_function(id, |b| {
        b.iter_custom(|iters| {
            let start = Instant::now();
            for _ in 0..iters {
                frame();
            }
            let elapsed = start.elapsed();
            samples.push(elapsed.as_secs_f64() * 1e3 / iters as f64);
            elapsed
        })
    });
    // Warm-up calls come first; the last SAMPLE_SIZE calls are the measured samples.
    let mut last: Vec<f64> = samples.iter().rev().take(SAMPLE_SIZE).copied().collect();
    if last.is_empty() {
        return None;
    }
    last.sort_by(f64::total_cmp);
    let n = last.len();
    Some(if n % 2 == 1 { last[n / 2] } else { (last[n / 2 - 1] + last[n / 2]) / 2.0 })
}

fn group<'c>(c: &'c mut Criterion, name: &str) -> BenchmarkGroup<'c, WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(SAMPLE_SIZE).measurement_time(MEASUREMENT).warm_up_time(WARM_UP).sampling_mode(SamplingMode::Flat);
    g
}

/// One line of the final table.
struct Row {
    scene: String,
    soft3d: Option<f64>,
    euc: Option<f64>,
    e3d: Option<f64>,
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let mut rows: Vec<Row> = Vec::new();
    let mut row = |scene: &str, soft3d: Option<f64>, euc: Option<f64>| {
        rows.push(Row { scene: scene.into(), soft3d, euc, e3d: None })
    };

    let (suzanne_scene, suzanne_bytes) = suzanne();
    let suzanne = Model::parse(&suzanne_bytes).expect("parse Suzanne");
    let sizes = [(240u16, 240u16), (640, 480)];
    let aspect = |(w, h): (u16, u16)| w as f32 / h as f32;

    // 1, 2: Suzanne, textured Gouraud (the reference frame) and flat untextured.
    let flat = RenderOptions { shading: Shading::Flat, textures: false, ..reference::options() };
    let mut g = group(&mut c, "suzanne");
    for (name, opts) in [("gouraud-textured", reference::options()), ("flat-untextured", flat)] {
        for (w, h) in sizes {
            let job = Job {
                model: suzanne,
                transform: reference::transform(),
                camera: reference::camera(w, h),
                lights: reference::lights(),
                opts,
            };
            let mut frame = Frame::new(w, h);
            let stats = frame.render(&job, h);
            println!("suzanne {name} {w}x{h}: covered {} pixels, {stats:?}", frame.covered());
            let t = bench(&mut g, &format!("{name}/{w}x{h}"), || {
                std::hint::black_box(frame.render(&job, h));
            });
            row(&format!("Suzanne {name} {w}x{h}"), t, None);
        }
    }
    g.finish();

    // 3: teapot, Phong, its scene's lights, framed by its bounding spheres.
    let teapot_bytes = teapot();
    let teapot = Model::parse(&teapot_bytes).expect("parse teapot");
    let mut g = group(&mut c, "teapot");
    {
        let (w, h) = (640, 480);
        let job = Job {
            model: teapot,
            transform: Mat4::IDENTITY,
            camera: Camera::framing(&teapot, 0.8, aspect((w, h))).expect("teapot has bounds"),
            lights: Lights::<4>::from_model(&teapot),
            opts: RenderOptions { shading: Shading::Phong, ..RenderOptions::default() },
        };
        let mut frame = Frame::new(w, h);
        let stats = frame.render(&job, h);
        println!("teapot phong {w}x{h}: covered {} pixels, {stats:?}", frame.covered());
        let t = bench(&mut g, "phong/640x480", || {
            std::hint::black_box(frame.render(&job, h));
        });
        row("Teapot Phong 640x480", t, None);
    }
    g.finish();

    // 4: fill rate: 3 full-screen textured quads back to front.
    let texture = suzanne_scene.textures.first().cloned().expect("Suzanne has a texture");
    let quads_bytes = fill_quads(aspect((640, 480)), texture.clone());
    let quads = Model::parse(&quads_bytes).expect("parse quads");
    let mut g = group(&mut c, "fill");
    for (name, textures) in [("textured", true), ("untextured", false)] {
        let (w, h) = (640, 480);
        let job = Job {
            model: quads,
            transform: Mat4::IDENTITY,
            camera: reference::camera(w, h),
            lights: reference::lights(),
            opts: RenderOptions { textures, ..reference::options() },
        };
        let mut frame = Frame::new(w, h);
        let stats = frame.render(&job, h);
        println!(
            "fill {name} {w}x{h}: covered {}, {} pixels written/frame, {stats:?}",
            frame.covered(),
            stats.pixels_written
        );
        let t = bench(&mut g, &format!("{name}/640x480"), || {
            std::hint::black_box(frame.render(&job, h));
        });
        if let Some(ms) = t {
            println!("fill {name}: {:.1} Mpixel/s", stats.pixels_written as f64 / ms / 1e3);
        }
        row(&format!("Fill 6 tris x3 overdraw {name} 640x480"), t, None);
    }
    g.finish();

    // 5: triangle rate: spheres of ~1k, ~10k, ~100k triangles.
    let mut g = group(&mut c, "sphere");
    for (slices, stacks) in [(32u32, 16u32), (100, 50), (316, 158)] {
        let bytes = sphere(slices, stacks);
        let model = Model::parse(&bytes).expect("parse sphere");
        let (w, h) = (640, 480);
        let job = Job {
            model,
            transform: Mat4::IDENTITY,
            camera: reference::camera(w, h),
            lights: reference::lights(),
            opts: RenderOptions { textures: false, ..reference::options() },
        };
        let tris = model.meshes().map(|m| m.triangle_count()).sum::<u32>();
        let mut frame = Frame::new(w, h);
        let stats = frame.render(&job, h);
        println!("sphere {tris} triangles {w}x{h}: covered {}, {stats:?}", frame.covered());
        let t = bench(&mut g, &format!("{tris}-tris/640x480"), || {
            std::hint::black_box(frame.render(&job, h));
        });
        row(&format!("Sphere {tris} tris Gouraud 640x480"), t, None);
    }
    g.finish();

    // 6: the reference frame in 8 bands of 30 rows versus 1 band.
    let job = Job {
        model: suzanne,
        transform: reference::transform(),
        camera: reference::camera(reference::WIDTH, reference::HEIGHT),
        lights: reference::lights(),
        opts: reference::options(),
    };
    let mut g = group(&mut c, "bands");
    let mut frame = Frame::new(reference::WIDTH, reference::HEIGHT);
    let mut band_times = Vec::new();
    for rows in [reference::HEIGHT, 30] {
        let n = reference::HEIGHT.div_ceil(rows);
        let stats = frame.render(&job, rows);
        println!("bands {n}x{rows} rows: covered {}, {stats:?}", frame.covered());
        let t = bench(&mut g, &format!("{n}x240x{rows}"), || {
            std::hint::black_box(frame.render(&job, rows));
        });
        row(&format!("Suzanne reference 240x240, {n} band(s) of 240x{rows}"), t, None);
        band_times.push(t);
    }
    // The same 8 bands with no scratch: no cache at all.
    let stats = frame.render_uncached(&job, 30);
    println!("bands 8x30 rows, no cache: covered {}, {stats:?}", frame.covered());
    let t = bench(&mut g, "8x240x30-uncached", || {
        std::hint::black_box(frame.render_uncached(&job, 30));
    });
    row("Suzanne reference 240x240, 8 band(s) of 240x30, no Scratch", t, None);
    band_times.push(t);
    g.finish();

    // 7: euc 0.5 on the same Suzanne: same triangles, matrices, texture and lights.
    let mesh = suzanne_scene.meshes.first().expect("Suzanne has a mesh");
    assert_eq!(suzanne_scene.meshes.len(), 1, "one mesh");
    let uvs = mesh.uvs.as_deref().expect("Suzanne has UVs");
    let texels = texels_from_bottom(&texture);
    let lights = reference::lights();
    let world = reference::transform() * Mat4::from_cols_array(&mesh.world);
    let mut g = group(&mut c, "euc-vs-soft3d");
    let mut coverage = Vec::new();
    for (w, h) in sizes {
        let camera = reference::camera(w, h);
        let job = Job {
            model: suzanne,
            transform: reference::transform(),
            camera,
            lights: lights.clone(),
            opts: reference::options(),
        };
        let mut frame = Frame::new(w, h);
        frame.render(&job, h);
        let mut euc = EucFrame {
            color: Buffer2d::new([w as usize, h as usize], Rgb565::BLACK),
            depth: Buffer2d::new([w as usize, h as usize], 1.0),
            pipeline: EucSuzanne {
                mvp: camera.view_projection() * world,
                world,
                normal_matrix: normal_matrix(&world),
                positions: &mesh.positions,
                normals: &mesh.normals,
                uvs,
                lights: &lights,
                texels: &texels,
                tex_size: (texture.width as usize, texture.height as usize),
            },
            indices: &mesh.indices,
        };
        euc.render();
        let (s, e) = (frame.covered(), euc.covered());
        let both = frame.depth.iter().zip(euc.depth.as_ref()).filter(|(&a, &b)| a != u16::MAX && b != 1.0).count();
        let close = frame
            .color
            .iter()
            .zip(euc.color.as_ref())
            .filter(|(a, b)| {
                let (a, b) = (a.to_rgb888(), b.to_rgb888());
                (0..3).all(|k| a[k].abs_diff(b[k]) <= 16)
            })
            .count();
        println!(
            "coverage {w}x{h}: soft3d {s} pixels, euc {e} pixels, both {both}; \
             {close} of {} pixels agree within 16/255 per channel",
            w as usize * h as usize
        );
        if (w, h) == (reference::WIDTH, reference::HEIGHT) {
            save_png("bench-soft3d.png", w, &frame.color);
            save_png("bench-euc.png", w, euc.color.as_ref());
        }
        coverage.push((w, h, s, e));
        let ts = bench(&mut g, &format!("soft3d/{w}x{h}"), || {
            std::hint::black_box(frame.render(&job, h));
        });
        let te = bench(&mut g, &format!("euc/{w}x{h}"), || {
            euc.render();
            std::hint::black_box(euc.color.as_ref());
        });
        row(&format!("Suzanne textured Gouraud {w}x{h} vs euc"), ts, te);
    }
    g.finish();

    // 8: embedded-3dgfx 0.7 on the same Suzanne: same triangles, camera, yaw and texture.
    let e3d_data = E3dSuzanne::new(mesh);
    let e3d_texels: &'static [Rgb565] = Box::leak(texels.iter().map(|&t| Rgb565::from_rgb888(t)).collect());
    let e3d_texture = Texture::new(e3d_texels, texture.width.into(), texture.height.into());
    let mut g = group(&mut c, "embedded-3dgfx-vs-soft3d");
    let mut e3d_coverage = Vec::new();
    for (w, h) in sizes {
        let job = Job {
            model: suzanne,
            transform: reference::transform(),
            camera: reference::camera(w, h),
            lights: lights.clone(),
            opts: reference::options(),
        };
        let mut frame = Frame::new(w, h);
        frame.render(&job, h);
        let mut e3d = E3dFrame::new((w, h), mesh, &e3d_data, world, uvs, e3d_texture);
        e3d.render();
        let (s, e) = (frame.covered(), e3d.covered());
        let both = frame.depth.iter().zip(&e3d.depth).filter(|(&a, &b)| a != u16::MAX && b != Z_MAX_VALUE).count();
        let close = frame
            .color
            .iter()
            .zip(&e3d.target.pixels)
            .filter(|(a, b)| {
                let (a, b) = (a.to_rgb888(), b.to_rgb888());
                (0..3).all(|k| a[k].abs_diff(b[k]) <= 16)
            })
            .count();
        println!(
            "coverage {w}x{h}: soft3d {s} pixels, embedded-3dgfx {e} pixels, both {both}; \
             {close} of {} pixels agree within 16/255 per channel",
            w as usize * h as usize
        );
        if (w, h) == (reference::WIDTH, reference::HEIGHT) {
            save_png("bench-embedded-3dgfx.png", w, &e3d.target.pixels);
        }
        e3d_coverage.push((w, h, e));
        let t = bench(&mut g, &format!("embedded-3dgfx/{w}x{h}"), || {
            e3d.render();
            std::hint::black_box(&e3d.target.pixels);
        });
        // Its column goes on the euc row of the same size, which holds soft3d's time.
        let scene = format!("Suzanne textured Gouraud {w}x{h} vs euc");
        if let Some(r) = rows.iter_mut().find(|r| r.scene == scene) {
            r.e3d = t;
        }
    }
    g.finish();

    c.final_summary();

    let ms = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{t:.3}"));
    println!();
    let ratio = |peer: Option<f64>, soft3d: Option<f64>| match (peer, soft3d) {
        (Some(p), Some(s)) => format!("{:.2}", p / s),
        _ => "-".into(),
    };
    println!(
        "| scene | soft3d median (ms/frame) | euc median (ms/frame) | euc / soft3d \
         | embedded-3dgfx median (ms/frame) | embedded-3dgfx / soft3d |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for r in &rows {
        println!(
            "| {} | {} | {} | {} | {} | {} |",
            r.scene,
            ms(r.soft3d),
            ms(r.euc),
            ratio(r.euc, r.soft3d),
            ms(r.e3d),
            ratio(r.e3d, r.soft3d)
        );
    }
    if let [Some(one), eight, uncached] = band_times[..] {
        println!();
        for (what, t) in [("8 bands of 240x30", eight), ("8 bands of 240x30 without Scratch", uncached)] {
            if let Some(t) = t {
                println!("{what} vs 1 band of 240x240: {t:.3} / {one:.3} ms = {:.2}x", t / one);
            }
        }
    }
    for (w, h, s, e) in coverage {
        println!("coverage {w}x{h}: soft3d {s}, euc {e} pixels");
    }
    for (w, h, e) in e3d_coverage {
        println!("coverage {w}x{h}: embedded-3dgfx {e} pixels");
    }
}
