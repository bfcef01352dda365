//! The fixed-point vertex path (`RenderOptions::fixed_vertices`, for FPU-less targets) against
//! the f32 one: every vertex of every asset projects within 1/16 pixel of where f32 puts it,
//! and rendered frames differ only in pixels whose centres lie that close to an edge.
use embedded_graphics_core::pixelcolor::{Rgb565, Rgb888, RgbColor};
use soft3d::convert::{emit, EmitOptions};
use soft3d::testing::math::{FixedTransform, Mat4, Vec3, Vec4};
use soft3d::testing::reference;
use soft3d::Model;
use soft3d::{Band, Camera, RenderOptions};

mod common;
use common::{scene, Rng, ASSETS};

const W: u16 = 240;
const H: u16 = 240;

/// Pixel position of a clip-space point (x right, y down).
fn screen(c: Vec4) -> (f64, f64) {
    let (x, y, w) = (c.x as f64, c.y as f64, c.w as f64);
    ((x / w + 1.0) * W as f64 / 2.0, (1.0 - y / w) * H as f64 / 2.0)
}

/// The largest distance in pixels between the f32 and the fixed projection of the mesh's
/// vertices that lie in front of the eye, and how many there were.
fn worst_projection_error(model: &Model<'_>, vp: Mat4) -> (f64, usize) {
    let (mut worst, mut n) = (0.0f64, 0);
    for (mesh, world) in model.draws() {
        let mvp = vp * world * mesh.dequantize();
        let arrays = mesh.arrays();
        let sphere = mesh.bounding_sphere();
        let (offset, step) = arrays.int_position_frame(sphere);
        let fixed = FixedTransform::new(&mvp, offset, step).expect("representable transform");
        for i in 0..mesh.vertex_count() {
            let exact = mvp * arrays.position_stored(i).extend(1.0);
            if exact.w < 0.1 {
                continue;
            }
            let got = fixed.apply(arrays.position_int(i, sphere));
            let ((ax, ay), (bx, by)) = (screen(exact), screen(got));
            worst = worst.max((ax - bx).abs()).max((ay - by).abs());
            n += 1;
        }
    }
    (worst, n)
}

fn camera(model: &Model<'_>) -> Camera {
    match model.camera() {
        Some(c) => Camera::from_scene(&c, W as f32 / H as f32).unwrap(),
        None => Camera::framing(model, 0.8, W as f32 / H as f32).unwrap(),
    }
}

#[test]
fn fixed_vertices_project_within_a_sixteenth_of_a_pixel() {
    let mut rng = Rng::new(7);
    for rel in ASSETS {
        for float_positions in [false, true] {
            let bytes = emit(&scene(rel), &EmitOptions { float_positions, ..Default::default() }).unwrap();
            let model = Model::parse(&bytes).unwrap();
            let cam = camera(&model);
            // The scene's own camera, then the model turned and moved about.
            let mut worst = worst_projection_error(&model, cam.view_projection());
            for _ in 0..4 {
                let spin = Mat4::from_rotation_y(rng.unit() as f32 * 6.3) * Mat4::from_rotation_x(rng.unit() as f32);
                let shift = Mat4::from_translation(Vec3::new(rng.unit() as f32 - 0.5, rng.unit() as f32 - 0.5, 0.0));
                let (e, n) = worst_projection_error(&model, cam.view_projection() * shift * spin);
                assert!(n > 0, "{rel}: no vertex in front of the eye");
                worst.0 = worst.0.max(e);
            }
            println!("{rel} (float positions: {float_positions}): worst {:.5} px over {} vertices", worst.0, worst.1);
            assert!(worst.0 < 1.0 / 16.0, "{rel}: fixed vertices {:.4} px off", worst.0);
        }
    }
}

