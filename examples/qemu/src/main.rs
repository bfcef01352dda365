//! soft3d on an emulated Cortex-M (or riscv32imc): renders the reference "Suzanne frame" (240x240 RGB565) in
//! horizontal bands, writes it to the host through semihosting and prints its statistics as
//! one JSON line, then exits with status 0 (non-zero on any failure).
//!
//! ```text
//! cd examples/qemu && mkdir -p out && cargo run --release                       # Cortex-M4F, mps2-an386
//! cd examples/qemu && mkdir -p out && cargo run --release --target thumbv6m-none-eabi  # on mps2-an385 (M3)
//! cd examples/qemu && mkdir -p out && cargo run --release --target riscv32imc-unknown-none-elf  # QEMU virt
//! ```
//!
//! Features: `two-frames` renders the frame twice (per-frame instruction count =
//! count(2 frames) - count(1 frame)); `one-band` renders one 240x240 band instead of eight
//! 240x30 ones; `rabbit` renders, instead of the Suzanne frame, the animated rabbit
//! (`../shared/assets/rabbit`, converted by build.rs) posed at frame 50 of its skeleton's
//! animation with `Renderer::draw_posed`, lit by one directional light (tests/qemu_frame.rs
//! renders the same frame on the host).
//!
//! Buffers: one colour and one depth band and the scratch's rows and vertices live in
//! `.bss`/`.data`, handed out once as `&'static mut`: by `#[entry]`'s `static mut` items on
//! Cortex-M (initialised before `main`, never built on the stack), by `riscv::singleton!` on
//! riscv32. They count as static RAM and stay out of the stack figure.
//!
//! Stack: cortex-m-rt's `paint-stack` feature fills `_stack_end.._stack_start` (everything
//! above the statics) with `0xCCCC_CCCC` before `main`; after the frame the lowest word that
//! no longer holds the pattern gives the high-water mark of the whole firmware. For the core
//! alone, in the first frame, the free stack below the caller's frame is painted again right
//! before each band's draw call and scanned right after it: the lowest touched word, measured
//! from the stack pointer at the call, gives the renderer's own use: all of it with the
//! `stack-probe` feature, which keeps the draw out of line (without it, LTO inlines the draw's
//! top levels, its context and the mesh's set-up, into `run`'s frame, above that stack pointer,
//! and the figure leaves them out). Cortex-M only: on riscv32 (riscv-rt does not paint the
//! stack) both stack figures are reported as 0.
#![no_std]
#![no_main]

use core::ffi::CStr;

#[cfg(target_arch = "arm")]
use cortex_m_rt::entry;
use embedded_graphics_core::pixelcolor::raw::{RawData, RawU16};
use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
#[cfg(target_arch = "riscv32")]
use riscv_rt::entry;
use semihosting::fs::File;
use semihosting::io::Write as _;
use semihosting::{eprintln, println, process};
use serde::Serialize;
#[cfg(feature = "rabbit")]
use soft3d::animation::{pose_memory, Pose};
use soft3d::testing::reference;
#[cfg(feature = "rabbit")]
use soft3d::Lights;
use soft3d::{
    Band, Camera, Mat4, Model, RenderOptions, Renderer, Scratch, Stats, TransformedVertex, TriangleRows, Vec3,
};

/// The reference scene, converted at build time (see build.rs).
#[cfg(not(feature = "rabbit"))]
static SUZANNE: &[u8] = soft3d::include_s3d!(concat!(env!("OUT_DIR"), "/suzanne.s3d"));
/// The animated rabbit (feature `rabbit`), converted at build time (see build.rs).
#[cfg(feature = "rabbit")]
static RABBIT: &[u8] = soft3d::include_s3d!(concat!(env!("OUT_DIR"), "/rabbit.s3d"));
/// `POSE_MATRICES` and `POSE_WEIGHTS`: the rabbit's pose memory, written by build.rs's
/// `build_script_convert` beside rabbit.s3d.
#[cfg(feature = "rabbit")]
mod rabbit {
    include!(concat!(env!("OUT_DIR"), "/rabbit.rs"));
}
#[cfg(feature = "rabbit")]
use rabbit::{POSE_MATRICES, POSE_WEIGHTS};
/// The rabbit's animation frame drawn (every group set to it).
#[cfg(all(feature = "rabbit", not(feature = "rabbit-rest")))]
const RABBIT_FRAME: f32 = 50.0;

