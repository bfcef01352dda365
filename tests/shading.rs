//! Shading tests: texture mapping, filtering, lighting and pixel formats, each checked against
//! an independent `f64` evaluation of `spec/babylon-conventions.md`.
//!
//! 1. Perspective-correct texturing on a floor and a wall seen at steep angles, per pixel
//!    against ray/plane intersections (sub-spans 1, 4, 8, 16 measured).
//! 2. Texture orientation: texel-to-pixel quads reproduce the image upright.
//! 3. Wrap / clamp / mirror and negative UVs by hand; bilinear against an f64 reference.
//! 4. Lighting: Phong against the exact sphere, flat and Gouraud against their definitions,
//!    point lights without falloff, cut-outs unchanged by light.
//! 5. Frame formats (`from_rgb888` of the Rgb888 frame, Rgb565Be bytes) and dithering.
//! 6. Texture storage formats (`encode_texel` / `decode_texel`, `.s3d` round trip).
//!
//! Scenes are built in code (`convert::scene`) and emitted with exact f32 positions and
//! Rgba8888 textures unless a test is about formats. Randomness is a seeded SplitMix64. Run
//! with `--nocapture` to see the measured numbers.

use std::f64::consts::PI;

use soft3d::convert::scene::{MaterialData, MeshData, Scene, SubMeshData, TextureData, Wrap as SceneWrap, IDENTITY};
use soft3d::convert::{emit, EmitOptions, TextureChoice};
use soft3d::testing::math::{normal_matrix, normalize_or_zero, Mat4, Vec3};
use soft3d::testing::Sampler;
use soft3d::FrameColor;
use soft3d::{decode_texel, encode_texel, Model, Texture, TextureFormat, Wrap};
use soft3d::{Band, Camera, Filter, Lights, RenderOptions, Rgb565Be, Shading};

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, Rgb565, Rgb888, RgbColor};
use embedded_graphics_core::prelude::IntoStorage;

// ---------------------------------------------------------------------------------------------
// Deterministic randomness
// ---------------------------------------------------------------------------------------------

mod common;
use common::Rng;

// ---------------------------------------------------------------------------------------------
// Scenes built in code
// ---------------------------------------------------------------------------------------------

/// A quad with corners in the order bottom-left, bottom-right, top-right, top-left as seen from
/// its front (so both triangles are front faces), with the given UVs and per-vertex normals
/// (`None`: the face normal).
fn quad(corners: [[f32; 3]; 4], uvs: Option<[[f32; 2]; 4]>, normals: Option<[[f32; 3]; 4]>) -> MeshData {
    let p = corners.map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64));
    let face = (p[2] - p[0]).cross(p[1] - p[0]).normalize();
    let normals = normals.unwrap_or([[face.x as f32, face.y as f32, face.z as f32]; 4]);
    MeshData {
        name: "quad".into(),
        world: IDENTITY,
        positions: corners.to_vec(),
        normals: normals.to_vec(),
        uvs: uvs.map(|u| u.to_vec()),
        colors: None,
        indices: vec![0, 1, 2, 0, 2, 3],
        submeshes: vec![SubMeshData { material: Some(0), index_start: 0, index_count: 6 }],
    }
}

/// A `w` x `h` quad in the plane z = 0 centred on the origin, facing -z (towards a camera at
/// negative z), with UVs from `uv0` (bottom-left) to `uv1` (top-right).
fn screen_quad(w: f32, h: f32, uv0: [f32; 2], uv1: [f32; 2]) -> MeshData {
    let (x, y) = (w / 2.0, h / 2.0);
    quad(
        [[-x, -y, 0.0], [x, -y, 0.0], [x, y, 0.0], [-x, y, 0.0]],
        Some([[uv0[0], uv0[1]], [uv1[0], uv0[1]], [uv1[0], uv1[1]], [uv0[0], uv1[1]]]),
        None,
    )
}

