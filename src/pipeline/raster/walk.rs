//! Which columns of each row a triangle covers: its three edges walked from row to row
//! ([`RowWalk`]), exactly (the fill rule's ties included), with one of two algorithms chosen by
//! the target: a division per edge and row where the CPU divides in one instruction (Cortex-M3
//! and up, RISC-V with `M`, hosts), or a quotient and remainder carried from row to row where
//! it does not (`cfg(no_hw_divide)`: Cortex-M0+, whose division is a library call). Both give
//! the same bounds, bit for bit (see the test below).
//!
//! On a row `dy` below the origin, the edge function at column `x` (pixels from the origin) is
//! `row + step·x` with `row = c + 16·b·dy` and `step = 16·a`. It is non-negative for
//! `x >= ceil(-row / step)` when `step > 0` (a left edge), for `x <= floor(row / -step)` when
//! `step < 0` (a right edge), and on the whole row or none of it when `step = 0` (a flat edge,
//! as `row >= 0` or not). Inside the triangle's box every edge function fits `i32` (see the
//! module's numbers), and so does `row` on every row of the box.
//!
//! Only two edges bound a row, but for one: with the vertices sorted top `T`, middle `M`, bottom
//! `B` by height, a row whose pixel centres lie above `M` is bounded by the edges from `T` (the
//! *long* edge `T`–`B` and the *upper* one `T`–`M`), and one below `M` by the long and the
//! *lower* edge `M`–`B`. The third edge cannot cut such a row: a point inside the
//! first two edges' wedge at `T` and above `M` lies strictly inside the third (its line meets
//! the wedge only at `M`'s height or below), so its edge function is at least 1 there, inside
//! whichever way the fill rule breaks ties. Only a row whose centres lie exactly at `M`'s
//! height (a flat top or bottom edge's row among them) takes all three edges.

use super::Edge;
#[cfg(any(not(no_hw_divide), test))]
use core::num::NonZeroU32;

/// A triangle's edges, stepped together row by row: the two that bound the current rows (see
/// the module's text) and the one that takes over at the middle vertex.
pub(super) struct RowWalk {
    left: EdgeRow,
    right: EdgeRow,
    /// The lower edge on the walk's first row (stepped to the middle vertex's row when it
    /// replaces the upper one there: not stepped row by row before).
    lower: EdgeRow,
    /// The rows from the first to the middle vertex's (the first value of `to_mid`).
    lower_rows: i32,
    /// Rows before the first whose centres are not above the middle vertex: positive above
    /// it, 0 on it, negative below.
    to_mid: i32,
    /// Whether the centres of that row lie at the middle vertex's height.
    mid_on_row: bool,
    /// Whether the long edge is a left one (`step > 0`).
    long_left: bool,
}

#[cfg(not(no_hw_divide))]
type EdgeRow = DividedEdge;
#[cfg(no_hw_divide)]
type EdgeRow = CarriedEdge;

