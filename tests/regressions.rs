//! Inputs that once made soft3d panic, each kept as a test (see `../shared/fuzz-crashes/` and the
//! issue tracker). A file input is first asserted to parse, so that a test cannot pass by the
//! parser refusing it; when the format changes, the file is ported, not dropped.
//!
//! Integration tests build with overflow checks on (the test profile inherits `dev`'s debug
//! assertions), as a firmware's development build does: a wrapped add is a panic here.

mod common;

use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
use soft3d::convert::{emit, EmitOptions};
use soft3d::testing::{ScreenVertex, Setup, Window, MAX_VARYINGS};
use soft3d::{Band, Camera, Lights, Mat4, Mode, Model, RenderOptions, Renderer, Scratch, Shading, Vec3};

/// Draws `model` into a `width` x `height` frame in bands of `rows` with every shading.
fn draw_every_shading(model: &Model<'_>, camera: &Camera, (width, height, rows): (u16, u16, u16)) {
    let lights = Lights::<4>::from_model(model);
    let n = width as usize * rows as usize;
    let (mut color, mut depth) = (vec![Rgb565::BLACK; n], vec![0u16; n]);
    for shading in [Shading::Unlit, Shading::Flat, Shading::Gouraud, Shading::Phong] {
        let renderer = Renderer::new(camera, &lights, RenderOptions { shading, ..RenderOptions::default() });
        for first_row in (0..height).step_by(rows as usize) {
            let take = (rows.min(height - first_row)) as usize * width as usize;
            let mut band = Band::new(&mut color[..take], &mut depth[..take], width, height, first_row).unwrap();
            band.clear(Rgb565::BLACK);
            renderer.draw(&mut band, model, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
        }
    }
}

/// `fuzz/fuzz_targets/parse.rs` at 25acddd: `attempt to add with overflow` in the affine planes'
/// set-up (`(gx + 128) >> 8`), because a box one pixel wide bounded nothing of `gx`.
#[test]
fn parse_raster_overflow_draws_without_panicking() {
    let bytes = include_bytes!("data/parse-raster-overflow.s3d");
    let model = Model::parse(bytes).expect("the crash input still parses");
    let camera = Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap();
    // The fuzz target's own draw: rows 8..16 of a 32x32 frame, default options.
    let lights = Lights::<2>::from_model(&model);
    let (mut color, mut depth) = ([Rgb565::BLACK; 32 * 8], [0u16; 32 * 8]);
    let mut band = Band::new(&mut color[..], &mut depth[..], 32, 32, 8).unwrap();
    let renderer = Renderer::new(&camera, &lights, RenderOptions::default());
    renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
    for size in [(1, 1, 1), (32, 32, 8), (7, 5, 2)] {
        draw_every_shading(&model, &camera, size);
    }
}

/// The same overflow from unedited scenes (reported with `double-sided`): a whole model in a
/// 1x1 frame, Phong, through an orthographic camera framing its bounds (eye 3 radii from the
/// centre, view 2.2 radii wide and high, near 0.1, far 6 radii), along z, its opposite and
/// 300 pseudo-random directions, for every asset. Every triangle is sub-pixel there: needles with huge gradients
/// in a box one pixel wide.
#[test]
fn whole_models_in_one_pixel_draw_without_panicking() {
    for name in common::ASSETS {
        let bytes = emit(&common::scene(name), &EmitOptions::default()).unwrap();
        let model = Model::parse(&bytes).unwrap();
        let (centre, r) = model.bounds().unwrap();
        let lights = Lights::<8>::from_model(&model);
        let options = RenderOptions { shading: Shading::Phong, ..RenderOptions::default() };
        let mut state = 1u64;
        let mut random = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            let yaw = (state >> 33) as f32 / 2f32.powi(31) * core::f32::consts::TAU;
            let lift = ((state >> 13) & 0xffff) as f32 / 65536.0 * 2.0 - 1.0;
            Vec3::new(yaw.cos(), lift, yaw.sin()).normalize()
        };
        // The reported direction (eye 3 radii from the centre along -z), its opposite, and more.
        let directions: Vec<Vec3> = [Vec3::Z, -Vec3::Z].into_iter().chain((0..300).map(|_| random())).collect();
        for dir in directions {
            let Ok(camera) = Camera::orthographic(centre - dir * 3.0 * r, centre, 2.2 * r, 2.2 * r, 0.1, 6.0 * r)
            else {
                continue;
            };
            let (mut color, mut depth) = ([Rgb565::BLACK; 1], [0u16; 1]);
            let mut band = Band::new(&mut color[..], &mut depth[..], 1, 1, 0).unwrap();
            let renderer = Renderer::new(&camera, &lights, options);
            renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
        }
    }
}

