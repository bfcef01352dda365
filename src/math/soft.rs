//! IEEE-754 binary32 arithmetic in integer code, for targets without an FPU: the same bits as
//! hardware `f32` (round to nearest, ties to even; subnormals, signed zeros, infinities) for
//! every input, NaN results being some NaN (no code relies on a NaN's sign or payload).
//!
//! Tuned for Cortex-M0+: 32 x 32 -> 32-bit multiplies only (the 24 x 24-bit significand product
//! from four of them, where the soft-float library calls `__aeabi_lmul`), no divide instruction,
//! no `CLZ`. Normal operands, by far the common case, go straight through; zeros, subnormals,
//! infinities and NaN take an out-of-line path.
//!
//! Compiled for tests on every target too, where `tests` compares it with the hardware.

use super::{leading_zeros_by_table as leading_zeros, order_key};

const SIGN: u32 = 0x8000_0000;
const INFINITY: u32 = 0x7f80_0000;
const NAN: u32 = 0x7fc0_0000;
/// The implicit leading one of a normal float's significand.
const IMPLICIT: u32 = 1 << 23;
const FRACTION: u32 = IMPLICIT - 1;
/// Half a unit in the last place, as a fraction below the significand (see [`round_pack`]).
const HALF: u32 = 1 << 31;

/// The biased exponent field.
#[inline(always)]
fn exponent(x: u32) -> i32 {
    ((x >> 23) & 0xff) as i32
}

/// A normal float's significand: its fraction with the leading one, in 2^23..2^24.
#[inline(always)]
fn significand(x: u32) -> u32 {
    (x & FRACTION) | IMPLICIT
}

/// Whether the exponent field is that of a normal number (not 0, not 255).
#[inline(always)]
fn is_normal(x: u32) -> bool {
    (exponent(x) as u32).wrapping_sub(1) < 254
}

#[inline(always)]
fn is_nan(x: u32) -> bool {
    x & !SIGN > INFINITY
}

/// The float nearest to `sign · (mant + rest / 2^32) · 2^(e - 150)`, ties to even, for
/// `2^23 <= mant < 2^24` and any `e`: `rest` is the fraction below the significand's last
/// place (only `rest == HALF`, above and below matter), `e` the biased exponent.
#[inline(always)]
fn round_pack(sign: u32, e: i32, mant: u32, rest: u32) -> u32 {
    if e >= 255 {
        return sign | INFINITY;
    }
    let (e, mant, rest) = if e <= 0 { denormalize(e, mant, rest) } else { (e, mant, rest) };
    // Up when the rest is above half, or exactly half and `mant` odd (ties to even).
    let up = rest > HALF - (mant & 1);
    // `mant` brings its leading one into the exponent field, hence `e - 1`. A rounding carry
    // out of the significand (mant + 1 = 2^24) then steps the exponent, which is exactly the
    // next float up, and from the largest finite one gives infinity; from the largest
    // subnormal (e = 1 below) it gives the smallest normal float.
    sign | ((((e - 1) as u32) << 23) + mant + u32::from(up))
}

/// A result below the normal range: the significand shifted right by `1 - e` (into the
/// subnormals' exponent field 0, written as `e = 1` without the leading one), the bits shifted
/// out folded into the rest: its half bit exactly, the others (and the old rest) as a sticky
/// one below it.
#[cold]
#[inline(never)]
fn denormalize(e: i32, mant: u32, rest: u32) -> (i32, u32, u32) {
    let shift = (1 - e) as u32;
    if shift > 25 {
        // Below a quarter of the smallest subnormal: rounds to zero.
        return (1, 0, 1);
    }
    (1, mant >> shift, (mant << (32 - shift)) | u32::from(rest != 0))
}

/// A nonzero finite float's biased exponent and significand with its leading one at bit 23:
/// subnormals normalized, with exponents `<= 0`.
#[inline(always)]
fn unpack(x: u32) -> (i32, u32) {
    let e = exponent(x);
    if e != 0 {
        return (e, significand(x));
    }
    let shift = leading_zeros(x & FRACTION) - 8;
    (1 - shift as i32, (x & FRACTION) << shift)
}

/// `a + b`.
#[inline(always)]
pub fn add(a: f32, b: f32) -> f32 {
    f32::from_bits(add_bits(a.to_bits(), b.to_bits()))
}

