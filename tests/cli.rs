//! The `soft3d` CLI refuses what it cannot honour with a message that names the option and
//! what it allows (issue "Any .babylon a user drops in shows up right the first time"): each
//! test runs the binary on a one-triangle scene written for it and checks the exit status and
//! the message.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A one-triangle `.babylon` scene in a fresh folder of the system's temporary one, named
/// after `test`; the folder.
fn scene(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("soft3d-cli-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = r#"{"meshes":[{"name":"t","id":"t","positions":[0,0,0,1,0,0,0,1,0],
        "indices":[0,1,2],"normals":[0,0,-1,0,0,-1,0,0,-1]}]}"#;
    std::fs::write(dir.join("tri.babylon"), json).unwrap();
    dir
}

/// `soft3d render SCENE -o OUTPUT ARGS`.
fn render_to(scene: &Path, output: &Path, args: &[&str]) -> Output {
    let render = [OsStr::new("render"), scene.as_os_str(), OsStr::new("-o"), output.as_os_str()];
    Command::new(env!("CARGO_BIN_EXE_soft3d")).args(render).args(args).output().unwrap()
}

/// `soft3d render tri.babylon -o out.png ARGS` in `scene(test)`'s folder.
fn render(test: &str, args: &[&str]) -> Output {
    let dir = scene(test);
    let out = render_to(&dir.join("tri.babylon"), &dir.join("out.png"), args);
    std::fs::remove_dir_all(&dir).unwrap();
    out
}

/// Asserts that `out` failed with a message holding every one of `parts`.
fn assert_refused(out: &Output, parts: &[&str]) {
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted; stderr: {message}");
    for part in parts {
        assert!(message.contains(part), "{part:?} not in {message:?}");
    }
}

#[test]
fn the_scene_renders() {
    let out = render("ok", &["--size", "64x48"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_size_out_of_range_names_the_range() {
    for size in ["70000x70000", "4000x3000", "0x0", "64x0"] {
        let out = render("size", &["--size", size]);
        assert_refused(&out, &["--size", "1..=1536", size]);
    }
}

#[test]
fn a_specular_exponent_must_be_finite_and_positive() {
    for exponent in ["nan", "-5", "0", "inf"] {
        let out = render("specular", &["--specular", exponent]);
        assert_refused(&out, &["--specular", "finite exponent above 0"]);
    }
}

#[test]
fn a_gif_has_at_least_one_frame() {
    let out = render("frames", &["--gif", "never-written.gif", "--frames", "0"]);
    assert_refused(&out, &["--frames", "0 is not in 1.."]);
}

#[test]
fn textures_are_at_least_one_texel() {
    let out = render("max-texture", &["--max-texture", "0"]);
    assert_refused(&out, &["--max-texture", "0 is not in 1.."]);
}

#[test]
fn a_light_needs_a_direction() {
    let out = render("light", &["--light", "dir:0,0,0"]);
    assert_refused(&out, &["--light", "direction must not be zero"]);
}

#[test]
fn the_picture_is_named_as_what_it_is() {
    let dir = scene("output");
    let out = render_to(&dir.join("tri.babylon"), &dir.join("out.jpg"), &[]);
    let written = dir.join("out.jpg").exists();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_refused(&out, &["-o", "PNG", "*.raw", "*.gif", "out.jpg"]);
    assert!(!written, "a file was written");
}

/// A 4x4 red texture in `format`, made by the `image` crate's own encoder (each format takes
/// the pixel type it can store).
fn red_texture(format: image::ImageFormat) -> Vec<u8> {
    use image::{DynamicImage, ImageFormat as F};
    let red = DynamicImage::ImageRgb8(image::RgbImage::from_pixel(4, 4, image::Rgb([255, 0, 0])));
    let img = match format {
        F::Hdr => DynamicImage::ImageRgb32F(red.to_rgb32f()),
        F::OpenExr => DynamicImage::ImageRgba32F(red.to_rgba32f()),
        F::Farbfeld => DynamicImage::ImageRgba16(red.to_rgba16()),
        F::Ico => DynamicImage::ImageRgba8(red.to_rgba8()),
        _ => red,
    };
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, format).unwrap_or_else(|e| panic!("{format:?}: {e}"));
    out.into_inner()
}

/// A 4x4 DXT1 DDS, every texel red (the `image` crate decodes DDS but does not write it).
fn red_dds() -> Vec<u8> {
    let mut dds = b"DDS ".to_vec();
    let flags = 0x1 | 0x2 | 0x4 | 0x1000; // caps, height, width, pixel format
    let header = [124, flags, 4, 4, 8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    let pixel_format = [32, 0x4, u32::from_le_bytes(*b"DXT1"), 0, 0, 0, 0, 0];
    for word in header.iter().chain(&pixel_format).chain(&[0x1000, 0, 0, 0, 0]) {
        dds.extend(word.to_le_bytes());
    }
    dds.extend([0x00, 0xF8, 0x00, 0xF8, 0, 0, 0, 0]); // both end colours RGB565 red, all texels colour 0
    dds
}

#[test]
fn every_pure_rust_image_format_is_a_texture() {
    use image::ImageFormat as F;
    let encoded = [F::Png, F::Jpeg, F::Gif, F::WebP, F::Pnm, F::Tiff, F::Tga, F::Bmp, F::Ico, F::Hdr];
    let mut files: Vec<(String, Vec<u8>)> = [F::OpenExr, F::Farbfeld, F::Qoi]
        .into_iter()
        .chain(encoded)
        .map(|f| (format!("red.{}", f.extensions_str()[0]), red_texture(f)))
        .collect();
    files.push(("red.dds".into(), red_dds()));
    for (name, bytes) in files {
        let dir = scene(&name.replace('.', "-"));
        std::fs::write(dir.join(&name), bytes).unwrap();
        let json = r#"{"materials":[{"name":"m","id":"m","diffuse":[1,1,1],"diffuseTexture":{"name":"NAME"}}],
            "meshes":[{"name":"t","id":"t","materialId":"m","positions":[-1,-1,0,1,-1,0,-1,1,0],
            "indices":[0,1,2],"normals":[0,0,-1,0,0,-1,0,0,-1],"uvs":[0,0,1,0,0,1]}]}"#;
        std::fs::write(dir.join("tex.babylon"), json.replace("NAME", &name)).unwrap();
        let out = render_to(&dir.join("tex.babylon"), &dir.join("out.png"), &["--size", "64x48", "--shading", "unlit"]);
        let picture = image::open(dir.join("out.png")).map(|i| i.to_rgb8());
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let red = picture.unwrap().pixels().filter(|p| p.0[0] > 240 && p.0[1] < 16 && p.0[2] < 16).count();
        assert!(red > 50, "{name}: {red} red pixels");
    }
}

#[test]
fn an_empty_scene_says_so() {
    let dir = scene("empty");
    std::fs::write(dir.join("empty.babylon"), "{}").unwrap();
    let out = render_to(&dir.join("empty.babylon"), &dir.join("out.png"), &[]);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_refused(&out, &["empty.babylon", "no triangles to draw"]);
}

#[test]
fn info_tells_the_file_from_the_converted_model() {
    let dir = scene("info");
    let out = Command::new(env!("CARGO_BIN_EXE_soft3d")).arg("info").arg(dir.join("tri.babylon")).output().unwrap();
    let file = std::fs::metadata(dir.join("tri.babylon")).unwrap().len();
    std::fs::remove_dir_all(&dir).unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let first = text.lines().next().unwrap_or_default();
    assert!(first.contains(&format!(": {file} bytes, ")) && first.ends_with(" bytes converted"), "{first}");
}

/// Renders the scene `json` (written as `test.babylon` in a fresh folder) with `args` at 64x48:
/// the run, and the picture when one was written.
fn render_scene(test: &str, json: &str, args: &[&str]) -> (Output, Option<image::RgbImage>) {
    let dir = scene(test);
    std::fs::write(dir.join("test.babylon"), json).unwrap();
    let mut all = vec!["--size", "64x48", "--background", "0,0,0"];
    if !args.contains(&"--shading") {
        all.extend(["--shading", "unlit"]);
    }
    all.extend_from_slice(args);
    let out = render_to(&dir.join("test.babylon"), &dir.join("out.png"), &all);
    let picture = image::open(dir.join("out.png")).ok().map(|i| i.to_rgb8());
    std::fs::remove_dir_all(&dir).unwrap();
    (out, picture)
}

/// Pixels of `picture` (which must exist) that are not the black background.
fn drawn_pixels(out: &Output, picture: Option<&image::RgbImage>) -> usize {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    picture.expect("a picture").pixels().filter(|p| p.0 != [0, 0, 0]).count()
}

/// A white square of side 20 at the origin, facing -z, and `camera` (JSON) as the scene's.
fn square_with(camera: &str) -> String {
    format!(
        r#"{{"meshes":[{{"name":"s","id":"s","positions":[-10,-10,0,10,-10,0,10,10,0,-10,10,0],
        "indices":[0,1,2,0,2,3],"normals":[0,0,-1,0,0,-1,0,0,-1,0,0,-1]}}],
        "cameras":[{camera}],"activeCameraID":"c"}}"#
    )
}

