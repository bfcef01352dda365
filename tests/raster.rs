//! Rasterizer tests.
//!
//! Everything here is checked against code written in this file from the spec
//! (`spec/babylon-conventions.md`), not against `src/raster.rs`:
//! - a slow reference rasterizer (`i64` edge functions per pixel centre, 28.4 input) with the
//!   tie rule taken from the spec's wording ("a centre exactly on an edge belongs to the
//!   triangle for which that edge is a *left* edge, or a *bottom* horizontal edge, as seen in
//!   the picture");
//! - watertightness of fans and jittered quad grids;
//! - bit-identical results whatever the band split;
//! - perspective-correct varyings against an `f64` evaluation;
//! - the near plane through the whole pipeline (feature `convert`);
//! - robustness against hostile numbers (proptest);
//! - hand-checked ASCII pictures.
//!
//! All randomness comes from a seeded SplitMix64 (or proptest's deterministic runner), so every
//! run tests the same cases.

use soft3d::testing::math::Vec4;
use soft3d::testing::{clip_triangle, ClipResult, ClipVertex, GuardBand, Polygon};
use soft3d::testing::{step_varyings, Reject, ScreenVertex, Setup, Span, SpanSink, Window, MAX_VARYINGS, VARYING_FRAC};

/// Every covered pixel of a [`Setup`], one at a time: the spans it hands out, stepped here as the
/// library's span loop steps them (tests only: the library has one span loop, the shader's).
trait Pixels<const V: usize> {
    fn for_each_pixel(&self, subspan: u32, pixel: impl FnMut(i32, i32, u32, &[i32; V]));
}

impl<const V: usize> Pixels<V> for Setup<V> {
    fn for_each_pixel(&self, subspan: u32, pixel: impl FnMut(i32, i32, u32, &[i32; V])) {
        struct Each<F>(F);
        impl<F: FnMut(i32, i32, u32, &[i32; V]), const V: usize> SpanSink<V> for Each<F> {
            fn span(&mut self, s: &Span<V>) {
                let (mut z, mut v) = (s.z, s.v);
                for x in s.x..s.x + s.len as i32 {
                    (self.0)(x, s.y, z, &v);
                    z = z.wrapping_add_signed(s.dz);
                    step_varyings(&mut v, &s.dv);
                }
            }
        }
        self.for_each_span(subspan, &mut Each(pixel));
    }
}
use soft3d::{Band, NoDepth, TargetError, GUARD_HALF_EXTENT};

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, GrayColor, Rgb565};
use proptest::prelude::*;
use proptest::test_runner::{RngSeed, TestCaseError};

// ---------------------------------------------------------------------------------------------
// Deterministic randomness
// ---------------------------------------------------------------------------------------------

mod common;
use common::Rng;

// ---------------------------------------------------------------------------------------------
// The reference rasterizer
// ---------------------------------------------------------------------------------------------

/// A point in 28.4 fixed point (1/16 pixel), image coordinates (y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Pt {
    x: i64,
    y: i64,
}

fn pt(x: i64, y: i64) -> Pt {
    Pt { x, y }
}

/// Twice the signed area of `a b p` (image coordinates).
fn orient(a: Pt, b: Pt, p: Pt) -> i64 {
    (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)
}

/// Whether a pixel centre exactly on edge `p q` of triangle `p q r` belongs to that triangle.
///
/// Spec: it does when the edge is a *left* edge (the triangle lies to the right of it in the
/// picture) or a *bottom* horizontal edge (the triangle lies above it in the picture, i.e. at
/// smaller image y).
fn edge_owned(p: Pt, q: Pt, r: Pt) -> bool {
    if p.y == q.y {
        r.y < p.y
    } else {
        // The edge's line at the third vertex's height is at
        //   x_line = p.x + (q.x - p.x)(r.y - p.y)/(q.y - p.y);
        // the triangle is to the right of the edge when r.x > x_line, i.e. when
        //   ((r.x - p.x)(q.y - p.y) - (q.x - p.x)(r.y - p.y)) / (q.y - p.y) > 0.
        let num = (r.x - p.x) * (q.y - p.y) - (q.x - p.x) * (r.y - p.y);
        (num > 0) == (q.y > p.y)
    }
}

/// Whether point `c` (28.4) is covered by triangle `t` (either winding) under the spec's rules.
fn ref_covers(t: &[Pt; 3], c: Pt) -> bool {
    let area = orient(t[0], t[1], t[2]);
    if area == 0 {
        return false;
    }
    (0..3).all(|i| {
        let (p, q, r) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
        // Inside is the side where the third vertex is.
        let e = orient(p, q, c) * area.signum();
        e > 0 || (e == 0 && edge_owned(p, q, r))
    })
}

/// Centre of pixel (column, row) in 28.4.
fn centre(c: i64, r: i64) -> Pt {
    pt(16 * c + 8, 16 * r + 8)
}

