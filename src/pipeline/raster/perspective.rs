//! Perspective-correct weights in integers: `b_k = E_k q_k / Σ E_j q_j` from the edge functions
//! `E_k` and fixed-point `1/w`s `q_k`, with 64-bit products, a normalising shift and a
//! reciprocal from a table plus two Newton steps. The same integers on every target; no float
//! and no division, so FPU-less targets (thumbv6m, riscv32imc) run no soft-float per row.
//!
//! # Numbers
//! - `q_k` has [`Q_BITS`] fractional bits, the largest exactly 1, the smallest at least
//!   [`Q_MIN`] (a depth ratio beyond 2^19 counts as 2^19).
//! - The edge functions are shifted left by a per-triangle amount that puts twice the area in
//!   `2^31..2^32`: inside the triangle `Σ E_k` is at least a third of that, so the 64-bit sum
//!   `Σ E_k q_k` is at least `2^29 · Q_MIN` and its upper half is never 0.
//! - A triangle whose `1/w`s lie within a factor of two and whose varyings span under 2^20
//!   units ([`is_narrow`]) is weighed from 16-bit operands instead ([`narrow_weights`],
//!   [`narrow_interpolate`]): 32-bit products only, one Newton step, within 2^7 units.
//!
//! # Precision
//! A 1000:1 depth ratio leaves the smallest `q` 21 significant bits, a relative error of 2^-21
//! that moves a weight by at most a quarter of that; the shifts, the reciprocal and the
//! products each add about 2^-30. So a weight is within about 2^-22 of the exact one: a
//! varying spanning 2^31 units (32,768 texels) is off by under 2^9 units (1/128 texel); see the
//! test against f64 below.

/// Fractional bits of the fixed-point `1/w`s (the largest is exactly `1 << Q_BITS`).
pub(super) const Q_BITS: u32 = 31;

/// The smallest fixed-point `1/w` (see the module's numbers).
pub(super) const Q_MIN: u32 = 1 << 12;

/// Fractional bits of a weight ([`weights`]).
const WEIGHT_BITS: u32 = 30;

/// `a · b` in full: from 16-bit halves ([`mul_u32_halves`]) where there is no widening
/// multiply (Armv6-M, RISC-V without `m`: a 64-bit multiply there is a library call).
#[inline(always)]
pub(crate) fn mul_u32(a: u32, b: u32) -> u64 {
    #[cfg(no_hw_divide)]
    {
        mul_u32_halves(a, b)
    }
    #[cfg(not(no_hw_divide))]
    {
        u64::from(a) * u64::from(b)
    }
}

/// `a · b` in full, for a `b` usually below 2^16 (a box's width, a tolerance): there, where
/// there is no widening multiply (see [`mul_u32`]), from two 16 x 16-bit products instead of
/// [`mul_u32_halves`]'s four.
#[inline(always)]
pub(super) fn mul_u32_small(a: u32, b: u32) -> u64 {
    #[cfg(no_hw_divide)]
    {
        mul_u32_small_halves(a, b)
    }
    #[cfg(not(no_hw_divide))]
    {
        u64::from(a) * u64::from(b)
    }
}

/// `a · b` in full, signed (see [`mul_u32`], [`mul_i32_halves`]).
#[inline(always)]
pub(crate) fn mul_i32(a: i32, b: i32) -> i64 {
    #[cfg(no_hw_divide)]
    {
        mul_i32_halves(a, b)
    }
    #[cfg(not(no_hw_divide))]
    {
        i64::from(a) * i64::from(b)
    }
}

/// [`mul_u32_small`] from 16 x 16-bit products: two for `b < 2^16`, else four.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn mul_u32_small_halves(a: u32, b: u32) -> u64 {
    if b >> 16 != 0 {
        return mul_u32_halves(a, b);
    }
    (u64::from((a >> 16) * b) << 16) + u64::from((a & 0xffff) * b)
}

/// `a · b` from four 16 x 16-bit products.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn mul_u32_halves(a: u32, b: u32) -> u64 {
    let (ah, al, bh, bl) = (a >> 16, a & 0xffff, b >> 16, b & 0xffff);
    let middle = u64::from(ah * bl) + u64::from(al * bh);
    (u64::from(ah * bh) << 32) + (middle << 16) + u64::from(al * bl)
}

