//! Triangle rasterization: integer edge functions in 28.4 fixed point, exact spans per row,
//! perspective-correct varyings, all in integers per pixel.
//!
//! # Numbers
//! - Vertex positions are snapped to 1/16 pixel (28.4). The pipeline clips geometry to a guard
//!   band of ±[`GUARD_HALF_EXTENT`](crate::target::GUARD_HALF_EXTENT) pixels around the frame
//!   centre, so a triangle spans at most 1920 pixels = 30,720 units < 2^15 on either axis and
//!   every edge function evaluated inside its bounding box, `A·dx + B·dy` with
//!   `|A|, |B|, |dx|, |dy| < 2^15`, fits in `i32`.
//! - Edge function of edge a→b at p: `E = (bx-ax)(py-ay) - (by-ay)(px-ax)` (image y down);
//!   triangles are reordered so that the inside is `E > 0` for all three edges.
//! - Fill rule (spec): a centre exactly on an edge (`E == 0`) is inside only if that edge is a
//!   left edge (`A > 0`) or a bottom horizontal edge (`A == 0 && B < 0`), where `A = ay - by`
//!   and `B = bx - ax` are the coefficients of `px` and `py`.
//! - Depth is affine in screen space and interpolated from a plane in 24.40 fixed point
//!   (`i64`); it reaches the depth buffer as 0..=2^30.
//! - Varyings (texture coordinates, light, normals) are `i32` with 16 fractional bits,
//!   interpolated with perspective-correct barycentrics `b_i = (E_i/w_i) / Σ(E_j/w_j)` computed
//!   exactly every `subspan` pixels along a span and linearly in between (`subspan = 1`: every
//!   pixel exact).
//!
//! Every value here is a function of the triangle and the pixel only, never of the band being
//! drawn, so a frame drawn in bands is bit-identical to the frame drawn whole.

/// The most varyings a vertex carries.
pub const MAX_VARYINGS: usize = 8;

/// Fractional bits of varyings in the per-pixel loop.
pub const VARYING_FRAC: u32 = 16;

/// What the rasterizer calls for each covered pixel.
pub trait Fragment<const V: usize> {
    /// Whether the pixel at frame `(x, y)` with depth `z` (0..=2^30) survives (the depth
    /// test); only then are its varyings computed and [`Fragment::shade`] called.
    fn test(&mut self, x: i32, y: i32, z: u32) -> bool;
    /// Shades the pixel with its perspective-correct varyings.
    fn shade(&mut self, x: i32, y: i32, z: u32, varyings: &[i32; V]);
}

/// A vertex after projection: what the rasterizer needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenVertex {
    /// x in 1/16 pixel (28.4), image coordinates.
    pub x: i32,
    /// y in 1/16 pixel (28.4), image coordinates, y down.
    pub y: i32,
    /// Depth 0 (near) ..= 1 (far): `(z/w + 1) / 2`.
    pub z: f32,
    /// `1 / w`.
    pub inv_w: f32,
    /// Attributes, already in their fixed-point units (16 fractional bits). A [`Setup`] of
    /// `V` varyings uses the first `V`.
    pub varyings: [i32; MAX_VARYINGS],
}

/// Rows and columns a triangle may touch: the band, in frame pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// Frame width in pixels.
    pub width: i32,
    /// First row (inclusive).
    pub row_start: i32,
    /// Last row (exclusive).
    pub row_end: i32,
}

/// One edge: `E(px, py) = a·(px - ox) + b·(py - oy) + c`, with the tie-break bias folded into
/// `c` so that a pixel is inside when `E >= 0` for all three edges.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: i32,
    b: i32,
    c: i32,
}

impl Edge {
    /// The edge from `p` to `q`, with its origin at the pixel-centre `(ox, oy)` (28.4).
    fn new(p: &ScreenVertex, q: &ScreenVertex, ox: i32, oy: i32) -> Edge {
        let a = p.y - q.y;
        let b = q.x - p.x;
        let owned = a > 0 || (a == 0 && b < 0);
        let c = a * (ox - p.x) + b * (oy - p.y) - i32::from(!owned);
        Edge { a, b, c }
    }

