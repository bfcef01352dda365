//! Render targets: the caller's colour and depth slices for one band of the frame.
//!
//! A band is `rows` full-width rows starting at `first_row` of a `width` x `height` frame;
//! a whole frame is the band with `first_row = 0` and `rows = height`. The renderer only ever
//! writes inside the slices given here. It does not decide what is drawn (the pipeline does)
//! or talk to a display (`eg` and the caller do).

use core::fmt;

mod color;
pub use color::{luma, FrameColor, Rgb565Be};

#[cfg(test)]
use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};

/// The largest frame width or height. Screen positions are kept in 28.4 fixed point with a
/// guard band of [`GUARD_HALF_EXTENT`] pixels around the frame centre; larger frames would not
/// fit it.
pub const MAX_DIMENSION: u16 = 1536;

/// Half the guard band's size in pixels: geometry is clipped to within this distance of the
/// frame centre, so any triangle's edge functions fit in `i32` (see `raster`).
pub const GUARD_HALF_EXTENT: f32 = 960.0;

/// One entry of a depth buffer, as the per-pixel loop sees it.
pub trait DepthCell {
    /// Whether depth `z` (0..=2^30) passes the LEQUAL test here.
    fn passes(&self, z: u32) -> bool;
    /// Stores `z` (0..=2^30) here.
    fn store(&mut self, z: u32);
}

/// A depth buffer for one band. Depth values arrive as 0..=2^30 (near..far, see the crate's
/// conventions); the test is LEQUAL.
pub trait DepthBuffer {
    /// The entries of a run of pixels, in order.
    type Cells<'a>: Iterator<Item: DepthCell>
    where
        Self: 'a;
    /// Number of entries (must equal the colour slice's length), or `None` for no buffer.
    fn depth_len(&self) -> Option<usize>;
    /// Entries `start..start + len`, or `None` when they are not all in the buffer.
    fn cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>>;
    /// Sets every entry to the far plane.
    fn clear_depth(&mut self);

    /// Whether depth `z` passes the LEQUAL test at entry `i` (false outside the buffer).
    #[inline]
    fn passes(&mut self, i: usize, z: u32) -> bool {
        self.cells(i, 1).and_then(|mut c| c.next()).is_some_and(|c| c.passes(z))
    }
    /// Stores `z` at entry `i` (ignored outside the buffer).
    #[inline]
    fn store(&mut self, i: usize, z: u32) {
        if let Some(mut c) = self.cells(i, 1).and_then(|mut c| c.next()) {
            c.store(z);
        }
    }

    /// The whole buffer as plain `u16` depths ([`DepthValue`] for `u16`), one per pixel of the
    /// band in row order, when that is what it is: the span loop then indexes it directly,
    /// checking its length once a triangle instead of each run's cells. `None` (the default)
    /// draws through [`DepthBuffer::cells`].
    #[inline(always)]
    fn as_u16(&mut self) -> Option<&mut [u16]> {
        None
    }
}

/// What a depth buffer of plain values stores: `u16` (`z >> 14`, 0 = near plane, 65535 = far
/// plane) or `f32` (0.0 near ..= 1.0 far).
pub trait DepthValue: Copy + PartialOrd {
    /// The far plane: what [`DepthBuffer::clear_depth`] writes.
    const FAR: Self;
    /// The stored form of depth `z` (0..=2^30).
    fn from_z(z: u32) -> Self;
    /// Whether depth `z` (0..=2^30) passes the LEQUAL test against `stored`.
    #[inline(always)]
    fn passes(z: u32, stored: Self) -> bool {
        Self::from_z(z) <= stored
    }
    /// `values` as `u16`s when `Self` is `u16` (see [`DepthBuffer::as_u16`]); `None` otherwise
    /// (the default).
    #[inline(always)]
    fn as_u16(values: &mut [Self]) -> Option<&mut [u16]> {
        let _ = values;
        None
    }
}

impl DepthValue for u16 {
    const FAR: Self = u16::MAX;
    #[inline(always)]
    fn from_z(z: u32) -> Self {
        z_to_u16(z)
    }
    /// Compared as `u32`, so that the saturated depth needs no narrowing first.
    #[inline(always)]
    fn passes(z: u32, stored: Self) -> bool {
        z_to_u16_wide(z) <= u32::from(stored)
    }
    #[inline(always)]
    fn as_u16(values: &mut [Self]) -> Option<&mut [u16]> {
        Some(values)
    }
}

