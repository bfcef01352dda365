//! Fog (issue "Scenes that move"): a hand-made `.babylon` scene with each `fogMode`, converted
//! and drawn with the scene's fog, against Babylon.js's `CalcFogFactor` evaluated here in f64
//! at every pixel: the pixel's view-space distance (the length of its view-space position, as
//! Babylon.js's `vFogDistance`) from the pixel's ray through the wall, the factor of the mode,
//! the colour `f · white + (1 - f) · fog colour`.

#![cfg(feature = "fog")]

use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use soft3d::convert::{emit, read_babylon, ConvertOptions, EmitOptions};
use soft3d::{Band, Camera, Fog, FogMode, Lights, Mat4, Model, RenderOptions, Renderer, Scratch, Shading, Vec3};

const WIDTH: u16 = 64;
const HEIGHT: u16 = 48;
/// The wall's distance along the view axis.
const WALL: f64 = 10.0;
const FOV: f64 = 0.8;
const FOG_COLOR: [f64; 3] = [0.2, 0.4, 0.6];

/// A white wall at z = 10 filling the view of a camera at the origin looking along +z, with
/// fog `fog` (the scene's JSON fields).
fn scene(fog: &str) -> String {
    format!(
        r#"{{
        "cameras": [{{"id": "c", "name": "c", "position": [0, 0, 0], "target": [0, 0, 10],
                     "fov": {FOV}, "minZ": 1, "maxZ": 100}}],
        "activeCameraID": "c",
        "materials": [{{"id": "white", "name": "white", "diffuse": [1, 1, 1]}}],
        "meshes": [{{"name": "wall", "id": "wall", "materialId": "white",
            "positions": [-40, -40, 10, 40, -40, 10, 40, 40, 10, -40, 40, 10],
            "normals": [0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1],
            "indices": [0, 1, 2, 0, 2, 3]}}],
        {fog}
    }}"#
    )
}

