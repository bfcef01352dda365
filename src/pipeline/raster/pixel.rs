//! Perspective at every pixel in f32, for draws with an FPU (see [`Setup::use_fpu_perspective`])
//! whose span loop walks the rows itself ([`PixelRows`]): the way TGX draws, with a bound.
//!
//! `n_k = E_k · q_k` (edge function times the vertex's normalised `1/w`) is an affine function
//! of the pixel, and so are `s = n_0 + n_1 + n_2` and, for every varying, `t = d_1·n_1 + d_2·n_2`
//! (`v_j`: the varying at vertex `j`, `d_j = v_j - v_0`). A pixel's varying is `v_0 + t / s`
//! exactly (added in f32, where `v_0` is kept exact: a varying that is the same at the three
//! vertices, such as flat light, is then exactly that everywhere). The set-up makes their planes over the box (values at its origin and steps per
//! column and row); each row evaluates them at its first covered pixel, and the span loop steps
//! them along the row and divides once a pixel: one division and a multiply per varying, and
//! a few multiply-adds a row. Texel coordinate `v` comes already shifted for the base (see
//! `Base::v_shift`): its values are multiplied by that power of two, exactly.
//!
//! # Error bound
//! With `ε = 2^-24`, covered pixels' `E_k >= 0` summing to `C` (twice the area, less the
//! tie-breaking biases), `q_k` within `[q_min, 1]`, `M = max(|d_1|, |d_2|)` for a
//! varying and `ρ·C` a bound on the planes' terms over the box (see `Setup::pixel_error_scale`): `s` lies within `[q_min·C, C]` and
//! `|t| <= M·C` at covered pixels, and the planes' terms anywhere in the box sum to at most
//! `ρ·C` for `s` and `M·ρ·C` for `t`. Making the planes and evaluating them at a row's first
//! pixel is off by at most `8ε·ρ·C` for `s` and `9ε·M·ρ·C` for `t`; at pixel `i` of the row,
//! stepping adds `ε·C·(6 + i)` and `ε·M·C·(6 + i)`. So the varying is off by at most
//! `ε·M·(17ρ + 12 + 2i) / q_min`, plus one unit for adding `v_0` and one for the conversion.
//! [`Setup::pixel_rows`] draws a triangle this way only when that is within the varying's
//! tolerance for `i` up to the box's width, with margin (`ε·M·(24ρ + 16 + 4·width) / q_min <=
//! tolerance - 2`), `v_0` is below 2^24 (exact in f32), every value stays within i32 (shifted
//! `v` too), and `q_min` was not raised to `Q_MIN`; other triangles take the exact path. A pixel's values depend only on its row's
//! first covered pixel, so bands draw them alike.

use super::perspective::{Q_BITS, Q_MIN};
use super::rows::{CoveredRow, RowCursor};
use super::Setup;
use crate::fixed::FDot16;
use crate::math::{times_power_of_two, F32};
use crate::pipeline::span::{RunRow, RunVaryings};
use crate::pipeline::varyings::VertexLit;

/// An affine function of the pixel: its value at the box's origin pixel and its steps per
/// column and per row.
#[derive(Clone, Copy)]
struct Plane {
    origin: F32,
    dx: F32,
    dy: F32,
}

impl Plane {
    /// `a·self + b·other`, term by term.
    #[inline(always)]
    fn mix(&self, a: F32, (b, other): (F32, &Plane)) -> Plane {
        Plane {
            origin: a * self.origin + b * other.origin,
            dx: a * self.dx + b * other.dx,
            dy: a * self.dy + b * other.dy,
        }
    }

    /// `self + other + third`, term by term.
    #[inline(always)]
    fn sum(&self, other: &Plane, third: &Plane) -> Plane {
        Plane {
            origin: self.origin + other.origin + third.origin,
            dx: self.dx + other.dx + third.dx,
            dy: self.dy + other.dy + third.dy,
        }
    }

    /// The value at column `x`, row `y` from the origin.
    #[inline(always)]
    fn at(&self, x: F32, y: F32) -> F32 {
        self.origin + self.dx * x + self.dy * y
    }
}

