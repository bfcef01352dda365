//! Wireframe edges and points: Bresenham lines between snapped vertices and single pixels,
//! depth-tested like fills. It does not fill triangles (`fragment` does).

use super::raster::ScreenVertex;
use super::Stats;
use crate::fixed::depth30_from_unit;
use crate::target::{Band, DepthBuffer, FrameColor};

/// Writes one pixel at integer pixel `(x, y)` if it is in the band and passes depth.
fn put<C: FrameColor, D: DepthBuffer>(band: &mut Band<'_, C, D>, x: i32, y: i32, z: u32, c: C, stats: &mut Stats) {
    let Some(i) = band.area().run_start(x, y, 1) else {
        return;
    };
    if !band.depth.passes(i, z) {
        stats.depth_rejected += 1;
        return;
    }
    if let Some(px) = band.color.get_mut(i) {
        *px = c;
        band.depth.store(i, z);
        stats.pixels_written += 1;
    }
}

pub(crate) fn plot<C: FrameColor, D: DepthBuffer>(
    band: &mut Band<'_, C, D>,
    p: &ScreenVertex,
    c: C,
    stats: &mut Stats,
) {
    put(band, p.x >> 4, p.y >> 4, depth30_from_unit(p.z), c, stats);
}

/// Bresenham line between pixel centres, endpoints in canonical order so that an edge shared
/// by two triangles lights the same pixels, walked whole in every band so bands agree.
pub(crate) fn line<C: FrameColor, D: DepthBuffer>(
    band: &mut Band<'_, C, D>,
    a: &ScreenVertex,
    b: &ScreenVertex,
    c: C,
    stats: &mut Stats,
) {
    let (a, b) = if (a.x, a.y) <= (b.x, b.y) { (a, b) } else { (b, a) };
    let (x0, y0, x1, y1) = (a.x >> 4, a.y >> 4, b.x >> 4, b.y >> 4);
    let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
    let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
    let steps = dx.max(-dy).max(1) as f32;
    let (mut x, mut y, mut err) = (x0, y0, dx + dy);
    let mut k = 0.0;
    loop {
        let z = a.z + (b.z - a.z) * (k / steps);
        put(band, x, y, depth30_from_unit(z), c, stats);
        if x == x1 && y == y1 {
            break;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
        k += 1.0;
    }
}
