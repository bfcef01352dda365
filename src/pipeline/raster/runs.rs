//! The runs a [`Setup`] hands a [`SpanSink`] through `dyn` ([`Setup::for_each_span`]): a
//! triangle's rows one [`Span`] each when it is affine, else cut into runs with exact
//! perspective-correct values at their ends ([`Setup::row_spans`]), and the span loop's side
//! of that hand-over ([`Span`], [`SpanSink`]). The variants whose span loop walks its rows
//! itself take their cut rows, and the rare triangles no walk takes, from here (see `rows`).

use super::Setup;
use crate::fixed::{depth40_to_30, Depth30, Depth40, FDot16, DEPTH30_FAR};
use crate::math::wrapping_mul_small;

impl<const V: usize> Setup<V> {
    /// Hands every covered run of pixels to `sink` as [`Span`]s, row by row, left to right:
    /// one span per row when the triangle [`is_affine`](Setup::is_affine); else runs with exact
    /// perspective-correct varyings at their first pixel, of `subspan` pixels when it is above
    /// 1, or (with `subspan == 1` and a tolerance from [`Setup::allow_affine`]) as long as the
    /// tolerance allows stepping linearly between exact ends, halving until it does.
    ///
    /// The sink is called through `dyn`: one out-of-line [`Setup::row_spans`] per varying count
    /// instead of one per shader (flash), at the cost of an indirect call per span; this loop
    /// over the rows is inlined where it is called. The common variants walk the same rows
    /// without that call ([`Setup::walked_rows`]).
    #[inline(always)]
    pub fn for_each_span(&self, subspan: u32, sink: &mut dyn SpanSink<V>) {
        // Beyond 4096 no span is long enough to tell the difference; the cap keeps x + subspan
        // from overflowing.
        let subspan = subspan.clamp(1, 1 << 12) as i32;
        for row in self.covered_rows() {
            self.row_spans(sink, subspan, row);
        }
    }

    /// The runs of the covered row `(y, dy, lo, hi)` (see [`Setup::covered_rows`]), as
    /// [`Setup::for_each_span`] hands them out. Out of line: its temporaries (the exact rows')
    /// in a frame of their own, above the span loop's, not in the frame of every caller (the
    /// variants that walk their rows call it for a row cut into runs, under their set-up's
    /// frame: the deepest stack). `subspan` in `1..=4096`, as `for_each_span` clamps it.
    #[inline(never)]
    pub(crate) fn row_spans(&self, sink: &mut dyn SpanSink<V>, subspan: i32, (y, dy, lo, hi): (i32, i32, i32, i32)) {
        debug_assert!((1..=1 << 12).contains(&subspan), "subspan {subspan}");
        match &self.affine {
            Some(p) => {
                let (v, dv) = p.at(lo, dy);
                self.emit(sink, y, lo, hi + 1, self.depth_at(lo, dy), v, dv);
            }
            None => self.exact_row(sink, subspan, (y, dy, lo, hi)),
        }
    }

