//! The rows of a triangle walked by the span loop itself ([`WalkedRows`]): the same runs as
//! [`Setup::for_each_span`] hands out through `dyn`, bit for bit, without a call or a [`Span`] in
//! memory per run. Affine triangles give a run a row from their planes; exact ones a run a row
//! when linear steps between the row's exact ends are within tolerance ([`Setup::linear_row`]),
//! else the row is cut into runs as before ([`WalkedRow::Cut`]). A per-triangle depth bound
//! ([`Setup::safe_depth_step`]) lets every run skip the depth range test.

#[cfg(doc)]
use super::Span;
use super::{RowWalk, Setup, SpanSink};
use crate::fixed::{depth40_to_30, Depth30, FDot16};
use crate::math::mul_wide;
use crate::pipeline::span::{RunRow, Stepped};

/// The bits of `2^-10` and of `1 - 2^-10` (see [`Setup::row_cursor_inside`]).
const F32_DEPTH_MIN: u32 = 0x3a80_0000;
const F32_DEPTH_MAX: u32 = 0x3f7f_c000;
const _: () =
    assert!(f32::from_bits(F32_DEPTH_MIN) == 1.0 / 1024.0 && f32::from_bits(F32_DEPTH_MAX) == 1.0 - 1.0 / 1024.0);