const WIDTH: u16 = reference::WIDTH;
const HEIGHT: u16 = reference::HEIGHT;
/// Bands per frame.
const BANDS: usize = if cfg!(feature = "one-band") { 1 } else { 8 };
const BAND_ROWS: usize = HEIGHT as usize / BANDS;
const BAND_PIXELS: usize = WIDTH as usize * BAND_ROWS;
const _: () = assert!(BAND_ROWS * BANDS == HEIGHT as usize, "BANDS must divide HEIGHT");
/// Triangles of the Suzanne model (one row-cache entry each).
#[cfg(not(feature = "rabbit"))]
const TRIANGLES: usize = 966;
/// Vertices of the Suzanne model (one transformed-vertex entry each, 28 bytes).
#[cfg(not(feature = "rabbit"))]
const VERTICES: usize = 886;
/// Triangles of the rabbit model (feature `rabbit`).
#[cfg(feature = "rabbit")]
const TRIANGLES: usize = 760;
/// Vertices of the rabbit model (feature `rabbit`).
#[cfg(feature = "rabbit")]
const VERTICES: usize = 540;
/// Frames rendered; the image file and the statistics are those of the last one.
const FRAMES: u32 = if cfg!(feature = "two-frames") { 2 } else { 1 };
/// Where the last frame goes, relative to QEMU's working directory: little-endian RGB565,
/// row-major, no header.
const FRAME_PATH: &CStr = c"out/qemu-frame.rgb565";
/// What cortex-m-rt's `paint-stack` writes over the stack before `main`.
#[cfg(target_arch = "arm")]
const STACK_PAINT: u32 = 0xCCCC_CCCC;

/// A band buffer aligned to a word (its type says so wherever it goes): clearing it is then
/// word stores (`__aeabi_memclr4`), not the byte-aligned `memset`, half as fast.
#[repr(C, align(4))]
struct Words<T>(T);

/// The firmware's buffers: a band of colour and depth, and the scratch's rows and vertices
/// (with feature `rabbit`, the pose's matrices and weights too).
struct Buffers {
    color: &'static mut Words<[Rgb565; BAND_PIXELS]>,
    depth: &'static mut Words<[u16; BAND_PIXELS]>,
    rows: &'static mut [TriangleRows; TRIANGLES],
    vertices: &'static mut [TransformedVertex; VERTICES],
    #[cfg(feature = "rabbit")]
    pose_matrices: &'static mut [Mat4; POSE_MATRICES],
    #[cfg(feature = "rabbit")]
    pose_weights: &'static mut [f32; POSE_WEIGHTS],
}

/// The single line printed on stdout.
#[derive(Serialize)]
struct Report {
    /// Frames rendered (the statistics are the last frame's).
    frame: u32,
    width: u16,
    height: u16,
    bands: usize,
    /// Triangles in the model (per frame, not per band).
    triangles: u32,
    /// Sum over bands of triangles that reached the rasterizer with pixels in the band (a
    /// triangle straddling a band boundary counts once per band).
    drawn: u32,
    pixels_written: u32,
    /// Sum over bands of the runs of pixels handed to the span loop.
    runs: u32,
    depth_rejected: u32,
    /// Depth entries not at the far plane after the frame.
    covered: u32,
    /// Stack high-water mark of the whole run, in bytes below `_stack_start` (0 on riscv32).
    stack_bytes: u32,
    /// Stack used by the renderer's calls alone (first frame), in bytes below `run`'s frame: all
    /// of the renderer's with `stack-probe`, else without what LTO inlined into `run` (0 on
    /// riscv32).
    core_stack_bytes: u32,
}

