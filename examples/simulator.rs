//! The soft3d demo: the tutorial's textured, lit Suzanne turning on a 240x240 RGB565 "display",
//! rendered band by band exactly as a microcontroller would render it, with an FPS overlay.
//!
//! ```text
//! cargo run --release --example simulator                     # headless: PNGs + GIF in out/simulator/
//! cargo run --release --example simulator --features window   # an SDL window (needs libsdl2-dev)
//! cargo run --release --example simulator -- scene.babylon    # another scene (.babylon or .s3d)
//! ```
//!
//! A scene with animations (node tracks, morph targets, skeletons, its camera and lights)
//! plays them all at their frame rate, looping, instead of turning: every band of a frame
//! drawn with one `Pose`, and the scene's camera and lights where the pose puts them.
//!
//! Window keys: `1` unlit, `2` flat, `3` Gouraud, `4` Phong, `5` wireframe, `6` points,
//! `7` solid + wireframe, `f` nearest/bilinear, `b` band height (240/120/48/30/1 rows),
//! `d` dithering, `t` textures, space pause, Escape or `q` quit.
//!
//! [`render_frame`] is the part to copy into firmware: two band-sized buffers allocated once,
//! and for each band `Band::new` → `clear` → `Renderer::draw` → HUD via embedded-graphics →
//! `present` onto any `DrawTarget` (here a `SimulatorDisplay`, on a board the display driver).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Parser, ValueEnum};
use embedded_graphics::mono_font::{ascii::FONT_6X10, MonoTextStyleBuilder};
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};
use embedded_graphics_simulator::{OutputSettingsBuilder, SimulatorDisplay};
use soft3d::convert::{emit, EmitOptions};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::math::{Mat4, Vec3};
use soft3d::{Band, Camera, Filter, Lights, Mode, Model, RenderOptions, Shading, Stats};

/// The display: 240x240, the size of the common ST7789 modules.
const WIDTH: u16 = 240;
const HEIGHT: u16 = 240;
/// Band heights offered by the `b` key: 1, 2, 5, 8 and 240 bands.
#[cfg(feature = "window")]
const BAND_HEIGHTS: [u16; 5] = [240, 120, 48, 30, 1];
/// 48 rows: 5 bands of 240x48, i.e. 23 KB of colour plus 23 KB of depth.
const DEFAULT_BAND_ROWS: u16 = 48;
/// (32, 32, 48) in RGB565.
const BACKGROUND: Rgb565 = Rgb565::new(4, 8, 6);
/// Headless frames are shown 60 ms each in the GIF; the window turns at the same speed.
const GIF_DELAY_MS: u32 = 60;

#[derive(Parser)]
#[command(about = "soft3d demo: a rotating, textured, lit model on a simulated 240x240 RGB565 display")]
struct Args {
    /// A .babylon or .s3d scene to show instead of the tutorial's Suzanne.
    scene: Option<PathBuf>,
    /// Where uv (0,0) is in the texture: bottom (Babylon.js; the default for other scenes) or top
    /// (the 2013 tutorial's Suzanne, the default for it).
    #[arg(long, value_enum)]
    uv_origin: Option<Origin>,
    /// Render headless (PNG frames + GIF) even when a window could be opened.
    #[arg(long)]
    headless: bool,
    /// Headless: frames of one full turn.
    #[arg(long, default_value_t = 36)]
    frames: u32,
    /// Headless: output directory.
    #[arg(long, default_value = "out/simulator")]
    out: PathBuf,
    /// Window: quit after this many seconds.
    #[arg(long)]
    seconds: Option<f32>,
    /// What to draw first (the keys 1-7 switch it in the window).
    #[arg(long, value_enum, default_value_t = Look::Gouraud)]
    look: Look,
    /// Bilinear texture filtering (the `f` key).
    #[arg(long)]
    bilinear: bool,
    /// Rows per band, 1-240 (the `b` key cycles 240, 120, 48, 30, 1).
    #[arg(long, default_value_t = DEFAULT_BAND_ROWS, value_parser = clap::value_parser!(u16).range(1..=HEIGHT as i64))]
    band_rows: u16,
    /// Ordered dithering down to RGB565 (the `d` key).
    #[arg(long)]
    dither: bool,
    /// Ignore the scene's camera: frame the model's bounding spheres instead.
    #[arg(long)]
    fit: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Origin {
    Bottom,
    Top,
}

/// The shading / drawing modes on keys 1-7.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Look {
    Unlit,
    Flat,
    Gouraud,
    Phong,
    Wireframe,
    Points,
    SolidWire,
}

