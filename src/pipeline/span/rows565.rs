//! Whole triangles' rows of the common variant in Armv7-M assembly (`cfg(span_asm)`): the
//! affine ([`affine_rows565`]) and per-pixel-perspective ([`pixel_rows565`]) row routines,
//! their record ([`RowWalk565`]) and the Rust that hands them a triangle's rows
//! (`Shader::rows_in_assembly`); the pixels as `armv7m`'s runs draw them (`asm565!`).

use super::run565::Run565;
use super::*;
use crate::pipeline::raster::PlainRows;
#[cfg(not(soft_float))]
use crate::pipeline::raster::{PixelRows, PixelRun};

/// The row routines' shared parts, as template lines (see [`RowWalk565`] for the offsets from
/// `r3`, and `asm565!` for the pixel loop's registers).
macro_rules! rows565 {
    // The steps at [sp] for the pixel loop; r6, r7 free; no pixel rejected yet.
    (enter) => {
        concat!(
            "push {{r6, r7}}\n",
            "add r6, r3, #20\n",
            "ldm r6, {{r6, r7, r11, r12}}\n",
            "push {{r6, r7, r11, r12}}\n",
            "mov r10, #0\n",
        )
    };
    // At `1:`, the next row (to `9f` after the last): its covered columns `r7..=hi` (to `1b`
    // when none) from the two edges, its rows below the origin `r0`, the run's ends `r1`,
    // `r2` and byte offset (in `scratch`), pixels and runs counted, and the depth at its first
    // pixel `r4`; the edges, `dy` and the row entries on to the next row.
    (row) => {
        concat!(
            "1:\n",
            "ldrd r0, r1, [r3, #64]\n",
            "cmp r0, r1\n",
            "bge 9f\n",
            "add r1, r0, #1\n",
            "str r1, [r3, #64]\n",
            // Both edges and `last`; the edges on to the next row.
            "add lr, r3, #36\n",
            "ldm lr, {{r1, r2, r4, r5, r6, r8, r9}}\n",
            "add r2, r1, r2\n",
            "add r6, r5, r6\n",
            "str r2, [r3, #36]\n",
            "str r6, [r3, #48]\n",
            // The left edge's first column: 0 when row > d - 1, else (d - 1 - row) / d; at least 0.
            "sub r7, r4, #1\n",
            "subs r7, r7, r1\n",
            "ite lt\n",
            "movlt r7, #0\n",
            "udivge r7, r7, r4\n",
            "bic r7, r7, r7, asr #31\n",
            // The right edge's last column: -1 when row < 0, else row / d; at most `last`.
            "cmp r5, #0\n",
            "ite lt\n",
            "mvnlt r12, #0\n",
            "udivge r12, r5, r8\n",
            "cmp r12, r9\n",
            "it gt\n",
            "movgt r12, r9\n",
            // This row's entries; the next row's.
            "ldrd r1, r2, [r3, #72]\n",
            "ldr r6, [r3, #80]\n",
            "add r4, r1, r6\n",
            "add r5, r2, r6\n",
            "strd r4, r5, [r3, #72]\n",
            "cmp r7, r12\n",
            "bgt 1b\n",
            // The run's ends and its byte offset from them; pixels and runs counted.
            "add r12, r12, #1\n",
            "add r1, r1, r12, lsl #1\n",
            "add r2, r2, r12, lsl #1\n",
            "sub r8, r7, r12\n",
            "ldrd r11, r12, [r3, #100]\n",
            "sub r11, r11, r8\n",
            "add r12, r12, #1\n",
            "strd r11, r12, [r3, #100]\n",
            "lsl r8, r8, #1\n",
            "str r8, [r3, #108]\n",
            // Depth at the first pixel: (z_origin + z_dx·lo + z_dy·dy) >> 10, low word.
            "ldrd r4, r5, [r3, #84]\n",
            "ldrd r11, r12, [r3, #92]\n",
            "smlal r4, r5, r11, r7\n",
            "smlal r4, r5, r12, r0\n",
            "lsr r4, r4, #10\n",
            "orr r4, r4, r5, lsl #22\n",
        )
    };
    // The rejected pixels' count (`4:`, see `asm565!`), and the way out (`9:`).
    (leave) => {
        concat!(asm565!(reject), "9:\n", "add sp, sp, #16\n", "pop {{r6, r7}}\n")
    };
}