impl<const V: usize> Setup<V> {
    /// The rows of this triangle for a span loop that walks them itself ([`WalkedRows`]):
    /// affine triangles, and exact ones with `subspan <= 1` (0 counts as 1) and a tolerance
    /// (each row a run when linear steps between its exact ends are within it, else handed back
    /// to [`Setup::row_spans`] through [`WalkedRows::cut_row`]), when every run's stepped depth provably stays within 0..=2^30
    /// (see [`Setup::row_cursor_inside`] for vertex depths `z`, else
    /// [`Setup::safe_depth_step`]); `None` otherwise (then [`Setup::for_each_span`]).
    #[inline(always)]
    pub(crate) fn walked_rows(&self, subspan: u32, z: [f32; 3]) -> Option<WalkedRows<'_, V>> {
        let adaptive = subspan <= 1 && self.tolerance.iter().any(|&t| t > 0);
        if self.affine.is_none() && !adaptive {
            return None;
        }
        let cursor = match self.row_cursor_inside(z) {
            Some(cursor) => cursor,
            None => self.row_cursor()?,
        };
        Some(WalkedRows { setup: self, dz: cursor.dz, cursor })
    }

    /// The walk of this triangle's rows for a span loop that walks them itself, when every
    /// run's stepped depth provably stays within 0..=2^30 (see [`Setup::safe_depth_step`]) on
    /// the window's rows.
    #[inline(always)]
    fn row_cursor(&self) -> Option<RowCursor> {
        let (z_dx, z_dy) = self.depth_gradients()?;
        let dz = self.safe_depth_step(z_dx, z_dy)?;
        Some(RowCursor { walk: self.row_walk(), y: self.y0, z_dx, z_dy, dz })
    }

    /// The walk of this triangle's rows when its vertices' depths `z` all lie within
    /// `2^-10 ..= 1 - 2^-10`: then every covered pixel's depth does too, and a run's stepped
    /// depth is off it by far less than that margin (the plane's f32 set-up by at most about
    /// 2^-21, which `affine::f32_depth_plane` checks, falling back to the integer plane; that
    /// one by under 2^-26 where its gradients fit i32; each step by under 2^-30), so no check
    /// over the box is needed (nor
    /// [`Setup::safe_depth_step`]'s four products).
    #[inline(always)]
    pub(super) fn row_cursor_inside(&self, z: [f32; 3]) -> Option<RowCursor> {
        // Positive floats order as their bits do.
        let inside = |z: f32| (F32_DEPTH_MIN..=F32_DEPTH_MAX).contains(&z.to_bits());
        let (z_dx, z_dy) = self.depth_gradients().filter(|_| z.iter().all(|&z| inside(z)))?;
        Some(RowCursor { walk: self.row_walk(), y: self.y0, z_dx, z_dy, dz: z_dx >> 10 })
    }

    /// The depth plane's gradients (24.40) when they fit i32 (all but the steepest
    /// triangles): the depth at a row's first pixel is then two 32x32-bit multiply-accumulates
    /// (`smlal` on Cortex-M4; see `math::mul_wide`, whose bound the box's rows and columns,
    /// below 2^11, meet).
    // Left to the compiler with an FPU (Cortex-M4F reference frame -5.3k instructions), inlined
    // without one (thumbv6m +4.6k otherwise).
    #[cfg_attr(soft_float, inline(always))]
    fn depth_gradients(&self) -> Option<(i32, i32)> {
        Some((i32::try_from(self.z_dx).ok()?, i32::try_from(self.z_dy).ok()?))
    }

    /// The varyings at the first pixel of the row `dy` below the origin (columns `lo..=hi`)
    /// and their steps, when that row of an exact triangle is one run (see
    /// [`Setup::exact_row`]: its first segment reaches the row's end); `None` when it is cut
    /// into shorter runs. Out of line: once per varying count.
    #[inline(never)]
    fn linear_row(&self, dy: i32, lo: i32, hi: i32) -> Option<([FDot16; V], [FDot16; V])> {
        let e: [i32; 3] = core::array::from_fn(|k| {
            let edge = &self.edges[k];
            edge.c + edge.b * 16 * dy + edge.a * 16 * lo
        });
        let start = self.varyings_at(e);
        if hi == lo {
            return Some((start.0, [0; V]));
        }
        let end = self.varyings_at(core::array::from_fn(|k| e[k] + self.edges[k].a * 16 * (hi - lo)));
        if hi > lo + 1 && !self.linear_within(&start, &end) {
            return None;
        }
        Some((start.0, per_pixel_steps(&start.0, &end.0, hi - lo)))
    }

    /// The per-pixel depth step in 2.30 when every run in the window steps within 0..=2^30
    /// from its first pixel's depth, so that no run needs the test of [`Setup::emit`]; for
    /// gradients `z_dx`, `z_dy` (24.40) within i32.
    ///
    /// A run of `len` pixels starting at depth `z` (24.40) steps to `(z >> 10) + dz·(len - 1)`
    /// with `dz = z_dx >> 10`: at most `z_last / 2^10` and above `z_last / 2^10 - len`, where
    /// `z_last` is the plane at its last pixel. The plane's extremes over the box are at its
    /// corners, so when every corner lies in `(width + 1)·2^10 ..= 2^40` (the box `width + 1`
    /// columns wide), every run starts and ends within 0..=2^30.
    fn safe_depth_step(&self, z_dx: i32, z_dy: i32) -> Option<i32> {
        // With the origin below 2^48 and the box under 2^11 pixels each way (its columns within
        // the frame, at most `MAX_DIMENSION`; its rows below the origin within the triangle's
        // height, at most `MAX_EXTENT / 16 + 1` = 1922), the sums below stay within 2^49: no
        // checks needed. A plane
        // beyond that (a needle triangle's) takes the checked path.
        if self.z_origin.unsigned_abs() >= 1 << 48 {
            return None;
        }
        let (w, dy0, dy1) = (self.x1 - self.x0, self.y0 - self.origin_row, self.y1 - self.origin_row);
        debug_assert!(w < 1 << 11 && (0..1 << 11).contains(&dy0) && dy1 < 1 << 11);
        let top = self.z_origin + mul_wide(z_dy, dy0);
        let bottom = self.z_origin + mul_wide(z_dy, dy1);
        let across = mul_wide(z_dx, w);
        let inside = |z: i64| ((w as i64 + 1) << 10..=1 << 40).contains(&z);
        (inside(top) && inside(top + across) && inside(bottom) && inside(bottom + across)).then_some(z_dx >> 10)
    }
}

/// `(end - start) / len` for each varying (the difference wrapping, the quotient truncated),
/// `len > 0`: without a divide instruction, from `len`'s inverse when it is below 1024.
#[inline(always)]
fn per_pixel_steps<const V: usize>(start: &[FDot16; V], end: &[FDot16; V], len: i32) -> [FDot16; V] {
    #[cfg(no_hw_divide)]
    if let Some(divisor) = super::divide::Divisor::small(len as u32) {
        return core::array::from_fn(|k| divisor.div_trunc(end[k].wrapping_sub(start[k])));
    }
    core::array::from_fn(|k| end[k].wrapping_sub(start[k]) / len)
}

/// `diff / len` (truncated), `len > 0`: without a divide instruction from `len`'s inverse when
/// it is below 1024, out of line (a library call's cost otherwise).
#[cfg_attr(no_hw_divide, inline(never))]
#[cfg_attr(not(no_hw_divide), inline(always))]
pub(super) fn divide_step(diff: FDot16, len: i32) -> FDot16 {
    #[cfg(no_hw_divide)]
    if let Some(divisor) = super::divide::Divisor::small(len as u32) {
        return divisor.div_trunc(diff);
    }
    diff / len
}