impl Look {
    fn name(self) -> &'static str {
        match self {
            Look::Unlit => "unlit",
            Look::Flat => "flat",
            Look::Gouraud => "gouraud",
            Look::Phong => "phong",
            Look::Wireframe => "wireframe",
            Look::Points => "points",
            Look::SolidWire => "solid+wire",
        }
    }

    /// Sets the shading and mode of `opts` for this look.
    fn apply(self, opts: &mut RenderOptions) {
        let (shading, mode) = match self {
            Look::Unlit => (Shading::Unlit, Mode::Solid),
            Look::Flat => (Shading::Flat, Mode::Solid),
            Look::Gouraud => (Shading::Gouraud, Mode::Solid),
            Look::Phong => (Shading::Phong, Mode::Solid),
            Look::Wireframe => (Shading::Gouraud, Mode::Wireframe),
            Look::Points => (Shading::Gouraud, Mode::Points),
            Look::SolidWire => (Shading::Gouraud, Mode::SolidWireframe),
        };
        opts.shading = shading;
        opts.mode = mode;
        opts.wire_color = (self == Look::SolidWire).then_some([255, 255, 0]);
    }
}

/// What the firmware has in flash and sets up once.
struct Scene<'a> {
    model: Model<'a>,
    camera: Camera,
    /// Whether `camera` is the scene's own (then its animation moves it).
    own_camera: bool,
    lights: Lights<4>,
    /// The model turns about the vertical axis through this point.
    pivot: Vec3,
    /// The scene's animation, when it has one: played instead of the turn.
    playback: Option<Playback>,
}

/// Every animation group of a scene, played together over their frames at their rate.
#[derive(Clone, Copy)]
struct Playback {
    from: f32,
    to: f32,
    fps: f32,
}

impl Playback {
    /// The scene's, if it has animation groups.
    fn of(model: &Model<'_>) -> Option<Self> {
        let a = model.animation()?;
        let groups: Vec<_> = (0..a.group_count()).filter_map(|g| a.group(g)).collect();
        let from = groups.iter().map(|g| g.range().0).fold(f32::INFINITY, f32::min);
        let to = groups.iter().map(|g| g.range().1).fold(f32::NEG_INFINITY, f32::max);
        let fps = groups.iter().flat_map(|g| g.tracks()).find_map(|t| a.track(t)).map_or(30.0, |t| t.fps());
        (!groups.is_empty()).then_some(Playback { from, to, fps })
    }

    /// The frame `seconds` into the playback, looping.
    fn frame(&self, seconds: f32) -> f32 {
        let length = (self.to - self.from).max(1e-3);
        self.from + (seconds * self.fps) % length
    }
}

/// Where the demo is after `seconds`: the turn's angle (`turn` radians a second) and, for an
/// animated scene, the animation's frame (the model then holds still).
fn motion(scene: &Scene<'_>, seconds: f32, turn: f32) -> (f32, Option<f32>) {
    match scene.playback {
        Some(p) => (0.0, Some(p.frame(seconds))),
        None => (seconds * turn, None),
    }
}

/// What the user can change while the demo runs.
struct Settings {
    look: Look,
    opts: RenderOptions,
    band_rows: u16,
}