/// What a triangle's per-pixel perspective needs besides its rows (see the module's text).
pub(crate) struct PixelPlanes<const V: usize> {
    s: Plane,
    t: [Plane; V],
    /// The varyings at vertex 0, exact in f32.
    v0: [F32; V],
    /// The left shift of texel coordinate `v` in these values.
    shift: u32,
}

/// A triangle's rows with per-pixel perspective (see [`Setup::pixel_rows`]).
pub(crate) struct PixelRows<'s, const V: usize> {
    setup: &'s Setup<V>,
    cursor: RowCursor,
    planes: PixelPlanes<V>,
}

/// The varyings along one run of [`PixelRows`]: `s` and `t` at the current pixel and their
/// steps (copied from the triangle's: the span loop keeps them in registers, which it could
/// not do through a reference that its stores might alias).
pub(crate) struct PixelRun<const V: usize> {
    s: F32,
    t: [F32; V],
    v0: [F32; V],
    ds: F32,
    dt: [F32; V],
    /// The left shift of texel coordinate `v` in these values.
    shift: u32,
}

impl<const V: usize> Setup<V> {
    /// This triangle's rows with perspective worked out at every pixel in f32 (see the module's
    /// text), texel coordinate `v` shifted left by `v_shift` (see `Base::v_shift`), when its
    /// error bound is within `tolerance[k]` units for every varying `k` (powers of two from 4
    /// to 2^12) and the depths `z` of its vertices lie within `2^-10 ..= 1 - 2^-10` (see
    /// [`Setup::row_cursor_inside`]); `None` otherwise.
    #[inline(always)]
    pub(crate) fn pixel_rows(&self, z: [f32; 3], tolerance: &[u32; V], v_shift: u32) -> Option<PixelRows<'_, V>> {
        let per_unit = self.pixel_error_scale()?;
        // `x ^ (x >> 31)` is `|x|` or `|x| - 1` (one instruction).
        let ones = |x: i32| (x ^ (x >> 31)) as u32;
        // With `tolerance = 2^b`, `tolerance - 2 >= 2^(b - 1)`: the bound holds where
        // `ceil(M / 2^(b - 1))·2^(Q_BITS - 24) <= per_unit`, for the worst varying.
        let (mut worst, mut differences, mut origins, mut fits) = (0, 0, 0, true);
        for (k, &t) in tolerance.iter().enumerate() {
            fits &= t.is_power_of_two() && (4..=1 << 12).contains(&t);
            let m = ones(self.d1[k]).max(ones(self.d2[k])) + 1;
            let b = t.trailing_zeros().max(1);
            worst = worst.max((m + (1 << (b - 1)) - 1) >> (b - 1));
            (differences, origins) = (differences | m, origins | ones(self.v0[k]));
        }
        let within = worst <= per_unit >> (Q_BITS - 24) && differences < 1 << 30;
        if !(fits && within && origins < (1 << 24) - 1) {
            return None;
        }
        // Every `v_0` exact in f32, and every value within i32: below `|v_0| + M + tolerance`,
        // under 2^24 + 2^30 + 2^12 (so within u32, as checked above), and so is shifted `v`:
        // `v << v_shift < 2^31` where `v` has more leading zeros than `v_shift`.
        let k = VertexLit::V;
        let v = ones(self.v0[k]) + ones(self.d1[k]).max(ones(self.d2[k])) + 2 + (1 << 12);
        if v.leading_zeros() <= v_shift {
            return None;
        }
        let cursor = self.row_cursor_inside(z)?;
        Some(PixelRows { setup: self, cursor, planes: self.pixel_planes(v_shift) })
    }

    /// `floor(q_min / (24ρ + 16 + 4·width))` (see the module's text), so that a varying is
    /// within its tolerance where `M·2^(Q_BITS - 24) <= (tolerance - 2)·` this; `None` where
    /// `ρ` is too large to be of use (needle triangles) or `q_min` was raised to `Q_MIN`.
    ///
    /// A plane's terms at a pixel of the box are at most `Σ_k q_k·(|c_k| + 16·|a_k|·width +
    /// 16·|b_k|·height)` (times `M` for `t`), and `q_k <= 1`: `ρ = Σ_k ceil(that_k / C)`.
    fn pixel_error_scale(&self) -> Option<u32> {
        if self.q_min <= Q_MIN {
            return None;
        }
        // The whole box's rows, not the band's: the same answer in every band.
        let (width, height) = ((self.x1 - self.x0) as u32, self.rows_below as u32);
        debug_assert!(width < 1 << 11 && height < 1 << 11);
        // `C = Σ_k c_k` (the edge functions' sum is the same at every pixel), positive for any
        // triangle that covers a pixel centre; the wrapping sum is exact (C fits i32).
        let c = self.edges.iter().fold(0i32, |sum, e| sum.wrapping_add(e.c));
        let c = u32::try_from(c).ok().filter(|&c| c > 0)?;
        // Per edge, `|c|` and the rest each below 2^31 (see the module's numbers), their sum
        // below 2^32.
        let largest =
            |e: &super::Edge| e.c.unsigned_abs() + 16 * (e.a.unsigned_abs() * width + e.b.unsigned_abs() * height);
        // Checked: with `C` as small as 1 (a sliver in a large frame) the sum can pass 2^32,
        // and such a triangle gains nothing here anyway.
        let rho = self.edges.iter().try_fold(0u32, |sum, e| sum.checked_add(largest(e) / c + 1))?;
        let k = rho.checked_mul(24)?.checked_add(16 + 4 * width)?;
        Some(self.q_min / k)
    }

    /// The planes of [`PixelPlanes`], texel coordinate `v` shifted by `v_shift`.
    fn pixel_planes(&self, v_shift: u32) -> PixelPlanes<V> {
        let q = &self.inv_w;
        let n: [Plane; 3] = core::array::from_fn(|k| {
            let e = &self.edges[k];
            Plane { origin: F32::from(e.c) * q[k], dx: F32::from(e.a * 16) * q[k], dy: F32::from(e.b * 16) * q[k] }
        });
        let s = n[0].sum(&n[1], &n[2]);
        // Times a power of two: exact.
        let scale = (1u32 << v_shift) as f32;
        let shifted = |k: usize, v: i32| {
            if k == VertexLit::V {
                F32(times_power_of_two(F32::from(v).0, scale))
            } else {
                F32::from(v)
            }
        };
        let t = core::array::from_fn(|k| n[1].mix(shifted(k, self.d1[k]), (shifted(k, self.d2[k]), &n[2])));
        PixelPlanes { s, t, v0: core::array::from_fn(|k| shifted(k, self.v0[k])), shift: v_shift }
    }
}

