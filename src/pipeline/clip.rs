//! Homogeneous clipping against the near and far planes and the guard band, and the outcodes
//! that classify a triangle for culling and clipping. It does not project or draw what is left
//! (`primitive` does).
//!
//! A triangle that crosses a plane is cut to the polygon the plane leaves (at most 3 + 6
//! vertices, in a fixed-capacity buffer) and drawn as a fan; one wholly outside any view
//! plane is rejected. The x/y planes are the guard band's, not the viewport's, so triangles
//! that merely overlap the screen edge are not cut (the rasterizer's bounding box does that).

use heapless::Vec;

use super::varyings::{ClipVaryings, MAX_VARYINGS};
use crate::math::Vec4;

/// A vertex in clip space with its varyings (in f32 before fixed-point conversion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// Clip-space position `(x, y, z, w)`.
    pub pos: Vec4,
    /// Attributes interpolated across the triangle.
    pub varyings: ClipVaryings,
}

/// The most vertices a clipped triangle can have (3 plus one per plane).
pub const MAX_CLIPPED: usize = 9;

/// A clipped polygon.
pub type Polygon = Vec<ClipVertex, MAX_CLIPPED>;

/// What clipping did to a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipResult {
    /// Entirely inside the guard band and depth range: draw as is.
    Inside,
    /// Cut by at least one plane: draw the polygon.
    Clipped,
    /// Nothing visible (outside a view plane, or a non-finite coordinate).
    Outside,
}

/// Guard-band half extents in clip units: `|x| <= gx·w`, `|y| <= gy·w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardBand {
    /// Horizontal guard band, >= 1.
    pub gx: f32,
    /// Vertical guard band, >= 1.
    pub gy: f32,
}

impl GuardBand {
    /// Signed distances (inside >= 0) to the six clipping planes.
    #[inline]
    fn distances(&self, p: Vec4) -> [f32; 6] {
        [p.z + p.w, p.w - p.z, self.gx * p.w + p.x, self.gx * p.w - p.x, self.gy * p.w + p.y, self.gy * p.w - p.y]
    }
}

/// [`outcode`] bits 0 to 5: outside the near, far, left, right, bottom or top view plane.
pub const OUTSIDE_VIEW: u8 = 0x3f;
/// [`outcode`] bit: a coordinate is infinite or NaN.
pub const NOT_FINITE: u8 = 0x40;
/// [`outcode`] bit: outside a clipping plane (near, far or the guard band).
pub const NEEDS_CLIP: u8 = 0x80;

/// Where a clip-space point lies: one bit per view plane it is outside ([`OUTSIDE_VIEW`]),
/// [`NOT_FINITE`], and [`NEEDS_CLIP`]. Computed once per vertex (and kept in the renderer's
/// vertex cache), so that per triangle culling and clipping decisions are bit operations.
#[must_use]
pub(crate) fn outcode(p: Vec4, guard: &GuardBand) -> u8 {
    #[cfg(soft_float)]
    {
        outcode_by_keys(p, guard)
    }
    #[cfg(not(soft_float))]
    {
        outcode_by_floats(p, guard)
    }
}

/// [`outcode`] with float comparisons. Each plane test `a + b < 0` is `a < -b`, exactly (a
/// float sum is zero only for opposite operands, and rounding keeps its sign): no additions,
/// and only the guard band's two products. The guard band's two planes of an axis are one
/// test: for finite `x` and non-NaN `g`, `|x| > g` is `x < -g || g < x`.
#[cfg_attr(soft_float, allow(dead_code))]
fn outcode_by_floats(p: Vec4, guard: &GuardBand) -> u8 {
    let [x, y, z, w] = p.to_array();
    // The common case first: inside the view volume, so inside every plane (the guard band
    // is >= 1) and finite (`|x| <= w < ∞`, false for NaN). Outcode 0.
    if x.abs() <= w && y.abs() <= w && z.abs() <= w && w < f32::INFINITY {
        return 0;
    }
    if !p.is_finite() {
        return NOT_FINITE;
    }
    let view = [z < -w, w < z, x < -w, w < x, y < -w, w < y];
    let outside = view.iter().enumerate().fold(0, |code, (k, &out)| code | u8::from(out) << k);
    // Finite operands (and products that may overflow, but not to NaN): `a >= b` is `!(a < b)`.
    let clip = view[0] || view[1] || x.abs() > guard.gx * w || y.abs() > guard.gy * w;
    outside | if clip { NEEDS_CLIP } else { 0 }
}