/// The band buffers, allocated once and reused for every band of every frame: firmware would
/// use two static arrays of `WIDTH * 48`. `rows` is the tallest band they will serve.
struct BandBuffers {
    color: Vec<Rgb565>,
    depth: Vec<u16>,
}

impl BandBuffers {
    fn new(rows: u16) -> Self {
        let n = WIDTH as usize * rows as usize;
        BandBuffers { color: vec![BACKGROUND; n], depth: vec![u16::MAX; n] }
    }
}

/// The overlay: a few lines of text, formatted without allocating, drawn into every band.
struct Hud {
    lines: [heapless::String<40>; 3],
    help: Option<&'static str>,
}

impl Hud {
    /// The overlay for a frame, from the previous frame's time and statistics.
    fn new(frame_time: Option<Duration>, stats: &Stats, triangles: u32, s: &Settings, help: bool) -> Self {
        let mut lines: [heapless::String<40>; 3] = Default::default();
        // A line that does not fit in 40 characters is cut short: ignore the error.
        let _ = match frame_time {
            Some(t) => {
                let ms = t.as_secs_f64() * 1e3;
                write!(lines[0], "{ms:.2} ms/frame  {:.0} fps", 1e3 / ms.max(1e-3))
            }
            None => write!(lines[0], "-- ms/frame"),
        };
        let rows = s.band_rows;
        let _ = write!(
            lines[1],
            "{} {} {}x{rows}{}{}",
            s.look.name(),
            if s.opts.filter == Filter::Bilinear { "bilinear" } else { "nearest" },
            HEIGHT.div_ceil(rows),
            if s.opts.dither { " dither" } else { "" },
            if s.opts.textures { "" } else { " notex" },
        );
        let _ = write!(lines[2], "px {}  zrej {}  tris {triangles}", stats.pixels_written, stats.depth_rejected);
        Hud { lines, help: help.then_some("1-4 shade 5 wire 6 pts 7 f b d t spc q") }
    }

    /// Draws the overlay in frame coordinates; a band keeps only the pixels inside it.
    fn draw<T: DrawTarget<Color = Rgb565>>(&self, target: &mut T) -> Result<(), T::Error> {
        let style = MonoTextStyleBuilder::new()
            .font(&FONT_6X10)
            .text_color(Rgb565::WHITE)
            .background_color(Rgb565::BLACK)
            .build();
        for (i, line) in self.lines.iter().enumerate() {
            Text::with_baseline(line, Point::new(2, 2 + 10 * i as i32), style, Baseline::Top).draw(target)?;
        }
        if let Some(help) = self.help {
            let style = MonoTextStyleBuilder::new().font(&FONT_6X10).text_color(Rgb565::YELLOW).build();
            Text::with_baseline(help, Point::new(2, HEIGHT as i32 - 2), style, Baseline::Bottom).draw(target)?;
        }
        Ok(())
    }
}

