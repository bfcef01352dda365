//! `soft3d`: convert `.babylon` scenes to `.s3d`, inspect them, and render them to PNG/GIF.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888};
use soft3d::convert::{emit, EmitOptions, TextureChoice};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::math::Vec3;
use soft3d::DepthBuffer;
use soft3d::TextureFormat;
use soft3d::{
    Band, Camera, DrawOrder, Filter, FrameColor, Lights, Mode, Model, NoDepth, RenderOptions, Rgb565Be, Scratch,
    Shading, SortEntry, Stats, MAX_DIMENSION,
};

#[derive(Parser)]
#[command(name = "soft3d", version, about = "Convert, inspect and render 3D scenes for soft3d")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Convert a .babylon scene into an .s3d file.
    Convert {
        /// The .babylon file.
        input: PathBuf,
        /// Where to write the .s3d file.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        conv: ConvertArgs,
    },
    /// Print what an .s3d (or .babylon) file holds.
    Info {
        /// The file.
        input: PathBuf,
        #[command(flatten)]
        conv: ConvertArgs,
    },
    /// Render a scene (.babylon or .s3d) to a PNG, a raw framebuffer or an animated GIF.
    Render(Box<RenderArgs>),
}

#[derive(Args, Clone)]
struct ConvertArgs {
    /// Where uv (0,0) is in the image: bottom (Babylon.js) or top (the 2013 tutorial's Suzanne).
    #[arg(long, value_enum, default_value_t = Origin::Bottom)]
    uv_origin: Origin,
    /// Downscale textures so that neither side exceeds N texels (N at least 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    max_texture: Option<u32>,
    /// Resize textures to power-of-two sizes.
    #[arg(long)]
    pow2: bool,
    /// Store exact f32 positions instead of quantized 16-bit ones.
    #[arg(long)]
    float_positions: bool,
    /// Texel storage: auto = rgb565, or rgba5551 when the texture has transparency.
    #[arg(long, value_enum, default_value_t = TexFormat::Auto)]
    texture_format: TexFormat,
}

#[derive(Clone, Copy, ValueEnum)]
enum Origin {
    Bottom,
    Top,
}