impl DepthValue for f32 {
    const FAR: Self = 1.0;
    #[inline(always)]
    fn from_z(z: u32) -> Self {
        z_to_f32(z)
    }
}

impl<T: DepthValue> DepthCell for &mut T {
    #[inline(always)]
    fn passes(&self, z: u32) -> bool {
        T::passes(z, **self)
    }
    #[inline(always)]
    fn store(&mut self, z: u32) {
        **self = T::from_z(z);
    }
}

impl<T: DepthValue> DepthBuffer for &mut [T] {
    type Cells<'a>
        = core::slice::IterMut<'a, T>
    where
        Self: 'a;
    #[inline]
    fn depth_len(&self) -> Option<usize> {
        Some(self.len())
    }
    #[inline(always)]
    fn cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>> {
        self.get_mut(start..start.checked_add(len)?).map(|s| s.iter_mut())
    }
    fn clear_depth(&mut self) {
        match T::as_u16(self) {
            Some(values) => fill_u16_in_blocks(values, <u16 as DepthValue>::FAR),
            None => self.fill(T::FAR),
        }
    }
    #[inline(always)]
    fn as_u16(&mut self) -> Option<&mut [u16]> {
        T::as_u16(self)
    }
}

/// Fills `values` with `value`, 32 bytes a block in their word-aligned middle: from eight
/// registers (`stm` on Cortex-M4; the library's `memset` stores 16 bytes in six instructions).
/// Not on Cortex-M0+, whose eight low registers cannot hold the block beside the loop's own
/// values: there the library's word stores are as fast.
fn fill_u16_in_blocks(values: &mut [u16], value: u16) {
    #[cfg(no_hw_divide)]
    values.fill(value);
    #[cfg(not(no_hw_divide))]
    {
        let (head, blocks, tail) = bytemuck::pod_align_to_mut::<u16, [u32; 8]>(values);
        head.fill(value);
        tail.fill(value);
        // Eight opaque copies (a visible value turns the loop back into `memset`), held in
        // registers.
        let block: [u32; 8] = core::array::from_fn(|_| core::hint::black_box(u32::from(value) * 0x1_0001));
        for b in blocks {
            *b = block;
        }
    }
}

/// Fills `values` with `value`, 16 entries a block copied from an opaque one: for RGB565 in a
/// word-aligned band buffer, 32 bytes in four `ldm`/`stm` on Cortex-M4F (the reference frame's
/// colour clear 43k instructions with the library's `memset` loop, about 25k so). Unlike
/// [`fill_u16_in_blocks`] it cannot hold the block in registers: a colour need not be plain
/// bits to view as words. Only where there is an FPU: the targets without one measured worse
/// (riscv32imc copies each block through a `memcpy` call, +169k a frame; thumbv6m +8k), and
/// take the library's fill.
fn fill_in_blocks<T: Copy>(values: &mut [T], value: T) {
    #[cfg(soft_float)]
    values.fill(value);
    #[cfg(not(soft_float))]
    fill_blocks_of_16(values, value);
}

/// [`fill_in_blocks`] on targets with an FPU.
#[cfg_attr(soft_float, allow(dead_code))]
fn fill_blocks_of_16<T: Copy>(values: &mut [T], value: T) {
    let (blocks, tail) = values.as_chunks_mut::<16>();
    // Opaque: a visible value turns the loop back into `memset`.
    let block: [T; 16] = core::hint::black_box([value; 16]);
    for b in blocks {
        *b = block;
    }
    tail.fill(value);
}

#[inline(always)]
fn z_to_u16(z: u32) -> u16 {
    z_to_u16_wide(z) as u16
}

/// [`z_to_u16`] before narrowing: 0..=65535.
#[inline(always)]
fn z_to_u16_wide(z: u32) -> u32 {
    debug_assert!(z <= 1 << 30);
    // 2^30 (the far plane) saturates to 65535: one instruction (usat) on Armv7-M; without it
    // (Armv6-M, RISC-V), three: only 2^30 itself has bit 30 set.
    #[cfg(not(soft_float))]
    {
        ((z as i32) >> 14).clamp(0, 0xffff) as u32
    }
    #[cfg(soft_float)]
    {
        z_to_u16_by_shifts(z)
    }
}

/// [`z_to_u16_wide`] without a saturating instruction, for `z <= 2^30`.
#[cfg(any(soft_float, test))]
#[inline(always)]
fn z_to_u16_by_shifts(z: u32) -> u32 {
    (z >> 14) - (z >> 30)
}