#[cfg(target_arch = "arm")]
#[entry]
fn main() -> ! {
    static mut COLOR: Words<[Rgb565; BAND_PIXELS]> = Words([Rgb565::BLACK; BAND_PIXELS]);
    static mut DEPTH: Words<[u16; BAND_PIXELS]> = Words([0; BAND_PIXELS]);
    static mut ROWS: [TriangleRows; TRIANGLES] = [TriangleRows::UNKNOWN; TRIANGLES];
    static mut VERTS: [TransformedVertex; VERTICES] = [TransformedVertex::UNKNOWN; VERTICES];
    #[cfg(feature = "rabbit")]
    static mut POSE_M: [Mat4; POSE_MATRICES] = [Mat4::IDENTITY; POSE_MATRICES];
    #[cfg(feature = "rabbit")]
    static mut POSE_W: [f32; POSE_WEIGHTS] = [0.0; POSE_WEIGHTS];
    exit(run(Buffers {
        color: COLOR,
        depth: DEPTH,
        rows: ROWS,
        vertices: VERTS,
        #[cfg(feature = "rabbit")]
        pose_matrices: POSE_M,
        #[cfg(feature = "rabbit")]
        pose_weights: POSE_W,
    }))
}

#[cfg(target_arch = "riscv32")]
#[entry]
fn main() -> ! {
    let buffers = (|| {
        Some(Buffers {
            color: riscv::singleton!(: Words<[Rgb565; BAND_PIXELS]> = Words([Rgb565::BLACK; BAND_PIXELS]))?,
            depth: riscv::singleton!(: Words<[u16; BAND_PIXELS]> = Words([0; BAND_PIXELS]))?,
            rows: riscv::singleton!(: [TriangleRows; TRIANGLES] = [TriangleRows::UNKNOWN; TRIANGLES])?,
            vertices: riscv::singleton!(: [TransformedVertex; VERTICES] = [TransformedVertex::UNKNOWN; VERTICES])?,
            #[cfg(feature = "rabbit")]
            pose_matrices: riscv::singleton!(: [Mat4; POSE_MATRICES] = [Mat4::IDENTITY; POSE_MATRICES])?,
            #[cfg(feature = "rabbit")]
            pose_weights: riscv::singleton!(: [f32; POSE_WEIGHTS] = [0.0; POSE_WEIGHTS])?,
        })
    })();
    exit(buffers.ok_or("buffers taken").and_then(run))
}

/// Exits with status 0, or with 1 after printing `result`'s error.
fn exit(result: Result<(), &'static str>) -> ! {
    match result {
        Ok(()) => process::exit(0),
        Err(msg) => {
            eprintln!("soft3d-qemu: {msg}");
            process::exit(1)
        }
    }
}

