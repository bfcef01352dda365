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
        stats.depth_rejected = stats.depth_rejected.saturating_add(1);
        return;
    }
    if let Some(px) = band.color.get_mut(i) {
        *px = c;
        band.depth.store(i, z);
        stats.pixels_written = stats.pixels_written.saturating_add(1);
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
/// by two triangles lights the same pixels in every band. Only the steps that land in the band
/// are walked, each found from its step number in closed form ([`Bresenham::at`]), so the work
/// is at most the band's width or rows, however far off screen the ends are.
pub(crate) fn line<C: FrameColor, D: DepthBuffer>(
    band: &mut Band<'_, C, D>,
    a: &ScreenVertex,
    b: &ScreenVertex,
    c: C,
    stats: &mut Stats,
) {
    let (a, b) = if (a.x, a.y) <= (b.x, b.y) { (a, b) } else { (b, a) };
    let walk = Bresenham::new((a.x >> 4, a.y >> 4), (b.x >> 4, b.y >> 4));
    let columns = (0, i64::from(band.width) - 1);
    let rows = (i64::from(band.first_row), i64::from(band.first_row) + i64::from(band.rows) - 1);
    let Some((first, last)) = walk.steps_within(columns, rows) else {
        return;
    };
    let steps = walk.steps.max(1) as f32;
    for k in first..=last {
        let (x, y) = walk.at(k);
        // `k as f32` is the step count the original loop accumulated in f32 (exact below 2^24).
        let z = a.z + (b.z - a.z) * (k as f32 / steps);
        // Inside the band by construction: both fit in i32.
        put(band, x as i32, y as i32, depth30_from_unit(z), c, stats);
        stats.line_steps = stats.line_steps.saturating_add(1);
    }
}

/// The pixels of a Bresenham line from `(x0, y0)` to `(x1, y1)` (the all-octant form: each step
/// moves along the major axis, and along the minor one when the error term says so), by step
/// number. Coordinates are whole pixels of 28.4 values (at most 2^27 in magnitude), so every
/// product below fits in i64.
#[derive(Clone, Copy, Debug)]
struct Bresenham {
    start: (i64, i64),
    sign: (i64, i64),
    /// `|x1 - x0|` and `|y1 - y0|`.
    delta: (i64, i64),
    /// Steps after the first pixel: `max(delta)`.
    steps: i64,
}

impl Bresenham {
    fn new((x0, y0): (i32, i32), (x1, y1): (i32, i32)) -> Self {
        let (x0, y0, x1, y1) = (i64::from(x0), i64::from(y0), i64::from(x1), i64::from(y1));
        let delta = ((x1 - x0).abs(), (y1 - y0).abs());
        let sign = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        Bresenham { start: (x0, y0), sign, delta, steps: delta.0.max(delta.1) }
    }

    /// The pixel after `k` steps (`0..=steps`). Along the major axis every step moves; the
    /// error term `err = dx - dy` (updated `-dy` per major and `+dx` per minor step, with the
    /// minor step taken when `2·err <= dx`) makes the minor coordinate move
    /// `floor((2·minor·k + major) / (2·major))` times in `k` steps (checked against the loop in
    /// the tests).
    fn at(&self, k: i64) -> (i64, i64) {
        let ((dx, dy), (sx, sy)) = (self.delta, self.sign);
        let moved = |minor: i64, major: i64| if major == 0 { 0 } else { (2 * minor * k + major) / (2 * major) };
        if dx >= dy {
            (self.start.0 + sx * k, self.start.1 + sy * moved(dy, dx))
        } else {
            (self.start.0 + sx * moved(dx, dy), self.start.1 + sy * k)
        }
    }

    /// The steps whose pixels lie in columns `x_range` and rows `y_range` (both inclusive):
    /// an interval, as both coordinates move monotonically.
    fn steps_within(&self, x_range: (i64, i64), y_range: (i64, i64)) -> Option<(i64, i64)> {
        let (xs, xe) = self.monotone_within(|k| self.sign.0 * self.at(k).0, x_range, self.sign.0)?;
        let (ys, ye) = self.monotone_within(|k| self.sign.1 * self.at(k).1, y_range, self.sign.1)?;
        let (first, last) = (xs.max(ys), xe.min(ye));
        (first <= last).then_some((first, last))
    }

    /// The steps where `g(k) = sign · coordinate` (non-decreasing in `k`) lies in `sign · range`,
    /// by two binary searches over `0..=steps`.
    fn monotone_within(&self, g: impl Fn(i64) -> i64, (lo, hi): (i64, i64), sign: i64) -> Option<(i64, i64)> {
        let (lo, hi) = if sign > 0 { (lo, hi) } else { (-hi, -lo) };
        let first_reaching = |t: i64| {
            let (mut a, mut b) = (0, self.steps + 1);
            while a < b {
                let m = a + (b - a) / 2;
                if g(m) >= t {
                    b = m;
                } else {
                    a = m + 1;
                }
            }
            a
        };
        let (first, last) = (first_reaching(lo), first_reaching(hi + 1) - 1);
        (first <= last).then_some((first, last))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The loop the closed form replaces, step by step.
    fn walked((x0, y0): (i32, i32), (x1, y1): (i32, i32)) -> std::vec::Vec<(i64, i64)> {
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let (mut x, mut y, mut err) = (x0, y0, dx + dy);
        let mut out = std::vec![];
        loop {
            out.push((x as i64, y as i64));
            if x == x1 && y == y1 {
                return out;
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
        }
    }

    #[test]
    fn closed_form_equals_the_loop_and_clipping_keeps_exactly_the_visible_steps() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: i32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % (2 * n as u64 + 1)) as i32 - n
        };
        for case in 0..20_000 {
            let n = if case % 2 == 0 { 12 } else { 300 };
            let (a, b) = ((next(n), next(n)), (next(n), next(n)));
            let (a, b) = if a <= b { (a, b) } else { (b, a) };
            let w = Bresenham::new(a, b);
            let pixels = walked(a, b);
            assert_eq!(pixels.len() as i64, w.steps + 1, "{a:?} {b:?}");
            for (k, p) in pixels.iter().enumerate() {
                assert_eq!(w.at(k as i64), *p, "{a:?} {b:?} step {k}");
            }
            let (xr, yr) = ((next(n) as i64, next(n) as i64), (next(n) as i64, next(n) as i64));
            let (xr, yr) = ((xr.0.min(xr.1), xr.0.max(xr.1)), (yr.0.min(yr.1), yr.0.max(yr.1)));
            let inside = |p: &(i64, i64)| (xr.0..=xr.1).contains(&p.0) && (yr.0..=yr.1).contains(&p.1);
            let want: std::vec::Vec<i64> = (0..pixels.len() as i64).filter(|&k| inside(&pixels[k as usize])).collect();
            match w.steps_within(xr, yr) {
                Some((f, l)) => assert_eq!((f..=l).collect::<std::vec::Vec<_>>(), want, "{a:?} {b:?} {xr:?} {yr:?}"),
                None => assert!(want.is_empty(), "{a:?} {b:?} {xr:?} {yr:?}"),
            }
        }
    }

    /// A line between saturated ends (what clipping leaves of a vertex at an infinite or huge
    /// x/w) is walked only where it crosses the band.
    #[test]
    fn lines_between_saturated_ends_walk_only_the_band() {
        use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
        let v = |x: i32, y: i32| ScreenVertex { x, y, z: 0.5, inv_w: 1.0, varyings: [0; 8] };
        let (mut color, mut depth) = ([Rgb565::BLACK; 240 * 30], [0u16; 240 * 30]);
        let mut band = Band::new(&mut color[..], &mut depth[..], 240, 240, 90).unwrap();
        band.clear(Rgb565::BLACK);
        let mut stats = Stats::default();
        for (a, b) in [
            (v(i32::MIN, i32::MIN), v(i32::MAX, i32::MAX)),
            (v(i32::MIN, 100 * 16), v(i32::MAX, 101 * 16)),
            (v(5, i32::MIN), v(7, i32::MAX)),
            (v(i32::MAX, i32::MIN), v(i32::MIN, i32::MAX)),
        ] {
            let before = stats.line_steps;
            line(&mut band, &a, &b, Rgb565::WHITE, &mut stats);
            assert!(stats.line_steps - before <= 240 + 30, "{a:?} {b:?}: {}", stats.line_steps - before);
        }
        assert!(stats.pixels_written > 0);
    }

    #[test]
    fn far_ends_cost_nothing_outside_the_window() {
        let w = Bresenham::new((i32::MIN >> 4, 10), (i32::MAX >> 4, 20));
        let (f, l) = w.steps_within((0, 239), (0, 29)).unwrap();
        assert!(l - f < 240, "{f}..={l}");
    }
}
