//! Affine varyings: one plane per varying over a triangle's box, in integers (see
//! [`AffinePlanes`]), for triangles whose varyings `Setup::allow_affine` finds affine within
//! tolerance; made in f32 or, for set-ups without f32 perspective, in integers, as is their
//! depth plane ([`integer_depth_plane`]), both through the area's reciprocal
//! ([`AreaReciprocal`]). It does not decide that (`raster` does) or step pixels (`span` does).

use super::perspective::{leading_zeros, mul_i32, mul_u32, mul_u32_small, reciprocal};
use super::Edge;
use crate::fixed::{depth30_truncated, DEPTH40_ONE};
use crate::fixed::{fdot8_floor, fdot8_round, FDot16, FDot8};
use crate::math::{
    at_least_power_of_two, mul_wide, shl_i64, shr_i64, times_16, times_power_of_two, wrapping_mul_small, F32,
};

/// Affine varyings: `v(x, y) = base + (origin + gx·x + gy·y) / 256` in pixels from the origin
/// pixel centre, in integers (24.8 varying units: rounding adds under 2^-8 units per pixel of
/// distance, far below the 2^-16 of a texel or of full light that a unit is). Stepping them
/// costs the same on every target, FPU or not, and gives the same value for a pixel whichever
/// band draws it.
///
/// The terms are vertex 0's value (16.16; the plane is relative to it), then the plane's
/// `origin`, `gx` and `gy` (24.8), each varying's four together (`terms`) where the span loop's
/// assembly reads them (`cfg(span_asm)`: four with one `ldm`, see `span::Affine565`), term by
/// term elsewhere (`base`, `origin`, `gx`, `gy`), which Armv6-M's and RISC-V's set-up and rows
/// measured faster (thumbv6m +20k instructions a frame, riscv32imc +30k, with them together).
/// Read through [`AffinePlanes::term`].
#[derive(Clone, Copy, Debug)]
pub(super) struct AffinePlanes<const V: usize> {
    #[cfg(span_asm)]
    terms: [[i32; 4]; V],
    #[cfg(not(span_asm))]
    base: [FDot16; V],
    #[cfg(not(span_asm))]
    origin: [FDot8; V],
    #[cfg(not(span_asm))]
    gx: [FDot8; V],
    #[cfg(not(span_asm))]
    gy: [FDot8; V],
    /// `gx` rounded to whole units: the per-pixel step along a row.
    step: [FDot16; V],
}

/// Which term of a varying's plane (see [`AffinePlanes::term`]).
const BASE: usize = 0;
const ORIGIN: usize = 1;
const GX: usize = 2;
const GY: usize = 3;

impl<const V: usize> AffinePlanes<V> {
    /// The planes through the three vertices' values: the weight of vertex 1 is `E_1 / area`
    /// and of vertex 2 is `E_2 / area` (screen-space barycentrics; `area`: twice the
    /// triangle's, in 1/256 pixel², positive, rounded to f32), so each plane term is `(d_1 ·
    /// coefficient_1 + d_2 · coefficient_2) / area`, computed in f32 (an FPU's few
    /// instructions; the same bits on every target). `None` when `origin + gx·x + gy·y` could
    /// leave i32 somewhere in `0..=width` by `0..=height` pixels from the origin (needle
    /// triangles with huge gradients): those keep per-run exact values. See
    /// [`AffinePlanes::in_integers`] for the planes without float.
    #[inline(always)]
    pub(super) fn new(
        edges: &[Edge; 3],
        area: F32,
        (v0, d1, d2): (&[i32; V], &[F32; V], &[F32; V]),
        extent: (i32, i32),
    ) -> Option<Self> {
        // The terms in 24.8: times 256, a power of two, which commutes with every rounding
        // below (no overflow: `d` is below 2^39 and the weights below 2^32), so it is taken
        // once here rather than on each difference (no soft-float multiply without an FPU).
        let inv_area = F32(times_power_of_two((F32(1.0) / area).0, 256.0));
        let per_pixel = |c: i32| F32::from(c * 16) * inv_area;
        let (b1x, b1y, b1o) = (per_pixel(edges[1].a), per_pixel(edges[1].b), F32::from(edges[1].c) * inv_area);
        let (b2x, b2y, b2o) = (per_pixel(edges[2].a), per_pixel(edges[2].b), F32::from(edges[2].c) * inv_area);
        #[cfg(not(span_asm))]
        let mut p = AffinePlanes { base: *v0, origin: [0; V], gx: [0; V], gy: [0; V], step: [0; V] };
        #[cfg(span_asm)]
        let mut p = AffinePlanes { terms: v0.map(|b| [b, 0, 0, 0]), step: [0; V] };
        for k in 0..V {
            let (d1, d2) = (d1[k], d2[k]);
            // Relative to vertex 0's value, added back in integers: large values (e.g. world
            // positions) keep their precision. Truncating (saturating: a saturated value fails
            // the bound): under one unit of 2^-8 off. Finite: `d` is below 2^39 and the weights
            // below 2^32.
            let (o, gx, gy) = (d1 * b1o + d2 * b2o, d1 * b1x + d2 * b2x, d1 * b1y + d2 * b2y);
            p.set(k, (o.to_i32(), gx.to_i32(), gy.to_i32()), extent)?;
        }
        Some(p)
    }