impl RowWalk {
    /// The walk of `edges` (in the set-up's cyclic order, inside on the left) from the row
    /// `dy` below the origin, for a middle vertex `to_mid` (28.4) below the origin row's
    /// centres.
    #[inline(always)]
    pub(super) fn new(edges: &[Edge; 3], to_mid: i32, dy: i32) -> Self {
        // The long edge spans the whole height: the largest `|a|` (a tie means a flat short
        // edge, and either of the tied ones serves as long with the other as short). Then the
        // next edge round the triangle and the one after. Indices: cheaper to pick than edges.
        let [h0, h1, h2] = edges.each_ref().map(|e| e.a.unsigned_abs());
        let long = if h0 >= h1 && h0 >= h2 {
            0
        } else if h1 >= h2 {
            1
        } else {
            2
        };
        let (next, after) = match long {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        // Going round the triangle, a left long edge runs up from the bottom vertex, so the
        // next edge runs from the top to the middle vertex (upper) and the one after from
        // there to the bottom (lower); a right one runs down, and the order is the reverse.
        let long_left = edges[long].a > 0;
        let (upper, lower) = if long_left { (next, after) } else { (after, next) };
        // Centres at `oy + 16·dy`: the first row at or below the middle vertex.
        let to_mid_row = ((to_mid + 15) >> 4) - dy;
        // Rows below the middle vertex are bounded by the lower edge from the first on.
        let short = if to_mid_row < 0 { lower } else { upper };
        let (left, right) = if long_left { (long, short) } else { (short, long) };
        let (left, right, lower) = (&edges[left], &edges[right], &edges[lower]);
        RowWalk {
            left: EdgeRow::new(left, dy),
            right: EdgeRow::new(right, dy),
            lower: EdgeRow::new(lower, dy),
            lower_rows: to_mid_row,
            to_mid: to_mid_row,
            mid_on_row: to_mid & 15 == 0,
            long_left,
        }
    }

    /// The current row's covered columns `(lo, hi)` within `0..=last` (empty when `lo > hi`),
    /// then on to the next row.
    pub(super) fn next_row(&mut self, last: i32) -> (i32, i32) {
        let span = if self.to_mid == 0 {
            self.middle_row(last)
        } else {
            (self.left.first().max(0), self.right.last().min(last))
        };
        self.to_mid = self.to_mid.wrapping_sub(1);
        self.left.next_row();
        self.right.next_row();
        span
    }

    /// The left and right edges (`[row, 16·b, d]` each, see [`DividedEdge`]) on the current
    /// row and the number of rows from it, at most `rows_left`, that [`RowWalk::next_row`] bounds
    /// by those two alone (none is the middle vertex's), for a loop that walks them itself;
    /// then on past those rows. `None` when the current row is the middle vertex's.
    #[cfg(span_asm)]
    pub(super) fn take_plain_rows(&mut self, rows_left: i32) -> Option<([i32; 3], [i32; 3], i32)> {
        let rows = match self.to_mid {
            0 => return None,
            above if above > 0 => above.min(rows_left),
            _ => rows_left,
        };
        let edge = |e: &DividedEdge| [e.row, e.b16, e.d.get() as i32];
        let plain = (edge(&self.left), edge(&self.right), rows);
        self.left.skip_rows(rows);
        self.right.skip_rows(rows);
        self.to_mid = self.to_mid.wrapping_sub(rows);
        Some(plain)
    }

    /// [`RowWalk::next_row`]'s span on the first row not above the middle vertex, where the
    /// lower edge takes over from the upper one; all three bound it when its centres lie at
    /// the middle vertex's height (the lower on the short side: the right when the long edge
    /// is left), a flat one possibly among them. Once a triangle: out of line.
    #[inline(never)]
    fn middle_row(&mut self, last: i32) -> (i32, i32) {
        self.lower.skip_rows(self.lower_rows);
        let all = self.mid_on_row.then(|| {
            let span = clamp(&self.left, true, (0, last));
            clamp(&self.lower, !self.long_left, clamp(&self.right, false, span))
        });
        if self.long_left {
            self.right = self.lower;
        } else {
            self.left = self.lower;
        }
        all.unwrap_or_else(|| (self.left.first().max(0), self.right.last().min(last)))
    }
}

/// What an edge says of the current row, however it is walked.
trait EdgeBound {
    /// Whether the edge is flat (`a = 0`; its `d` is 1 then, and at least 16 otherwise).
    fn is_flat(&self) -> bool;
    /// A left edge's first inside column, `ceil(-row / step)` (or anything at most 0 when that
    /// is negative).
    fn first(&self) -> i32;
    /// A right edge's last inside column, `floor(row / -step)` (or anything negative when that
    /// is).
    fn last(&self) -> i32;
    /// A flat edge's `row >= 0`: the whole row is inside, or all of it outside.
    fn flat_inside(&self) -> bool;
}

/// `[lo, hi]` (with `lo >= 0`) narrowed to where edge `e`, a left one if `left` (else right)
/// unless flat, is non-negative on the current row.
#[inline(always)]
fn clamp(e: &impl EdgeBound, left: bool, (lo, hi): (i32, i32)) -> (i32, i32) {
    if e.is_flat() {
        if e.flat_inside() {
            (lo, hi)
        } else {
            (1, 0)
        }
    } else if left {
        (lo.max(e.first()), hi)
    } else {
        (lo, hi.min(e.last()))
    }
}

/// One edge on the current row: its value at column 0, stepped by `16·b` a row, and the bound
/// it puts on the columns found by a division.
#[cfg(any(not(no_hw_divide), test))]
#[derive(Clone, Copy, Debug)]
struct DividedEdge {
    row: i32,
    b16: i32,
    /// `|16·a|`, or 1 for a flat edge (never divided by: a divisor known not to be 0 needs
    /// no check before each division).
    d: NonZeroU32,
}

#[cfg(any(not(no_hw_divide), test))]
impl DividedEdge {
    fn new(e: &Edge, dy: i32) -> Self {
        let d = NonZeroU32::new((e.a * 16).unsigned_abs()).unwrap_or(NonZeroU32::MIN);
        DividedEdge { row: e.c + e.b * 16 * dy, b16: e.b * 16, d }
    }

