//! Triangle rasterization: integer edge functions in 28.4 fixed point, exact spans per row,
//! perspective-correct varyings; the per-pixel loop only adds integers.
//!
//! # Numbers
//! - Vertex positions are snapped to 1/16 pixel (28.4). The pipeline clips geometry to a guard
//!   band of ±[`GUARD_HALF_EXTENT`](crate::target::GUARD_HALF_EXTENT) pixels around the frame
//!   centre, so a triangle spans at most 1920 pixels = 30,720 units < 2^15 on either axis and
//!   every edge function evaluated inside its bounding box, `A·dx + B·dy` with
//!   `|A|, |B|, |dx|, |dy| < 2^15`, fits in `i32`.
//! - Edge function of edge a→b at p: `E = (bx-ax)(py-ay) - (by-ay)(px-ax)` (image y down);
//!   triangles are reordered so that the inside is `E > 0` for all three edges.
//! - Fill rule (spec): a centre exactly on an edge (`E == 0`) is inside only if that edge is a
//!   left edge (`A > 0`) or a bottom horizontal edge (`A == 0 && B < 0`), where `A = ay - by`
//!   and `B = bx - ax` are the coefficients of `px` and `py`.
//! - Depth is affine in screen space and interpolated from a plane in 24.40 fixed point
//!   (`i64`); it reaches the depth buffer as 0..=2^30. The per-triangle values (this plane, the
//!   affine varyings' planes, the `1/w`s divided by the largest) come from f32 arithmetic in a
//!   set-up for f32 perspective, and from integers otherwise (see `affine`,
//!   `perspective::normalised_q`): each the same bits on every target, and the integer one
//!   runs no soft-float where there is no FPU.
//! - Varyings (texture coordinates, light, normals) are `i32` with 16 fractional bits,
//!   interpolated with perspective-correct barycentrics `b_i = (E_i/w_i) / Σ(E_j/w_j)` (in
//!   integers, alike on every target and without soft-float: see `perspective`; or in f32,
//!   whose basic operations round alike on every target, where an FPU makes that cheaper:
//!   [`Setup::use_fpu_perspective`]) computed exactly every `subspan` pixels along a span and
//!   linearly in between (`subspan = 1`: every pixel exact), or, within
//!   a chosen tolerance ([`Setup::allow_affine`]), from one affine plane per varying (the whole
//!   triangle) or exactly at the ends of runs as long as the tolerance allows (`subspan = 1`);
//!   with an FPU, where a bound allows, in f32 at every pixel (see `pixel`); with an FPU, for
//!   triangles whose box holds at most `SMALL_BOX` pixel centres, exactly at every covered
//!   pixel (see `small`).
//! - Pixels reach the shader as runs ([`Span`]s): a run of pixels on one row with a first value
//!   and a per-pixel step for depth and every varying, so the per-pixel loop only adds. The span
//!   loop either walks the rows itself ([`Setup::walked_rows`], one run a row, no call) or gets
//!   the runs through `dyn` ([`Setup::for_each_span`]); both give the same runs, bit for bit.
//!
//! Every value here is a function of the triangle and the pixel only, never of the band being
//! drawn, so a frame drawn in bands is bit-identical to the frame drawn whole. It does not
//! decide what a pixel looks like (`fragment` and `span` do) or clip (`clip` does).

use super::varyings::ScreenVaryings;
use crate::fixed::{Depth40, FDot16, FDot4};
use crate::math::{max, min, times_power_of_two, wrapping_mul_small, F32};

mod affine;
#[cfg(any(no_hw_divide, test))]
mod divide;
mod facing;
mod perspective;
mod pixel;
mod rows;
mod runs;
#[cfg(test)]
mod slivers;
#[cfg(any(not(soft_float), test))]
mod small;
mod walk;
use affine::{AffinePlanes, AreaReciprocal};
pub(crate) use facing::{area_in_guard_band, facing_in_guard_band, facing_of, in_guard_band};
pub use facing::{facing, MAX_COORD, MAX_EXTENT};
pub(crate) use perspective::{leading_zeros, mul_i32, mul_u32, reciprocal};
use perspective::{Q_BITS, Q_MIN};
use pixel::f32_varyings;
#[cfg(all(span_asm, not(soft_float)))]
pub(crate) use pixel::{PixelRows, PixelRun};
#[cfg(span_asm)]
pub(crate) use rows::PlainRows;
pub(crate) use rows::{AffineRows, WalkedRow, WalkedRows};
pub use runs::{step_varyings, Span, SpanSink};
#[cfg(not(soft_float))]
pub(crate) use small::{SmallTriangle, SMALL_BOX};
use walk::RowWalk;