    /// [`AffinePlanes::new`] in integers, for draws without f32 perspective (no soft-float
    /// where there is no FPU): each term's numerator `d_1 · coefficient_1 + d_2 ·
    /// coefficient_2` exact in 64 bits, times the area's reciprocal ([`AreaReciprocal`]). Not
    /// the same bits as `new`'s (a draw uses one or the other for all its triangles), and as
    /// close to the exact planes. Out of line with an FPU, whose draws never call it.
    #[cfg_attr(soft_float, inline(always))]
    #[cfg_attr(not(soft_float), inline(never))]
    pub(super) fn in_integers(
        edges: &[Edge; 3],
        inverse: &AreaReciprocal,
        (v0, d1, d2): (&[i32; V], &[i32; V], &[i32; V]),
        extent: (i32, i32),
    ) -> Option<Self> {
        let (e1, e2) = (&edges[1], &edges[2]);
        // `v0`'s values stand in until `set` sets every varying's terms: a copy is a few stores,
        // where zeros are a `memset` call on Armv6-M.
        #[cfg(not(span_asm))]
        let mut p = AffinePlanes { base: *v0, origin: *v0, gx: *v0, gy: *v0, step: *v0 };
        #[cfg(span_asm)]
        let mut p = AffinePlanes { terms: v0.map(|b| [b; 4]), step: *v0 };
        for k in 0..V {
            let (d1, d2) = (d1[k], d2[k]);
            // `a` and `b` are per 1/16 pixel and the terms in 24.8 units: per pixel, times 2^12;
            // `c` is the origin's value, times 2^8. Each sum is exact: the products are below
            // 2^46 (`|a|, |b| < 2^15`) and 2^62 (`|c| <= 2·30,735² + 1 < 2^31`), the sum of two
            // below 8.1e18 < 2^63.
            let o = inverse.times(mul_i32(d1, e1.c) + mul_i32(d2, e2.c), 8)?;
            let gx = inverse.times(mul_wide(d1, e1.a) + mul_wide(d2, e2.a), 12)?;
            let gy = inverse.times(mul_wide(d1, e1.b) + mul_wide(d2, e2.b), 12)?;
            p.set(k, (o, gx, gy), extent)?;
        }
        Some(p)
    }