fn run(buffers: Buffers) -> Result<(), &'static str> {
    #[cfg(not(feature = "rabbit"))]
    let Buffers { color: Words(color), depth: Words(depth), rows: rows_seen, vertices: vertices_seen } = buffers;
    #[cfg(feature = "rabbit")]
    let Buffers {
        color: Words(color),
        depth: Words(depth),
        rows: rows_seen,
        vertices: vertices_seen,
        pose_matrices,
        pose_weights,
    } = buffers;
    #[cfg(not(feature = "rabbit"))]
    let model = Model::parse(SUZANNE).map_err(|_| "suzanne.s3d does not parse")?;
    #[cfg(not(feature = "rabbit"))]
    if model.draw_counts() != (TRIANGLES, VERTICES) {
        return Err("suzanne.s3d does not have the expected triangle and vertex counts");
    }
    #[cfg(feature = "rabbit")]
    let model = Model::parse(RABBIT).map_err(|_| "rabbit.s3d does not parse")?;
    #[cfg(feature = "rabbit")]
    if model.draw_counts() != (TRIANGLES, VERTICES) {
        return Err("rabbit.s3d does not have the expected triangle and vertex counts");
    }
    // The rabbit's pose, in the memory build.rs sized (the same sizes the model asks for).
    #[cfg(feature = "rabbit")]
    let animation = model.animation().ok_or("rabbit.s3d has no animation")?;
    #[cfg(feature = "rabbit")]
    #[cfg_attr(feature = "rabbit-rest", allow(unused_variables, unused_mut, reason = "drawn at rest"))]
    let mut pose = {
        let (m, w) = pose_memory(animation.node_count(), animation.palette_count(), animation.weight_count());
        if (m, w) != (POSE_MATRICES, POSE_WEIGHTS) {
            return Err("rabbit.s3d's pose memory differs from build.rs's POSE_MATRICES/POSE_WEIGHTS");
        }
        Pose::new(&mut pose_matrices[..], &mut pose_weights[..])
    };
    // The reference frame, shared with the host test that compares our output (or, with a
    // `view-*` feature, another view of the same model for the benchmarks).
    let (camera, transform) = view()?;
    #[cfg(not(feature = "rabbit"))]
    let lights = reference::lights();
    // The rabbit: the white directional light of `../shared/animation`'s Babylon.js renders of
    // this view, no ambient (the scene's own point light is behind the rabbit, which it leaves
    // nearly black from here).
    #[cfg(feature = "rabbit")]
    let lights = rabbit_lights();
    // FPU-less builds (thumbv6m, riscv32imc) transform vertices in integers (see RenderOptions);
    // build.rs gives them 16-bit positions (every target but `eabihf`).
    let opts = RenderOptions { fixed_vertices: cfg!(not(target_abi = "eabihf")), ..reference::options() };
    let renderer = Renderer::new(&camera, &lights, opts);

    let mut stats = Stats::default();
    let mut covered = 0u32;
    // The whole firmware's deepest use, kept up to date before every re-painting below.
    let (mut firmware_stack, mut core_stack) = (stack_high_water(), 0);
    for frame in 1..=FRAMES {
        let last = frame == FRAMES;
        let mut file = if last { Some(create_frame_file()?) } else { None };
        // Part of each frame's cost: an animated scene poses itself every frame.
        #[cfg(all(feature = "rabbit", not(feature = "rabbit-rest")))]
        pose.evaluate(&animation, RABBIT_FRAME, None).map_err(|_| "the rabbit's pose does not evaluate")?;
        stats = Stats::default();
        covered = 0;
        // Rows each triangle covers, learnt in the first band it is drawn in, so that later
        // bands skip it before any vertex work; each vertex transformed and lit once.
        let mut cache = Scratch::none().with_rows(&mut rows_seen[..]).with_vertices(&mut vertices_seen[..]);
        for b in 0..BANDS {
            let first_row = (b * BAND_ROWS) as u16;
            {
                let mut band = Band::new(&mut color[..], &mut depth[..], WIDTH, HEIGHT, first_row)
                    .map_err(|_| "band does not fit the frame")?;
                band.clear(Rgb565::BLACK);
                // Instrumentation in the first frame only: it cancels out of the per-frame count.
                let painted = (frame == 1).then(|| repaint_free_stack(&mut firmware_stack));
                #[cfg(any(not(feature = "rabbit"), feature = "rabbit-rest"))]
                let drawn = draw(&renderer, &mut band, &model, transform, &mut cache)?;
                #[cfg(all(feature = "rabbit", not(feature = "rabbit-rest")))]
                let drawn = draw_posed(&renderer, &mut band, &model, &pose, transform, &mut cache)?;
                stats += drawn;
                if let Some((sp, from)) = painted {
                    core_stack = core_stack.max(sp.saturating_sub(lowest_touched_stack(from)) as u32);
                }
            }
            // Reported for the last frame only, so that counting is not part of a frame's cost.
            if let Some(f) = file.as_mut() {
                covered += covered_pixels(&depth[..]);
                write_band(f, &color[..])?;
            }
        }
    }

    let report = Report {
        frame: FRAMES,
        width: WIDTH,
        height: HEIGHT,
        bands: BANDS,
        triangles: model.draws().map(|(mesh, _)| mesh.triangle_count()).sum(),
        drawn: stats.drawn,
        pixels_written: stats.pixels_written,
        runs: stats.runs,
        depth_rejected: stats.depth_rejected,
        covered,
        stack_bytes: firmware_stack.max(stack_high_water()),
        core_stack_bytes: core_stack,
    };
    let mut line = [0u8; 256];
    let n = serde_json_core::to_slice(&report, &mut line).map_err(|_| "JSON line too long")?;
    let line = core::str::from_utf8(&line[..n]).map_err(|_| "JSON is not UTF-8")?;
    println!("{line}");
    Ok(())
}