    /// On to the next row (wrapping: the row after the box's last need not fit).
    #[inline(always)]
    fn next_row(&mut self) {
        self.row = self.row.wrapping_add(self.b16);
    }

    /// On by `rows` rows (`rows >= 0`, within the box).
    fn skip_rows(&mut self, rows: i32) {
        self.row = self.row.wrapping_add(self.b16.wrapping_mul(rows));
    }
}

#[cfg(any(not(no_hw_divide), test))]
impl EdgeBound for DividedEdge {
    #[inline(always)]
    fn is_flat(&self) -> bool {
        self.d.get() == 1
    }
    #[inline(always)]
    fn first(&self) -> i32 {
        // `ceil(-row / d) = floor((d - 1 - row) / d)`, at most 0 when `row >= 0`; in u32,
        // where `d - 1 - row` (below 2^31 + 2^20) fits whenever it is non-negative.
        let d_1 = self.d.get() - 1;
        if self.row > d_1 as i32 {
            0
        } else {
            (d_1.wrapping_sub(self.row as u32) / self.d) as i32
        }
    }
    #[inline(always)]
    fn last(&self) -> i32 {
        if self.row < 0 {
            -1
        } else {
            (self.row as u32 / self.d) as i32
        }
    }
    #[inline(always)]
    fn flat_inside(&self) -> bool {
        self.row >= 0
    }
}

/// One edge on the current row, stepped without a division: with `d = |step|`, `row = q·d + r`
/// (`0 <= r < d`) is carried from row to row as quotient and remainder, which gives exactly
/// the floors above. Flat edges carry `row` itself in `q` (with `d = 1`, `r = 0`).
#[cfg(any(no_hw_divide, test))]
#[derive(Clone, Copy, Debug)]
struct CarriedEdge {
    q: i32,
    r: i32,
    /// `16·b = dq·d + dr`, `0 <= dr < d`.
    dq: i32,
    dr: i32,
    /// `|16·a|`, or 1 for a flat edge.
    d: i32,
}

#[cfg(any(no_hw_divide, test))]
impl CarriedEdge {
    fn new(e: &Edge, dy: i32) -> Self {
        let (row, b16, step) = (e.c + e.b * 16 * dy, e.b * 16, e.a * 16);
        if step == 0 {
            return CarriedEdge { q: row, r: 0, dq: b16, dr: 0, d: 1 };
        }
        let d = step.abs();
        let (q, dq) = match super::divide::Divisor::small(d as u32 >> 4) {
            // `d = 16·|a|`, and `floor(n / 16a) = floor(floor(n / 16) / a)`: edges less than 64
            // pixels tall (most) divide by `|a|`'s inverse.
            Some(a) => (a.floor_div(row >> 4), a.floor_div(b16 >> 4)),
            None => (super::floor_div(row, d), super::floor_div(b16, d)),
        };
        CarriedEdge { q, r: row - q * d, dq, dr: b16 - dq * d, d }
    }

    /// On to the next row (wrapping: the row after the box's last need not fit).
    #[inline(always)]
    fn next_row(&mut self) {
        self.q = self.q.wrapping_add(self.dq);
        self.r += self.dr;
        if self.r >= self.d {
            self.r -= self.d;
            self.q = self.q.wrapping_add(1);
        }
    }

