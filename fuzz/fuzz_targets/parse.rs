//! `Model::parse` on arbitrary bytes, then every accessor and a small render: never panics.
#![no_main]
use embedded_graphics_core::pixelcolor::Rgb565;
use libfuzzer_sys::fuzz_target;
use soft3d::{Band, Camera, Lights, Mat4, Model, RenderOptions, Renderer, Scratch, Vec3};

fuzz_target!(|data: &[u8]| {
    let Ok(model) = Model::parse(data) else { return };
    for (mesh, _) in model.draws() {
        for i in 0..mesh.vertex_count().min(4096) {
            let _ = (mesh.position(i), mesh.normal(i), mesh.uv(i), mesh.color(i));
        }
    }
    let camera = Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, 1.0, 0.1, 100.0).unwrap();
    let lights = Lights::<2>::from_model(&model);
    let mut color = [Rgb565::default(); 32 * 8];
    let mut depth = [0u16; 32 * 8];
    let mut band = Band::new(&mut color[..], &mut depth[..], 32, 32, 8).unwrap();
    let renderer = Renderer::new(&camera, &lights, RenderOptions::default());
    renderer.draw(&mut band, &model, Mat4::IDENTITY, &mut Scratch::none()).expect("stored order needs no scratch");
});