    /// Sets varying `k`'s plane terms (24.8) when they are within reach over a box of `width`
    /// by `height` pixels from the origin (see [`AffinePlanes::new`]).
    #[inline(always)]
    fn set(&mut self, k: usize, (o, gx, gy): (FDot8, FDot8, FDot8), (width, height): (i32, i32)) -> Option<()> {
        // At least one pixel each way: the bound must hold `gx` and `gy` themselves too (the
        // per-pixel step is `gx`, rounded), also for a box one column or row wide.
        let (w, h) = (width.max(1) as u32, height.max(1) as u32);
        // Within 2^30 in integers: `origin + gx·x + gy·y` fits i32 for every pixel of the box,
        // and `gx + 128` too. `x ^ (x >> 31)` is `|x|` or `|x| - 1` (one instruction): the sum
        // is at most `1 + w + h` under the exact one, still far within i32. The products are
        // 32 x 32 -> 64 bits (`umull`; without one, two 16-bit products each, the box being
        // under 2^11 pixels each way, not a 64-bit multiply's library call).
        let abs = |v: i32| (v ^ (v >> 31)) as u32;
        if u64::from(abs(o)) + mul_u32_small(abs(gx), w) + mul_u32_small(abs(gy), h) >= 1 << 30 {
            return None;
        }
        self.step[k] = fdot8_round(gx);
        #[cfg(span_asm)]
        {
            self.terms[k] = [self.terms[k][BASE], o, gx, gy];
        }
        #[cfg(not(span_asm))]
        {
            (self.origin[k], self.gx[k], self.gy[k]) = (o, gx, gy);
        }
        Some(())
    }

    /// Term `t` (`BASE`, `ORIGIN`, `GX` or `GY`) of varying `k`.
    #[inline(always)]
    fn term(&self, k: usize, t: usize) -> i32 {
        #[cfg(span_asm)]
        {
            self.terms[k][t]
        }
        #[cfg(not(span_asm))]
        {
            [&self.base, &self.origin, &self.gx, &self.gy][t][k]
        }
    }

    /// Each varying's `[base, origin, gx, gy]` (see [`AffinePlanes::at`]), and the steps.
    #[cfg(span_asm)]
    pub(super) fn terms(&self) -> (&[[i32; 4]; V], &[FDot16; V]) {
        (&self.terms, &self.step)
    }

    /// Varyings at column `x`, row `y` from the origin pixel, and the step per pixel.
    #[inline(always)]
    pub(super) fn at(&self, x: i32, y: i32) -> ([i32; V], [i32; V]) {
        let v = |k: usize| {
            let t = |term: usize| self.term(k, term);
            t(BASE).wrapping_add(fdot8_floor(t(ORIGIN) + t(GX) * x + t(GY) * y))
        };
        (core::array::from_fn(v), self.step)
    }
}

/// The depth plane (24.40: at the origin pixel `(ox, oy)` (28.4), and per pixel in x and y)
/// through `(x, y, z)` (28.4, and depth in 0..=1) of a triangle's vertices in the set-up's
/// order, of twice the area `area` (1/256 pixel², positive), in integers: depth in 2.30
/// (truncated, under 2^-30 off), the gradients as [`AffinePlanes::in_integers`]'s terms
/// (`(dz_1·ey_2 - dz_2·ey_1) · 2^14 / area`, the numerators exact, within a unit and 2^-29
/// relative), and the origin's value from vertex 0's along them (wrapping, as the f32 plane
/// saturates: only a needle triangle's absurd gradients take it out of range). Bit for bit the
/// same on every target, and no soft-float. Inlined (thumbv6m, 8 bands: 40k instructions a
/// frame fewer than out of line, for 59 KB more flash; the Cortex-M4F 5k fewer, for 21 KB).
#[inline(always)]
pub(super) fn integer_depth_plane(v: [(i32, i32, f32); 3], area: u32, origin: (i32, i32)) -> (i64, i64, i64) {
    depth_plane_with(v, &AreaReciprocal::new(area), origin)
}

