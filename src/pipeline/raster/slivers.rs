//! Tests: the depth of slivers and needles (triangles far thinner than long), whose depth
//! planes are ill-conditioned: every covered pixel's depth, as the span loop steps it, within
//! 0..=2^30 and close to the exact plane through the vertices, in both set-ups (f32 and
//! integer), and the per-pixel perspective bound refusing what it cannot bound.

use super::{facing, Corner, ScreenVertex, Setup, Span, SpanSink, WalkedRow, Window};
use crate::test_rng::Lcg;
use std::vec::Vec;

/// Collects the runs a sink is handed.
struct Collect(Vec<Span<3>>);

impl SpanSink<3> for Collect {
    fn span(&mut self, span: &Span<3>) {
        self.0.push(*span);
    }
}

/// A screen vertex at `(x, y)` (28.4) with depth `z`, `1/w` 1 and varyings `v` (u, v, light).
fn vertex((x, y, z): (i32, i32, f32), v: [i32; 3]) -> ScreenVertex {
    let mut varyings = [0; 8];
    varyings[..3].copy_from_slice(&v);
    ScreenVertex { x, y, z, inv_w: 1.0, varyings }
}

/// The set-up of `tri` in a `width` x `height` frame, f32 (`fpu`) or integer.
fn setup(tri: &[ScreenVertex; 3], (width, height): (i32, i32), fpu: bool) -> Option<Setup<3>> {
    let area = facing(tri, false, false).ok()?;
    let window = Window { width, row_start: 0, row_end: height };
    Setup::with_area(&tri.each_ref().map(Corner::of), &window, area, fpu).ok()
}

/// Every covered pixel's frame column, row and depth (2.30) as the span loop steps it (in
/// i64: a value that left 0..=2^30 shows), from walked rows where the set-up has them, else
/// from `for_each_span`.
fn pixel_depths(setup: &Setup<3>, z: [f32; 3]) -> Vec<(i32, i32, i64)> {
    let mut out = Collect(Vec::new());
    match setup.walked_rows(1, z) {
        Some(mut rows) => {
            let dz = rows.dz;
            while let Some(row) = rows.next_row() {
                match row {
                    WalkedRow::Run(y, x, len, z, v, dv) => out.0.push(Span { y, x, len, z, dz, v, dv }),
                    WalkedRow::Cut(y, dy, lo, hi) => rows.cut_row(&mut out, (y, dy, lo, hi)),
                    WalkedRow::Empty => {}
                }
            }
        }
        None => setup.for_each_span(1, &mut out),
    }
    let stepped = |s: &Span<3>, k: i32| i64::from(s.z) + i64::from(s.dz) * i64::from(k);
    out.0.iter().flat_map(|s| (0..s.len as i32).map(move |k| (s.x + k, s.y, stepped(s, k)))).collect()
}

/// The exact depth (2.30) at the centre of pixel `(x, y)` of the plane through `tri`.
fn exact_depth(tri: &[ScreenVertex; 3], (x, y): (i32, i32)) -> f64 {
    let [a, b, c] = tri.map(|v| (f64::from(v.x), f64::from(v.y), f64::from(v.z)));
    let (px, py) = (f64::from(x * 16 + 8), f64::from(y * 16 + 8));
    let det = (b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1);
    let wb = ((px - a.0) * (c.1 - a.1) - (c.0 - a.0) * (py - a.1)) / det;
    let wc = ((b.0 - a.0) * (py - a.1) - (px - a.0) * (b.1 - a.1)) / det;
    (a.2 + wb * (b.2 - a.2) + wc * (c.2 - a.2)) * f64::from(1u32 << 30)
}

/// Checks every covered pixel of `tri` in both set-ups: within 0..=2^30 and within 2^-20 of
/// the exact depth. The number of pixels checked.
fn check_depths(tri: &[ScreenVertex; 3], frame: (i32, i32), what: &str) -> usize {
    let mut checked = 0;
    for fpu in [true, false] {
        let Some(s) = setup(tri, frame, fpu) else { continue };
        for (x, y, z) in pixel_depths(&s, tri.each_ref().map(|v| v.z)) {
            let exact = exact_depth(tri, (x, y));
            assert!((0..=1 << 30).contains(&z), "{what} (fpu {fpu}) at ({x}, {y}): depth {z} (exact {exact})");
            let error = (z as f64 - exact).abs();
            assert!(error <= 1024.0, "{what} (fpu {fpu}) at ({x}, {y}): depth {z}, exact {exact}");
            checked += 1;
        }
    }
    checked
}

