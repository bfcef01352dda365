//! Float operations with the same bits as f32's own, which FPU-less targets (`cfg(soft_float)`)
//! work out from the bits where that is exact and much cheaper than the soft-float library:
//! multiplies by powers of two, an addition to +0, a 16-bit integer times a float.

#[cfg(soft_float)]
use super::soft;

use super::F32;

/// `x · 16`, the same bits as the float multiply: without an FPU, from the bits when that is
/// exact ([`times_power_of_two`]), as the multiply costs about 66 instructions there.
#[inline(always)]
#[must_use]
pub fn times_16(x: f32) -> f32 {
    times_power_of_two(x, 16.0)
}

/// `x · m`, the same bits as the float multiply; without an FPU, from the bits when `m` is a
/// positive normal power of two and the product is exact (`times_pow2_bits`).
#[inline(always)]
#[must_use]
pub fn times_power_of_two(x: f32, m: f32) -> f32 {
    #[cfg(soft_float)]
    {
        // The sign bit makes a negative `m`'s exponent field over 255.
        let (mb, e) = (m.to_bits(), (m.to_bits() >> 23) as i32);
        if mb & 0x7f_ffff == 0 && (1..=254).contains(&e) {
            if let Some(y) = times_pow2_bits(x, e - 127) {
                return y;
            }
        }
    }
    (F32(x) * F32(m)).0
}

/// `a + b`, the same bits as the float addition (NaN: some NaN); without an FPU, from `b`'s
/// bits when `a` is +0 (the usual texel offset), as the addition costs about 70 instructions
/// there.
#[inline(always)]
#[must_use]
pub fn offset_add(a: f32, b: f32) -> f32 {
    #[cfg(soft_float)]
    if a.to_bits() == 0 {
        return zero_plus(b);
    }
    (F32(a) + F32(b)).0
}

/// `(n as f32) · b`, the same bits; without an FPU in one step (`soft::mul_u16`).
#[inline(always)]
#[must_use]
pub fn u16_times(n: u16, b: f32) -> f32 {
    #[cfg(soft_float)]
    {
        soft::mul_u16(n, b)
    }
    #[cfg(not(soft_float))]
    {
        (F32::from(u32::from(n)) * F32(b)).0
    }
}

/// `to_i32(times_power_of_two(u16_times(n, b), m))` (the texel coordinate of a vertex) in one
/// step from the bits, the same integer: the 40-bit product `n · b` rounded to 24 bits (to
/// nearest, ties to even, as the float multiply rounds), scaled by `m`, truncated towards zero
/// and saturated. For a normal `b` and a positive normal power of two `m`; `None` otherwise.
/// Without an FPU it replaces a software multiply and a conversion (about 75 instructions)
/// with a few integer operations. The pipeline uses [`U16Scale`], which takes `b` and `m` apart
/// once for many `n`.
#[cfg(test)]
#[must_use]
pub fn u16_times_to_i32(n: u16, b: f32, m: f32) -> Option<i32> {
    U16Scale::new(b, m)?.times_to_i32(n)
}

/// The factors `b` and `m` of [`u16_times_to_i32`], taken apart once (a mesh's texel scale and
/// texture size, the same for all its vertices).
#[cfg(any(soft_float, test))]
#[derive(Clone, Copy, Debug)]
pub struct U16Scale {
    /// `b`'s 24-bit significand, the implicit bit set.
    significand: u32,
    /// The power of two of the product's unit: `b`'s exponent less the significand's 23
    /// fraction bits, plus `m`'s.
    shift: i32,
    /// `b` is negative.
    negative: bool,
}

#[cfg(any(soft_float, test))]
impl U16Scale {
    /// `b` and `m` taken apart, when `b` is normal and `m` a positive normal power of two of at
    /// least 1 (see [`u16_times_to_i32`]).
    #[inline(always)]
    #[must_use]
    pub fn new(b: f32, m: f32) -> Option<Self> {
        let (bb, mb) = (b.to_bits(), m.to_bits());
        let (eb, em) = (((bb >> 23) & 0xff) as i32, (mb >> 23) as i32);
        if !(1..=254).contains(&eb) || mb & 0x7f_ffff != 0 || !(127..=254).contains(&em) {
            return None;
        }
        let significand = (bb & 0x7f_ffff) | 1 << 23;
        Some(U16Scale { significand, shift: eb - 150 + em - 127, negative: bb >> 31 != 0 })
    }