/// [`integer_depth_plane`] with the area's reciprocal `inverse` (see [`AreaReciprocal`]).
#[inline(always)]
fn depth_plane_with(v: [(i32, i32, f32); 3], inverse: &AreaReciprocal, (ox, oy): (i32, i32)) -> (i64, i64, i64) {
    // Depth within 0..=1 (NaN gives 0, and anything else is clamped there): so the
    // differences fit i32.
    let z = v.map(|(_, _, z)| depth30_truncated(z));
    let [(ax, ay, _), (bx, by, _), (cx, cy, _)] = v;
    let (dz1, dz2) = (z[1] - z[0], z[2] - z[0]);
    // Coordinates within the guard band: differences below 2^15, so `mul_wide` holds them and
    // each numerator is below 2^46.
    let gx = mul_wide(dz1, cy - ay) - mul_wide(dz2, by - ay);
    let gy = mul_wide(dz2, bx - ax) - mul_wide(dz1, cx - ax);
    // Per 1/16 pixel in units of 2^-30: per pixel in 2^-40, times 2^14.
    let (z_dx, z_dy) = (inverse.quotient(gx, 14), inverse.quotient(gy, 14));
    // Vertex 0 to the origin, in 1/16 pixels: floor of the sum over 16.
    ((i64::from(z[0]) << 10).wrapping_add(floor_sixteenth((z_dx, ox - ax), (z_dy, oy - ay))), z_dx, z_dy)
}

/// `floor((z_1·d_1 + z_2·d_2) / 16)` modulo 2^64 (offsets `|d| < 2^15`, from the guard band):
/// exact, so that a steep plane's origin, far from a needle triangle, is still congruent to its
/// value there and the wrapping sums at the triangle's pixels give their exact depths (a
/// wrapped product shifted by 4 would keep it only modulo 2^60). In 64 bits where the products
/// are below 2^61 (gradients below 2^46: every triangle but needles), else in 128.
#[inline(always)]
fn floor_sixteenth((z1, d1): (i64, i32), (z2, d2): (i64, i32)) -> i64 {
    debug_assert!(d1.unsigned_abs() < 1 << 15 && d2.unsigned_abs() < 1 << 15);
    if (z1.unsigned_abs() | z2.unsigned_abs()) < 1 << 46 {
        (wrapping_mul_small(z1, d1) + wrapping_mul_small(z2, d2)) >> 4
    } else {
        ((i128::from(z1) * i128::from(d1) + i128::from(z2) * i128::from(d2)) >> 4) as i64
    }
}

/// The depth plane of [`integer_depth_plane`] for a triangle of twice the (signed, non-zero)
/// area `area`: with `fpu`, in f32 (24.40 from the f32 values, truncated) where that is
/// accurate, within about 2^-21 of the exact plane at every pixel of the box; in integers for
/// the ill-conditioned rest (slivers, whose gradient's two products nearly cancel: off by up
/// to twice itself in f32) and without `fpu` (with the area's reciprocal `inverse` when
/// given).
///
/// Each product `p` is within `ε·|p|` (`ε = 2^-24`), the differences of depths too, and the
/// numerator's difference within `ε` of both products' magnitudes: a gradient is within
/// `4ε·(|p_1| + |p_2|) / area`. At a pixel of the box, no further than `|e_1| + |e_2|` (the
/// edges from vertex 0) from vertex 0 each way, the plane is then within `4ε·S / area` of the
/// exact one, with `S = (|p_1| + |p_2|)·(|ex_1| + |ex_2|) + (|p_3| + |p_4|)·(|ey_1| + |ey_2|)`,
/// plus about `2ε` for the sum at the origin: `S <= area` keeps it within `2^-22 + 2^-23`.
/// NaN and infinite depths fail it too. The gradients are then at most one depth unit per
/// 1/16 pixel (the edge lengths are at least one unit): nothing saturates in 24.40.
#[inline(always)]
pub(super) fn depth_plane(
    v: [(i32, i32, f32); 3],
    area: i32,
    (ox, oy): (i32, i32),
    (fpu, inverse): (bool, Option<&AreaReciprocal>),
) -> (i64, i64, i64) {
    if !fpu {
        return match inverse {
            Some(inverse) => depth_plane_with(v, inverse, (ox, oy)),
            None => integer_depth_plane(v, area.unsigned_abs(), (ox, oy)),
        };
    }
    if let Some((z_at_origin, gx, gy)) = f32_depth_plane(v, area, (ox, oy)) {
        // Powers of two: exact, and no soft-float multiply without an FPU.
        let to_fixed = |v: F32| crate::math::f32_to_i64(times_power_of_two(v.0, DEPTH40_ONE));
        return (to_fixed(z_at_origin), to_fixed(gx), to_fixed(gy));
    }
    integer_depth_plane(v, area.unsigned_abs(), (ox, oy))
}