#[derive(Clone, Copy, ValueEnum)]
enum TexFormat {
    Auto,
    Rgb565,
    Rgba5551,
    Rgb888,
    Rgba8888,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum StatsFormat {
    Text,
    Json,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum DepthKind {
    U16,
    F32,
    None,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum PixelFormat {
    /// RGB565, little-endian in a raw file (as a Cortex-M or RISC-V framebuffer holds it).
    Rgb565,
    /// RGB565 big-endian (what ST7789 and ILI9341 displays take, and embedded-graphics'
    /// `ImageRaw<Rgb565>` reads).
    #[value(name = "rgb565be")]
    Rgb565Be,
    Rgb888,
    Gray8,
    Mono,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum CameraKind {
    Perspective,
    /// Orthographic, showing --ortho-height world units from the bottom of the frame to the top.
    Ortho,
}

#[derive(Clone, Copy, ValueEnum)]
enum ModeArg {
    Solid,
    Wire,
    Points,
    /// Solid with the triangle edges drawn over it.
    SolidWire,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum ShadingArg {
    Unlit,
    Flat,
    Gouraud,
    Phong,
}

#[derive(Clone, Copy, ValueEnum)]
enum FilterArg {
    Nearest,
    Bilinear,
}

#[derive(Args, Clone)]
struct RenderArgs {
    /// The scene (.babylon is converted in memory).
    input: PathBuf,
    /// Output file, by its extension: .png (a PNG picture), .raw or .bin (the framebuffer's
    /// bytes, row by row, in --format's layout; mono: 1 bit a pixel, rows padded to a byte,
    /// most significant bit first) or .gif (the turntable animation of --frames frames).
    #[arg(short, long)]
    output: PathBuf,
    /// Frame size WxH, each in 1..=1536.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Camera position x,y,z (default: the scene's camera, or one framing the scene).
    #[arg(long, allow_hyphen_values = true)]
    eye: Option<String>,
    /// Camera target x,y,z.
    #[arg(long, allow_hyphen_values = true)]
    target: Option<String>,
    /// The direction x,y,z that points up on screen (default 0,1,0; the scene camera's own is
    /// not read): for a camera looking straight up or down, or a tilted horizon.
    #[arg(long, allow_hyphen_values = true)]
    up: Option<String>,
    /// Move the camera along its view direction (and sideways) until the whole model fills 95%
    /// of the frame's height or width, with near and far fitted to it: what a scene without a
    /// camera gets.
    #[arg(long)]
    fit: bool,
    /// The projection.
    #[arg(long, value_enum, default_value_t = CameraKind::Perspective)]
    camera: CameraKind,
    /// --camera ortho: the world units the frame shows from bottom to top (default: the
    /// diameter of the scene's bounding sphere); the width follows from the frame's aspect.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_positive)]
    ortho_height: Option<f32>,
    /// Vertical field of view in radians, in (0, pi) (default: the scene camera's, else 0.8).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_fov)]
    fov: Option<f32>,
    /// Near clip distance, above 0.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_positive)]
    near: Option<f32>,
    /// Far clip distance, beyond the near one.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_positive)]
    far: Option<f32>,
    /// What to draw.
    #[arg(long, value_enum, default_value_t = ModeArg::Solid)]
    mode: ModeArg,
    /// Depth buffer (none: triangles drawn back to front, the painter's algorithm).
    #[arg(long, value_enum, default_value_t = DepthKind::U16)]
    depth: DepthKind,
    /// Render in N horizontal bands, in 1..=the frame's height (default: four a thread).
    #[arg(long)]
    bands: Option<u16>,
    /// Threads drawing the bands (default: one a core); the picture is the same for every
    /// count.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=256))]
    threads: Option<u16>,
    /// Background colour r,g,b (0-255).
    #[arg(long, default_value = "32,32,48")]
    background: String,
    /// Lighting.
    #[arg(long, value_enum, default_value_t = ShadingArg::Gouraud)]
    shading: ShadingArg,
    /// Texture filter.
    #[arg(long, value_enum, default_value_t = FilterArg::Nearest)]
    filter: FilterArg,
    /// A light, dir:x,y,z or point:x,y,z (repeatable; default: the scene's lights).
    #[arg(long, allow_hyphen_values = true)]
    light: Vec<String>,
    /// Pixel format rendered into (the PNG shows it widened back to 8 bits).
    #[arg(long, value_enum, default_value_t = PixelFormat::Rgb888)]
    format: PixelFormat,
    /// Blinn-Phong specular highlights (per vertex) with this exponent, e.g. 64 (a finite
    /// number above 0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_exponent)]
    specular: Option<f32>,
    /// Transform vertices in integers, as FPU-less microcontrollers do (within 1/16 pixel).
    #[arg(long)]
    fixed_vertices: bool,
    /// Ordered dithering when the pixel format has fewer than 8 bits per channel.
    #[arg(long)]
    dither: bool,
    /// Exact perspective correction every N pixels, N at least 1 (1 = every pixel).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    subspan: u32,
    /// Also write a turntable animation to this GIF.
    #[arg(long)]
    gif: Option<PathBuf>,
    /// Frames of the GIF (at least 1).
    #[arg(long, default_value_t = 36, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// How the statistics are printed: a line of text, or one JSON object a frame (the
    /// firmware's fields that a host render knows, and the time).
    #[arg(long, value_enum, default_value_t = StatsFormat::Text)]
    stats: StatsFormat,
    #[command(flatten)]
    conv: ConvertArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Convert { input, output, conv } => cmd_convert(&input, &output, &conv),
        Command::Info { input, conv } => cmd_info(&input, &conv),
        Command::Render(args) => cmd_render(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("soft3d: {e}");
            ExitCode::FAILURE
        }
    }
}

type Result<T> = std::result::Result<T, String>;

/// Converts a `.babylon` file to `.s3d` bytes, printing the converter's warnings.
fn convert_bytes(input: &Path, conv: &ConvertArgs) -> Result<Vec<u8>> {
    let opts = ConvertOptions {
        uv_origin: match conv.uv_origin {
            Origin::Bottom => UvOrigin::Bottom,
            Origin::Top => UvOrigin::Top,
        },
        max_texture: conv.max_texture,
        power_of_two: conv.pow2,
    };
    let (scene, warnings) = read_babylon_file(input, &opts).map_err(|e| e.to_string())?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    let textures = match conv.texture_format {
        TexFormat::Auto => TextureChoice::Auto,
        TexFormat::Rgb565 => TextureChoice::Fixed(TextureFormat::Rgb565),
        TexFormat::Rgba5551 => TextureChoice::Fixed(TextureFormat::Rgba5551),
        TexFormat::Rgb888 => TextureChoice::Fixed(TextureFormat::Rgb888),
        TexFormat::Rgba8888 => TextureChoice::Fixed(TextureFormat::Rgba8888),
    };
    emit(&scene, &EmitOptions { textures, float_positions: conv.float_positions })
        .map_err(|e| format!("{}: {e}", input.display()))
}

/// Reads a scene: `.s3d` as is, anything else through the converter.
fn load_scene(input: &Path, conv: &ConvertArgs) -> Result<Vec<u8>> {
    if input.extension().is_some_and(|e| e == "s3d") {
        std::fs::read(input).map_err(|e| format!("{}: {e}", input.display()))
    } else {
        convert_bytes(input, conv)
    }
}

/// Writes `bytes` to `path` through a temporary file and a rename, so that a failure never
/// leaves a partial file behind.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    // A rename would replace a device or other special file (`/dev/null`) with a regular one.
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(format!("{}: not a regular file, not overwritten", path.display()));
    }
    let tmp = path.with_extension("tmp-soft3d");
    std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path)).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}