/// Added to [`Setup`]'s edge shift (below 32) for narrow integer weights.
const NARROW: u32 = 32;

/// A vertex after projection: what the rasterizer needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenVertex {
    /// x in 1/16 pixel, image coordinates.
    pub x: FDot4,
    /// y in 1/16 pixel, image coordinates, y down.
    pub y: FDot4,
    /// Depth 0 (near) ..= 1 (far): `(z/w + 1) / 2`.
    pub z: f32,
    /// `1 / w`.
    pub inv_w: f32,
    /// Attributes, already in their fixed-point units (16 fractional bits). A [`Setup`] of
    /// `V` varyings uses the first `V`.
    pub varyings: ScreenVaryings,
}

/// What the set-up reads of a corner: a [`ScreenVertex`] with only the `V` varyings a variant
/// interpolates (built where the variant is known, so the common path carries no more).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Corner<const V: usize> {
    /// x and y in 1/16 pixel, as [`ScreenVertex`]'s.
    pub(crate) x: FDot4,
    pub(crate) y: FDot4,
    /// Depth 0 (near) ..= 1 (far).
    pub(crate) z: f32,
    /// `1 / w`.
    pub(crate) inv_w: f32,
    /// The first `V` varyings.
    pub(crate) v: [FDot16; V],
}

impl<const V: usize> Corner<V> {
    /// The corner at `(x, y)` (28.4) with depth `z`, `1/w` and the first `V` of `varyings`.
    #[inline(always)]
    pub(crate) fn new((x, y): (FDot4, FDot4), z: f32, inv_w: f32, varyings: &ScreenVaryings) -> Self {
        const { assert!(V <= super::varyings::MAX_VARYINGS) };
        Corner { x, y, z, inv_w, v: core::array::from_fn(|k| varyings[k]) }
    }

    /// The corner of a screen vertex.
    #[inline(always)]
    pub(crate) fn of(s: &ScreenVertex) -> Self {
        Self::new((s.x, s.y), s.z, s.inv_w, &s.varyings)
    }
}

/// Rows and columns a triangle may touch: the band, in frame pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// Frame width in pixels.
    pub width: i32,
    /// First row (inclusive).
    pub row_start: i32,
    /// Last row (exclusive).
    pub row_end: i32,
}

/// One edge: `E(px, py) = a·(px - ox) + b·(py - oy) + c`, with the tie-break bias folded into
/// `c` so that a pixel is inside when `E >= 0` for all three edges.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: i32,
    b: i32,
    c: i32,
}

impl Edge {
    /// The edge from `p` to `q`, with its origin at the pixel-centre `(ox, oy)` (28.4). The
    /// origin lies in the triangle's bounding box, so `|ox - p.x|` and `|oy - p.y|` are below
    /// `MAX_EXTENT` as `a` and `b` are, and `c` below `2·MAX_EXTENT²` < 2^31 (see `facing`).
    fn new<const V: usize>(p: &Corner<V>, q: &Corner<V>, ox: i32, oy: i32) -> Edge {
        let a = p.y - q.y;
        let b = q.x - p.x;
        let owned = a > 0 || (a == 0 && b < 0);
        let c = a * (ox - p.x) + b * (oy - p.y) - i32::from(!owned);
        Edge { a, b, c }
    }
}

