//! Issue "Scenes that move": a posed frame (`Renderer::draw_posed`) drawn in bands of any
//! height is bit for bit the frame drawn whole, as `tests/bands.rs` checks for still scenes:
//! the skinned rabbit, the morph cube and the head (morph targets) at frames where they have
//! moved, with the scratch's row and vertex caches (which hold deformed vertices) as bands use
//! them. The rabbit and the cube are in `../shared/assets/` (skipped, with a note, when absent);
//! the head is in `assets/`. With `SOFT3D_REQUIRE_GOLDEN` set (CI), an absent file fails.
#![cfg(feature = "convert")]

use std::path::PathBuf;

use embedded_graphics_core::pixelcolor::Rgb888;
use soft3d::animation::{pose_memory, Pose};
use soft3d::convert::{emit, read_babylon_file, ConvertOptions, EmitOptions};
use soft3d::{Band, Camera, Filter, Lights, Mat4, Model, RenderOptions, Renderer, Scratch, Shading, Vec3};
use soft3d::{TransformedVertex, TriangleRows};

const W: u16 = 320;
const H: u16 = 240;

/// A posed scene: its file, the frame, and the camera of `../shared/animation/README.md`
/// (eye, target, vertical field of view, near, far).
struct Case {
    file: PathBuf,
    frame: f32,
    camera: ([f32; 3], [f32; 3], f32, f32, f32),
}

fn cases() -> Vec<Case> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/assets");
    vec![
        Case {
            file: shared.join("rabbit/Rabbit.babylon"),
            frame: 50.0,
            camera: ([40.0, 55.0, -75.0], [0.0, 30.0, 5.0], 0.8, 1.0, 1000.0),
        },
        Case {
            file: shared.join("morph-cube/AnimatedMorphCube.babylon"),
            frame: 30.0,
            camera: ([75.0, 220.0, -420.0], [75.0, 50.0, 0.0], 0.8, 1.0, 2000.0),
        },
        Case {
            file: root.join("assets/shapekey/shapekeyAnimation.babylon"),
            frame: 45.0,
            camera: ([0.15, 0.05, -0.45], [0.0; 3], 0.69, 0.1, 100.0),
        },
    ]
}

/// Whether `case`'s file is there (if not: a note, or a failure under `SOFT3D_REQUIRE_GOLDEN`).
fn present(case: &Case) -> bool {
    let there = case.file.exists();
    if !there {
        assert!(std::env::var_os("SOFT3D_REQUIRE_GOLDEN").is_none(), "{} is missing", case.file.display());
        println!("note: {} is absent: skipped", case.file.display());
    }
    there
}

fn s3d(path: &std::path::Path) -> Vec<u8> {
    let (scene, _) = read_babylon_file(path, &ConvertOptions::default()).unwrap();
    emit(&scene, &EmitOptions::default()).unwrap()
}

/// A frame's colour and u16 depth.
type Frame = (Vec<Rgb888>, Vec<u16>);

/// What draws a frame: the camera, lights and options.
struct View {
    camera: Camera,
    lights: Lights<1>,
    opts: RenderOptions,
}

impl View {
    fn new(case: &Case, opts: RenderOptions) -> Self {
        let (eye, target, fov, near, far) = case.camera;
        let camera = Camera::perspective(eye.into(), target.into(), fov, f32::from(W) / f32::from(H), near, far);
        let mut lights = Lights::<1>::new(Vec3::splat(0.1));
        lights.push(Lights::<1>::directional(Vec3::new(0.3, -0.6, 0.7), 0.9)).unwrap();
        View { camera: camera.unwrap(), lights, opts }
    }

