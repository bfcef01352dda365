//! Render targets: the caller's colour and depth slices for one band of the frame.
//!
//! A band is `rows` full-width rows starting at `first_row` of a `width` x `height` frame;
//! a whole frame is the band with `first_row = 0` and `rows = height`. The renderer only ever
//! writes inside the slices given here. It does not decide what is drawn (the pipeline does)
//! or talk to a display (`eg` and the caller do).

use core::fmt;

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, GrayColor, Rgb565, Rgb888, RgbColor};

/// The largest frame width or height. Screen positions are kept in 28.4 fixed point with a
/// guard band of [`GUARD_HALF_EXTENT`] pixels around the frame centre; larger frames would not
/// fit it.
pub const MAX_DIMENSION: u16 = 1536;

/// Half the guard band's size in pixels: geometry is clipped to within this distance of the
/// frame centre, so any triangle's edge functions fit in `i32` (see `raster`).
pub const GUARD_HALF_EXTENT: f32 = 960.0;

/// A pixel colour soft3d can render into, converted from 8-bit RGB without dynamic dispatch.
pub trait FrameColor: Copy {
    /// Converts from 8-bit RGB (rounding to nearest).
    fn from_rgb888(rgb: [u8; 3]) -> Self;
    /// Converts to 8-bit RGB.
    fn to_rgb888(self) -> [u8; 3];
    /// Whether [`FrameColor::from_rgb888_dithered`] depends on the position: false lets a draw
    /// asked to dither take the plain path (the same pixels, drawn faster). True unless a
    /// format says otherwise.
    const DITHERS: bool = true;
    /// Converts with ordered dithering for pixel `(x, y)` of the frame; formats with 8 bits per
    /// channel ignore the position.
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        let _ = (x, y);
        Self::from_rgb888(rgb)
    }
    /// An RGB565 texel lit by `light` (16.16 per channel): [`modulate`](crate::texture::modulate)
    /// of the widened texel, converted. RGB565 formats override it with
    /// [`modulate565`](crate::texture::modulate565), which stays in RGB565 (within one step).
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        let [r, g, b, _] = crate::format::decode_texel(crate::format::TextureFormat::Rgb565, &texel.to_le_bytes());
        Self::from_rgb888(crate::texture::modulate([r, g, b], light))
    }
    /// An RGB565 texel lit by white `light` (16.16) interpolated from vertex lights in 0..=1
    /// (so within `-1/64 .. 1 + 1/64`): [`FrameColor::from_lit_rgb565`] with the light on
    /// every channel. RGB565 formats override it with `texture::modulate565_white` (within one
    /// step of that; outside that range of light, some other colour).
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Self::from_lit_rgb565(texel, [light; 3])
    }
    /// [`FrameColor::from_white_lit_rgb565`] given the constants RGB565 formats use for it
    /// (see `texture::modulate565_white_with`); others ignore them.
    #[doc(hidden)]
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, light: i32, constants: [u32; 2]) -> Self {
        let _ = constants;
        Self::from_white_lit_rgb565(texel, light)
    }
}

/// The 4x4 Bayer matrix: thresholds 0..16.
const BAYER4: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// `v` (0..=255) scaled to `0..=max` with ordered dithering: the threshold `(t + 1/2) / 16`
/// replaces rounding's 1/2, so over a 4x4 tile the average equals `v · max / 255`.
#[inline]
fn narrow_dithered(v: u8, max: u32, x: u32, y: u32) -> u8 {
    let t = BAYER4[(y & 3) as usize][(x & 3) as usize] as u32;
    ((v as u32 * max * 32 + (2 * t + 1) * 255) / (255 * 32)).min(max) as u8
}

/// `v` (0..=255) scaled to `0..=max`, rounded to nearest.
const fn narrow_exact(v: u8, max: u32) -> u8 {
    ((v as u32 * max + 127) / 255) as u8
}

/// `v` (0..=max) scaled to 0..=255, rounded to nearest.
const fn widen_exact(v: u8, max: u32) -> u8 {
    ((v as u32 * 255 + max / 2) / max) as u8
}

/// Tables of [`narrow_exact`] (`widen == false`) or [`widen_exact`] for every `v`: per-pixel
/// conversions without division.
const fn table(widen: bool, max: u32) -> [u8; 256] {
    let mut t = [0; 256];
    let mut v = 0;
    while v < 256 {
        t[v] = if widen { widen_exact(v as u8, max) } else { narrow_exact(v as u8, max) };
        v += 1;
    }
    t
}
const NARROW5: [u8; 256] = table(false, 31);
const NARROW6: [u8; 256] = table(false, 63);
const WIDEN5: [u8; 256] = table(true, 31);
const WIDEN6: [u8; 256] = table(true, 63);

/// Rec. 601 luma of 8-bit RGB, in 0..=255.
#[inline]
#[must_use]
pub fn luma(rgb: [u8; 3]) -> u8 {
    ((rgb[0] as u32 * 77 + rgb[1] as u32 * 150 + rgb[2] as u32 * 29 + 128) >> 8) as u8
}

impl FrameColor for Rgb888 {
    const DITHERS: bool = false;
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Rgb888::new(rgb[0], rgb[1], rgb[2])
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [self.r(), self.g(), self.b()]
    }
}