fn cmd_convert(input: &Path, output: &Path, conv: &ConvertArgs) -> Result<()> {
    let bytes = convert_bytes(input, conv)?;
    write_atomically(output, &bytes)?;
    let source = std::fs::metadata(input).map(|m| m.len()).unwrap_or(0);
    println!("{} ({} bytes) -> {} ({} bytes)", input.display(), source, output.display(), bytes.len());
    Ok(())
}

fn cmd_info(input: &Path, conv: &ConvertArgs) -> Result<()> {
    let bytes = load_scene(input, conv)?;
    let model = Model::parse(&bytes).map_err(|e| format!("{}: {e}", input.display()))?;
    // The file's size, and the converted model's where it was converted here.
    let file = std::fs::metadata(input).map(|m| m.len()).map_err(|e| format!("{}: {e}", input.display()))?;
    if file == bytes.len() as u64 && input.extension().is_some_and(|e| e == "s3d") {
        println!("{}: {file} bytes", input.display());
    } else {
        println!("{}: {file} bytes, {} bytes converted", input.display(), bytes.len());
    }
    let (mut tris, mut verts) = (0u64, 0u64);
    for (i, m) in model.meshes().enumerate() {
        let (c, r) = m.bounding_sphere();
        let w = m.world().transform_point3(c);
        println!(
            "  mesh {i} \"{}\": {} vertices, {} triangles, {} sub-meshes{}{}, bounds centre ({:.3}, {:.3}, {:.3}) radius {:.3} (local)",
            m.name(),
            m.vertex_count(),
            m.triangle_count(),
            m.submeshes().count(),
            if m.has_uvs() { ", uvs" } else { "" },
            if m.has_colors() { ", colours" } else { "" },
            w.x,
            w.y,
            w.z,
            r
        );
        tris += m.triangle_count() as u64;
        verts += m.vertex_count() as u64;
    }
    for i in 0..model.instance_count() {
        if let Some((m, world)) = model.instance(i) {
            let t = world.w_axis;
            println!("  instance {i}: mesh {m} at ({:.3}, {:.3}, {:.3})", t.x, t.y, t.z);
        }
    }
    for i in 0..model.material_count() as u16 {
        if let Some(m) = model.material(i) {
            println!(
                "  material {i}: rgba {:?}, {}, texture {:?}, wrap {:?}/{:?}",
                m.rgba,
                if m.cull_back_faces { "back faces culled" } else { "two-sided" },
                m.texture,
                m.wrap_u,
                m.wrap_v
            );
        }
    }
    for i in 0..model.texture_count() as u16 {
        if let Some(t) = model.texture(i) {
            println!("  texture {i}: {}x{} {:?}, {} bytes", t.width, t.height, t.format, t.texels.len());
        }
    }
    for l in model.lights() {
        println!(
            "  light {:?} {:?} diffuse {:?} intensity {}",
            l.kind,
            l.vector.to_array(),
            l.diffuse.to_array(),
            l.intensity
        );
    }
    if let Some(c) = model.camera() {
        println!(
            "  camera at {:?} looking at {:?}, fov {}, near {}, far {}",
            c.position.to_array(),
            c.target.to_array(),
            c.fov,
            c.near,
            c.far
        );
    }
    println!(
        "  total: {} meshes, {} instances, {verts} vertices, {tris} triangles, {} materials, {} textures",
        model.mesh_count(),
        model.instance_count(),
        model.material_count(),
        model.texture_count()
    );
    Ok(())
}

fn parse_vec3(s: &str, what: &str) -> Result<Vec3> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("{what}: expected x,y,z, got {s:?}"))?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("{what}: expected three finite numbers x,y,z, got {s:?}")),
    }
}