#[test]
fn an_infinite_far_plane_reaches_the_whole_scene() {
    let camera = r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0],"fov":0.8,"minZ":1,"maxZ":0}"#;
    let (out, picture) = render_scene("maxz", &square_with(camera), &[]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("maxZ 0 (an infinite far plane)"));
    assert!(drawn_pixels(&out, picture.as_ref()) > 300);
}

#[test]
fn a_camera_looking_at_its_own_position_is_replaced() {
    let camera = r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,-40]}"#;
    let (out, picture) = render_scene("degenerate", &square_with(camera), &[]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("its position is its target"));
    assert!(drawn_pixels(&out, picture.as_ref()) > 300);
}

#[test]
fn a_moved_eye_fits_the_near_and_far_planes() {
    // The scene's far plane (at 50) would cut the square off from an eye 80 away.
    let camera = r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0],"minZ":1,"maxZ":50}"#;
    let (out, picture) = render_scene("eye", &square_with(camera), &["--eye", "0,0,-80"]);
    assert!(drawn_pixels(&out, picture.as_ref()) > 100);
    // Unless the user says where they are.
    let (out, picture) = render_scene("eye-far", &square_with(camera), &["--eye", "0,0,-80", "--far", "50"]);
    assert_eq!(drawn_pixels(&out, picture.as_ref()), 0);
}