/// `a - b`: `a + (-b)`, as the hardware computes it.
#[inline(always)]
pub fn sub(a: f32, b: f32) -> f32 {
    f32::from_bits(add_bits(a.to_bits(), b.to_bits() ^ SIGN))
}

/// `a + b` on the bits.
#[inline(never)]
fn add_bits(a: u32, b: u32) -> u32 {
    // `a` the larger in magnitude: its sign is the result's (unless it is zero).
    let (a, b) = if a << 1 >= b << 1 { (a, b) } else { (b, a) };
    if !(is_normal(a) && is_normal(b)) {
        return add_special(a, b);
    }
    let (ea, eb) = (exponent(a), exponent(b));
    // Significands at the top of the word, leading one at bit 31: 8 bits below for rounding.
    let top = |x: u32| (x << 8) | SIGN;
    add_significands(a & SIGN, ea, top(a), top(b), (ea - eb) as u32, (a ^ b) & SIGN != 0)
}

/// `a + b` (`a` the larger in magnitude) when either is zero, subnormal, infinite or NaN.
#[cold]
#[inline(never)]
fn add_special(a: u32, b: u32) -> u32 {
    if exponent(a) == 255 {
        // inf - inf is NaN; NaN stays NaN (a NaN `b` makes `a` one too, being larger).
        return if is_nan(a) || b == a ^ SIGN { NAN } else { a };
    }
    if b << 1 == 0 {
        // x + 0 is x, and +0 + -0 is +0: -0 only from -0 + -0.
        return if a << 1 == 0 { a & b } else { a };
    }
    // Subnormals are significands without the leading one at exponent 1 (the same scale).
    let (ea, eb) = (exponent(a).max(1), exponent(b).max(1));
    let top = |x: u32| (x << 8) | if exponent(x) == 0 { 0 } else { SIGN };
    add_significands(a & SIGN, ea, top(a), top(b), (ea - eb) as u32, (a ^ b) & SIGN != 0)
}

/// The float nearest `±(sa + sb / 2^shift) · 2^(e - 158)` (`-` when `subtract`), for
/// significands at the top of the word, `sa >= sb / 2^shift`: normalized and rounded once.
#[inline(always)]
fn add_significands(sign: u32, e: i32, sa: u32, sb: u32, shift: u32, subtract: bool) -> u32 {
    // Align `b`: bits shifted out make the last bit sticky (it is below the rounding position
    // after any normalization below, so it stands for "a little more than this").
    let shift = shift.min(31);
    let aligned = sb >> shift;
    let sb = aligned | u32::from(aligned << shift != sb);
    let mut e = e;
    let mut s = if subtract {
        sa - sb
    } else {
        let (s, carry) = sa.overflowing_add(sb);
        if carry {
            // The sum has 33 bits: the leading one above the word, nothing lost below.
            return round_pack(sign, e + 1, (s >> 9) | IMPLICIT, s << 23);
        }
        s
    };
    if s < SIGN {
        if s == 0 {
            // Exact cancellation is +0.
            return 0;
        }
        // Cancellation (or subnormal operands): exact, as it needs exponents at most one apart.
        let shift = leading_zeros(s);
        s <<= shift;
        e -= shift as i32;
    }
    round_pack(sign, e, s >> 8, s << 24)
}

/// `a · b`.
#[inline(always)]
pub fn mul(a: f32, b: f32) -> f32 {
    let (a, b) = (a.to_bits(), b.to_bits());
    let bits = if is_normal(a) && is_normal(b) {
        mul_significands((a ^ b) & SIGN, exponent(a) + exponent(b) - 127, significand(a), significand(b))
    } else {
        mul_special(a, b)
    };
    f32::from_bits(bits)
}

/// `(n as f32) · b`, the conversion (exact) folded into the multiply: for a normal `b` and
/// `n > 0`, `n`'s significand and exponent straight from its leading zeros.
#[inline(always)]
pub fn mul_u16(n: u16, b: f32) -> f32 {
    let (n, bb) = (u32::from(n), b.to_bits());
    if n == 0 || !is_normal(bb) {
        return mul(from_u32(n), b);
    }
    // As `from_magnitude`: `n · 2^shift` has its leading one at bit 31, the float's exponent
    // field is `158 - shift`, and its significand `n · 2^(shift - 8)`, nothing cut off.
    let shift = leading_zeros(n);
    f32::from_bits(mul_significands(
        bb & SIGN,
        158 - shift as i32 + exponent(bb) - 127,
        n << (shift - 8),
        significand(bb),
    ))
}