    /// Inclusive column range `[lo, hi]` (relative to the origin, in pixels) where this edge
    /// is non-negative on the row `dy` pixels below the origin; `None` when none is.
    #[inline]
    fn span(&self, dy: i32, lo: i32, hi: i32) -> Option<(i32, i32)> {
        let row = self.c + self.b * 16 * dy;
        let step = self.a * 16;
        if step > 0 {
            // row + step * x >= 0  <=>  x >= ceil(-row / step)
            Some((lo.max(ceil_div(-row, step)), hi))
        } else if step < 0 {
            // x <= floor(row / -step)
            Some((lo, hi.min(floor_div(row, -step))))
        } else if row >= 0 {
            Some((lo, hi))
        } else {
            None
        }
    }
}

#[inline]
fn floor_div(n: i32, d: i32) -> i32 {
    let q = n / d;
    if (n % d != 0) && ((n < 0) != (d < 0)) {
        q - 1
    } else {
        q
    }
}

#[inline]
fn ceil_div(n: i32, d: i32) -> i32 {
    -floor_div(-n, d)
}

/// A triangle ready to rasterize: edges, depth plane and varyings relative to the origin pixel.
pub struct Setup<const V: usize> {
    edges: [Edge; 3],
    /// Bounding box in pixels (inclusive), already clipped to the frame.
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
    /// Frame row of the origin pixel centre (the bounding box's top row, unclipped by the band).
    origin_row: i32,
    /// Depth at the origin pixel centre, and per pixel in x and y, 24.40.
    z_origin: i64,
    z_dx: i64,
    z_dy: i64,
    /// 1/w of each vertex, normalised so the largest is 2^16 - 1.
    inv_w: [u32; 3],
    /// Varyings at vertex 0 and their differences to vertices 1 and 2.
    v0: [i32; V],
    d1: [i32; V],
    d2: [i32; V],
}

/// Result of [`Setup::new`] when nothing is to be drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reject {
    /// Zero area after snapping.
    Degenerate,
    /// Back-facing while back faces are culled.
    BackFace,
    /// No pixel centre of the window is covered.
    Empty,
    /// A vertex lies outside the guard band or has a non-finite or non-positive `1/w`
    /// (only float rounding at clipping produces one).
    OutsideGuardBand,
}

/// The largest extent of a triangle in 1/16 pixels: twice the guard band's half extent plus
/// one pixel of slack, so that `A·dx + B·dy` over its bounding box fits in `i32`.
pub const MAX_EXTENT: i32 = (2 * crate::target::GUARD_HALF_EXTENT as i32 + 1) * 16;

/// The largest absolute coordinate, in 1/16 pixels, the rasterizer accepts.
pub const MAX_COORD: i32 = 1 << 24;

/// Twice the signed image-space area of `tri` (y down), checked against the culling rule:
/// front faces are counter-clockwise with y up, i.e. a negative area here, unless `flip`.
///
/// # Errors
/// [`Reject::Degenerate`] for zero area, [`Reject::BackFace`] for a culled back face.
pub fn facing(tri: &[ScreenVertex; 3], cull_back: bool, flip: bool) -> Result<i64, Reject> {
    // Clipping keeps triangles inside the guard band, but float rounding (or a denormal w) can
    // still push a vertex out; the integer ranges above hold only inside, so refuse the rest.
    let span = |c: fn(&ScreenVertex) -> i32| {
        let (lo, hi) = tri.iter().map(c).fold((i32::MAX, i32::MIN), |(l, h), v| (l.min(v), h.max(v)));
        lo > -MAX_COORD && hi < MAX_COORD && (hi as i64 - lo as i64) < MAX_EXTENT as i64
    };
    if !span(|v| v.x) || !span(|v| v.y) || tri.iter().any(|v| !(v.inv_w > 0.0 && v.inv_w.is_finite())) {
        return Err(Reject::OutsideGuardBand);
    }
    let [p0, p1, p2] = tri;
    // Coordinates are < 2^15 apart (checked above): the products fit i64 easily.
    let area = (p1.x - p0.x) as i64 * (p2.y - p0.y) as i64 - (p2.x - p0.x) as i64 * (p1.y - p0.y) as i64;
    if area == 0 {
        return Err(Reject::Degenerate);
    }
    if cull_back && (area < 0) == flip {
        return Err(Reject::BackFace);
    }
    Ok(area)
}

