//! The reference Suzanne frame on the host: its coverage, and bit-identity with the frames the
//! QEMU firmware wrote (Cortex-M4F and thumbv6m builds of the same code).
use embedded_graphics_core::pixelcolor::raw::{RawData, RawU16};
use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
use soft3d::convert::{emit, EmitOptions};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::reference;
use soft3d::{Band, Model, Stats};

/// The firmware's conversion: UV origin at the top, 128-texel texture, exact (f32) positions
/// or (`float_positions` false, for the fixed-point vertex path) 16-bit ones.
fn firmware_model_bytes(max_texture: Option<u32>, float_positions: bool) -> Vec<u8> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/suzanne/monkey.babylon");
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture, ..Default::default() };
    let (scene, _) = read_babylon_file(path.as_ref(), &opts).unwrap();
    emit(&scene, &EmitOptions { float_positions, ..Default::default() }).unwrap()
}

/// Renders the reference frame in bands of `rows`: RGB565 pixels, depth, stats.
fn render(model: &Model<'_>, rows: u16) -> (Vec<Rgb565>, Vec<u16>, Stats) {
    render_with(model, rows, &reference::options())
}

fn render_with(model: &Model<'_>, rows: u16, opts: &soft3d::RenderOptions) -> (Vec<Rgb565>, Vec<u16>, Stats) {
    let (w, h) = (reference::WIDTH as usize, reference::HEIGHT as usize);
    let mut color = vec![Rgb565::BLACK; w * h];
    let mut depth = vec![0u16; w * h];
    let mut stats = Stats::default();
    let camera = reference::camera(reference::WIDTH, reference::HEIGHT);
    let lights = reference::lights();
    for (k, (c, z)) in color.chunks_mut(rows as usize * w).zip(depth.chunks_mut(rows as usize * w)).enumerate() {
        let mut band = Band::new(c, z, reference::WIDTH, reference::HEIGHT, k as u16 * rows).unwrap();
        band.clear(Rgb565::BLACK);
        stats += soft3d::Renderer::new(&camera, &lights, *opts)
            .draw(&mut band, model, reference::transform(), &mut soft3d::Scratch::none())
            .unwrap();
    }
    (color, depth, stats)
}

#[test]
fn reference_frame_covers_the_reference_pixel_count() {
    let bytes = firmware_model_bytes(None, true);
    let model = Model::parse(&bytes).unwrap();
    let (_, depth, stats) = render(&model, reference::HEIGHT);
    let covered = depth.iter().filter(|&&d| d != u16::MAX).count();
    println!("{stats:?}, covered {covered}");
    assert_eq!(covered, reference::COVERED_PIXELS as usize);
}

/// FNV-1a (64 bits) of the frames the firmware writes: the M4F frame recorded when small
/// triangles (`raster::small`, exact varyings at every pixel) grew from boxes of up to 24 pixel
/// centres to 32 (6 pixels differ from the frame before, by at most 2 RGB565 steps: those
/// triangles' pixels had affine varyings within 1/16 texel, now exact ones), the thumbv6m one
/// when its integer perspective (`raster/perspective.rs`, within 1/64 texel of the exact value)
/// began to weigh triangles with narrow ranges from 16-bit operands (2 pixels differ from the
/// frame before, by 1 RGB565 step). The QEMU frames must equal the host's rendering, and that
/// rendering must not change unnoticed.
const RECORDED_FRAMES: [(&str, u64); 2] =
    [("qemu-frame-m4.rgb565", 0x4388_b267_020d_737c), ("qemu-frame-m0.rgb565", 0x0dd6_37c8_3039_8d30)];

/// FNV-1a (64 bits) of `bytes`.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// The host's rendering of each firmware frame (and so, when QEMU ran, the firmware's) is the
/// recorded one.
#[test]
fn qemu_frames_equal_the_host_frame() {
    let required = std::env::var_os("SOFT3D_REQUIRE_QEMU").is_some();
    let mut compared = 0;
    // The M4F firmware draws f32 positions with f32 vertices; the thumbv6m one 16-bit positions
    // with the fixed-point vertex path (its build.rs and main.rs).
    for (name, fpu) in [("qemu-frame-m4.rgb565", true), ("qemu-frame-m0.rgb565", false)] {
        let bytes = firmware_model_bytes(Some(128), fpu);
        let model = Model::parse(&bytes).unwrap();
        let opts = soft3d::RenderOptions { fixed_vertices: !fpu, ..reference::options() };
        let (host, _, _) = render_with(&model, 30, &opts);
        let host_bytes: Vec<u8> = host.iter().flat_map(|c| RawU16::from(*c).into_inner().to_le_bytes()).collect();
        let recorded = RECORDED_FRAMES.iter().find(|(n, _)| *n == name).map(|(_, h)| *h);
        assert_eq!(Some(fnv1a(&host_bytes)), recorded, "{name}: the frame changed (hash {:016x})", fnv1a(&host_bytes));
        compared += usize::from(equals_qemu_frame(name, &host_bytes, required));
    }
    println!("{compared} QEMU frame(s) bit-identical to the host's");
}

/// The rabbit firmware's scene (examples/qemu, feature `rabbit`): `../shared/assets/rabbit`.
fn rabbit_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/rabbit/Rabbit.babylon")
}