/// Every pixel of `win` whose centre `t` covers, row by row, left to right.
fn ref_pixels(t: &[Pt; 3], win: &Window) -> Vec<(i32, i32)> {
    let minx = t.iter().map(|p| p.x).min().unwrap();
    let maxx = t.iter().map(|p| p.x).max().unwrap();
    let miny = t.iter().map(|p| p.y).min().unwrap();
    let maxy = t.iter().map(|p| p.y).max().unwrap();
    // A generous candidate box; the edge tests decide.
    let c0 = (minx.div_euclid(16) - 1).max(0);
    let c1 = (maxx.div_euclid(16) + 1).min(win.width as i64 - 1);
    let r0 = (miny.div_euclid(16) - 1).max(win.row_start as i64);
    let r1 = (maxy.div_euclid(16) + 1).min(win.row_end as i64 - 1);
    let mut out = Vec::new();
    for r in r0..=r1 {
        for c in c0..=c1 {
            if ref_covers(t, centre(c, r)) {
                out.push((c as i32, r as i32));
            }
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Driving the fast rasterizer
// ---------------------------------------------------------------------------------------------

fn sv(p: Pt) -> ScreenVertex {
    ScreenVertex { x: p.x as i32, y: p.y as i32, z: 0.5, inv_w: 1.0, varyings: [0; MAX_VARYINGS] }
}

fn svs(t: &[Pt; 3]) -> [ScreenVertex; 3] {
    t.map(sv)
}

/// Pixels visited by `Setup::for_each_pixel`, in visiting order.
fn fast_pixels(tri: &[ScreenVertex; 3], win: &Window, subspan: u32) -> Vec<(i32, i32)> {
    let mut out = Vec::new();
    if let Ok(s) = Setup::<2>::new(tri, win, false, false) {
        s.for_each_pixel(subspan, |x, y, _, _| out.push((x, y)));
    }
    out
}

/// One visited pixel with everything the rasterizer computed for it.
type Frag<const V: usize> = (i32, i32, u32, [i32; V]);

fn fast_frags<const V: usize>(tri: &[ScreenVertex; 3], win: &Window, subspan: u32) -> Vec<Frag<V>> {
    let mut out = Vec::new();
    if let Ok(s) = Setup::<V>::new(tri, win, false, false) {
        s.for_each_pixel(subspan, |x, y, z, v| out.push((x, y, z, *v)));
    }
    out
}

fn full_window(w: i32, h: i32) -> Window {
    Window { width: w, row_start: 0, row_end: h }
}

// ---------------------------------------------------------------------------------------------
// Random triangles
// ---------------------------------------------------------------------------------------------

/// A frame size in pixels.
#[derive(Clone, Copy, Debug)]
struct Frame {
    w: i32,
    h: i32,
}

impl Frame {
    /// Guard band in 28.4: ±960 px around the frame centre (what the pipeline clips to).
    fn guard(&self) -> (i64, i64, i64, i64) {
        let g = (GUARD_HALF_EXTENT as i64) * 16;
        let (cx, cy) = (self.w as i64 * 8, self.h as i64 * 8);
        (cx - g, cx + g, cy - g, cy + g)
    }
    fn clamp(&self, p: Pt) -> Pt {
        let (x0, x1, y0, y1) = self.guard();
        pt(p.x.clamp(x0, x1), p.y.clamp(y0, y1))
    }
    /// A point in or near the frame (28.4).
    fn near_point(&self, rng: &mut Rng, margin_px: i64) -> Pt {
        let m = margin_px * 16;
        pt(rng.range(-m, self.w as i64 * 16 + m), rng.range(-m, self.h as i64 * 16 + m))
    }
    /// A pixel centre in or near the frame (28.4).
    fn near_centre(&self, rng: &mut Rng, margin_px: i64) -> Pt {
        centre(rng.range(-margin_px, self.w as i64 + margin_px), rng.range(-margin_px, self.h as i64 + margin_px))
    }
}

/// A random triangle of one of several families (both windings), inside the guard band.
fn random_triangle(rng: &mut Rng, f: &Frame) -> [Pt; 3] {
    let (gx0, gx1, gy0, gy1) = f.guard();
    let off = |rng: &mut Rng, p: Pt, r: i64| pt(p.x + rng.range(-r, r), p.y + rng.range(-r, r));
    let t = match rng.range(0, 9) {
        // Anywhere in the guard band: often larger than the window.
        0 => [0; 3].map(|_| pt(rng.range(gx0, gx1), rng.range(gy0, gy1))),
        // Medium, near the window.
        1 => {
            let c = f.near_point(rng, 20);
            [0; 3].map(|_| off(rng, c, 16 * 60))
        }
        // Small (a few pixels).
        2 => {
            let c = f.near_point(rng, 4);
            [0; 3].map(|_| off(rng, c, 16 * 4))
        }
        // Sub-pixel.
        3 => {
            let c = f.near_point(rng, 2);
            [0; 3].map(|_| off(rng, c, 12))
        }
        // Sliver: a long edge and a third vertex a few 1/16 pixel off it.
        4 => {
            let a = if rng.chance(0.5) { f.near_point(rng, 10) } else { pt(rng.range(gx0, gx1), rng.range(gy0, gy1)) };
            let b = f.near_point(rng, 10);
            let s = rng.unit();
            let m = pt(a.x + ((b.x - a.x) as f64 * s) as i64, a.y + ((b.y - a.y) as f64 * s) as i64);
            [a, b, off(rng, m, 3)]
        }
        // Every vertex exactly on a pixel centre: many centres lie exactly on edges.
        5 => {
            let c = f.near_centre(rng, 4);
            let r = [1, 3, 8, 40][rng.range(0, 3) as usize];
            [0; 3].map(|_| pt(c.x + 16 * rng.range(-r, r), c.y + 16 * rng.range(-r, r)))
        }
        // Axis-aligned right triangle (horizontal and vertical edges), often on centres.
        6 => {
            let on = rng.chance(0.6);
            let a = if on { f.near_centre(rng, 3) } else { f.near_point(rng, 3) };
            let r = [2, 8, 64][rng.range(0, 2) as usize];
            let (dx, dy) = if on {
                (16 * rng.range(-r, r), 16 * rng.range(-r, r))
            } else {
                (rng.range(-16 * r, 16 * r), rng.range(-16 * r, 16 * r))
            };
            [a, pt(a.x + dx, a.y), pt(a.x, a.y + dy)]
        }
        // Vertices on the half-pixel lattice (centres and corners).
        7 => {
            let c = f.near_centre(rng, 4);
            [0; 3].map(|_| pt(c.x + 8 * rng.range(-30, 30), c.y + 8 * rng.range(-30, 30)))
        }
        // Edges with small integer slopes through centres (1:1, 1:2, 2:1 ...).
        8 => {
            let a = f.near_centre(rng, 2);
            let k = rng.range(1, 12);
            let dirs = [(1, 1), (1, -1), (2, 1), (1, 2), (-2, 1), (3, 1), (1, 0), (0, 1)];
            let (ux, uy) = dirs[rng.range(0, 7) as usize];
            let (vx, vy) = dirs[rng.range(0, 7) as usize];
            let j = rng.range(1, 12);
            [a, pt(a.x + 16 * k * ux, a.y + 16 * k * uy), pt(a.x - 16 * j * vy, a.y + 16 * j * vx)]
        }
        // Very large and thin: two far-apart guard-band points and a third nearby one.
        _ => {
            let a = pt(rng.range(gx0, gx1), rng.range(gy0, gy1));
            let b = pt(rng.range(gx0, gx1), rng.range(gy0, gy1));
            [a, b, off(rng, b, 40)]
        }
    };
    let t = t.map(|p| f.clamp(p));
    if rng.chance(0.5) {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// A fan of triangles around a centre (a closed star-shaped polygon), both windings mixed.
/// Returns the triangles and the outer boundary, or `None` when snapping broke it.
fn random_fan(rng: &mut Rng, f: &Frame) -> Option<(Vec<[Pt; 3]>, Vec<Pt>)> {
    let c = if rng.chance(0.5) { f.near_centre(rng, 0) } else { f.near_point(rng, 0) };
    let n = rng.range(5, 14) as usize;
    let phase = rng.unit() * std::f64::consts::TAU;
    let on_centres = rng.chance(0.4);
    let rmax = [3.0, 12.0, 40.0][rng.range(0, 2) as usize];
    let ring: Vec<Pt> = (0..n)
        .map(|k| {
            let spacing = std::f64::consts::TAU / n as f64;
            let a = phase + spacing * (k as f64 + (rng.unit() - 0.5) * 0.8);
            let r = (0.3 + rng.unit() * 0.7) * rmax * 16.0;
            let p = pt(c.x + (r * a.cos()) as i64, c.y + (r * a.sin()) as i64);
            if on_centres {
                pt(p.x.div_euclid(16) * 16 + 8, p.y.div_euclid(16) * 16 + 8)
            } else {
                p
            }
        })
        .collect();
    let tris: Vec<[Pt; 3]> = (0..n).map(|k| [c, ring[k], ring[(k + 1) % n]]).collect();
    // All triangles must turn the same way (no fold-over, no degenerate piece).
    let s0 = orient(tris[0][0], tris[0][1], tris[0][2]).signum();
    if s0 == 0 || tris.iter().any(|t| orient(t[0], t[1], t[2]).signum() != s0) {
        return None;
    }
    let tris =
        tris.into_iter().map(|t| if rng.chance(0.5) { [t[1], t[2], t[0]] } else { [t[0], t[2], t[1]] }).collect();
    Some((tris, ring))
}

/// A jittered grid of quads, each split along a random diagonal, both windings mixed. Returns
/// the triangles and the outer boundary, or `None` when a triangle is degenerate (fold-overs
/// are rejected by the caller).
fn random_grid(rng: &mut Rng, f: &Frame) -> Option<(Vec<[Pt; 3]>, Vec<Pt>)> {
    let (nx, ny) = (rng.range(1, 6) as usize, rng.range(1, 5) as usize);
    let cell = rng.range(2, 14) * 16;
    let jitter = cell / 4 - 1;
    let origin = f.near_point(rng, 8);
    let on_centres = rng.chance(0.3);
    let mut v = vec![vec![pt(0, 0); nx + 1]; ny + 1];
    for (j, row) in v.iter_mut().enumerate() {
        for (i, p) in row.iter_mut().enumerate() {
            let q = pt(
                origin.x + i as i64 * cell + rng.range(-jitter, jitter),
                origin.y + j as i64 * cell + rng.range(-jitter, jitter),
            );
            *p = if on_centres { pt(q.x.div_euclid(16) * 16 + 8, q.y.div_euclid(16) * 16 + 8) } else { q };
        }
    }
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (v[j][i], v[j][i + 1], v[j + 1][i + 1], v[j + 1][i]);
            let pair = if rng.chance(0.5) { [[a, b, c], [a, c, d]] } else { [[a, b, d], [b, c, d]] };
            for t in pair {
                tris.push(if rng.chance(0.5) { t } else { [t[0], t[2], t[1]] });
            }
        }
    }
    if tris.iter().any(|t| orient(t[0], t[1], t[2]) == 0) {
        return None;
    }
    let mut boundary = Vec::new();
    boundary.extend((0..nx).map(|i| v[0][i]));
    boundary.extend((0..ny).map(|j| v[j][nx]));
    boundary.extend((0..nx).map(|i| v[ny][nx - i]));
    boundary.extend((0..ny).map(|j| v[ny - j][0]));
    Some((tris, boundary))
}

// ---------------------------------------------------------------------------------------------
// 1. Fast rasterizer == reference, in every window
// ---------------------------------------------------------------------------------------------

/// Windows over a frame: full, single rows, 7-row and random bands, and an empty one.
fn windows(rng: &mut Rng, f: &Frame) -> Vec<Window> {
    let mut w = vec![full_window(f.w, f.h)];
    let r = rng.range(0, f.h as i64 - 1) as i32;
    w.push(Window { width: f.w, row_start: r, row_end: r + 1 });
    w.push(Window { width: f.w, row_start: 0, row_end: 1 });
    w.push(Window { width: f.w, row_start: f.h - 1, row_end: f.h });
    let s = rng.range(0, f.h as i64 - 1) as i32;
    w.push(Window { width: f.w, row_start: s, row_end: (s + 7).min(f.h) });
    let a = rng.range(0, f.h as i64) as i32;
    let b = rng.range(0, f.h as i64) as i32;
    w.push(Window { width: f.w, row_start: a.min(b), row_end: a.max(b) });
    w
}

fn check_against_reference(t: &[Pt; 3], win: &Window, what: &str) -> usize {
    let tri = svs(t);
    let got = fast_pixels(&tri, win, 1);
    for &(x, y) in &got {
        assert!(
            x >= 0 && x < win.width && y >= win.row_start && y < win.row_end,
            "{what}: pixel ({x}, {y}) outside {win:?} for {t:?}"
        );
    }
    // Row by row, left to right, strictly increasing: no pixel visited twice.
    for pair in got.windows(2) {
        let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
        assert!((y0, x0) < (y1, x1), "{what}: ({x1}, {y1}) visited after ({x0}, {y0}) for {t:?} in {win:?}");
    }
    let want = ref_pixels(t, win);
    if got != want {
        let missing: Vec<_> = want.iter().filter(|p| !got.contains(p)).take(10).collect();
        let extra: Vec<_> = got.iter().filter(|p| !want.contains(p)).take(10).collect();
        panic!(
            "{what}: triangle {t:?} in {win:?}: {} pixels, reference {}; missing {missing:?}, extra {extra:?}",
            got.len(),
            want.len()
        );
    }
    // The reject reasons agree with the geometry.
    match Setup::<0>::new(&tri, win, false, false) {
        Err(Reject::Degenerate) => assert_eq!(orient(t[0], t[1], t[2]), 0, "{what}: {t:?} called degenerate"),
        Err(Reject::Empty) => assert!(want.is_empty(), "{what}: {t:?} called empty"),
        Err(Reject::BackFace) => panic!("{what}: back face reported with culling off"),
        Err(Reject::OutsideGuardBand) => panic!("{what}: {t:?} called outside the guard band"),
        Ok(_) => assert_ne!(orient(t[0], t[1], t[2]), 0),
    }
    got.len()
}

#[test]
fn coverage_matches_reference_for_random_triangles() {
    let mut rng = Rng::new(0x5EED_0001);
    let frames = [
        Frame { w: 64, h: 48 },
        Frame { w: 320, h: 240 },
        Frame { w: 17, h: 9 },
        Frame { w: 1, h: 1 },
        Frame { w: 1536, h: 8 },
    ];
    let mut triangles = 0;
    let mut pixels = 0;
    for f in &frames {
        let n = if f.w * f.h > 20_000 { 1500 } else { 2500 };
        for _ in 0..n {
            let t = random_triangle(&mut rng, f);
            for win in windows(&mut rng, f) {
                pixels += check_against_reference(&t, &win, "random");
            }
            triangles += 1;
            // Every tenth time, a fan of triangles sharing edges (and a vertex).
            if triangles % 10 == 0 {
                if let Some((fan, _)) = random_fan(&mut rng, f) {
                    let wins = windows(&mut rng, f);
                    for t in &fan {
                        for win in &wins {
                            pixels += check_against_reference(t, win, "fan");
                        }
                        triangles += 1;
                    }
                }
            }
        }
    }
    // The largest frame, with triangles spanning the whole guard band (edge functions close to
    // the i32 limit).
    let f = Frame { w: 1536, h: 1536 };
    let (gx0, gx1, gy0, gy1) = f.guard();
    for k in 0..12 {
        let corners = [pt(gx0, gy0), pt(gx1, gy0), pt(gx1, gy1), pt(gx0, gy1)];
        let t = if k < 4 {
            [corners[k], corners[(k + 1) % 4], corners[(k + 2) % 4]]
        } else {
            random_triangle(&mut rng, &f)
        };
        let win = Window { width: f.w, row_start: rng.range(0, 700) as i32, row_end: rng.range(700, 1536) as i32 };
        pixels += check_against_reference(&t, &win, "guard band");
        triangles += 1;
    }
    println!("reference check: {triangles} triangles, {pixels} pixels compared");
}

#[test]
fn coverage_ties_on_pixel_centres() {
    // Small triangles with all vertices on a fine lattice around a few pixel centres: every
    // combination of vertex-on-centre, edge-through-centre, horizontal and vertical edge.
    let f = Frame { w: 12, h: 10 };
    let mut rng = Rng::new(0x5EED_0002);
    let win = full_window(f.w, f.h);
    let mut n = 0;
    for _ in 0..20_000 {
        let t = [0; 3].map(|_| pt(8 * rng.range(4, 18), 8 * rng.range(4, 16)));
        check_against_reference(&t, &win, "lattice");
        n += 1;
    }
    println!("lattice ties: {n} triangles");
}

#[test]
fn culling_follows_the_spec() {
    // Spec: front faces appear counter-clockwise with y up, i.e. counter-clockwise as seen in
    // the picture. Top-left, bottom-left, top-right goes round anticlockwise on screen; its
    // signed area in image coordinates (y down) is negative.
    let ccw_picture = [pt(8, 8), pt(8, 16 * 6 + 8), pt(16 * 10 + 8, 8)];
    assert!(orient(ccw_picture[0], ccw_picture[1], ccw_picture[2]) < 0);
    let win = full_window(16, 8);
    let front = svs(&ccw_picture);
    let back = [front[0], front[2], front[1]];
    assert!(Setup::<0>::new(&front, &win, true, false).is_ok());
    assert!(matches!(Setup::<0>::new(&back, &win, true, false), Err(Reject::BackFace)));
    // A mirroring transform swaps them.
    assert!(matches!(Setup::<0>::new(&front, &win, true, true), Err(Reject::BackFace)));
    assert!(Setup::<0>::new(&back, &win, true, true).is_ok());
    // Without culling both draw the same pixels.
    assert_eq!(fast_pixels(&front, &win, 1), fast_pixels(&back, &win, 1));
    // Collinear after snapping: degenerate.
    let flat = svs(&[pt(8, 8), pt(40, 40), pt(72, 72)]);
    assert!(matches!(Setup::<0>::new(&flat, &win, false, false), Err(Reject::Degenerate)));
}

// ---------------------------------------------------------------------------------------------
// 2. Watertightness
// ---------------------------------------------------------------------------------------------

/// Whether `c` lies on the closed segment `a b`.
fn on_segment(a: Pt, b: Pt, c: Pt) -> bool {
    orient(a, b, c) == 0 && c.x >= a.x.min(b.x) && c.x <= a.x.max(b.x) && c.y >= a.y.min(b.y) && c.y <= a.y.max(b.y)
}

/// Whether `c` is in the closed triangle `t`.
fn in_closed(t: &[Pt; 3], c: Pt) -> bool {
    let s = orient(t[0], t[1], t[2]).signum();
    (0..3).all(|i| orient(t[i], t[(i + 1) % 3], c) * s >= 0)
}

/// Draws `tris` into a per-pixel visit counter and checks: no pixel twice; every centre inside
/// the union (in a closed triangle and not on the outer boundary) exactly once; nothing outside.
fn check_watertight(tris: &[[Pt; 3]], boundary: &[Pt], f: &Frame, what: &str) -> usize {
    let win = full_window(f.w, f.h);
    let mut count = vec![0u8; (f.w * f.h) as usize];
    for t in tris {
        for (x, y) in fast_pixels(&svs(t), &win, 1) {
            count[(y * f.w + x) as usize] += 1;
        }
    }
    let mut inside = 0;
    for r in 0..f.h {
        for c in 0..f.w {
            let n = count[(r * f.w + c) as usize];
            let p = centre(c as i64, r as i64);
            assert!(n <= 1, "{what}: pixel ({c}, {r}) drawn {n} times by {tris:?}");
            let in_union = tris.iter().any(|t| in_closed(t, p));
            let on_boundary =
                (0..boundary.len()).any(|k| on_segment(boundary[k], boundary[(k + 1) % boundary.len()], p));
            if in_union && !on_boundary {
                assert_eq!(n, 1, "{what}: hole at pixel ({c}, {r}) in {tris:?}");
                inside += 1;
            } else if !in_union {
                assert_eq!(n, 0, "{what}: pixel ({c}, {r}) outside the union drawn");
            }
        }
    }
    inside
}

#[test]
fn fans_and_grids_are_watertight() {
    let mut rng = Rng::new(0x5EED_0003);
    let f = Frame { w: 48, h: 40 };
    let (mut fans, mut grids, mut pixels) = (0, 0, 0);
    while fans < 1500 {
        if let Some((tris, ring)) = random_fan(&mut rng, &f) {
            pixels += check_watertight(&tris, &ring, &f, "fan");
            fans += 1;
        }
    }
    while grids < 800 {
        if let Some((tris, boundary)) = random_grid(&mut rng, &f) {
            // Reject grids folded by jitter: all triangles must have the grid's orientation once
            // put back in a common winding. Since windings are random, compare areas instead:
            // the sum of |areas| equals the area of the boundary polygon iff nothing overlaps.
            let sum: i64 = tris.iter().map(|t| orient(t[0], t[1], t[2]).abs()).sum();
            let poly: i64 = (0..boundary.len())
                .map(|k| {
                    let (a, b) = (boundary[k], boundary[(k + 1) % boundary.len()]);
                    a.x * b.y - a.y * b.x
                })
                .sum();
            if sum != poly.abs() {
                continue;
            }
            pixels += check_watertight(&tris, &boundary, &f, "grid");
            grids += 1;
        }
    }
    println!("watertight: {fans} fans, {grids} grids, {pixels} interior pixels each drawn once");
}

// ---------------------------------------------------------------------------------------------
// 3. Bands give bit-identical results
// ---------------------------------------------------------------------------------------------

fn random_attributes(rng: &mut Rng, t: &[Pt; 3]) -> [ScreenVertex; 3] {
    let mut tri = svs(t);
    for v in &mut tri {
        v.z = rng.unit() as f32;
        v.inv_w = (1.0 / (0.1 + rng.unit() * 50.0)) as f32;
        for a in &mut v.varyings {
            *a = rng.range(-(1 << 28), 1 << 28) as i32;
        }
    }
    tri
}

#[test]
fn bands_are_bit_identical_to_the_full_frame() {
    let mut rng = Rng::new(0x5EED_0004);
    let f = Frame { w: 96, h: 64 };
    let full = full_window(f.w, f.h);
    let mut frags = 0;
    for case in 0..400 {
        let t = random_triangle(&mut rng, &f);
        let tri = random_attributes(&mut rng, &t);
        let subspan = [1, 2, 3, 4, 8, 16][case % 6];
        let whole: Vec<Frag<MAX_VARYINGS>> = fast_frags(&tri, &full, subspan);
        // Bands of fixed heights, and a random split.
        let mut splits: Vec<Vec<i32>> =
            [1, 7, 16, f.h].iter().map(|&h| (0..f.h).step_by(h as usize).chain([f.h]).collect()).collect();
        let mut cuts: Vec<i32> = (0..4).map(|_| rng.range(1, f.h as i64 - 1) as i32).collect();
        cuts.extend([0, f.h]);
        cuts.sort_unstable();
        cuts.dedup();
        splits.push(cuts);
        for bounds in &splits {
            let mut banded = Vec::new();
            for pair in bounds.windows(2) {
                let win = Window { width: f.w, row_start: pair[0], row_end: pair[1] };
                banded.extend(fast_frags::<MAX_VARYINGS>(&tri, &win, subspan));
            }
            assert!(banded == whole, "bands {bounds:?} differ from the full frame for {tri:?} (subspan {subspan})");
        }
        frags += whole.len();
    }
    println!("bands: {frags} fragments compared per split");
}

// ---------------------------------------------------------------------------------------------
// 4. Perspective-correct varyings
// ---------------------------------------------------------------------------------------------

/// The perspective-correct value of varying `k` at the centre of pixel (x, y), in f64.
fn exact_varying(tri: &[ScreenVertex; 3], x: i32, y: i32, k: usize) -> f64 {
    let p = [0, 1, 2].map(|i| (tri[i].x as f64 / 16.0, tri[i].y as f64 / 16.0));
    let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
    let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
    // Screen-space barycentrics: λ_i is the area opposite vertex i.
    let sub = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0) * (cy - a.1) - (b.1 - a.1) * (cx - a.0);
    let l = [sub(p[1], p[2]) / area, sub(p[2], p[0]) / area, sub(p[0], p[1]) / area];
    // Perspective: weights λ_i / w_i, renormalised.
    let q: [f64; 3] = core::array::from_fn(|i| l[i] * tri[i].inv_w as f64);
    let s = q[0] + q[1] + q[2];
    (0..3).map(|i| q[i] / s * tri[i].varyings[k] as f64).sum()
}

#[test]
fn affine_shortcuts_stay_within_their_tolerance() {
    let mut rng = Rng::new(0x5EED_0006);
    let f = Frame { w: 200, h: 150 };
    let win = full_window(f.w, f.h);
    // 1/16 texel, 1/256 of light 1.0, and 1/16 unit or (every fifth case) 0: always exact.
    let (mut affine, mut adaptive, mut pixels) = (0, 0, 0usize);
    let mut worst = [0.0f64; 3];
    for case in 0..600 {
        let c = f.near_point(&mut rng, 0);
        let size = [8, 40, 150][case % 3];
        let t =
            [0; 3].map(|_| f.clamp(pt(c.x + rng.range(-16 * size, 16 * size), c.y + rng.range(-16 * size, 16 * size))));
        let mut tri = svs(&t);
        // From nearly flat (w ratio 1.001) to strong perspective (1:4).
        let spread = [0.001, 0.01, 0.1, 3.0][case % 4];
        for v in tri.iter_mut() {
            v.inv_w = (1.0 / (1.0 + rng.unit() * spread)) as f32;
            v.z = rng.unit() as f32;
            v.varyings[0] = rng.range(0, 16 << VARYING_FRAC) as i32;
            v.varyings[1] = rng.range(0, 1 << VARYING_FRAC) as i32;
            v.varyings[2] = rng.range(-(1 << 20), 1 << 20) as i32;
        }
        let tolerance = [1u32 << 12, 1 << 8, if case % 5 == 0 { 0 } else { 1 << 12 }];
        let Ok(mut s) = Setup::<3>::new(&tri, &win, false, false) else { continue };
        // The exact path as drawing takes it: `allow_affine` also decides how exact values are
        // worked out (narrow triangles' from 16-bit operands), and no tolerance allows no
        // shortcut.
        s.allow_affine([0; 3]);
        let mut exact = Vec::new();
        s.for_each_pixel(1, |x, y, _, v| exact.push((x, y, *v)));
        s.allow_affine(tolerance);
        if s.is_affine() {
            affine += 1;
        } else {
            adaptive += 1;
        }
        let mut got = Vec::new();
        s.for_each_pixel(1, |x, y, _, v| got.push((x, y, *v)));
        assert_eq!(got.len(), exact.len(), "coverage must not change");
        // Longest run stepped linearly: bounds the stepping's rounding.
        let max_len = (t.iter().map(|p| p.x).max().unwrap() - t.iter().map(|p| p.x).min().unwrap()) / 16 + 2;
        let exact_error: [f64; 3] = core::array::from_fn(|k| {
            exact.iter().map(|(x, y, e)| (e[k] as f64 - exact_varying(&tri, *x, *y, k)).abs()).fold(0.0, f64::max)
        });
        for ((x, y, v), (ex, ey, e)) in got.iter().zip(&exact) {
            assert_eq!((x, y), (ex, ey));
            for k in 0..3 {
                let err = (v[k] as f64 - exact_varying(&tri, *x, *y, k)).abs();
                let rounding = exact_error[k] + 2.0 + max_len as f64 + (v[k] as f64).abs() * 1e-6;
                if tolerance[k] == 0 {
                    // Never shortcut: bit-identical to the exact path.
                    assert_eq!(v[k], e[k], "varying {k} at ({x}, {y})");
                } else {
                    assert!(err <= tolerance[k] as f64 + rounding, "varying {k} at ({x}, {y}): error {err}, {tri:?}");
                }
                worst[k] = worst[k].max(err);
            }
            pixels += 1;
        }
    }
    println!("affine shortcuts: {affine} affine triangles, {adaptive} adaptive, {pixels} pixels, worst {worst:?}");
    assert!(affine > 50 && adaptive > 50, "{affine} affine, {adaptive} adaptive");
}

#[test]
fn varyings_are_perspective_correct() {
    let mut rng = Rng::new(0x5EED_0005);
    let f = Frame { w: 200, h: 150 };
    let win = full_window(f.w, f.h);
    let subspans = [1u32, 2, 4, 8, 16];
    // Per subspan, the worst error as a fraction of the varying's range over the triangle:
    // - `vs_ideal`: against exact values at the sample pixels (every `subspan` pixels from the
    //   span's first pixel, and its last) linearly interpolated in between, i.e. what subspan
    //   stepping promises; must stay tiny;
    // - `vs_exact_*`: against true perspective-correct values at every pixel. With subspan 1
    //   that is the precision of the integer barycentrics; above 1 it is dominated by the
    //   perspective curvature across a subspan, large where 1/w varies a lot per pixel (w
    //   ratios up to 20 on small triangles), small for mild perspective.
    let mut vs_ideal = [0.0f64; 5];
    let mut vs_exact_strong = [0.0f64; 5];
    let mut vs_exact_mild = [0.0f64; 5];
    let mut pixels = 0usize;
    for case in 0..240 {
        let strong = case % 2 == 0;
        // Medium and large triangles.
        let t = loop {
            let t = if case % 3 == 0 {
                let (gx0, gx1, gy0, gy1) = f.guard();
                [0; 3].map(|_| pt(rng.range(gx0, gx1), rng.range(gy0, gy1)))
            } else {
                let c = f.near_point(&mut rng, 0);
                [0; 3].map(|_| pt(c.x + rng.range(-16 * 150, 16 * 150), c.y + rng.range(-16 * 150, 16 * 150)))
            };
            let t = t.map(|p| f.clamp(p));
            // Mild cases are also well shaped: every altitude at least 16 pixels.
            let longest = (0..3)
                .map(|i| {
                    let (a, b) = (t[i], t[(i + 1) % 3]);
                    (((b.x - a.x).pow(2) + (b.y - a.y).pow(2)) as f64).sqrt()
                })
                .fold(0.0, f64::max);
            let area = orient(t[0], t[1], t[2]).abs();
            if area > 16 * 16 * 50 && (strong || area as f64 / longest >= 16.0 * 16.0) {
                break t;
            }
        };
        let mut tri = svs(&t);
        // w ratios up to 1:20 (a floor seen at a grazing angle), or up to 1:1.5.
        let spread = if strong { 19.0 } else { 0.5 };
        let w = [1.0, 1.0 + rng.unit() * spread, 1.0 + rng.unit() * spread];
        for (k, v) in tri.iter_mut().enumerate() {
            v.inv_w = (1.0 / w[k]) as f32;
            v.z = rng.unit() as f32;
            // Varyings of different ranges: texels (64 px texture), light 0..1, large values.
            v.varyings[0] = rng.range(0, 64 << VARYING_FRAC) as i32;
            v.varyings[1] = rng.range(0, 1 << VARYING_FRAC) as i32;
            v.varyings[2] = rng.range(-(1 << 27), 1 << 27) as i32;
        }
        let ranges: [f64; 3] = core::array::from_fn(|k| {
            let vals = tri.map(|p| p.varyings[k] as f64);
            vals.iter().cloned().fold(f64::MIN, f64::max) - vals.iter().cloned().fold(f64::MAX, f64::min)
        });
        let Ok(s) = Setup::<3>::new(&tri, &win, false, false) else { continue };
        for (si, &subspan) in subspans.iter().enumerate() {
            let frags: Vec<Frag<3>> = {
                let mut v = Vec::new();
                s.for_each_pixel(subspan, |x, y, z, a| v.push((x, y, z, *a)));
                v
            };
            // Spans: runs of consecutive pixels on a row.
            let mut i = 0;
            while i < frags.len() {
                let (lo, y) = (frags[i].0, frags[i].1);
                let mut j = i;
                while j + 1 < frags.len() && frags[j + 1].1 == y && frags[j + 1].0 == frags[j].0 + 1 {
                    j += 1;
                }
                let hi = frags[j].0;
                for frag in &frags[i..=j] {
                    let x = frag.0;
                    let xs = lo + (x - lo) / subspan as i32 * subspan as i32;
                    let xe = (xs + subspan as i32).min(hi);
                    for k in (0..3).filter(|&k| ranges[k] >= 256.0) {
                        let exact = exact_varying(&tri, x, y, k);
                        let ideal = if xe == xs {
                            exact
                        } else {
                            let (a, b) = (exact_varying(&tri, xs, y, k), exact_varying(&tri, xe, y, k));
                            a + (b - a) * (x - xs) as f64 / (xe - xs) as f64
                        };
                        let got = frag.3[k] as f64;
                        // Stepping truncates the step: up to one unit per pixel of the subspan.
                        let e_ideal = ((got - ideal).abs() - subspan as f64).max(0.0) / ranges[k];
                        vs_ideal[si] = vs_ideal[si].max(e_ideal);
                        let e = (got - exact).abs() / ranges[k];
                        let worst = if strong { &mut vs_exact_strong[si] } else { &mut vs_exact_mild[si] };
                        *worst = worst.max(e);
                    }
                }
                i = j + 1;
            }
            pixels += frags.len();
        }
    }
    for (si, &subspan) in subspans.iter().enumerate() {
        println!(
            "perspective varyings: subspan {subspan:2}: max error vs exact {:.6} (1/{:.0}) with w ratio <= 1.5, \
             {:.6} (1/{:.0}) with w ratio <= 20; vs ideal stepping {:.6} (1/{:.0})",
            vs_exact_mild[si],
            1.0 / vs_exact_mild[si],
            vs_exact_strong[si],
            1.0 / vs_exact_strong[si],
            vs_ideal[si],
            1.0 / vs_ideal[si],
        );
    }
    println!("perspective varyings: {pixels} fragments checked");
    // Exact every pixel: within 1/256 of the range (measured about 1/1000).
    assert!(vs_exact_strong[0].max(vs_exact_mild[0]) <= 1.0 / 256.0, "subspan 1: {vs_exact_strong:?}");
    // Stepping does what it promises, for every subspan.
    for (si, e) in vs_ideal.iter().enumerate() {
        assert!(*e <= 1.0 / 256.0, "subspan {}: {e} from ideal linear stepping", subspans[si]);
    }
    // Mild perspective on well-shaped triangles: bounded error.
    for (si, bound) in [(1, 1.0 / 64.0), (2, 1.0 / 32.0), (3, 1.0 / 16.0), (4, 1.0 / 8.0)] {
        assert!(vs_exact_mild[si] <= bound, "subspan {}: error {} > {bound}", subspans[si], vs_exact_mild[si]);
    }
}

// ---------------------------------------------------------------------------------------------
// 6. Robustness (direct: clip + project + setup with raw clip-space vertices)
// ---------------------------------------------------------------------------------------------

/// Clip space to screen exactly as the pipeline does (`pipeline/vertex.rs`'s `project`).
fn project(v: &ClipVertex, (hw, hh): (f32, f32)) -> ScreenVertex {
    let inv_w = 1.0 / v.pos.w;
    let x = (v.pos.x * inv_w + 1.0) * hw;
    let y = (1.0 - v.pos.y * inv_w) * hh;
    let snap = |p: f32| soft3d::testing::math::floor_to_i32(p * 16.0);
    ScreenVertex {
        x: snap(x),
        y: snap(y),
        z: ((v.pos.z * inv_w + 1.0) * 0.5).clamp(0.0, 1.0),
        inv_w,
        varyings: v.varyings.map(|a| a as i32),
    }
}

/// Clips, projects and rasterizes like the pipeline; returns the visited pixels.
fn clip_and_raster(
    tri: &[ClipVertex; 3],
    width: i32,
    height: i32,
    win: &Window,
    subspan: u32,
    cull: bool,
) -> Vec<(i32, i32)> {
    let (w, h) = (width as f32, height as f32);
    let planes = GuardBand { gx: GUARD_HALF_EXTENT / (w * 0.5), gy: GUARD_HALF_EXTENT / (h * 0.5) };
    let mut poly = Polygon::new();
    let res = clip_triangle(tri, &planes, &mut poly);
    match res {
        ClipResult::Outside => return Vec::new(),
        ClipResult::Inside => {
            assert!(poly.is_empty() || poly.len() == 3);
            poly.clear();
            poly.extend_from_slice(tri).unwrap();
        }
        ClipResult::Clipped => assert!(poly.len() >= 3, "clipped polygon with {} vertices", poly.len()),
    }
    let screen: Vec<ScreenVertex> = poly.iter().map(|v| project(v, (w * 0.5, h * 0.5))).collect();
    let mut out = Vec::new();
    for k in 1..screen.len() - 1 {
        let t = [screen[0], screen[k], screen[k + 1]];
        if let Ok(s) = Setup::<MAX_VARYINGS>::new(&t, win, cull, false) {
            s.for_each_pixel(subspan, |x, y, z, _| {
                assert!(z <= 1 << 30);
                out.push((x, y));
            });
        }
    }
    out
}

/// Deterministic proptest settings: a fixed seed and no failure files.
fn config(cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig { cases, rng_seed: RngSeed::Fixed(seed), failure_persistence: None, ..ProptestConfig::default() }
}

/// Hostile numbers of moderate magnitude: NaN, infinities, signed zeros, tiny values and
/// everyday ranges. (Large finite magnitudes are in [`extreme_f32`]: they hit a known bug.)
fn special_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => -3.0f32..3.0,
        2 => -2000.0f32..2000.0,
        1 => prop::sample::select(vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e-30,
            -1e-30,
            f32::MIN_POSITIVE,
            1.0,
            -1.0,
            0.5,
        ]),
    ]
}