impl<const V: usize> Setup<V> {
    /// Prepares `tri` for rasterization into `win`. `cull_front_ccw`: cull triangles whose
    /// image-space winding is counter-clockwise in window coordinates' opposite sense, i.e. back
    /// faces; `flip` inverts which winding counts as front (negative-determinant transforms).
    pub fn new(tri: &[ScreenVertex; 3], win: &Window, cull_back: bool, flip: bool) -> Result<Self, Reject> {
        let [p0, p1, p2] = tri;
        let area = facing(tri, cull_back, flip)?;
        // Reorder so the inside is E > 0 (positive image-space area).
        let (a, b, c) = if area > 0 { (p0, p1, p2) } else { (p0, p2, p1) };
        let area = area.abs();

        // Pixel rows/columns whose centres (16k + 8) lie inside the bounding box.
        let min_x = a.x.min(b.x).min(c.x);
        let max_x = a.x.max(b.x).max(c.x);
        let min_y = a.y.min(b.y).min(c.y);
        let max_y = a.y.max(b.y).max(c.y);
        let x0 = ceil_div(min_x - 8, 16).max(0);
        let x1 = floor_div(max_x - 8, 16).min(win.width - 1);
        let y0 = ceil_div(min_y - 8, 16).max(win.row_start);
        let y1 = floor_div(max_y - 8, 16).min(win.row_end - 1);
        if x0 > x1 || y0 > y1 {
            return Err(Reject::Empty);
        }
        // The origin is the bounding box's first pixel centre *of the frame*, not of the band,
        // so that every interpolated value is the same whichever band draws the pixel.
        let fy0 = ceil_div(min_y - 8, 16).max(0);
        let (ox, oy) = (x0 * 16 + 8, fy0 * 16 + 8);
        let edges = [Edge::new(b, c, ox, oy), Edge::new(c, a, ox, oy), Edge::new(a, b, ox, oy)];

        // Depth plane from the three vertices (f32 setup, deterministic on every target).
        let af = area as f32;
        let (dz1, dz2) = (b.z - a.z, c.z - a.z);
        let (ex1, ey1, ex2, ey2) = ((b.x - a.x) as f32, (b.y - a.y) as f32, (c.x - a.x) as f32, (c.y - a.y) as f32);
        let gx = (dz1 * ey2 - dz2 * ey1) / af; // per 1/16 pixel
        let gy = (dz2 * ex1 - dz1 * ex2) / af;
        const Z_ONE: f32 = (1u64 << 40) as f32;
        let z_at_origin = a.z + gx * (ox - a.x) as f32 + gy * (oy - a.y) as f32;
        let to_fixed = |v: f32| (v * Z_ONE) as i64;

        let max_w = a.inv_w.max(b.inv_w).max(c.inv_w);
        let norm = |q: f32| ((q / max_w * 65535.0) as u32).max(1);

        let mut v0 = [0; V];
        let mut d1 = [0; V];
        let mut d2 = [0; V];
        for k in 0..V {
            v0[k] = a.varyings[k];
            d1[k] = b.varyings[k].wrapping_sub(a.varyings[k]);
            d2[k] = c.varyings[k].wrapping_sub(a.varyings[k]);
        }
        Ok(Setup {
            edges,
            x0,
            x1,
            y0,
            y1,
            origin_row: fy0,
            z_origin: to_fixed(z_at_origin),
            z_dx: to_fixed(gx * 16.0),
            z_dy: to_fixed(gy * 16.0),
            inv_w: [norm(a.inv_w), norm(b.inv_w), norm(c.inv_w)],
            v0,
            d1,
            d2,
        })
    }

    /// Rows this triangle covers in the window, as `first..=last`.
    #[must_use]
    pub fn rows(&self) -> (i32, i32) {
        (self.y0, self.y1)
    }

    /// Perspective-correct varyings where the edge functions are `e` (all >= 0).
    #[inline(always)]
    fn varyings_at(&self, e: [i32; 3]) -> [i32; V] {
        // Full-precision weights E_k · (1/w_k): truncating E first loses the far vertices'
        // weights when the near one is magnified by a large depth ratio.
        let n = |k: usize| e[k].max(0) as u64 * self.inv_w[k] as u64;
        let (n1, n2) = (n(1), n(2));
        let sum = n(0) + n1 + n2;
        let mut out = self.v0;
        if sum == 0 {
            return out;
        }
        // Bring the denominator below 2^16 so that (numerator << 16) fits in u32.
        let s = (64 - sum.leading_zeros()).saturating_sub(16);
        let den = (sum >> s) as u32;
        let b1 = (((n1 >> s) as u32) << 16) / den;
        let b2 = (((n2 >> s) as u32) << 16) / den;
        for ((o, d1), d2) in out.iter_mut().zip(self.d1).zip(self.d2) {
            let delta = d1 as i64 * b1 as i64 + d2 as i64 * b2 as i64;
            *o = o.wrapping_add((delta >> 16) as i32);
        }
        out
    }