/// A triangle's corners in the set-up's order (reordered so that the inside is `E > 0`: positive
/// image-space area, given as `area`), the origin pixel centre (28.4) and its frame row, and the
/// edges from that origin. The origin is the first pixel centre of the box *in the frame*, not
/// in the band, so that every interpolated value is the same whichever band draws the pixel.
#[inline(always)]
fn oriented<'t, const V: usize>(
    tri: &'t [Corner<V>; 3],
    bbox: &CoveredBox,
    area: i32,
) -> ([&'t Corner<V>; 3], (i32, i32), i32, [Edge; 3]) {
    let [p0, p1, p2] = tri;
    let (a, b, c) = if area > 0 { (p0, p1, p2) } else { (p0, p2, p1) };
    let fy0 = first_centre(bbox.min_y).max(0);
    let (ox, oy) = (bbox.x0 * 16 + 8, fy0 * 16 + 8);
    let edges = [Edge::new(b, c, ox, oy), Edge::new(c, a, ox, oy), Edge::new(a, b, ox, oy)];
    ([a, b, c], (ox, oy), fy0, edges)
}

/// The `1/w`s `inv_w` of a triangle's vertices (positive and finite) divided by the largest, in
/// f32: that one exactly 1.
#[inline(always)]
fn normalised_inv_w(inv_w: [f32; 3]) -> [F32; 3] {
    let max_w = F32(max(max(inv_w[0], inv_w[1]), inv_w[2]));
    inv_w.map(|q| F32(q) / max_w)
}

/// `floor(n / d)` for `d > 0`.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn floor_div(n: i32, d: i32) -> i32 {
    debug_assert!(d > 0);
    let q = n / d;
    if n - q * d < 0 {
        q - 1
    } else {
        q
    }
}

/// The first pixel row or column whose centre (`16k + 8`) is at or after `p` (28.4):
/// `ceil((p - 8) / 16)`, as a shift (`p` within the guard band, so `p + 7` fits).
#[inline(always)]
pub(crate) fn first_centre(p: i32) -> i32 {
    (p + 7) >> 4
}

/// The last pixel row or column whose centre is at or before `p` (28.4): `floor((p - 8) / 16)`.
#[inline(always)]
pub(crate) fn last_centre(p: i32) -> i32 {
    (p - 8) >> 4
}

/// A triangle ready to rasterize: edges, depth plane and varyings relative to the origin pixel.
pub struct Setup<const V: usize> {
    edges: [Edge; 3],
    /// The middle vertex's height (by y) below the origin row's centres, 28.4 (see
    /// `walk::RowWalk`).
    to_mid: i32,
    /// Bounding box in pixels (inclusive), already clipped to the frame.
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
    /// Frame row of the origin pixel centre (the bounding box's top row, unclipped by the band).
    origin_row: i32,
    /// Rows of the bounding box below the origin row, unclipped by the band.
    rows_below: i32,
    /// Depth at the origin pixel centre, and per pixel in x and y, 24.40.
    z_origin: Depth40,
    z_dx: Depth40,
    z_dy: Depth40,
    /// 1/w of each vertex divided by the largest, in `Q_BITS` fixed point (so in
    /// `Q_MIN..=1 << Q_BITS`, the largest exactly `1 << Q_BITS`).
    q: [u32; 3],
    /// The smallest of `q`, also where `q` is not worked out (see [`Setup::with_area`]).
    q_min: u32,
    /// The left shift of edge functions for [`perspective::weights`], plus [`NARROW`] where the
    /// integer weights come from 16-bit operands ([`perspective::narrow_weights`]: `1/w`s
    /// within a factor of two and varyings spanning under 2^20 units, decided with the
    /// tolerance in [`Setup::allow_affine`]). One field, not two: the common path's set-up
    /// stays as it was.
    e_shift: u32,
    /// The same 1/w divided by the largest, in f32 (in (0, 1], the largest exactly 1).
    inv_w: [F32; 3],
    /// Whether perspective is worked out in f32 (see [`Setup::use_fpu_perspective`]).
    fpu: bool,
    /// Varyings at vertex 0 and their differences to vertices 1 and 2 (wrapping).
    v0: [FDot16; V],
    d1: [i32; V],
    d2: [i32; V],
    /// Twice the triangle's area in 1/256 pixel², positive (below 2^31, see
    /// `facing_in_guard_band`).
    area: u32,
    /// `1 / area` for the planes in integers, made once where they are (without f32
    /// perspective: see [`Setup::with_area`]), on targets without an FPU.
    #[cfg(soft_float)]
    inverse: Option<AreaReciprocal>,
    /// Affine varyings when allowed (see [`Setup::allow_affine`]).
    affine: Option<AffinePlanes<V>>,
    /// Four times the tolerance of each varying, saturated (0: no shortcut where `1/w` varies).
    tolerance: [u32; V],
}