fn parse_size(s: &str) -> Result<(u16, u16)> {
    let (w, h) = s.split_once('x').ok_or_else(|| format!("--size: expected WxH, got {s:?}"))?;
    let p = |v: &str| {
        v.parse::<u16>()
            .ok()
            .filter(|n| (1..=MAX_DIMENSION).contains(n))
            .ok_or_else(|| format!("--size: width and height must be whole numbers in 1..={MAX_DIMENSION}, got {s:?}"))
    };
    Ok((p(w)?, p(h)?))
}

/// A distance or size: a finite number above 0.
fn parse_positive(s: &str) -> Result<f32> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| x.is_finite() && *x > 0.0)
        .ok_or_else(|| format!("expected a finite number above 0, got {s:?}"))
}

/// `--fov`: radians in (0, pi).
fn parse_fov(s: &str) -> Result<f32> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| *x > 0.0 && *x < std::f32::consts::PI)
        .ok_or_else(|| format!("expected radians in (0, 3.1416), e.g. 0.8, got {s:?}"))
}

/// `--specular`'s exponent: a finite number above 0.
fn parse_exponent(s: &str) -> Result<f32> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|e| e.is_finite() && *e > 0.0)
        .ok_or_else(|| format!("expected a finite exponent above 0, e.g. 64, got {s:?}"))
}

fn parse_rgb(s: &str) -> Result<[u8; 3]> {
    let v: Vec<u8> = s
        .split(',')
        .map(|p| p.trim().parse::<u8>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("--background: expected r,g,b in 0-255, got {s:?}"))?;
    <[u8; 3]>::try_from(v).map_err(|_| format!("--background: expected three values, got {s:?}"))
}

struct View {
    camera: Camera,
    lights: Lights<8>,
    opts: RenderOptions,
    background: [u8; 3],
    width: u16,
    height: u16,
    bands: u16,
    /// Threads drawing the bands (at most one a band).
    threads: u16,
}

/// How much of the frame's limiting dimension a fitted model fills (see `--fit`).
const FIT_FILL: f32 = 0.95;

/// Near and far planes for an eye at `eye` that take in the whole of `model` (its bounding
/// sphere, with 1% to spare): what `--eye` and `--target` get unless `--near` and `--far` are
/// given.
fn fitted_planes(eye: Vec3, model: &Model<'_>) -> (f32, f32) {
    let (centre, radius) = model.bounds().unwrap_or((Vec3::ZERO, 1.0));
    let (d, r) = (eye.distance(centre), radius * 1.01);
    let far = (d + r).max(1e-3);
    ((d - r).max(far * 1e-3), far)
}

/// The lights of the render: the scene's (at most 8), or `--light`'s in their place, with
/// `--specular`; a warning for each thing left out.
fn scene_lights(args: &RenderArgs, model: &Model<'_>) -> Result<Lights<8>> {
    let mut lights = Lights::<8>::from_model(model);
    if model.light_count() > 8 {
        eprintln!(
            "warning: the scene has {} lights; soft3d draws 8: the last {} are left out",
            model.light_count(),
            model.light_count() - 8
        );
    }
    if !args.light.is_empty() {
        if model.light_count() > 0 {
            eprintln!("warning: --light replaces the scene's {} light(s) and its ambient light", model.light_count());
        }
        lights = Lights::new(Vec3::ZERO);
        for l in &args.light {
            let light = if let Some(v) = l.strip_prefix("dir:") {
                let dir = parse_vec3(v, "--light dir")?;
                if dir == Vec3::ZERO {
                    return Err(format!("--light: a direction must not be zero, got {l:?}"));
                }
                Lights::<8>::directional(dir, 1.0)
            } else if let Some(v) = l.strip_prefix("point:") {
                Lights::<8>::point(parse_vec3(v, "--light point")?, 1.0)
            } else {
                return Err(format!("--light: expected dir:x,y,z or point:x,y,z, got {l:?}"));
            };
            lights.push(light).map_err(|_| "--light: at most 8 lights".to_string())?;
        }
    }
    if let Some(power) = args.specular {
        if args.shading == ShadingArg::Phong {
            eprintln!(
                "warning: --specular is not drawn with --shading phong (its per-pixel light has no specular term)"
            );
        }
        lights.specular = Vec3::ONE;
        lights.shininess = power;
    }
    Ok(lights)
}

