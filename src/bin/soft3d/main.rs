//! `soft3d`: convert `.babylon` scenes to `.s3d`, inspect them, and render them to PNG/GIF.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888};
use soft3d::animation::{pose_memory, Pose};
use soft3d::convert::{emit, EmitOptions, TextureChoice};
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};
use soft3d::testing::math::{Mat4, Vec3};
use soft3d::TextureFormat;
use soft3d::{
    Band, Camera, DrawOrder, Filter, FrameColor, Lights, Mode, Model, NoDepth, RenderOptions, Rgb565Be, Scratch,
    Shading, SortEntry, Stats, MAX_DIMENSION,
};
use soft3d::{DepthBuffer, Fog, FogMode};

mod info;
mod output;
mod render;
mod view;

use output::*;
use render::*;
use view::*;

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
    /// of the frame's height or width, with near and far fitted to it (--camera ortho: centre it
    /// and size the view so): what a scene without a camera gets.
    #[arg(long)]
    fit: bool,
    /// The projection.
    #[arg(long, value_enum, default_value_t = CameraKind::Perspective)]
    camera: CameraKind,
    /// --camera ortho: the world units the frame shows from bottom to top, above 0 (default:
    /// fitted with --fit or for a scene without a camera, else the diameter of the scene's
    /// bounding sphere); the width follows from the frame's aspect.
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
    /// Threads drawing the bands, in 1..=256 (default: one a core); the picture is the same
    /// for every count.
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
    /// A white light of intensity 1, dir:x,y,z (a direction, not zero) or point:x,y,z (a
    /// position); repeatable, at most 8. Given, they replace the scene's lights and ambient
    /// (default: the scene's lights, at most 8).
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
    /// Fog instead of the scene's own (default: the scene's, none without): off,
    /// exp:DENSITY, exp2:DENSITY or linear:START,END (distances from the camera), as
    /// Babylon.js's fogMode computes it per pixel.
    #[arg(long)]
    fog: Option<String>,
    /// Fog colour r,g,b (0-255; default: the scene's, else Babylon.js's 51,51,77).
    #[arg(long)]
    fog_color: Option<String>,
    /// Pose the scene's animations at this frame (every group at once, or --animation's), as
    /// Babylon.js's `goToFrame` does; without it the scene is drawn as it stands.
    #[arg(long, allow_hyphen_values = true)]
    frame: Option<f32>,
    /// The animation group to pose with --frame (by name; `soft3d info` lists them).
    #[arg(long)]
    animation: Option<String>,
    /// Also write a turntable animation to this GIF.
    #[arg(long)]
    gif: Option<PathBuf>,
    /// Frames of a turntable GIF (at least 1); a scene with animations plays every frame of
    /// its range instead (--animation's group, else all), at its frame rate.
    #[arg(long, default_value_t = 36, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// How the statistics are printed: a line of text, or one JSON object a frame (the
    /// firmware's fields that a host render knows, summed over the bands: `drawn` counts a
    /// triangle once for each band it has pixels in; and the time).
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
    info::print_animation(&model);
    info::print_lights_fog_camera(&model);
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

/// A number `s` that `ok` accepts, else a message saying what was `expected` and what came.
fn parse_number(s: &str, ok: impl Fn(f32) -> bool, expected: &str) -> Result<f32> {
    s.trim().parse::<f32>().ok().filter(|&x| ok(x)).ok_or_else(|| format!("expected {expected}, got {s:?}"))
}

/// A distance or size: a finite number above 0.
fn parse_positive(s: &str) -> Result<f32> {
    parse_number(s, |x| x.is_finite() && x > 0.0, "a finite number above 0")
}

/// `--fov`: radians in (0, pi).
fn parse_fov(s: &str) -> Result<f32> {
    parse_number(s, |x| x > 0.0 && x < std::f32::consts::PI, "radians in (0, 3.1416), e.g. 0.8")
}

/// `--specular`'s exponent: a finite number above 0.
fn parse_exponent(s: &str) -> Result<f32> {
    parse_number(s, |x| x.is_finite() && x > 0.0, "a finite exponent above 0, e.g. 64")
}

/// A colour r,g,b in 0-255, given to option `what`.
fn parse_rgb(s: &str, what: &str) -> Result<[u8; 3]> {
    let v: Vec<u8> = s
        .split(',')
        .map(|p| p.trim().parse::<u8>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("{what}: expected r,g,b in 0-255, got {s:?}"))?;
    <[u8; 3]>::try_from(v).map_err(|_| format!("{what}: expected three values, got {s:?}"))
}
