//! The reference "Suzanne frame": checks coverage against the figure other renderers give.
use embedded_graphics_core::pixelcolor::Rgb565;
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::format::{emit, EmitOptions};
use soft3d::math::{Mat4, Vec3};
use soft3d::{Band, Camera, Lights, Model, RenderOptions};

#[test]
fn suzanne_reference_frame_covers_14457_pixels() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/suzanne/monkey.babylon");
    let (scene, _) =
        read_babylon_file(path.as_ref(), &ConvertOptions { uv_origin: UvOrigin::Top, ..Default::default() }).unwrap();
    let bytes = emit(&scene, &EmitOptions { float_positions: true, ..Default::default() }).unwrap();
    let model = Model::parse(&bytes).unwrap();
    let camera = Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap();
    let mut lights = Lights::<1>::new(Vec3::splat(0.2));
    lights.push(Lights::<1>::directional(Vec3::new(0.5, -0.5, 1.0), 0.8)).unwrap();
    let mut color = vec![Rgb565::new(0, 0, 0); 240 * 240];
    let mut depth = vec![0u16; 240 * 240];
    let mut band = Band::new(&mut color[..], &mut depth[..], 240, 240, 0).unwrap();
    band.clear(Rgb565::new(0, 0, 0));
    let stats =
        soft3d::draw_model(&mut band, &model, Mat4::from_rotation_y(0.5), &camera, &lights, &RenderOptions::default());
    let covered = depth.iter().filter(|&&d| d != u16::MAX).count();
    println!("{stats:?} covered {covered}");
    assert_eq!(covered, 14457);
}