/// The pixel centres a triangle's bounding box holds in a window (inclusive, in frame
/// pixels), and the box's top and bottom (28.4).
#[derive(Clone, Copy)]
pub(crate) struct CoveredBox {
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
    min_y: i32,
    max_y: i32,
}

impl CoveredBox {
    /// Pixel centres in the box in the frame: its columns (clipped to the frame) times its rows
    /// not clipped by the band, so that every band makes the same choice with it (see
    /// `small::SMALL_BOX`).
    #[cfg(any(not(soft_float), test))]
    #[inline(always)]
    pub(crate) fn frame_pixels(&self) -> u32 {
        let rows = last_centre(self.max_y) - first_centre(self.min_y).max(0) + 1;
        ((self.x1 - self.x0 + 1) as u32).saturating_mul(rows.max(0) as u32)
    }

    /// The box of `tri` in `win`, `None` when it holds no pixel centre of the window.
    #[inline(always)]
    pub(crate) fn of<const V: usize>(tri: &[Corner<V>; 3], win: &Window) -> Option<Self> {
        let [a, b, c] = tri;
        // Pixel rows/columns whose centres (16k + 8) lie inside the bounding box.
        let (min_x, max_x) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        let (min_y, max_y) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let x0 = first_centre(min_x).max(0);
        let x1 = last_centre(max_x).min(win.width.saturating_sub(1));
        let y0 = first_centre(min_y).max(win.row_start.max(0));
        let y1 = last_centre(max_y).min(win.row_end.saturating_sub(1));
        (x0 <= x1 && y0 <= y1).then_some(CoveredBox { x0, x1, y0, y1, min_y, max_y })
    }
}

/// Result of [`Setup::new`] when nothing is to be drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reject {
    /// Zero area after snapping.
    Degenerate,
    /// Back-facing while back faces are culled.
    BackFace,
    /// No pixel centre of the window is covered.
    Empty,
    /// A vertex lies outside the guard band or has a non-finite or non-positive `1/w`
    /// (only float rounding at clipping produces one).
    OutsideGuardBand,
}

impl<const V: usize> Setup<V> {
    /// Prepares `tri` for rasterization into `win`. `cull_back`: refuse back faces (front faces
    /// wind counter-clockwise with y up, see the crate's conventions); `flip` inverts which
    /// winding counts as front (negative-determinant transforms).
    ///
    /// # Errors
    /// The [`Reject`] that says why nothing is drawn.
    pub fn new(tri: &[ScreenVertex; 3], win: &Window, cull_back: bool, flip: bool) -> Result<Self, Reject> {
        let (corners, area) = (tri.each_ref().map(Corner::of), facing(tri, cull_back, flip)?);
        let mut setup = Self::with_area(&corners, win, area, false)?;
        // For `use_fpu_perspective`, which only a set-up made here may be switched to: the
        // vertices in `with_area`'s order.
        let [a, b, c] = corners.map(|c| c.inv_w);
        setup.inv_w = normalised_inv_w(if area > 0 { [a, b, c] } else { [a, c, b] });
        Ok(setup)
    }

    /// [`Setup::new`] for a triangle that already passed [`facing`], which gave `area`; with
    /// `fpu`, as [`Setup::use_fpu_perspective`] makes it, without the integer perspective's
    /// per-triangle values (and with the depth plane in f32); without, with no f32 values
    /// (the depth plane and `1/w`s in integers).
    #[inline(always)]
    pub(crate) fn with_area(tri: &[Corner<V>; 3], win: &Window, area: i32, fpu: bool) -> Result<Self, Reject> {
        let bbox = CoveredBox::of(tri, win).ok_or(Reject::Empty)?;
        Ok(Self::in_box(tri, &bbox, area, fpu))
    }