    /// Calls `pixel(x, y, z, varyings)` for every covered pixel centre in the window, row by
    /// row, left to right. `z` is 0..=2^30. `subspan` (>= 1) is how often along a span the
    /// varyings are computed exactly; in between they are stepped linearly.
    #[inline]
    pub fn for_each_pixel(&self, subspan: u32, pixel: impl FnMut(i32, i32, u32, &[i32; V])) {
        struct All<F>(F);
        impl<F: FnMut(i32, i32, u32, &[i32; V]), const V: usize> Fragment<V> for All<F> {
            #[inline(always)]
            fn test(&mut self, _: i32, _: i32, _: u32) -> bool {
                true
            }
            #[inline(always)]
            fn shade(&mut self, x: i32, y: i32, z: u32, v: &[i32; V]) {
                (self.0)(x, y, z, v);
            }
        }
        self.for_each_fragment(subspan, &mut All(pixel));
    }

    /// Like [`Setup::for_each_pixel`], but asks `f.test` (the depth test) first, so that with
    /// `subspan == 1` a hidden pixel costs no perspective division.
    #[inline]
    pub fn for_each_fragment(&self, subspan: u32, f: &mut impl Fragment<V>) {
        let subspan = subspan.max(1) as i32;
        let width = self.x1 - self.x0;
        for y in self.y0..=self.y1 {
            // Rows are measured from the origin row in frame coordinates (see `new`).
            let dy = y - self.origin_row;
            let mut lo = 0;
            let mut hi = width;
            for e in &self.edges {
                match e.span(dy, lo, hi) {
                    Some((l, h)) => {
                        lo = l;
                        hi = h;
                    }
                    None => {
                        lo = 1;
                        hi = 0;
                    }
                }
            }
            if lo > hi {
                continue;
            }
            let mut e: [i32; 3] = core::array::from_fn(|k| {
                let edge = &self.edges[k];
                edge.c + edge.b * 16 * dy + edge.a * 16 * lo
            });
            let step_e: [i32; 3] = core::array::from_fn(|k| self.edges[k].a * 16);
            let mut z = self.z_origin + self.z_dx * lo as i64 + self.z_dy * dy as i64;
            let depth = |z: i64| (z >> 10).clamp(0, 1 << 30) as u32;
            if subspan == 1 {
                // Exact: every pixel gets its own perspective division, after the depth test.
                for x in lo..=hi {
                    let zq = depth(z);
                    if f.test(self.x0 + x, y, zq) {
                        f.shade(self.x0 + x, y, zq, &self.varyings_at(e));
                    }
                    z += self.z_dx;
                    for k in 0..3 {
                        e[k] += step_e[k];
                    }
                }
                continue;
            }
            let e_at = |x: i32| -> [i32; 3] { core::array::from_fn(|k| e[k] + step_e[k] * (x - lo)) };
            let mut xs = lo;
            let mut vs = self.varyings_at(e_at(xs));
            loop {
                if xs == hi {
                    let zq = depth(z);
                    if f.test(self.x0 + xs, y, zq) {
                        f.shade(self.x0 + xs, y, zq, &vs);
                    }
                    break;
                }
                let xe = (xs + subspan).min(hi);
                let ve = self.varyings_at(e_at(xe));
                let len = xe - xs;
                let mut step = [0i32; V];
                for k in 0..V {
                    let diff = ve[k].wrapping_sub(vs[k]);
                    step[k] = if len == subspan && subspan.count_ones() == 1 {
                        diff >> subspan.trailing_zeros()
                    } else {
                        diff / len
                    };
                }
                let mut cur = vs;
                for x in xs..xe {
                    let zq = depth(z);
                    if f.test(self.x0 + x, y, zq) {
                        f.shade(self.x0 + x, y, zq, &cur);
                    }
                    z += self.z_dx;
                    for k in 0..V {
                        cur[k] = cur[k].wrapping_add(step[k]);
                    }
                }
                xs = xe;
                vs = ve;
            }
        }
    }
}