fn make_view(args: &RenderArgs, model: &Model<'_>) -> Result<View> {
    let (width, height) = parse_size(&args.size)?;
    if model.draw_counts().0 == 0 {
        return Err(format!("{}: the scene has no triangles to draw", args.input.display()));
    }
    let aspect = width as f32 / height.max(1) as f32;
    let scene_cam = model.camera();
    let fov = args.fov.or(scene_cam.map(|c| c.fov)).unwrap_or(0.8);
    let framing = Camera::framing(model, fov, aspect).map_err(|e| e.to_string())?;
    let (default_eye, default_target) = match &scene_cam {
        Some(c) => (c.position, c.target),
        None => (framing.eye, framing.target),
    };
    let eye = args.eye.as_deref().map(|s| parse_vec3(s, "--eye")).transpose()?.unwrap_or(default_eye);
    let target = args.target.as_deref().map(|s| parse_vec3(s, "--target")).transpose()?.unwrap_or(default_target);
    let up = args.up.as_deref().map(|s| parse_vec3(s, "--up")).transpose()?.unwrap_or(Vec3::Y);
    let moved = args.eye.is_some() || args.target.is_some();
    // `--fit`, or a scene without a camera of its own: closer, along the same direction.
    let fitted = (args.fit || (scene_cam.is_none() && !moved))
        .then(|| Camera::fit(model, (target - eye, up), fov, aspect, FIT_FILL))
        .transpose()
        .map_err(|e| camera_error(e, (eye, target, up)))?;
    let (eye, target) = fitted.map_or((eye, target), |c| (c.eye, c.target));
    // A camera the user moved sees the model from elsewhere: its planes are fitted to it.
    let (default_near, default_far) = match (&fitted, &scene_cam, moved) {
        (Some(c), _, _) => (c.near, c.far),
        (None, _, true) => fitted_planes(eye, model),
        (None, Some(c), false) => (c.near, c.far),
        (None, None, false) => (framing.near, framing.far),
    };
    let far = args.far.unwrap_or(default_far);
    // A near plane beyond the user's far plane would leave nothing: theirs decides.
    let near = args.near.unwrap_or(if default_near < far { default_near } else { far * 1e-3 });
    if near >= far {
        return Err(format!("--far: must be beyond the near plane at {near}, got {far} (--near, --far)"));
    }
    let camera = match args.camera {
        CameraKind::Perspective => Camera::perspective_up((eye, target, up), fov, aspect, near, far),
        CameraKind::Ortho => {
            let diameter = 2.0 * model.bounds().map_or(1.0, |(_, radius)| radius);
            let h = args.ortho_height.unwrap_or(diameter);
            if !(h.is_finite() && h > 0.0) {
                return Err(format!("--ortho-height: the scene's bounds give {h}: give a finite size above 0"));
            }
            Camera::orthographic_up((eye, target, up), h * aspect, h, near, far)
        }
    }
    .map_err(|e| camera_error(e, (eye, target, up)))?;
    let lights = scene_lights(args, model)?;
    let opts = render_options(args);
    let threads = args.threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, |n| u16::try_from(n.get()).unwrap_or(256).min(256))
    });
    let bands = match args.bands {
        Some(b) if b == 0 || b > height => {
            return Err(format!("--bands: must be 1..={height} (the frame's height), got {b}"))
        }
        Some(b) => b,
        // Four a thread: the busy rows of a scene spread over all of them.
        None => threads.saturating_mul(4).min(height),
    };
    let background = parse_rgb(&args.background)?;
    Ok(View { camera, lights, opts, background, width, height, bands, threads: threads.min(bands) })
}

/// The drawing options the arguments ask for.
fn render_options(args: &RenderArgs) -> RenderOptions {
    RenderOptions {
        shading: match args.shading {
            ShadingArg::Unlit => Shading::Unlit,
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Phong => Shading::Phong,
        },
        mode: match args.mode {
            ModeArg::Solid => Mode::Solid,
            ModeArg::Wire => Mode::Wireframe,
            ModeArg::Points => Mode::Points,
            ModeArg::SolidWire => Mode::SolidWireframe,
        },
        filter: match args.filter {
            FilterArg::Nearest => Filter::Nearest,
            FilterArg::Bilinear => Filter::Bilinear,
        },
        subspan: args.subspan,
        textures: true,
        dither: args.dither,
        fixed_vertices: args.fixed_vertices,
        // Without a depth buffer the nearest triangle must be drawn last.
        order: if args.depth == DepthKind::None { DrawOrder::BackToFront } else { DrawOrder::AsStored },
        wire_color: matches!(args.mode, ModeArg::SolidWire).then_some([255, 255, 0]),
    }
}