/// The scene converted with the fog fields `fog`.
fn model_bytes(fog: &str) -> Vec<u8> {
    let (scene, warnings) = read_babylon(scene(fog).as_bytes(), None, "fog.babylon", &ConvertOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(warnings.is_empty(), "{warnings:?}");
    emit(&scene, &EmitOptions { float_positions: true, ..EmitOptions::default() }).unwrap()
}

/// The model drawn unlit, both sides, with its camera and `fog`.
fn render(model: &Model<'_>, fog: Option<Fog>) -> Vec<Rgb888> {
    let c = model.camera().unwrap();
    let aspect = f32::from(WIDTH) / f32::from(HEIGHT);
    let camera = Camera::perspective(c.position, c.target, c.fov, aspect, c.near, c.far).unwrap();
    let opts = RenderOptions { shading: Shading::Unlit, fog, ..RenderOptions::default() };
    let n = usize::from(WIDTH) * usize::from(HEIGHT);
    let (mut color, mut depth) = (vec![Rgb888::BLACK; n], vec![u16::MAX; n]);
    let mut band = Band::new(&mut color[..], &mut depth[..], WIDTH, HEIGHT, 0).unwrap();
    let lights = Lights::<1>::new(Vec3::ZERO);
    Renderer::new(&camera, &lights, opts).draw(&mut band, model, Mat4::IDENTITY, &mut Scratch::none()).unwrap();
    color
}

/// Babylon.js's `CalcFogFactor` for a mode code and density, start, end, in f64.
fn babylon_factor(mode: u8, (density, start, end): (f64, f64, f64), d: f64) -> f64 {
    // Babylon.js's GLSL `#define E 2.71828`, not e.
    #[allow(clippy::approx_constant)]
    let e = 2.71828f64;
    let f = match mode {
        1 => 1.0 / e.powf(d * density),
        2 => 1.0 / e.powf(d * d * density * density),
        _ => (end - d) / (end - start),
    };
    f.clamp(0.0, 1.0)
}

/// The view-space distance of the wall at pixel `(x, y)`'s centre.
fn distance(x: usize, y: usize) -> f64 {
    let t = (FOV / 2.0).tan();
    let aspect = f64::from(WIDTH) / f64::from(HEIGHT);
    let nx = (x as f64 + 0.5) / (f64::from(WIDTH) / 2.0) - 1.0;
    let ny = 1.0 - (y as f64 + 0.5) / (f64::from(HEIGHT) / 2.0);
    WALL * (1.0 + (nx * t * aspect).powi(2) + (ny * t).powi(2)).sqrt()
}

/// The largest difference, over every pixel and channel, between the frame and Babylon.js's
/// fogged white for `mode` with `params`.
fn largest_error(frame: &[Rgb888], mode: u8, params: (f64, f64, f64)) -> f64 {
    let mut worst = 0.0f64;
    for (i, px) in frame.iter().enumerate() {
        let (x, y) = (i % usize::from(WIDTH), i / usize::from(WIDTH));
        let f = babylon_factor(mode, params, distance(x, y));
        for (c, got) in [px.r(), px.g(), px.b()].into_iter().enumerate() {
            let want = 255.0 * (f + (1.0 - f) * FOG_COLOR[c]);
            worst = worst.max((f64::from(got) - want).abs());
        }
    }
    worst
}

/// Each mode of a hand-made scene, read from its file: every pixel within 1.5 of Babylon.js's
/// formula (8-bit rounding of the colour and of the factor's 1/256ths), and the fog visibly
/// varying across the wall (the distance is radial: the corners are fogged more).
#[test]
fn each_fog_mode_matches_babylons_factor_at_every_pixel() {
    let modes = [
        (1, (0.05, 0.0, 0.0), r#""fogMode": 1, "fogDensity": 0.05"#),
        (2, (0.08, 0.0, 0.0), r#""fogMode": 2, "fogDensity": 0.08"#),
        (3, (0.0, 4.0, 16.0), r#""fogMode": 3, "fogStart": 4, "fogEnd": 16"#),
    ];
    for (mode, params, fields) in modes {
        let fog_fields = format!(r#"{fields}, "fogColor": [0.2, 0.4, 0.6]"#);
        let bytes = model_bytes(&fog_fields);
        let model = Model::parse(&bytes).unwrap();
        let fog = model.fog().expect("the scene's fog");
        assert_eq!(fog.mode as u8, mode);
        let frame = render(&model, Some(fog));
        let error = largest_error(&frame, mode, params);
        let (centre, corner) = (frame[usize::from(HEIGHT / 2 * WIDTH + WIDTH / 2)], frame[0]);
        println!("fog mode {mode}: largest error {error:.2} of 255; centre {centre:?}, corner {corner:?}");
        assert!(error <= 1.5, "mode {mode}: {error}");
        assert_ne!(centre, corner, "mode {mode}: the fog does not vary with the distance");
    }
}

/// Without fog the wall is white; the render option overrides the scene's fog (here: off).
#[test]
fn the_render_option_decides() {
    let bytes = model_bytes(r#""fogMode": 2, "fogDensity": 0.5, "fogColor": [0, 0, 0]"#);
    let model = Model::parse(&bytes).unwrap();
    assert!(render(&model, None).iter().all(|&c| c == Rgb888::WHITE));
    let thick = Fog { density: 1.0, ..Fog::new(FogMode::Exp, Vec3::ZERO) };
    assert!(render(&model, Some(thick)).iter().all(|&c| c == Rgb888::BLACK));
}

/// A scene without fog stays a version 1 file with none; with fog its file is version 3.
#[test]
fn fog_travels_in_the_file() {
    let still = model_bytes(r#""fogMode": 0"#);
    assert_eq!(u16::from_le_bytes([still[4], still[5]]), 1);
    assert_eq!(Model::parse(&still).unwrap().fog(), None);
    let foggy = model_bytes(r#""fogMode": 3, "fogStart": 1, "fogEnd": 2"#);
    assert_eq!(u16::from_le_bytes([foggy[4], foggy[5]]), 3);
    let fog = Model::parse(&foggy).unwrap().fog().unwrap();
    // Babylon.js's defaults for what the file leaves out.
    assert_eq!(
        (fog.mode, fog.color, fog.density, fog.start, fog.end),
        (FogMode::Linear, Vec3::new(0.2, 0.2, 0.3), 0.1, 1.0, 2.0)
    );
}

/// A bad fog in a file is an error naming it.
#[test]
fn a_bad_fog_mode_is_an_error() {
    let json = scene(r#""fogMode": 7"#);
    let e = read_babylon(json.as_bytes(), None, "fog.babylon", &ConvertOptions::default()).unwrap_err();
    assert!(e.to_string().contains("fogMode 7"), "{e}");
}