/// `a · b` from four 16 x 16-bit products of signed upper halves (`-2^15..2^15`) and unsigned
/// lower ones: every partial product but the lowest fits i32 (at most `2^15 · (2^16 - 1)`),
/// and no sign needs fixing afterwards (fewer instructions than [`mul_u32_halves`] of the
/// magnitudes and a negation).
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn mul_i32_halves(a: i32, b: i32) -> i64 {
    let (ah, al, bh, bl) = (a >> 16, a & 0xffff, b >> 16, b & 0xffff);
    let middle = i64::from(ah * bl) + i64::from(al * bh);
    (i64::from(ah * bh) << 32) + (middle << 16) + i64::from((al as u32) * (bl as u32))
}

/// `≈ 2^62 / d` for `d >= 2^31` (in `2^30..=2^31`), within about 2^-30 relative: an estimate
/// good to 2^-8 from [`RECIPROCALS`], then two Newton steps `x (2 - d x)`, each squaring the
/// error (and approaching from below: no overflow).
#[inline(always)]
pub(crate) fn reciprocal(d: u32) -> u32 {
    debug_assert!(d >= 1 << 31);
    let x = reciprocal_step(d);
    let dx = (mul_u32(d, x) >> 32) as u32;
    let e = (dx << 1).wrapping_neg();
    (mul_u32(x, e) >> 31) as u32
}

/// [`reciprocal`]'s estimate after its first Newton step: `≈ 2^62 / d` for `d >= 2^31`, within
/// about 2^-17 relative, from below.
#[inline(always)]
fn reciprocal_step(d: u32) -> u32 {
    // The first step from the table's 16 bits `t` (`x = t·2^15`): `d x / 2^32 = d t / 2^17` and
    // `x e / 2^31 = t e / 2^16`, products of 32 by 16 bits (two halves' products without a
    // widening multiply, not four); the same integers.
    let t = RECIPROCALS[(d >> 24) as usize & 127];
    // `d x` (2^30 for 1), then `2 - d x` (2^31 for 1).
    let e = (((mul_u32_u16(d, t) >> 17) as u32) << 1).wrapping_neg();
    (mul_u32_u16(e, t) >> 16) as u32
}

/// `a · b` in full for a 16-bit `b`: two 16 x 16-bit products where there is no widening
/// multiply (see [`mul_u32`]).
#[inline(always)]
fn mul_u32_u16(a: u32, b: u16) -> u64 {
    #[cfg(no_hw_divide)]
    {
        mul_u32_u16_halves(a, b)
    }
    #[cfg(not(no_hw_divide))]
    {
        u64::from(a) * u64::from(b)
    }
}

/// [`mul_u32_u16`] from two 16 x 16-bit products.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn mul_u32_u16_halves(a: u32, b: u16) -> u64 {
    let b = u32::from(b);
    (u64::from((a >> 16) * b) << 16) + u64::from((a & 0xffff) * b)
}

/// `2^39 / (2i + 257)` for `i` in `0..128`, `>> 15`: the reciprocal (`2^62 / d`, its upper 16
/// bits) at the middle of the `i`th of the 128 intervals of `d >> 24` in `128..256`.
const RECIPROCALS: [u16; 128] = {
    let mut t = [0; 128];
    let mut i = 0;
    while i < 128 {
        t[i] = (((1u64 << 39) / (2 * i as u64 + 257)) >> 15) as u16;
        i += 1;
    }
    t
};