/// A triangle's rows for a span loop that walks them itself: the covered columns of each
/// row and the depth at the first (see [`Setup::row_cursor`]).
pub(crate) struct RowCursor {
    walk: RowWalk,
    /// The next frame row.
    y: i32,
    /// The depth plane's gradients (24.40), which fit i32 here.
    z_dx: i32,
    z_dy: i32,
    /// The per-pixel depth step in 2.30.
    pub(crate) dz: i32,
}

/// One row of a [`RowCursor`] with covered pixels: frame row, rows below the origin, covered
/// columns `lo..=hi` of the box, depth (2.30) at `lo`.
pub(crate) struct CoveredRow {
    pub(crate) y: i32,
    pub(crate) dy: i32,
    pub(crate) lo: i32,
    pub(crate) hi: i32,
    pub(crate) z: Depth30,
}

impl RowCursor {
    /// The next row of `s` (the set-up this cursor walks): `None` after the last, `Some(None)`
    /// for a row with no pixel centre covered.
    #[inline(always)]
    pub(crate) fn next_row<const V: usize>(&mut self, s: &Setup<V>) -> Option<Option<CoveredRow>> {
        let y = self.y;
        if y > s.y1 {
            return None;
        }
        self.y += 1;
        let (lo, hi) = self.walk.next_row(s.x1 - s.x0);
        if lo > hi {
            return Some(None);
        }
        let dy = y - s.origin_row;
        // The same value as `Setup::depth_at` (the same products, wrapping sums).
        let z40 = s.z_origin.wrapping_add(mul_wide(self.z_dx, lo)).wrapping_add(mul_wide(self.z_dy, dy));
        Some(Some(CoveredRow { y, dy, lo, hi, z: depth40_to_30(z40) as Depth30 }))
    }
}

/// An affine triangle's rows, walked by the span loop itself (see [`Setup::affine_rows`]): the
/// runs of [`WalkedRows`] for such a triangle, from a loop that has no exact rows to cut.
pub(crate) struct AffineRows<'s, const V: usize> {
    setup: &'s Setup<V>,
    planes: &'s super::AffinePlanes<V>,
    cursor: RowCursor,
    /// The per-pixel depth step in 2.30.
    pub(crate) dz: i32,
}

impl<const V: usize> Setup<V> {
    /// [`Setup::walked_rows`] of an affine triangle; `None` for a triangle that is not affine
    /// or whose runs' depth is not provably within range (see there).
    #[inline(always)]
    pub(crate) fn affine_rows(&self, z: [f32; 3]) -> Option<AffineRows<'_, V>> {
        let planes = self.affine.as_ref()?;
        let cursor = match self.row_cursor_inside(z) {
            Some(cursor) => cursor,
            None => self.row_cursor()?,
        };
        Some(AffineRows { setup: self, planes, dz: cursor.dz, cursor })
    }
}

impl<const V: usize> AffineRows<'_, V> {
    /// The next row, `None` after the last; `Some(None)` for a row with no pixel centre
    /// covered.
    #[inline(always)]
    pub(in crate::pipeline) fn next_row(&mut self) -> Option<Option<RunRow<Stepped<V>>>> {
        let s = self.setup;
        let Some(CoveredRow { y, dy, lo, hi, z }) = self.cursor.next_row(s)? else {
            return Some(None);
        };
        let (v, dv) = self.planes.at(lo, dy);
        Some(Some(((s.x0 + lo, y, (hi + 1 - lo) as u32), z, Stepped(v, dv))))
    }
}

/// Rows of a triangle for a loop that walks them itself (the span loop's assembly, see
/// `span::RowWalk565`): the left and right edges (`[row, 16·b, d]`, see `walk::DividedEdge`)
/// on the first row, the first row's frame row and its rows below the origin, and the number
/// of rows. On each, the covered columns of the box are `max(first, 0) ..= min(last_of_right,
/// x1 - x0)`, with `first` the left
/// edge's `ceil(-row / d)` (0 when `row > d - 1`, in u32 otherwise) and `last_of_right` the
/// right edge's `floor(row / d)` (-1 when `row < 0`); then each edge's `row` steps by its `16·b`.
#[cfg(span_asm)]
pub(crate) struct PlainRows {
    pub(crate) left: [i32; 3],
    pub(crate) right: [i32; 3],
    pub(crate) y: i32,
    pub(crate) dy: i32,
    pub(crate) rows: i32,
}