/// A UV sphere of `nu` x `nv` segments with exact unit normals, every triangle a front face
/// from outside (degenerate pole triangles left out).
fn uv_sphere(centre: [f64; 3], radius: f64, nu: u32, nv: u32) -> MeshData {
    let c = DVec3::from(centre);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for i in 0..=nv {
        let theta = PI * i as f64 / nv as f64;
        for j in 0..=nu {
            let phi = 2.0 * PI * j as f64 / nu as f64;
            let n = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let p = c + n * radius;
            positions.push([p.x as f32, p.y as f32, p.z as f32]);
            normals.push([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    let idx = |i: u32, j: u32| i * (nu + 1) + j;
    let mut indices = Vec::new();
    let pos = |k: u32| DVec3::from(positions[k as usize].map(f64::from));
    let mut push = |t: [u32; 3]| {
        let (p0, p1, p2) = (pos(t[0]), pos(t[1]), pos(t[2]));
        // Outward when (p2 - p0) x (p1 - p0) points away from the centre (see pipeline/vertex.rs).
        let n = (p2 - p0).cross(p1 - p0);
        if n.dot((p0 + p1 + p2) / 3.0 - c) > 0.0 {
            indices.extend_from_slice(&t);
        } else {
            indices.extend_from_slice(&[t[0], t[2], t[1]]);
        }
    };
    for i in 0..nv {
        for j in 0..nu {
            let (a, b, cc, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j));
            if i != 0 {
                push([a, b, cc]);
            }
            if i != nv - 1 {
                push([a, cc, d]);
            }
        }
    }
    let n = indices.len() as u32;
    MeshData {
        name: "sphere".into(),
        world: IDENTITY,
        positions,
        normals,
        uvs: None,
        colors: None,
        indices,
        submeshes: vec![SubMeshData { material: Some(0), index_start: 0, index_count: n }],
    }
}

/// A texture from `f(i, j)` with `j` counted from the bottom row (as UVs are), stored in
/// [`TextureData`]'s order: rows from the top of the image.
fn texture(w: u16, h: u16, mut f: impl FnMut(u32, u32) -> [u8; 4]) -> TextureData {
    let mut rgba = Vec::with_capacity(w as usize * h as usize * 4);
    for row in 0..h as u32 {
        for i in 0..w as u32 {
            rgba.extend_from_slice(&f(i, h as u32 - 1 - row));
        }
    }
    TextureData { name: "t".into(), width: w, height: h, rgba }
}

fn material(diffuse: [f32; 3], texture: Option<u16>) -> MaterialData {
    MaterialData { diffuse, texture, ..Default::default() }
}

fn scene(meshes: Vec<MeshData>, materials: Vec<MaterialData>, textures: Vec<TextureData>) -> Scene {
    Scene { meshes, materials, textures, ..Default::default() }
}

fn emit_with(scene: &Scene, format: TextureFormat) -> Vec<u8> {
    emit(scene, &EmitOptions { float_positions: true, textures: TextureChoice::Fixed(format) }).unwrap()
}

fn emit_rgba(scene: &Scene) -> Vec<u8> {
    emit_with(scene, TextureFormat::Rgba8888)
}

// ---------------------------------------------------------------------------------------------
// Rendering
// ---------------------------------------------------------------------------------------------

/// A rendered frame: colours and u16 depth (65535 where nothing was drawn).
struct Frame<C> {
    w: usize,
    color: Vec<C>,
    depth: Vec<u16>,
}

impl<C: Copy> Frame<C> {
    fn at(&self, x: usize, y: usize) -> C {
        self.color[y * self.w + x]
    }
    fn drawn(&self, x: usize, y: usize) -> bool {
        self.depth[y * self.w + x] != u16::MAX
    }
}

fn render<C: FrameColor, const L: usize>(
    model: &Model<'_>,
    cam: &Camera,
    lights: &Lights<L>,
    opts: &RenderOptions,
    (w, h): (u16, u16),
    bg: [u8; 3],
) -> Frame<C> {
    let n = w as usize * h as usize;
    let mut color = vec![C::from_rgb888(bg); n];
    let mut depth = vec![0u16; n];
    let mut band = Band::new(&mut color[..], &mut depth[..], w, h, 0).unwrap();
    band.clear(C::from_rgb888(bg));
    soft3d::Renderer::new(cam, lights, *opts)
        .draw(&mut band, model, Mat4::IDENTITY, &mut soft3d::Scratch::none())
        .unwrap();
    Frame { w: w as usize, color, depth }
}

fn unlit() -> RenderOptions {
    RenderOptions { shading: Shading::Unlit, ..Default::default() }
}

fn no_lights() -> Lights<1> {
    Lights::new(Vec3::ZERO)
}

/// An orthographic camera looking along +z at a `w` x `h` window centred on the origin, so that
/// with a `w` x `h` frame one world unit is one pixel.
fn ortho(w: f32, h: f32) -> Camera {
    Camera::orthographic(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, w, h, 1.0, 100.0).unwrap()
}

fn rgb(c: Rgb888) -> [u8; 3] {
    [c.r(), c.g(), c.b()]
}

// ---------------------------------------------------------------------------------------------
// f64 geometry (glam's f64 types are not enabled in this crate: a few lines of our own)
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct DVec3 {
    x: f64,
    y: f64,
    z: f64,
}

impl DVec3 {
    const fn new(x: f64, y: f64, z: f64) -> Self {
        DVec3 { x, y, z }
    }
    fn from(a: [f64; 3]) -> Self {
        DVec3::new(a[0], a[1], a[2])
    }
    fn of(v: Vec3) -> Self {
        DVec3::new(v.x as f64, v.y as f64, v.z as f64)
    }
    fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    fn cross(self, o: Self) -> Self {
        DVec3::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }
    fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    fn normalize(self) -> Self {
        self / self.length()
    }
}

impl std::ops::Add for DVec3 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        DVec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl std::ops::Sub for DVec3 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        DVec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl std::ops::Mul<f64> for DVec3 {
    type Output = Self;
    fn mul(self, k: f64) -> Self {
        DVec3::new(self.x * k, self.y * k, self.z * k)
    }
}

impl std::ops::Div<f64> for DVec3 {
    type Output = Self;
    fn div(self, k: f64) -> Self {
        DVec3::new(self.x / k, self.y / k, self.z / k)
    }
}

/// A 4x4 matrix in f64, rows `m[r]`, acting on column vectors.
#[derive(Clone, Copy, Debug)]
struct DMat4([[f64; 4]; 4]);

impl DMat4 {
    fn of(m: Mat4) -> Self {
        DMat4(core::array::from_fn(|r| m.row(r).to_array().map(f64::from)))
    }
    fn apply(&self, v: [f64; 4]) -> [f64; 4] {
        core::array::from_fn(|r| (0..4).map(|c| self.0[r][c] * v[c]).sum())
    }
    /// Gauss-Jordan elimination with partial pivoting.
    fn inverse(&self) -> Self {
        let mut a = self.0;
        let mut inv = [[0.0; 4]; 4];
        for (k, row) in inv.iter_mut().enumerate() {
            row[k] = 1.0;
        }
        for col in 0..4 {
            let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs())).unwrap();
            a.swap(col, pivot);
            inv.swap(col, pivot);
            let p = a[col][col];
            assert!(p != 0.0, "singular matrix");
            for c in 0..4 {
                a[col][c] /= p;
                inv[col][c] /= p;
            }
            for r in 0..4 {
                if r != col {
                    let f = a[r][col];
                    for c in 0..4 {
                        a[r][c] -= f * a[col][c];
                        inv[r][c] -= f * inv[col][c];
                    }
                }
            }
        }
        DMat4(inv)
    }
}

/// The camera's view-projection in f64, its inverse, and the frame size.
struct Rays {
    vp: DMat4,
    inv: DMat4,
    w: f64,
    h: f64,
}

impl Rays {
    fn new(cam: &Camera, (w, h): (u16, u16)) -> Self {
        let vp = DMat4::of(cam.view_projection());
        Rays { vp, inv: vp.inverse(), w: w as f64, h: h as f64 }
    }

    /// The ray through image point `(x, y)` (pixels, y down): origin on the near plane and
    /// direction to the far plane.
    fn ray(&self, x: f64, y: f64) -> (DVec3, DVec3) {
        let xn = x / (self.w / 2.0) - 1.0;
        let yn = 1.0 - y / (self.h / 2.0);
        let unproject = |z: f64| {
            let p = self.inv.apply([xn, yn, z, 1.0]);
            DVec3::new(p[0], p[1], p[2]) / p[3]
        };
        let a = unproject(-1.0);
        (a, unproject(1.0) - a)
    }

    /// The world point on the ray through `(x, y)` whose clip w is `w`.
    fn at_depth(&self, x: f64, y: f64, w: f64) -> DVec3 {
        let (o, d) = self.ray(x, y);
        let r = self.vp.0[3];
        let rv = DVec3::new(r[0], r[1], r[2]);
        let t = (w - rv.dot(o) - r[3]) / rv.dot(d);
        o + d * t
    }
}

/// A vertex as the renderer places it: projected in f32 exactly as `pipeline/vertex.rs` does, snapped
/// down to the 1/16-pixel grid (the documented convention), with its clip w.
#[derive(Clone, Copy, Debug)]
struct Snapped {
    x: f64,
    y: f64,
    w: f64,
}

fn snapped(cam: &Camera, p: Vec3, (w, h): (u16, u16)) -> Snapped {
    let c = cam.view_projection() * p.extend(1.0);
    let inv_w = 1.0 / c.w;
    let x = (c.x * inv_w + 1.0) * (w as f32 * 0.5);
    let y = (1.0 - c.y * inv_w) * (h as f32 * 0.5);
    Snapped { x: (x * 16.0).floor() as f64 / 16.0, y: (y * 16.0).floor() as f64 / 16.0, w: c.w as f64 }
}

/// Screen-space barycentrics of `(x, y)` in the triangle `t` (any winding).
fn barycentric(t: &[Snapped; 3], x: f64, y: f64) -> [f64; 3] {
    let e = |a: &Snapped, b: &Snapped| (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
    let area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
    [e(&t[1], &t[2]) / area, e(&t[2], &t[0]) / area, e(&t[0], &t[1]) / area]
}

/// Perspective-correct weights from screen-space barycentrics (weights / w, renormalised).
fn perspective(t: &[Snapped; 3], l: [f64; 3]) -> [f64; 3] {
    let q = [l[0] / t[0].w, l[1] / t[1].w, l[2] / t[2].w];
    let s = q[0] + q[1] + q[2];
    q.map(|v| v / s)
}

/// Distance in pixels from `(x, y)` to the inside of triangle `t` (0 inside).
fn outside_distance(t: &[Snapped; 3], x: f64, y: f64) -> f64 {
    let l = barycentric(t, x, y);
    let mut d: f64 = 0.0;
    for k in 0..3 {
        if l[k] < 0.0 {
            // Height of the triangle over the edge opposite vertex k.
            let (a, b) = (&t[(k + 1) % 3], &t[(k + 2) % 3]);
            let len = ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt();
            let area = ((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y)).abs();
            d = d.max(-l[k] * area / len);
        }
    }
    d
}

/// Ray / triangle intersection (Moller-Trumbore): barycentric weights of the hit point on the
/// triangle's plane (not clipped to the triangle).
fn ray_plane_weights(o: DVec3, d: DVec3, p: [DVec3; 3]) -> [f64; 3] {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let pv = d.cross(e2);
    let inv = 1.0 / e1.dot(pv);
    let tv = o - p[0];
    let u = tv.dot(pv) * inv;
    let v = d.dot(tv.cross(e1)) * inv;
    [1.0 - u - v, u, v]
}

/// Distance in texels from coordinate `s` (texels) to texel `i` on a ring of `n` texels.
fn cell_distance(s: f64, i: u32, n: u32) -> f64 {
    let n = n as f64;
    [-n, 0.0, n]
        .iter()
        .map(|k| {
            let lo = i as f64 + k;
            if s < lo {
                lo - s
            } else if s > lo + 1.0 {
                s - lo - 1.0
            } else {
                0.0
            }
        })
        .fold(f64::INFINITY, f64::min)
}

// ---------------------------------------------------------------------------------------------
// 1. Perspective correctness
// ---------------------------------------------------------------------------------------------

/// Texel size of the perspective test's texture.
const PERSPECTIVE_TEX: u32 = 256;

/// One pixel of the perspective test: what was drawn and what should have been.
#[derive(Clone, Copy, Debug)]
struct TexelCheck {
    x: usize,
    y: usize,
    /// Texel drawn (from the pixel's red and green).
    drawn: [u32; 2],
    /// Exact texel coordinates `(u·W, v·H)` of the pixel centre.
    exact: [f64; 2],
    /// Texels per pixel around this pixel (the larger of the steps to the next column and row).
    footprint: f64,
    /// Distance in texels from `exact` to the drawn texel (0 when it is the exact texel).
    error: f64,
    /// The same for the texel an affine (screen-linear) mapping would pick.
    affine_error: f64,
}

/// A large textured plane seen at a steep angle, for the perspective test.
struct Plane {
    name: &'static str,
    /// Corners: bottom-left, bottom-right, top-right, top-left as seen from the front, mapped to
    /// UV (0,0), (1,0), (1,1), (0,1).
    corners: [[f32; 3]; 4],
    eye: [f32; 3],
    target: [f32; 3],
}

/// The floor: 8 wide from z = 1 to z = 50, seen from 1.5 units above it looking diagonally
/// across it (so that depth changes along scanlines too); the far corner is ~30x farther than
/// the near ones and pixels near the horizon span ~25 texels.
const FLOOR: Plane = Plane {
    name: "floor",
    corners: [[-4.0, 0.0, 1.0], [4.0, 0.0, 1.0], [4.0, 0.0, 50.0], [-4.0, 0.0, 50.0]],
    eye: [-3.0, 1.5, -1.0],
    target: [2.0, 0.0, 14.0],
};

/// A wall (x = -1.5, facing +x) from z = 1 to z = 50 seen almost edge-on: each scanline crosses
/// the whole depth range, the worst case for sub-span stepping.
const WALL: Plane = Plane {
    name: "wall",
    corners: [[-1.5, -0.5, 1.0], [-1.5, -0.5, 50.0], [-1.5, 2.0, 50.0], [-1.5, 2.0, 1.0]],
    eye: [0.0, 0.75, -1.0],
    target: [0.0, 0.75, 14.0],
};

/// Renders `plane` with a 256x256 texture whose texel (i, j) (j from the bottom) is
/// (R, G) = (i, j), unlit, nearest, with each `subspan`, and checks every drawn pixel against
/// the exact mapping. Also prints the scene's numbers.
///
/// The exact UV of a pixel centre is the intersection, in f64, of its ray (from the inverse
/// view-projection) with the plane of the triangle the renderer draws: the triangle with its
/// vertices snapped to the 1/16-pixel grid (the documented convention). That plane differs
/// from the unsnapped one by up to ~1.5 texels where one pixel spans ~25 texels; the snapping
/// is not what this test is about.
fn texel_checks(plane: &Plane, subspans: &[u32]) -> Vec<Vec<TexelCheck>> {
    let n = PERSPECTIVE_TEX;
    let size = (320u16, 240u16);
    let tex = texture(n as u16, n as u16, |i, j| [i as u8, j as u8, 0, 255]);
    let mesh = quad(plane.corners, Some([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), None);
    let s = scene(vec![mesh], vec![material([1.0; 3], Some(0))], vec![tex]);
    let bytes = emit_rgba(&s);
    let model = Model::parse(&bytes).unwrap();
    let mesh = model.mesh(0).unwrap();
    let aspect = size.0 as f32 / size.1 as f32;
    let cam = Camera::perspective(plane.eye.into(), plane.target.into(), 0.8, aspect, 0.5, 100.0).unwrap();
    let rays = Rays::new(&cam, size);

    // The two triangles as drawn (snapped screen vertices and their world points), the
    // unsnapped world points, and the UVs.
    type Tri = ([Snapped; 3], [DVec3; 3], [DVec3; 3], [[f64; 2]; 3]);
    let tris: Vec<Tri> = (0..mesh.triangle_count())
        .map(|t| {
            let idx = mesh.triangle(t);
            let sv = idx.map(|i| snapped(&cam, mesh.position(i), size));
            for v in &sv {
                // No vertex is clipped (near plane, guard band): the drawn triangles are these.
                assert!(v.w > 0.5 && (v.x - 160.0).abs() < 900.0 && (v.y - 120.0).abs() < 900.0, "{v:?}");
            }
            let world = sv.map(|v| rays.at_depth(v.x, v.y, v.w));
            let unsnapped = idx.map(|i| DVec3::of(mesh.position(i)));
            let uv = idx.map(|i| mesh.uv(i).map(f64::from));
            (sv, world, unsnapped, uv)
        })
        .collect();
    let ws: Vec<f64> = tris.iter().flat_map(|t| t.0.map(|v| v.w)).collect();
    let w_ratio = ws.iter().cloned().fold(0.0, f64::max) / ws.iter().cloned().fold(f64::INFINITY, f64::min);

    // Exact texel coordinates of image point (px, py) on a plane through `p` with UVs `uv`.
    let exact = |p: [DVec3; 3], uv: [[f64; 2]; 3], px: f64, py: f64| {
        let (o, d) = rays.ray(px, py);
        let b = ray_plane_weights(o, d, p);
        [0, 1].map(|k| (b[0] * uv[0][k] + b[1] * uv[1][k] + b[2] * uv[2][k]) * n as f64)
    };

    let (w, h) = (size.0 as usize, size.1 as usize);
    // Per pixel centre inside a triangle: exact coordinates, footprint, affine coordinates.
    let mut reference = vec![None; w * h];
    let mut snapping: f64 = 0.0;
    for y in 0..h {
        for x in 0..w {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let Some(t) = tris.iter().find(|t| outside_distance(&t.0, px, py) < 1e-9) else { continue };
            let st = exact(t.1, t.3, px, py);
            let (right, down) = (exact(t.1, t.3, px + 1.0, py), exact(t.1, t.3, px, py + 1.0));
            let footprint = (0..2).map(|k| (right[k] - st[k]).abs().max((down[k] - st[k]).abs())).fold(0.0, f64::max);
            let l = barycentric(&t.0, px, py);
            let affine = [0, 1].map(|k| (l[0] * t.3[0][k] + l[1] * t.3[1][k] + l[2] * t.3[2][k]) * n as f64);
            let unsnapped = exact(t.2, t.3, px, py);
            snapping = snapping.max((unsnapped[0] - st[0]).abs()).max((unsnapped[1] - st[1]).abs());
            reference[y * w + x] = Some((st, footprint, affine));
        }
    }
    println!(
        "perspective, {}: far/near w ratio {w_ratio:.1}; snapped vs unsnapped plane: up to {snapping:.2} texels",
        plane.name
    );

    let err = |st: [f64; 2], ij: [u32; 2]| cell_distance(st[0], ij[0], n).max(cell_distance(st[1], ij[1], n));
    subspans
        .iter()
        .map(|&subspan| {
            let opts = RenderOptions { subspan, ..unlit() };
            let frame: Frame<Rgb888> = render(&model, &cam, &no_lights(), &opts, size, [0, 0, 255]);
            let mut checks = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    if !frame.drawn(x, y) {
                        continue;
                    }
                    let Some((exact, footprint, affine)) = reference[y * w + x] else {
                        panic!("{}: pixel ({x}, {y}) drawn outside the plane", plane.name);
                    };
                    let c = rgb(frame.at(x, y));
                    let drawn = [c[0] as u32, c[1] as u32];
                    checks.push(TexelCheck {
                        x,
                        y,
                        drawn,
                        exact,
                        footprint,
                        error: err(exact, drawn),
                        affine_error: err(affine, drawn),
                    });
                }
            }
            assert!(checks.len() > 20_000, "{}: only {} pixels drawn", plane.name, checks.len());
            checks
        })
        .collect()
}

fn worst(checks: &[TexelCheck], keep: impl Fn(&TexelCheck) -> bool) -> Option<TexelCheck> {
    checks.iter().filter(|c| keep(c)).copied().max_by(|a, b| a.error.total_cmp(&b.error))
}

/// Perspective-correct texture mapping: every drawn texel is the exact texel of its pixel
/// centre, or a neighbour when the exact UV is within 1/8 texel of it, wherever a pixel spans
/// at most 4 texels; everywhere (up to ~35 texels per pixel at the horizon), within 1/8 texel
/// plus 1/64 of the pixel's footprint. Sub-span stepping (4, 8, 16) is measured and loosely
/// bounded: within 1/8 texel plus half a sub-span's worth of texels.
#[test]
fn perspective_correct_texture_mapping() {
    let subspans = [1u32, 4, 8, 16];
    for plane in [&FLOOR, &WALL] {
        let all = texel_checks(plane, &subspans);
        for (subspan, checks) in subspans.iter().zip(&all) {
            let max_err = worst(checks, |_| true).unwrap();
            let fine = worst(checks, |c| c.footprint <= 4.0).unwrap();
            let off = checks.iter().filter(|c| c.error > 0.0).count();
            let mut by_footprint = [0f64; 6];
            for c in checks {
                let b = (c.footprint.log2().max(-1.0) + 1.0).min(5.0) as usize;
                by_footprint[b] = by_footprint[b].max(c.error);
            }
            println!(
                "perspective, {}: subspan {subspan:2}: {} pixels, max texel error {:.3} (pixel ({}, {}) drew \
                 texel {:?}, exact {:.3?}, {:.1} texels/px), {:.3} where <= 4 texels/px; by footprint \
                 <1/2,<1,<2,<4,<8,more: {by_footprint:.3?}; {off} pixels off their exact texel",
                plane.name,
                checks.len(),
                max_err.error,
                max_err.x,
                max_err.y,
                max_err.drawn,
                max_err.exact,
                max_err.footprint,
                fine.error
            );
            if *subspan == 1 {
                let affine = checks.iter().map(|c| c.affine_error).fold(0.0, f64::max);
                println!("perspective, {}: an affine mapping would be off by up to {affine:.1} texels", plane.name);
                assert!(affine > 20.0, "the scene does not exercise perspective correction");
                assert!(fine.error <= 0.125, "{fine:?}");
                let loose = worst(checks, |c| c.error > 0.125 + c.footprint / 64.0);
                assert!(loose.is_none(), "{loose:?}");
            } else {
                // Stepping linearly between exact values `subspan` pixels apart: the sampled point
                // stays within the sub-span.
                let px = checks.iter().map(|c| c.error / c.footprint).fold(0.0, f64::max);
                println!("perspective, {}: subspan {subspan:2}: worst sample offset {px:.2} px", plane.name);
                let loose = worst(checks, |c| c.error > 0.125 + c.footprint * *subspan as f64 / 2.0);
                assert!(loose.is_none(), "subspan {subspan}: {loose:?}");
            }
        }
    }
}

/// The strict rule (drawn texel within 1/8 texel of the exact UV) everywhere, including the
/// horizon where one pixel spans ~25 texels.
#[test]
// Regression: varyings_at once shifted the edge values to 15 bits before weighting them by 1/w,
// and floor pixel (60, 102) drew texel row 240 for an exact v·H of 239.75.
fn perspective_correct_texture_mapping_at_the_horizon() {
    for plane in [&FLOOR, &WALL] {
        let checks = &texel_checks(plane, &[1])[0];
        let max_err = worst(checks, |_| true).unwrap();
        assert!(max_err.error <= 0.125, "{}: {max_err:?}", plane.name);
    }
}

// ---------------------------------------------------------------------------------------------
// 2. Texture orientation
// ---------------------------------------------------------------------------------------------

/// A W x H quad exactly covering a W x H frame under an orthographic camera, UVs 0..1 with v = 0
/// at the bottom, reproduces an asymmetric image exactly and upright: frame row 0 is the top row
/// of the image file (nearest), and within 2 LSB with bilinear filtering (pixel centres are
/// texel centres).
#[test]
fn texture_is_upright_texel_to_pixel() {
    let (w, h) = (24u16, 16u16);
    let mut rng = Rng(7);
    // Image file order: rows from the top.
    let image: Vec<[u8; 4]> = (0..w as usize * h as usize).map(|_| [rng.byte(), rng.byte(), rng.byte(), 255]).collect();
    let pixel = |col: usize, row: usize| image[row * w as usize + col];
    assert!((0..w as usize).any(|c| pixel(c, 0) != pixel(c, h as usize - 1)), "the image must not be symmetric");
    let tex =
        TextureData { name: "image".into(), width: w, height: h, rgba: image.iter().flatten().copied().collect() };
    let mesh = screen_quad(w as f32, h as f32, [0.0, 0.0], [1.0, 1.0]);
    let s = scene(vec![mesh], vec![material([1.0; 3], Some(0))], vec![tex]);
    let bytes = emit_rgba(&s);
    let model = Model::parse(&bytes).unwrap();
    let cam = ortho(w as f32, h as f32);
    for filter in [Filter::Nearest, Filter::Bilinear] {
        let opts = RenderOptions { filter, ..unlit() };
        let frame: Frame<Rgb888> = render(&model, &cam, &no_lights(), &opts, (w, h), [0, 0, 0]);
        for row in 0..h as usize {
            for col in 0..w as usize {
                assert!(frame.drawn(col, row), "({col}, {row}) not drawn");
                let (got, want) = (rgb(frame.at(col, row)), pixel(col, row));
                let diff = (0..3).map(|k| (got[k] as i32 - want[k] as i32).abs()).max().unwrap();
                // Bilinear: the interpolated UV lands a few 1/65536 texel from the texel centre,
                // and the 8-bit weights are truncated (see the bilinear test): up to 2 LSB.
                let tolerance = if filter == Filter::Nearest { 0 } else { 2 };
                assert!(diff <= tolerance, "{filter:?}: frame ({col}, {row}) = {got:?}, image {want:?}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Wrap modes, negative UVs, bilinear filtering
// ---------------------------------------------------------------------------------------------

/// Texel index `i` folded into `0..n` by a wrap mode, written from the spec / GL definitions:
/// repeat is `i mod n` (negative too), clamp is the edge texel, mirror is repeat with every
/// other copy reversed (`0 1 2 3 3 2 1 0 0 1 ...`).
fn fold(i: i64, n: i64, wrap: Wrap) -> i64 {
    match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n {
                m
            } else {
                2 * n - 1 - m
            }
        }
    }
}

/// Rgba8888 texels stored as in `.s3d` (bottom row first) with texel (i, j) = (i, j, 7, 255).
fn index_texels(w: u16, h: u16) -> Vec<u8> {
    (0..h as u32).flat_map(|j| (0..w as u32).flat_map(move |i| [i as u8, j as u8, 7, 255])).collect()
}

fn fixed(texels: f64) -> i32 {
    (texels * 65536.0) as i32
}

#[test]
fn wrap_modes_and_negative_uvs_by_hand() {
    let bytes = index_texels(4, 3);
    let tex = Texture { width: 4, height: 3, format: TextureFormat::Rgba8888, texels: &bytes };
    let modes = [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror];
    // Texel coordinate u·W (W = 4) -> expected texel column for repeat, clamp, mirror.
    let u_table: [(f64, [u8; 3]); 12] = [
        (-8.5, [3, 0, 0]),
        (-4.5, [3, 0, 3]),
        (-3.5, [0, 0, 3]),
        (-0.25, [3, 0, 0]),
        (0.0, [0, 0, 0]),
        (3.75, [3, 3, 3]),
        (4.0, [0, 3, 3]),
        (5.5, [1, 3, 2]),
        (7.75, [3, 3, 0]),
        (8.0, [0, 3, 0]),
        (9.5, [1, 3, 1]),
        (1000.5, [0, 3, 0]),
    ];
    // Texel coordinate v·H (H = 3, not a power of two) -> expected texel row from the bottom.
    let v_table: [(f64, [u8; 3]); 7] = [
        (-3.5, [2, 0, 2]),
        (-0.5, [2, 0, 0]),
        (1.5, [1, 1, 1]),
        (3.25, [0, 2, 2]),
        (4.75, [1, 2, 1]),
        (6.125, [0, 2, 0]),
        (-6.125, [2, 0, 0]),
    ];
    for (m, &mode) in modes.iter().enumerate() {
        let across = Sampler::new(tex, mode, Wrap::Repeat, Filter::Nearest);
        for &(s, want) in &u_table {
            assert_eq!(across.sample(fixed(s), fixed(1.5))[..2], [want[m], 1], "{mode:?} u·W = {s}");
            assert_eq!(fold(s.floor() as i64, 4, mode), want[m] as i64, "reference fold {mode:?} {s}");
        }
        let down = Sampler::new(tex, Wrap::Repeat, mode, Filter::Nearest);
        for &(t, want) in &v_table {
            assert_eq!(down.sample(fixed(2.5), fixed(t))[..2], [2, want[m]], "{mode:?} v·H = {t}");
            assert_eq!(fold(t.floor() as i64, 3, mode), want[m] as i64, "reference fold {mode:?} {t}");
        }
    }
    // A one-texel texture is that texel everywhere, in every mode.
    let one = [9u8, 8, 7, 255];
    let single = Texture { width: 1, height: 1, format: TextureFormat::Rgba8888, texels: &one };
    for mode in modes {
        for filter in [Filter::Nearest, Filter::Bilinear] {
            let sampler = Sampler::new(single, mode, mode, filter);
            for s in [-5.3, -0.5, 0.0, 0.7, 12.9] {
                assert_eq!(sampler.sample(fixed(s), fixed(-s)), one, "{mode:?} {filter:?} {s}");
            }
        }
    }
}

/// A 12 x 9 quad with UVs from (-1, -1) to (2, 2) and a 4 x 3 texture, one texel per pixel:
/// pixel (c, r) samples texel column c - 4 and row (from the bottom) 5 - r before wrapping.
#[test]
fn wrap_modes_on_a_rendered_quad_with_uvs_from_minus_one_to_two() {
    let (tw, th) = (4u16, 3u16);
    let (w, h) = (3 * tw, 3 * th);
    let tex = texture(tw, th, |i, j| [40 * i as u8 + 10, 60 * j as u8 + 20, 200, 255]);
    let modes = [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror];
    let scene_wrap = |m: Wrap| match m {
        Wrap::Repeat => SceneWrap::Repeat,
        Wrap::Clamp => SceneWrap::Clamp,
        Wrap::Mirror => SceneWrap::Mirror,
    };
    for wrap_u in modes {
        for wrap_v in modes {
            let mat =
                MaterialData { wrap_u: scene_wrap(wrap_u), wrap_v: scene_wrap(wrap_v), ..material([1.0; 3], Some(0)) };
            let mesh = screen_quad(w as f32, h as f32, [-1.0, -1.0], [2.0, 2.0]);
            let s = scene(vec![mesh], vec![mat], vec![tex.clone()]);
            let bytes = emit_rgba(&s);
            let model = Model::parse(&bytes).unwrap();
            let frame: Frame<Rgb888> =
                render(&model, &ortho(w as f32, h as f32), &no_lights(), &unlit(), (w, h), [0; 3]);
            for r in 0..h as usize {
                for c in 0..w as usize {
                    let i = fold(c as i64 - 4, tw as i64, wrap_u) as u8;
                    let j = fold(5 - r as i64, th as i64, wrap_v) as u8;
                    let want = [40 * i + 10, 60 * j + 20, 200];
                    assert_eq!(rgb(frame.at(c, r)), want, "{wrap_u:?}/{wrap_v:?} pixel ({c}, {r})");
                }
            }
        }
    }
}

/// Bilinear filtering against an f64 implementation of the spec: sample point
/// `(u·W - 0.5, v·H - 0.5)`, the four surrounding texels (wrapped), weights from the fractional
/// parts, each channel unrounded.
fn bilinear_reference(texels: &[u8], w: u16, h: u16, wraps: (Wrap, Wrap), u: i32, v: i32) -> [f64; 4] {
    let s = u as f64 / 65536.0 - 0.5;
    let t = v as f64 / 65536.0 - 0.5;
    let (i0, j0) = (s.floor(), t.floor());
    let (fu, fv) = (s - i0, t - j0);
    let texel = |di: i64, dj: i64| {
        let i = fold(i0 as i64 + di, w as i64, wraps.0) as usize;
        let j = fold(j0 as i64 + dj, h as i64, wraps.1) as usize;
        let at = 4 * (j * w as usize + i);
        [0, 1, 2, 3].map(|k| texels[at + k] as f64)
    };
    let (t00, t10, t01, t11) = (texel(0, 0), texel(1, 0), texel(0, 1), texel(1, 1));
    [0, 1, 2, 3].map(|k| (1.0 - fv) * ((1.0 - fu) * t00[k] + fu * t10[k]) + fv * ((1.0 - fu) * t01[k] + fu * t11[k]))
}

/// Largest difference (per channel, in 8-bit steps) between `Sampler` and the f64 reference
/// over many random textures and UVs.
fn bilinear_max_error(cases: usize, samples: usize, range: i64) -> (f64, i32, Option<String>) {
    let mut rng = Rng(0xB111);
    let modes = [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror];
    let (mut max_real, mut max_rounded, mut worst) = (0.0f64, 0i32, None);
    for _ in 0..cases {
        let (w, h) = (rng.range(1, 9) as u16, rng.range(1, 9) as u16);
        let wraps = (modes[rng.range(0, 2) as usize], modes[rng.range(0, 2) as usize]);
        // Mostly high-contrast texels (0 or 255), where weight errors show most.
        let texels: Vec<u8> = (0..4 * w as usize * h as usize)
            .map(|_| match rng.range(0, 3) {
                0 => 0,
                1 => 255,
                _ => rng.byte(),
            })
            .collect();
        let tex = Texture { width: w, height: h, format: TextureFormat::Rgba8888, texels: &texels };
        let sampler = Sampler::new(tex, wraps.0, wraps.1, Filter::Bilinear);
        for _ in 0..samples {
            let u = rng.range(-range * w as i64 * 65536, range * w as i64 * 65536) as i32;
            let v = rng.range(-range * h as i64 * 65536, range * h as i64 * 65536) as i32;
            let got = sampler.sample(u, v);
            let want = bilinear_reference(&texels, w, h, wraps, u, v);
            for k in 0..4 {
                let real = (got[k] as f64 - want[k]).abs();
                let rounded = (got[k] as i32 - (want[k] + 0.5).floor() as i32).abs();
                if rounded > max_rounded {
                    worst = Some(format!(
                        "{w}x{h} {wraps:?} u={u} v={v} channel {k}: got {}, exact {:.3}",
                        got[k], want[k]
                    ));
                }
                max_real = max_real.max(real);
                max_rounded = max_rounded.max(rounded);
            }
        }
    }
    (max_real, max_rounded, worst)
}

/// A looser bound over a wider range of coordinates (the strict 1 LSB test follows).
#[test]
fn bilinear_matches_f64_reference_within_two_lsb() {
    // Texel coordinates within +-3 texture sizes of the origin, in 16.16.
    let (real, rounded, worst) = bilinear_max_error(400, 400, 3);
    println!("bilinear: max error {real:.3} (vs exact), {rounded} LSB (vs rounded exact); worst {worst:?}");
    assert!(real < 2.5 && rounded <= 2, "{worst:?}");
}

/// The required bound: within 1 LSB of the (rounded) exact value.
#[test]
// Regression: the sampler once truncated its 8-bit weights instead of rounding them (2 LSB off).
fn bilinear_matches_f64_reference_within_one_lsb() {
    // Minimal case: 2x2 texture, red 0 at (0, 0) and 255 elsewhere, sampled 255/65536 texel
    // right of and above the centre of texel (0, 0). Exact: 1.98 -> 2; the sampler gives 0.
    let texels = [0, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255];
    let tex = Texture { width: 2, height: 2, format: TextureFormat::Rgba8888, texels: &texels };
    let (u, v) = ((1 << 15) + 255, (1 << 15) + 255);
    let exact = bilinear_reference(&texels, 2, 2, (Wrap::Clamp, Wrap::Clamp), u, v)[0];
    let got = Sampler::new(tex, Wrap::Clamp, Wrap::Clamp, Filter::Bilinear).sample(u, v)[0];
    assert!((got as f64 - exact).abs() <= 1.0, "got {got}, exact {exact:.3}");
    let (real, rounded, worst) = bilinear_max_error(400, 400, 3);
    assert!(rounded <= 1, "max {real:.3}: {worst:?}");
}

// ---------------------------------------------------------------------------------------------
// 4. Lighting
// ---------------------------------------------------------------------------------------------

/// `c · light` with light in 16.16 as the renderer rounds it (`pipeline/vertex.rs`: light varyings are
/// `(light · colour/255 · 65536) as i32`; the pixel is `(c · l + 2^15) >> 16`).
fn modulate_ref(c: u8, l: i64) -> u8 {
    ((c as i64 * l.clamp(0, 1 << 16) + (1 << 15)) >> 16) as u8
}

/// Light (one channel) in 16.16 as the renderer converts it: `(x · 1.0 · 65536) as i32`.
fn light_fixed(x: f32) -> i64 {
    (x * 1.0 * 65536.0) as i32 as i64
}

/// The lighting scene: a white untextured unit sphere of 64 x 32 segments at the origin seen
/// (or as given) from 4 units away, frame 200 x 200, one directional light (no ambient).
struct SphereScene {
    bytes: Vec<u8>,
    cam: Camera,
    size: (u16, u16),
    lights: Lights<1>,
    /// Unit vector towards the light.
    to_light: DVec3,
}

fn sphere_scene(nu: u32, nv: u32) -> SphereScene {
    let mesh = uv_sphere([0.0; 3], 1.0, nu, nv);
    let s = scene(vec![mesh], vec![material([1.0; 3], None)], vec![]);
    let size = (200u16, 200u16);
    let cam = Camera::perspective(Vec3::new(0.0, 1.2, -3.8), Vec3::ZERO, 0.8, 1.0, 0.5, 20.0).unwrap();
    let dir = Vec3::new(0.6, -0.5, 0.9);
    let mut lights = Lights::new(Vec3::ZERO);
    lights.push(Lights::<1>::directional(dir, 1.0)).unwrap();
    SphereScene { bytes: emit_rgba(&s), cam, size, lights, to_light: (DVec3::of(dir) * -1.0).normalize() }
}

/// Per pixel, the front-facing triangles (as the renderer places them) whose area is within
/// 0.1 px of the pixel centre.
fn triangle_candidates(model: &Model<'_>, cam: &Camera, size: (u16, u16)) -> Vec<Vec<u32>> {
    let mesh = model.mesh(0).unwrap();
    let (w, h) = (size.0 as i64, size.1 as i64);
    let mut cands = vec![Vec::new(); (w * h) as usize];
    for t in 0..mesh.triangle_count() {
        let sv = mesh.triangle(t).map(|i| snapped(cam, mesh.position(i), size));
        let area = (sv[1].x - sv[0].x) * (sv[2].y - sv[0].y) - (sv[2].x - sv[0].x) * (sv[1].y - sv[0].y);
        if area >= 0.0 {
            continue; // back face (front faces are clockwise in the y-down picture)
        }
        let (x0, x1) =
            (sv.iter().map(|v| v.x).fold(f64::INFINITY, f64::min), sv.iter().map(|v| v.x).fold(0.0, f64::max));
        let (y0, y1) =
            (sv.iter().map(|v| v.y).fold(f64::INFINITY, f64::min), sv.iter().map(|v| v.y).fold(0.0, f64::max));
        for y in (y0.floor() as i64 - 1).max(0)..=(y1.ceil() as i64).min(h - 1) {
            for x in (x0.floor() as i64 - 1).max(0)..=(x1.ceil() as i64).min(w - 1) {
                if outside_distance(&sv, x as f64 + 0.5, y as f64 + 0.5) <= 0.1 {
                    cands[(y * w + x) as usize].push(t);
                }
            }
        }
    }
    cands
}

/// Phong errors of the sphere of `nu` x `nv` segments, over every drawn pixel more than 1.5 px
/// from the silhouette: (pixels, max error against the exact sphere, max error against the
/// mesh's own interpolated normal). The exact sphere normal is taken where the pixel centre's
/// ray meets the sphere; the mesh normal is the normalised perspective-correct interpolation
/// of the (radial) vertex normals where the ray meets the drawn triangle, i.e. the direction
/// of that point from the centre.
fn phong_errors(nu: u32, nv: u32) -> (usize, f64, f64) {
    let sc = sphere_scene(nu, nv);
    let model = Model::parse(&sc.bytes).unwrap();
    let mesh = model.mesh(0).unwrap();
    let cands = triangle_candidates(&model, &sc.cam, sc.size);
    let opts = RenderOptions { shading: Shading::Phong, ..Default::default() };
    let frame: Frame<Rgb888> = render(&model, &sc.cam, &sc.lights, &opts, sc.size, [1, 2, 3]);
    let rays = Rays::new(&sc.cam, sc.size);
    let eye = DVec3::of(sc.cam.eye);
    // The sphere is centred on the view axis: its silhouette is a circle around the image
    // centre of radius f · tan(asin(r / distance)).
    let f = sc.size.1 as f64 / 2.0 * sc.cam.projection.y_axis.y as f64;
    let silhouette = f * (1.0 / eye.length()).asin().tan();
    let (cx, cy) = (sc.size.0 as f64 / 2.0, sc.size.1 as f64 / 2.0);
    let (mut checked, mut sphere_err, mut mesh_err) = (0, 0.0f64, 0.0f64);
    let w = sc.size.0 as usize;
    for y in 0..sc.size.1 as usize {
        for x in 0..w {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let rho = ((px - cx).powi(2) + (py - cy).powi(2)).sqrt();
            if (rho - silhouette).abs() < 1.5 {
                continue;
            }
            let inside = rho < silhouette;
            assert_eq!(frame.drawn(x, y), inside, "{nu}x{nv}: pixel ({x}, {y}) coverage");
            if !inside {
                assert_eq!(rgb(frame.at(x, y)), [1, 2, 3]);
                continue;
            }
            let got = rgb(frame.at(x, y));
            assert!(got[0] == got[1] && got[1] == got[2], "white light on white: {got:?}");
            let got = got[0] as f64;
            let (o, d) = rays.ray(px, py);
            // Exact sphere: |o + t d|^2 = 1, nearest root.
            let (a, b, c) = (d.dot(d), 2.0 * o.dot(d), o.dot(o) - 1.0);
            let t = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
            let n = (o + d * t).normalize();
            let err = (got - n.dot(sc.to_light).max(0.0) * 255.0).abs();
            assert!(err <= 3.0, "{nu}x{nv}: pixel ({x}, {y}) = {got}, {err:.2} from the exact sphere");
            sphere_err = sphere_err.max(err);
            // The mesh: the best of the triangles drawn around this pixel.
            let err = cands[y * w + x]
                .iter()
                .map(|&t| {
                    let p = mesh.triangle(t).map(|i| DVec3::of(mesh.position(i)));
                    let b = ray_plane_weights(o, d, p);
                    let hit = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
                    (got - hit.normalize().dot(sc.to_light).max(0.0) * 255.0).abs()
                })
                .fold(f64::INFINITY, f64::min);
            mesh_err = mesh_err.max(err);
            checked += 1;
        }
    }
    (checked, sphere_err, mesh_err)
}

/// Phong: every drawn pixel (more than 1.5 px from the silhouette) is `max(0, N·L) · 255`
/// within 2/255, N the exact sphere normal where the pixel centre's ray meets the sphere. With
/// 64 x 32 segments the mesh itself is up to ~2.2/255 away from the sphere near the silhouette
/// (its facets lie inside the sphere, and the ray meets them at a grazing angle), so that bound
/// is asserted for 128 x 64 segments; for both, the renderer is within 1.5/255 of the mesh's
/// own normalised interpolated normal.
#[test]
fn phong_matches_the_exact_sphere() {
    for (nu, nv) in [(64, 32), (128, 64)] {
        let (checked, sphere, mesh) = phong_errors(nu, nv);
        println!(
            "phong {nu}x{nv}: {checked} pixels, max error {sphere:.3}/255 from the exact sphere, {mesh:.3}/255 \
             from the mesh's interpolated normal"
        );
        assert!(checked > 8000, "{checked}");
        assert!(mesh <= 1.5, "{nu}x{nv}: {mesh}");
        if nu >= 128 {
            assert!(sphere <= 2.0, "{nu}x{nv}: {sphere}");
        }
    }
}

/// Flat: every drawn pixel is, exactly, the light of its face from the world-space face normal
/// (`Lights::at` at the centroid, converted to 16.16 and applied as the renderer rounds).
/// Gouraud: the perspective-correct interpolation of the per-vertex light values, within 1 LSB.
#[test]
fn flat_and_gouraud_match_their_definitions() {
    let sc = sphere_scene(64, 32);
    let model = Model::parse(&sc.bytes).unwrap();
    let mesh = model.mesh(0).unwrap();
    let cands = triangle_candidates(&model, &sc.cam, sc.size);
    let normals = normal_matrix(&Mat4::IDENTITY);
    let (w, h) = (sc.size.0 as usize, sc.size.1 as usize);

    // Flat.
    let face: Vec<u8> = (0..mesh.triangle_count())
        .map(|t| {
            let p = mesh.triangle(t).map(|i| mesh.position(i));
            let n = normalize_or_zero((p[2] - p[0]).cross(p[1] - p[0]));
            modulate_ref(255, light_fixed(sc.lights.at((p[0] + p[1] + p[2]) / 3.0, n).x))
        })
        .collect();
    let opts = RenderOptions { shading: Shading::Flat, ..Default::default() };
    let frame: Frame<Rgb888> = render(&model, &sc.cam, &sc.lights, &opts, sc.size, [1, 2, 3]);
    let (mut checked, mut unique, mut babylon) = (0, 0, 0i32);
    for y in 0..h {
        for x in 0..w {
            if !frame.drawn(x, y) {
                continue;
            }
            let c = &cands[y * w + x];
            let got = rgb(frame.at(x, y));
            assert!(!c.is_empty(), "pixel ({x}, {y}) drawn outside every front face");
            assert!(c.iter().any(|&t| got == [face[t as usize]; 3]), "flat pixel ({x}, {y}) = {got:?}, faces {c:?}");
            // Babylon's rounding of the exact face light: floor(N·L · 255 + 0.5).
            if let [t] = c[..] {
                let p = mesh.triangle(t).map(|i| DVec3::of(mesh.position(i)));
                let n = (p[2] - p[0]).cross(p[1] - p[0]).normalize();
                let exact = (n.dot(sc.to_light).max(0.0) * 255.0 + 0.5).floor() as i32;
                babylon = babylon.max((exact - got[0] as i32).abs());
                unique += 1;
            }
            checked += 1;
        }
    }
    println!("flat: {checked} pixels ({unique} inside one face) exact; max difference from f64 face light {babylon}");
    assert!(checked > 8000 && unique > checked * 3 / 4 && babylon <= 1, "{checked} {unique} {babylon}");

    // Gouraud.
    let vertex_light = |i: u32| {
        let n = normalize_or_zero(normals * mesh.normal(i));
        light_fixed(sc.lights.at(mesh.position(i), n).x) as f64
    };
    let opts = RenderOptions { shading: Shading::Gouraud, ..Default::default() };
    let frame: Frame<Rgb888> = render(&model, &sc.cam, &sc.lights, &opts, sc.size, [1, 2, 3]);
    let (mut checked, mut max_err) = (0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            if !frame.drawn(x, y) {
                continue;
            }
            let got = rgb(frame.at(x, y))[0] as f64;
            let err = cands[y * w + x]
                .iter()
                .map(|&t| {
                    let idx = mesh.triangle(t);
                    let sv = idx.map(|i| snapped(&sc.cam, mesh.position(i), sc.size));
                    let b = perspective(&sv, barycentric(&sv, x as f64 + 0.5, y as f64 + 0.5));
                    let l: f64 = (0..3).map(|k| b[k] * vertex_light(idx[k])).sum();
                    (got - 255.0 * l / 65536.0).abs()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(err < 1.5, "gouraud pixel ({x}, {y}) = {got}: {err:.3} from the interpolated light");
            max_err = max_err.max(err);
            checked += 1;
        }
    }
    println!("gouraud: {checked} pixels, max error {max_err:.3} LSB from the exact interpolation");
    assert!(checked > 8000);
}

/// A point light has no distance falloff: scaling the whole scene (quad, light position,
/// camera) by 8 and 64 moves the light 8 and 64 times farther from every point with every
/// direction unchanged, and the picture stays the same: bit for bit with flat and Gouraud
/// shading (powers of two scale f32 exactly), within 1 LSB with integer per-pixel lighting.
/// The centre pixel is `N·L · 255` whatever the distance.
#[test]
fn point_light_has_no_falloff() {
    let size = (32u16, 32u16);
    let light = Vec3::new(10.0, 6.0, -12.0);
    for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
        let mut frames: Vec<Frame<Rgb888>> = Vec::new();
        for k in [1.0f32, 8.0, 64.0] {
            let mesh = screen_quad(32.0 * k, 32.0 * k, [0.0, 0.0], [1.0, 1.0]);
            let s = scene(vec![mesh], vec![material([1.0; 3], None)], vec![]);
            let bytes = emit_rgba(&s);
            let model = Model::parse(&bytes).unwrap();
            let cam =
                Camera::orthographic(Vec3::new(0.0, 0.0, -10.0 * k), Vec3::ZERO, 32.0 * k, 32.0 * k, k, 100.0 * k)
                    .unwrap();
            let mut lights = Lights::<1>::new(Vec3::ZERO);
            lights.push(Lights::<1>::point(light * k, 1.0)).unwrap();
            let opts = RenderOptions { shading, ..Default::default() };
            frames.push(render(&model, &cam, &lights, &opts, size, [0, 0, 0]));
        }
        let centre = |f: &Frame<Rgb888>| rgb(f.at(16, 15))[0];
        // Pixel (16, 15) is centred on world (0.5, 0.5, 0) (times k); N = -z.
        let p = DVec3::new(0.5, 0.5, 0.0);
        let exact = (DVec3::of(light) - p).normalize().dot(DVec3::new(0.0, 0.0, -1.0)) * 255.0;
        let mut max_diff = 0;
        for f in &frames[1..] {
            for i in 0..f.color.len() {
                let d = (0..3)
                    .map(|c| (rgb(f.color[i])[c] as i32 - rgb(frames[0].color[i])[c] as i32).abs())
                    .max()
                    .unwrap();
                max_diff = max_diff.max(d);
            }
            if shading == Shading::Phong {
                assert!((centre(f) as f64 - exact).abs() <= 1.0, "{} vs {exact:.2}", centre(f));
            }
        }
        println!("point light, {shading:?}: largest change over distances x1, x8, x64: {max_diff}");
        assert!(frames[0].color.iter().any(|c| c.r() > 100), "the quad must be lit");
        let bound = if shading == Shading::Phong { 1 } else { 0 };
        assert!(max_diff <= bound, "{shading:?}: {max_diff}");
    }
}

/// Lighting never changes alpha: with every shading and light set (unlit, dark, half-lit,
/// over-bright, ambient), the transparent texels of a cut-out texture stay transparent (neither
/// colour nor depth written) and every opaque texel is drawn, dark where unlit: the cut-out
/// shape is the same in every case. Checked with Rgba8888 and Rgba5551 textures.
#[test]
fn lighting_never_changes_the_cut_out() {
    let (tw, th) = (8u16, 8u16);
    let (w, h) = (16u16, 16u16);
    let opaque = |i: u32, j: u32| (i * 3 + j * 5) % 7 >= 3;
    let tex = texture(tw, th, |i, j| {
        let a = if opaque(i, j) { 255 } else { 0 };
        [200 - 20 * i as u8, 100 + 15 * j as u8, 180, a]
    });
    // Normals bent from -x on the left to +x on the right: with light from +x, the left half
    // is dark and the right half lit (Gouraud and Phong).
    let s2 = std::f32::consts::FRAC_1_SQRT_2;
    let (left, right) = ([-s2, 0.0, -s2], [s2, 0.0, -s2]);
    let (x, y) = (w as f32 / 2.0, h as f32 / 2.0);
    let mesh = quad(
        [[-x, -y, 0.0], [x, -y, 0.0], [x, y, 0.0], [-x, y, 0.0]],
        Some([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        Some([left, right, right, left]),
    );
    let s = scene(vec![mesh], vec![material([1.0; 3], Some(0))], vec![tex]);
    let mut light_sets: Vec<(&str, Lights<2>)> = Vec::new();
    light_sets.push(("none", Lights::new(Vec3::ZERO)));
    let mut half = Lights::new(Vec3::ZERO);
    half.push(Lights::<2>::directional(Vec3::new(-1.0, 0.0, 0.0), 1.0)).unwrap();
    light_sets.push(("half-lit", half));
    let mut bright = Lights::new(Vec3::splat(0.5));
    bright.push(Lights::<2>::point(Vec3::new(20.0, 3.0, -2.0), 4.0)).unwrap();
    bright.push(Lights::<2>::directional(Vec3::new(0.0, 0.0, 1.0), 3.0)).unwrap();
    light_sets.push(("over-bright", bright));
    light_sets.push(("ambient", Lights::new(Vec3::splat(0.3))));
    let bg = [1, 2, 250];
    for format in [TextureFormat::Rgba8888, TextureFormat::Rgba5551] {
        let bytes = emit_with(&s, format);
        let model = Model::parse(&bytes).unwrap();
        for (name, lights) in &light_sets {
            for shading in [Shading::Unlit, Shading::Flat, Shading::Gouraud, Shading::Phong] {
                let opts = RenderOptions { shading, ..Default::default() };
                let frame: Frame<Rgb888> = render(&model, &ortho(w as f32, h as f32), lights, &opts, (w, h), bg);
                let (mut black, mut lit) = (0, 0);
                for r in 0..h as usize {
                    for c in 0..w as usize {
                        let (i, j) = (c as u32 / 2, th as u32 - 1 - r as u32 / 2);
                        let what = format!("{format:?} {name} {shading:?} pixel ({c}, {r})");
                        assert_eq!(frame.drawn(c, r), opaque(i, j), "{what}");
                        if !opaque(i, j) {
                            assert_eq!(rgb(frame.at(c, r)), bg, "{what}");
                        } else if rgb(frame.at(c, r)).iter().all(|&v| v < 24) {
                            black += 1;
                        } else {
                            lit += 1;
                        }
                    }
                }
                if *name == "half-lit" && matches!(shading, Shading::Gouraud | Shading::Phong) {
                    assert!(black > 20 && lit > 20, "{format:?} {shading:?}: not half-lit ({black} dark, {lit} lit)");
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 5. Frame formats and dithering
// ---------------------------------------------------------------------------------------------

/// A small scene using every part of the shading path: a textured quad behind a coloured
/// sphere, one directional light plus ambient, 64 x 48.
fn format_scene() -> (Vec<u8>, Camera, Lights<2>) {
    let mut rng = Rng(55);
    let tex = texture(16, 16, |_, _| [rng.byte(), rng.byte(), rng.byte(), 255]);
    let back = quad(
        [[-3.0, -2.0, 2.0], [3.0, -2.0, 2.0], [3.0, 2.0, 2.0], [-3.0, 2.0, 2.0]],
        Some([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        None,
    );
    let mut ball = uv_sphere([0.3, 0.0, 0.0], 1.0, 24, 12);
    ball.submeshes[0].material = Some(1);
    let s = scene(vec![back, ball], vec![material([1.0; 3], Some(0)), material([0.9, 0.5, 0.2], None)], vec![tex]);
    let cam = Camera::perspective(Vec3::new(0.0, 0.5, -4.0), Vec3::ZERO, 0.9, 64.0 / 48.0, 0.5, 20.0).unwrap();
    let mut lights = Lights::new(Vec3::splat(0.1));
    lights.push(Lights::<2>::directional(Vec3::new(0.4, -0.6, 1.0), 0.9)).unwrap();
    (emit_rgba(&s), cam, lights)
}

/// Renders the format scene into `C` and checks every pixel against `C::from_rgb888` of the
/// Rgb888 render; returns the frame.
fn same_as_rgb888<C: FrameColor + PartialEq + std::fmt::Debug>(opts: &RenderOptions) -> Vec<C> {
    let (bytes, cam, lights) = format_scene();
    let model = Model::parse(&bytes).unwrap();
    let size = (64u16, 48u16);
    let bg = [30, 60, 90];
    let reference: Frame<Rgb888> = render(&model, &cam, &lights, opts, size, bg);
    let frame: Frame<C> = render(&model, &cam, &lights, opts, size, bg);
    assert_eq!(frame.depth, reference.depth);
    for (k, (&got, &want)) in frame.color.iter().zip(&reference.color).enumerate() {
        assert_eq!(got, C::from_rgb888(rgb(want)), "{} pixel {k}", std::any::type_name::<C>());
    }
    assert!(reference.depth.iter().filter(|&&d| d != u16::MAX).count() > 1500);
    frame.color
}

/// Without dithering every format gets exactly `C::from_rgb888` of the Rgb888 picture, and
/// Rgb565Be holds the big-endian bytes of the Rgb565 value. Rgb888 and Gray8 (8 bits) ignore
/// the dither flag.
#[test]
fn every_format_is_the_conversion_of_the_rgb888_frame() {
    for opts in [
        RenderOptions { shading: Shading::Gouraud, ..Default::default() },
        RenderOptions { shading: Shading::Phong, filter: Filter::Bilinear, ..Default::default() },
        RenderOptions { shading: Shading::Flat, subspan: 8, ..Default::default() },
    ] {
        let rgb888 = same_as_rgb888::<Rgb888>(&opts);
        let rgb565 = same_as_rgb888::<Rgb565>(&opts);
        let gray = same_as_rgb888::<Gray8>(&opts);
        same_as_rgb888::<BinaryColor>(&opts);
        let be = same_as_rgb888::<Rgb565Be>(&opts);
        for (a, b) in rgb565.iter().zip(&be) {
            assert_eq!(b.0, a.into_storage().to_be_bytes());
        }
        let dithered = RenderOptions { dither: true, ..opts };
        assert_eq!(same_as_rgb888::<Rgb888>(&dithered), rgb888);
        assert_eq!(same_as_rgb888::<Gray8>(&dithered), gray);
    }
}

/// A full-frame quad, flat-lit, grey material `m`, light intensity `k` at 60 degrees.
fn grey_quad<C: FrameColor>(m: u8, k: f32, dither: bool) -> Frame<C> {
    let (w, h) = (32u16, 32u16);
    let s = scene(
        vec![screen_quad(w as f32, h as f32, [0.0, 0.0], [1.0, 1.0])],
        vec![material([m as f32 / 255.0; 3], None)],
        vec![],
    );
    let bytes = emit_rgba(&s);
    let model = Model::parse(&bytes).unwrap();
    let mut lights = Lights::<1>::new(Vec3::ZERO);
    lights.push(Lights::<1>::directional(Vec3::new(0.0, -0.866, 0.5), k)).unwrap();
    let opts = RenderOptions { shading: Shading::Flat, dither, ..Default::default() };
    render(&model, &ortho(w as f32, h as f32), &lights, &opts, (w, h), [0; 3])
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for v in values {
        sum += v;
        n += 1;
    }
    sum / n as f64
}

/// Ordered dithering keeps the average intensity of a flat-lit grey quad within half a
/// quantization step (Rgb565: 255/31/2 for red and blue, 255/63/2 for green; BinaryColor:
/// 255/2, and in fact within half a step of the 17 levels a 4x4 pattern can show), and only
/// ever uses the two levels around the exact value.
#[test]
fn dithering_keeps_the_average_of_a_flat_grey() {
    let (mut worst565, mut worst_plain565, mut worst1, mut worst_plain1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (m, k) in [(255u8, 1.0f32), (200, 1.0), (255, 0.3), (130, 0.77), (77, 0.5), (255, 0.05), (33, 1.0), (250, 1.1)]
    {
        let exact: Frame<Rgb888> = grey_quad(m, k, false);
        let g = rgb(exact.color[0]);
        assert!(exact.color.iter().all(|&c| rgb(c) == g), "flat light must be uniform");
        let g = g[0] as f64;
        for dither in [true, false] {
            let f565: Frame<Rgb565> = grey_quad(m, k, dither);
            for (ch, max) in [(0usize, 31.0), (1, 63.0), (2, 31.0)] {
                let avg = mean(f565.color.iter().map(|c| c.to_rgb888()[ch] as f64));
                let err = (avg - g).abs();
                if dither {
                    assert!(err <= 255.0 / max / 2.0, "565 grey {g} channel {ch}: average {avg}");
                    worst565 = worst565.max(err / (255.0 / max));
                    // Only the two levels around g.
                    let levels = [(g * max / 255.0).floor(), (g * max / 255.0).ceil()];
                    for c in &f565.color {
                        let raw = [c.r(), c.g(), c.b()][ch] as f64;
                        assert!(levels.contains(&raw), "565 grey {g} channel {ch}: level {raw} not in {levels:?}");
                    }
                } else {
                    worst_plain565 = worst_plain565.max(err / (255.0 / max));
                }
            }
            let mono: Frame<BinaryColor> = grey_quad(m, k, dither);
            let avg = mean(mono.color.iter().map(|c| c.to_rgb888()[0] as f64));
            let err = (avg - g).abs();
            if dither {
                assert!(err <= 255.0 / 16.0 / 2.0 + 0.5, "mono grey {g}: average {avg}");
                worst1 = worst1.max(err / 255.0);
            } else {
                worst_plain1 = worst_plain1.max(err / 255.0);
            }
        }
    }
    println!(
        "dither: worst average error in quantization steps: Rgb565 {worst565:.3} (undithered {worst_plain565:.3}), \
         BinaryColor {worst1:.3} (undithered {worst_plain1:.3})"
    );
    assert!(worst565 < worst_plain565 && worst1 < worst_plain1);
}

/// A smooth Gouraud gradient (light 0 at the left edge to 1 at the right, on a material of
/// 0.25 grey, so 0..64): dithering shows many
/// more changes of level between neighbouring pixels than plain rounding's bands, and the
/// averages over 4-column strips follow the exact gradient more closely.
#[test]
fn dithering_breaks_up_gradient_bands() {
    let (w, h) = (128u16, 16u16);
    let s2 = std::f32::consts::FRAC_1_SQRT_2;
    let (left, right) = ([-s2, 0.0, -s2], [s2, 0.0, -s2]);
    let (x, y) = (w as f32 / 2.0, h as f32 / 2.0);
    let mesh = quad([[-x, -y, 0.0], [x, -y, 0.0], [x, y, 0.0], [-x, y, 0.0]], None, Some([left, right, right, left]));
    // A dim material: 0..64 over 128 pixels, wide bands (16 levels of 6-bit green, 2 of 1-bit).
    let s = scene(vec![mesh], vec![material([0.25; 3], None)], vec![]);
    let bytes = emit_rgba(&s);
    let model = Model::parse(&bytes).unwrap();
    // L = (1, 0, -1)/sqrt 2: N·L is 0 on the left vertices and 1 on the right ones.
    let mut lights = Lights::<1>::new(Vec3::ZERO);
    lights.push(Lights::<1>::directional(Vec3::new(-s2, 0.0, s2), 1.0)).unwrap();
    let cam = ortho(w as f32, h as f32);
    let run = |dither: bool| RenderOptions { shading: Shading::Gouraud, dither, ..Default::default() };
    let exact: Frame<Rgb888> = render(&model, &cam, &lights, &run(false), (w, h), [0; 3]);
    let (w, h) = (w as usize, h as usize);
    let column = |f: &dyn Fn(usize, usize) -> f64, x: usize| mean((0..h).map(|y| f(x, y)));

    fn stats(
        level: &dyn Fn(usize, usize) -> f64,
        exact: &dyn Fn(usize, usize) -> f64,
        (w, h): (usize, usize),
    ) -> (usize, f64) {
        let changes = (0..h).map(|y| (1..w).filter(|&x| level(x, y) != level(x - 1, y)).count()).sum();
        // Averages over 4-column strips (whole 4x4 dither tiles).
        let strip = |f: &dyn Fn(usize, usize) -> f64, x: usize| mean((0..4 * h).map(|k| f(x + k / h, k % h)));
        let err = mean((0..w).step_by(4).map(|x| (strip(level, x) - strip(exact, x)).abs()));
        (changes, err)
    }
    let exact_v = |x: usize, y: usize| rgb(exact.at(x, y))[1] as f64;
    assert!(column(&exact_v, 0) < 3.0 && column(&exact_v, w - 1) > 60.0, "not a full gradient");

    let plain565: Frame<Rgb565> = render(&model, &cam, &lights, &run(false), (w as u16, h as u16), [0; 3]);
    let dith565: Frame<Rgb565> = render(&model, &cam, &lights, &run(true), (w as u16, h as u16), [0; 3]);
    let plain1: Frame<BinaryColor> = render(&model, &cam, &lights, &run(false), (w as u16, h as u16), [0; 3]);
    let dith1: Frame<BinaryColor> = render(&model, &cam, &lights, &run(true), (w as u16, h as u16), [0; 3]);
    let g565 = |f: &Frame<Rgb565>, x: usize, y: usize| f.at(x, y).to_rgb888()[1] as f64;
    let g1 = |f: &Frame<BinaryColor>, x: usize, y: usize| f.at(x, y).to_rgb888()[0] as f64;
    let (c_plain565, e_plain565) = stats(&|x, y| g565(&plain565, x, y), &exact_v, (w, h));
    let (c_dith565, e_dith565) = stats(&|x, y| g565(&dith565, x, y), &exact_v, (w, h));
    let (c_plain1, e_plain1) = stats(&|x, y| g1(&plain1, x, y), &exact_v, (w, h));
    let (c_dith1, e_dith1) = stats(&|x, y| g1(&dith1, x, y), &exact_v, (w, h));
    println!(
        "gradient: level changes between neighbours Rgb565 green {c_plain565} -> {c_dith565} dithered, \
         BinaryColor {c_plain1} -> {c_dith1}; mean 4-column-strip error {e_plain565:.2} -> {e_dith565:.2}, \
         {e_plain1:.1} -> {e_dith1:.1}"
    );
    assert!(c_dith565 > 3 * c_plain565 && c_dith1 > 10 * c_plain1);
    assert!(e_dith565 < e_plain565 && e_dith1 < e_plain1 / 4.0);
}

// ---------------------------------------------------------------------------------------------
// 6. Texture storage formats
// ---------------------------------------------------------------------------------------------

/// Known encodings and decodings of single texels.
#[test]
fn texel_codecs_known_values() {
    use TextureFormat::*;
    let le = |v: u16| {
        let b = v.to_le_bytes();
        [b[0], b[1], 0, 0]
    };
    // Rgb565 of (255, 128, 0): r 31, g round(128·63/255) = 32, b 0 -> 0xFC00 -> (255, 130, 0).
    assert_eq!(encode_texel(Rgb565, [255, 128, 0, 255]), le(0xFC00));
    assert_eq!(decode_texel(Rgb565, &le(0xFC00)[..2]), [255, 130, 0, 255]);
    assert_eq!(encode_texel(Rgb565, [0, 255, 255, 0]), le(0x07FF));
    assert_eq!(decode_texel(Rgb565, &le(0x07FF)[..2]), [0, 255, 255, 255]);
    // (8, 4, 8): 5-bit 1, 6-bit 1, 5-bit 1 -> 0x0821 -> (8, 4, 8).
    assert_eq!(encode_texel(Rgb565, [8, 4, 8, 255]), le(0x0821));
    assert_eq!(decode_texel(Rgb565, &le(0x0821)[..2]), [8, 4, 8, 255]);
    // Rgba5551 of (255, 128, 0): r 31, g round(128·31/255) = 16, b 0, a 1 -> 0xFC01 -> (255, 132, 0).
    assert_eq!(encode_texel(Rgba5551, [255, 128, 0, 255]), le(0xFC01));
    assert_eq!(decode_texel(Rgba5551, &le(0xFC01)[..2]), [255, 132, 0, 255]);
    assert_eq!(encode_texel(Rgba5551, [255, 128, 0, 0]), le(0xFC00));
    assert_eq!(decode_texel(Rgba5551, &le(0xFC00)[..2]), [255, 132, 0, 0]);
    assert_eq!(encode_texel(Rgba5551, [0, 0, 0, 127])[0] & 1, 0, "alpha < 128 is transparent");
    assert_eq!(encode_texel(Rgba5551, [0, 0, 0, 128])[0] & 1, 1, "alpha >= 128 is opaque");
    // 8-bit formats are stored as they are (Rgb888 drops alpha and decodes opaque).
    assert_eq!(encode_texel(Rgb888, [255, 128, 0, 7])[..3], [255, 128, 0]);
    assert_eq!(decode_texel(Rgb888, &[255, 128, 0]), [255, 128, 0, 255]);
    assert_eq!(encode_texel(Rgba8888, [255, 128, 0, 7]), [255, 128, 0, 7]);
    assert_eq!(decode_texel(Rgba8888, &[255, 128, 0, 7]), [255, 128, 0, 7]);

    // Every 16-bit code survives decode + encode, and every 8-bit value comes back within half
    // a step of its channel's precision.
    for code in 0..=u16::MAX {
        for f in [Rgb565, Rgba5551] {
            let c = decode_texel(f, &code.to_le_bytes());
            assert_eq!(encode_texel(f, c)[..2], code.to_le_bytes(), "{f:?} {code:#06x}");
        }
    }
    for v in 0..=255u8 {
        let c565 = decode_texel(Rgb565, &encode_texel(Rgb565, [v, v, v, 255])[..2]);
        let c5551 = decode_texel(Rgba5551, &encode_texel(Rgba5551, [v, v, v, 255])[..2]);
        let d = |a: u8| (a as f64 - v as f64).abs();
        assert!(d(c565[0]) <= 255.0 / 62.0 && d(c565[1]) <= 255.0 / 126.0 && d(c565[2]) <= 255.0 / 62.0, "{v}");
        assert!(d(c5551[0]) <= 255.0 / 62.0 && d(c5551[1]) <= 255.0 / 62.0 && d(c5551[2]) <= 255.0 / 62.0, "{v}");
    }
}

/// A texture stored in each format in an `.s3d` file decodes to the expected texels, bottom row
/// first, and renders texel-to-pixel to exactly those colours.
#[test]
fn s3d_textures_decode_in_every_format() {
    let (w, h) = (6u16, 5u16);
    let mut rng = Rng(99);
    let colours: Vec<[u8; 4]> = (0..w as usize * h as usize)
        .map(|k| [rng.byte(), rng.byte(), rng.byte(), if k % 3 == 0 { 0 } else { 255 }])
        .collect();
    // Texel (i, j), j from the bottom.
    let at = |i: u32, j: u32| colours[(j * w as u32 + i) as usize];
    let tex = texture(w, h, at);
    let s = scene(
        vec![screen_quad(w as f32, h as f32, [0.0, 0.0], [1.0, 1.0])],
        vec![material([1.0; 3], Some(0))],
        vec![tex],
    );
    for format in [TextureFormat::Rgb565, TextureFormat::Rgba5551, TextureFormat::Rgb888, TextureFormat::Rgba8888] {
        let bytes = emit_with(&s, format);
        let model = Model::parse(&bytes).unwrap();
        let t = model.texture(0).unwrap();
        assert_eq!((t.width, t.height, t.format), (w, h, format));
        let n = format.bytes_per_texel();
        assert_eq!(t.texels.len(), w as usize * h as usize * n);
        assert_eq!(t.texels[..n], encode_texel(format, at(0, 0))[..n], "{format:?}: bottom-left texel first");
        let frame: Frame<Rgb888> = render(&model, &ortho(w as f32, h as f32), &no_lights(), &unlit(), (w, h), [0; 3]);
        for j in 0..h as u32 {
            for i in 0..w as u32 {
                let want = decode_texel(format, &encode_texel(format, at(i, j))[..n]);
                assert_eq!(t.rgba(i, j), want, "{format:?} texel ({i}, {j})");
                if format.has_alpha() {
                    assert_eq!(want[3], at(i, j)[3], "{format:?} keeps cut-outs");
                }
                let (c, r) = (i as usize, (h as u32 - 1 - j) as usize);
                assert_eq!(frame.drawn(c, r), want[3] >= 128, "{format:?} pixel ({c}, {r})");
                if want[3] >= 128 {
                    assert_eq!(rgb(frame.at(c, r)), want[..3], "{format:?} pixel ({c}, {r})");
                }
            }
        }
    }
    // The default choice: Rgba5551 when a texel is transparent, Rgb565 otherwise.
    let auto = emit(&s, &EmitOptions { float_positions: true, ..Default::default() }).unwrap();
    assert_eq!(Model::parse(&auto).unwrap().texture(0).unwrap().format, TextureFormat::Rgba5551);
    let mut opaque = s.clone();
    opaque.textures[0].rgba.chunks_exact_mut(4).for_each(|c| c[3] = 255);
    let auto = emit(&opaque, &EmitOptions { float_positions: true, ..Default::default() }).unwrap();
    assert_eq!(Model::parse(&auto).unwrap().texture(0).unwrap().format, TextureFormat::Rgb565);
}