    /// [`Setup::with_area`] of a triangle whose [`CoveredBox`] is `bbox` (infallible: built in
    /// place, not moved out of a `Result`). Out of line with an FPU: its temporaries then stay
    /// out of the frame of `fragment::fragments`, which lives on under the row walks (core stack
    /// -88 bytes; Cortex-M4F reference frame -7.6k instructions, by the registers it frees);
    /// inlined without one (thumbv6m +46k otherwise).
    #[cfg_attr(soft_float, inline(always))]
    #[cfg_attr(not(soft_float), inline(never))]
    pub(crate) fn in_box(tri: &[Corner<V>; 3], bbox: &CoveredBox, area: i32, fpu: bool) -> Self {
        let CoveredBox { x0, x1, y0, y1, min_y, max_y } = *bbox;
        let ([a, b, c], (ox, oy), fy0, edges) = oriented(tri, bbox, area);

        // Depth plane from the three vertices: in f32 with f32 perspective (an FPU's few
        // instructions; `F32`: deterministic on every target) where that is accurate, else in
        // integers (no soft-float without an FPU; see `affine::integer_depth_plane`).
        // Made once for both the depth plane and the affine planes where they are in integers
        // (thumbv6m reference frame: -60k instructions). Not kept with an FPU, whose draws
        // take them in f32 (the Cortex-M4F's frame costs 5k more with the field).
        #[cfg(soft_float)]
        let inverse = (!fpu).then(|| AreaReciprocal::new(area.unsigned_abs()));
        #[cfg(not(soft_float))]
        let inverse = None;
        let corners = [a, b, c].map(|v| (v.x, v.y, v.z));
        let (z_origin, z_dx, z_dy) = affine::depth_plane(corners, area, (ox, oy), (fpu, inverse.as_ref()));

        // Divided by the largest, positive and finite (`facing`): that one becomes exactly 1,
        // the others at most that: in f32 where f32 works perspective out, else in `Q_BITS`
        // fixed point (at least `Q_MIN`, see `perspective::normalised_q`). Their smallest in
        // fixed point always (truncating keeps the order).
        let (inv_w, q, q_min) = if fpu {
            let inv_w = normalised_inv_w([a.inv_w, b.inv_w, c.inv_w]);
            let one = F32((1u32 << Q_BITS) as f32);
            let q_min = F32(min(min(inv_w[0].0, inv_w[1].0), inv_w[2].0));
            let q_min = crate::math::f32_to_i64(times_power_of_two(q_min.0, one.0)).clamp(Q_MIN.into(), 1 << Q_BITS);
            (inv_w, [1 << Q_BITS; 3], q_min as u32)
        } else {
            // Not read: f32 perspective is not used (see `Setup::new` for the one way to it).
            let q = perspective::normalised_q([a.inv_w, b.inv_w, c.inv_w]);
            ([F32(1.0); 3], q, q[0].min(q[1]).min(q[2]))
        };

        let v0 = a.v;
        let d1 = core::array::from_fn(|k| b.v[k].wrapping_sub(a.v[k]));
        let d2 = core::array::from_fn(|k| c.v[k].wrapping_sub(a.v[k]));
        Setup {
            edges,
            // The median of the three.
            to_mid: a.y + b.y + c.y - min_y - max_y - oy,
            x0,
            x1,
            y0,
            y1,
            origin_row: fy0,
            rows_below: last_centre(max_y) - fy0,
            z_origin,
            z_dx,
            z_dy,
            q,
            q_min,
            e_shift: perspective::edge_shift(area.unsigned_abs()),
            inv_w,
            fpu,
            v0,
            d1,
            d2,
            area: area.unsigned_abs(),
            #[cfg(soft_float)]
            inverse,
            affine: None,
            tolerance: [0; V],
        }
    }

    /// Rows this triangle covers in the window, as `first..=last`.
    #[must_use]
    pub fn rows(&self) -> (i32, i32) {
        (self.y0, self.y1)
    }

