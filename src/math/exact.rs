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