/// Anything, including huge finite values.
fn extreme_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        2 => special_f32(),
        1 => any::<f32>(),
        1 => prop::sample::select(vec![1e30, -1e30, 1e15, -1e15, 1e9, -1e9, f32::MAX, f32::MIN]),
    ]
}

/// A clip-space vertex with coordinates from `coord` and `w` from `w`.
fn clip_vertex(coord: BoxedStrategy<f32>, w: BoxedStrategy<f32>) -> impl Strategy<Value = ClipVertex> {
    (coord.clone(), coord.clone(), coord.clone(), w, coord).prop_map(|(x, y, z, w, a)| ClipVertex {
        pos: Vec4::new(x, y, z, w),
        varyings: [a, -a, a * 0.5, 1.0, 0.0, a, 3.0, -7.0],
    })
}

/// Raw triangles: one vertex with any w (including 0, negative, NaN), one with w in an
/// everyday range and one in front of the eye.
fn raw_triangle(coord: fn() -> BoxedStrategy<f32>) -> impl Strategy<Value = [ClipVertex; 3]> {
    [
        clip_vertex(coord(), coord()).boxed(),
        clip_vertex(coord(), prop_oneof![coord(), 1e-3f32..10.0].boxed()).boxed(),
        clip_vertex(coord(), (0.01f32..100.0).boxed()).boxed(),
    ]
}