    /// Works this triangle's perspective-correct varyings out in f32 instead of integers:
    /// fewer instructions with an FPU (one division instead of a reciprocal's Newton steps),
    /// and soft-float without one. Both are within the same bounds of the exact values, and
    /// each gives the same bits on every target (f32's basic operations round alike
    /// everywhere), but not the same bits as the other: a draw picks one for all its
    /// triangles (`RenderOptions::fixed_vertices` picks integers). The depth plane stays that
    /// of [`Setup::new`] (in integers); affine planes allowed after this are made in f32.
    pub fn use_fpu_perspective(&mut self) {
        self.fpu = true;
    }

    /// Perspective-correct varyings where the edge functions are `e` (negative ones count as
    /// 0), and `Σ E_k/w_k` there (proportional to the pixel's `1/w`, 0 where every `E_k` is).
    ///
    /// In integers (see [`perspective`]): the same on every target, and no soft-float where
    /// there is no FPU; or in f32 (see [`Setup::use_fpu_perspective`]).
    #[inline(always)]
    fn varyings_at(&self, e: [i32; 3]) -> ([i32; V], u32) {
        if self.fpu {
            return self.varyings_at_f32(e);
        }
        self.varyings_in_integers(e)
    }

    /// [`Setup::varyings_at`] in integers.
    #[inline(always)]
    fn varyings_in_integers(&self, e: [i32; 3]) -> ([i32; V], u32) {
        let weights = if self.e_shift >= NARROW {
            perspective::narrow_weights(e, self.e_shift - NARROW, &self.q)
        } else {
            perspective::weights(e, self.e_shift, &self.q)
        };
        match weights {
            Some((w, sum)) => {
                // A loop, not `array::from_fn`: that is a call of its own on Armv6-M (not
                // inlined).
                let (mut out, narrow) = (self.v0, self.e_shift >= NARROW);
                for (k, o) in out.iter_mut().enumerate() {
                    *o = if narrow {
                        perspective::narrow_interpolate(*o, self.d1[k], self.d2[k], w)
                    } else {
                        perspective::interpolate(*o, self.d1[k], self.d2[k], w)
                    };
                }
                (out, sum)
            }
            None => (self.v0, 0),
        }
    }

    /// Whether stepping linearly from `(a, qa)` to `(b, qb)` (exact varyings and `1/w` weights
    /// at a segment's ends) stays within the tolerance: the same bound as for the whole
    /// triangle (see [`Setup::allow_affine`]), for a segment of one row.
    #[inline]
    fn linear_within(&self, (a, qa): &([i32; V], u32), (b, qb): &([i32; V], u32)) -> bool {
        let dv = core::array::from_fn(|k| b[k].wrapping_sub(a[k]));
        if self.fpu {
            // The sums are f32 bits there (see `varyings_at_f32`). 0 gives an infinite or NaN
            // ratio: refused.
            let (qa, qb) = (F32(f32::from_bits(*qa)), F32(f32::from_bits(*qb)));
            let ratio = (qa - qb).abs() / F32(min(qa.0, qb.0));
            return (0..V).all(|k| F32::from(dv[k]).abs() * ratio <= F32::from(self.tolerance[k]));
        }
        perspective::linear_within(dv, (*qa, *qb), &self.tolerance, self.e_shift >= NARROW)
    }

    /// [`Setup::varyings_at`] in f32 (see [`f32_varyings`]).
    #[inline(always)]
    fn varyings_at_f32(&self, e: [i32; 3]) -> ([i32; V], u32) {
        f32_varyings(e, &self.inv_w, &self.v0, |k| (F32::from(self.d1[k]), F32::from(self.d2[k])))
    }