/// Renders one frame band by band onto `display`, as firmware does: for each band of
/// `band_rows` rows, clear it, draw the model turned by `angle` about y, draw the HUD over it,
/// and send it to the display. Only the two band buffers are ever written.
fn render_frame<T: DrawTarget<Color = Rgb565>>(
    display: &mut T,
    buffers: &mut BandBuffers,
    scene: &Scene<'_>,
    (angle, frame): (f32, Option<f32>),
    settings: &Settings,
    hud: &Hud,
) -> Result<Stats, T::Error> {
    let band_rows = settings.band_rows;
    // The pose, once a frame, in memory sized by the model (every band draws the same).
    let animation = scene.model.animation().filter(|_| frame.is_some());
    let sizes = animation.map(|a| soft3d::animation::pose_memory(a.node_count(), a.palette_count(), a.weight_count()));
    let (nodes, weights) = sizes.unwrap_or((0, 0));
    let (mut node_memory, mut weight_memory) = (vec![Mat4::IDENTITY; nodes], vec![0.0f32; weights]);
    let mut pose = soft3d::animation::Pose::new(&mut node_memory, &mut weight_memory);
    if let (Some(a), Some(f)) = (animation, frame) {
        pose.evaluate(&a, f, None).expect("memory sized by pose_memory");
    }
    let (camera, lights) = posed_view(scene, &pose);
    let transform = if scene.pivot == Vec3::ZERO {
        Mat4::from_rotation_y(angle)
    } else {
        Mat4::from_translation(scene.pivot) * Mat4::from_rotation_y(angle) * Mat4::from_translation(-scene.pivot)
    };
    let mut stats = Stats::default();
    let mut first_row = 0;
    while first_row < HEIGHT {
        let rows = band_rows.min(HEIGHT - first_row);
        let n = WIDTH as usize * rows as usize;
        let mut band = Band::new(&mut buffers.color[..n], &mut buffers.depth[..n], WIDTH, HEIGHT, first_row)
            .expect("the band buffers hold the tallest band");
        band.clear(BACKGROUND);
        stats += soft3d::Renderer::new(&camera, &lights, settings.opts)
            .draw_posed(&mut band, &scene.model, &pose, transform, &mut soft3d::Scratch::none())
            .unwrap();
        // `Band` is a DrawTarget in frame coordinates, and drawing into it cannot fail.
        let Ok(()) = hud.draw(&mut band);
        soft3d::present(&band, display)?;
        first_row += rows;
    }
    Ok(stats)
}

/// The scene's camera and lights at `pose`: where its tracks put them (the demo's own camera
/// stays), as they are when the pose is not set.
fn posed_view(scene: &Scene<'_>, pose: &soft3d::animation::Pose<'_>) -> (Camera, Lights<4>) {
    let mut lights = Lights::from_model_posed(&scene.model, pose);
    lights.ambient = scene.lights.ambient;
    let still = scene.model.camera().filter(|_| scene.own_camera);
    let posed = still.zip(scene.model.animation()).map(|(c, a)| pose.camera(&a, c));
    // A degenerate camera at some frame keeps the still one.
    let camera = posed.and_then(|c| Camera::from_scene(&c, WIDTH as f32 / HEIGHT as f32).ok());
    (camera.unwrap_or(scene.camera), lights)
}

fn main() -> ExitCode {
    match run(&Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("simulator: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<(), String> {
    let default_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/suzanne/monkey.babylon");
    let path = args.scene.clone().unwrap_or(default_path);
    // The tutorial's monkey.babylon counts v from the top of Suzanne.jpg: read as Babylon.js
    // does (from the bottom) the texture lands upside down and the eyes end up on the skull.
    let uv_origin = match args.uv_origin {
        Some(Origin::Top) => UvOrigin::Top,
        Some(Origin::Bottom) => UvOrigin::Bottom,
        None if args.scene.is_none() => UvOrigin::Top,
        None => UvOrigin::Bottom,
    };
    let bytes = load(&path, uv_origin)?;
    let model = Model::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    let tutorial = args.scene.is_none();
    // Suzanne sits at the origin; other scenes turn about the centre of their bounds.
    let pivot = if tutorial { Vec3::ZERO } else { model.bounds().map_or(Vec3::ZERO, |(c, _)| c) };
    let playback = Playback::of(&model);
    let own_camera = !tutorial && !args.fit && model.camera().is_some();
    let camera = camera(&model, tutorial, args.fit)?;
    let scene = Scene { camera, own_camera, lights: lights(&model), pivot, model, playback };
    // The scene's own fog, as Babylon.js draws it.
    let mut opts = RenderOptions { dither: args.dither, fog: scene.model.fog(), ..RenderOptions::default() };
    opts.filter = if args.bilinear { Filter::Bilinear } else { Filter::Nearest };
    args.look.apply(&mut opts);
    let settings = Settings { look: args.look, opts, band_rows: args.band_rows };
    println!("{}: {} triangles", path.display(), triangles(&scene.model));

    if args.headless {
        return run_headless(&scene, settings, args);
    }
    #[cfg(feature = "window")]
    if display_available() {
        return run_window(&scene, settings, args.seconds);
    }
    #[cfg(feature = "window")]
    println!("no display (DISPLAY / WAYLAND_DISPLAY unset): rendering headless");
    #[cfg(not(feature = "window"))]
    println!("built without the `window` feature: rendering headless (add `--features window` for a window)");
    run_headless(&scene, settings, args)
}

/// The scene as `.s3d` bytes: an `.s3d` file as it is, a `.babylon` converted in memory exactly
/// as `soft3d convert` would (RGB565 textures, quantized positions).
fn load(path: &Path, uv_origin: UvOrigin) -> Result<Vec<u8>, String> {
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("s3d")) {
        return std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()));
    }
    let opts = ConvertOptions { uv_origin, ..ConvertOptions::default() };
    let (scene, warnings) = read_babylon_file(path, &opts).map_err(|e| e.to_string())?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    emit(&scene, &EmitOptions::default()).map_err(|e| format!("{}: {e}", path.display()))
}