/// `a · b` when either is zero, subnormal, infinite or NaN.
#[cold]
#[inline(never)]
fn mul_special(a: u32, b: u32) -> u32 {
    let sign = (a ^ b) & SIGN;
    let (zero, infinite) = (|x: u32| x & !SIGN == 0, |x: u32| x & !SIGN == INFINITY);
    if is_nan(a) || is_nan(b) || (infinite(a) && zero(b)) || (zero(a) && infinite(b)) {
        NAN
    } else if infinite(a) || infinite(b) {
        sign | INFINITY
    } else if zero(a) || zero(b) {
        sign
    } else {
        let ((ea, ma), (eb, mb)) = (unpack(a), unpack(b));
        mul_significands(sign, ea + eb - 127, ma, mb)
    }
}

/// The float nearest `ma · mb · 2^(e - 173)` (so `e` is the biased exponent of the result
/// when the product is below 2^47), for significands `ma`, `mb` in 2^23..2^24.
#[inline(always)]
fn mul_significands(sign: u32, e: i32, ma: u32, mb: u32) -> u32 {
    // The 48-bit product as hi·2^32 + lo from 8- and 16-bit halves: every partial product fits
    // a 32-bit multiply (al·bl < 2^32, the cross terms < 2^24 each, ah·bh < 2^16).
    let (ah, al, bh, bl) = (ma >> 16, ma & 0xffff, mb >> 16, mb & 0xffff);
    let low = al * bl;
    let cross = ah * bl + al * bh;
    let lo = low.wrapping_add(cross << 16);
    let hi = ah * bh + (cross >> 16) + u32::from(lo < low);
    // The product is in 2^46..2^48: its top 24 bits are the significand, the rest below.
    if hi >= 1 << 15 {
        round_pack(sign, e + 1, (hi << 8) | (lo >> 24), lo << 8)
    } else {
        round_pack(sign, e, (hi << 9) | (lo >> 23), lo << 9)
    }
}

/// `a / b`.
#[inline(always)]
pub fn div(a: f32, b: f32) -> f32 {
    let (a, b) = (a.to_bits(), b.to_bits());
    let bits = if is_normal(a) && is_normal(b) {
        div_significands((a ^ b) & SIGN, exponent(a) - exponent(b) + 127, significand(a), significand(b))
    } else {
        div_special(a, b)
    };
    f32::from_bits(bits)
}

/// `a / b` when either is zero, subnormal, infinite or NaN.
#[cold]
#[inline(never)]
fn div_special(a: u32, b: u32) -> u32 {
    let sign = (a ^ b) & SIGN;
    let (zero, infinite) = (|x: u32| x & !SIGN == 0, |x: u32| x & !SIGN == INFINITY);
    if is_nan(a) || is_nan(b) || (infinite(a) && infinite(b)) || (zero(a) && zero(b)) {
        NAN
    } else if infinite(a) || zero(b) {
        sign | INFINITY
    } else if zero(a) || infinite(b) {
        sign
    } else {
        let ((ea, ma), (eb, mb)) = (unpack(a), unpack(b));
        div_significands(sign, ea - eb + 127, ma, mb)
    }
}

/// The float nearest `ma / mb · 2^(e - 127)`, for significands `ma`, `mb` in 2^23..2^24: long
/// division in two digits of 12 and 11 bits, each estimated from a 16-bit reciprocal of `mb`
/// and corrected by its exact remainder (no divide instruction).
#[inline(always)]
fn div_significands(sign: u32, e: i32, ma: u32, mb: u32) -> u32 {
    // The quotient's leading one: ma/mb in 1..2, doubling `ma` (one exponent down) when below.
    let (e, r) = if ma >= mb { (e, ma - mb) } else { (e - 1, (ma << 1) - mb) };
    let inverse = reciprocal(mb);
    let (high, r) = quotient_digit(r, mb, inverse, 12);
    let (low, r) = quotient_digit(r, mb, inverse, 11);
    // The rest from the remainder: zero, below half or above half. Never exactly half: that
    // is `ma · 2^24 = (2q + 1) · mb` (or `2ma`), but `mb < 2^24` cannot hold the factor 2^24.
    let rest = if 2 * r > mb { HALF | 1 } else { u32::from(r != 0) };
    round_pack(sign, e, IMPLICIT | (high << 11) | low, rest)
}