    /// One row with perspective-correct varyings: runs with exact values at their ends (see
    /// [`Setup::for_each_span`]).
    #[inline(always)]
    fn exact_row(&self, sink: &mut dyn SpanSink<V>, subspan: i32, (y, dy, lo, hi): (i32, i32, i32, i32)) {
        let z = self.depth_at(lo, dy);
        let e: [i32; 3] = core::array::from_fn(|k| {
            let edge = &self.edges[k];
            edge.c + edge.b * 16 * dy + edge.a * 16 * lo
        });
        let e_at = |x: i32| -> [i32; 3] { core::array::from_fn(|k| e[k] + self.edges[k].a * 16 * (x - lo)) };
        let exact = |x: i32| self.varyings_at(e_at(x));
        let adaptive = subspan == 1 && self.tolerance.iter().any(|&t| t > 0);
        let mut xs = lo;
        let mut start = exact(xs);
        // Adaptive: the next segment's length to try, from the last one that passed (per row
        // only, so that every band makes the same choices).
        let mut try_len = hi - lo;
        while xs <= hi {
            let z = z.wrapping_add(wrapping_mul_small(self.z_dx, xs - lo));
            if xs == hi {
                // The last pixel of the span on its own.
                self.emit(sink, y, xs, xs + 1, z, start.0, [0; V]);
                break;
            }
            // The segment's far end: `subspan` pixels on, or (adaptive) as far as linear steps
            // are provably close enough, halving the distance until they are.
            let mut xe = if adaptive { (xs + try_len).min(hi) } else { (xs + subspan).min(hi) };
            let mut end = exact(xe);
            while adaptive && xe > xs + 1 && !self.linear_within(&start, &end) {
                xe = xs + (xe - xs) / 2;
                end = exact(xe);
            }
            let len = xe - xs;
            try_len = 2 * len;
            let step = core::array::from_fn(|k| {
                let diff = end.0[k].wrapping_sub(start.0[k]);
                if len == subspan && subspan.count_ones() == 1 {
                    diff >> subspan.trailing_zeros()
                } else {
                    super::rows::divide_step(diff, len)
                }
            });
            if adaptive && xe == hi {
                // Within tolerance up to the span's end: its last pixel steps there too.
                self.emit(sink, y, xs, xe + 1, z, start.0, step);
                break;
            }
            self.emit(sink, y, xs, xe, z, start.0, step);
            xs = xe;
            start = end;
        }
    }

    /// Sends columns `xs..xe` (relative to `x0`) of row `y` to `sink`, with depth `z` (24.40)
    /// at `xs`. Depth is stepped in 2.30; where float rounding at setup lets the stepped depth
    /// leave 0..=2^30 (triangles touching the near or far plane), pixels go one by one, clamped.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn emit(&self, sink: &mut dyn SpanSink<V>, y: i32, xs: i32, xe: i32, z: Depth40, v: [FDot16; V], dv: [FDot16; V]) {
        let (len, first, x) = (xe - xs, depth40_to_30(z), self.x0 + xs);
        // The per-pixel depth step in 2.30, when it fits and keeps the whole run in 0..=2^30.
        let last = |dz: i32| first + dz as i64 * (len - 1) as i64;
        let stepped = i32::try_from(depth40_to_30(self.z_dx))
            .ok()
            .filter(|&dz| (0..=DEPTH30_FAR).contains(&first) && (0..=DEPTH30_FAR).contains(&last(dz)));
        if let Some(dz) = stepped {
            sink.span(&Span { y, x, len: len as u32, z: first as Depth30, dz, v, dv });
            return;
        }
        // Depth leaves 0..=2^30 somewhere in the run (a triangle touching the near or far
        // plane, or float rounding in a needle triangle's depth plane): pixel by pixel, clamped.
        let mut v = v;
        for k in 0..len {
            let z = depth40_to_30(z.wrapping_add(wrapping_mul_small(self.z_dx, k))).clamp(0, DEPTH30_FAR) as Depth30;
            sink.span(&Span { y, x: x + k, len: 1, z, dz: 0, v, dv });
            step_varyings(&mut v, &dv);
        }
    }
}

/// Adds one pixel's steps to the varyings (wrapping, like every varying sum).
#[inline(always)]
pub fn step_varyings<const V: usize>(v: &mut [i32; V], dv: &[i32; V]) {
    for (v, dv) in v.iter_mut().zip(dv) {
        *v = v.wrapping_add(*dv);
    }
}

/// A run of covered pixels on one row, with everything needed to step across it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span<const V: usize> {
    /// Frame row.
    pub y: i32,
    /// Frame column of the first pixel.
    pub x: i32,
    /// Pixels in the run (>= 1).
    pub len: u32,
    /// Depth of the first pixel.
    pub z: Depth30,
    /// Depth step per pixel; `z + k·dz` stays in 0..=2^30 for every `k < len`.
    pub dz: i32,
    /// Varyings at the first pixel.
    pub v: [FDot16; V],
    /// Varying steps per pixel (wrapping adds).
    pub dv: [FDot16; V],
}

/// What the rasterizer hands runs of covered pixels to (see [`Setup::for_each_span`]).
pub trait SpanSink<const V: usize> {
    /// Draws one run.
    fn span(&mut self, span: &Span<V>);
}
