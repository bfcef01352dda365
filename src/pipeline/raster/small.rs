//! Small triangles: a set-up of their own ([`SmallTriangle`]: the edges, the depth plane kept
//! in f32, the corners' perspective values), then every pixel centre of the box tested against
//! the three edges and each covered one given its exact perspective-correct varyings
//! ([`SmallTriangle::for_each_pixel`]), for triangles whose box holds so few pixels that the
//! planes, the affine test and the row walk of the other paths cost more than the pixels
//! themselves (a distant mesh's triangles, most of them one to three pixels). It does not shade
//! the pixels (`span` does).

use super::affine::{f32_depth_plane, integer_depth_plane};
use super::{f32_varyings, normalised_inv_w, oriented, Corner, CoveredBox, Edge};
use crate::fixed::{depth30_from_unit, Depth30, FDot16};
use crate::math::{i64_to_f32_scaled, F32};

/// The largest box, in pixel centres (see `CoveredBox::frame_pixels`), drawn pixel by pixel.
/// Measured on the Cortex-M4F reference frame once the box scan lost its inclusive range,
/// against 32: 24 +8.8k, 28 +1.5k, 40 +4.5k, 48 +13.6k instructions (see BENCHMARKS.md).
pub(crate) const SMALL_BOX: u32 = 32;

/// A small triangle ready to draw pixel by pixel: only what [`SmallTriangle::for_each_pixel`]
/// reads (no planes for the varyings, no row walk, no affine test: for a few pixels, their
/// set-up costs more than the exact values at each).
pub(crate) struct SmallTriangle<const V: usize> {
    /// The rows' edges, from the same origin (see `raster::oriented`): the same pixels.
    edges: [Edge; 3],
    /// The box in frame pixels (inclusive), already clipped to the window.
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
    /// Frame row of the origin pixel centre (unclipped by the band).
    origin_row: i32,
    /// The depth plane in f32: depth (0..=1) at the origin pixel centre, and per pixel in x and
    /// y (see `affine::f32_depth_plane`).
    z: (F32, F32, F32),
    /// The corners' `1/w` divided by the largest, their varyings at vertex 0 and the
    /// differences to vertices 1 and 2 (in f32: converted once, not at each pixel), for
    /// `raster::f32_varyings`.
    inv_w: [F32; 3],
    v0: [FDot16; V],
    d1: [F32; V],
    d2: [F32; V],
}

impl<const V: usize> SmallTriangle<V> {
    /// The triangle `tri` of signed area `area` (see `facing`) in its box `bbox`.
    #[inline(always)]
    pub(crate) fn new(tri: &[Corner<V>; 3], bbox: &CoveredBox, area: i32) -> Self {
        let ([a, b, c], origin, origin_row, edges) = oriented(tri, bbox, area);
        let v = [a, b, c].map(|v| (v.x, v.y, v.z));
        SmallTriangle {
            edges,
            x0: bbox.x0,
            x1: bbox.x1,
            y0: bbox.y0,
            y1: bbox.y1,
            origin_row,
            z: f32_depth_plane(v, area, origin).unwrap_or_else(|| steep_depth_plane(v, area, origin)),
            inv_w: normalised_inv_w([a.inv_w, b.inv_w, c.inv_w]),
            v0: a.v,
            d1: core::array::from_fn(|k| F32::from(b.v[k].wrapping_sub(a.v[k]))),
            d2: core::array::from_fn(|k| F32::from(c.v[k].wrapping_sub(a.v[k]))),
        }
    }