/// `2^39 / mb` for `mb` in 2^23..2^24, from below: short of it by a relative 2^-20 to 2^-13
/// (checked for every `mb` by a test), so below 2^16. An 8-bit estimate from a table of the top
/// bits, sharpened by one Newton step, less 2 to stay below.
#[inline(always)]
fn reciprocal(mb: u32) -> u32 {
    let x = u32::from(RECIPROCALS[(mb >> 16) as usize & 0x7f]);
    // x · (mb >> 8) is at most 2^31, short of it by x's relative error `err` (< 2^-7);
    // x · (1 + err) is then off by about err² only.
    let short = (1u32 << 31) - (mb >> 8) * x;
    x + ((x * (short >> 9)) >> 22) - 2
}

/// `2^23 / (129 + i)`: `2^39 / mb` at the top of the range of `mb` whose bits 22..16 are `i`,
/// so at most `2^39 / mb` and within 2^-7 of it.
const RECIPROCALS: [u16; 128] = {
    let mut table = [0; 128];
    let mut i = 0;
    while i < 128 {
        table[i] = ((1 << 23) / (129 + i)) as u16;
        i += 1;
    }
    table
};

/// The next `bits <= 12` quotient bits of the remainder `r < mb` divided by `mb`, and the new
/// remainder. Estimated as `(r >> 8) · inverse / 2^(31 - bits)` (in 32 bits), which is never
/// above the true digit `d = r · 2^bits / mb` (all its factors round down) and is above
/// `d - 1.6` (`inverse`'s relative error times `d < 2^12` is below 0.44, the bits of `r` cut
/// off are under 0.13, the final truncation under 1): so `d - 1` or `d`, corrected by one
/// comparison of the remainder. The remainder is exact in wrapping 32-bit arithmetic as its
/// true value is below `2·mb`.
#[inline(always)]
fn quotient_digit(r: u32, mb: u32, inverse: u32, bits: u32) -> (u32, u32) {
    let digit = ((r >> 8) * inverse) >> (31 - bits);
    let rest = (r << bits).wrapping_sub(digit.wrapping_mul(mb));
    if rest >= mb {
        (digit + 1, rest - mb)
    } else {
        (digit, rest)
    }
}

/// `v as f32`.
#[inline(always)]
pub fn from_u32(v: u32) -> f32 {
    f32::from_bits(from_magnitude(0, v))
}

/// `v as f32`.
#[inline(always)]
pub fn from_i32(v: i32) -> f32 {
    f32::from_bits(from_magnitude(v as u32 & SIGN, v.unsigned_abs()))
}

/// `v as f32`, in 32-bit halves (no 64-bit shifts, which are library calls on Armv6-M).
#[inline(always)]
pub fn from_i64(v: i64) -> f32 {
    let sign = (v >> 32) as u32 & SIGN;
    let m = v.unsigned_abs();
    let (high, low) = ((m >> 32) as u32, m as u32);
    if high == 0 {
        return f32::from_bits(from_magnitude(sign, low));
    }
    // The top 32 bits from the leading one down; the bits of `low` below them only as sticky.
    let shift = leading_zeros(high);
    let top = if shift == 0 { high } else { (high << shift) | (low >> (32 - shift)) };
    let sticky = u32::from(low << shift != 0);
    f32::from_bits(round_pack(sign, 190 - shift as i32, top >> 8, (top << 24) | sticky))
}

/// `sign · m` rounded to a float: `m` shifted until its leading one is bit 31, the low 8 bits
/// the rest.
#[inline(always)]
fn from_magnitude(sign: u32, m: u32) -> u32 {
    if m == 0 {
        return sign;
    }
    let shift = leading_zeros(m);
    let n = m << shift;
    round_pack(sign, 158 - shift as i32, n >> 8, n << 24)
}

