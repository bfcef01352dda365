//! Which way a triangle faces, and whether its snapped corners are within the ranges the
//! rasterizer's integers hold for (the guard band): twice its signed area, exact in `i32`, and
//! the culling rule. It does not clip (`clip` does) or set the triangle up (`raster` does).

use super::{Reject, ScreenVertex};

/// The largest extent of a triangle in 1/16 pixels: twice the guard band's half extent plus
/// one pixel of slack, so that `A·dx + B·dy` over its bounding box fits in `i32`.
pub const MAX_EXTENT: i32 = (2 * crate::target::GUARD_HALF_EXTENT as i32 + 1) * 16;

// Twice the area of a triangle of that extent fits i32 (see `facing_in_guard_band`).
const _: () = assert!((MAX_EXTENT as i64 - 1) * (MAX_EXTENT as i64 - 1) * 2 < 1 << 31);

/// The largest absolute coordinate, in 1/16 pixels, the rasterizer accepts.
pub const MAX_COORD: i32 = 1 << 24;

/// Twice the signed image-space area of `tri` (y down), checked against the culling rule:
/// front faces are counter-clockwise with y up, i.e. a negative area here, unless `flip`.
///
/// # Errors
/// [`Reject::Degenerate`] for zero area, [`Reject::BackFace`] for a culled back face.
pub fn facing(tri: &[ScreenVertex; 3], cull_back: bool, flip: bool) -> Result<i32, Reject> {
    facing_of(tri.each_ref().map(|v| (v.x, v.y, v.inv_w)), cull_back, flip)
}

/// [`facing`] of the vertices' `(x, y, 1/w)`.
pub(crate) fn facing_of(p: [(i32, i32, f32); 3], cull_back: bool, flip: bool) -> Result<i32, Reject> {
    let w_ok = crate::math::is_positive_finite;
    if !(in_guard_band(p.map(|p| (p.0, p.1))) && p.iter().all(|p| w_ok(p.2))) {
        return Err(Reject::OutsideGuardBand);
    }
    facing_in_guard_band(p.map(|p| (p.0, p.1)), cull_back, flip)
}

/// Whether the snapped positions `p` lie within the ranges the rasterizer's integers hold for
/// (see the module's numbers). Clipping keeps triangles inside the guard band, but float
/// rounding (or a denormal w) can still push a vertex out.
#[inline(always)]
pub(crate) fn in_guard_band(p: [(i32, i32); 3]) -> bool {
    let span = |[a, b, c]: [i32; 3]| {
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        // Both within ±2^24, so the difference fits i32.
        lo > -MAX_COORD && hi < MAX_COORD && hi - lo < MAX_EXTENT
    };
    span(p.map(|p| p.0)) && span(p.map(|p| p.1))
}

/// [`facing_of`] of positions already known [`in_guard_band`], with positive finite `1/w`s.
#[inline(always)]
pub(crate) fn facing_in_guard_band(p: [(i32, i32); 3], cull_back: bool, flip: bool) -> Result<i32, Reject> {
    let area = area_in_guard_band(p);
    if area == 0 {
        return Err(Reject::Degenerate);
    }
    if cull_back && (area < 0) == flip {
        return Err(Reject::BackFace);
    }
    Ok(area)
}

/// Twice the signed image-space area of positions `p` known [`in_guard_band`] (see
/// [`facing`]).
#[inline(always)]
pub(crate) fn area_in_guard_band(p: [(i32, i32); 3]) -> i32 {
    debug_assert!(in_guard_band(p));
    let [p0, p1, p2] = p;
    // Coordinates are less than `MAX_EXTENT` < 2^15 apart (in the guard band): each product is
    // below 2^30 in magnitude and their difference below 2 · (MAX_EXTENT - 1)^2 < 2^31, so the
    // area is exact in i32 (one multiply and one multiply-subtract).
    (p1.0 - p0.0) * (p2.1 - p0.1) - (p2.0 - p0.0) * (p1.1 - p0.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn facing_refuses_a_non_positive_or_non_finite_w() {
        let v = |x: i32, y: i32, inv_w: f32| ScreenVertex { x, y, z: 0.5, inv_w, varyings: [0; 8] };
        let tri = |w: f32| [v(0, 0, 1.0), v(160, 0, 1.0), v(0, 160, w)];
        assert!(facing(&tri(0.5), false, false).is_ok());
        assert!(facing(&tri(f32::MIN_POSITIVE / 2.0), false, false).is_ok(), "subnormal but positive");
        assert!(facing(&tri(f32::MAX), false, false).is_ok());
        for bad in [0.0, -0.0, -1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, -f32::NAN] {
            assert_eq!(facing(&tri(bad), false, false), Err(Reject::OutsideGuardBand), "1/w = {bad}");
        }
    }
}