    /// `model` at `frame` drawn in bands of `rows` rows (the last may be shorter) with `scratch`
    /// (the whole frame: none).
    fn draw(&self, model: &Model<'_>, frame: f32, rows: u16, scratch: &mut Scratch<'_>) -> Frame {
        let a = model.animation().unwrap();
        let (n, w) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
        let (mut nodes, mut weights) = (vec![Mat4::ZERO; n], vec![0.0; w]);
        let mut pose = Pose::new(&mut nodes, &mut weights);
        pose.evaluate(&a, frame, None).unwrap();
        let pixels = usize::from(W) * usize::from(H);
        let (mut color, mut depth) = (vec![Rgb888::new(0, 0, 0); pixels], vec![0u16; pixels]);
        let band_len = usize::from(rows) * usize::from(W);
        for (k, (c, z)) in color.chunks_mut(band_len).zip(depth.chunks_mut(band_len)).enumerate() {
            let mut band = Band::new(c, z, W, H, k as u16 * rows).unwrap();
            band.clear(Rgb888::new(10, 20, 30));
            let renderer = Renderer::new(&self.camera, &self.lights, self.opts);
            renderer.draw_posed(&mut band, model, &pose, Mat4::from_rotation_y(0.2), scratch).unwrap();
        }
        (color, depth)
    }
}

/// Row and vertex memory for `model`'s draws.
fn caches(model: &Model<'_>) -> (Vec<TriangleRows>, Vec<TransformedVertex>) {
    let (triangles, vertices) = model.draw_counts();
    (vec![TriangleRows::default(); triangles], vec![TransformedVertex::default(); vertices])
}

/// Bands of `rows` rows with a scratch as `tests/bands.rs` lends them: every vertex cached for
/// 1-row bands, rows only for 7, and a vertex cache one entry short (the last draw uncached)
/// for others.
fn bands(view: &View, model: &Model<'_>, frame: f32, rows: u16) -> Frame {
    let (mut seen, mut transformed) = caches(model);
    let mut scratch = match rows {
        1 => Scratch::none().with_rows(&mut seen).with_vertices(&mut transformed),
        7 => Scratch::none().with_rows(&mut seen),
        _ => Scratch::none().with_rows(&mut seen).with_vertices(&mut transformed[1..]),
    };
    view.draw(model, frame, rows, &mut scratch)
}

fn option_sets() -> [RenderOptions; 2] {
    let phong = RenderOptions { shading: Shading::Phong, filter: Filter::Bilinear, ..RenderOptions::default() };
    [RenderOptions::default(), phong]
}

#[test]
fn posed_bands_equal_the_whole_posed_frame() {
    for case in cases() {
        if !present(&case) {
            continue;
        }
        let bytes = s3d(&case.file);
        let model = Model::parse(&bytes).unwrap();
        for opts in option_sets() {
            let view = View::new(&case, opts);
            let whole = view.draw(&model, case.frame, H, &mut Scratch::none());
            // The pose must show: the frame at rest differs, and enough is drawn.
            let rest = view.draw(&model, 0.0, H, &mut Scratch::none());
            let drawn = whole.1.iter().filter(|&&d| d != u16::MAX).count();
            assert!(drawn > 1000 && rest != whole, "{}: nothing to prove ({drawn} pixels)", case.file.display());
            for rows in [1, 7, 16, 100] {
                let banded = bands(&view, &model, case.frame, rows);
                assert!(banded == whole, "{} {opts:?}: bands of {rows} rows differ", case.file.display());
            }
        }
    }
}

/// A scratch that drew one pose draws another pose of the same model, in the same frame (no
/// `new_frame`), as a fresh scratch does: its cached rows and deformed vertices are the first
/// pose's.
#[test]
fn a_scratch_reused_for_another_pose_changes_nothing() {
    for case in cases() {
        if !present(&case) {
            continue;
        }
        let bytes = s3d(&case.file);
        let model = Model::parse(&bytes).unwrap();
        let view = View::new(&case, RenderOptions::default());
        let (mut seen, mut transformed) = caches(&model);
        let mut shared = Scratch::none().with_rows(&mut seen).with_vertices(&mut transformed);
        view.draw(&model, case.frame, 16, &mut shared);
        let later = case.frame + 7.0;
        let fresh = view.draw(&model, later, H, &mut Scratch::none());
        assert!(
            fresh != view.draw(&model, case.frame, H, &mut Scratch::none()),
            "{}: the poses look alike",
            case.file.display()
        );
        assert!(view.draw(&model, later, 16, &mut shared) == fresh, "{}: frame {later}", case.file.display());
    }
}
