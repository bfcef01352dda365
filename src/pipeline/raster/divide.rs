//! Exact integer division by a small divisor (below 1024: a run's length in pixels, an edge's
//! height in 1/16 pixel), for targets without a divide instruction (`cfg(no_hw_divide)`), where
//! each `/` is a library call of about 100 instructions: the quotient from the high half of a
//! 32 x 32 -> 64-bit product with the divisor's inverse from a table (four 16-bit products),
//! corrected by its remainder. The same integers as `/` and `%`.

/// The divisors with an inverse in the tables (4 KiB of flash). 1024, not 256: edges up to 64
/// pixels tall then take no library division (thumbv6m, 8 bands: -18.6k instructions a frame on
/// the reference frame, whose edges are all below that).
const SMALL: u32 = 1024;

/// A divisor `d` in `1..1024` with its inverse `floor((2^32 - 1) / d)` in 16-bit halves (high,
/// low), looked up in two tables: seeing the halves split from one value, LLVM would turn
/// [`mul_high`] back into a 64-bit multiply, a library call (`__aeabi_lmul`) on Armv6-M.
#[derive(Clone, Copy, Debug)]
pub(super) struct Divisor {
    d: u32,
    inverse: (u32, u32),
}

impl Divisor {
    /// `d` with its inverse, or `None` when it is 0 or not below 1024.
    #[inline(always)]
    pub(super) fn small(d: u32) -> Option<Self> {
        let i = d as usize;
        (d.wrapping_sub(1) < SMALL - 1).then(|| Divisor { d, inverse: (INVERSE_HIGH[i].into(), INVERSE_LOW[i].into()) })
    }

    /// `(n / d, n % d)`. The estimate `n · inverse / 2^32` is at most `n / d` and, as
    /// `inverse > (2^32 - 1) / d - 1`, less than 2 below it: at most two corrections.
    #[inline(always)]
    pub(super) fn div_rem(&self, n: u32) -> (u32, u32) {
        let mut q = mul_high(n, self.inverse);
        let mut r = n.wrapping_sub(q.wrapping_mul(self.d));
        while r >= self.d {
            (q, r) = (q + 1, r - self.d);
        }
        (q, r)
    }

    /// `n / d` truncated towards zero, as `i32`'s `/` (`i32::MIN / 1` included).
    #[inline(always)]
    pub(super) fn div_trunc(&self, n: i32) -> i32 {
        let q = self.div_rem(n.unsigned_abs()).0 as i32;
        if n < 0 {
            q.wrapping_neg()
        } else {
            q
        }
    }

    /// `floor(n / d)`.
    #[inline(always)]
    pub(super) fn floor_div(&self, n: i32) -> i32 {
        let (q, r) = self.div_rem(n.unsigned_abs());
        match (n < 0, r != 0) {
            (false, _) => q as i32,
            (true, false) => (q as i32).wrapping_neg(),
            // -(q·d + r) with 0 < r < d: between -(q + 1)·d and -q·d.
            (true, true) => (q as i32).wrapping_neg() - 1,
        }
    }
}

/// `(a · b) >> 32` for `b` given as 16-bit halves `(bh, bl)`, carrying the middle sum in two
/// steps (Hacker's Delight's `mulhu`): each partial sum is below 2^32. Armv6-M has no
/// widening multiply.
#[inline(always)]
fn mul_high(a: u32, (bh, bl): (u32, u32)) -> u32 {
    let (ah, al) = (a >> 16, a & 0xffff);
    let t = ah * bl + ((al * bl) >> 16);
    let middle = al * bh + (t & 0xffff);
    ah * bh + (t >> 16) + (middle >> 16)
}

/// One half (`shift` 16: the high, 0: the low) of `floor((2^32 - 1) / d)` for each `d` below
/// 1024 (0 for `d = 0`, never used).
const fn inverse_halves(shift: u32) -> [u16; SMALL as usize] {
    let mut table = [0; SMALL as usize];
    let mut d = 1;
    while d < SMALL {
        table[d as usize] = ((u32::MAX / d) >> shift) as u16;
        d += 1;
    }
    table
}

const INVERSE_HIGH: [u16; SMALL as usize] = inverse_halves(16);
const INVERSE_LOW: [u16; SMALL as usize] = inverse_halves(0);

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the native operations: every divisor, extreme and random numerators.
    #[test]
    fn divides_like_the_operators() {
        let mut rng = crate::test_rng::Lcg(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.next();
        let edges = [0, 1, 2, 3, 0x7fff_ffff, 0x8000_0000, 0x8000_0001, u32::MAX - 1, u32::MAX];
        assert!(Divisor::small(0).is_none() && Divisor::small(SMALL).is_none() && Divisor::small(u32::MAX).is_none());
        for d in 1..SMALL {
            let div = Divisor::small(d).unwrap();
            let extremes = edges.into_iter().chain((0..3 * d).flat_map(|k| [k, u32::MAX - k, 0x8000_0000 - k]));
            for n in extremes.chain((0..4000).map(|_| next() >> (next() % 32))) {
                assert_eq!(div.div_rem(n), (n / d, n % d), "{n} / {d}");
                let s = n as i32;
                assert_eq!(div.div_trunc(s), s.wrapping_div(d as i32), "{s} / {d}");
                assert_eq!(div.floor_div(s), s.div_euclid(d as i32), "{s} / {d}");
            }
        }
    }
}