fn triangles(model: &Model<'_>) -> u32 {
    model.draws().map(|(m, _)| m.triangle_count()).sum()
}

/// The camera. monkey.babylon's own camera stands at (4.1, 1.4, -4.8) aimed at a point one unit
/// above the head: on a 240x240 display Suzanne comes out small, in the lower left corner, seen
/// from the side. The tutorial's final demo looks at her face on, so for her we use a camera at
/// (0, 0, -4) looking at the origin with a 0.8 rad field of view: she fills about two thirds of
/// the screen and stays inside it at every angle. Other scenes use their own camera, or (with
/// `--fit`, or when they have none) one that frames their bounding spheres.
fn camera(model: &Model<'_>, tutorial_scene: bool, fit: bool) -> Result<Camera, String> {
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let camera = match model.camera() {
        _ if tutorial_scene && !fit => {
            Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, aspect, 0.1, 100.0)
        }
        Some(c) if !fit => Camera::from_scene(&c, aspect),
        _ => {
            let (eye, target, far) = framing(model);
            Camera::perspective(eye, target, 0.8, aspect, 0.01, far)
        }
    };
    camera.map_err(|e| e.to_string())
}

/// Eye, target and far distance for a camera showing the whole model at every angle of a turn
/// about its centre.
fn framing(model: &Model<'_>) -> (Vec3, Vec3, f32) {
    match model.bounds() {
        Some((centre, radius)) => {
            (centre + Vec3::new(0.0, 0.3, -1.0).normalize() * radius * 2.6, centre, radius * 10.0)
        }
        None => (Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, 100.0),
    }
}

/// The scene's own lights plus some ambient light. monkey.babylon has a single point light at
/// (4.1, 5.9, 1.0): above, to the right of and slightly behind Suzanne's face (she looks along
/// -z, towards the camera), so facing us her face only gets grazing light and renders nearly
/// black, and the back of her head is unlit for half of every turn. 0.2 of ambient keeps the
/// texture readable all the way round while the point light still models the shape.
fn lights(model: &Model<'_>) -> Lights<4> {
    let mut lights = Lights::from_model(model);
    lights.ambient = Vec3::splat(0.2);
    lights
}