fn band_geometry() -> impl Strategy<Value = (i32, i32, i32, i32)> {
    (1i32..=80, 1i32..=80)
        .prop_flat_map(|(w, h)| (Just(w), Just(h), 0..h))
        .prop_flat_map(|(w, h, s)| (Just(w), Just(h), Just(s), (s + 1)..=h))
}

fn check_raw(
    tri: &[ClipVertex; 3],
    (width, height, row_start, row_end): (i32, i32, i32, i32),
    subspan: u32,
    cull: bool,
) -> Result<(), TestCaseError> {
    let win = Window { width, row_start, row_end };
    for (x, y) in clip_and_raster(tri, width, height, &win, subspan, cull) {
        prop_assert!(x >= 0 && x < width && y >= row_start && y < row_end, "({}, {}) outside {:?}", x, y, win);
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(3000, 0x5EED_0006))]

    /// Raw clip-space triangles with NaN, infinities, zeros, tiny and everyday values, clipped,
    /// projected and rasterized like the pipeline, never panic and never visit a pixel outside
    /// the window.
    #[test]
    fn raw_clip_space_never_panics(
        tri in raw_triangle(|| special_f32().boxed()),
        geometry in band_geometry(),
        subspan in 0u32..20,
        cull in any::<bool>(),
    ) {
        check_raw(&tri, geometry, subspan, cull)?;
    }
}