/// The `1/w`s `inv_w` of a triangle's vertices (positive and finite) divided by the largest, in
/// `Q_BITS` fixed point: the largest exactly `1 << Q_BITS`, the others from the significands'
/// quotient through [`reciprocal`] (within 3 units: the reciprocal's 2^-30 of 2^31, and the
/// truncation), at least [`Q_MIN`] and at most `1 << Q_BITS`. In integers: no soft-float
/// division without an FPU. Out of line with an FPU, whose draws use it only without f32
/// perspective (`RenderOptions::fixed_vertices`).
#[cfg_attr(soft_float, inline(always))]
#[cfg_attr(not(soft_float), inline(never))]
pub(super) fn normalised_q(inv_w: [f32; 3]) -> [u32; 3] {
    // Positive floats order as their bits do.
    let bits = inv_w.map(f32::to_bits);
    let max = bits[0].max(bits[1]).max(bits[2]);
    let (e_max, m_max) = unpack_positive(max);
    // `≈ 2^54 / m_max`, so that `m · r / 2^23 ≈ m · 2^31 / m_max`, below 2^32 (`m < 2 · m_max`).
    let r = reciprocal(m_max << 8);
    let q = |b: u32| {
        let (e, m) = unpack_positive(b);
        let shift = (e_max - e) as u32;
        if b == max {
            1 << Q_BITS
        } else if shift > 20 {
            // Below 2^(1 - shift) of the largest: less than `Q_MIN`.
            Q_MIN
        } else {
            (((mul_u32(m, r) >> 23) as u32) >> shift).clamp(Q_MIN, 1 << Q_BITS)
        }
    };
    // Spelt out: an array's `map` is a call of its own on Armv6-M (not inlined).
    [q(bits[0]), q(bits[1]), q(bits[2])]
}

/// A positive float's exponent and significand (in `2^23..2^24`; subnormals normalised, their
/// exponents below 1).
#[inline(always)]
fn unpack_positive(bits: u32) -> (i32, u32) {
    let (e, fraction) = ((bits >> 23) as i32, bits & 0x7f_ffff);
    if e != 0 {
        return (e, fraction | 1 << 23);
    }
    // Subnormal (`fraction > 0`: the float is positive): rare, out of the way.
    let shift = leading_zeros(fraction) - 8;
    (1 - shift as i32, fraction << shift)
}

/// The shift for the edge functions of a triangle whose doubled area is `area` (> 0): see the
/// module's numbers.
#[inline(always)]
pub(super) fn edge_shift(area: u32) -> u32 {
    // Not `area.leading_zeros()`: a library call without a count-leading-zeros instruction.
    leading_zeros(area)
}

/// The weights of vertices 1 and 2 (fractions of `2^WEIGHT_BITS`) where the edge functions are
/// `e` (of a pixel inside the triangle; negative ones count as 0), shifted by `shift` (see
/// [`edge_shift`]), and the `1/w`s `q`; and the upper half of the sum `Σ e_k q_k` (proportional
/// to the pixel's `1/w`, with at least 17 significant bits for a 1000:1 depth ratio). `None`
/// where that is 0 (every edge function is 0: never inside).
#[inline(always)]
pub(super) fn weights(e: [i32; 3], shift: u32, q: &[u32; 3]) -> Option<([i32; 2], u32)> {
    // Each below 2^32 · 2^31 and (inside the triangle) their sum too; wrapping outside.
    let n = |k: usize| mul_u32((e[k].max(0) as u32) << shift, q[k]);
    let (n1, n2) = (n(1), n(2));
    let sum = n(0).wrapping_add(n1).wrapping_add(n2);
    let high = (sum >> 32) as u32;
    if high == 0 {
        return None;
    }
    // Top bit at 63: 32 significant bits of each in its upper half, `n_k <= sum`.
    let s = leading_zeros(high);
    // `(n << s) >> 32` in halves, with no shift by 32 (`s` is below 32).
    let top = |n: u64| (((n >> 32) as u32) << s) | (((n as u32) >> 1) >> (31 - s));
    let inv = reciprocal(top(sum));
    let weight = |n: u64| (mul_u32(top(n), inv) >> 32) as i32;
    Some(([weight(n1), weight(n2)], high))
}

/// Whether a triangle's integer weights may come from [`narrow_weights`]: its `1/w`s within a
/// factor of two (the smallest `q_min` at least half the largest, `1 << Q_BITS`) and every
/// varying's `ranges` (over its three vertices) below 2^20 units (16 texels, or 16 times full
/// light).
#[inline(always)]
pub(super) fn is_narrow(q_min: u32, mut ranges: impl Iterator<Item = u32>) -> bool {
    q_min >= 1 << (Q_BITS - 1) && ranges.all(|range| range < 1 << 20)
}