impl FrameColor for Rgb565 {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Rgb565::new(NARROW5[rgb[0] as usize], NARROW6[rgb[1] as usize], NARROW5[rgb[2] as usize])
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        Rgb565::new(
            narrow_dithered(rgb[0], 31, x, y),
            narrow_dithered(rgb[1], 63, x, y),
            narrow_dithered(rgb[2], 31, x, y),
        )
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [WIDEN5[self.r() as usize], WIDEN6[self.g() as usize], WIDEN5[self.b() as usize]]
    }
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565(texel, light)))
    }
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565_white(
            texel, light,
        )))
    }
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, light: i32, constants: [u32; 2]) -> Self {
        Rgb565::from(embedded_graphics_core::pixelcolor::raw::RawU16::new(crate::texture::modulate565_white_with(
            texel, light, constants,
        )))
    }
}

impl FrameColor for Gray8 {
    const DITHERS: bool = false;
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Gray8::new(luma(rgb))
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], _: u32, _: u32) -> Self {
        // Gray8 keeps all 8 bits of luma: nothing to dither.
        Gray8::new(luma(rgb))
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        [self.luma(); 3]
    }
}

impl FrameColor for BinaryColor {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        BinaryColor::from(luma(rgb) >= 128)
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        BinaryColor::from(narrow_dithered(luma(rgb), 1, x, y) == 1)
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        if self.is_on() {
            [255; 3]
        } else {
            [0; 3]
        }
    }
}

/// RGB565 stored big-endian in memory, as most SPI displays (ST7789, ILI9341) want it: a
/// band of these can go to the display's DMA as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Rgb565Be(pub [u8; 2]);

impl FrameColor for Rgb565Be {
    #[inline]
    fn from_rgb888(rgb: [u8; 3]) -> Self {
        Self::from(Rgb565::from_rgb888(rgb))
    }
    #[inline]
    fn from_rgb888_dithered(rgb: [u8; 3], x: u32, y: u32) -> Self {
        Self::from(Rgb565::from_rgb888_dithered(rgb, x, y))
    }
    #[inline(always)]
    fn from_lit_rgb565(texel: u16, light: [i32; 3]) -> Self {
        Rgb565Be(crate::texture::modulate565(texel, light).to_be_bytes())
    }
    #[inline(always)]
    fn from_white_lit_rgb565(texel: u16, light: i32) -> Self {
        Rgb565Be(crate::texture::modulate565_white(texel, light).to_be_bytes())
    }
    #[inline(always)]
    fn from_white_lit_rgb565_with(texel: u16, light: i32, constants: [u32; 2]) -> Self {
        Rgb565Be(crate::texture::modulate565_white_with(texel, light, constants).to_be_bytes())
    }
    #[inline]
    fn to_rgb888(self) -> [u8; 3] {
        let v = u16::from_be_bytes(self.0);
        Rgb565::new((v >> 11) as u8, ((v >> 5) & 63) as u8, (v & 31) as u8).to_rgb888()
    }
}

impl From<Rgb565> for Rgb565Be {
    fn from(c: Rgb565) -> Self {
        let v = (c.r() as u16) << 11 | (c.g() as u16) << 5 | c.b() as u16;
        Rgb565Be(v.to_be_bytes())
    }
}

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

    #[test]
    fn dithering_keeps_the_average() {
        for v in [0u8, 1, 3, 7, 100, 128, 200, 254, 255] {
            let mut sum565 = 0u32;
            let mut sum1 = 0u32;
            for y in 0..4 {
                for x in 0..4 {
                    sum565 += Rgb565::from_rgb888_dithered([v, v, v], x, y).to_rgb888()[0] as u32;
                    sum1 += BinaryColor::from_rgb888_dithered([v, v, v], x, y).to_rgb888()[0] as u32;
                }
            }
            // Averages over a 4x4 tile land within half a quantization step of the input.
            assert!((sum565 as f32 / 16.0 - v as f32).abs() <= 255.0 / 31.0 / 2.0, "565 {v}: {sum565}");
            assert!((sum1 as f32 / 16.0 - v as f32).abs() <= 255.0 / 16.0 / 2.0 + 0.5, "mono {v}: {sum1}");
        }
        // A mid grey dithers to both neighbouring levels.
        let levels: [u8; 4] = core::array::from_fn(|x| Rgb565::from_rgb888_dithered([130, 130, 130], x as u32, 0).r());
        assert!(levels.iter().min() != levels.iter().max());
    }

    #[test]
    fn colour_conversions() {
        assert_eq!(Rgb565::from_rgb888([255, 128, 0]), Rgb565::new(31, 32, 0));
        assert_eq!(Rgb565::new(31, 63, 0).to_rgb888(), [255, 255, 0]);
        assert_eq!(Rgb565Be::from_rgb888([255, 0, 0]).0, [0xF8, 0x00]);
        assert_eq!(Gray8::from_rgb888([255, 255, 255]), Gray8::new(255));
        assert_eq!(BinaryColor::from_rgb888([200, 200, 200]), BinaryColor::On);
        assert_eq!(BinaryColor::from_rgb888([20, 20, 20]), BinaryColor::Off);
    }
}