/// [`outcode`] for targets without an FPU: the same bits with integer comparisons of
/// [`order_key`](crate::math::order_key)s. Each plane test `a + b < 0` is `a < -b`, exactly
/// (a float sum is zero only for opposite operands, and rounding keeps its sign), so only the
/// guard band's two products are float operations.
#[cfg_attr(not(soft_float), allow(dead_code))]
fn outcode_by_keys(p: Vec4, guard: &GuardBand) -> u8 {
    use crate::math::order_key as key;
    let [x, y, z, w] = p.to_array();
    if [x, y, z, w].iter().any(|c| c.to_bits() & 0x7f80_0000 == 0x7f80_0000) {
        return NOT_FINITE;
    }
    let (kx, ky, kz, kw, minus_w) = (key(x), key(y), key(z), key(w), key(-w));
    let view = [kz < minus_w, kw < kz, kx < minus_w, kw < kx, ky < minus_w, kw < ky];
    let outside = view.iter().enumerate().fold(0, |code, (k, &out)| code | u8::from(out) << k);
    // Inside the view volume (the common case): inside the guard band too (it is >= 1), so
    // neither of its products (library calls) is needed.
    if outside == 0 {
        return 0;
    }
    let product = |g: f32| (crate::math::F32(g) * crate::math::F32(w)).0;
    let (gx, gy) = (product(guard.gx), product(guard.gy));
    let inside = kz >= minus_w && kw >= kz && kx >= key(-gx) && key(gx) >= kx && ky >= key(-gy) && key(gy) >= ky;
    outside | if inside { 0 } else { NEEDS_CLIP }
}

/// What to do with a triangle whose vertices have the outcodes `codes`: `Outside` when it
/// cannot cover any pixel (all three outside one view plane, or a coordinate not finite),
/// `Inside` when no vertex is outside a clipping plane, else `Clipped` (it needs [`cut`]). The
/// one classification that culling and clipping share.
#[inline(always)]
#[must_use]
pub(crate) fn classify([a, b, c]: [u8; 3]) -> ClipResult {
    if a & b & c & OUTSIDE_VIEW != 0 || (a | b | c) & NOT_FINITE != 0 {
        ClipResult::Outside
    } else if (a | b | c) & NEEDS_CLIP == 0 {
        ClipResult::Inside
    } else {
        ClipResult::Clipped
    }
}

/// Clips triangle `tri` into `out`: `classify`, then varyings checked finite, then `cut`.
pub fn clip_triangle(tri: &[ClipVertex; 3], guard: &GuardBand, out: &mut Polygon) -> ClipResult {
    out.clear();
    let class = classify(tri.each_ref().map(|v| outcode(v.pos, guard)));
    if class == ClipResult::Outside || !finite_varyings(&tri.each_ref().map(|v| v.varyings), MAX_VARYINGS) {
        return ClipResult::Outside;
    }
    match class {
        ClipResult::Clipped => cut(tri, guard, out),
        r => r,
    }
}

/// Whether the first `checked` varyings of three vertices are all finite.
#[inline]
pub(crate) fn finite_varyings<const N: usize>(v: &[[f32; N]; 3], checked: usize) -> bool {
    // `a · 0` is 0 for every finite `a` and NaN for infinities and NaN: one multiply-add each.
    let junk: f32 = v.iter().flat_map(|v| v.iter().take(checked)).map(|a| a * 0.0).sum();
    junk == 0.0
}

/// Cuts `tri` by every plane into `out`: `Clipped`, or `Outside` when nothing is left.
pub(crate) fn cut(tri: &[ClipVertex; 3], guard: &GuardBand, out: &mut Polygon) -> ClipResult {
    out.clear();
    let mut a: Polygon = tri.iter().copied().collect();
    for plane in 0..6 {
        let mut b = Polygon::new();
        clip_polygon(&a, &mut b, |v| guard.distances(v.pos)[plane]);
        a = b;
        if a.len() < 3 {
            return ClipResult::Outside;
        }
    }
    *out = a;
    ClipResult::Clipped
}

/// One Sutherland–Hodgman pass. New vertices are always interpolated from the inside vertex
/// towards the outside one, so two triangles sharing an edge get the same cut point.
fn clip_polygon(input: &Polygon, output: &mut Polygon, dist: impl Fn(&ClipVertex) -> f32) {
    for (i, a) in input.iter().enumerate() {
        let b = &input[(i + 1) % input.len()];
        let (da, db) = (dist(a), dist(b));
        if da >= 0.0 {
            // Capacity: each pass adds at most one vertex, and we start with 3 of 9.
            let _ = output.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            // Interpolate from the endpoint nearer the plane: with distances 2^24 apart, the
            // other way round rounds `t` to 1 and returns the far vertex itself. The choice
            // depends only on the edge, so two triangles sharing it still agree.
            let (near, far, dn, df) = if da.abs() <= db.abs() { (a, b, da, db) } else { (b, a, db, da) };
            let t = dn / (dn - df);
            let _ = output.push(lerp(near, far, t));
        }
    }
}