/// [`weights`] for a triangle [`is_narrow`] allows, from 16-bit operands: every product is 16 x
/// 16 bits (one multiply without a widening one), the reciprocal one Newton step; the weights
/// in 16 fractional bits (for [`narrow_interpolate`]).
///
/// `E_k << shift` is below 2^32 and their sum too (see [`weights`]), so their upper halves
/// `e_k` sum to under 2^16: exact where `shift >= 16` (twice the area below 2^16), else each
/// off by under 1 of at least 2^15 - 3 in all; `q_k >> 16` is in `2^14..=2^15`, off by under
/// 2^-14 relative. The sum `S = Σ e_k (q_k >> 16)` is below 2^31 (no overflow) and, for twice
/// the area at least 4 (its `E_k` sum at least a quarter of it, the fill rule's biases apart),
/// at least 2^27; 0 only where every `E_k` is (`None`, as [`weights`] gives). The reciprocal of
/// `S` normalised is within about 2^-17, each weight's product of upper halves within 2^-15
/// more (and at most 2^16): a weight is within about 2^-13 of the exact one, a varying within
/// 2^7 units (1/512 texel).
/// `S` stands for the pixel's `1/w` in [`linear_within`], alike at both ends of a run.
#[inline(always)]
pub(super) fn narrow_weights(e: [i32; 3], shift: u32, q: &[u32; 3]) -> Option<([i32; 2], u32)> {
    // Each below 2^31 (`q_k <= 2^31`), and (inside the triangle) their sum too; wrapping
    // outside, as in `weights`.
    let n = |k: usize| (((e[k].max(0) as u32) << shift) >> 16) * (q[k] >> 16);
    let (n1, n2) = (n(1), n(2));
    let sum = n(0).wrapping_add(n1).wrapping_add(n2);
    if sum == 0 {
        return None;
    }
    // `sum << s` in `2^31..2^32`, and `x ≈ 2^62 / (sum << s)` in `2^30..=2^31`: the weight
    // `n · 2^16 / sum = (n << s) · x / 2^46`, from the upper 16 bits of each (`n <= sum`).
    let s = leading_zeros(sum);
    let x = reciprocal_step(sum << s) >> 15;
    let weight = |n: u32| ((((n << s) >> 16) * x) >> 15) as i32;
    Some(([weight(n1), weight(n2)], sum))
}

/// `v0 + d1 · w1 + d2 · w2` for [`narrow_weights`]' weights (at most `2^16`) and differences
/// below 2^20 in magnitude ([`is_narrow`]): `d = dh · 2^16 + dl` (`|dh| < 2^4`, `dl` below
/// 2^16), so each product is two 16-bit ones within 32 bits (`dl · w` unsigned); truncating
/// drops under a unit each.
#[inline(always)]
pub(super) fn narrow_interpolate(v0: i32, d1: i32, d2: i32, [w1, w2]: [i32; 2]) -> i32 {
    debug_assert!((0..=1 << 16).contains(&w1) && (0..=1 << 16).contains(&w2));
    let weighted = |d: i32, w: i32| (d >> 16) * w + (((d & 0xffff) as u32).wrapping_mul(w as u32) >> 16) as i32;
    v0.wrapping_add(weighted(d1, w1) + weighted(d2, w2))
}

/// `v0 + d1 · w1 + d2 · w2` for weights `w` from [`weights`], wrapping: each product's upper
/// half (a single instruction on Cortex-M4), which drops under 2^-(32 - WEIGHT_BITS) units
/// each (8 units of 2^-16 in all, far below a texel or a step of light).
#[inline(always)]
pub(super) fn interpolate(v0: i32, d1: i32, d2: i32, [w1, w2]: [i32; 2]) -> i32 {
    v0.wrapping_add(weighted(d1, w1).wrapping_add(weighted(d2, w2)) << (32 - WEIGHT_BITS))
}

/// The upper half of `d · w` for a weight `w` in `0..=2^30` (see [`weights`]): without a
/// widening multiply (see [`mul_u32`]), from four 16-bit products in 32-bit sums (no 64-bit
/// additions).
#[inline(always)]
fn weighted(d: i32, w: i32) -> i32 {
    debug_assert!((0..=1 << WEIGHT_BITS).contains(&w));
    #[cfg(no_hw_divide)]
    {
        weighted_halves(d, w)
    }
    #[cfg(not(no_hw_divide))]
    {
        (mul_i32(d, w) >> 32) as i32
    }
}