/// [`Renderer::draw`], inlined into the frame loop (as LTO does in a firmware of one call
/// site) or, with the `stack-probe` feature, out of line: then every frame of the renderer lies
/// below the one `run` measures the core stack from (see `core_stack_bytes`).
#[cfg(any(not(feature = "rabbit"), feature = "rabbit-rest"))]
#[cfg_attr(feature = "stack-probe", inline(never))]
#[cfg_attr(not(feature = "stack-probe"), inline(always))]
fn draw(
    renderer: &Renderer<'_, 1>,
    band: &mut Band<'_, Rgb565, &mut [u16]>,
    model: &Model<'_>,
    transform: Mat4,
    scratch: &mut Scratch<'_>,
) -> Result<Stats, &'static str> {
    renderer.draw(band, model, transform, scratch).map_err(|_| "draw refused")
}

/// [`Renderer::draw_posed`] (feature `rabbit`), inlined or out of line as [`draw`] is.
#[cfg(all(feature = "rabbit", not(feature = "rabbit-rest")))]
#[cfg_attr(feature = "stack-probe", inline(never))]
#[cfg_attr(not(feature = "stack-probe"), inline(always))]
fn draw_posed(
    renderer: &Renderer<'_, 1>,
    band: &mut Band<'_, Rgb565, &mut [u16]>,
    model: &Model<'_>,
    pose: &Pose<'_>,
    transform: Mat4,
    scratch: &mut Scratch<'_>,
) -> Result<Stats, &'static str> {
    renderer.draw_posed(band, model, pose, transform, scratch).map_err(|_| "draw refused")
}

/// Opens the frame file on the host (truncating it).
fn create_frame_file() -> Result<File, &'static str> {
    File::create(FRAME_PATH)
        .map_err(|_| "cannot create out/qemu-frame.rgb565 (does out/ exist in QEMU's working directory?)")
}

/// Writes a band's pixels as little-endian RGB565, one row per semihosting call.
fn write_band(f: &mut File, pixels: &[Rgb565]) -> Result<(), &'static str> {
    let mut row = [0u8; 2 * WIDTH as usize];
    for px in pixels.chunks(WIDTH as usize) {
        for (out, &p) in row.chunks_exact_mut(2).zip(px) {
            out.copy_from_slice(&RawU16::from(p).into_inner().to_le_bytes());
        }
        f.write_all(&row[..2 * px.len()]).map_err(|_| "writing the frame file failed")?;
    }
    Ok(())
}

#[cfg(target_arch = "arm")]
extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// Bytes of stack used so far: from `_stack_start` (the top) down to the lowest word that no
/// longer holds the paint.
#[cfg(target_arch = "arm")]
fn stack_high_water() -> u32 {
    (&raw const _stack_start as usize - lowest_touched_stack(&raw const _stack_end as usize)) as u32
}

/// How far below the caller's frame [`repaint_free_stack`] paints (more than the renderer
/// uses; the scan stops at the first touched word, so a bigger window costs nothing more).
#[cfg(target_arch = "arm")]
const CORE_STACK_WINDOW: usize = 16 * 1024;

/// The lowest address at or above `from` that no longer holds the paint cortex-m-rt (or
/// [`repaint_free_stack`]) put on the stack. Never inlined, like [`paint_stack`]: the one- and
/// two-frame builds must run the very same code for it, or its instruction count would not
/// cancel out of the per-frame figure.
#[cfg(target_arch = "arm")]
#[inline(never)]
fn lowest_touched_stack(from: usize) -> usize {
    let top = &raw const _stack_start as usize;
    let mut p = from;
    while p < top {
        // SAFETY: `_stack_end.._stack_start` is RAM reserved for the stack by cortex-m-rt's
        // linker script, 4-byte aligned, and `from` lies in it; it is only read here
        // (volatile, so the compiler cannot assume its contents), and the words below the
        // stack pointer belong to no live object.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != STACK_PAINT {
            break;
        }
        p += 4;
    }
    p
}

/// Paints the [`CORE_STACK_WINDOW`] below the current stack pointer again (leaving 256 bytes
/// for [`paint_stack`]'s own frame) and returns the stack pointer and the window's start.
/// First raises `high_water` (bytes below `_stack_start`) to what the window shows, since
/// painting erases it. Inlined into its caller, so that the pointer is the caller's.
#[cfg(target_arch = "arm")]
#[inline(always)]
fn repaint_free_stack(high_water: &mut u32) -> (usize, usize) {
    let sp = cortex_m::register::msp::read() as usize;
    let from = (&raw const _stack_end as usize).max(sp.saturating_sub(CORE_STACK_WINDOW)) & !3;
    let seen = (&raw const _stack_start as usize - lowest_touched_stack(from)) as u32;
    *high_water = (*high_water).max(seen);
    paint_stack(from, sp - 256);
    (sp, from)
}