#[test]
fn without_a_depth_buffer_the_nearest_triangle_is_drawn_last() {
    // The red triangle in front comes first in the file: drawn as stored, the blue one behind
    // would cover it.
    let tri = |z: i32| format!("-10,-10,{z},10,-10,{z},0,10,{z}");
    let json = format!(
        r#"{{"materials":[{{"name":"r","id":"r","diffuse":[1,0,0]}},{{"name":"b","id":"b","diffuse":[0,0,1]}}],
        "meshes":[{{"name":"near","id":"near","materialId":"r","positions":[{}],"indices":[0,1,2],
        "normals":[0,0,-1,0,0,-1,0,0,-1]}},
        {{"name":"far","id":"far","materialId":"b","positions":[{}],"indices":[0,1,2],
        "normals":[0,0,-1,0,0,-1,0,0,-1]}}],
        "cameras":[{{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0]}}],"activeCameraID":"c"}}"#,
        tri(0),
        tri(5)
    );
    for depth in ["none", "u16"] {
        let (out, picture) = render_scene(&format!("depth-{depth}"), &json, &["--depth", depth]);
        assert!(drawn_pixels(&out, picture.as_ref()) > 100);
        let centre = picture.unwrap().get_pixel(32, 24).0;
        assert_eq!(centre, [255, 0, 0], "--depth {depth}: the centre is {centre:?}");
    }
}

