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

use super::Edge;
#[cfg(any(not(no_hw_divide), test))]
use core::num::NonZeroU32;

/// A triangle's three edges, stepped together row by row.
pub(super) struct RowWalk([EdgeRow; 3]);

#[cfg(not(no_hw_divide))]
type EdgeRow = DividedEdge;
#[cfg(no_hw_divide)]
type EdgeRow = CarriedEdge;

impl RowWalk {
    /// The walk of `edges` from the row `dy` below the origin.
    pub(super) fn new(edges: &[Edge; 3], dy: i32) -> Self {
        RowWalk(edges.each_ref().map(|e| EdgeRow::new(e, dy)))
    }

    /// The current row's covered columns `(lo, hi)` within `0..=last` (empty when `lo > hi`),
    /// then on to the next row.
    #[inline(always)]
    pub(super) fn next_row(&mut self, last: i32) -> (i32, i32) {
        let span = self.0.iter().fold((0, last), |span, w| clamp(w, span));
        self.0.iter_mut().for_each(EdgeRow::next_row);
        span
    }
}

/// What an edge says of the current row, however it is walked.
trait EdgeBound {
    /// `16·a`: positive for a left edge, negative for a right one, 0 for a flat one.
    fn step(&self) -> i32;
    /// A left edge's first inside column, `ceil(-row / step)` (or anything at most 0 when that
    /// is negative).
    fn first(&self) -> i32;
    /// A right edge's last inside column, `floor(row / -step)` (or anything negative when that
    /// is).
    fn last(&self) -> i32;
    /// A flat edge's `row >= 0`: the whole row is inside, or all of it outside.
    fn flat_inside(&self) -> bool;
}

/// `[lo, hi]` (with `lo >= 0`) narrowed to where edge `e` is non-negative on the current row.
#[inline(always)]
fn clamp(e: &impl EdgeBound, (lo, hi): (i32, i32)) -> (i32, i32) {
    let step = e.step();
    if step > 0 {
        (lo.max(e.first()), hi)
    } else if step < 0 {
        (lo, hi.min(e.last()))
    } else if e.flat_inside() {
        (lo, hi)
    } else {
        (1, 0)
    }
}

/// One edge on the current row: its value at column 0, stepped by `16·b` a row, and the bound
/// it puts on the columns found by a division.
#[cfg(any(not(no_hw_divide), test))]
#[derive(Clone, Copy, Debug)]
struct DividedEdge {
    row: i32,
    b16: i32,
    /// `|step|`, or 1 for a flat edge (never divided by: a divisor known not to be 0 needs
    /// no check before each division).
    d: NonZeroU32,
    step: i32,
}

#[cfg(any(not(no_hw_divide), test))]
impl DividedEdge {
    fn new(e: &Edge, dy: i32) -> Self {
        let d = NonZeroU32::new((e.a * 16).unsigned_abs()).unwrap_or(NonZeroU32::MIN);
        DividedEdge { row: e.c + e.b * 16 * dy, b16: e.b * 16, d, step: e.a * 16 }
    }

    /// On to the next row (wrapping: the row after the box's last need not fit).
    #[inline(always)]
    fn next_row(&mut self) {
        self.row = self.row.wrapping_add(self.b16);
    }
}

#[cfg(any(not(no_hw_divide), test))]
impl EdgeBound for DividedEdge {
    #[inline(always)]
    fn step(&self) -> i32 {
        self.step
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
    d: i32,
    step: i32,
}

#[cfg(any(no_hw_divide, test))]
impl CarriedEdge {
    fn new(e: &Edge, dy: i32) -> Self {
        let (row, b16, step) = (e.c + e.b * 16 * dy, e.b * 16, e.a * 16);
        if step == 0 {
            return CarriedEdge { q: row, r: 0, dq: b16, dr: 0, d: 1, step };
        }
        let d = step.abs();
        let (q, dq) = match super::divide::Divisor::small(d as u32 >> 4) {
            // `d = 16·|a|`, and `floor(n / 16a) = floor(floor(n / 16) / a)`: edges less than 16
            // pixels tall (most) divide by `|a|`'s inverse.
            Some(a) => (a.floor_div(row >> 4), a.floor_div(b16 >> 4)),
            None => (super::floor_div(row, d), super::floor_div(b16, d)),
        };
        CarriedEdge { q, r: row - q * d, dq, dr: b16 - dq * d, d, step }
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
}

#[cfg(any(no_hw_divide, test))]
impl EdgeBound for CarriedEdge {
    #[inline(always)]
    fn step(&self) -> i32 {
        self.step
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

    /// Both algorithms give the same bounds on every row, for random edges (a small LCG:
    /// reproducible without a dependency), ties (`row` a multiple of `d`) included.
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
                let (d, c) = (covered(clamp(&divided, span)), covered(clamp(&carried, span)));
                assert_eq!(d, c, "{e:?} at row value {}", divided.row);
                ties += i32::from(divided.step != 0 && divided.row % divided.d.get() as i32 == 0);
                divided.next_row();
                carried.next_row();
            }
        }
        assert!(ties > 100, "{ties} ties");
    }
}
