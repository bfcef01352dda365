//! The one place where soft3d does floating-point maths.
//!
//! Every transcendental function goes through [`libm`] explicitly, and glam is built with its
//! `libm` and `scalar-math` features, so a host test and a Cortex-M build evaluate the same
//! operations in the same order and get bit-identical results. (Calling `x.sin()` in a
//! `no_std` crate silently picks std's version whenever std is linked, which differs.)
//!
//! Matrices are glam's column-major [`Mat4`] acting on column vectors. A Babylon.js row-vector
//! matrix `m[16]` is the same 16 numbers: `Mat4::from_cols_array(&m)` is the transform that
//! Babylon writes `p · M`, and Babylon's `A · B` (A first) is glam's `B * A`.

pub use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

mod exact;
mod fixed_transform;
mod float;
#[cfg(any(soft_float, test))]
mod soft;
mod wide;

#[cfg(soft_float)]
pub(crate) use exact::U16Scale;
pub use exact::{offset_add, times_16, times_power_of_two, u16_times};
#[cfg(test)]
use exact::{times_pow2_bits, zero_plus};
pub use fixed_transform::FixedTransform;
pub use float::F32;
use float::{greater, less};
pub use wide::{at_least_power_of_two, mul_wide, shl_i64, shr_i64, wrapping_mul_small};

/// `x.leading_zeros()`: two halving steps and a table of bit lengths for the last byte, for
/// targets with no count-leading-zeros instruction (Armv6-M, RISC-V without Zbb), where the
/// library's `__clzsi2` costs about 34 instructions with its call and a binary search about 15.
#[cfg(any(soft_float, no_hw_divide, target_arch = "riscv32", test))]
#[inline(always)]
pub(crate) fn leading_zeros_by_table(x: u32) -> u32 {
    let (x, zeros) = if x >> 16 == 0 { (x, 16) } else { (x >> 16, 0) };
    let (x, zeros) = if x >> 8 == 0 { (x, zeros + 8) } else { (x >> 8, zeros) };
    zeros + 8 - u32::from(BIT_LENGTH[x as usize & 0xff])
}

/// The number of significant bits of every byte.
#[cfg(any(soft_float, no_hw_divide, target_arch = "riscv32", test))]
const BIT_LENGTH: [u8; 256] = {
    let mut table = [0; 256];
    let mut i = 1;
    while i < 256 {
        table[i] = table[i / 2] + 1;
        i += 1;
    }
    table
};

/// Square root (libm).
#[inline]
#[must_use]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// Sine (libm).
#[inline]
#[must_use]
pub fn sin(x: f32) -> f32 {
    libm::sinf(x)
}

/// Cosine (libm).
#[inline]
#[must_use]
pub fn cos(x: f32) -> f32 {
    libm::cosf(x)
}

/// The remainder of `x / y`, with the sign of `x` (libm).
#[inline]
#[must_use]
pub fn fmod(x: f32, y: f32) -> f32 {
    libm::fmodf(x, y)
}

/// Arc cosine (libm).
#[inline]
#[must_use]
pub fn acos(x: f32) -> f32 {
    libm::acosf(x)
}

/// Tangent (libm).
#[inline]
#[must_use]
pub fn tan(x: f32) -> f32 {
    libm::tanf(x)
}

/// `x` raised to `y` (libm).
#[inline]
#[must_use]
pub fn powf(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}

/// `x as i32`: truncated towards zero, saturating, NaN gives 0.
///
/// On targets without an FPU (`eabi` Arm, RISC-V without `f`) in integer code from the bits
/// (`split_float`, about 15 instructions), as the soft-float library's conversion and the
/// comparisons around it cost about 100; with an FPU, the hardware conversion.
#[inline(always)]
#[must_use]
pub fn to_i32(x: f32) -> i32 {
    #[cfg(soft_float)]
    {
        split_float(x).0
    }
    #[cfg(not(soft_float))]
    {
        x as i32
    }
}