proptest! {
    #![proptest_config(config(3000, 0x5EED_0007))]

    /// The same with huge finite values too. Fails: see `clip_output_escapes_the_guard_band`.
    #[test]
    fn raw_clip_space_with_huge_values_never_panics(
        tri in raw_triangle(|| extreme_f32().boxed()),
        geometry in band_geometry(),
        subspan in 0u32..20,
        cull in any::<bool>(),
    ) {
        check_raw(&tri, geometry, subspan, cull)?;
    }
}

proptest! {
    #![proptest_config(config(2000, 0x5EED_0008))]

    /// `Band::new` accepts exactly the consistent slices, and says why it rejects the others.
    #[test]
    fn band_new_checks_lengths(
        len in 0usize..400,
        dlen in prop_oneof![Just(None), (0usize..400).prop_map(Some)],
        width in prop_oneof![0u16..40, Just(1536u16), Just(1537u16)],
        height in prop_oneof![0u16..40, Just(1536u16), Just(1537u16), Just(u16::MAX)],
        first_row in prop_oneof![0u16..40, Just(u16::MAX)],
        same_depth in any::<bool>(),
    ) {
        let mut color = vec![Rgb565::new(1, 2, 3); len];
        let dlen = if same_depth { Some(len) } else { dlen };
        let mut depth = vec![0u16; dlen.unwrap_or(0)];
        let size_ok = width >= 1 && height >= 1 && width <= 1536 && height <= 1536;
        let len_ok = size_ok && len > 0 && len % width as usize == 0;
        let rows_ok = len_ok && first_row as usize + len / width as usize <= height as usize;
        let res = match dlen {
            Some(_) => Band::new(&mut color[..], &mut depth[..], width, height, first_row).map(|_| ()),
            None => Band::new(&mut color[..], NoDepth, width, height, first_row).map(|_| ()),
        };
        let want_ok = rows_ok && dlen.is_none_or(|d| d == len);
        prop_assert_eq!(res.is_ok(), want_ok, "len {} depth {:?} {}x{} first row {}: {:?}", len, dlen, width, height, first_row, res);
        if let Err(e) = res {
            let expected_kind = if !size_ok {
                "size"
            } else if !len_ok {
                "color"
            } else if !rows_ok {
                "rows"
            } else {
                "depth"
            };
            let kind = match e {
                TargetError::BadSize { .. } => "size",
                TargetError::ColorLength { .. } => "color",
                TargetError::BandOutsideFrame { .. } => "rows",
                TargetError::DepthLength { .. } => "depth",
            };
            prop_assert_eq!(kind, expected_kind);
        }
    }
}

/// Regression test for a fixed bug: clipping in f32 a triangle whose plane distances differ by
/// more than 2^24 makes `t = d_in / (d_in - d_out)` round to exactly 1, so the "cut" point is
/// the outside vertex itself. Here (proptest's minimal case, 1x1 frame: guard band 1920 in
/// clip units) vertex 0 is on the eye plane (w = 0) with y = 0.19, outside the guard band;
/// cutting edge 0-1 (w = 3.2e23) returns vertex 0 unchanged, it projects to y = +inf, the
/// saturating cast gives `i32::MAX`, and `Setup::new` overflows `i32` computing the area.
#[test]
fn clip_output_escapes_the_guard_band() {
    let v = |x: f32, y: f32, z: f32, w: f32| ClipVertex { pos: Vec4::new(x, y, z, w), varyings: [0.0; MAX_VARYINGS] };
    let tri = [v(0.0, 0.18978009, 0.0, 0.0), v(0.0, 0.0, 0.0, 3.2383803e23), v(0.0, 0.0, 0.0, 0.01)];
    let planes = GuardBand { gx: GUARD_HALF_EXTENT / 0.5, gy: GUARD_HALF_EXTENT / 0.5 };
    let mut poly = Polygon::new();
    assert_eq!(clip_triangle(&tri, &planes, &mut poly), ClipResult::Clipped);
    for p in &poly {
        let slack = 1.0 + 1e-5;
        assert!(
            p.pos.w > 0.0
                && p.pos.x.abs() <= planes.gx * p.pos.w * slack
                && p.pos.y.abs() <= planes.gy * p.pos.w * slack,
            "clipped vertex outside the guard band: {:?}",
            p.pos
        );
    }
    // What the pipeline does next must not panic either.
    let _ = clip_and_raster(&tri, 1, 1, &full_window(1, 1), 1, false);
}

/// Was a library bug: a clip-space vertex whose `w` is so small that `1/w`
/// overflows (a denormal, e.g. `1e-40`) passes `clip_triangle` as `Inside` (`|x| <= gx·w`
/// holds), projects to `x = ±inf`, which the saturating cast turns into `i32::MAX`/`MIN`, and
/// `Setup::new` then overflows `i32` in its area computation (`p1.x - p0.x`): a panic with
/// overflow checks on (tests, debug builds), garbage coverage without.
#[test]
fn tiny_w_inside_the_guard_band_overflows_setup() {
    let v = |x: f32, y: f32, z: f32, w: f32| ClipVertex { pos: Vec4::new(x, y, z, w), varyings: [0.0; MAX_VARYINGS] };
    let tri = [v(1e-40, 0.0, 0.0, 1e-40), v(0.5, 0.0, 0.5, 1.0), v(0.0, 0.5, 0.5, 1.0)];
    let win = full_window(64, 48);
    let mut poly = Polygon::new();
    // The vertex is "inside" every plane ...
    assert_eq!(clip_triangle(&tri, &GuardBand { gx: 30.0, gy: 40.0 }, &mut poly), ClipResult::Inside);
    // ... but does not project to a finite screen position, so the rasterizer refuses it.
    let screen = [project(&tri[0], (32.0, 24.0)), project(&tri[1], (32.0, 24.0)), project(&tri[2], (32.0, 24.0))];
    assert_eq!(Setup::<0>::new(&screen, &win, false, false).err(), Some(Reject::OutsideGuardBand));
    // And this must not panic.
    let _ = clip_and_raster(&tri, 64, 48, &win, 1, false);
}

// ---------------------------------------------------------------------------------------------
// 7. ASCII pictures (hand-checked)
// ---------------------------------------------------------------------------------------------

/// Pixel coordinates (in pixels, y down) to 28.4.
fn px(x: f64, y: f64) -> Pt {
    pt((x * 16.0).round() as i64, (y * 16.0).round() as i64)
}

/// Draws each triangle with its digit ('1', '2', ...), 'X' where two overlap.
fn ascii(tris: &[[Pt; 3]], w: i32, h: i32) -> Vec<String> {
    let mut grid = vec![vec!['.'; w as usize]; h as usize];
    for (k, t) in tris.iter().enumerate() {
        let mark = char::from_digit(k as u32 + 1, 10).unwrap();
        for (x, y) in fast_pixels(&svs(t), &full_window(w, h), 1) {
            let cell = &mut grid[y as usize][x as usize];
            *cell = if *cell == '.' { mark } else { 'X' };
        }
    }
    grid.into_iter().map(|r| r.into_iter().collect()).collect()
}

/// The tie case, worked out by hand:
/// A = (0.5, 0.5), B = (12.5, 0.5), C = (0.5, 6.5) are pixel centres; the diagonal B–C,
/// x = 12.5 - 2(y - 0.5), passes through the centre (12 - 2r + 0.5, r + 0.5) of every row.
/// Triangle 1 = A B C: A–B is its *top* edge (not owned: row 0 empty, even A itself), A–C its
/// left edge (owned: column 0 drawn), B–C its right edge (not owned). Row r has columns
/// 0 ..= 11 - 2r.
/// Triangle 2 = B D C with D = (12.5, 6.5): B–D is its right edge (column 12 not drawn), D–C
/// its bottom edge (owned: row 6 drawn, C included), C–B its left edge (owned). Row r has
/// columns 12 - 2r ..= 11.
/// Together they cover rows 1..=6, columns 0..=11, each pixel exactly once.
const TIE_PICTURE: [&str; 8] = [
    "................",
    "111111111122....",
    "111111112222....",
    "111111222222....",
    "111122222222....",
    "112222222222....",
    "222222222222....",
    "................",
];

/// A triangle with no centre on an edge: (1, 1), (15, 4), (6, 7.5). Per row centre y:
/// left edge x = 1 + 5(y-1)/6.5, right edge x = 1 + 14(y-1)/3 above y = 4 and
/// 15 - 9(y-4)/3.5 below:
/// y=1.5: (1.38, 3.33) -> columns 1..=2;  y=2.5: (2.15, 8.0) -> 2..=7;
/// y=3.5: (2.92, 12.67) -> 3..=12;        y=4.5: (3.69, 13.71) -> 4..=13;
/// y=5.5: (4.46, 11.14) -> 4..=10;        y=6.5: (5.23, 8.57) -> 5..=8;  y=7.5: vertex, empty.
const PLAIN_PICTURE: [&str; 8] = [
    "................",
    ".11.............",
    "..111111........",
    "...1111111111...",
    "....1111111111..",
    "....1111111.....",
    ".....1111.......",
    "................",
];