/// A row routine: the template lines given, with `walk` (a [`RowWalk565`]) in `r3`, every other
/// register it may use declared clobbered, and the pixels the depth test rejected (`r10`) as
/// its value. `unsafe`: an `asm!`.
macro_rules! row_routine {
    ($walk:expr, $($line:expr),+ $(,)?) => {{
        let rejected: u32;
        core::arch::asm!(
            $($line),+,
            in("r3") core::ptr::from_mut($walk),
            out("r0") _,
            out("r1") _,
            out("r2") _,
            out("r4") _,
            out("r5") _,
            out("r8") _,
            out("r9") _,
            out("r10") rejected,
            out("r11") _,
            out("r12") _,
            out("lr") _,
        );
        rejected
    }};
}

/// Draws the rows `walk` describes with affine varyings: on each, the columns between its
/// edges (as `raster::PlainRows` defines them) within `0..=last`, from the depth and varyings
/// at the first (`raster::RowCursor::depth_terms`, `raster::AffineRows::terms`) stepped by
/// `steps`, with the depth test and shading of [`run565`]; counts the pixels and runs in `walk`.
/// The walk of the rows, the planes at each run's first pixel and the pixel loop, all in the
/// registers of one routine: about 65 instructions a row where the Rust walk and
/// [`Shader::run`] took about 140. The pixels the depth test rejected.
fn affine_rows565(walk: &mut RowWalk565<Affine565>) -> u32 {
    // SAFETY: on each of the rows `dy..dy_end`, the loop writes colour and depth entries
    // `lo..=hi` of the row's `color_row` and `depth_row`, with `0 <= lo` (the `bic`) and `hi <=
    // last` (the `movgt`), the rows `stride` bytes (one band row) apart: within the triangle's
    // box, which `rows_in_assembly` checked lies in the band's slices (both `run_start`s and
    // their distance) and the rows within it; it reads texels as `run565` does, reads and
    // writes `walk`'s fields, and restores `r6`, `r7` and `sp`.
    unsafe {
        row_routine!(
            walk,
            rows565!(enter),
            rows565!(row),
            // Varyings at the first pixel: base + ((origin + gx·lo + gy·dy) >> 8); v scaled.
            "add r6, r3, #112",
            "ldm r6!, {{r9, r11, r12, lr}}",
            "mla r11, r12, r7, r11",
            "mla r11, lr, r0, r11",
            "add r5, r9, r11, asr #8",
            "ldm r6!, {{r9, r11, r12, lr}}",
            "mla r11, r12, r7, r11",
            "mla r11, lr, r0, r11",
            "add r8, r9, r11, asr #8",
            "ldm r6!, {{r9, r11, r12, lr}}",
            "mla r11, r12, r7, r11",
            "mla r11, lr, r0, r11",
            "add r9, r9, r11, asr #8",
            "ldr r11, [r6]",
            "lsl r8, r8, r11",
            "ldr r0, [r3, #108]",
            // The pixels, as `run565`'s loop.
            asm565!(linear_pixels),
            "b 1b",
            rows565!(leave),
        )
    }
}