#[test]
fn stats_print_as_json_one_object_a_frame() {
    // Never /dev/null: the CLI writes through a rename, which would replace the device.
    let gif = std::env::temp_dir().join(format!("soft3d-cli-spin-{}.gif", std::process::id()));
    let gif = gif.to_str().unwrap();
    let (out, _) = render_scene(
        "json",
        &square_with(r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0]}"#),
        &["--stats", "json", "--gif", gif, "--frames", "2", "--bands", "1"],
    );
    let _ = std::fs::remove_file(gif);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let frames: Vec<serde_json::Value> = text
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}")))
        .collect();
    // The picture's frame, then the GIF's two.
    assert_eq!(frames.len(), 3, "{text}");
    assert_eq!(frames[0]["frame"], 1);
    assert_eq!(frames[2]["frame"], 2);
    for f in &frames {
        assert_eq!((f["width"].as_u64(), f["height"].as_u64(), f["triangles"].as_u64()), (Some(64), Some(48), Some(2)));
        assert!(f["ms"].is_number(), "{f}");
    }
    // The GIF's second frame shows the square's back (turned half a turn).
    assert!(frames[0]["pixels_written"].as_u64().unwrap() > 100, "{}", frames[0]);
    assert_eq!((frames[2]["drawn"].as_u64(), frames[2]["culled_back_face"].as_u64()), (Some(0), Some(2)));
}

#[test]
fn what_the_lights_options_drop_is_said() {
    let light = |k: u32| format!(r#"{{"name":"l{k}","id":"l{k}","type":1,"direction":[0,0,1],"intensity":0.1}}"#);
    let lights: Vec<String> = (0..10).map(light).collect();
    let json = square_with(r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0]}"#).replacen(
        "\"cameras\"",
        &format!("\"lights\":[{}],\"cameras\"", lights.join(",")),
        1,
    );
    let (out, _) = render_scene("lights", &json, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("the scene has 10 lights; soft3d draws 8: the last 2 are left out"), "{stderr}");
    let (out, _) = render_scene("light-flag", &json, &["--light", "dir:0,0,1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--light replaces the scene's 10 light(s)"), "{stderr}");
    let (out, _) = render_scene("phong", &json, &["--shading", "phong", "--specular", "32"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && stderr.contains("--specular is not drawn with --shading phong"), "{stderr}");
}