fn tie_triangles() -> [[Pt; 3]; 2] {
    let (a, b, c, d) = (px(0.5, 0.5), px(12.5, 0.5), px(0.5, 6.5), px(12.5, 6.5));
    [[a, b, c], [b, d, c]]
}

fn plain_triangle() -> [Pt; 3] {
    [px(1.0, 1.0), px(15.0, 4.0), px(6.0, 7.5)]
}

#[test]
fn ascii_pictures_match_hand_checked_rules() {
    assert_eq!(ascii(&tie_triangles(), 16, 8), TIE_PICTURE);
    // The rules do not depend on vertex order or winding.
    let [t1, t2] = tie_triangles();
    assert_eq!(ascii(&[[t1[2], t1[1], t1[0]], [t2[1], t2[2], t2[0]]], 16, 8), TIE_PICTURE);
    assert_eq!(ascii(&[plain_triangle()], 16, 8), PLAIN_PICTURE);
    // And the reference agrees with the pictures.
    for (tris, pic) in [(&tie_triangles()[..], &TIE_PICTURE), (&[plain_triangle()][..], &PLAIN_PICTURE)] {
        for (k, t) in tris.iter().enumerate() {
            let mark = char::from_digit(k as u32 + 1, 10).unwrap();
            let want: Vec<(i32, i32)> = (0..8)
                .flat_map(|y| (0..16).map(move |x| (x, y)))
                .filter(|&(x, y)| pic[y as usize].as_bytes()[x as usize] == mark as u8)
                .collect();
            assert_eq!(ref_pixels(t, &full_window(16, 8)), want);
        }
    }
    // Drawn band by band (one row each) the pictures are the same.
    for row in 0..8 {
        let win = Window { width: 16, row_start: row, row_end: row + 1 };
        let got: String = (0..16)
            .map(|x| {
                let hits: Vec<usize> = tie_triangles()
                    .iter()
                    .enumerate()
                    .filter(|(_, t)| fast_pixels(&svs(t), &win, 1).contains(&(x, row)))
                    .map(|(k, _)| k)
                    .collect();
                match hits[..] {
                    [] => '.',
                    [k] => char::from_digit(k as u32 + 1, 10).unwrap(),
                    _ => 'X',
                }
            })
            .collect();
        assert_eq!(got, TIE_PICTURE[row as usize], "row {row}");
    }
}

// ---------------------------------------------------------------------------------------------
// Pipeline tests (need the converter to build models): 5, 6 (pipeline part), 7 (pipeline part)
// ---------------------------------------------------------------------------------------------

#[cfg(feature = "convert")]
mod pipeline {
    use super::*;
    use soft3d::convert::scene::{MaterialData, MeshData, Scene, SubMeshData, IDENTITY};
    use soft3d::convert::{emit, EmitOptions};
    use soft3d::testing::math::{Mat4, Vec3};
    use soft3d::{Camera, Model};
    use soft3d::{Filter, Lights};
    use soft3d::{Mode, RenderOptions, Shading, Stats};

    /// A mesh of triangles given as corner lists (local = world).
    fn mesh(name: &str, tris: &[[[f32; 3]; 3]], material: Option<u16>) -> MeshData {
        let positions: Vec<[f32; 3]> = tris.iter().flatten().copied().collect();
        let n = positions.len();
        MeshData {
            name: name.into(),
            world: IDENTITY,
            normals: vec![[0.0, 1.0, 0.0]; n],
            positions,
            uvs: None,
            colors: None,
            indices: (0..n as u32).collect(),
            submeshes: vec![SubMeshData { material, index_start: 0, index_count: n as u32 }],
        }
    }

    /// A quad a b c d as two triangles (a b c), (a c d).
    fn quad(q: [[f32; 3]; 4]) -> [[[f32; 3]; 3]; 2] {
        [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    }

    fn white(cull: bool) -> MaterialData {
        MaterialData { name: "white".into(), back_face_culling: cull, ..MaterialData::default() }
    }

    /// An `.s3d` file with exact f32 positions (so that vertices on pixel centres stay there).
    fn build(meshes: Vec<MeshData>, materials: Vec<MaterialData>) -> Vec<u8> {
        let scene = Scene { meshes, materials, ..Scene::default() };
        emit(&scene, &EmitOptions { float_positions: true, ..EmitOptions::default() }).expect("emit")
    }

    fn unlit() -> RenderOptions {
        RenderOptions { shading: Shading::Unlit, textures: false, dither: false, ..RenderOptions::default() }
    }

    /// Renders a whole frame into Gray8 (background 0) with a u16 depth buffer.
    fn render(model: &Model<'_>, cam: &Camera, w: u16, h: u16, opts: &RenderOptions) -> (Vec<u8>, Stats) {
        let mut color = vec![Gray8::new(0); w as usize * h as usize];
        let mut depth = vec![u16::MAX; color.len()];
        let mut band = Band::new(&mut color[..], &mut depth[..], w, h, 0).unwrap();
        let lights = Lights::<1>::new(Vec3::ONE);
        let stats = soft3d::Renderer::new(cam, &lights, *opts)
            .draw(&mut band, model, Mat4::IDENTITY, &mut soft3d::Scratch::none())
            .unwrap();
        (color.iter().map(|c| c.luma()).collect(), stats)
    }

    fn perspective(eye: [f32; 3], target: [f32; 3], aspect: f32, near: f32) -> Camera {
        perspective_fov(eye, target, 0.8, aspect, near)
    }

    fn perspective_fov(eye: [f32; 3], target: [f32; 3], fov: f32, aspect: f32, near: f32) -> Camera {
        Camera::perspective(Vec3::from(eye), Vec3::from(target), fov, aspect, near, 1000.0).unwrap()
    }

    // ----- 5. Near plane ---------------------------------------------------------------------

    #[test]
    fn floor_through_the_near_plane_stops_at_the_horizon() {
        let (w, h) = (64u16, 48u16);
        // Front face seen from above: near-left, near-right, far-right, far-left is
        // counter-clockwise with y up on screen.
        let floor = quad([[-50.0, -1.0, -50.0], [50.0, -1.0, -50.0], [50.0, -1.0, 200.0], [-50.0, -1.0, 200.0]]);
        let data = build(vec![mesh("floor", &floor, Some(0))], vec![white(true)]);
        let model = Model::parse(&data).unwrap();
        let cam = perspective([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], w as f32 / h as f32, 0.1);
        let (img, stats) = render(&model, &cam, w, h, &unlit());
        // The far edge (z = 200) projects just below the middle: y = (1 + t/200)·24 ≈ 24.28.
        for y in 0..h as usize {
            let row = &img[y * w as usize..(y + 1) * w as usize];
            if y < 24 {
                assert!(row.iter().all(|&l| l == 0), "row {y} above the horizon drawn: {row:?}");
            } else if y > 24 {
                assert!(row.iter().all(|&l| l == 255), "row {y} below the horizon not all floor: {row:?}");
            }
        }
        assert_eq!(stats.clipped, 2, "{stats:?}");
        assert_eq!(stats.culled_back_face, 0, "{stats:?}");
        // Seen from below, the same floor is a back face: nothing drawn.
        let cam = perspective([0.0, -2.0, 0.0], [0.0, -2.0, 1.0], w as f32 / h as f32, 0.1);
        let (img, stats) = render(&model, &cam, w, h, &unlit());
        assert!(img.iter().all(|&l| l == 0), "{stats:?}");
    }

    #[test]
    fn quad_behind_the_camera_draws_nothing() {
        let (w, h) = (64u16, 48u16);
        let q = quad([[-3.0, -3.0, -5.0], [3.0, -3.0, -5.0], [3.0, 3.0, -5.0], [-3.0, 3.0, -5.0]]);
        let data = build(vec![mesh("behind", &q, Some(0))], vec![white(false)]);
        let model = Model::parse(&data).unwrap();
        let cam = perspective([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], w as f32 / h as f32, 0.1);
        let (img, stats) = render(&model, &cam, w, h, &unlit());
        assert!(img.iter().all(|&l| l == 0));
        assert_eq!(stats.pixels_written, 0);
        assert_eq!(stats.clipped, 0);
        assert_eq!(stats.culled_frustum + stats.culled_frustum_mesh, 2, "{stats:?}");
        // Wireframe and points draw nothing either.
        for mode in [Mode::Wireframe, Mode::Points] {
            let (img, _) = render(&model, &cam, w, h, &RenderOptions { mode, ..unlit() });
            assert!(img.iter().all(|&l| l == 0), "{mode:?}");
        }
    }

    /// View depth at which the ray through image point (px, py) (pixels) leaves the box
    /// [-1, 1]^3 from `eye` inside it (Babylon's LookAtLH and PerspectiveFovLH, in f64).
    fn box_exit_depth(eye: [f64; 3], target: [f64; 3], fov: f64, (w, h): (f64, f64), (px, py): (f64, f64)) -> f64 {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let norm = |a: [f64; 3]| {
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            [a[0] / l, a[1] / l, a[2] / l]
        };
        let z = norm(sub(target, eye));
        let x = norm(cross([0.0, 1.0, 0.0], z));
        let y = cross(z, x);
        let t = (fov / 2.0).tan();
        let (xn, yn) = (px / w * 2.0 - 1.0, 1.0 - py / h * 2.0);
        let (a, b) = (xn * t * w / h, yn * t);
        // Direction whose view-space z is 1: the ray parameter is the view depth.
        let d: [f64; 3] = core::array::from_fn(|i| x[i] * a + y[i] * b + z[i]);
        (0..3).filter(|&i| d[i] != 0.0).map(|i| (d[i].signum() - eye[i]) / d[i]).fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn camera_inside_a_box_sees_walls_up_to_the_near_plane() {
        // Six faces around the eye, culling off. Each pixel's ray leaves the box through
        // exactly one wall; the pixel is drawn, exactly once, iff that exit point is at least
        // `near` in front of the eye. Along the walls' shared edges (cut by the near plane in
        // both neighbours) nothing may be missing or doubled. Only pixels for which points
        // 1/8 pixel around the centre disagree about the near plane are not checked.
        let (w, h) = (80u16, 60u16);
        let c = |x: f32, y: f32, z: f32| [x, y, z];
        let faces = [
            quad([c(-1., -1., -1.), c(1., -1., -1.), c(1., 1., -1.), c(-1., 1., -1.)]),
            quad([c(-1., -1., 1.), c(1., -1., 1.), c(1., 1., 1.), c(-1., 1., 1.)]),
            quad([c(-1., -1., -1.), c(-1., 1., -1.), c(-1., 1., 1.), c(-1., -1., 1.)]),
            quad([c(1., -1., -1.), c(1., 1., -1.), c(1., 1., 1.), c(1., -1., 1.)]),
            quad([c(-1., -1., -1.), c(1., -1., -1.), c(1., -1., 1.), c(-1., -1., 1.)]),
            quad([c(-1., 1., -1.), c(1., 1., -1.), c(1., 1., 1.), c(-1., 1., 1.)]),
        ];
        let tris: Vec<[[f32; 3]; 3]> = faces.iter().flatten().copied().collect();
        let data = build(vec![mesh("box", &tris, Some(0))], vec![white(false)]);
        let model = Model::parse(&data).unwrap();
        // (eye, target, field of view, whether the near plane must cut something away)
        let views = [
            ([0.1, 0.2, -0.05], [1.0, 0.7, 0.8], 0.8, false),
            ([0.1, 0.2, -0.05], [1.0, 0.7, 0.8], 2.4, false),
            ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 2.0, false),
            ([0.9, -0.9, 0.9], [-1.0, 1.0, -0.5], 1.5, true),
            ([-0.3, 0.5, 0.2], [1.0, -1.0, 1.0], 2.8, false),
            // Right next to a wall, looking along it.
            ([0.97, 0.1, -0.5], [0.97, 0.0, 1.0], 1.6, true),
            ([-0.5, -0.98, 0.0], [0.5, -0.9, 0.3], 2.0, true),
            // In a corner, looking out of it diagonally.
            ([0.96, 0.96, 0.96], [-1.0, -0.8, -1.0], 2.6, true),
        ];
        let (mut clipped, mut cut_away, mut unchecked) = (0, 0, 0);
        for (eye, target, fov, crosses) in views {
            for near in [0.05f32, 0.2] {
                let cam = perspective_fov(eye, target, fov, w as f32 / h as f32, near);
                let (img, stats) = render(&model, &cam, w, h, &unlit());
                let (e64, t64) = (eye.map(f64::from), target.map(f64::from));
                let mut missing = 0;
                for (i, &l) in img.iter().enumerate() {
                    let (px, py) = ((i % w as usize) as f64 + 0.5, (i / w as usize) as f64 + 0.5);
                    let seen = |dx: f64, dy: f64| {
                        box_exit_depth(e64, t64, fov as f64, (w as f64, h as f64), (px + dx, py + dy)) >= near as f64
                    };
                    let want = seen(0.0, 0.0);
                    let e = 0.125;
                    if [(e, 0.0), (-e, 0.0), (0.0, e), (0.0, -e)].iter().any(|&(dx, dy)| seen(dx, dy) != want) {
                        unchecked += 1;
                        continue;
                    }
                    assert_eq!(l == 255, want, "eye {eye:?} fov {fov} near {near}: pixel ({px}, {py}); {stats:?}");
                    missing += usize::from(!want);
                }
                let drawn = img.iter().filter(|&&l| l == 255).count();
                assert_eq!(stats.pixels_written as usize, drawn, "a pixel drawn twice: {stats:?}");
                if crosses {
                    assert!(stats.clipped > 0, "eye {eye:?}: expected near-plane clipping: {stats:?}");
                }
                clipped += stats.clipped;
                cut_away += missing;
            }
        }
        println!(
            "box: {clipped} clipped triangles, {cut_away} pixels correctly cut away by the near plane, \
             {unchecked} pixels within 1/8 px of the near-plane cut not checked"
        );
        assert!(cut_away > 1000 && unchecked < cut_away / 4);
    }

    /// Sutherland–Hodgman in f64 against the same six planes as the pipeline; each output
    /// vertex remembers whether it is an original vertex.
    /// Signed distance to one clipping plane of a clip-space point, given the guard bands.
    type PlaneFn = fn(&[f64; 4], f64, f64) -> f64;

    fn clip_f64(tri: &[[f64; 4]; 3], gx: f64, gy: f64) -> Vec<([f64; 4], bool)> {
        let planes: [PlaneFn; 6] = [
            |p, _, _| p[2] + p[3],
            |p, _, _| p[3] - p[2],
            |p, gx, _| gx * p[3] + p[0],
            |p, gx, _| gx * p[3] - p[0],
            |p, _, gy| gy * p[3] + p[1],
            |p, _, gy| gy * p[3] - p[1],
        ];
        let mut poly: Vec<([f64; 4], bool)> = tri.iter().map(|&p| (p, true)).collect();
        for d in planes {
            let mut out = Vec::new();
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                let (da, db) = (d(&a.0, gx, gy), d(&b.0, gx, gy));
                if da >= 0.0 {
                    out.push(a);
                }
                if (da >= 0.0) != (db >= 0.0) {
                    let t = da / (da - db);
                    out.push((core::array::from_fn(|k| a.0[k] + (b.0[k] - a.0[k]) * t), false));
                }
            }
            poly = out;
            if poly.len() < 3 {
                return Vec::new();
            }
        }
        poly
    }

