//! A track's value at a frame, interpolated as Babylon.js's `Animation._interpolate` does: the
//! first or last key's value outside the keys, a step key's value until the next key, Hermite
//! where the first key of a span has an out tangent and the last an in tangent (scaled by the
//! frames between them), else linear, and
//! quaternions by `Quaternion.Slerp` (Hermite ones normalised).

use crate::format::Track;
use crate::math::{acos, sin, sqrt, Vec4};

/// `track`'s value at `frame` (components beyond its count zero).
#[must_use]
pub(super) fn value_at(track: &Track<'_>, frame: f32, quaternion: bool) -> Vec4 {
    let last = track.key_count().saturating_sub(1);
    // The first key after `frame` (binary search: keys are in increasing order).
    let (mut lo, mut hi) = (0, track.key_count());
    while lo < hi {
        let mid = (lo + hi) / 2;
        if track.frame(mid) <= frame {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    if lo == 0 {
        return track.value(0, 0);
    }
    if lo > last {
        return track.value(last, 0);
    }
    let (k, next) = (lo - 1, lo);
    let (f0, f1) = (track.frame(k), track.frame(next));
    if track.is_step(k) || f1 <= f0 {
        return track.value(k, 0);
    }
    let t = (frame - f0) / (f1 - f0);
    let (v0, v1) = (track.value(k, 0), track.value(next, 0));
    if track.has_out_tangent(k) && track.has_in_tangent(next) {
        let delta = f1 - f0;
        let h = hermite(v0, track.value(k, 2) * delta, v1, track.value(next, 1) * delta, t);
        return if quaternion { normalised(h) } else { h };
    }
    if quaternion {
        slerp(v0, v1, t)
    } else {
        v0 + (v1 - v0) * t
    }
}

/// Babylon.js's `Scalar.Hermite`, on each component.
fn hermite(v1: Vec4, t1: Vec4, v2: Vec4, t2: Vec4, amount: f32) -> Vec4 {
    let squared = amount * amount;
    let cubed = amount * squared;
    let part1 = 2.0 * cubed - 3.0 * squared + 1.0;
    let part2 = -2.0 * cubed + 3.0 * squared;
    let part3 = cubed - 2.0 * squared + amount;
    let part4 = cubed - squared;
    v1 * part1 + v2 * part2 + t1 * part3 + t2 * part4
}

/// `q` at unit length (zero stays zero).
fn normalised(q: Vec4) -> Vec4 {
    let length = sqrt(q.dot(q));
    if length > 0.0 {
        q / length
    } else {
        q
    }
}

/// Babylon.js's `Quaternion.Slerp`: the shorter way round, linear when nearly equal.
fn slerp(left: Vec4, right: Vec4, amount: f32) -> Vec4 {
    let mut cos = left.dot(right);
    let flip = cos < 0.0;
    if flip {
        cos = -cos;
    }
    let (a, b) = if cos > 0.999_999 {
        (1.0 - amount, amount)
    } else {
        let angle = acos(cos);
        let inverse_sin = 1.0 / sin(angle);
        (sin((1.0 - amount) * angle) * inverse_sin, sin(amount * angle) * inverse_sin)
    };
    left * a + right * if flip { -b } else { b }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_with_zero_tangents_eases_between_the_values() {
        let (a, b) = (Vec4::splat(1.0), Vec4::splat(3.0));
        assert_eq!(hermite(a, Vec4::ZERO, b, Vec4::ZERO, 0.0), a);
        assert_eq!(hermite(a, Vec4::ZERO, b, Vec4::ZERO, 1.0), b);
        assert_eq!(hermite(a, Vec4::ZERO, b, Vec4::ZERO, 0.5), Vec4::splat(2.0));
    }

    #[test]
    fn slerp_takes_the_shorter_way_and_keeps_unit_length() {
        let half = core::f32::consts::FRAC_1_SQRT_2;
        let (identity, quarter_turn) = (Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(0.0, half, 0.0, half));
        let mid = slerp(identity, quarter_turn, 0.5);
        // An eighth of a turn about y: (0, sin(pi/8), 0, cos(pi/8)).
        let expected =
            Vec4::new(0.0, libm::sinf(core::f32::consts::PI / 8.0), 0.0, libm::cosf(core::f32::consts::PI / 8.0));
        assert!((mid - expected).abs().max_element() < 1e-6, "{mid}");
        // -q is the same rotation: slerp goes the short way to it too.
        let mid_negated = slerp(identity, -quarter_turn, 0.5);
        assert!((mid_negated.abs() - expected.abs()).abs().max_element() < 1e-6, "{mid_negated}");
    }
}