#[inline(always)]
fn z_to_f32(z: u32) -> f32 {
    z as f32 * (1.0 / (1u32 << 30) as f32)
}

/// No depth buffer: every fragment passes (use painter's order or a single convex mesh).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoDepth;

/// The cell of [`NoDepth`]: every depth passes, nothing is stored.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoDepthCell;

impl DepthCell for NoDepthCell {
    #[inline(always)]
    fn passes(&self, _: u32) -> bool {
        true
    }
    #[inline(always)]
    fn store(&mut self, _: u32) {}
}

impl DepthBuffer for NoDepth {
    type Cells<'a> = core::iter::RepeatN<NoDepthCell>;
    #[inline]
    fn depth_len(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn cells(&mut self, _: usize, len: usize) -> Option<Self::Cells<'_>> {
        Some(core::iter::repeat_n(NoDepthCell, len))
    }
    fn clear_depth(&mut self) {}
}

/// Why a [`Band`] could not be made from the given slices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetError {
    /// Width or height is 0 or above [`MAX_DIMENSION`].
    BadSize {
        /// Requested width.
        width: u16,
        /// Requested height.
        height: u16,
    },
    /// The colour slice is empty or not a whole number of rows.
    ColorLength {
        /// The slice's length.
        len: usize,
        /// The frame width.
        width: u16,
    },
    /// The band's rows do not fit in the frame.
    BandOutsideFrame {
        /// First row of the band.
        first_row: u16,
        /// Rows in the band.
        rows: usize,
        /// Frame height.
        height: u16,
    },
    /// The depth slice's length differs from the colour slice's.
    DepthLength {
        /// Depth entries given.
        depth: usize,
        /// Colour entries given.
        color: usize,
    },
}

impl fmt::Display for TargetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TargetError::BadSize { width, height } => {
                write!(f, "frame size {width}x{height} outside 1..={MAX_DIMENSION}")
            }
            TargetError::ColorLength { len, width } => {
                write!(f, "colour slice of {len} pixels is not a whole number of {width}-pixel rows")
            }
            TargetError::BandOutsideFrame { first_row, rows, height } => {
                write!(f, "band rows {first_row}..{} outside a frame of {height} rows", first_row as usize + rows)
            }
            TargetError::DepthLength { depth, color } => {
                write!(f, "depth slice has {depth} entries but colour slice has {color}")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for TargetError {}

/// One horizontal band of a frame: the caller's colour slice plus a depth buffer.
pub struct Band<'a, C, D> {
    pub(crate) color: &'a mut [C],
    pub(crate) depth: D,
    pub(crate) width: u16,
    pub(crate) height: u16,
    pub(crate) first_row: u16,
    pub(crate) rows: u16,
}

impl<'a, C: FrameColor, D: DepthBuffer> Band<'a, C, D> {
    /// A band of `color.len() / width` rows starting at `first_row` of a `width` x `height`
    /// frame. For a whole frame pass `first_row = 0` and slices of `width * height`.
    ///
    /// # Errors
    /// [`TargetError`] when the size is out of range or a slice's length does not fit.
    pub fn new(color: &'a mut [C], depth: D, width: u16, height: u16, first_row: u16) -> Result<Self, TargetError> {
        if width == 0 || height == 0 || width > MAX_DIMENSION || height > MAX_DIMENSION {
            return Err(TargetError::BadSize { width, height });
        }
        let len = color.len();
        if len == 0 || !len.is_multiple_of(width as usize) {
            return Err(TargetError::ColorLength { len, width });
        }
        let rows = len / width as usize;
        if first_row as usize + rows > height as usize {
            return Err(TargetError::BandOutsideFrame { first_row, rows, height });
        }
        if let Some(depth_len) = depth.depth_len() {
            if depth_len != len {
                return Err(TargetError::DepthLength { depth: depth_len, color: len });
            }
        }
        Ok(Band { color, depth, width, height, first_row, rows: rows as u16 })
    }

    /// Fills the colour slice with `c` and resets depth to the far plane.
    pub fn clear(&mut self, c: C) {
        fill_in_blocks(self.color, c);
        self.depth.clear_depth();
    }

    /// Frame width in pixels.
    #[must_use]
    pub fn width(&self) -> u16 {
        self.width
    }

    /// Frame height in pixels.
    #[must_use]
    pub fn height(&self) -> u16 {
        self.height
    }

    /// First frame row of this band.
    #[must_use]
    pub fn first_row(&self) -> u16 {
        self.first_row
    }