/// [`depth_plane`]'s plane in f32 (depth 0..=1 at the origin pixel `(ox, oy)`, and per pixel in
/// x and y) where that is accurate (see there), else `None`.
#[inline(always)]
pub(super) fn f32_depth_plane(v: [(i32, i32, f32); 3], area: i32, (ox, oy): (i32, i32)) -> Option<(F32, F32, F32)> {
    let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = v.map(|(x, y, z)| (x, y, F32(z)));
    let (dz1, dz2) = (bz - az, cz - az);
    let (ex1, ey1, ex2, ey2) = (F32::from(bx - ax), F32::from(by - ay), F32::from(cx - ax), F32::from(cy - ay));
    let af = F32::from(area.unsigned_abs());
    let (p1, p2, p3, p4) = (dz1 * ey2, dz2 * ey1, dz2 * ex1, dz1 * ex2);
    let sum = (p1.abs() + p2.abs()) * (ex1.abs() + ex2.abs()) + (p3.abs() + p4.abs()) * (ey1.abs() + ey2.abs());
    // Written so that NaN fails it.
    (sum <= af).then(|| {
        let gx = (p1 - p2) / af; // per 1/16 pixel
        let gy = (p3 - p4) / af;
        let z_at_origin = az + gx * F32::from(ox - ax) + gy * F32::from(oy - ay);
        // Times 16, a power of two: exact, and no soft-float multiply without an FPU.
        (z_at_origin, F32(times_16(gx.0)), F32(times_16(gy.0)))
    })
}

/// `1 / area` for [`AffinePlanes::in_integers`] and [`integer_depth_plane`]: `area = m / 2^s`
/// with `m` in `2^31..2^32`, and `r ≈ 2^62 / m` (within about 2^-30 relative, see
/// `perspective::reciprocal`), so that `p · 2^k / area ≈ p · r / 2^(62 - s - k)`. Made once a
/// triangle (see `Setup::in_box`): a reciprocal is two Newton steps of 32 x 32-bit products,
/// each four 16-bit ones without a widening multiply (thumbv6m).
#[derive(Clone, Copy, Debug)]
pub(super) struct AreaReciprocal {
    r: u32,
    s: u32,
}

impl AreaReciprocal {
    /// The reciprocal of `area` (twice a triangle's area: positive, below 2^31).
    #[inline(always)]
    pub(super) fn new(area: u32) -> Self {
        debug_assert!(area > 0 && area < 1 << 31);
        let s = leading_zeros(area);
        // Capping `2^31` itself costs 2^-31 relative.
        AreaReciprocal { r: reciprocal(area << s).min((1 << 31) - 1), s }
    }

    /// `floor(p · 2^k / area)`, within 3 units (the reciprocal's 2^-29 of a value below 2^31,
    /// and the floor), when its magnitude is below 2^30; `None` for `|p| >= 2^n` (`n = 62 - s -
    /// k`), whose quotient is at least 2^30 (`r >= 2^30`). For `k <= 12`.
    #[inline(always)]
    fn times(&self, p: i64, k: u32) -> Option<i32> {
        // `s <= 31`: `n >= 19`.
        if at_least_power_of_two(p.unsigned_abs(), 62 - self.s - k) {
            return None;
        }
        // `|p · r / 2^n| < 2^31`: the quotient fits i32.
        Some(self.quotient(p, k) as i32)
    }