/// [`affine_rows565`] with perspective at every pixel (`raster::PixelRows`): at each run's
/// first pixel (column `lo`, row `dy`), `s` and each `t` are `origin + dx·lo + dy·dy` in f32
/// (`raster::PixelRows::float_terms`), then each pixel is [`run565_perspective`]'s, `s` and `t`
/// stepping by their `dx`. The planes stay in `s16`-`s27` and `v0` in `s4`-`s6` for the whole
/// call; it saves and restores `s0`-`s27` itself (see [`run565_perspective`]).
#[cfg(not(soft_float))]
fn pixel_rows565(walk: &mut RowWalk565<Pixel565>) -> u32 {
    // SAFETY: as `affine_rows565`'s (the same rows, entries and texels); it also restores
    // `s0`-`s27`.
    unsafe {
        row_routine!(
            walk,
            "vpush {{s0-s27}}",
            rows565!(enter),
            "add r6, r3, #112",
            "vldm r6!, {{s16-s27}}",
            "vldm r6, {{s4-s6}}",
            "vmov.f32 s11, #1.0",
            rows565!(row),
            // s and t at the first pixel: origin + dx·lo + dy·dy, rounded as `Plane::at`.
            "vmov s12, r7",
            "vmov s13, r0",
            "vcvt.f32.s32 s12, s12",
            "vcvt.f32.s32 s13, s13",
            "vmov.f32 s0, s16",
            "vmla.f32 s0, s17, s12",
            "vmla.f32 s0, s18, s13",
            "vmov.f32 s1, s19",
            "vmla.f32 s1, s20, s12",
            "vmla.f32 s1, s21, s13",
            "vmov.f32 s2, s22",
            "vmla.f32 s2, s23, s12",
            "vmla.f32 s2, s24, s13",
            "vmov.f32 s3, s25",
            "vmla.f32 s3, s26, s12",
            "vmla.f32 s3, s27, s13",
            "ldr r0, [r3, #108]",
            // The pixels, as `run565_perspective`'s loop.
            "2:",
            asm565!(depth_test),
            asm565!(perspective),
            asm565!(shade),
            "5:",
            "vadd.f32 s0, s0, s17",
            "vadd.f32 s1, s1, s20",
            "vadd.f32 s2, s2, s23",
            "vadd.f32 s3, s3, s26",
            "ldr r6, [sp]",
            "add r4, r4, r6",
            "adds r0, r0, #2",
            "bne 2b",
            "b 1b",
            rows565!(leave),
            "vpop {{s0-s27}}",
        )
    }
}

/// What the row routines ([`affine_rows565`], [`pixel_rows565`]) read and keep as they walk a
/// triangle's rows: [`Run565`]'s constants and the per-pixel steps (depth, then `u`, `v` scaled
/// and light for linear varyings) where the pixel loop loads them, the two edges and the rows'
/// place in the band (stepped row by row), the depth plane, the counts, and the routine's own
/// planes `P`. The assembly reads the fields at the offsets asserted below.
#[repr(C)]
struct RowWalk565<P> {
    k: Run565,
    steps: [i32; 4],
    /// `[row, 16·b, d]` of the left and right edges on the next row (see `raster::PlainRows`).
    left: [i32; 3],
    right: [i32; 3],
    /// The box's last column (`x1 - x0`).
    last: i32,
    /// The next row's rows below the origin, and the first's below them all.
    dy: i32,
    dy_end: i32,
    /// The colour and depth entries of the next row's first box column, and the bytes from a
    /// row's entry to the next row's.
    color_row: *mut u16,
    depth_row: *mut u16,
    stride: u32,
    /// The depth plane (see `raster::RowCursor::depth_terms`): the origin's value as `[low,
    /// high]` words, and per pixel in x and y.
    z_origin: [u32; 2],
    z_dx: i32,
    z_dy: i32,
    /// Pixels of the runs drawn, and runs.
    pixels: u32,
    runs: u32,
    /// The assembly's one spill: the run's byte offset.
    scratch: i32,
    planes: P,
}

/// [`affine_rows565`]'s planes: `[base, origin, gx, gy]` of `u`, `v` and light (see
/// `raster::AffineRows::terms`), and the left shift of `v`.
#[repr(C)]
struct Affine565 {
    terms: [[i32; 4]; 3],
    v_shift: u32,
}

/// [`pixel_rows565`]'s planes: `[origin, dx, dy]` of `s`, `t0`, `t1`, `t2`, then `v0` (see
/// `raster::PixelRows::float_terms`).
#[cfg(not(soft_float))]
type Pixel565 = [f32; 15];