/// [`weighted`] from halves: `d = dh·2^16 + dl` (`dh` signed), `w = wh·2^16 + wl` (`wh` at most
/// 2^14), so `d · w = dh·wh·2^32 + (dh·wl + dl·wh)·2^16 + dl·wl`, each partial sum below within
/// i32 or u32 where it is formed, and the floors of the divisions by 2^16 carry exactly.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn weighted_halves(d: i32, w: i32) -> i32 {
    let (dh, dl, wh, wl) = (d >> 16, (d & 0xffff) as u32, w >> 16, (w & 0xffff) as u32);
    // `|dh·wl| <= 2^15·(2^16 - 1)`, plus `dl·wl / 2^16 < 2^16`: within i32.
    let m1 = dh * wl as i32 + ((dl * wl) >> 16) as i32;
    // `dl·wh < 2^30`, plus the low half of `m1`: within i32.
    let m2 = (dl * wh as u32) as i32 + (m1 & 0xffff);
    dh * wh + (m1 >> 16) + (m2 >> 16)
}

/// Whether `range · (1/q_min - 1) <= four_tolerance` for the smallest of a triangle's `1/w`s,
/// `q_min` (the largest being 1): see `Setup::allow_affine`. Exact.
#[inline(always)]
pub(super) fn affine_within(range: u32, q_min: u32, four_tolerance: u32) -> bool {
    // `1 << Q_BITS` is 1. The pipeline's tolerances are at most 2^12 (see `mul_u32_small`).
    mul_u32(range, (1 << Q_BITS) - q_min) <= mul_u32_small(q_min, four_tolerance)
}

/// Whether `|dv| · (max(qa, qb) / min(qa, qb) - 1) <= four_tolerance` for every varying, with
/// `dv` the differences between a segment's ends and `qa`, `qb` the sums of [`weights`] there;
/// rounded towards refusing: the sums' upper halves truncate them, so their difference is
/// taken one larger (false where either is 0).
#[inline(always)]
pub(super) fn linear_within<const V: usize>(
    dv: [i32; V],
    (qa, qb): (u32, u32),
    four_tolerance: &[u32; V],
    narrow: bool,
) -> bool {
    let (lo, hi) = if qa < qb { (qa, qb) } else { (qb, qa) };
    if lo == 0 {
        return false;
    }
    if narrow {
        // [`narrow_weights`]' sums (at least 2^27 but for the tiniest triangles, below 2^31)
        // are within about 2^-13 relative of the exact ones' ratio: in units of 2^16, their
        // difference rounded up with that margin (below 2^15 + 9) and the smaller rounded down:
        // products by 16 bits.
        let (lo, diff) = (lo >> 16, ((hi - lo) >> 16) + 1 + (hi >> 28));
        return (0..V).all(|k| mul_u32_u16(dv[k].unsigned_abs(), diff as u16) <= mul_u32_small(four_tolerance[k], lo));
    }
    let diff = (hi - lo).saturating_add(1);
    (0..V).all(|k| mul_u32(dv[k].unsigned_abs(), diff) <= mul_u32_small(lo, four_tolerance[k]))
}