/// `v as f32`, with the common case of a `v` that fits in i32 converted by the FPU (`as f32` of
/// an i64 is a library call even on Cortex-M4F), or without one by [`F32`]'s integer code. The
/// same rounding either way.
#[inline(always)]
#[must_use]
pub fn i64_to_f32(v: i64) -> f32 {
    match i32::try_from(v) {
        Ok(small) => F32::from(small).0,
        // From the bits: given `v as f32` here, the compiler would merge the two branches into
        // that library call.
        Err(_) => bits_i64_to_f32(v),
    }
}

/// `x as i64` (truncated towards zero, saturating, NaN gives 0) without the library call that
/// `as i64` is on 32-bit targets: below 2^31 in magnitude through i32; above, a float is an
/// integer, its 24-bit significand shifted into place.
#[inline]
#[must_use]
pub fn f32_to_i64(x: f32) -> i64 {
    let b = x.to_bits();
    let exp = ((b >> 23) & 0xff) as i32 - 127;
    if exp < 31 {
        return to_i32(x) as i64;
    }
    if exp >= 63 {
        let nan = exp == 128 && b << 9 != 0;
        return if nan {
            0
        } else if b >> 31 != 0 {
            i64::MIN
        } else {
            i64::MAX
        };
    }
    let magnitude = (((b & 0x7f_ffff) | 0x80_0000) as i64) << (exp - 23);
    if b >> 31 != 0 {
        -magnitude
    } else {
        magnitude
    }
}

/// `floor(x) as i32` (saturating; NaN gives 0) without a float `floor`, which Cortex-M4F's
/// FPU lacks: truncate, then step down where truncation went up (from the bits without an
/// FPU, see [`to_i32`]).
#[inline]
#[must_use]
pub fn floor_to_i32(x: f32) -> i32 {
    #[cfg(soft_float)]
    {
        let (t, cut) = split_float(x);
        if cut && x.to_bits() >> 31 != 0 {
            t - 1
        } else {
            t
        }
    }
    #[cfg(not(soft_float))]
    {
        let t = x as i32;
        if (t as f32) > x {
            t.saturating_sub(1)
        } else {
            t
        }
    }
}

/// Whether `x` is positive and finite (0 < x < infinity, not NaN), from its bits: positive
/// finite floats are exactly the bit patterns 1..=0x7f7f_ffff. A float comparison and
/// `is_finite` would cost several instructions each on Cortex-M4F, and library calls without
/// an FPU.
#[inline(always)]
#[must_use]
pub fn is_positive_finite(x: f32) -> bool {
    x.to_bits().wrapping_sub(1) < 0x7f7f_ffff
}

/// An integer that orders like `x` for every non-NaN float, with `-0.0` and `+0.0` equal:
/// float comparisons as integer ones, for targets without an FPU.
#[inline(always)]
#[must_use]
pub fn order_key(x: f32) -> i32 {
    let b = x.to_bits() as i32;
    if b < 0 {
        -(b & 0x7fff_ffff)
    } else {
        b
    }
}

/// `x · 2^e` for `|e| <= 120`, exact unless the result leaves f32's normal range.
#[inline]
#[must_use]
pub fn scale_by_power_of_two(x: f32, e: i32) -> f32 {
    // Without an FPU the two multiplications are library calls (about 80 instructions each
    // on Armv6-M); a normal result of a normal `x` is its exponent moved, the same bits.
    #[cfg(soft_float)]
    if let Some(y) = exponent_moved(x, e) {
        return y;
    }
    // Two factors keep each one a normal float.
    let pow2 = |k: i32| f32::from_bits(((127 + k) as u32) << 23);
    x * pow2(e / 2) * pow2(e - e / 2)
}