    /// Hands every covered pixel of the window to `pixel`, row by row, left to right: frame
    /// column and row, depth (the f32 plane's, stepped from each row's first column, in 2.30:
    /// within about 2^-19 of the exact plane, see the test) and the exact perspective-correct
    /// varyings (`raster::f32_varyings`, as the exact rows give them), worked out when read
    /// ([`ExactVaryings::get`]: not for a pixel the depth test rejects). The edge functions are
    /// the rows' (`c + 16·b·dy + 16·a·x`), so the covered pixels are the same ones.
    #[inline(always)]
    pub(crate) fn for_each_pixel(&self, mut pixel: impl FnMut(i32, i32, Depth30, ExactVaryings<'_, V>)) {
        let steps: [i32; 3] = core::array::from_fn(|k| self.edges[k].a * 16);
        let (z_origin, z_dx, z_dy) = self.z;
        for y in self.y0..=self.y1 {
            let dy = y - self.origin_row;
            let mut e: [i32; 3] = core::array::from_fn(|k| self.edges[k].c + self.edges[k].b * 16 * dy);
            // From the row's first column of the box, the same in every band.
            let mut z = z_origin + z_dy * F32::from(dy);
            // Half-open: an inclusive range carries an "exhausted" flag through the loop (-10.6k
            // a reference frame; the rows' loop measured better inclusive).
            for x in 0..self.x1 - self.x0 + 1 {
                // Inside every edge: all three non-negative, so their sign bits' union is clear.
                if e[0] | e[1] | e[2] >= 0 {
                    pixel(self.x0 + x, y, depth30_from_unit(z.0), ExactVaryings(self, e));
                }
                // Within the box every edge function fits i32 (see the module's numbers); the
                // step after the last column is not used (wrapping: it may leave the box).
                e = core::array::from_fn(|k| e[k].wrapping_add(steps[k]));
                z = z + z_dx;
            }
        }
    }
}

/// A covered pixel's exact varyings (see [`SmallTriangle::for_each_pixel`]), worked out by
/// [`ExactVaryings::get`]: for a pixel the depth test rejects, not at all.
pub(crate) struct ExactVaryings<'t, const V: usize>(&'t SmallTriangle<V>, [i32; 3]);

impl<const V: usize> ExactVaryings<'_, V> {
    /// The varyings (`raster::f32_varyings` at the pixel's edge functions).
    #[inline(always)]
    pub(crate) fn get(&self) -> [FDot16; V] {
        let (t, e) = (self.0, self.1);
        f32_varyings(e, &t.inv_w, &t.v0, |k| (t.d1[k], t.d2[k])).0
    }
}

/// The depth plane of a triangle whose f32 plane is not accurate (a sliver, or depths far apart
/// for its size: see `affine::depth_plane`), as `SmallTriangle` steps it: the integer plane's
/// values (exact within a unit of 2^-40) rounded to f32. Rare in a mesh: out of line.
#[cold]
#[inline(never)]
fn steep_depth_plane(v: [(i32, i32, f32); 3], area: i32, origin: (i32, i32)) -> (F32, F32, F32) {
    let (z, z_dx, z_dy) = integer_depth_plane(v, area.unsigned_abs(), origin);
    let to_f32 = |v: i64| F32(i64_to_f32_scaled(v, 40));
    (to_f32(z), to_f32(z_dx), to_f32(z_dy))
}

#[cfg(test)]
mod tests {
    use super::super::{facing, oriented, Corner, CoveredBox, ScreenVertex, Setup, Span, SpanSink, Window};
    use super::*;
    use std::vec::Vec;

    /// Collects the pixels of the runs a sink is handed: frame column and row, depth, varyings.
    struct Pixels(Vec<(i32, i32, Depth30, [FDot16; 3])>);

    impl SpanSink<3> for Pixels {
        fn span(&mut self, s: &Span<3>) {
            assert_eq!(s.len, 1, "exact rows with subspan 1 and no tolerance: a run a pixel");
            self.0.push((s.x, s.y, s.z, s.v));
        }
    }