    /// [`u16_times_to_i32`] of `n` and these factors.
    #[inline(always)]
    #[must_use]
    pub fn times_to_i32(self, n: u16) -> Option<i32> {
        let significand = self.significand;
        if n == 0 {
            return Some(0);
        }
        // `n · significand` below 2^40, as `upper · 2^32 + lower`, in 32-bit halves (a 64-bit
        // shift by a variable amount is a library call on Armv6-M).
        let (high, low) = (u32::from(n) * (significand >> 16), u32::from(n) * (significand & 0xffff));
        let lower = low.wrapping_add(high << 16);
        let upper = (high >> 16) + u32::from(lower < low);
        // The bits below the float's 24 (as many as the product has above 2^24).
        let top = (upper << 8) | (lower >> 24);
        let dropped = if top == 0 { 0 } else { 32 - super::leading_zeros_by_table(top) };
        let (mut kept, rest) = if dropped == 0 {
            (lower, 0)
        } else {
            ((lower >> dropped) | (upper << (32 - dropped)), lower & ((1 << dropped) - 1))
        };
        let half = (1u32 << dropped) >> 1;
        if dropped > 0 && (rest > half || (rest == half && kept & 1 != 0)) {
            kept += 1;
        }
        // `kept · 2^(dropped + eb - 150 + em - 127)`, truncated.
        let shift = dropped as i32 + self.shift;
        let magnitude = match shift {
            ..=-32 => 0,
            -31..=0 => kept >> -shift,
            // Below 2^31 only if `kept` is small enough; the float path saturates the rest.
            1..=30 if kept >> (31 - shift) == 0 => kept << shift,
            _ => return None,
        };
        Some(if self.negative { -(magnitude as i32) } else { magnitude as i32 })
    }
}

/// `+0 + b` from the bits: `b`, but for `b` = -0: +0 (round to nearest).
#[cfg(any(soft_float, test))]
#[inline(always)]
pub(super) fn zero_plus(b: f32) -> f32 {
    f32::from_bits(if b.to_bits() == 0x8000_0000 { 0 } else { b.to_bits() })
}

/// `x · 2^k` for a normal `x` whose product is normal too (exponent fields 1..=254): `k` added
/// to the exponent, exactly the product. `None` otherwise (zeros, subnormals, overflow, NaN).
#[cfg(any(soft_float, test))]
#[inline(always)]
pub(super) fn times_pow2_bits(x: f32, k: i32) -> Option<f32> {
    let b = x.to_bits();
    let e = ((b >> 23) & 0xff) as i32;
    let normal = |e: i32| (1..=254).contains(&e);
    (normal(e) && normal(e + k)).then(|| f32::from_bits(b.wrapping_add((k as u32) << 23)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `u16_times_to_i32` is the float composition's integer, for random texel coordinates,
    /// scales of any sign and magnitude, and power-of-two sizes (ties of the rounding included:
    /// small significands make exact halves common).
    #[test]
    fn texel_integer_is_the_float_compositions() {
        let mut rng = crate::test_rng::Lcg(23);
        let mut fast = 0;
        for t in 0..1_000_000 {
            let n = if t % 7 == 0 { rng.below(1 << 16) as u16 & 0xff00 } else { rng.below(1 << 16) as u16 };
            let exponent = 100 + rng.below(60);
            let fraction = if t % 3 == 0 { rng.below(1 << 23) & 0x7f_ff00 } else { rng.below(1 << 23) };
            let b = f32::from_bits(rng.below(2) << 31 | exponent << 23 | fraction);
            let m = f32::from_bits((127 + rng.below(30)) << 23);
            let float = times_power_of_two(u16_times(n, b), m);
            let expected = (float.abs() < 2f32.powi(31)).then(|| crate::math::to_i32(float));
            assert_eq!(u16_times_to_i32(n, b, m), expected, "{n} · {b} · {m}");
            fast += usize::from(expected.is_some());
        }
        assert!(fast > 300_000, "{fast}");
        assert_eq!(u16_times_to_i32(3, 1.0, 3.0), None);
        assert_eq!(u16_times_to_i32(3, f32::NAN, 2.0), None);
        assert_eq!(u16_times_to_i32(3, 0.0, 2.0), None);
    }
}