#[cfg(all(span_asm, not(soft_float)))]
impl<const V: usize> PixelRows<'_, V> {
    /// See [`RowCursor::take_plain_rows`].
    pub(crate) fn take_plain_rows(&mut self) -> Option<super::rows::PlainRows> {
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

    /// For three varyings: `[origin, dx, dy]` of `s`, `t0`, `t1` and `t2`, then `v0`, as
    /// [`PixelRows::next_row`] and [`PixelRun`] take them (`s` and `t` at column `x` of the box
    /// on the row `dy` below the origin are `origin + dx·x + dy·dy`, from `x` and `dy` as f32,
    /// each operation rounded; they step by `dx` a pixel). `None` for another count.
    pub(crate) fn float_terms(&self) -> Option<[f32; 15]> {
        let p = &self.planes;
        let (t, v0) = (<&[Plane; 3]>::try_from(&p.t[..]).ok()?, <&[F32; 3]>::try_from(&p.v0[..]).ok()?);
        let [s, t0, t1, t2] = [&p.s, &t[0], &t[1], &t[2]].map(|q| [q.origin.0, q.dx.0, q.dy.0]);
        let [[a, b, c], [d, e, f], [g, h, i], [j, k, l]] = [s, t0, t1, t2];
        Some([a, b, c, d, e, f, g, h, i, j, k, l, v0[0].0, v0[1].0, v0[2].0])
    }
}