/// Scenes far from the origin in large units, and tiny ones: the per-row scales keep them exact.
#[test]
fn fixed_transform_keeps_precision_at_any_scale() {
    for (scale, offset) in [(1e-3f32, 0.0f32), (1.0, 1e4), (1e3, -3e5), (1e-2, 50.0)] {
        let m = Mat4::perspective_lh_like(scale, offset);
        let step = scale / 32767.0;
        let fixed = FixedTransform::new(&m, Vec3::splat(offset), step).unwrap();
        let mut rng = Rng::new(11);
        let (mut worst_f32, mut worst_fixed) = (0.0f64, 0.0f64);
        for _ in 0..1000 {
            let q = [0; 3].map(|_| rng.range(-32768, 32768) as i32);
            let p = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) * step + Vec3::splat(offset);
            let (a, b) = (m * p.extend(1.0), fixed.apply(q));
            // Exact, in f64, relative to the size of the terms summed.
            for k in 0..4 {
                let row = m.row(k).to_array().map(f64::from);
                let pk = q.map(|c| c as f64 * step as f64 + offset as f64);
                let exact = row[3] + (0..3).map(|j| row[j] * pk[j]).sum::<f64>();
                let size = row[3].abs() + (0..3).map(|j| (row[j] * pk[j]).abs()).sum::<f64>();
                worst_f32 = worst_f32.max((a[k] as f64 - exact).abs() / size);
                worst_fixed = worst_fixed.max((b[k] as f64 - exact).abs() / size);
            }
        }
        println!("scale {scale}, offset {offset}: worst relative error f32 {worst_f32:e}, fixed {worst_fixed:e}");
        assert!(worst_fixed < 1e-6, "scale {scale}, offset {offset}: fixed {worst_fixed:e}");
    }
}

/// A transform with the magnitudes of a camera looking at a scene of size `scale` placed at
/// `offset` on every axis.
trait LikeACamera {
    fn perspective_lh_like(scale: f32, offset: f32) -> Mat4;
}

impl LikeACamera for Mat4 {
    fn perspective_lh_like(scale: f32, offset: f32) -> Mat4 {
        let to_origin = Mat4::from_translation(Vec3::new(-offset, -offset, -offset + 4.0 * scale));
        let project = Mat4::from_cols_array(&[
            1.5 / scale,
            0.0,
            0.0,
            0.0,
            0.0,
            1.5 / scale,
            0.0,
            0.0,
            0.0,
            0.3,
            1.0,
            1.0,
            0.0,
            0.0,
            -0.1,
            0.0,
        ]);
        project * to_origin * Mat4::from_rotation_y(0.4)
    }
}