/// `x · 2^e` by its exponent alone, when `x` and the result are normal floats (then exact, as
/// the product is), or `x` itself when it is a zero; `None` otherwise (subnormal, infinite or
/// NaN, either way).
#[cfg_attr(not(soft_float), allow(dead_code))]
fn exponent_moved(x: f32, e: i32) -> Option<f32> {
    let bits = x.to_bits();
    if bits << 1 == 0 {
        return Some(x);
    }
    let exp = ((bits >> 23) & 0xff) as i32;
    let moved = exp.wrapping_add(e);
    ((1..255).contains(&exp) && (1..255).contains(&moved))
        .then(|| f32::from_bits((bits & !(0xff << 23)) | ((moved as u32) << 23)))
}

/// `v as f32 · 2^-e` (`v as f32` rounds to nearest, ties to even), for `|e| <= 120`.
///
/// Without an FPU, `v as f32` is built from the bits in integer code and the scale is added
/// to the exponent, where the soft-float library would take a conversion and two multiplies.
#[inline]
#[must_use]
pub fn i64_to_f32_scaled(v: i64, e: i32) -> f32 {
    #[cfg(soft_float)]
    {
        soft_i64_to_f32_scaled(v, e)
    }
    #[cfg(not(soft_float))]
    {
        scale_by_power_of_two(v as f32, -e)
    }
}

/// [`i64_to_f32_scaled`] in integer code.
#[cfg_attr(not(soft_float), allow(dead_code))]
fn soft_i64_to_f32_scaled(v: i64, e: i32) -> f32 {
    let f = bits_i64_to_f32(v);
    exponent_moved(f, -e).unwrap_or_else(|| scale_by_power_of_two(f, -e))
}

/// `v as f32` in integer code: the top 24 significant bits, rounded to nearest, ties to even.
/// Not inlined: with an FPU it is the rare path of [`i64_to_f32`]. Without one, in 32-bit
/// halves ([`soft::from_i64`]): the 64-bit leading-zero count and shifts here are library calls
/// there.
#[inline(never)]
fn bits_i64_to_f32(v: i64) -> f32 {
    #[cfg(soft_float)]
    {
        soft::from_i64(v)
    }
    #[cfg(not(soft_float))]
    {
        bits_i64_to_f32_wide(v)
    }
}

/// [`bits_i64_to_f32`] in 64-bit integers.
#[cfg_attr(soft_float, allow(dead_code))]
fn bits_i64_to_f32_wide(v: i64) -> f32 {
    if v == 0 {
        return 0.0;
    }
    let sign = if v < 0 { 1u32 << 31 } else { 0 };
    let m = v.unsigned_abs();
    let top = 63 - m.leading_zeros(); // position of the leading 1
    let (mut mantissa, mut exp) = if top <= 23 {
        ((m << (23 - top)) as u32, top)
    } else {
        let shift = top - 23;
        let (kept, rest, half) = ((m >> shift) as u32, m & ((1u64 << shift) - 1), 1u64 << (shift - 1));
        (kept + u32::from(rest > half || (rest == half && kept & 1 == 1)), top)
    };
    if mantissa == 1 << 24 {
        (mantissa, exp) = (mantissa >> 1, exp + 1);
    }
    f32::from_bits(sign | ((exp + 127) << 23) | (mantissa & 0x7f_ffff))
}

/// `(x as i32, whether a nonzero fraction was cut off)` from the bits of `x` alone: the
/// integer conversion of FPU-less targets (see [`to_i32`]). Saturates like `as`; NaN gives
/// `(0, false)`, and so do values cut off at saturation.
#[cfg_attr(not(soft_float), allow(dead_code))]
#[inline(always)]
fn split_float(x: f32) -> (i32, bool) {
    let b = x.to_bits();
    let exp = ((b >> 23) & 0xff) as i32 - 127;
    let negative = b >> 31 != 0;
    if exp < 0 {
        // |x| < 1: only zero has nothing to cut.
        return (0, b << 1 != 0);
    }
    if exp >= 31 {
        let nan = exp == 128 && b << 9 != 0;
        return (
            if nan {
                0
            } else if negative {
                i32::MIN
            } else {
                i32::MAX
            },
            false,
        );
    }
    let m = (b & 0x7f_ffff) | 0x80_0000;
    let (magnitude, cut) = if exp >= 23 { (m << (exp - 23), false) } else { (m >> (23 - exp), m << (9 + exp) != 0) };
    (if negative { (magnitude as i32).wrapping_neg() } else { magnitude as i32 }, cut)
}