/// The rabbit firmware's conversion (its build.rs): Babylon's UV origin, 128-texel texture,
/// exact (f32) positions or (`float_positions` false, FPU-less targets) 16-bit ones.
fn rabbit_model_bytes(float_positions: bool) -> Vec<u8> {
    let opts = ConvertOptions { max_texture: Some(128), ..Default::default() };
    let (scene, _) = read_babylon_file(&rabbit_path(), &opts).unwrap();
    emit(&scene, &EmitOptions { float_positions, ..Default::default() }).unwrap()
}

/// The rabbit firmware's frame: posed at frame 50 of every group, seen from (40, 55, -75)
/// looking at (0, 30, 5) (vertical fov 0.8, near 1, far 1000, 240x240), lit by a white
/// directional light along (0.3, -0.6, 0.7) and no ambient, drawn in 8 bands of 30 rows with
/// `opts`.
fn render_rabbit(model: &Model<'_>, opts: &soft3d::RenderOptions) -> (Vec<Rgb565>, usize) {
    use soft3d::animation::{pose_memory, Pose};
    use soft3d::{Camera, Lights, Mat4, Vec3};
    let (w, h) = (reference::WIDTH, reference::HEIGHT);
    let camera = Camera::perspective(
        Vec3::new(40.0, 55.0, -75.0),
        Vec3::new(0.0, 30.0, 5.0),
        0.8,
        f32::from(w) / f32::from(h),
        1.0,
        1000.0,
    )
    .unwrap();
    let mut lights = Lights::<1>::new(Vec3::ZERO);
    lights.push(Lights::<1>::directional(Vec3::new(0.3, -0.6, 0.7), 1.0)).unwrap();
    let a = model.animation().expect("the rabbit is animated");
    let (m, wt) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
    let (mut matrices, mut weights) = (vec![Mat4::IDENTITY; m], vec![0.0f32; wt]);
    let mut pose = Pose::new(&mut matrices, &mut weights);
    pose.evaluate(&a, 50.0, None).unwrap();
    let renderer = soft3d::Renderer::new(&camera, &lights, *opts);
    let rows = 30usize;
    let mut color = vec![Rgb565::BLACK; usize::from(w) * usize::from(h)];
    let mut depth = vec![0u16; color.len()];
    let band_len = rows * usize::from(w);
    for (k, (c, z)) in color.chunks_mut(band_len).zip(depth.chunks_mut(band_len)).enumerate() {
        let mut band = Band::new(c, z, w, h, (k * rows) as u16).unwrap();
        band.clear(Rgb565::BLACK);
        renderer.draw_posed(&mut band, model, &pose, Mat4::IDENTITY, &mut soft3d::Scratch::none()).unwrap();
    }
    let covered = depth.iter().filter(|&&d| d != u16::MAX).count();
    (color, covered)
}

/// The posed rabbit frames the QEMU firmwares wrote (feature `rabbit`, scripts/qemu-check.sh)
/// are bit-identical to the host's rendering of the same model bytes with the same options.
#[test]
fn qemu_rabbit_frames_equal_the_host_frame() {
    let required = std::env::var_os("SOFT3D_REQUIRE_QEMU").is_some();
    if !rabbit_path().exists() {
        assert!(!required, "{} missing", rabbit_path().display());
        println!("skipped: {} is absent", rabbit_path().display());
        return;
    }
    let mut compared = 0;
    for (name, fpu) in [("qemu-frame-rabbit-m4.rgb565", true), ("qemu-frame-rabbit-m0.rgb565", false)] {
        let bytes = rabbit_model_bytes(fpu);
        let model = Model::parse(&bytes).unwrap();
        let opts = soft3d::RenderOptions { fixed_vertices: !fpu, ..reference::options() };
        let (host, covered) = render_rabbit(&model, &opts);
        let host_bytes: Vec<u8> = host.iter().flat_map(|c| RawU16::from(*c).into_inner().to_le_bytes()).collect();
        println!("{name}: host covers {covered} pixels, hash {:016x}", fnv1a(&host_bytes));
        assert!(covered > 0, "{name}: the host frame is empty");
        compared += usize::from(equals_qemu_frame(name, &host_bytes, required));
    }
    println!("{compared} QEMU rabbit frame(s) bit-identical to the host's");
}

/// Whether the frame QEMU wrote to `out/NAME` equals `host_bytes` (little-endian RGB565) bit for bit:
/// it fails naming the first differing pixel; a missing frame is skipped (false), or a failure
/// when `required`.
fn equals_qemu_frame(name: &str, host_bytes: &[u8], required: bool) -> bool {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("out").join(name);
    let Ok(qemu) = std::fs::read(&path) else {
        assert!(!required, "{} missing: run scripts/qemu-check.sh first", path.display());
        println!("skipped {name}: run scripts/qemu-check.sh to produce it");
        return false;
    };
    assert_eq!(qemu.len(), host_bytes.len(), "{name}: wrong size");
    let differing: Vec<usize> =
        qemu.chunks(2).zip(host_bytes.chunks(2)).enumerate().filter(|(_, (a, b))| a != b).map(|(i, _)| i).collect();
    if let Some(&first) = differing.first() {
        let (x, y) = (first % usize::from(reference::WIDTH), first / usize::from(reference::WIDTH));
        let px = |b: &[u8]| u16::from_le_bytes([b[2 * first], b[2 * first + 1]]);
        panic!(
            "{name}: {} pixels differ from the host rendering; first at ({x}, {y}): QEMU {:04x}, host {:04x}",
            differing.len(),
            px(&qemu),
            px(host_bytes)
        );
    }
    true
}