#[cfg(span_asm)]
impl RowCursor {
    /// The rows from the current one of `s` (the set-up this cursor walks) that need no
    /// middle-vertex handoff (see [`PlainRows`]), for a loop that walks them itself; the walk
    /// goes on after them. `None` when the current row is the middle vertex's (then
    /// `next_row`) or past the last.
    pub(crate) fn take_plain_rows<const V: usize>(&mut self, s: &Setup<V>) -> Option<PlainRows> {
        let rows_left = s.y1 - self.y + 1;
        if rows_left <= 0 {
            return None;
        }
        let (left, right, rows) = self.walk.take_plain_rows(rows_left)?;
        let plain = PlainRows { left, right, y: self.y, dy: self.y - s.origin_row, rows };
        self.y += rows;
        Some(plain)
    }

    /// The box's columns `x0..=x1` and the rows from the current one to the last: `(x0, x1,
    /// y, y1)`, frame pixels.
    pub(crate) fn remaining_box<const V: usize>(&self, s: &Setup<V>) -> (i32, i32, i32, i32) {
        (s.x0, s.x1, self.y, s.y1)
    }

    /// The depth plane as a loop that walks the rows itself takes it: `(z_origin, z_dx, z_dy,
    /// dz)`, the depth (2.30) at column `x` of the box on the row `dy` below the origin being the
    /// low 32 bits of `(z_origin + z_dx·x + z_dy·dy) >> 10` (in i64), stepping by `dz` a pixel.
    pub(crate) fn depth_terms<const V: usize>(&self, s: &Setup<V>) -> (i64, i32, i32, i32) {
        (s.z_origin, self.z_dx, self.z_dy, self.dz)
    }
}

#[cfg(span_asm)]
impl<'s, const V: usize> AffineRows<'s, V> {
    /// See [`RowCursor::take_plain_rows`].
    pub(crate) fn take_plain_rows(&mut self) -> Option<PlainRows> {
        self.cursor.take_plain_rows(self.setup)
    }

    /// See [`RowCursor::remaining_box`].
    pub(crate) fn remaining_box(&self) -> (i32, i32, i32, i32) {
        self.cursor.remaining_box(self.setup)
    }

    /// See [`RowCursor::depth_terms`].
    pub(crate) fn depth_terms(&self) -> (i64, i32, i32, i32) {
        self.cursor.depth_terms(self.setup)
    }

    /// Each varying's `[base, origin, gx, gy]` (24.8 but the base, 16.16), its value at column
    /// `x` of the box on the row `dy` below the origin being `base + ((origin + gx·x + gy·dy) >>
    /// 8)` (wrapping), and the steps per pixel.
    pub(crate) fn terms(&self) -> (&'s [[i32; 4]; V], &'s [FDot16; V]) {
        self.planes.terms()
    }
}

/// A triangle's rows, walked by the span loop itself (see [`Setup::walked_rows`]): the same
/// spans as [`Setup::for_each_span`] hands out, bit for bit, without a call or a [`Span`] in
/// memory per run.
pub(crate) struct WalkedRows<'s, const V: usize> {
    setup: &'s Setup<V>,
    cursor: RowCursor,
    /// The per-pixel depth step in 2.30.
    pub(crate) dz: i32,
}

/// One row of [`WalkedRows`].
pub(crate) enum WalkedRow<const V: usize> {
    /// No pixel centre covered.
    Empty,
    /// One run: frame row and column, pixels, depth (2.30), varyings at its first pixel and
    /// their steps.
    Run(i32, i32, u32, Depth30, [FDot16; V], [FDot16; V]),
    /// An exact row cut into several runs: frame row, rows below the origin, covered columns
    /// `lo..=hi` of the box, for [`WalkedRows::cut_row`].
    Cut(i32, i32, i32, i32),
}