    /// `floor(p · 2^k / area)` within `1 + |quotient| · 2^-29`, for `k <= 14` and `p` below
    /// 2^47, or below `2^n` (`n = 62 - s - k`).
    #[inline(always)]
    fn quotient(&self, p: i64, k: u32) -> i64 {
        // `s <= 31`: `n >= 17`; `s >= 1`: `n <= 61 - k`.
        let n = 62 - self.s - k;
        // `p · r = ph · r · 2^32 + pl · r`, and `hi = floor(p · r / 2^32)`: `|ph| < 2^31`, so
        // each product is below 2^62.
        let (ph, pl) = ((p >> 32) as i32, p as u32);
        let low = mul_u32(pl, self.r);
        // `ph · r` needs no product for the common `|p| < 2^32` (a library-free but long one
        // without a widening multiply).
        let high = match ph {
            0 => 0,
            -1 => -i64::from(self.r),
            _ => mul_i32(ph, self.r as i32),
        };
        let hi = high + (low >> 32) as i64;
        // Below 32 the shift is left, of `|hi| < 2^46` (`p` below 2^47) by at most 15, or of
        // `|hi| < 2^(n - 1)` (`p` below `2^n`) by `32 - n`: within i64 either way.
        if n >= 32 {
            shr_i64(hi, n - 32)
        } else {
            shl_i64(hi, 32 - n) | i64::from(low as u32 >> n)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::perspective::tests::triangle;
    use super::super::{Setup, Window};
    use super::*;
    use crate::test_rng::Lcg;

    /// The integer plane terms against the exact quotients in f64, for random triangles (tiny
    /// to guard-band sized, varyings spanning 2^12 to 2^32 units): within 3 units of 2^-8
    /// wherever they are kept, refused only where the exact terms leave the bound (or come
    /// within 4 units of it), and kept or refused alike with the f32 planes but for such
    /// borderline triangles.
    #[test]
    fn integer_planes_are_within_three_units_of_the_exact_ones() {
        let mut rng = Lcg(0x6a09_e667_f3bc_c908);
        let window = Window { width: 1 << 11, row_start: 0, row_end: 1 << 11 };
        let (mut kept, mut refused, mut worst) = (0, 0, 0f64);
        for t in 0..20_000 {
            let extent = [1, 3, 40, 400, 1900][rng.below(5) as usize];
            let texels = [1 << 12, 1 << 16, 1 << 24, u32::MAX][rng.below(4) as usize];
            let mut tri = triangle(&mut rng, extent, 1.0, texels);
            // One base for the three texel coordinates u (`triangle` gives each its own).
            let base = rng.next() as i32;
            for v in &mut tri {
                v.varyings[0] = base.wrapping_add((rng.next() % texels) as i32);
            }
            let Ok(s) = Setup::<3>::new(&tri, &window, false, false) else { continue };
            let extent = (s.x1 - s.x0, s.rows_below);
            let planes =
                AffinePlanes::in_integers(&s.edges, &AreaReciprocal::new(s.area), (&s.v0, &s.d1, &s.d2), extent);
            let (d1, d2) = (s.d1.map(F32::from), s.d2.map(F32::from));
            let float = AffinePlanes::new(&s.edges, F32::from(s.area), (&s.v0, &d1, &d2), extent);
            // The exact terms, and whether they are within the bound with a margin of 4 units.
            let area = f64::from(s.area);
            let (e1, e2) = (&s.edges[1], &s.edges[2]);
            let exact = |k: usize, c1: i32, c2: i32, scale: f64| {
                (f64::from(s.d1[k]) * f64::from(c1) + f64::from(s.d2[k]) * f64::from(c2)) * scale / area
            };
            let terms =
                |k: usize| [exact(k, e1.c, e2.c, 256.0), exact(k, e1.a, e2.a, 4096.0), exact(k, e1.b, e2.b, 4096.0)];
            let (w, h) = (f64::from(extent.0.max(1)), f64::from(extent.1.max(1)));
            let reach = |[o, gx, gy]: [f64; 3], margin: f64| {
                (o.abs() + margin) + (gx.abs() + margin) * w + (gy.abs() + margin) * h
            };
            let clearly_in = (0..3).all(|k| reach(terms(k), 4.0) < f64::from(1 << 30) - 8.0);
            let clearly_out = (0..3).any(|k| reach(terms(k), -4.0) >= f64::from(1 << 30));
            match planes {
                Some(p) => {
                    assert!(!clearly_out, "triangle {t}: kept beyond the bound");
                    kept += 1;
                    for k in 0..3 {
                        let [o, gx, gy] = terms(k);
                        for (got, want) in [(p.term(k, ORIGIN), o), (p.term(k, GX), gx), (p.term(k, GY), gy)] {
                            let error = (f64::from(got) - want.floor()).abs();
                            worst = worst.max(error);
                            assert!(error <= 3.0, "triangle {t}, varying {k}: {got} for {want}");
                        }
                        assert_eq!(p.step[k], fdot8_round(p.term(k, GX)));
                    }
                }
                None => {
                    assert!(!clearly_in, "triangle {t}: refused within the bound");
                    refused += 1;
                }
            }
            if clearly_in || clearly_out {
                assert_eq!(planes.is_some(), float.is_some(), "triangle {t}: f32 planes decide otherwise");
            }
        }
        // Both outcomes, many times over.
        assert!(kept > 5000 && refused > 500, "{kept} kept, {refused} refused");
        std::println!("{kept} kept, {refused} refused; worst error {worst} units of 2^-8");
    }

    /// The integer depth plane against the exact one in f64 (from the same vertex depths in
    /// 2.30), for random triangles tiny to guard-band sized with depths over the whole range:
    /// gradients within a unit and 2^-28 relative, the origin's value within that error carried
    /// from vertex 0 plus the truncations.
    #[test]
    fn the_integer_depth_plane_is_within_its_bound() {
        let mut rng = Lcg(0xbb67_ae85_84ca_a73b);
        let window = Window { width: 1 << 11, row_start: 0, row_end: 1 << 11 };
        let mut checked = 0;
        for t in 0..20_000 {
            let extent = [1, 3, 40, 400, 1900][rng.below(5) as usize];
            let mut tri = triangle(&mut rng, extent, 1.0, 1);
            for v in &mut tri {
                v.z = [0.0, 1.0, rng.unit() as f32, 0.5 + rng.unit() as f32 / 1024.0][rng.below(4) as usize];
            }
            let Ok(s) = Setup::<3>::new(&tri, &window, false, false) else { continue };
            let order = if super::super::facing(&tri, false, false).unwrap() > 0 { [0, 1, 2] } else { [0, 2, 1] };
            let v = order.map(|i| tri[i]);
            let (ox, oy) = (s.x0 * 16 + 8, s.origin_row * 16 + 8);
            let (z0, dx, dy) = integer_depth_plane(v.map(|v| (v.x, v.y, v.z)), s.area, (ox, oy));
            let z = v.map(|v| (f64::from(v.z) * f64::from(1 << 30)).floor());
            let (ex1, ey1) = (f64::from(v[1].x - v[0].x), f64::from(v[1].y - v[0].y));
            let (ex2, ey2) = (f64::from(v[2].x - v[0].x), f64::from(v[2].y - v[0].y));
            let scale = f64::from(1 << 14) / f64::from(s.area);
            let gx = ((z[1] - z[0]) * ey2 - (z[2] - z[0]) * ey1) * scale;
            let gy = ((z[2] - z[0]) * ex1 - (z[1] - z[0]) * ex2) * scale;
            let (off_x, off_y) = (f64::from(ox - v[0].x) / 16.0, f64::from(oy - v[0].y) / 16.0);
            let origin = z[0] * 1024.0 + gx * off_x + gy * off_y;
            let bound = |g: f64| 1.0 + g.abs() / f64::from(1 << 28);
            assert!((dx as f64 - gx).abs() <= bound(gx), "triangle {t}: {dx} for {gx}");
            assert!((dy as f64 - gy).abs() <= bound(gy), "triangle {t}: {dy} for {gy}");
            if origin.abs() < 2f64.powi(60) {
                let carried = bound(gx) * off_x.abs() + bound(gy) * off_y.abs() + 2.0;
                assert!((z0 as f64 - origin).abs() <= carried, "triangle {t}: {z0} for {origin}");
                checked += 1;
            }
        }
        assert!(checked > 10_000, "{checked} checked");
        std::println!("{checked} checked");
    }
}