    /// Distance from `p` to segment `a b` (all in pixels).
    fn dist_to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 { (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
        let (qx, qy) = (a.0 + t * dx, a.1 + t * dy);
        ((p.0 - qx).powi(2) + (p.1 - qy).powi(2)).sqrt()
    }

    #[test]
    fn triangle_with_a_vertex_behind_the_eye_matches_the_reference() {
        let (w, h) = (64u16, 48u16);
        let cases: [[[f32; 3]; 3]; 4] = [
            [[-1.0, -0.5, 3.0], [1.5, -0.3, 4.0], [0.2, 0.4, -2.0]],
            [[-2.0, 1.0, 6.0], [0.25, -2.0, -1.0], [2.0, 0.75, 5.0]],
            [[0.0, -1.0, -0.5], [-3.0, -1.0, 10.0], [3.0, -1.0, 10.0]],
            [[-0.5, -0.5, -0.5], [1.0, 0.5, 2.0], [-1.0, 0.25, 8.0]],
        ];
        for (case, tri) in cases.iter().enumerate() {
            let data = build(vec![mesh("tri", &[*tri], Some(0))], vec![white(false)]);
            let model = Model::parse(&data).unwrap();
            let cam = perspective([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], w as f32 / h as f32, 0.25);
            let (img, stats) = render(&model, &cam, w, h, &unlit());
            assert_eq!(stats.clipped, 1, "case {case}: {stats:?}");

            // The clip-space vertices as the pipeline computes them (f32), then everything
            // else in f64.
            let m = model.mesh(0).unwrap();
            let mvp = cam.view_projection() * (Mat4::IDENTITY * m.dequantize());
            let clip: [[f64; 4]; 3] = core::array::from_fn(|k| {
                let c = mvp * m.position_stored(m.triangle(0)[k]).extend(1.0);
                [c.x as f64, c.y as f64, c.z as f64, c.w as f64]
            });
            let (hw, hh) = (w as f64 / 2.0, h as f64 / 2.0);
            let g = GUARD_HALF_EXTENT as f64;
            let poly = clip_f64(&clip, g / hw, g / hh);
            assert!(poly.len() >= 4, "case {case}: the near plane should cut a corner off");
            let screen: Vec<(f64, f64)> =
                poly.iter().map(|(p, _)| ((p[0] / p[3] + 1.0) * hw, (1.0 - p[1] / p[3]) * hh)).collect();
            // Original vertices must not sit on a 1/16 rounding boundary, or f32 vs f64 could
            // snap them differently and the comparison below would be unfair.
            for (k, (p, orig)) in poly.iter().enumerate() {
                if *orig {
                    for v in [screen[k].0, screen[k].1] {
                        let frac = (v * 16.0).fract();
                        assert!(
                            frac > 1e-3 && frac < 1.0 - 1e-3,
                            "case {case}: vertex {p:?} projects onto a snapping boundary"
                        );
                    }
                }
            }
            let snapped: Vec<Pt> =
                screen.iter().map(|&(x, y)| pt((x * 16.0).floor() as i64, (y * 16.0).floor() as i64)).collect();
            let full = full_window(w as i32, h as i32);
            let mut want = vec![false; img.len()];
            for k in 1..snapped.len() - 1 {
                for (x, y) in ref_pixels(&[snapped[0], snapped[k], snapped[k + 1]], &full) {
                    want[(y * w as i32 + x) as usize] = true;
                }
            }
            // Edges the clip created: any polygon edge with a new endpoint. The pipeline computes
            // those endpoints in f32, so they may snap 1/16 pixel away from the f64 ones; allow
            // a difference only at pixel centres within 1/8 pixel of such an edge.
            let created: Vec<((f64, f64), (f64, f64))> = (0..poly.len())
                .filter(|&k| !poly[k].1 || !poly[(k + 1) % poly.len()].1)
                .map(|k| (screen[k], screen[(k + 1) % poly.len()]))
                .collect();
            let (mut drawn, mut near_edge_diffs) = (0, 0);
            for (i, &l) in img.iter().enumerate() {
                let got = l == 255;
                drawn += usize::from(got);
                if got != want[i] {
                    let p = ((i % w as usize) as f64 + 0.5, (i / w as usize) as f64 + 0.5);
                    let d = created.iter().map(|&(a, b)| dist_to_segment(p, a, b)).fold(f64::MAX, f64::min);
                    assert!(
                        d <= 0.125,
                        "case {case}: pixel {p:?} drawn={got}, reference says {}; {d} px from a clip edge",
                        want[i]
                    );
                    near_edge_diffs += 1;
                }
            }
            assert!(drawn > 0, "case {case}: nothing drawn");
            println!("near plane case {case}: {} polygon vertices, {drawn} pixels, {near_edge_diffs} differ (within 1/8 px of a clip edge)", poly.len());
        }
    }

    // ----- 6. Robustness through the whole pipeline ------------------------------------------

    const SENTINEL: Rgb565 = Rgb565::new(3, 5, 7);
    const DEPTH_SENTINEL: u16 = 0xBEEF;

    /// Finite hostile values (emit rejects non-finite ones, see `emit_rejects_non_finite_positions`),
    /// including +-1e30.
    fn finite_f32() -> impl Strategy<Value = f32> {
        prop_oneof![
            4 => special_f32().prop_filter("emit needs finite positions", |v| v.is_finite()),
            1 => prop::sample::select(vec![1e30, -1e30, 1e-30, f32::MIN_POSITIVE, 1e6, -1e6]),
        ]
    }

    /// Positions, world scale/translation, band geometry, flags, subspan, padding.
    type PipelineCase = (Vec<[f32; 3]>, [f32; 4], (i32, i32, i32, i32), u16, u32, usize);

    fn pipeline_case() -> impl Strategy<Value = PipelineCase> {
        (
            prop::collection::vec([finite_f32(), finite_f32(), finite_f32()], 3..=12),
            [finite_f32(), finite_f32(), finite_f32(), finite_f32()],
            band_geometry(),
            0u16..256,
            0u32..20,
            0usize..9,
        )
    }

    proptest! {
        #![proptest_config(config(400, 0x5EED_0009))]

        /// Hostile geometry and world matrices through emit/parse/draw never panic and never
        /// write outside the band's colour and depth slices.
        #[test]
        fn pipeline_never_panics_or_writes_outside(
            (positions, world_s, (width, height, first_row, end_row), flags, subspan, pad) in pipeline_case(),
        ) {
            let n = positions.len() / 3 * 3;
            let tris: Vec<[[f32; 3]; 3]> = positions[..n].chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
            let mut m = mesh("hostile", &tris, Some(0));
            // A world matrix with a hostile scale and translation (still finite, as emit demands).
            m.world = [world_s[0], 0.0, 0.0, 0.0, 0.0, world_s[1], 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, world_s[2], world_s[3], 0.0, 1.0];
            let scene = Scene { meshes: vec![m], materials: vec![white(flags & 1 != 0)], ..Scene::default() };
            let emit_opts = EmitOptions { float_positions: flags & 128 != 0, ..EmitOptions::default() };
            let Ok(data) = emit(&scene, &emit_opts) else { return Ok(()) };
            let model = Model::parse(&data).unwrap();
            let rows = (end_row - first_row) as usize;
            let len = width as usize * rows;
            let mut color = vec![SENTINEL; len + 2 * pad];
            let mut depth = vec![DEPTH_SENTINEL; len + 2 * pad];
            let mode = [Mode::Solid, Mode::Wireframe, Mode::Points, Mode::SolidWireframe][(flags >> 1) as usize % 4];
            let shading = [Shading::Unlit, Shading::Flat, Shading::Gouraud, Shading::Phong][(flags >> 3) as usize % 4];
            let opts = RenderOptions {
                mode,
                shading,
                subspan,
                filter: Filter::Nearest,
                textures: true,
                dither: flags & 32 != 0,
                ..RenderOptions::default()
            };
            let cam = if flags & 64 != 0 {
                perspective([0.5, 1.0, -4.0], [0.0, 0.0, 0.0], width as f32 / height as f32, 0.1)
            } else {
                Camera::orthographic(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, 4.0, 3.0, 0.1, 100.0).unwrap()
            };
            let mut lights = Lights::<2>::new(Vec3::splat(0.2));
            let _ = lights.push(Lights::<2>::directional(Vec3::new(0.3, -1.0, 0.5), 1.0));
            {
                let (c, d) = (&mut color[pad..pad + len], &mut depth[pad..pad + len]);
                let mut band = Band::new(c, d, width as u16, height as u16, first_row as u16).unwrap();
                let stats = soft3d::Renderer::new(&cam, &lights, opts).draw(&mut band, &model, Mat4::IDENTITY, &mut soft3d::Scratch::none()).unwrap();
                prop_assert!(stats.pixels_written as usize <= len * 12 * 4);
            }
            prop_assert!(color[..pad].iter().chain(&color[pad + len..]).all(|&c| c == SENTINEL));
            prop_assert!(depth[..pad].iter().chain(&depth[pad + len..]).all(|&d| d == DEPTH_SENTINEL));
        }
    }

    #[test]
    fn emit_rejects_non_finite_positions() {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let m = mesh("bad", &[[[0.0, 0.0, 0.0], [1.0, bad, 0.0], [0.0, 1.0, 0.0]]], None);
            let scene = Scene { meshes: vec![m], ..Scene::default() };
            assert!(emit(&scene, &EmitOptions::default()).is_err());
        }
    }