/// Whether an SDL window can be opened: on X11/Wayland systems only with a display server.
#[cfg(feature = "window")]
fn display_available() -> bool {
    if cfg!(any(target_os = "macos", target_os = "windows")) {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Renders `--frames` frames of one turn through [`render_frame`] into a `SimulatorDisplay`,
/// writes each as `frame-NNN.png` (scaled 2x) and all of them as `rotation.gif`.
fn run_headless(scene: &Scene<'_>, settings: Settings, args: &Args) -> Result<(), String> {
    if args.seconds.is_some() {
        eprintln!("note: --seconds only applies to the window");
    }
    let frames = args.frames.max(1);
    let out = &args.out;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let output_settings = OutputSettingsBuilder::new().scale(2).build();
    let mut display = SimulatorDisplay::<Rgb565>::new(Size::new(WIDTH as u32, HEIGHT as u32));
    let mut buffers = BandBuffers::new(settings.band_rows);
    let triangles = triangles(&scene.model);

    // A first frame, not saved, so that frame 0 shows a measured time like all the others.
    let hud = Hud::new(None, &Stats::default(), triangles, &settings, false);
    let start = Instant::now();
    let Ok(mut stats) = render_frame(&mut display, &mut buffers, scene, motion(scene, 0.0, 0.0), &settings, &hud);
    let mut last = start.elapsed();

    let mut gif = Vec::new();
    let mut times = Vec::with_capacity(frames as usize);
    {
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(&mut gif, 10);
        encoder.set_repeat(image::codecs::gif::Repeat::Infinite).map_err(|e| e.to_string())?;
        for k in 0..frames {
            // One turn in `frames` frames of the GIF's delay, or the animation at its rate.
            let seconds = (k * GIF_DELAY_MS) as f32 / 1e3;
            let turn = std::f32::consts::TAU / (frames * GIF_DELAY_MS) as f32 * 1e3;
            let hud = Hud::new(Some(last), &stats, triangles, &settings, false);
            let start = Instant::now();
            let Ok(s) = render_frame(&mut display, &mut buffers, scene, motion(scene, seconds, turn), &settings, &hud);
            last = start.elapsed();
            stats = s;
            times.push(last);

            let image = display.to_rgb_output_image(&output_settings);
            let path = out.join(format!("frame-{k:03}.png"));
            let tmp = path.with_extension("png.tmp");
            image
                .save_png(&tmp)
                .map_err(|e| e.to_string())
                .and_then(|()| std::fs::rename(&tmp, &path).map_err(|e| e.to_string()))
                .map_err(|e| format!("{}: {e}", path.display()))?;
            let rgba: image::RgbaImage = image::buffer::ConvertBuffer::convert(&image.as_image_buffer());
            let delay = image::Delay::from_numer_denom_ms(GIF_DELAY_MS, 1);
            encoder.encode_frame(image::Frame::from_parts(rgba, 0, 0, delay)).map_err(|e| e.to_string())?;
        }
    }
    let gif_path = out.join("rotation.gif");
    let tmp = out.join("rotation.gif.tmp");
    std::fs::write(&tmp, &gif)
        .and_then(|()| std::fs::rename(&tmp, &gif_path))
        .map_err(|e| format!("{}: {e}", gif_path.display()))?;

    let total: Duration = times.iter().sum();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "{}/frame-000.png .. frame-{:03}.png: {frames} frames, {}x{} scaled 2x",
        out.display(),
        frames - 1,
        WIDTH,
        HEIGHT
    );
    println!("{}: {} bytes", gif_path.display(), gif.len());
    println!(
        "frame time ({} bands of {} rows, {}): average {:.2} ms, min {:.2} ms, max {:.2} ms",
        HEIGHT.div_ceil(settings.band_rows),
        settings.band_rows,
        settings.look.name(),
        ms(total) / frames as f64,
        times.iter().map(|&t| ms(t)).fold(f64::INFINITY, f64::min),
        times.iter().map(|&t| ms(t)).fold(0.0, f64::max),
    );
    Ok(())
}

/// The interactive demo: the same [`render_frame`] into a `SimulatorDisplay` shown in an SDL
/// window scaled 2x, turning at the GIF's speed, with the keys listed at the top of this file.
#[cfg(feature = "window")]
fn run_window(scene: &Scene<'_>, mut settings: Settings, seconds: Option<f32>) -> Result<(), String> {
    use embedded_graphics_simulator::sdl2::Keycode;
    use embedded_graphics_simulator::{SimulatorEvent, Window};

    let mut window = Window::new("soft3d", &OutputSettingsBuilder::new().scale(2).build());
    let mut display = SimulatorDisplay::<Rgb565>::new(Size::new(WIDTH as u32, HEIGHT as u32));
    // The `b` key can pick any band height up to the whole frame.
    let mut buffers = BandBuffers::new(HEIGHT);
    let triangles = triangles(&scene.model);
    // One turn in 36 frames of the GIF's delay.
    let speed = std::f32::consts::TAU / (36.0 * GIF_DELAY_MS as f32 / 1e3);
    // Seconds played (paused time left out): the turn's angle or the animation's frame.
    let (mut played, mut paused) = (0.0f32, false);
    let mut smoothed: Option<f64> = None;
    let mut stats = Stats::default();
    let (mut frames, mut total) = (0u32, Duration::ZERO);
    let began = Instant::now();
    let mut tick = Instant::now();
    loop {
        let hud = Hud::new(smoothed.map(Duration::from_secs_f64), &stats, triangles, &settings, true);
        let start = Instant::now();
        let Ok(s) = render_frame(&mut display, &mut buffers, scene, motion(scene, played, speed), &settings, &hud);
        let took = start.elapsed();
        stats = s;
        frames += 1;
        total += took;
        // Smoothed over about 10 frames so that the number can be read.
        smoothed = Some(smoothed.map_or(took.as_secs_f64(), |m| m * 0.9 + took.as_secs_f64() * 0.1));
        window.update(&display);

        let mut quit = seconds.is_some_and(|s| began.elapsed().as_secs_f32() >= s);
        for event in window.events() {
            match event {
                SimulatorEvent::Quit => quit = true,
                SimulatorEvent::KeyDown { keycode, repeat: false, .. } => {
                    let look = match keycode {
                        Keycode::NUM_1 => Some(Look::Unlit),
                        Keycode::NUM_2 => Some(Look::Flat),
                        Keycode::NUM_3 => Some(Look::Gouraud),
                        Keycode::NUM_4 => Some(Look::Phong),
                        Keycode::NUM_5 => Some(Look::Wireframe),
                        Keycode::NUM_6 => Some(Look::Points),
                        Keycode::NUM_7 => Some(Look::SolidWire),
                        _ => None,
                    };
                    if let Some(look) = look {
                        settings.look = look;
                        look.apply(&mut settings.opts);
                    }
                    match keycode {
                        Keycode::ESCAPE | Keycode::Q => quit = true,
                        Keycode::SPACE => paused = !paused,
                        Keycode::F => {
                            settings.opts.filter = match settings.opts.filter {
                                Filter::Nearest => Filter::Bilinear,
                                Filter::Bilinear => Filter::Nearest,
                            }
                        }
                        Keycode::B => {
                            let next = BAND_HEIGHTS.iter().position(|&h| h == settings.band_rows).map_or(0, |i| i + 1);
                            settings.band_rows = BAND_HEIGHTS[next % BAND_HEIGHTS.len()];
                            smoothed = None;
                        }
                        Keycode::D => settings.opts.dither = !settings.opts.dither,
                        Keycode::T => settings.opts.textures = !settings.opts.textures,
                        _ => {}
                    }
                }
                _ => {}
            }
        }
        if quit {
            break;
        }
        let now = Instant::now();
        if !paused {
            // Wrapped at a whole number of turns (and of animation loops, nearly): no drift.
            played = (played + (now - tick).as_secs_f32()) % 3600.0;
        }
        tick = now;
    }
    if frames > 0 {
        println!("{frames} frames, average render time {:.2} ms", total.as_secs_f64() * 1e3 / frames as f64);
    }
    Ok(())
}