impl<const V: usize> PixelRows<'_, V> {
    /// The per-pixel depth step in 2.30.
    pub(crate) fn dz(&self) -> i32 {
        self.cursor.dz
    }

    /// The next row, `None` after the last; `Some(None)` for a row with no pixel centre
    /// covered.
    #[inline(always)]
    pub(crate) fn next_row(&mut self) -> Option<Option<RunRow<PixelRun<V>>>> {
        let setup = self.setup;
        let Some(CoveredRow { y, dy, lo, hi, z }) = self.cursor.next_row(setup)? else {
            return Some(None);
        };
        let (x, row) = (F32::from(lo), F32::from(dy));
        let p = &self.planes;
        let run = PixelRun {
            s: p.s.at(x, row),
            t: core::array::from_fn(|k| p.t[k].at(x, row)),
            v0: p.v0,
            ds: p.s.dx,
            dt: core::array::from_fn(|k| p.t[k].dx),
            shift: p.shift,
        };
        Some(Some(((setup.x0 + lo, y, (hi + 1 - lo) as u32), z, run)))
    }
}

impl<const V: usize> RunVaryings<V> for PixelRun<V> {
    /// The values come shifted already (see [`Setup::pixel_rows`]).
    #[inline(always)]
    fn shift_v(&mut self, shift: u32) {
        debug_assert_eq!(shift, self.shift);
    }

    #[cfg(all(span_asm, not(soft_float)))]
    #[inline(always)]
    fn perspective(&self) -> Option<[f32; 11]> {
        let three = |v: &[F32; V]| <[F32; 3]>::try_from(&v[..]).ok();
        let ([t0, t1, t2], [v0, v1, v2], [d0, d1, d2]) = (three(&self.t)?, three(&self.v0)?, three(&self.dt)?);
        Some([self.s, t0, t1, t2, v0, v1, v2, self.ds, d0, d1, d2].map(|x| x.0))
    }

    #[inline(always)]
    fn current(&self) -> [FDot16; V] {
        let r = F32(1.0) / self.s;
        core::array::from_fn(|k| (self.t[k] * r + self.v0[k]).to_i32())
    }

    #[inline(always)]
    fn advance(&mut self) {
        self.s = self.s + self.ds;
        for (t, dt) in self.t.iter_mut().zip(&self.dt) {
            *t = *t + *dt;
        }
    }
}

/// Perspective-correct varyings in f32 where the edge functions are `e` (negative ones count as
/// 0), for `1/w`s `inv_w` divided by the largest, varyings `v0` at vertex 0 and their
/// differences to vertices 1 and 2 (`d(k)` for varying `k`, in f32: converted where the caller
/// keeps them, with no array of them made here): the weights `E_k · (1/w_k)` keep full relative
/// precision however much the near vertex is magnified by a large depth ratio, and one division
/// serves every varying. The sum comes back as its f32 bits (positive, so they order as the
/// values do; 0 where every `E_k` is).
#[inline(always)]
pub(super) fn f32_varyings<const V: usize>(
    e: [i32; 3],
    inv_w: &[F32; 3],
    v0: &[FDot16; V],
    d: impl Fn(usize) -> (F32, F32),
) -> ([i32; V], u32) {
    // Non-negative, so converted as unsigned (the same value, a shorter conversion).
    let n = |k: usize| F32::from(e[k].max(0) as u32) * inv_w[k];
    let (n1, n2) = (n(1), n(2));
    let sum = n(0) + n1 + n2;
    let mut out = *v0;
    if sum <= F32(0.0) {
        return (out, 0);
    }
    let inv = F32(1.0) / sum;
    let (b1, b2) = (n1 * inv, n2 * inv);
    for (k, o) in out.iter_mut().enumerate() {
        let (d1, d2) = d(k);
        let offset = d1 * b1 + d2 * b2;
        *o = o.wrapping_add(offset.to_i32());
    }
    (out, sum.0.to_bits())
}

#[cfg(test)]
mod tests {
    use super::super::perspective::tests::triangle;
    use super::super::{facing, Window};
    use super::*;
    use crate::fixed::depth40_to_30;
    use crate::test_rng::Lcg;