    /// Number of rows in this band.
    #[must_use]
    pub fn rows(&self) -> u16 {
        self.rows
    }

    /// The colour slice.
    #[must_use]
    pub fn pixels(&self) -> &[C] {
        self.color
    }

    /// The depth buffer.
    pub fn depth(&mut self) -> &mut D {
        &mut self.depth
    }

    /// Where this band lies in its frame (for [`BandArea::run_start`]).
    #[inline(always)]
    pub(crate) fn area(&self) -> BandArea {
        BandArea { width: self.width as usize, rows: self.rows as usize, first_row: self.first_row as i32 }
    }
}

/// Where a band lies in its frame: the one test of whether pixels are inside a band, shared by
/// the span loop, lines and points, and embedded-graphics drawing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BandArea {
    width: usize,
    rows: usize,
    first_row: i32,
}

impl BandArea {
    /// The band's width in pixels: the distance between a pixel's entry and the next row's.
    #[cfg(span_asm)]
    #[inline(always)]
    pub(crate) fn width(&self) -> usize {
        self.width
    }

    /// The index in the band's slices of the first of the `len` pixels that start at frame
    /// pixel `(x, y)` and run right along its row, when all of them are inside the band.
    #[inline(always)]
    pub(crate) fn run_start(&self, x: i32, y: i32, len: usize) -> Option<usize> {
        // In u32, where nothing can overflow (widths and rows are at most MAX_DIMENSION);
        // a negative x or row becomes a huge value and fails the comparisons.
        let (row, x) = (y.wrapping_sub(self.first_row) as u32 as usize, x as u32 as usize);
        if row >= self.rows || x >= self.width || len > self.width - x {
            return None;
        }
        Some(row * self.width + x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The depth conversion without a saturating instruction is the clamped one over `0..=2^30`.
    #[test]
    fn u16_depth_by_shifts_is_the_clamped_shift() {
        let near_steps = (0..=1u32 << 16).flat_map(|k| [k << 14, (k << 14).saturating_sub(1), (k << 14) + 1]);
        for z in near_steps.filter(|&z| z <= 1 << 30) {
            assert_eq!(z_to_u16_by_shifts(z), ((z as i32) >> 14).clamp(0, 0xffff) as u32, "{z}");
        }
    }

    /// The block fill writes `value` to every entry of slices of every length and start
    /// (word-aligned or not, shorter than a block or not), and nothing beside them.
    #[test]
    fn fill_u16_in_blocks_fills_exactly_the_slice() {
        let mut buffer = [0u16; 80];
        for start in 0..4 {
            for len in 0..(buffer.len() - start - 1) {
                buffer.fill(7);
                fill_u16_in_blocks(&mut buffer[start..start + len], 0xabcd);
                for (i, &v) in buffer.iter().enumerate() {
                    let inside = (start..start + len).contains(&i);
                    assert_eq!(v, if inside { 0xabcd } else { 7 }, "start {start}, len {len}, entry {i}");
                }
            }
        }
    }

    /// The colour block fill writes `value` to every entry of slices of every length (shorter
    /// than a block or not), and nothing beside them.
    #[test]
    fn fill_in_blocks_fills_exactly_the_slice() {
        let mut buffer = [Rgb565::BLACK; 80];
        for start in 0..3 {
            for len in 0..(buffer.len() - start - 1) {
                buffer.fill(Rgb565::WHITE);
                fill_in_blocks(&mut buffer[start..start + len], Rgb565::RED);
                for (i, &v) in buffer.iter().enumerate() {
                    let inside = (start..start + len).contains(&i);
                    assert_eq!(
                        v,
                        if inside { Rgb565::RED } else { Rgb565::WHITE },
                        "start {start}, len {len}, entry {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn wrong_lengths_are_errors() {
        let mut c = [Rgb565::BLACK; 100];
        let mut z = [0u16; 99];
        assert!(matches!(Band::new(&mut c[..], &mut z[..], 10, 10, 0), Err(TargetError::DepthLength { .. })));
        assert!(matches!(Band::new(&mut c[..], NoDepth, 7, 100, 0), Err(TargetError::ColorLength { .. })));
        assert!(matches!(Band::new(&mut c[..], NoDepth, 10, 15, 6), Err(TargetError::BandOutsideFrame { .. })));
        assert!(matches!(Band::new(&mut c[..], NoDepth, 0, 15, 0), Err(TargetError::BadSize { .. })));
        assert!(Band::new(&mut c[..], NoDepth, 10, 15, 5).is_ok());
    }
}
