//! Renders the reference Suzanne frame repeatedly (for profilers such as callgrind or perf).
//! `cargo run --release --example profile -- [frames] [width] [height] [bands] [unlit|flat|gouraud|phong]`
use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
use soft3d::convert::{emit, EmitOptions};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::reference;
use soft3d::{Band, Model};

fn main() {
    let arg = |i: usize, d: usize| std::env::args().nth(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (frames, w, h, bands) = (arg(1, 200), arg(2, 240), arg(3, 240), arg(4, 1));
    let shading = match std::env::args().nth(5).as_deref() {
        Some("unlit") => soft3d::Shading::Unlit,
        Some("flat") => soft3d::Shading::Flat,
        Some("phong") => soft3d::Shading::Phong,
        _ => soft3d::Shading::Gouraud,
    };
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/suzanne/monkey.babylon");
    let opts = ConvertOptions { uv_origin: UvOrigin::Top, max_texture: Some(128), ..Default::default() };
    let (scene, _) = read_babylon_file(path.as_ref(), &opts).expect("asset converts");
    let bytes = emit(&scene, &EmitOptions { float_positions: true, ..Default::default() }).expect("emit");
    let model = Model::parse(&bytes).expect("parse");
    let camera = reference::camera(w as u16, h as u16);
    let lights = reference::lights();
    let rows = h.div_ceil(bands);
    let mut color = vec![Rgb565::BLACK; w * rows];
    let mut depth = vec![0u16; w * rows];
    let start = std::time::Instant::now();
    let mut pixels = 0;
    let (triangles, vertices) = model.draw_counts();
    let mut rows_seen = vec![soft3d::TriangleRows::default(); triangles];
    let mut vertices_seen = vec![soft3d::TransformedVertex::default(); vertices];
    for _ in 0..frames {
        let mut cache = soft3d::Scratch::none().with_rows(&mut rows_seen).with_vertices(&mut vertices_seen);
        for first in (0..h).step_by(rows) {
            let n = rows.min(h - first) * w;
            let mut band = Band::new(&mut color[..n], &mut depth[..n], w as u16, h as u16, first as u16).expect("band");
            band.clear(Rgb565::BLACK);
            let (t, o) = (reference::transform(), soft3d::RenderOptions { shading, ..reference::options() });
            pixels += soft3d::Renderer::new(&camera, &lights, o)
                .draw(&mut band, &model, t, &mut cache)
                .unwrap()
                .pixels_written;
        }
    }
    let per = start.elapsed().as_secs_f64() * 1e3 / frames as f64;
    println!(
        "{w}x{h} {shading:?} in {bands} band(s): {per:.3} ms/frame, {} pixels written/frame",
        pixels / frames as u32
    );
}