/// The reference frame drawn with fixed vertices: the same coverage up to pixels on edges.
/// Untextured, the same colours within one step wherever both draw the same triangle (light
/// comes from the same vertices; only the sampling positions move, by under 1/16 pixel).
/// Textured, nearest sampling may pick the neighbouring texel where a pixel centre is that
/// close to a texel edge: a small share of pixels.
#[test]
fn reference_frame_with_fixed_vertices_matches_the_f32_frame() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/suzanne/monkey.babylon");
    let opts = soft3d::convert::ConvertOptions { uv_origin: soft3d::convert::UvOrigin::Top, ..Default::default() };
    let (scene, _) = soft3d::convert::read_babylon_file(path.as_ref(), &opts).unwrap();
    let bytes = emit(&scene, &EmitOptions { float_positions: true, ..Default::default() }).unwrap();
    let model = Model::parse(&bytes).unwrap();
    let render = |fixed_vertices: bool, textures: bool| {
        let mut color = vec![Rgb888::BLACK; W as usize * H as usize];
        let mut depth = vec![0u16; W as usize * H as usize];
        let mut band = Band::new(&mut color[..], &mut depth[..], W, H, 0).unwrap();
        band.clear(Rgb888::BLACK);
        let opts = RenderOptions { fixed_vertices, textures, ..reference::options() };
        let cam = reference::camera(W, H);
        soft3d::Renderer::new(&cam, &reference::lights(), opts)
            .draw(&mut band, &model, reference::transform(), &mut soft3d::Scratch::none())
            .unwrap();
        (color, depth)
    };
    for textures in [false, true] {
        let ((c0, d0), (c1, d1)) = (render(false, textures), render(true, textures));
        let covered = d0.iter().filter(|&&d| d != u16::MAX).count();
        let coverage_differs = d0.iter().zip(&d1).filter(|(a, b)| (**a == u16::MAX) != (**b == u16::MAX)).count();
        // Pixels of the same surface (depth within 2^-10) whose colours differ by over one step.
        let off = c0
            .iter()
            .zip(&c1)
            .zip(d0.iter().zip(&d1))
            .filter(|((a, b), (za, zb))| {
                let steps = [a.r().abs_diff(b.r()), a.g().abs_diff(b.g()), a.b().abs_diff(b.b())];
                za.abs_diff(**zb) < 64 && steps.iter().any(|&s| s > 1)
            })
            .count();
        println!("textures {textures}: covered {covered}; coverage differs at {coverage_differs}, colour (> 1 step) at {off}");
        assert_eq!(covered, reference::COVERED_PIXELS as usize);
        assert!(coverage_differs * 200 <= covered, "coverage differs at {coverage_differs} of {covered} pixels");
        if textures {
            assert!(off * 50 <= covered, "{off} of {covered} textured pixels differ by more than one step");
        } else {
            // Only where the pixel went to the neighbouring triangle across an edge whose
            // vertices are split (same depth there, different vertex normals and light): 5
            // pixels when this was written.
            assert!(off * 1000 <= covered, "{off} untextured pixels differ by more than one step");
        }
    }
}

/// The reference model one byte further on draws the same frame, bit for bit, with f32 and
/// with fixed vertices: a model parses and draws at any address (`include_bytes!`
/// gives alignment 1), and the span loop's RGB565 path (`Repeat565`, whose modulation is
/// within a step of the sampler's, not equal) must not depend on it.
#[test]
fn a_model_one_byte_further_on_draws_the_same_frame() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/suzanne/monkey.babylon");
    // As the firmware converts it: a 128x128 texture (within `Repeat565`'s 2^16 texels).
    let opts = soft3d::convert::ConvertOptions {
        uv_origin: soft3d::convert::UvOrigin::Top,
        max_texture: Some(128),
        ..Default::default()
    };
    let (scene, _) = soft3d::convert::read_babylon_file(path.as_ref(), &opts).unwrap();
    let bytes = emit(&scene, &EmitOptions::default()).unwrap();
    let mut shifted = vec![0u8; bytes.len() + 1];
    shifted[1..].copy_from_slice(&bytes);
    let (model, moved) = (Model::parse(&bytes).unwrap(), Model::parse(&shifted[1..]).unwrap());
    // The texels at an even address in one and at an odd one in the other.
    let address = |m: &Model<'_>| m.texture(0).unwrap().texels.as_ptr() as usize;
    assert_ne!(address(&model) % 2, address(&moved) % 2);
    let render = |model: &Model<'_>, fixed_vertices: bool| {
        let mut color = vec![Rgb565::BLACK; W as usize * H as usize];
        let mut depth = vec![0u16; W as usize * H as usize];
        let mut band = Band::new(&mut color[..], &mut depth[..], W, H, 0).unwrap();
        band.clear(Rgb565::BLACK);
        let opts = RenderOptions { fixed_vertices, ..reference::options() };
        soft3d::Renderer::new(&reference::camera(W, H), &reference::lights(), opts)
            .draw(&mut band, model, reference::transform(), &mut soft3d::Scratch::none())
            .unwrap();
        color
    };
    for fixed_vertices in [false, true] {
        let frame = render(&model, fixed_vertices);
        assert!(frame.iter().filter(|&&c| c != Rgb565::BLACK).count() > 10_000);
        assert!(frame == render(&moved, fixed_vertices), "fixed vertices {fixed_vertices}");
    }
}
