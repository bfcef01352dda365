//! Exact widening and wrapping multiplies of small factors, from 32-bit products on FPU-less
//! targets (Armv6-M has no 64-bit multiply: `__aeabi_lmul` is a call of about 40 instructions).

/// `a · q` exactly, for any `a` and `|q| <= 2^15`: two 32-bit products on FPU-less targets
/// (whose 64-bit multiply is a library call), one widening multiply elsewhere.
#[inline(always)]
#[must_use]
pub fn mul_wide(a: i32, q: i32) -> i64 {
    debug_assert!(q.unsigned_abs() <= 1 << 15);
    #[cfg(soft_float)]
    {
        mul_wide_halves(a, q)
    }
    #[cfg(not(soft_float))]
    {
        a as i64 * q as i64
    }
}

/// [`mul_wide`] from `a`'s 16-bit halves: `|a >> 16| <= 2^15` and `(a & 0xffff) < 2^16`, so
/// with `|q| <= 2^15` the products are at most 2^30 and `2^31 - 2^15` in magnitude: both fit
/// in i32.
#[cfg(any(soft_float, test))]
#[inline(always)]
fn mul_wide_halves(a: i32, q: i32) -> i64 {
    (((a >> 16) * q) as i64) * 65536 + ((a & 0xffff) * q) as i64
}

/// `z.wrapping_mul(k)` for an `i64` and a small `k` (a pixel or row offset): without an FPU
/// (Armv6-M: no 64-bit multiply, `__aeabi_lmul` is a call of about 40 instructions) from three
/// 32-bit products when `|k| < 2^15`, else the plain wrapping multiply.
#[inline(always)]
#[must_use]
pub fn wrapping_mul_small(z: i64, k: i32) -> i64 {
    #[cfg(soft_float)]
    {
        if k.unsigned_abs() < 1 << 15 {
            return wrapping_mul_halves(z, k);
        }
    }
    z.wrapping_mul(k as i64)
}

/// [`wrapping_mul_small`] for `|k| < 2^15` from 32-bit products: `z = high·2^32 + low`, so
/// `z·k = high·k·2^32 + low·k (mod 2^64)`, with `low·k` from `low`'s 16-bit halves (each
/// product below 2^31 in magnitude).
#[cfg(any(soft_float, test))]
#[inline(always)]
fn wrapping_mul_halves(z: i64, k: i32) -> i64 {
    debug_assert!(k.unsigned_abs() < 1 << 15);
    let (high, low) = ((z >> 32) as i32, z as u32);
    let low_k = ((((low >> 16) as i32 * k) as i64) << 16) + ((low & 0xffff) as i32 * k) as i64;
    ((high.wrapping_mul(k) as i64) << 32).wrapping_add(low_k)
}

/// `x >> s` (arithmetic) for `s < 32`: in 32-bit halves where a 64-bit shift by a variable
/// amount is a library call (Armv6-M's `__aeabi_lasr`, about 20 instructions with the call).
#[inline(always)]
#[must_use]
pub fn shr_i64(x: i64, s: u32) -> i64 {
    debug_assert!(s < 32);
    #[cfg(no_hw_divide)]
    {
        shr_i64_halves(x, s)
    }
    #[cfg(not(no_hw_divide))]
    {
        x >> s
    }
}

/// [`shr_i64`] in 32-bit halves.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn shr_i64_halves(x: i64, s: u32) -> i64 {
    if s == 0 {
        return x;
    }
    let (high, low) = ((x >> 32) as i32, x as u32);
    ((i64::from(high >> s)) << 32) | i64::from((low >> s) | ((high as u32) << (32 - s)))
}

/// `x << s` (wrapping) for `s < 32`, as [`shr_i64`].
#[inline(always)]
#[must_use]
pub fn shl_i64(x: i64, s: u32) -> i64 {
    debug_assert!(s < 32);
    #[cfg(no_hw_divide)]
    {
        shl_i64_halves(x, s)
    }
    #[cfg(not(no_hw_divide))]
    {
        x << s
    }
}

/// [`shl_i64`] in 32-bit halves.
#[cfg(any(no_hw_divide, test))]
#[inline(always)]
fn shl_i64_halves(x: i64, s: u32) -> i64 {
    if s == 0 {
        return x;
    }
    let (high, low) = ((x >> 32) as u32, x as u32);
    ((u64::from((high << s) | (low >> (32 - s))) << 32) | u64::from(low << s)) as i64
}

/// Whether `x >= 2^n` (`n < 64`), from `x`'s 32-bit halves: no 64-bit shift (see [`shr_i64`]).
#[inline(always)]
#[must_use]
pub fn at_least_power_of_two(x: u64, n: u32) -> bool {
    debug_assert!(n < 64);
    let (high, low) = ((x >> 32) as u32, x as u32);
    if n >= 32 {
        high >> (n - 32) != 0
    } else {
        high != 0 || low >> n != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shifts in halves equal the 64-bit ones, and the power-of-two bound the comparison.
    #[test]
    fn shifts_in_halves_are_the_64_bit_shifts() {
        let mut rng = crate::test_rng::Lcg(3);
        for _ in 0..100_000 {
            let x = (u64::from(rng.next()) << 32 | u64::from(rng.next())) as i64 >> rng.below(64);
            let s = rng.below(32);
            assert_eq!(shr_i64_halves(x, s), x >> s, "{x} >> {s}");
            assert_eq!(shl_i64_halves(x, s), x << s, "{x} << {s}");
            let n = rng.below(64);
            assert_eq!(at_least_power_of_two(x.unsigned_abs(), n), x.unsigned_abs() >= 1 << n, "{x} {n}");
        }
    }

    /// `mul_wide`'s halves equal the 64-bit product over the whole range of `a` and the
    /// extremes of `q`.
    #[test]
    fn mul_wide_halves_is_the_exact_product() {
        let edges = [i32::MIN, i32::MIN + 1, -65_537, -65_536, -1, 0, 1, 65_535, 65_536, i32::MAX - 1, i32::MAX];
        let mut seed = 0x1234_5678_u32;
        let random = (0..100_000).map(|_| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            seed as i32
        });
        for a in edges.into_iter().chain(random) {
            for q in [-(1 << 15), -(1 << 15) + 1, -2_047, -1, 0, 1, 2_047, (1 << 15) - 1, 1 << 15] {
                assert_eq!(mul_wide_halves(a, q), a as i64 * q as i64, "{a} * {q}");
            }
        }
    }

    /// The 32-bit-product multiply of FPU-less targets wraps like `i64::wrapping_mul`.
    #[test]
    fn wrapping_mul_halves_matches_wrapping_mul() {
        let mut state = 0x0123_4567_89ab_cdefu64;
        for n in 0..1_000_000u32 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let z = (state as i64) >> (n % 64);
            let k = (state >> 17) as i32 % (1 << 15);
            assert_eq!(wrapping_mul_halves(z, k), z.wrapping_mul(k as i64), "{z} * {k}");
        }
        for z in [i64::MIN, i64::MAX, -1, 1 << 32, -(1 << 40) + 3] {
            for k in [0, 1, -1, (1 << 15) - 1, -(1 << 15) + 1] {
                assert_eq!(wrapping_mul_halves(z, k), z.wrapping_mul(k as i64), "{z} * {k}");
            }
        }
    }
}