    /// Allows affine (screen-linear) varyings when that is provably within `tolerance[k]`
    /// units of the perspective-correct value for every varying `k`; see [`Setup::is_affine`].
    ///
    /// With screen-space barycentrics `b_i` and `q_i = 1/w_i`, the perspective-correct value
    /// minus the affine one is `Σ b_i (v_i - c)(q_i/Q - 1)` for any constant `c`, where
    /// `Q = Σ b_i q_i`; taking `c` mid-range bounds it by `range(v) · (q_max - q_min) / (4 Q)`.
    /// So when `range(v_k) · (q_max/q_min - 1) <= 4 · tolerance[k]` for every `k`, the whole
    /// triangle is drawn from one plane per varying, with no division per pixel or per row.
    /// Otherwise, with `subspan == 1`, runs of a row step linearly between exact ends when the
    /// same bound holds for the run. The tolerance is on top of stepping's own rounding: under
    /// one unit (of 2^-16) per pixel of a run, which the exact path has too for `subspan > 1`.
    /// With equal `1/w` everywhere (e.g. an orthographic camera) affine is exact and always used.
    /// Exact values in integers come from 16-bit operands after this where the triangle allows
    /// (see [`perspective::narrow_weights`]).
    #[cfg_attr(not(soft_float), inline(always))]
    pub fn allow_affine(&mut self, tolerance: [u32; V]) {
        let q_min = self.q_min;
        let range = |k: usize| {
            // `max(d1, d2, 0) - min(d1, d2, 0)`: below 2^32, exact in u32.
            let (d1, d2) = (self.d1[k], self.d2[k]);
            let (hi, lo) = if d1 > d2 { (d1, d2) } else { (d2, d1) };
            hi.max(0).wrapping_sub(lo.min(0)) as u32
        };
        let within = (0..V).all(|k| perspective::affine_within(range(k), q_min, tolerance[k].saturating_mul(4)));
        // Exact values are worked out only where the varyings are not affine.
        if !within && !self.fpu && perspective::is_narrow(q_min, (0..V).map(range)) {
            self.e_shift |= NARROW;
        }
        let extent = (self.x1 - self.x0, self.rows_below);
        self.affine = within
            .then(|| {
                if self.fpu {
                    let (d1, d2) = (self.d1.map(F32::from), self.d2.map(F32::from));
                    AffinePlanes::new(&self.edges, F32::from(self.area), (&self.v0, &d1, &d2), extent)
                } else {
                    #[cfg(soft_float)]
                    let inverse = self.inverse.unwrap_or_else(|| AreaReciprocal::new(self.area));
                    #[cfg(not(soft_float))]
                    let inverse = AreaReciprocal::new(self.area);
                    AffinePlanes::in_integers(&self.edges, &inverse, (&self.v0, &self.d1, &self.d2), extent)
                }
            })
            .flatten();
        self.tolerance = tolerance.map(|t| t.saturating_mul(4));
    }

    /// Whether varyings are interpolated affinely (see [`Setup::allow_affine`]).
    #[must_use]
    pub fn is_affine(&self) -> bool {
        self.affine.is_some()
    }

    /// The covered rows of the window, top to bottom: `(y, dy, lo, hi)` with `y` the frame row,
    /// `dy` its distance below the origin row and `lo..=hi` the covered columns (relative to
    /// `x0`). Rows are measured from the origin row in frame coordinates (see `new`), so every
    /// band starts its edge walks where the whole frame's would be on that row.
    #[inline(always)]
    fn covered_rows(&self) -> impl Iterator<Item = (i32, i32, i32, i32)> + '_ {
        let mut walk = self.row_walk();
        (self.y0..=self.y1).filter_map(move |y| {
            let (lo, hi) = walk.next_row(self.x1 - self.x0);
            (lo <= hi).then_some((y, y - self.origin_row, lo, hi))
        })
    }

    /// The edge walks of the window's rows, from its first (see [`Setup::covered_rows`]).
    #[inline(always)]
    fn row_walk(&self) -> RowWalk {
        RowWalk::new(&self.edges, self.to_mid, self.y0 - self.origin_row)
    }

    /// Depth (24.40) at column `x` of the row `dy` below the origin. Wrapping: exact whenever
    /// the depth is representable; needle triangles with absurd gradients only get clamped
    /// garbage, never a panic.
    #[inline(always)]
    fn depth_at(&self, x: i32, dy: i32) -> Depth40 {
        self.z_origin.wrapping_add(wrapping_mul_small(self.z_dx, x)).wrapping_add(wrapping_mul_small(self.z_dy, dy))
    }
}