/// What is wrong with a camera at `eye` looking at `target` with `up`, in the options' words.
fn camera_error(e: soft3d::CameraError, (eye, target, up): (Vec3, Vec3, Vec3)) -> String {
    if e == soft3d::CameraError::BadLookAt && eye != target && up != Vec3::ZERO {
        let along = (target - eye).normalize().cross(up.normalize()).length() < 1e-6;
        if along {
            return format!(
                "camera: it looks along its up direction {:?} (--up, default 0,1,0): give another --up, e.g. --up 0,0,1",
                up.to_array()
            );
        }
    }
    if e == soft3d::CameraError::BadLookAt && up == Vec3::ZERO {
        return "--up: must not be zero".to_string();
    }
    e.to_string()
}

/// A rendered frame: its pixels widened to RGB888 (for PNG and GIF), the framebuffer's own
/// bytes (for raw output, when asked for) and what the draw counted.
struct Frame {
    rgb: Vec<[u8; 3]>,
    raw: Vec<u8>,
    stats: Stats,
}

/// A pixel format the CLI renders into, and how its framebuffer is written to a raw file.
trait RawPixels: FrameColor + Default + Send {
    /// `pixels`, rows of `width`, as the bytes of a raw file.
    fn raw(pixels: &[Self], width: usize) -> Vec<u8>;
}

impl RawPixels for Rgb888 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().flat_map(|c| c.to_rgb888()).collect()
    }
}

impl RawPixels for Rgb565 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        use embedded_graphics_core::prelude::IntoStorage;
        pixels.iter().flat_map(|c| c.into_storage().to_le_bytes()).collect()
    }
}

impl RawPixels for Rgb565Be {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().flat_map(|c| c.0).collect()
    }
}

impl RawPixels for Gray8 {
    fn raw(pixels: &[Self], _: usize) -> Vec<u8> {
        pixels.iter().map(|c| c.to_rgb888()[0]).collect()
    }
}

impl RawPixels for BinaryColor {
    fn raw(pixels: &[Self], width: usize) -> Vec<u8> {
        let mut out = Vec::with_capacity(pixels.len().div_ceil(8));
        for row in pixels.chunks(width) {
            out.extend(
                row.chunks(8)
                    .map(|byte| byte.iter().enumerate().fold(0u8, |b, (i, c)| b | (u8::from(c.is_on()) << (7 - i)))),
            );
        }
        out
    }
}

/// The caller's depth memory for a frame, of the kind `--depth` asks for.
enum Depth {
    U16(Vec<u16>),
    F32(Vec<f32>),
    None,
}

/// One thread's share of a frame: its rows' colour and depth memory.
enum DepthRows<'a> {
    U16(&'a mut [u16]),
    F32(&'a mut [f32]),
    None,
}

impl Depth {
    fn new(kind: DepthKind, pixels: usize) -> Self {
        match kind {
            DepthKind::U16 => Depth::U16(vec![0; pixels]),
            DepthKind::F32 => Depth::F32(vec![0.0; pixels]),
            DepthKind::None => Depth::None,
        }
    }

    /// The depth memory in parts of `part` pixels (the last may be shorter), `parts` of them.
    fn split(&mut self, part: usize, parts: usize) -> Vec<DepthRows<'_>> {
        match self {
            Depth::U16(z) => z.chunks_mut(part).map(DepthRows::U16).collect(),
            Depth::F32(z) => z.chunks_mut(part).map(DepthRows::F32).collect(),
            Depth::None => (0..parts).map(|_| DepthRows::None).collect(),
        }
    }
}

/// One band of a frame: its first row, its colour and depth memory, and its pixels widened.
struct BandRows<'a, C> {
    first_row: u16,
    color: &'a mut [C],
    depth: DepthRows<'a>,
    rgb: &'a mut [[u8; 3]],
}