/// `Setup::new` with windows no band makes: nothing to draw, no overflow.
#[test]
fn extreme_windows_are_empty_not_a_panic() {
    let v = |x: i32, y: i32| ScreenVertex { x, y, z: 0.5, inv_w: 1.0, varyings: [0; MAX_VARYINGS] };
    let tri = [v(0, 0), v(160, 0), v(0, 160)];
    for win in [
        Window { width: i32::MIN, row_start: 0, row_end: 10 },
        Window { width: 10, row_start: 0, row_end: i32::MIN },
        Window { width: i32::MIN, row_start: i32::MIN, row_end: i32::MIN },
        Window { width: 0, row_start: 0, row_end: 10 },
        Window { width: -5, row_start: 5, row_end: 2 },
    ] {
        assert!(Setup::<3>::new(&tri, &win, false, false).is_err(), "{win:?}");
    }
    assert!(Setup::<3>::new(&tri, &Window { width: 10, row_start: 0, row_end: 10 }, false, false).is_ok());
}

/// A wireframe of a model scaled by 65,536 (and by 1e19, and through a projective transform)
/// took minutes a frame: clipped vertices saturate and every edge was walked over about 2^28
/// pixels in every band. Lines are now walked only inside the band: at most its width plus its
/// rows a line (a clipped polygon has at most 9 edges a triangle). `line.rs`'s tests walk a line
/// between saturated ends; this draws whole scenes.
#[test]
fn huge_wireframes_walk_only_the_band() {
    let (w, h, rows) = (64u16, 48u16, 16u16);
    let (mut color, mut depth) = (vec![Rgb565::BLACK; 64 * 16], vec![0u16; 64 * 16]);
    let mut projective = Mat4::from_scale(Vec3::splat(3.0));
    projective.x_axis.w = 0.7;
    projective.z_axis.w = -0.4;
    let mut walked = 0;
    for name in ["double-sided/DoubleSidedMaterial.babylon", "tree/tree.babylon", "suzanne/monkey.babylon"] {
        let bytes = emit(&common::scene(name), &EmitOptions::default()).unwrap();
        let model = Model::parse(&bytes).unwrap();
        let (centre, r) = model.bounds().unwrap();
        let camera = Camera::perspective(centre - Vec3::Z * 3.0 * r, centre, 0.8, 1.0, 0.1, 100.0 * r).unwrap();
        let lights = Lights::<2>::from_model(&model);
        let about_centre = |m: Mat4| Mat4::from_translation(centre) * m * Mat4::from_translation(-centre);
        for transform in [Mat4::from_scale(Vec3::splat(65_536.0)), Mat4::from_scale(Vec3::splat(1e19)), projective] {
            for mode in [Mode::Wireframe, Mode::SolidWireframe, Mode::Points] {
                let renderer = Renderer::new(&camera, &lights, RenderOptions { mode, ..RenderOptions::default() });
                for first_row in (0..h).step_by(rows as usize) {
                    let mut band = Band::new(&mut color[..], &mut depth[..], w, h, first_row).unwrap();
                    let stats =
                        renderer.draw(&mut band, &model, about_centre(transform), &mut Scratch::none()).unwrap();
                    let bound = (w as u32 + rows as u32) * 9 * stats.triangles_submitted;
                    assert!(stats.line_steps <= bound, "{name} {mode:?}: {} steps, bound {bound}", stats.line_steps);
                    walked += stats.line_steps;
                }
            }
        }
    }
    assert!(walked > 0, "some lines are drawn");
}

/// Counts summed over many draws (65,535 instances of a large mesh count more than 2^32
/// triangles) saturate instead of overflowing (debug: a panic) or wrapping to a small count.
#[test]
fn stats_saturate() {
    let mut total = soft3d::Stats { triangles_submitted: u32::MAX - 1, pixels_written: 7, ..Default::default() };
    let draw = soft3d::Stats { triangles_submitted: 65_537, pixels_written: 5, ..Default::default() };
    total += draw;
    assert_eq!((total.triangles_submitted, total.pixels_written), (u32::MAX, 12));
    total += draw;
    assert_eq!(total.triangles_submitted, u32::MAX);
}