fn lerp(a: &ClipVertex, b: &ClipVertex, t: f32) -> ClipVertex {
    ClipVertex {
        pos: a.pos + (b.pos - a.pos) * t,
        varyings: core::array::from_fn(|k| a.varyings[k] + (b.varyings[k] - a.varyings[k]) * t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32, w: f32) -> ClipVertex {
        ClipVertex { pos: Vec4::new(x, y, z, w), varyings: [0.0; MAX_VARYINGS] }
    }

    #[test]
    fn near_plane_cuts_one_vertex_behind() {
        let planes = GuardBand { gx: 4.0, gy: 4.0 };
        let mut out = Polygon::new();
        // Vertex 2 is behind the eye (w < 0): the near plane z >= -w keeps a quad.
        let tri = [v(0.0, 0.0, 0.5, 1.0), v(0.5, 0.0, 0.5, 1.0), v(0.0, 0.5, -2.0, -1.0)];
        assert_eq!(clip_triangle(&tri, &planes, &mut out), ClipResult::Clipped);
        assert_eq!(out.len(), 4);
        assert!(out.iter().all(|p| p.pos.z + p.pos.w >= -1e-6 && p.pos.w > 0.0));
    }

    #[test]
    fn nan_and_fully_behind_are_outside() {
        let planes = GuardBand { gx: 4.0, gy: 4.0 };
        let mut out = Polygon::new();
        let tri = [v(f32::NAN, 0.0, 0.5, 1.0), v(0.5, 0.0, 0.5, 1.0), v(0.0, 0.5, 0.5, 1.0)];
        assert_eq!(clip_triangle(&tri, &planes, &mut out), ClipResult::Outside);
        let tri = [v(0.0, 0.0, -2.0, -1.0), v(0.5, 0.0, -2.0, -1.0), v(0.0, 0.5, -2.0, -1.0)];
        assert_eq!(clip_triangle(&tri, &planes, &mut out), ClipResult::Outside);
    }

    fn outside_view_or_not_finite(p: [Vec4; 3]) -> bool {
        classify(p.map(|p| outcode(p, &GuardBand { gx: 4.0, gy: 4.0 }))) == ClipResult::Outside
    }

    /// Integer and float outcodes agree: random points of every magnitude and sign, points on
    /// the planes, zeros of both signs and non-finite coordinates.
    #[test]
    fn outcodes_by_keys_equal_outcodes_by_floats() {
        let planes = GuardBand { gx: 4.0, gy: 3.0 };
        let mut state = 0x0123_4567_89ab_cdefu64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let special = [0.0, -0.0, 1.0, -1.0, 4.0, -4.0, 0.5, f32::MAX, f32::MIN_POSITIVE, f32::INFINITY, f32::NAN];
        for n in 0..300_000 {
            let mut c = [0.0f32; 4];
            for v in c.iter_mut() {
                let r = next();
                *v = match r % 4 {
                    0 => special[(r >> 8) as usize % special.len()] * if r & 128 != 0 { -1.0 } else { 1.0 },
                    1 => f32::from_bits((r >> 16) as u32),
                    _ => ((r >> 20) % 2001) as f32 / 250.0 - 4.0,
                };
            }
            // Points exactly on a plane: x = ±w, y = ±gy·w, z = ±w.
            if n % 5 == 0 {
                let k = (next() % 3) as usize;
                c[k] = if k == 1 { planes.gy * c[3] } else { -c[3] };
            }
            let p = Vec4::from_array(c);
            assert_eq!(outcode_by_keys(p, &planes), outcode_by_floats(p, &planes), "{p:?}");
        }
    }

    /// Each plane on its own, points exactly on a plane, and every non-finite coordinate.
    #[test]
    fn outside_view_finds_each_plane_and_every_non_finite_coordinate() {
        let p = Vec4::new;
        let inside = [p(0.0, 0.0, 0.5, 1.0), p(0.5, 0.0, 0.5, 1.0), p(0.0, 0.5, 0.5, 1.0)];
        assert!(!outside_view_or_not_finite(inside));
        // Exactly on the left plane (x = -w) with the other points inside: kept.
        assert!(!outside_view_or_not_finite([p(-1.0, 0.0, 0.5, 1.0), inside[1], inside[2]]));
        // All three on the plane itself: distance +0, kept (may still cover pixel centres).
        assert!(!outside_view_or_not_finite([p(-1.0, 0.0, 0.5, 1.0), p(-1.0, 0.5, 0.5, 1.0), p(-2.0, 0.0, 0.5, 2.0)]));
        for axis in 0..3 {
            for side in [-1.0, 1.0] {
                let beyond = |t: f32| {
                    let mut c = [t, 0.1, 0.5 * side];
                    c[axis] = side * 1.5;
                    p(c[0], c[1], c[2], 1.0)
                };
                let tri = [beyond(0.0), beyond(0.2), beyond(-0.2)];
                assert!(outside_view_or_not_finite(tri), "axis {axis}, side {side}");
                // One point back inside: the triangle may cross the view.
                assert!(!outside_view_or_not_finite([tri[0], tri[1], inside[0]]), "axis {axis}, side {side}");
            }
        }
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for k in 0..12 {
                let mut tri = inside;
                tri[k / 4][k % 4] = bad;
                assert!(outside_view_or_not_finite(tri), "{bad} at {k}");
            }
        }
        // Huge but finite: not culled for being huge.
        assert!(!outside_view_or_not_finite([p(1e30, 0.0, 0.5, 1e30), inside[1], inside[2]]));
    }
}