/// A sliver on screen in a 1536 x 1536 frame (twice its area 48/256 pixel²) whose f32 depth
/// gradient came out twice the exact one (the products of its numerator cancel): the walked
/// rows, trusting the plane, stepped to -0.071 where the exact depth is 0.331 (debug: the u16
/// depth's assertion; release: drawn over everything). And one through the guard band of a
/// 320 x 240 frame that stepped past 2^30.
#[test]
fn f32_depth_planes_of_slivers_are_accurate() {
    let sliver = [(744, 21720, 0.992_196_7), (23544, 3192, 0.001_078_63), (16435, 8969, 0.310_107_56)];
    let tri = sliver.map(|p| vertex(p, [0; 3]));
    assert!(check_depths(&tri, (1536, 1536), "1536 x 1536 sliver") > 0);
    let guard = [(11784, -7176, 0.00889), (3016, 3000, 0.99276), (2985, 3036, 0.99624)];
    let tri = guard.map(|p| vertex(p, [0; 3]));
    assert!(check_depths(&tri, (320, 240), "guard-band sliver") > 0);
}

/// A needle in a 320 x 480 frame whose integer depth plane, taken to its box's origin far from
/// it, wrapped an i64 product before dividing by 16: the origin was off by a multiple of 2^60
/// and the one pixel it covers, (35, 304), clamped to the far plane instead of 0.218 (no
/// panic, a wrong picture).
#[test]
fn integer_depth_planes_of_needles_are_accurate() {
    let needle = [(-12680, 13560, 0.150), (4984, 1976, 0.241), (-10963, 12434, 0.837)];
    let tri = needle.map(|p| vertex(p, [0; 3]));
    assert!(check_depths(&tri, (320, 480), "needle") > 0);
}

/// Random slivers across a 1536 x 1536 frame (long, a fraction of a pixel to a few pixels
/// wide, depths 0.01..0.99): every covered pixel in range and within 2^-20 of the exact depth,
/// f32 and integer set-ups.
#[test]
fn random_slivers_have_accurate_depths() {
    let mut rng = Lcg(0x5bd1_e995_1b87_3593);
    let mut checked = 0;
    for t in 0..3000 {
        let at = |rng: &mut Lcg| rng.below(1536 * 16) as i32;
        let (ax, ay, bx, by) = (at(&mut rng), at(&mut rng), at(&mut rng), at(&mut rng));
        // The third vertex a fraction along the edge, moved off it by 1/16 to 64/16 pixel.
        let f = rng.unit();
        let (nx, ny) = (-(by - ay) as f64, (bx - ax) as f64);
        let offset = (1 + rng.below(64)) as f64 / (nx * nx + ny * ny).sqrt().max(1.0);
        let cx = (ax as f64 + f * (bx - ax) as f64 + nx * offset) as i32;
        let cy = (ay as f64 + f * (by - ay) as f64 + ny * offset) as i32;
        let depth = |rng: &mut Lcg| (0.01 + 0.98 * rng.unit()) as f32;
        let tri = [(ax, ay), (bx, by), (cx, cy)].map(|(x, y)| vertex((x, y, depth(&mut rng)), [0; 3]));
        checked += check_depths(&tri, (1536, 1536), &std::format!("sliver {t} {tri:?}"));
    }
    assert!(checked > 10_000, "{checked} pixels checked");
}

/// A sliver whose box spans a 1536 x 1536 frame with the edge functions' sum `C` = 1: the
/// per-pixel perspective bound's three terms passed 2^32 (debug: an overflow panic; release:
/// a wrapped, small bound that let the sliver's varyings go unbounded). It is refused.
#[test]
fn the_perspective_bound_refuses_what_it_cannot_bound() {
    let corners = [(-54, 26356, 0.5), (23148, 1760, 0.5), (27592, -2951, 0.5)];
    let tri =
        [vertex(corners[0], [0, 0, 0]), vertex(corners[1], [1 << 20, 0, 1 << 15]), vertex(corners[2], [0, 1 << 20, 0])];
    let mut tri = tri;
    tri[1].inv_w = 0.5;
    let mut s = setup(&tri, (1536, 1536), true).expect("covers pixels");
    s.allow_affine([1 << 12, 1 << 12, 1 << 8]);
    assert!(!s.is_affine());
    assert!(s.pixel_rows([0.5; 3], &[1 << 12, 1 << 12, 1 << 8], 0).is_none());
}