    /// Regression test for a fixed bug, reached through the whole pipeline: a long thin triangle at
    /// eye level (y = 0 with the eye at the origin), two corners on the eye plane and one
    /// 3·10^7 units ahead. Seen edge-on it covers nothing, but clipping it yields a vertex
    /// with w = 0 and `Setup::new` panics with "attempt to subtract with overflow" (wraps to
    /// garbage without overflow checks). The same happens for a wall beside the eye reaching
    /// 10^8 units, and with the default quantized positions for coordinates around 10^9.
    #[test]
    fn huge_triangle_through_the_eye_plane_does_not_panic() {
        let cases: [[[f32; 3]; 3]; 3] = [
            [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.5, 0.0, 3e7]],
            [[-1.0, -1e8, 1.0], [-1.0, 1e8, -1e8], [-1.0, 1e8, 1e8]],
            [[-1e9, 0.0, 0.0], [0.0, 0.0, -1.0], [1e9, 0.0, -1e9]],
        ];
        for (k, tri) in cases.iter().enumerate() {
            let scene = Scene {
                meshes: vec![mesh("huge", &[*tri], Some(0))],
                materials: vec![white(false)],
                ..Scene::default()
            };
            let data = emit(&scene, &EmitOptions { float_positions: k < 2, ..EmitOptions::default() }).unwrap();
            let model = Model::parse(&data).unwrap();
            let cam = perspective([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 4.0 / 3.0, 0.1);
            let (_, stats) = render(&model, &cam, 64, 48, &unlit());
            println!("case {k}: {stats:?}");
        }
    }

    /// Regression test for a fixed bug: `emit` fails on finite positions above ~1.8e19 with
    /// "internal error, emitted file invalid: mesh record: non-finite number": the bounding
    /// sphere radius is computed as an f32 length whose squares overflow to infinity, and the
    /// reader (rightly) rejects the non-finite radius.
    #[test]
    fn emit_handles_large_finite_positions() {
        let m = mesh("big", &[[[0.0, 0.0, 0.0], [1e20, 0.0, 0.0], [0.0, 1e20, 0.0]]], None);
        let scene = Scene { meshes: vec![m], ..Scene::default() };
        for float_positions in [false, true] {
            match emit(&scene, &EmitOptions { float_positions, ..EmitOptions::default() }) {
                Ok(data) => assert!(Model::parse(&data).is_ok()),
                Err(e) => assert!(!e.0.contains("internal error"), "{e}"),
            }
        }
    }

    // ----- 7. ASCII pictures through the pipeline --------------------------------------------

    /// An orthographic camera that maps world (x, y) to pixel (x, 8 - y) in a 16x8 frame.
    fn pixel_camera() -> Camera {
        Camera::orthographic(Vec3::new(8.0, 4.0, -10.0), Vec3::new(8.0, 4.0, 0.0), 16.0, 8.0, 0.1, 100.0).unwrap()
    }

    /// World coordinates for a picture position (pixels, y down).
    fn world(x: f32, y: f32) -> [f32; 3] {
        [x, 8.0 - y, 0.0]
    }

    #[test]
    fn ascii_pictures_through_the_pipeline() {
        // Tie case: triangle 1 white (luma 255 -> '1'), triangle 2 grey (luma 128 -> '2'); both
        // listed as front faces (counter-clockwise in the picture), culling on.
        let (a, b, c, d) = (world(0.5, 0.5), world(12.5, 0.5), world(0.5, 6.5), world(12.5, 6.5));
        let mut m1 = mesh("tie", &[[a, c, b], [b, c, d]], None);
        m1.submeshes = vec![
            SubMeshData { material: Some(0), index_start: 0, index_count: 3 },
            SubMeshData { material: Some(1), index_start: 3, index_count: 3 },
        ];
        let grey = MaterialData { diffuse: [128.0 / 255.0; 3], ..white(true) };
        let data = build(vec![m1], vec![white(true), grey]);
        let model = Model::parse(&data).unwrap();
        let (img, stats) = render(&model, &pixel_camera(), 16, 8, &unlit());
        let pic: Vec<String> = img
            .chunks(16)
            .map(|row| {
                row.iter()
                    .map(|&l| match l {
                        0 => '.',
                        255 => '1',
                        128 => '2',
                        _ => '?',
                    })
                    .collect()
            })
            .collect();
        assert_eq!(pic, TIE_PICTURE);
        assert_eq!(stats.pixels_written, 72, "each pixel of the 12x6 rectangle once: {stats:?}");
        assert_eq!(stats.depth_rejected, 0);

        // The plain triangle into a BinaryColor frame.
        let [p, q, r] = plain_triangle().map(|v| world(v.x as f32 / 16.0, v.y as f32 / 16.0));
        let data = build(vec![mesh("plain", &[[p, r, q]], Some(0))], vec![white(true)]);
        let model = Model::parse(&data).unwrap();
        let mut color = [BinaryColor::Off; 16 * 8];
        let mut band = Band::new(&mut color[..], NoDepth, 16, 8, 0).unwrap();
        let stats = soft3d::Renderer::new(&pixel_camera(), &Lights::<0>::new(Vec3::ONE), unlit())
            .draw(&mut band, &model, Mat4::IDENTITY, &mut soft3d::Scratch::none())
            .unwrap();
        let pic: Vec<String> =
            color.chunks(16).map(|row| row.iter().map(|c| if c.is_on() { '1' } else { '.' }).collect()).collect();
        assert_eq!(pic, PLAIN_PICTURE, "{stats:?}");
        // Clockwise in the picture is a back face: culled.
        let data = build(vec![mesh("plain", &[[p, q, r]], Some(0))], vec![white(true)]);
        let model = Model::parse(&data).unwrap();
        let (img, stats) = render(&model, &pixel_camera(), 16, 8, &unlit());
        assert!(img.iter().all(|&l| l == 0));
        assert_eq!(stats.culled_back_face, 1);
    }
}

/// Degenerate-looking but legal triangles (a needle whose f32 depth plane strays far outside
/// its vertices' depths; a large triangle whose depth gradient times its width overflows
/// i64 in 24.40; an absurd `subspan`) draw without panicking, with depth in 0..=2^30.
#[test]
fn needles_huge_gradients_and_huge_subspans_do_not_panic() {
    let vert = |x: i32, y: i32, z: f32| ScreenVertex { x, y, z, inv_w: 1.0, varyings: [7 << 16; MAX_VARYINGS] };
    let cases = [
        // A needle: two vertices at depth 2^-14, the third a 1/16 pixel away at 0.694.
        (
            [vert(344, 2712, 1.0 / 16384.0), vert(4952, -2536, 1.0 / 16384.0), vert(4952, -2535, 0.694)],
            full_window(240, 240),
        ),
        // Large and thin in a 1536-wide frame: z_dx times the column overflows i64.
        (
            {
                let b = (24008, 24008);
                let a = (b.0 - 16000, b.1 - 16001);
                let c = (a.0 + 16001, a.1 + 16002);
                [vert(a.0, a.1, 0.5), vert(b.0, b.1, 0.5), vert(c.0, c.1, 0.9)]
            },
            full_window(1536, 1536),
        ),
    ];
    for (tri, win) in &cases {
        for subspan in [1, 3, 4096, u32::MAX] {
            let Ok(s) = Setup::<MAX_VARYINGS>::new(tri, win, false, false) else { continue };
            let mut n = 0;
            s.for_each_pixel(subspan, |_, _, z, _| {
                assert!(z <= 1 << 30, "depth {z}");
                n += 1;
            });
            assert!(n > 0, "{tri:?} covers pixels");
        }
    }
}