/// The largest factor by which `m` stretches any direction's length, bounded by its largest
/// column (axis) length: what a bounding sphere's radius is multiplied by.
#[inline]
#[must_use]
pub fn max_axis_scale(m: &Mat4) -> f32 {
    [m.x_axis, m.y_axis, m.z_axis].iter().map(|a| a.truncate().length()).fold(0.0, f32::max)
}

/// `v / |v|`, or zero for a zero or non-finite vector.
#[inline]
#[must_use]
pub fn normalize_or_zero(v: Vec3) -> Vec3 {
    let len2 = v.dot(v);
    if len2 > 0.0 && len2.is_finite() {
        v * (1.0 / sqrt(len2))
    } else {
        Vec3::ZERO
    }
}

/// Babylon's `LookAtLH` view matrix (up = +y): world to camera space, camera looking along +z.
///
/// Returns `None` when `eye == target` or the view direction is parallel to `up`.
#[must_use]
pub fn look_at_lh(eye: Vec3, target: Vec3, up: Vec3) -> Option<Mat4> {
    let z = normalize_or_zero(target - eye);
    let x = normalize_or_zero(up.cross(z));
    if z == Vec3::ZERO || x == Vec3::ZERO {
        return None;
    }
    let y = z.cross(x);
    // Rows of Babylon's matrix are x, y, z axes as columns; glam stores columns.
    Some(Mat4::from_cols(
        Vec4::new(x.x, y.x, z.x, 0.0),
        Vec4::new(x.y, y.y, z.y, 0.0),
        Vec4::new(x.z, y.z, z.z, 0.0),
        Vec4::new(-x.dot(eye), -y.dot(eye), -z.dot(eye), 1.0),
    ))
}

/// Babylon's `PerspectiveFovLH`: vertical field of view `fov_y` (radians), `aspect` = width /
/// height; maps view z in `[near, far]` to NDC z in `[-1, 1]` and puts view z in clip w.
#[must_use]
pub fn perspective_lh(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let t = 1.0 / tan(fov_y * 0.5);
    let a = (far + near) / (far - near);
    let b = -2.0 * far * near / (far - near);
    Mat4::from_cols(
        Vec4::new(t / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, t, 0.0, 0.0),
        Vec4::new(0.0, 0.0, a, 1.0),
        Vec4::new(0.0, 0.0, b, 0.0),
    )
}

/// Babylon's `OrthoLH` for a view volume `width` x `height` centred on the view axis, mapping
/// view z in `[near, far]` to NDC z in `[-1, 1]` (clip w = 1).
#[must_use]
pub fn orthographic_lh(width: f32, height: f32, near: f32, far: f32) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(2.0 / width, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / height, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 2.0 / (far - near), 0.0),
        Vec4::new(0.0, 0.0, -(far + near) / (far - near), 1.0),
    )
}

/// The matrix that transforms normals: the inverse-transpose of `m`'s 3x3 part (never `m`
/// itself, which skews normals under non-uniform scale). Zero for a singular matrix.
#[must_use]
pub fn normal_matrix(m: &Mat4) -> Mat3 {
    let m3 = Mat3::from_mat4(*m);
    let det = m3.determinant();
    if det == 0.0 || !det.is_finite() {
        return Mat3::ZERO;
    }
    m3.inverse().transpose()
}