impl<const V: usize> WalkedRows<'_, V> {
    /// The next row, `None` after the last.
    #[inline(always)]
    pub(crate) fn next_row(&mut self) -> Option<WalkedRow<V>> {
        let s = self.setup;
        let Some(CoveredRow { y, dy, lo, hi, z }) = self.cursor.next_row(s)? else {
            return Some(WalkedRow::Empty);
        };
        let (v, dv) = match &s.affine {
            Some(p) => p.at(lo, dy),
            None => match s.linear_row(dy, lo, hi) {
                Some(v_dv) => v_dv,
                None => return Some(WalkedRow::Cut(y, dy, lo, hi)),
            },
        };
        Some(WalkedRow::Run(y, s.x0 + lo, (hi + 1 - lo) as u32, z, v, dv))
    }

    /// Hands the runs of a [`WalkedRow::Cut`] row to `sink`, as [`Setup::for_each_span`] does.
    pub(crate) fn cut_row(&self, sink: &mut dyn SpanSink<V>, row: (i32, i32, i32, i32)) {
        // An exact triangle's row: `row_spans` gives it to `exact_row`.
        debug_assert!(!self.setup.is_affine());
        self.setup.row_spans(sink, 1, row);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ScreenVertex, Span, SpanSink, Window};
    use super::*;
    use std::vec::Vec;

    /// Collects the runs a sink is handed.
    struct Collect(Vec<Span<3>>);

    impl SpanSink<3> for Collect {
        fn span(&mut self, span: &Span<3>) {
            self.0.push(*span);
        }
    }

    /// The runs of walked rows, cut rows included, as the span loop sees them.
    fn walked(setup: &Setup<3>, subspan: u32, z: [f32; 3]) -> Option<Vec<Span<3>>> {
        let mut rows = setup.walked_rows(subspan, z)?;
        let (dz, mut out) = (rows.dz, Collect(Vec::new()));
        while let Some(row) = rows.next_row() {
            match row {
                WalkedRow::Run(y, x, len, z, v, dv) => out.0.push(Span { y, x, len, z, dz, v, dv }),
                WalkedRow::Cut(y, dy, lo, hi) => rows.cut_row(&mut out, (y, dy, lo, hi)),
                WalkedRow::Empty => {}
            }
        }
        Some(out.0)
    }

    /// Walked rows give exactly the runs `for_each_span` gives, affine and exact, in every
    /// band, for random triangles (a small LCG: reproducible without a dependency).
    #[test]
    fn walked_rows_equal_the_runs_of_for_each_span() {
        let mut rng = crate::test_rng::Lcg(0x2545_f491);
        let mut next = |n: u32| (rng.next() >> 1) % n;
        let (mut walked_affine, mut walked_exact) = (0, 0);
        for _ in 0..20_000 {
            let size = [40, 200, 1200][next(3) as usize];
            // Small varying ranges and near-equal depths make affine triangles; the rest exact.
            let (range, depth) = ([1 << 8, 1 << 16, 1 << 24][next(3) as usize], [1, 1000][next(2) as usize]);
            let vertex = |next: &mut dyn FnMut(u32) -> u32| ScreenVertex {
                x: next(size * 16) as i32,
                y: next(size * 16) as i32,
                z: next(1000) as f32 / 1000.0,
                inv_w: 0.5 + next(depth) as f32 / 1000.0,
                varyings: core::array::from_fn(|_| next(range) as i32 - (range / 2) as i32),
            };
            let mut tri = [vertex(&mut next), vertex(&mut next), vertex(&mut next)];
            // Some vertices nearer than 2^-10: such triangles check their depth over the box.
            if next(4) == 0 {
                tri[0].z = 1.0 / 4096.0;
            }
            let (row_start, rows) = (next(size) as i32, 1 + next(32) as i32);
            let window = Window { width: size as i32, row_start, row_end: row_start + rows };
            let Ok(mut setup) = Setup::<3>::new(&tri, &window, false, false) else { continue };
            setup.allow_affine([[0, 1 << 8, 1 << 12, 1 << 16][next(4) as usize]; 3]);
            let subspan = next(3);
            let Some(walked) = walked(&setup, subspan, tri.each_ref().map(|v| v.z)) else { continue };
            let mut old = Collect(Vec::new());
            setup.for_each_span(subspan, &mut old);
            assert_eq!(walked, old.0, "{tri:?} in {window:?}, subspan {subspan}");
            // An affine triangle's own loop (`AffineRows`) gives the same runs too.
            let affine = setup.affine_rows(tri.each_ref().map(|v| v.z)).map(|mut rows| {
                let mut runs = Vec::new();
                while let Some(row) = rows.next_row() {
                    if let Some(((x, y, len), z, Stepped(v, dv))) = row {
                        runs.push(Span { y, x, len, z, dz: rows.dz, v, dv });
                    }
                }
                runs
            });
            assert_eq!(affine.is_some(), setup.is_affine(), "{tri:?} in {window:?}");
            if let Some(affine) = affine {
                assert_eq!(affine, old.0, "{tri:?} in {window:?}: affine rows");
            }
            if setup.is_affine() {
                walked_affine += 1;
            } else {
                walked_exact += 1;
            }
        }
        // Both kinds were compared, many times over.
        assert!(walked_affine > 100 && walked_exact > 100, "{walked_affine} affine, {walked_exact} exact");
    }
}