const _: () = {
    use core::mem::offset_of;
    type W = RowWalk565<Affine565>;
    assert!(offset_of!(W, steps) == 20 && offset_of!(W, left) == 36 && offset_of!(W, right) == 48);
    assert!(offset_of!(W, last) == 60 && offset_of!(W, dy) == 64 && offset_of!(W, dy_end) == 68);
    assert!(offset_of!(W, color_row) == 72 && offset_of!(W, depth_row) == 76 && offset_of!(W, stride) == 80);
    assert!(offset_of!(W, z_origin) == 84 && offset_of!(W, z_dx) == 92 && offset_of!(W, z_dy) == 96);
    assert!(offset_of!(W, pixels) == 100 && offset_of!(W, runs) == 104 && offset_of!(W, scratch) == 108);
    assert!(offset_of!(W, planes) == 112 && offset_of!(Affine565, v_shift) == 48);
    // The varyings' order in `planes`.
    assert!(VertexLit::U == 0 && VertexLit::V == 1 && VertexLit::LIGHT == 2);
};
#[cfg(not(soft_float))]
const _: () = assert!(core::mem::offset_of!(RowWalk565<Pixel565>, planes) == 112);

/// Rows that a row routine draws in part ([`PlainRows`]), the rest with [`Shader::run`].
trait AssemblyRows<const V: usize> {
    /// How the varyings of the rows drawn by [`Shader::run`] step.
    type Run: RunVaryings<V>;
    /// See `raster::RowCursor::take_plain_rows`.
    fn take_plain_rows(&mut self) -> Option<PlainRows>;
    /// The next row, `None` after the last; `Some(None)` for a row with no pixel centre.
    fn next_run(&mut self) -> Option<Option<RunRow<Self::Run>>>;
}

impl<const V: usize> AssemblyRows<V> for AffineRows<'_, V> {
    type Run = Stepped<V>;
    fn take_plain_rows(&mut self) -> Option<PlainRows> {
        AffineRows::take_plain_rows(self)
    }
    fn next_run(&mut self) -> Option<Option<RunRow<Stepped<V>>>> {
        self.next_row()
    }
}

#[cfg(not(soft_float))]
impl<const V: usize> AssemblyRows<V> for PixelRows<'_, V> {
    type Run = PixelRun<V>;
    fn take_plain_rows(&mut self) -> Option<PlainRows> {
        PixelRows::take_plain_rows(self)
    }
    fn next_run(&mut self) -> Option<Option<RunRow<PixelRun<V>>>> {
        self.next_row()
    }
}

impl<C: FrameColor, D: RunCells, B: Base, Lt: Lighting, const DITHER: bool> Shader<'_, '_, C, D, B, Lt, DITHER> {
    /// Draws an affine triangle's rows with [`affine_rows565`] where it can (see
    /// [`Shader::rows_in_assembly`]); `None`, drawing nothing, when the triangle's box does not
    /// lie in the band or its varyings are not the three that [`Run565`]'s variant has.
    pub(super) fn draw_affine_rows_in_assembly<const V: usize>(
        &mut self,
        k: &Run565,
        rows: &mut AffineRows<'_, V>,
    ) -> Option<()> {
        let (terms, step) = rows.terms();
        let (Ok(terms), Ok(step)) = (<&[[i32; 4]; 3]>::try_from(&terms[..]), <&[i32; 3]>::try_from(&step[..])) else {
            return None;
        };
        let v_shift = self.v_shift & 31;
        let (z, area) = (rows.depth_terms(), rows.remaining_box());
        let steps = [z.3, step[0], step[1].wrapping_shl(v_shift), step[2]];
        let walk = RowWalk565::new(k, steps, z, Affine565 { terms: *terms, v_shift });
        self.rows_in_assembly(rows, walk, area, affine_rows565)
    }