/// Renders one frame in pixel format `C`, its bands dealt out among the view's threads in turn
/// (band k to thread k mod n: a scene's busy rows are shared), each band drawn whole by one
/// thread, so the picture is the one a single thread draws; the raw bytes only when `raw`.
fn render_frame<C: RawPixels>(
    model: &Model<'_>,
    view: &View,
    spin: f32,
    (depth, raw): (DepthKind, bool),
) -> Result<Frame> {
    let (w, h) = (view.width as usize, view.height as usize);
    let mut color = vec![C::default(); w * h];
    let mut depth = Depth::new(depth, w * h);
    let mut rgb = vec![[0u8; 3]; w * h];
    let band_rows = h.div_ceil(view.bands as usize);
    let band = band_rows * w;
    let depth_parts = depth.split(band, h.div_ceil(band_rows));
    let mut shares: Vec<Vec<BandRows<'_, C>>> = (0..view.threads).map(|_| Vec::new()).collect();
    let bands = color.chunks_mut(band).zip(depth_parts).zip(rgb.chunks_mut(band));
    for (k, ((color, depth), rgb)) in bands.enumerate() {
        let first_row = (k * band_rows) as u16;
        shares[k % view.threads as usize].push(BandRows { first_row, color, depth, rgb });
    }
    let transform = soft3d::testing::math::Mat4::from_rotation_y(spin);
    let results: Vec<Result<Stats>> = std::thread::scope(|scope| {
        let threads: Vec<_> =
            shares.into_iter().map(|share| scope.spawn(move || draw_bands(share, view, (model, transform)))).collect();
        threads.into_iter().map(|t| t.join().unwrap_or_else(|_| Err("a render thread panicked".into()))).collect()
    });
    let mut stats = Stats::default();
    for s in results {
        stats += s?;
    }
    let raw = if raw { C::raw(&color, w) } else { Vec::new() };
    Ok(Frame { rgb, raw, stats })
}

/// Draws `bands` and widens their pixels: one thread's share of [`render_frame`].
fn draw_bands<C: FrameColor>(
    bands: Vec<BandRows<'_, C>>,
    view: &View,
    scene: (&Model<'_>, soft3d::testing::math::Mat4),
) -> Result<Stats> {
    // The back-to-front list, one entry a triangle, when the order needs it; otherwise each
    // triangle's rows and each transformed vertex, so that the thread's bands after its first
    // skip the triangles that miss them and transform no vertex again.
    let (triangles, vertices) = scene.0.draw_counts();
    let sorted = view.opts.order == DrawOrder::BackToFront;
    let mut sort = vec![SortEntry::default(); if sorted { triangles } else { 0 }];
    let mut rows = vec![soft3d::TriangleRows::default(); if sorted { 0 } else { triangles }];
    let mut cache = vec![soft3d::TransformedVertex::default(); if sorted { 0 } else { vertices }];
    let mut scratch = Scratch::none().with_sort(&mut sort).with_rows(&mut rows).with_vertices(&mut cache);
    let bg = C::from_rgb888(view.background);
    let mut stats = Stats::default();
    for b in bands {
        let at = b.first_row;
        stats += match b.depth {
            DepthRows::U16(z) => draw_band((&mut *b.color, z), view, at, scene, bg, &mut scratch)?,
            DepthRows::F32(z) => draw_band((&mut *b.color, z), view, at, scene, bg, &mut scratch)?,
            DepthRows::None => draw_band((&mut *b.color, NoDepth), view, at, scene, bg, &mut scratch)?,
        };
        for (out, c) in b.rgb.iter_mut().zip(b.color.iter()) {
            *out = c.to_rgb888();
        }
    }
    Ok(stats)
}

fn draw_band<C: FrameColor, D: DepthBuffer>(
    (color, depth): (&mut [C], D),
    view: &View,
    first_row: u16,
    (model, transform): (&Model<'_>, soft3d::testing::math::Mat4),
    bg: C,
    scratch: &mut Scratch<'_>,
) -> Result<Stats> {
    let mut band = Band::new(color, depth, view.width, view.height, first_row).map_err(|e| e.to_string())?;
    band.clear(bg);
    soft3d::Renderer::new(&view.camera, &view.lights, view.opts)
        .draw(&mut band, model, transform, scratch)
        .map_err(|e| format!("draw: {e}"))
}

fn render_any(model: &Model<'_>, view: &View, spin: f32, args: &RenderArgs, raw: bool) -> Result<Frame> {
    let how = (args.depth, raw);
    match args.format {
        PixelFormat::Rgb888 => render_frame::<Rgb888>(model, view, spin, how),
        PixelFormat::Rgb565 => render_frame::<Rgb565>(model, view, spin, how),
        PixelFormat::Rgb565Be => render_frame::<Rgb565Be>(model, view, spin, how),
        PixelFormat::Gray8 => render_frame::<Gray8>(model, view, spin, how),
        PixelFormat::Mono => render_frame::<BinaryColor>(model, view, spin, how),
    }
}

/// What `-o` writes, by its extension.
#[derive(Clone, Copy, PartialEq)]
enum OutputKind {
    Png,
    Raw,
    Gif,
}

fn output_kind(path: &Path) -> Result<OutputKind> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(OutputKind::Png),
        Some("raw" | "bin") => Ok(OutputKind::Raw),
        Some("gif") => Ok(OutputKind::Gif),
        _ => Err(format!(
            "-o: name the output *.png (a PNG picture), *.raw or *.bin (the framebuffer's bytes) or *.gif (the turntable), got {:?}",
            path.display()
        )),
    }
}