#[test]
fn a_legacy_textured_file_hints_at_the_uv_origin() {
    let suzanne = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/suzanne/monkey.babylon");
    let dir = scene("uv-origin");
    for (args, hinted) in [(&[][..], true), (&["--uv-origin", "top"][..], false)] {
        let out = render_to(&suzanne, &dir.join("out.png"), &[&["--size", "32x32"][..], args].concat());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        assert_eq!(stderr.contains("--uv-origin top"), hinted, "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_special_file_is_never_replaced() {
    // A folder named like a picture: the write's rename must not replace it.
    let dir = scene("special");
    std::fs::create_dir_all(dir.join("out.png")).unwrap();
    let out = render_to(&dir.join("tri.babylon"), &dir.join("out.png"), &[]);
    let still_a_folder = dir.join("out.png").is_dir();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_refused(&out, &["out.png", "not a regular file"]);
    assert!(still_a_folder);
}

/// Renders the scene `json` (as `render_scene` does, at 64x48 over black) into `output` in a
/// fresh folder: the run and the file's bytes (empty when none was written).
fn render_scene_as(test: &str, json: &str, output: &str, args: &[&str]) -> (Output, Vec<u8>) {
    let dir = scene(test);
    std::fs::write(dir.join("test.babylon"), json).unwrap();
    let all = [&["--size", "64x48", "--background", "0,0,0", "--shading", "unlit"][..], args].concat();
    let out = render_to(&dir.join("test.babylon"), &dir.join(output), &all);
    let bytes = std::fs::read(dir.join(output)).unwrap_or_default();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(out.status.success(), "{test}: {}", String::from_utf8_lossy(&out.stderr));
    (out, bytes)
}

/// A square seen from (0,0,-40), tinted (a material colour with three different channels).
fn tinted_square() -> String {
    square_with(r#"{"id":"c","name":"c","position":[0,0,-40],"target":[0,0,0]}"#).replacen(
        "\"meshes\":[{",
        r#""materials":[{"name":"m","id":"m","diffuse":[1,0.5,0.25]}],"meshes":[{"materialId":"m","#,
        1,
    )
}

#[test]
fn any_thread_and_band_count_draws_the_same_picture() {
    let json = tinted_square();
    let (_, one) = render_scene_as("threads-1", &json, "out.png", &["--threads", "1", "--bands", "1"]);
    for args in
        [&["--threads", "2"][..], &["--threads", "3", "--bands", "7"], &["--threads", "8", "--bands", "48"], &[]]
    {
        let (out, many) = render_scene_as("threads-n", &json, "out.png", args);
        assert!(many == one, "{args:?}: {}", String::from_utf8_lossy(&out.stdout));
    }
    let out = render("bands", &["--bands", "0"]);
    assert_refused(&out, &["--bands", "1..=480"]);
}

#[test]
fn raw_output_is_the_framebuffer_in_the_chosen_format() {
    let json = tinted_square();
    let png = |format: &str| {
        let (_, bytes) = render_scene_as(&format!("png-{format}"), &json, "out.png", &["--format", format]);
        image::load_from_memory(&bytes).unwrap().to_rgb8().into_raw()
    };
    let raw =
        |format: &str, name: &str| render_scene_as(&format!("raw-{format}"), &json, name, &["--format", format]).1;
    // RGB888: three bytes a pixel, the PNG's; gray: one, the PNG's grey level.
    assert_eq!(raw("rgb888", "out.raw"), png("rgb888"));
    let grey: Vec<u8> = png("gray8").chunks(3).map(|p| p[0]).collect();
    assert_eq!(raw("gray8", "out.bin"), grey);
    // RGB565: two bytes a pixel, little-endian, and big-endian for rgb565be; the tint's
    // channels narrowed to 5, 6 and 5 bits.
    let (le, be) = (raw("rgb565", "out.raw"), raw("rgb565be", "out.raw"));
    assert_eq!(le.len(), 64 * 48 * 2);
    let swapped: Vec<u8> = be.chunks(2).flat_map(|p| [p[1], p[0]]).collect();
    assert_eq!(le, swapped);
    let centre = (24 * 64 + 32) * 2;
    assert_eq!(u16::from_be_bytes([be[centre], be[centre + 1]]), 31 << 11 | 32 << 5 | 8);
    // Mono: a bit a pixel, most significant first, 8 bytes a row of 64.
    let mono = raw("mono", "out.raw");
    let lit: Vec<bool> = png("mono").chunks(3).map(|p| p[0] > 0).collect();
    assert_eq!(mono.len(), 64 * 48 / 8);
    for (i, on) in lit.iter().enumerate() {
        assert_eq!(mono[i / 8] >> (7 - i % 8) & 1 == 1, *on, "pixel {i}");
    }
    assert!(lit.iter().any(|&on| on) && !lit.iter().all(|&on| on));
}

#[test]
fn a_gif_output_is_the_turntable() {
    let (_, gif) = render_scene_as("gif-out", &tinted_square(), "spin.gif", &["--frames", "3"]);
    use image::AnimationDecoder;
    let decoder = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(gif)).unwrap();
    let frames = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[0].buffer().dimensions(), (64, 48));
}

/// A scene with an animation makes a GIF of every frame of its range, at its frame rate as far
/// as a GIF can keep it: delays are whole hundredths of a second, and browsers play those under
/// two at a tenth of a second, so a 60 fps track gets 20 ms, not 17 (stored as 10).
#[test]
fn a_gif_of_an_animated_scene_plays_its_range() {
    let slide = r#""animations":[{"property":"position.x","dataType":0,"framePerSecond":60,
        "keys":[{"frame":0,"values":[-8]},{"frame":4,"values":[8]}]}],"#;
    let json = tinted_square().replacen(r#""name":"s","#, &format!(r#""name":"s",{slide}"#), 1);
    let (_, gif) = render_scene_as("gif-animation", &json, "slide.gif", &[]);
    use image::AnimationDecoder;
    let decoder = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(gif)).unwrap();
    let frames = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 5, "frames 0 to 4");
    assert!(frames[0].buffer() != frames[4].buffer(), "the square moves");
    for f in &frames {
        assert_eq!(f.delay().numer_denom_ms(), (20, 1));
    }
}