/// The pixels of a band whose depth was written. Out of line, so that both builds of the
/// per-frame count (one frame and two) compile it alike and it cancels out: inlined into the
/// frame loop, LLVM made it 3 instructions a pixel in one and 4 in the other (riscv32imc, one
/// band: 115,200 instructions counted as the frame's).
#[inline(never)]
fn covered_pixels(depth: &[u16]) -> u32 {
    depth.iter().filter(|&&d| d != u16::MAX).count() as u32
}

/// Writes the paint pattern over `from..to`. Never inlined (see [`lowest_touched_stack`]).
#[cfg(target_arch = "arm")]
#[inline(never)]
fn paint_stack(from: usize, to: usize) {
    let mut p = from;
    while p < to {
        // SAFETY: as in `lowest_touched_stack`; these words are below the stack pointer (no
        // live object, no interrupt handler runs here) and only ever hold the paint pattern.
        unsafe { core::ptr::write_volatile(p as *mut u32, STACK_PAINT) };
        p += 4;
    }
}

/// riscv32 stand-ins for the stack measurement above (Cortex-M only): every figure is 0.
#[cfg(target_arch = "riscv32")]
fn stack_high_water() -> u32 {
    0
}

/// See [`stack_high_water`] (riscv32): the scan finds nothing, so it stops where it starts.
#[cfg(target_arch = "riscv32")]
fn lowest_touched_stack(from: usize) -> usize {
    from
}

/// See [`stack_high_water`] (riscv32): paints nothing; stack pointer and window start are 0.
#[cfg(target_arch = "riscv32")]
fn repaint_free_stack(_high_water: &mut u32) -> (usize, usize) {
    (0, 0)
}

/// The camera and model transform drawn: the reference frame, or with feature `view-far` the
/// model at distance 12 (camera at (0, 0, -12) looking at the origin, model turned -0.7 rad
/// about y: few pixels, vertex-bound), or with `view-near` a close-up at distance 1.6 that
/// overflows the frame (pixel-bound, with clipping at the guard band).
#[cfg(not(feature = "rabbit"))]
fn view() -> Result<(Camera, Mat4), &'static str> {
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let at = |eye: Vec3, turn: f32| {
        Camera::perspective(eye, Vec3::ZERO, 0.8, aspect, 0.1, 100.0)
            .map(|c| (c, Mat4::from_rotation_y(turn)))
            .map_err(|_| "bad camera")
    };
    if cfg!(feature = "view-far") {
        at(Vec3::new(0.0, 0.0, -12.0), -0.7)
    } else if cfg!(feature = "view-near") {
        at(Vec3::new(0.3, 0.2, -1.6), 0.5)
    } else {
        Ok((reference::camera(WIDTH, HEIGHT), reference::transform()))
    }
}

/// The rabbit's camera (feature `rabbit`): from (40, 55, -75) looking at (0, 30, 5), vertical
/// fov 0.8, near 1, far 1000; the posed model drawn as it stands (identity transform).
#[cfg(feature = "rabbit")]
fn view() -> Result<(Camera, Mat4), &'static str> {
    let aspect = WIDTH as f32 / HEIGHT as f32;
    Camera::perspective(Vec3::new(40.0, 55.0, -75.0), Vec3::new(0.0, 30.0, 5.0), 0.8, aspect, 1.0, 1000.0)
        .map(|c| (c, Mat4::IDENTITY))
        .map_err(|_| "bad camera")
}

/// The rabbit's light (feature `rabbit`): directional along (0.3, -0.6, 0.7), intensity 1, no
/// ambient.
#[cfg(feature = "rabbit")]
fn rabbit_lights() -> Lights<1> {
    let mut lights = Lights::new(Vec3::ZERO);
    let _ = lights.push(Lights::<1>::directional(Vec3::new(0.3, -0.6, 0.7), 1.0));
    lights
}