fn cmd_render(args: &RenderArgs) -> Result<()> {
    // Checked before any work: a picture written under another format's name would mislead.
    let kind = output_kind(&args.output)?;
    let mut conv = args.conv.clone();
    // Keep 8-bit texels when rendering to RGB888 so the output compares exactly with others.
    if args.format == PixelFormat::Rgb888
        && matches!(conv.texture_format, TexFormat::Auto)
        && args.input.extension().is_none_or(|e| e != "s3d")
    {
        conv.texture_format = TexFormat::Rgba8888;
    }
    let bytes = load_scene(&args.input, &conv)?;
    let model = Model::parse(&bytes).map_err(|e| format!("{}: {e}", args.input.display()))?;
    let view = make_view(args, &model)?;
    if kind == OutputKind::Gif {
        return write_gif(&args.output, &model, &view, args);
    }
    let start = std::time::Instant::now();
    let frame = render_any(&model, &view, 0.0, args, kind == OutputKind::Raw)?;
    let elapsed = start.elapsed();
    let bytes = match kind {
        OutputKind::Raw => frame.raw,
        _ => encode_png(&frame.rgb, view.width, view.height)?,
    };
    write_atomically(&args.output, &bytes)?;
    let ms = elapsed.as_secs_f64() * 1e3;
    let stats = frame.stats;
    match args.stats {
        StatsFormat::Text => {
            println!(
                "{}: {}x{} in {ms:.2} ms ({} bands, {} threads), {stats:?}",
                args.output.display(),
                view.width,
                view.height,
                view.bands,
                view.threads
            );
        }
        StatsFormat::Json => println!("{}", stats_json(1, &view, (&model, &stats), ms)),
    }
    if let Some(gif) = &args.gif {
        write_gif(gif, &model, &view, args)?;
    }
    Ok(())
}

fn encode_png(rgb: &[[u8; 3]], w: u16, h: u16) -> Result<Vec<u8>> {
    let flat: Vec<u8> = rgb.iter().flatten().copied().collect();
    let img = image::RgbImage::from_raw(w as u32, h as u32, flat).ok_or("image size mismatch")?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// One frame's statistics as a JSON object: the fields of the firmware's line (examples/qemu)
/// that a host render knows, and the time it took.
fn stats_json(frame: u32, view: &View, (model, stats): (&Model<'_>, &Stats), ms: f64) -> String {
    serde_json::json!({
        "frame": frame,
        "width": view.width,
        "height": view.height,
        "bands": view.bands,
        "threads": view.threads,
        "triangles": model.draw_counts().0,
        "drawn": stats.drawn,
        "pixels_written": stats.pixels_written,
        "runs": stats.runs,
        "depth_rejected": stats.depth_rejected,
        "culled_back_face": stats.culled_back_face,
        "culled_frustum": stats.culled_frustum + stats.culled_frustum_mesh,
        "clipped": stats.clipped,
        "ms": ms,
    })
    .to_string()
}

fn write_gif(path: &Path, model: &Model<'_>, view: &View, args: &RenderArgs) -> Result<()> {
    let mut out = Vec::new();
    {
        let mut enc = image::codecs::gif::GifEncoder::new_with_speed(&mut out, 10);
        enc.set_repeat(image::codecs::gif::Repeat::Infinite).map_err(|e| e.to_string())?;
        let frames = args.frames;
        for f in 0..frames {
            let spin = f as f32 / frames as f32 * std::f32::consts::TAU;
            let start = std::time::Instant::now();
            let frame = render_any(model, view, spin, args, false)?;
            if args.stats == StatsFormat::Json {
                println!("{}", stats_json(f + 1, view, (model, &frame.stats), start.elapsed().as_secs_f64() * 1e3));
            }
            let rgba: Vec<u8> = frame.rgb.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect();
            let img =
                image::RgbaImage::from_raw(view.width as u32, view.height as u32, rgba).ok_or("image size mismatch")?;
            let frame = image::Frame::from_parts(img, 0, 0, image::Delay::from_numer_denom_ms(50, 1));
            enc.encode_frame(frame).map_err(|e| e.to_string())?;
        }
    }
    write_atomically(path, &out)?;
    println!("{}: {} frames", path.display(), args.frames);
    Ok(())
}