/// `x.leading_zeros()` for `x > 0`, with no library call (see
/// [`leading_zeros_by_table`](crate::math::leading_zeros_by_table)).
#[inline(always)]
pub(crate) fn leading_zeros(x: u32) -> u32 {
    #[cfg(any(no_hw_divide, target_arch = "riscv32"))]
    {
        crate::math::leading_zeros_by_table(x)
    }
    #[cfg(not(any(no_hw_divide, target_arch = "riscv32")))]
    {
        x.leading_zeros()
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::{ScreenVertex, Setup, Window};
    use super::*;
    use crate::test_rng::Lcg;

    /// The products from 16-bit halves are the full products, at the extremes and for random
    /// factors of every size.
    /// The weighted product from halves is the 64-bit product's upper half.
    #[test]
    fn weighted_halves_is_the_upper_half() {
        let mut rng = Lcg(0x51f1_5eed);
        let edges = [0, 1, -1, 0xffff, -0x1_0000, 0x7fff_ffff, i32::MIN, 0x1234_5678];
        for k in 0..1_000_000 {
            let d = if k % 5 == 0 { edges[k % edges.len()] } else { rng.next() as i32 };
            let w = if k % 7 == 0 { [0, 1, 0xffff, 1 << 30][k % 4] } else { rng.below((1 << 30) + 1) as i32 };
            assert_eq!(weighted_halves(d, w), ((i64::from(d) * i64::from(w)) >> 32) as i32, "{d} * {w}");
        }
    }

    #[test]
    fn products_from_halves_are_exact() {
        let mut rng = Lcg(0x3c6e_f372_fe94_f82b);
        let edges = [0, 1, 0xffff, 0x1_0000, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff];
        let mut pairs: std::vec::Vec<(u32, u32)> =
            edges.iter().flat_map(|&a| edges.iter().map(move |&b| (a, b))).collect();
        for _ in 0..100_000 {
            let size = |rng: &mut Lcg| rng.next() >> rng.below(32);
            pairs.push((size(&mut rng), size(&mut rng)));
        }
        for (a, b) in pairs {
            assert_eq!(mul_u32_halves(a, b), u64::from(a) * u64::from(b), "{a} * {b}");
            for (a, b) in [(a as i32, b as i32), (a as i32, (b as i32).wrapping_neg())] {
                assert_eq!(mul_i32_halves(a, b), i64::from(a) * i64::from(b), "{a} * {b}");
            }
        }
    }

    /// `normalised_q` against the quotients in f64, for `1/w`s from subnormal to huge and depth
    /// ratios from 1 to beyond `Q_MIN`'s: the largest exactly `1 << Q_BITS`, the others within
    /// 3 units of the exact value, or `Q_MIN` where that is smaller.
    #[test]
    fn normalised_q_is_within_two_units_of_the_quotient() {
        let mut rng = Lcg(0x3c6e_f372_fe94_f82b);
        for t in 0..200_000 {
            let scale = 2f64.powi(rng.below(250) as i32 - 140);
            let ratio: f64 = [1.0, 1.0001, 3.0, 1000.0, 1e7][rng.below(5) as usize];
            let inv_w: [f32; 3] =
                core::array::from_fn(|_| ((scale * ratio.powf(-rng.unit())) as f32).max(f32::from_bits(1)));
            let q = normalised_q(inv_w);
            let max = inv_w[0].max(inv_w[1]).max(inv_w[2]);
            for k in 0..3 {
                let exact = f64::from(inv_w[k]) / f64::from(max) * f64::from(1u32 << Q_BITS);
                if inv_w[k] == max {
                    assert_eq!(q[k], 1 << Q_BITS, "{t}: {inv_w:?}");
                } else if exact < f64::from(Q_MIN) {
                    assert_eq!(q[k], Q_MIN, "{t}: {inv_w:?}");
                } else {
                    let error = (exact - f64::from(q[k])).abs();
                    assert!(error <= 3.0, "{t}: {inv_w:?} {k}: {} for {exact}", q[k]);
                }
            }
        }
    }

    #[test]
    fn multiplies_and_inverts() {
        let mut rng = Lcg(0x2545_f491);
        let mut next = || rng.next();
        for _ in 0..100_000 {
            let (a, b) = (next(), next());
            assert_eq!(mul_u32(a, b), a as u64 * b as u64);
            assert_eq!(mul_u32_small_halves(a, b), a as u64 * b as u64);
            assert_eq!(mul_u32_small_halves(a, b & 0xffff), a as u64 * (b & 0xffff) as u64);
            assert_eq!(mul_u32_u16_halves(a, b as u16), a as u64 * (b & 0xffff) as u64);
            let x = a >> (b % 32) | 1;
            assert_eq!(crate::math::leading_zeros_by_table(x), x.leading_zeros());
            let (a, b) = (a as i32, b as i32);
            assert_eq!(mul_i32(a, b), a as i64 * b as i64);
            let d = next() | 1 << 31;
            let exact = (1u128 << 62) as f64 / d as f64;
            let x = reciprocal(d) as f64;
            assert!((x - exact).abs() <= exact * 2f64.powi(-29), "1/{d}: {x} against {exact}");
        }
        for d in [1 << 31, (1 << 31) + 1, u32::MAX] {
            let exact = (1u128 << 62) as f64 / d as f64;
            assert!((reciprocal(d) as f64 - exact).abs() <= exact * 2f64.powi(-29), "1/{d}");
        }
    }

    /// The reciprocal's first Newton step from the table's 16 bits gives the same integers as
    /// two full steps from `x = t·2^15`: every table interval's ends and random divisors.
    #[test]
    fn reciprocal_is_two_newton_steps() {
        let two_steps = |d: u32| {
            let mut x = u32::from(RECIPROCALS[(d >> 24) as usize & 127]) << 15;
            for _ in 0..2 {
                let dx = ((d as u64 * x as u64) >> 32) as u32;
                let e = (dx << 1).wrapping_neg();
                x = ((x as u64 * e as u64) >> 31) as u32;
            }
            x
        };
        let mut rng = Lcg(0x7ec1_9c0a);
        let ends = (128..256u32).flat_map(|i| [i << 24, (i << 24) | 0xff_ffff]);
        for d in ends.chain((0..100_000).map(|_| rng.next() | 1 << 31)) {
            assert_eq!(reciprocal(d), two_steps(d), "1/{d}");
        }
    }

    /// A random triangle within `extent` pixels (28.4), with `1/w`s up to `ratio`:1 apart and
    /// varyings 0, 1 (texels) spanning up to `texels` units and 2 (light) within 0..=1.
    pub(in crate::pipeline::raster) fn triangle(
        rng: &mut Lcg,
        extent: u32,
        ratio: f64,
        texels: u32,
    ) -> [ScreenVertex; 3] {
        let scale = 2f64.powi(rng.below(40) as i32 - 20);
        core::array::from_fn(|_| {
            let mut varyings = [0; 8];
            let base = rng.next() as i32;
            varyings[0] = base.wrapping_add((rng.next() % texels.max(1)) as i32);
            varyings[1] = ((rng.next() % texels.max(1)) as i32).wrapping_sub((texels / 2) as i32);
            varyings[2] = rng.below((1 << 16) + 1) as i32;
            ScreenVertex {
                x: rng.below(extent * 16) as i32,
                y: rng.below(extent * 16) as i32,
                z: 0.5,
                inv_w: (scale * ratio.powf(-rng.unit())) as f32,
                varyings,
            }
        })
    }

    /// `varyings_at` against the perspective-correct value in f64 (the same edge functions, the
    /// vertices' `1/w` as given), at both ends and the middle of every covered row of random
    /// triangles: tiny to guard-band sized, depth ratios up to 1000:1, texel
    /// coordinates spanning up to 2^31 units, light 0..=1. Texels stay within 1/64 texel
    /// (2^10 units), light within 1/4096 (2^4 units): well inside the 1/16 texel and 1/256
    /// light the pictures are allowed, with the linear steps' own tolerance on top. Both ways:
    /// in integers (narrow triangles' from 16-bit operands among them) and in f32
    /// (`Setup::use_fpu_perspective`).
    #[test]
    fn varyings_at_is_within_the_bound_of_the_exact_value() {
        let mut rng = Lcg(0x853c_49e6_748f_ea9b);
        let window = Window { width: 1 << 12, row_start: 0, row_end: 1 << 12 };
        let (mut worst, mut worst_narrow, mut pixels, mut narrow) = ([0i64; 3], [0i64; 3], 0, 0);
        for t in 0..6000 {
            let extent = [1, 3, 40, 400, 1900][rng.below(5) as usize];
            let ratio = [1.0, 1.5, 10.0, 1000.0, 1000.0][rng.below(5) as usize];
            let texels = [1 << 12, 1 << 24, u32::MAX][rng.below(3) as usize];
            let mut tri = triangle(&mut rng, extent, ratio, texels);
            if t % 4 == 0 {
                // One base for the three texel coordinates u (`triangle` gives each its own),
                // and both texel coordinates spanning up to the narrow weights' bound: narrow
                // triangles, for ratios up to 2.
                let span = [1 << 12, 1 << 19, (1 << 20) - 1][rng.below(3) as usize];
                for k in 1..3 {
                    tri[k].varyings[0] = tri[0].varyings[0].wrapping_add((rng.next() % span) as i32);
                    tri[k].varyings[1] = tri[0].varyings[1].wrapping_add((rng.next() % span) as i32);
                }
            }
            let Ok(mut setup) = Setup::<3>::new(&tri, &window, false, false) else { continue };
            if t % 2 == 1 {
                setup.use_fpu_perspective();
            } else {
                // Which decides whether the weights are narrow (the tolerance changes nothing
                // here: `varyings_at` is exact whether affine is allowed or not).
                setup.allow_affine([0; 3]);
            }
            if setup.e_shift >= super::super::NARROW && !setup.fpu {
                narrow += 1;
            }
            // The vertices in the set-up's order (reordered for a positive area).
            let order =
                if crate::pipeline::raster::facing(&tri, false, false).unwrap() > 0 { [0, 1, 2] } else { [0, 2, 1] };
            let v = order.map(|i| tri[i]);
            let stride = 1 + (setup.y1 - setup.y0) / 50;
            for (_, dy, lo, hi) in setup.covered_rows().step_by(stride as usize) {
                for x in [lo, (lo + hi) / 2, hi] {
                    let e: [i32; 3] = core::array::from_fn(|k| {
                        let edge = &setup.edges[k];
                        edge.c + edge.b * 16 * dy + edge.a * 16 * x
                    });
                    let n: [f64; 3] = core::array::from_fn(|k| e[k].max(0) as f64 * v[k].inv_w as f64);
                    let sum = n[0] + n[1] + n[2];
                    if sum == 0.0 {
                        // Every edge function 0 (a triangle of area 1 whose ties leave none):
                        // no perspective value to compare with.
                        continue;
                    }
                    let (got, _) = setup.varyings_at(e);
                    for k in 0..3 {
                        let d = |i: usize| v[i].varyings[k].wrapping_sub(v[0].varyings[k]) as f64;
                        let exact = v[0].varyings[k] as f64 + (d(1) * n[1] + d(2) * n[2]) / sum;
                        // The difference modulo 2^32 (varyings wrap).
                        let error = (got[k] as i64 - exact.round() as i64) as i32 as i64;
                        worst[k] = worst[k].max(error.abs());
                        if setup.e_shift >= super::super::NARROW && !setup.fpu {
                            worst_narrow[k] = worst_narrow[k].max(error.abs());
                        }
                        let bound = if k == 2 { 1 << 4 } else { 1 << 10 };
                        assert!(
                            error.abs() <= bound,
                            "triangle {t} {tri:?}, row {dy} column {x}, varying {k}: {error}"
                        );
                    }
                    pixels += 1;
                }
            }
        }
        assert!(pixels > 100_000 && narrow > 100, "{pixels} pixels, {narrow} narrow triangles");
        std::println!("worst errors {worst:?} over {pixels} pixels, {worst_narrow:?} in narrow triangles");
    }

    /// `linear_within` never allows more than the exact bound (f64) does, for any sums and for
    /// narrow weights' (below 2^31).
    #[test]
    fn linear_within_is_never_looser_than_the_exact_bound() {
        let mut rng = Lcg(0xda3e_39cb_94b9_5bdb);
        let mut allowed = [0; 2];
        for t in 0..400_000 {
            let narrow = t % 2 == 1;
            let qa = (rng.next() >> u32::from(narrow)) >> rng.below(32);
            let qb = (qa as f64 * (1.0 + rng.unit() * [1e-6, 1e-3, 1e-1, 10.0][rng.below(4) as usize])) as u32;
            let qb = if narrow { qb.min((1 << 31) - 1) } else { qb };
            let dv = [rng.next() as i32 >> rng.below(32), rng.next() as i32 >> rng.below(32)];
            let tolerance = [1 << rng.below(20), 1 << rng.below(20)];
            if linear_within(dv, (qa, qb), &tolerance, narrow) {
                allowed[usize::from(narrow)] += 1;
                let ratio = qa.max(qb) as f64 / qa.min(qb) as f64 - 1.0;
                for k in 0..2 {
                    assert!(
                        dv[k].unsigned_abs() as f64 * ratio <= tolerance[k] as f64,
                        "{dv:?} {qa} {qb} {tolerance:?}, narrow {narrow}"
                    );
                }
            }
        }
        assert!(allowed[0] > 10_000 && allowed[1] > 5_000, "{allowed:?}");
    }
}
