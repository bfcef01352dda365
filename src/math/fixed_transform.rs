//! The fixed-point vertex path's model-to-clip transform ([`FixedTransform`]): a matrix's rows
//! as integers at their own power-of-two scales, applied to integer positions exactly.

use super::{i64_to_f32_scaled, max, mul_wide, scale_by_power_of_two, to_i32, Mat4, Vec3, Vec4};

/// A model-to-clip transform evaluated in integers: the fixed-point vertex path of targets
/// without an FPU (see [`RenderOptions::fixed_vertices`](crate::RenderOptions)).
///
/// Positions come as integers `q` (`|q| <= 2^15`, see
/// `format::Arrays::position_int`). Each output row `i` is `(Σ a_ij·q_j + b_i) / 2^e_i`
/// with `a_ij` rounded to integers below 2^30 at the row's own power-of-two scale, so the
/// coefficients keep 29 or more significant bits whatever the scene's units; the sums are exact
/// in i64 and rounded to f32 once at the end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedTransform {
    a: [[i32; 3]; 4],
    b: [i64; 4],
    e: [i32; 4],
}

impl FixedTransform {
    /// `m · (offset + q·step, 1)` for integer `q`. `None` when a coefficient is not finite or
    /// the scales leave the representable range.
    #[must_use]
    pub fn new(m: &Mat4, offset: Vec3, step: f32) -> Option<Self> {
        let mut t = FixedTransform { a: [[0; 3]; 4], b: [0; 4], e: [0; 4] };
        for i in 0..4 {
            let row = m.row(i);
            let a = [row.x * step, row.y * step, row.z * step];
            let b = row.w + row.truncate().dot(offset);
            let largest = max(max(a[0].abs(), a[1].abs()), max(a[2].abs(), f32::MIN_POSITIVE));
            if !(largest.is_finite() && b.is_finite()) {
                return None;
            }
            // largest < 2^(k+1) with k its binary exponent: scaled by 2^(29-k) it is below 2^30.
            let e = 29 - (((largest.to_bits() >> 23) & 0xff) as i32 - 127);
            if e.abs() > 120 {
                return None;
            }
            let b = scale_by_power_of_two(b, e);
            let fits = b.abs() < (1u64 << 61) as f32;
            if !fits {
                return None;
            }
            t.a[i] = a.map(|c| to_i32(scale_by_power_of_two(c, e)));
            (t.b[i], t.e[i]) = (b as i64, e);
        }
        Some(t)
    }

    /// The clip-space position of the point with integer coordinates `q`.
    #[must_use]
    pub fn apply(&self, q: [i32; 3]) -> Vec4 {
        let sums = self.sums(q);
        let row = |i: usize| i64_to_f32_scaled(sums[i], self.e[i]);
        Vec4::new(row(0), row(1), row(2), row(3))
    }

    /// The clip-space position of the point with integer coordinates `q`, exactly: coordinate
    /// `i` is `sums[i] · 2^-e[i]`, with `e` from [`FixedTransform::exponents`].
    #[inline(always)]
    #[must_use]
    pub fn sums(&self, q: [i32; 3]) -> [i64; 4] {
        // Spelt out: `array::from_fn` here is a call of its own on Armv6-M (not inlined).
        let row = |i: usize| {
            self.b[i] + mul_wide(self.a[i][0], q[0]) + mul_wide(self.a[i][1], q[1]) + mul_wide(self.a[i][2], q[2])
        };
        [row(0), row(1), row(2), row(3)]
    }

    /// The power-of-two scale of each coordinate's sum (see [`FixedTransform::sums`]).
    #[must_use]
    pub fn exponents(&self) -> [i32; 4] {
        self.e
    }
}
