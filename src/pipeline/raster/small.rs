//! Small triangles: every pixel centre of the box tested against the three edges and each
//! covered one given its exact perspective-correct varyings ([`Setup::for_each_pixel`]), for
//! triangles whose box holds so few pixels that the planes, the affine test and the row walk
//! of the other paths cost more than the pixels themselves (a distant mesh's triangles, most of
//! them one to three pixels). It does not shade the pixels (`span` does).

use super::Setup;
use crate::fixed::{depth40_to_30, Depth30, FDot16, DEPTH30_FAR};

/// The largest box, in pixel centres (see `CoveredBox::frame_pixels`), drawn pixel by pixel.
pub(crate) const SMALL_BOX: u32 = 16;

impl<const V: usize> Setup<V> {
    /// Hands every covered pixel of the window to `pixel`, row by row, left to right: frame
    /// column and row, depth (the depth plane's, as [`Setup::for_each_span`] steps it, clamped
    /// to 0..=2^30) and the exact perspective-correct varyings (`Setup::varyings_at`, as the
    /// exact rows give them). The edge functions are the rows' (`c + 16·b·dy + 16·a·x`), so the
    /// covered pixels are the same ones.
    #[inline(always)]
    pub(crate) fn for_each_pixel(&self, mut pixel: impl FnMut(i32, i32, Depth30, [FDot16; V])) {
        let steps: [i32; 3] = core::array::from_fn(|k| self.edges[k].a * 16);
        for y in self.y0..=self.y1 {
            let dy = y - self.origin_row;
            let mut e: [i32; 3] = core::array::from_fn(|k| self.edges[k].c + self.edges[k].b * 16 * dy);
            for x in 0..=self.x1 - self.x0 {
                // Inside every edge: all three non-negative, so their sign bits' union is clear.
                if e[0] | e[1] | e[2] >= 0 {
                    let z = depth40_to_30(self.depth_at(x, dy)).clamp(0, DEPTH30_FAR) as Depth30;
                    pixel(self.x0 + x, y, z, self.varyings_at(e).0);
                }
                // Within the box every edge function fits i32 (see the module's numbers); the
                // step after the last column is not used (wrapping: it may leave the box).
                e = core::array::from_fn(|k| e[k].wrapping_add(steps[k]));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Corner, CoveredBox, ScreenVertex, Span, SpanSink, Window};
    use super::*;
    use std::vec::Vec;

    /// Collects the pixels of the runs a sink is handed: frame column and row, depth.
    struct Pixels(Vec<(i32, i32, Depth30)>);

    impl SpanSink<3> for Pixels {
        fn span(&mut self, s: &Span<3>) {
            for k in 0..s.len as i32 {
                self.0.push((s.x + k, s.y, (s.z as i32 + s.dz * k) as Depth30));
            }
        }
    }

    /// Small triangles drawn pixel by pixel cover exactly the pixels the rows cover, with the
    /// same depths, in every band, and their varyings are the exact ones; the choice is the same
    /// in every band (a small LCG: reproducible without a dependency).
    #[test]
    fn pixels_of_small_triangles_are_the_rows_pixels() {
        let mut rng = crate::test_rng::Lcg(0x5a11_b0c5);
        let mut next = |n: u32| (rng.next() >> 1) % n;
        let (mut small, mut pixels) = (0, 0);
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
            let whole = Window { width: 400, row_start: 0, row_end: 400 };
            let (row_start, rows) = (at / 16 + next(size + 2) as i32 - 1, 1 + next(4) as i32);
            let band = Window { width: 400, row_start, row_end: row_start + rows };
            for (window, fpu) in [(whole, false), (band, false), (whole, true), (band, true)] {
                let Ok(mut setup) = Setup::<3>::new(&tri, &window, false, false) else { continue };
                if fpu {
                    setup.use_fpu_perspective();
                }
                // The same choice as the whole frame's.
                let corners = tri.each_ref().map(Corner::<3>::of);
                let box_pixels = |window: &Window| CoveredBox::of(&corners, window).map(|b| b.frame_pixels());
                assert_eq!(box_pixels(&window), box_pixels(&whole), "{tri:?} in {window:?}");
                if box_pixels(&window).is_none_or(|p| p > SMALL_BOX) {
                    continue;
                }
                small += 1;
                let mut rows = Pixels(Vec::new());
                setup.for_each_span(1, &mut rows);
                let mut each = Vec::new();
                setup.for_each_pixel(|x, y, z, v| {
                    let (dx, dy) = (x - setup.x0, y - setup.origin_row);
                    let e = core::array::from_fn(|k| {
                        let edge = &setup.edges[k];
                        edge.c + edge.b * 16 * dy + edge.a * 16 * dx
                    });
                    assert_eq!(v, setup.varyings_at(e).0, "{tri:?} at ({x}, {y})");
                    each.push((x, y, z));
                });
                assert_eq!(each, rows.0, "{tri:?} in {window:?}");
                pixels += each.len();
            }
        }
        assert!(small > 5000 && pixels > 5000, "{small} small triangles, {pixels} pixels");
    }
}