/// `a < b`: an integer comparison of the bits (see [`order_key`]), false with a NaN.
#[inline(always)]
pub fn lt(a: f32, b: f32) -> bool {
    !is_nan(a.to_bits()) && !is_nan(b.to_bits()) && order_key(a) < order_key(b)
}

/// `a <= b`, false with a NaN (see [`lt`]).
#[inline(always)]
pub fn le(a: f32, b: f32) -> bool {
    !is_nan(a.to_bits()) && !is_nan(b.to_bits()) && order_key(a) <= order_key(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64: a stream of pseudo-random 64-bit words.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }

        /// Pairs of floats: uniformly random bits, and pairs with close exponents (where
        /// additions cancel and round), small significands (exact halfway cases) and extreme
        /// exponents (overflow, underflow).
        fn pair(&mut self) -> (f32, f32) {
            let r = self.next();
            let (a, b) = (r as u32, (r >> 32) as u32);
            // b's exponent up to 39 above a's: every alignment shift of an addition.
            let near =
                |b: u32| (b & !(0xff << 23)) | ((a & (0xff << 23)).wrapping_add(((b >> 8) % 40) << 23) & (0xff << 23));
            let b = match self.next() % 8 {
                0..=2 => near(b),
                // Few significant bits, exponents apart: ties after alignment.
                3 if b & 1 == 0 => near(b & 0x8000_00ff),
                // Few significant bits: ties when adding or multiplying.
                3 => b & 0xfff0_0000,
                4 => (a & 0xfff8_0000) ^ (b & 0x8100_0001),
                _ => b,
            };
            // Now and then a smaller exponent for `a`: products near the subnormals.
            let a = if self.next().is_multiple_of(5) { a & !(0x78 << 23) } else { a };
            (f32::from_bits(a), f32::from_bits(b))
        }
    }

    fn same(got: f32, want: f32) -> bool {
        got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan())
    }

    fn check(a: f32, b: f32) {
        let show = |op: &str| std::format!("{a:e} {op} {b:e} ({:#x}, {:#x})", a.to_bits(), b.to_bits());
        assert!(same(add(a, b), a + b), "{}: {:e}", show("+"), add(a, b));
        assert!(same(sub(a, b), a - b), "{}: {:e}", show("-"), sub(a, b));
        assert!(same(mul(a, b), a * b), "{}: {:e}", show("*"), mul(a, b));
        assert!(same(div(a, b), a / b), "{}: {:e}", show("/"), div(a, b));
        assert_eq!(lt(a, b), a < b, "{}", show("<"));
        assert_eq!(le(a, b), a <= b, "{}", show("<="));
    }

    /// Every special value against every other, and their neighbours.
    #[test]
    fn special_values_match_the_hardware() {
        let mut values = std::vec![0.0f32, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, -f32::NAN];
        for bits in [1u32, 2, 3, FRACTION, IMPLICIT, IMPLICIT + 1, 0x7f7f_ffff, 0x7f00_0000, 0x3f80_0000, 0x3fc0_0000] {
            values.extend([f32::from_bits(bits), f32::from_bits(bits | SIGN)]);
        }
        values.extend([0.5, 1.5, 3.0, 1e-30, 1e30, 2.0f32.powi(-126), 2.0f32.powi(-127), 2.0f32.powi(127)]);
        values.extend([1.0 + f32::EPSILON, 1.0 - f32::EPSILON / 2.0, 16777215.0, 16777217.0]);
        for &a in &values {
            for &b in &values {
                check(a, b);
            }
        }
    }

    /// Targeted roundings: exact halfway cases both ways, carries into the exponent, overflow
    /// to infinity, underflow to subnormals and zero.
    #[test]
    fn rounding_edges_match_the_hardware() {
        let one = 1.0f32;
        let ulp = f32::EPSILON;
        let cases = [
            (one, ulp / 2.0),                                                      // tie, to even (down)
            (one + ulp, ulp / 2.0),                                                // tie, to even (up)
            (2.0 - ulp, ulp / 2.0),                                                // carry into the exponent
            (f32::MAX, f32::MAX),                                                  // overflow
            (f32::MAX, 2.0f32.powi(103)),                                          // tie at the top: infinity
            (f32::MIN_POSITIVE, -f32::from_bits(f32::MIN_POSITIVE.to_bits() - 1)), // subnormal result
            (1.5 * 2.0f32.powi(-75), 2.0f32.powi(-75)), // product near the smallest subnormal
            (2.0f32.powi(-75), 2.0f32.powi(-75)),       // product exactly half the smallest
            (3.0 * 2.0f32.powi(-76), 2.0f32.powi(-75)), // product 3/4 of the smallest
            (f32::from_bits(1), 0.5),                   // tie to zero
            (f32::from_bits(3), 0.5),                   // tie to even 2
            (f32::from_bits(0x007f_ffff), 1.0 + ulp),   // subnormal rounding into normal
            (16777217.0, 1.0),
            (1.0, 3.0),
            (2.0f32.powi(-126), 3.0),
        ];
        for (a, b) in cases {
            for (a, b) in [(a, b), (b, a), (-a, b), (a, -b)] {
                check(a, b);
            }
        }
    }

    /// Millions of pseudo-random pairs, all four operations and both comparisons.
    #[test]
    fn random_operands_match_the_hardware() {
        let mut random = Random(0x2545_f491_4f6c_dd1d);
        for _ in 0..3_000_000 {
            let (a, b) = random.pair();
            check(a, b);
        }
    }

    /// The division's reciprocal is below `2^39 / mb` by a relative 2^-20 to 2^-13 for every
    /// significand, which makes each quotient digit's estimate exact or one short.
    /// `mul_u16` is the conversion and the multiply, for every `n` and a spread of `b`.
    #[test]
    fn mul_u16_is_convert_and_multiply() {
        let mut bits = 0u32;
        while let Some(next) = bits.checked_add(0x00ff_fff1) {
            for b in [bits, bits | 0x7f_ffff, bits ^ 0x8000_0000] {
                let b = f32::from_bits(b);
                for n in (0..=u16::MAX).step_by(7).chain([1, 2, 3, 255, 256, u16::MAX]) {
                    let (want, got) = (n as f32 * b, mul_u16(n, b));
                    assert!(want.to_bits() == got.to_bits() || want.is_nan() && got.is_nan(), "{n} · {b:e}");
                }
            }
            bits = next;
        }
    }

    #[test]
    fn reciprocal_is_close_and_below() {
        for mb in (1u32 << 23)..(1 << 24) {
            let (inverse, exact) = (f64::from(reciprocal(mb)), 2f64.powi(39) / f64::from(mb));
            let short = 1.0 - inverse / exact;
            assert!((2f64.powi(-20)..2f64.powi(-13)).contains(&short), "{mb:#x}: {short:e}");
        }
    }

    /// Integer conversions (u32, i32, i64): every power of two and its neighbours, and random integers of
    /// every length.
    #[test]
    fn conversions_match_as() {
        let mut values = std::vec![0u32, 1, u32::MAX, 1 << 31, (1 << 24) + 1, (1 << 25) + 2, (1 << 25) + 6];
        for wide in [i64::MIN, i64::MAX, 1 << 32, (1 << 56) + (1 << 32) + 1, (1 << 40) + (1 << 16)] {
            assert_eq!(from_i64(wide).to_bits(), (wide as f32).to_bits(), "{wide}");
            let negated = wide.wrapping_neg();
            assert_eq!(from_i64(negated).to_bits(), (negated as f32).to_bits(), "{wide}");
        }
        for k in 0..32 {
            values.extend([1u32 << k, (1u32 << k).wrapping_sub(1), (1u32 << k) + 1, (3u32 << k) >> 1]);
        }
        let mut random = Random(0x9e37_79b9_7f4a_7c15);
        values.extend((0..2_000_000).map(|k| (random.next() as u32) >> (k % 32)));
        for (k, &v) in values.iter().enumerate() {
            let wide = (i64::from(v) << 32 | i64::from(values[k / 2])) >> (k % 64);
            assert_eq!(from_i64(wide).to_bits(), (wide as f32).to_bits(), "{wide}");
            assert_eq!(from_i64(i64::from(v)).to_bits(), (v as f32).to_bits(), "{v}");
            assert_eq!(from_u32(v).to_bits(), (v as f32).to_bits(), "{v}");
            let i = v as i32;
            assert_eq!(from_i32(i).to_bits(), (i as f32).to_bits(), "{i}");
            assert_eq!(leading_zeros(v), v.leading_zeros(), "{v}");
        }
    }
}