/// `max(a, b)` by comparison, `b` when `a` is NaN (as `f32::max` for a NaN `a`): `f32::max`
/// is a library call (`fmaxf`) on Cortex-M4F, whose FPU has no max instruction (and without
/// an FPU, the comparison is integer code, see `less`).
#[inline(always)]
#[must_use]
pub fn max(a: f32, b: f32) -> f32 {
    if greater(a, b) {
        a
    } else {
        b
    }
}

/// `min(a, b)` by comparison, `b` when `a` is NaN (see [`max`]).
#[inline(always)]
#[must_use]
pub fn min(a: f32, b: f32) -> f32 {
    if less(a, b) {
        a
    } else {
        b
    }
}

/// `x` clamped to 0..=1, 0 for NaN.
#[inline(always)]
#[must_use]
pub fn clamp01(x: f32) -> f32 {
    min(max(x, 0.0), 1.0)
}

/// Whether `m` is a rotation (orthonormal columns, to 1e-6): it keeps unit vectors unit.
#[must_use]
pub fn is_rotation(m: &Mat3) -> bool {
    let near = |a: f32, b: f32| (a - b).abs() <= 1e-6;
    let (x, y, z) = (m.x_axis, m.y_axis, m.z_axis);
    near(x.dot(x), 1.0)
        && near(y.dot(y), 1.0)
        && near(z.dot(z), 1.0)
        && near(x.dot(y), 0.0)
        && near(y.dot(z), 0.0)
        && near(z.dot(x), 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `+0 + b` from the bits is the addition, for every non-NaN `b` (NaN: a NaN).
    #[test]
    fn zero_plus_from_the_bits_is_the_sum() {
        let mut bits = 0u32;
        while let Some(next) = bits.checked_add(0x7fff) {
            for b in [bits, bits | 0x7f_ffff, bits & !0x7f_ffff, 0x8000_0000] {
                let x = f32::from_bits(b);
                let (sum, fast) = (0.0 + x, zero_plus(x));
                assert!(sum.to_bits() == fast.to_bits() || sum.is_nan() && fast.is_nan(), "{x:e}");
                assert!(offset_add(0.0, x).to_bits() == sum.to_bits() || sum.is_nan(), "{x:e}");
            }
            bits = next;
        }
    }

    /// Where it answers, exactly the multiply; it answers for every normal `x` below 2^124.
    #[test]
    fn times_16_from_the_bits_is_the_product() {
        let (mut answered, mut bits) = (0u32, 0u32);
        while let Some(next) = bits.checked_add(0x3f_fff7) {
            for b in [bits, bits | 0x7f_ffff, bits & !0x7f_ffff] {
                let x = f32::from_bits(b);
                if let Some(y) = times_pow2_bits(x, 4) {
                    assert_eq!(y.to_bits(), (x * 16.0).to_bits(), "{x:e}");
                    answered += 1;
                }
                assert_eq!(times_16(x).to_bits(), (x * 16.0).to_bits(), "{x:e}");
                for (k, m) in [(-1, 0.5f32), (23, 8_388_608.0), (-30, 1.0 / 1_073_741_824.0)] {
                    if let Some(y) = times_pow2_bits(x, k) {
                        assert_eq!(y.to_bits(), (x * m).to_bits(), "{x:e} · 2^{k}");
                    }
                }
                for m in [0.5f32, 8_388_608.0, 3.0, -2.0, 0.0, f32::INFINITY] {
                    assert_eq!(times_power_of_two(x, m).to_bits(), (x * m).to_bits(), "{x:e} · {m}");
                }
            }
            bits = next;
        }
        assert!(times_pow2_bits(1.0, 4).is_some() && times_pow2_bits(f32::from_bits(0x7d7f_ffff), 4).is_some());
        assert!(
            times_pow2_bits(f32::from_bits(0x7d80_0000), 4).is_none()
                && times_pow2_bits(f32::MIN_POSITIVE / 2.0, 4).is_none()
        );
        assert!(answered > 1000, "{answered}");
    }

    #[test]
    fn max_min_clamp_match_the_float_methods() {
        for (a, b) in [(1.0f32, 2.0), (2.0, 1.0), (-0.5, 0.0), (f32::NAN, 0.0), (3.0, 3.0)] {
            assert_eq!(max(a, b).to_bits(), a.max(b).to_bits(), "max({a}, {b})");
            assert_eq!(min(a, b).to_bits(), a.min(b).to_bits(), "min({a}, {b})");
        }
        assert_eq!([clamp01(-1.0), clamp01(0.25), clamp01(7.0), clamp01(f32::NAN)], [0.0, 0.25, 1.0, 0.0]);
    }

    /// The i32-first conversions between f32 and i64 equal `as`.
    #[test]
    fn i64_float_conversions_match_as() {
        let mut state = 0x5555_aaaa_1234_9876u64;
        for k in 0..1_000_000u32 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let v = (state as i64) >> (k % 64);
            assert_eq!(i64_to_f32(v).to_bits(), (v as f32).to_bits(), "{v}");
            let x = f32::from_bits(state as u32);
            assert_eq!(f32_to_i64(x), x as i64, "{x:e}");
        }
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 9.2e18, -9.3e18, 2147483648.0, -2147483648.0, -0.7] {
            assert_eq!(f32_to_i64(x), x as i64, "{x:e}");
        }
    }

    /// The integer `i64 as f32` of FPU-less targets rounds like the hardware one, and scaling
    /// by the exponent gives what multiplying does.
    #[test]
    fn integer_i64_to_f32_matches_as() {
        let mut values = std::vec![0i64, 1, -1, i64::MAX, i64::MIN, (1 << 24) + 1, (1 << 25) + 3, -(1 << 25) - 1];
        for k in 0..63 {
            values.extend([1i64 << k, (1i64 << k) - 1, (1i64 << k) + 1, -(1i64 << k), (3i64 << k) >> 1]);
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        values.extend((0..1_000_000).map(|k| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state as i64) >> (k % 64)
        }));
        for v in values {
            assert_eq!(bits_i64_to_f32_wide(v).to_bits(), (v as f32).to_bits(), "{v}");
            for e in [-40, -3, 0, 7, 60, 100, 120] {
                let want = scale_by_power_of_two(v as f32, -e);
                assert_eq!(soft_i64_to_f32_scaled(v, e).to_bits(), want.to_bits(), "{v} / 2^{e}");
            }
        }
    }

    /// Moving the exponent gives the product's bits wherever it gives any: every exponent and
    /// the special values, scaled by every power in reach (`scale_by_power_of_two`'s range).
    #[test]
    fn exponent_moved_is_the_product() {
        let mut values = std::vec![0.0f32, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE, 1e-40];
        values.extend(
            (0..=255u32)
                .flat_map(|exp| [exp << 23 | 0x2a_5a5a, 1 << 31 | exp << 23, exp << 23 | 0x7f_ffff])
                .map(f32::from_bits),
        );
        let mut moved = 0;
        for x in values {
            for e in -120..=120 {
                let pow2 = |k: i32| f32::from_bits(((127 + k) as u32) << 23);
                let product = x * pow2(e / 2) * pow2(e - e / 2);
                if let Some(y) = exponent_moved(x, e) {
                    assert_eq!(y.to_bits(), product.to_bits(), "{x:e} * 2^{e}");
                    moved += 1;
                }
                assert_eq!(scale_by_power_of_two(x, e).to_bits(), product.to_bits(), "{x:e} * 2^{e}");
            }
        }
        assert!(moved > 100_000, "{moved}");
    }

    /// The integer conversion of FPU-less targets equals `as i32` and floor for every special
    /// value, every power of two and its neighbours, and a million pseudo-random bit patterns.
    #[test]
    fn integer_float_conversion_matches_the_hardware_one() {
        let mut values =
            std::vec![0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, f32::MIN_POSITIVE, -f32::MIN_POSITIVE];
        values.extend([f32::MAX, f32::MIN, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, -f32::NAN, 2147483520.0]);
        values.extend([-2147483648.0, -2147483904.0, 2147483648.0, 8388607.5, -8388607.5, 16777215.0, -16777217.0]);
        for e in -30..40 {
            let p = 2f32.powi(e);
            for x in [p, -p] {
                values.extend([x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits() - 1)]);
            }
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        values.extend((0..1_000_000).map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            f32::from_bits(state as u32)
        }));
        for x in values {
            let (t, cut) = split_float(x);
            assert_eq!(t, x as i32, "{x:e} ({:#x})", x.to_bits());
            let floor = if cut && x < 0.0 { t - 1 } else { t };
            let want = if x.is_nan() { 0 } else { libm::floorf(x).clamp(i32::MIN as f32, i32::MAX as f32) as i32 };
            assert_eq!(floor, want, "floor {x:e} ({:#x})", x.to_bits());
        }
    }

    #[test]
    fn rotations_are_recognised() {
        assert!(is_rotation(&Mat3::from_rotation_y(0.5)));
        assert!(is_rotation(&Mat3::IDENTITY));
        assert!(!is_rotation(&Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0))));
        assert!(!is_rotation(&Mat3::ZERO));
    }

    #[test]
    fn floor_to_i32_is_floor() {
        for x in [
            0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 1e-30, -1e-30, 8388607.5, -8388607.5, 3e9, -3e9, 1e30, -1e30,
        ] {
            assert_eq!(floor_to_i32(x), libm::floorf(x) as i32, "{x}");
        }
        assert_eq!(floor_to_i32(f32::NAN), 0);
        assert_eq!(floor_to_i32(f32::INFINITY), i32::MAX);
        assert_eq!(floor_to_i32(f32::NEG_INFINITY), i32::MIN);
    }

    #[test]
    fn babylon_rotation_y_matches_spec() {
        // Spec: Ry(a) = [c 0 -s; 0 1 0; s 0 c] in row-vector form, so (1,0,0) -> (c, 0, -s).
        let m = Mat4::from_rotation_y(0.5);
        let p = m.transform_point3(Vec3::X);
        assert!((p - Vec3::new(cos(0.5), 0.0, -sin(0.5))).length() < 1e-6);
    }

    #[test]
    fn look_at_puts_target_in_front() {
        let v = look_at_lh(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, Vec3::Y).unwrap();
        let p = v.transform_point3(Vec3::ZERO);
        assert_eq!(p, Vec3::new(0.0, 0.0, 4.0));
        let right = v.transform_point3(Vec3::X);
        assert!(right.x > 0.0, "left-handed: +x stays right");
    }

    #[test]
    fn perspective_maps_near_far_to_ndc() {
        let p = perspective_lh(0.8, 1.0, 0.5, 10.0);
        let near = p * Vec4::new(0.0, 0.0, 0.5, 1.0);
        let far = p * Vec4::new(0.0, 0.0, 10.0, 1.0);
        assert!((near.z / near.w + 1.0).abs() < 1e-6);
        assert!((far.z / far.w - 1.0).abs() < 1e-6);
        assert_eq!(near.w, 0.5);
    }

    #[test]
    fn normal_matrix_keeps_normals_perpendicular_under_scale() {
        let m = Mat4::from_scale(Vec3::new(4.0, 1.0, 1.0));
        // A plane x + y = 0 has normal (1,1,0); scaling x by 4 turns the plane into x/4 + y = 0.
        let n = normal_matrix(&m) * Vec3::new(1.0, 1.0, 0.0);
        let tangent = m.transform_vector3(Vec3::new(1.0, -1.0, 0.0));
        assert!(n.dot(tangent).abs() < 1e-6);
    }
}