    /// On by `rows` rows (`rows >= 0`): one at a time (no division).
    fn skip_rows(&mut self, rows: i32) {
        for _ in 0..rows {
            self.next_row();
        }
    }
}

#[cfg(any(no_hw_divide, test))]
impl EdgeBound for CarriedEdge {
    #[inline(always)]
    fn is_flat(&self) -> bool {
        self.d == 1
    }
    #[inline(always)]
    fn first(&self) -> i32 {
        -self.q
    }
    #[inline(always)]
    fn last(&self) -> i32 {
        self.q
    }
    #[inline(always)]
    fn flat_inside(&self) -> bool {
        self.q >= 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both algorithms give the same bounds on every row, stepped a row or a few at once, for
    /// random edges (a small LCG: reproducible without a dependency), ties (`row` a multiple
    /// of `d`) included.
    #[test]
    fn divided_and_carried_edges_bound_the_same_columns() {
        let mut rng = crate::test_rng::Lcg(0x9e37_79b9);
        let mut next = |n: u32| ((rng.next() >> 1) % n) as i32;
        let mut ties = 0;
        for _ in 0..20_000 {
            let scale = [4, 64, 1024, 30_000][next(4) as usize] as u32;
            let e = Edge {
                a: next(2 * scale) - scale as i32,
                b: next(2 * scale) - scale as i32,
                c: next(1 << 20) - (1 << 19),
            };
            let (mut divided, mut carried) = (DividedEdge::new(&e, 0), CarriedEdge::new(&e, 0));
            let last = next(2000);
            // Rows start as `(0, last)` (see `RowWalk::next_row`); an empty span may differ.
            let covered = |(lo, hi): (i32, i32)| (lo <= hi).then_some((lo, hi));
            for _ in 0..40 {
                let span = (next(2), last);
                let left = e.a > 0;
                let (d, c) = (covered(clamp(&divided, left, span)), covered(clamp(&carried, left, span)));
                assert_eq!(d, c, "{e:?} at row value {}", divided.row);
                ties += i32::from(e.a != 0 && divided.row % divided.d.get() as i32 == 0);
                // On by one row, or by a few at once (as the lower edge is at the middle row).
                let skip = [1, 1, 0, 3][next(4) as usize];
                if skip == 1 {
                    divided.next_row();
                    carried.next_row();
                } else {
                    divided.skip_rows(skip);
                    carried.skip_rows(skip);
                }
            }
        }
        assert!(ties > 100, "{ties} ties");
    }

    /// The covered columns of every row, as the walk finds them with two edges a row (see
    /// `walk`), are exactly the pixels where all three edge functions are non-negative, for
    /// random triangles and windows: vertices often on pixel centres and rows (ties, the
    /// middle vertex's row, flat edges), tiny to large.
    #[test]
    fn covered_rows_are_where_all_three_edge_functions_are_non_negative() {
        let mut rng = crate::test_rng::Lcg(0x7a1c_e5d3);
        let (mut middle_rows, mut flat, mut pixels) = (0, 0, 0u64);
        for _ in 0..20_000 {
            let scale = [2, 8, 40, 300][rng.below(4) as usize];
            // Coordinates on a grid of 1/2 pixel or of 1/16: centres and rows are hit often.
            let grid = [8, 1][rng.below(2) as usize];
            let mut p = || (rng.below(scale * 16 / grid) * grid) as i32;
            let v = |x: i32, y: i32| super::super::ScreenVertex { x, y, z: 0.5, inv_w: 1.0, varyings: [0; 8] };
            let tri = [v(p(), p()), v(p(), p()), v(p(), p())];
            let (row_start, rows) = (rng.below(scale) as i32, 1 + rng.below(scale) as i32);
            let window = super::super::Window { width: scale as i32, row_start, row_end: row_start + rows };
            let Ok(setup) = super::super::Setup::<3>::new(&tri, &window, false, false) else { continue };
            flat += i32::from(setup.edges.iter().any(|e| e.a == 0));
            middle_rows += i32::from(setup.to_mid & 15 == 0);
            let mut rows = setup.covered_rows().peekable();
            for y in setup.y0..=setup.y1 {
                let dy = y - setup.origin_row;
                let inside = |x: i32| setup.edges.iter().all(|e| e.c + e.b * 16 * dy + e.a * 16 * x >= 0);
                let want: std::vec::Vec<i32> = (0..=setup.x1 - setup.x0).filter(|&x| inside(x)).collect();
                let got = match rows.peek() {
                    Some(&(ry, _, lo, hi)) if ry == y => {
                        rows.next();
                        (lo..=hi).collect()
                    }
                    _ => std::vec::Vec::new(),
                };
                assert_eq!(got, want, "{tri:?} in {window:?}, row {y}");
                pixels += want.len() as u64;
            }
        }
        assert!(middle_rows > 1000 && flat > 1000 && pixels > 100_000, "{middle_rows} {flat} {pixels}");
    }
}