#[test]
fn an_up_direction_orients_a_camera_looking_straight_down() {
    // The square lies in the xz plane under an eye at y = 40.
    let json = r#"{"meshes":[{"name":"s","id":"s","positions":[-10,0,-10,10,0,-10,10,0,10,-10,0,10],
        "indices":[0,1,2,0,2,3],"normals":[0,1,0,0,1,0,0,1,0,0,1,0]}]}"#;
    let down = ["--eye", "0,40,0", "--target", "0,0,0"];
    let (out, _) = render_scene("up-default", json, &down);
    assert_refused(&out, &["--up", "0,0,1"]);
    let (out, picture) = render_scene("up", json, &[&down[..], &["--up", "0,0,1"]].concat());
    assert!(drawn_pixels(&out, picture.as_ref()) > 300);
    let (out, _) = render_scene("up-zero", json, &[&down[..], &["--up", "0,0,0"]].concat());
    assert_refused(&out, &["--up", "not be zero"]);
}

#[test]
fn an_orthographic_camera_shows_the_same_size_at_any_distance() {
    let json = tinted_square();
    // 40 units from the bottom of the frame to the top: the 20-unit square is 24 of 48 rows,
    // and 24 columns (the frame shows 53.3 units across its 64).
    for eye in ["0,0,-20", "0,0,-200"] {
        let args = ["--camera", "ortho", "--ortho-height", "40", "--eye", eye, "--target", "0,0,0"];
        let (out, picture) = render_scene(&format!("ortho{eye}"), &json, &args);
        assert_eq!(drawn_pixels(&out, picture.as_ref()), 24 * 24, "eye {eye}");
    }
    let (out, _) = render_scene("ortho-bad", &json, &["--camera", "ortho", "--ortho-height", "-1"]);
    assert_refused(&out, &["--ortho-height", "finite number above 0"]);
}

/// The rows and columns holding drawn (not black) pixels: their counts.
fn drawn_extent(picture: &image::RgbImage) -> (u32, u32) {
    let lit: Vec<(u32, u32)> =
        picture.enumerate_pixels().filter(|(_, _, p)| p.0 != [0, 0, 0]).map(|(x, y, _)| (x, y)).collect();
    let span = |v: Vec<u32>| v.iter().max().zip(v.iter().min()).map_or(0, |(hi, lo)| hi - lo + 1);
    (span(lit.iter().map(|p| p.0).collect()), span(lit.iter().map(|p| p.1).collect()))
}

#[test]
fn a_scene_without_a_camera_and_fit_fill_the_frame() {
    let square = r#"{"meshes":[{"name":"s","id":"s","positions":[-10,-10,0,10,-10,0,10,10,0,-10,10,0],
        "indices":[0,1,2,0,2,3],"normals":[0,0,-1,0,0,-1,0,0,-1,0,0,-1]}]}"#;
    let far_camera = square_with(r#"{"id":"c","name":"c","position":[0,0,-400],"target":[0,0,0],"maxZ":1000}"#);
    let ortho = ["--camera", "ortho"];
    for (test, json, args) in [
        ("no-camera", square, &[][..]),
        ("fit", &far_camera, &["--fit"][..]),
        ("ortho-no-camera", square, &ortho[..]),
        ("ortho-fit", &far_camera, &[&ortho[..], &["--fit"]].concat()[..]),
    ] {
        let (out, picture) = render_scene(test, json, args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        // 48 rows is the limiting dimension of 64x48: at least 90% of it.
        let (columns, rows) = drawn_extent(&picture.unwrap());
        assert!((44..=48).contains(&rows) && columns <= 64, "{test}: {columns}x{rows}");
    }
    // Without --fit the far camera sees the square small.
    let (_, picture) = render_scene("far", &far_camera, &[]);
    assert!(drawn_extent(&picture.unwrap()).1 < 10);
}

#[test]
fn camera_options_name_themselves_and_their_range() {
    for (args, parts) in [
        (&["--fov", "5"][..], &["--fov", "(0, 3.1416)"][..]),
        (&["--fov", "-1"], &["--fov", "(0, 3.1416)"]),
        (&["--near", "-1"], &["--near", "finite number above 0"]),
        (&["--far", "nan"], &["--far", "finite number above 0"]),
        (&["--near", "5", "--far", "2"], &["--far", "beyond the near plane at 5"]),
        (&["--subspan", "0"], &["--subspan", "0 is not in 1.."]),
    ] {
        let out = render("camera-options", args);
        assert_refused(&out, parts);
    }
}