    /// Every pixel of [`PixelRows`] against the perspective-correct value in f64 (the same
    /// edge functions, the vertices' `1/w` as given), for random triangles: tiny to guard-band
    /// sized, depth ratios up to 1000:1, texel coordinates spanning 1/16 texel to 2^31 units, light
    /// 0..=1, tolerances 1/256 to 1/16 texel, `v` shifted by up to 7 bits. Those drawn this way stay within their tolerance,
    /// and cover the same columns with the same depth as the exact path's rows.
    #[test]
    fn pixel_rows_are_within_the_tolerance_of_the_exact_values() {
        let mut rng = Lcg(0x1405_7b7e_f767_814f);
        let window = Window { width: 1 << 11, row_start: 0, row_end: 1 << 11 };
        let (mut drawn, mut refused, mut pixels, mut worst) = (0, 0, 0u64, [0f64; 3]);
        for t in 0..6000 {
            let extent = [1, 3, 40, 400, 1900][rng.below(5) as usize];
            let ratio = [1.0, 1.5, 3.0, 10.0, 1000.0][rng.below(5) as usize];
            let texels = [1 << 12, 1 << 16, 1 << 20, u32::MAX][rng.below(4) as usize];
            let mut tri = triangle(&mut rng, extent, ratio, texels);
            // One base for the three texel coordinates u (`triangle` gives each its own), mostly
            // below 2^24 (those above are refused).
            let base = rng.next() as i32 >> [0, 8, 9, 12][rng.below(4) as usize];
            for v in &mut tri {
                v.varyings[0] = base.wrapping_add((rng.next() % texels) as i32);
            }
            let Ok(mut setup) = Setup::<3>::new(&tri, &window, false, false) else { continue };
            setup.use_fpu_perspective();
            let tolerance = [[1 << 8, 1 << 12][rng.below(2) as usize]; 2];
            let tolerance = [tolerance[0], tolerance[1], [1 << 4, 1 << 8][rng.below(2) as usize]];
            let shift = rng.below(8);
            let Some(mut rows) = setup.pixel_rows([0.5; 3], &tolerance, shift) else {
                refused += 1;
                continue;
            };
            drawn += 1;
            let order = if facing(&tri, false, false).unwrap() > 0 { [0, 1, 2] } else { [0, 2, 1] };
            let v = order.map(|i| tri[i]);
            let mut exact_rows = setup.covered_rows();
            // Every row and pixel stepped; some 40 rows and 40 pixels a row checked.
            let (row_stride, column_stride) = (1 + (setup.y1 - setup.y0) / 40, 1 + (setup.x1 - setup.x0) / 40);
            while let Some(row) = rows.next_row() {
                let Some(((x, y, len), z, mut run)) = row else { continue };
                let (ey, dy, lo, hi) = exact_rows.next().expect("no more exact rows");
                assert_eq!((y, x, len), (ey, setup.x0 + lo, (hi + 1 - lo) as u32), "triangle {t}");
                assert_eq!(z as i64, depth40_to_30(setup.depth_at(lo, dy)), "triangle {t} row {dy}");
                for column in lo..=hi {
                    if dy % row_stride != 0 || (column % column_stride != 0 && column != hi) {
                        run.advance();
                        continue;
                    }
                    let got = run.current();
                    let n: [f64; 3] = core::array::from_fn(|k| {
                        let edge = &setup.edges[k];
                        (edge.c + edge.b * 16 * dy + edge.a * 16 * column) as f64 * v[k].inv_w as f64
                    });
                    let sum = n[0] + n[1] + n[2];
                    for k in 0..3 {
                        let d = |i: usize| v[i].varyings[k].wrapping_sub(v[0].varyings[k]) as f64;
                        let exact = v[0].varyings[k] as f64 + (d(1) * n[1] + d(2) * n[2]) / sum;
                        // Texel coordinate v comes shifted.
                        let scale = if k == 1 { (1u32 << shift) as f64 } else { 1.0 };
                        let (exact, bound) = (exact * scale, tolerance[k] as f64 * scale);
                        // The difference modulo 2^32 (varyings wrap).
                        let error = ((got[k] as i64 - exact.floor() as i64) as i32 as f64).abs();
                        worst[k] = worst[k].max(error / bound);
                        assert!(error <= bound, "triangle {t} {tri:?}, row {dy} column {column}, varying {k}: {error}");
                    }
                    run.advance();
                    pixels += 1;
                }
            }
            assert!(exact_rows.next().is_none(), "triangle {t}: rows missing");
        }
        // Both outcomes, many times over.
        assert!(drawn > 1000 && refused > 500 && pixels > 150_000, "{drawn} drawn, {refused} refused, {pixels}");
        std::println!(
            "{drawn} drawn, {refused} refused; worst error / tolerance {worst:?} over {pixels} pixels checked"
        );
    }
}