    /// Draws a triangle's rows with per-pixel perspective with [`pixel_rows565`] where it can
    /// (see [`Shader::rows_in_assembly`]); `None`, drawing nothing, as
    /// [`Shader::draw_affine_rows_in_assembly`].
    #[cfg(not(soft_float))]
    pub(super) fn draw_pixel_rows_in_assembly<const V: usize>(
        &mut self,
        k: &Run565,
        rows: &mut PixelRows<'_, V>,
    ) -> Option<()> {
        let planes = rows.float_terms()?;
        let (z, area) = (rows.depth_terms(), rows.remaining_box());
        let walk = RowWalk565::new(k, [z.3, 0, 0, 0], z, planes);
        self.rows_in_assembly(rows, walk, area, pixel_rows565)
    }

    /// Draws `rows` (the rest of a triangle's, in the box `(x0, x1, y0, y1)`): those bounded
    /// by two edges with `draw` (a row routine, its record `walk`), the middle vertex's with
    /// [`Shader::run`]; `None`, drawing nothing, when the box does not lie in the band.
    fn rows_in_assembly<const V: usize, P>(
        &mut self,
        rows: &mut impl AssemblyRows<V>,
        mut walk: RowWalk565<P>,
        (x0, x1, y0, y1): (i32, i32, i32, i32),
        draw: fn(&mut RowWalk565<P>) -> u32,
    ) -> Option<()> {
        let (width, stride) = (usize::try_from(x1 - x0 + 1).ok()?, self.area.width());
        let first = self.area.run_start(x0, y0, width)?;
        let last_row = self.area.run_start(x0, y1, width)?;
        // Every entry of the box, from the first row's first column to the last's last.
        let entries = (last_row + width).checked_sub(first)?;
        // SAFETY: `run_start` gave `last_row` only with `last_row + width <= rows · width`.
        let depths = unsafe { self.depth.run_u16(first, entries) }?.as_mut_ptr();
        let colors = C::as_rgb565_values(colors_of(self.color, first, entries)?)?;
        let box_rows = usize::try_from(y1 - y0).ok()?;
        if colors.len() != entries || last_row - first != box_rows * stride {
            return None;
        }
        let colors = colors.as_mut_ptr();
        (walk.last, walk.stride) = (x1 - x0, (stride * 2) as u32);
        let (base, dz, mut rejected) = (*self.base, walk.steps[0], 0);
        loop {
            if let Some(plain) = rows.take_plain_rows() {
                // Within the box's rows (`take_plain_rows` gives no other; checked, as the
                // assembly writes where this says).
                let Some(from_top) =
                    usize::try_from(plain.y - y0).ok().filter(|&r| r + plain.rows as usize <= box_rows + 1)
                else {
                    continue;
                };
                (walk.left, walk.right) = (plain.left, plain.right);
                (walk.dy, walk.dy_end) = (plain.dy, plain.dy + plain.rows);
                walk.color_row = colors.wrapping_add(from_top * stride);
                walk.depth_row = depths.wrapping_add(from_top * stride);
                rejected += draw(&mut walk);
                continue;
            }
            match rows.next_run() {
                None => break,
                Some(None) => {}
                Some(Some((at, z, vary))) => self.run(&base, at, (z, dz), vary),
            }
        }
        self.written += walk.pixels - rejected;
        self.rejected += rejected;
        self.runs += walk.runs;
        Some(())
    }
}

impl<P> RowWalk565<P> {
    /// The record for a triangle drawn with constants `k`, per-pixel `steps`, depth plane `z`
    /// (see `raster::RowCursor::depth_terms`) and the routine's `planes`; the rest set per
    /// triangle and per run of rows by [`Shader::rows_in_assembly`].
    fn new(k: &Run565, steps: [i32; 4], (z_origin, z_dx, z_dy, _): (i64, i32, i32, i32), planes: P) -> Self {
        RowWalk565 {
            k: *k,
            steps,
            left: [0; 3],
            right: [0; 3],
            last: 0,
            dy: 0,
            dy_end: 0,
            color_row: core::ptr::null_mut(),
            depth_row: core::ptr::null_mut(),
            stride: 0,
            z_origin: [z_origin as u32, (z_origin >> 32) as u32],
            z_dx,
            z_dy,
            pixels: 0,
            runs: 0,
            scratch: 0,
            planes,
        }
    }
}