    /// Small triangles drawn pixel by pixel cover exactly the pixels the rows cover, with their
    /// exact varyings (the rows' at every pixel, as `subspan = 1` gives them) and depths within
    /// 2^11 units of 2^-30 (1/8 of a 16-bit depth step) of the rows' plane where its values are
    /// at most 1 (more for steep planes, in proportion), in every band; the choice is
    /// the same in every band (a small LCG: reproducible without a dependency).
    #[test]
    fn pixels_of_small_triangles_are_the_rows_pixels() {
        let mut rng = crate::test_rng::Lcg(0x5a11_b0c5);
        let mut next = |n: u32| (rng.next() >> 1) % n;
        let (mut small, mut steep, mut pixels, mut worst) = (0, 0, 0, 0);
        for _ in 0..20_000 {
            let (size, at) = ([3, 6, 12][next(3) as usize], next(200) as i32 * 16);
            let vertex = |next: &mut dyn FnMut(u32) -> u32| ScreenVertex {
                x: at + next(size * 16) as i32,
                y: at + next(size * 16) as i32,
                z: next(1000) as f32 / 1000.0,
                inv_w: 0.5 + next(1000) as f32 / 1000.0,
                varyings: core::array::from_fn(|_| next(1 << 20) as i32),
            };
            let tri = [vertex(&mut next), vertex(&mut next), vertex(&mut next)];
            let Ok(area) = facing(&tri, false, false) else { continue };
            let corners = tri.each_ref().map(Corner::<3>::of);
            let whole = Window { width: 400, row_start: 0, row_end: 400 };
            let (row_start, rows) = (at / 16 + next(size + 2) as i32 - 1, 1 + next(4) as i32);
            let band = Window { width: 400, row_start, row_end: row_start + rows };
            let small_in = |window: &Window| {
                let bbox = CoveredBox::of(&corners, window)?;
                (bbox.frame_pixels() <= SMALL_BOX).then(|| SmallTriangle::new(&corners, &bbox, area))
            };
            for window in [whole, band] {
                let Some(bbox) = CoveredBox::of(&corners, &window) else { continue };
                // The same choice as the whole frame's.
                let whole_box = CoveredBox::of(&corners, &whole).unwrap();
                assert_eq!(bbox.frame_pixels(), whole_box.frame_pixels(), "{tri:?} in {window:?}");
                let Some(triangle) = small_in(&window) else { continue };
                assert!(small_in(&whole).is_some(), "{tri:?} in {window:?}: small here only");
                small += 1;
                let ([a, b, c], origin, _, _) = oriented(&corners, &bbox, area);
                steep += u32::from(f32_depth_plane([a, b, c].map(|v| (v.x, v.y, v.z)), area, origin).is_none());
                let mut setup = Setup::<3>::new(&tri, &window, false, false).unwrap();
                setup.use_fpu_perspective();
                let mut rows = Pixels(Vec::new());
                setup.for_each_span(1, &mut rows);
                let mut each = Vec::new();
                triangle.for_each_pixel(|x, y, z, v| each.push((x, y, z, v.get())));
                assert_eq!(each.len(), rows.0.len(), "{tri:?} in {window:?}");
                // f32 steps from the plane's values: within some ulps of the largest term (and
                // the f32 plane's own 2^-21, see `affine::depth_plane`).
                let (z0, dx, dy) = triangle.z;
                let largest = [1.0, z0.0.abs(), 16.0 * dx.0.abs(), 16.0 * dy.0.abs()].into_iter().fold(0f32, f32::max);
                let bound = (2048.0 * largest) as u32;
                for (&(x, y, z, v), &(rx, ry, rz, rv)) in each.iter().zip(&rows.0) {
                    assert_eq!((x, y, v), (rx, ry, rv), "{tri:?} in {window:?}");
                    let off = z.abs_diff(rz);
                    worst = worst.max(off);
                    assert!(off <= bound, "{tri:?} at ({x}, {y}): depth {z} for {rz}");
                }
                pixels += each.len();
            }
        }
        assert!(
            small > 5000 && steep > 10 && pixels > 5000,
            "{small} small triangles ({steep} with steep planes), {pixels} pixels"
        );
        std::println!(
            "{small} small triangles ({steep} with steep planes), {pixels} pixels, depth at most {worst} units off"
        );
    }
}
