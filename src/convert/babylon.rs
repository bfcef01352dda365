//! Reads Babylon.js `.babylon` scene files into a [`Scene`].
//!
//! The rules are those of `spec/babylon-conventions.md`; the choices this reader makes where
//! the spec is silent:
//!
//! - **Geometry layouts**: split `positions/normals/uvs/uvs2/colors/indices`, the 2013 legacy
//!   interleaved `vertices` + `uvCount` (stride `6 + 2·uvCount`), shared
//!   `geometries.vertexData[]` referenced by `geometryId`, and side files named by
//!   `delayLoadingFile` (binary `.babylonbinarymeshdata` described by `_binaryInfo`, or JSON).
//!   As in Babylon.js, binary `count`s are numbers of scalars (of 5-int records for subMeshes),
//!   attributes are `f32` and indices/subMeshes `i32`, little-endian; `dataType`/`stride` are
//!   ignored.
//! - **Transforms**: `Local = S·R·T` (with the mesh's `pivotMatrix` ignored, warned when not
//!   identity), `World = Local · World(parent)`. A mesh with `autoAnimate` shows the first
//!   frame of its animations, as Babylon.js does when it starts playing them: the
//!   `position`/`rotation`/`scaling`/`rotationQuaternion` keys at `autoAnimateFrom` (linear
//!   between keys) replace the static values.
//! - **Instances** inherit the source mesh's position/rotation/scaling when they omit one (as
//!   Babylon's `createInstance` does); their parent is their own `parentId` when the key is
//!   present (even `null`), else the mesh's parent.
//! - **Hidden meshes** (`isVisible` or `isEnabled` false) are not drawn by Babylon.js: they are
//!   skipped with a warning (but stay available as parents).
//! - **Texture matrices** follow `Texture.getTextureMatrix`: rows are built from
//!   `RotationYawPitchRoll(vAng, uAng, wAng)` around the rotation centres (default 0.5) and
//!   applied as `[u v 1 0] · M`; with no rotation that is `u' = u·uScale + uOffset`,
//!   `v' = v·vScale + vOffset`. A texture with `invertY: false` is uploaded unflipped by
//!   Babylon.js, so `v' = 1 - v'` is stored to keep "(0,0) = bottom-left". [`UvOrigin::Top`]
//!   flips once more after that.
//! - **Texture alpha** is kept only where Babylon.js uses it: the texture's `hasAlpha` is true
//!   and the material's `transparencyMode` is not 0 (opaque); otherwise alpha is set to 255.
//! - **Missing normals** are computed smooth and area-weighted with Babylon's facet orientation
//!   (`(p0 - p1) × (p2 - p1)`); a zero-length normal in the file is replaced the same way.
//! - **Cameras**: `activeCameraID` (or the legacy `activeCamera`), else the first camera. The
//!   target is `target`, else the world position of `lockedTargetId`, else the origin for an
//!   `ArcRotateCamera` (Babylon's default target), else `position` + the rotated +z axis.

use std::borrow::ToOwned;
use std::collections::HashMap;
use std::fmt;
use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec;
use std::vec::Vec;

use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use base64::Engine as _;
use serde_json::Value;

use super::scene::{
    CameraData, InstanceData, LightData, LightKind, MaterialData, Matrix, MeshData, Scene, SubMeshData, TextureData,
    Wrap, IDENTITY,
};

/// Where `v = 0` lies in the file's texture coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UvOrigin {
    /// The Babylon.js rule: `v = 0` is the bottom row of the image; `v` is kept.
    #[default]
    Bottom,
    /// `v = 0` is the top row of the image (the 2013 tutorial's Suzanne): `v' = 1 - v` is stored.
    Top,
}

/// Options of the `.babylon` reader.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ConvertOptions {
    /// How to read the file's texture coordinates.
    pub uv_origin: UvOrigin,
    /// Downscale textures so that `max(width, height) <= N`, keeping the aspect ratio.
    pub max_texture: Option<u32>,
    /// Resize textures to power-of-two sizes (the next lower power of two on each side).
    pub power_of_two: bool,
}

/// Something the reader could not honour but worked around (e.g. a missing texture file).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning(pub String);

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why a `.babylon` file could not be converted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ConvertError {
    /// A file (the scene or a geometry side file) could not be read.
    Io {
        /// The file's path.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The scene is not valid JSON.
    Json {
        /// The scene file's name.
        file: String,
        /// The parser's message (with line and column).
        message: String,
    },
    /// The JSON is well formed but breaks a rule of the format.
    Invalid {
        /// The scene file's name.
        file: String,
        /// The object at fault, e.g. `mesh "Suzanne"`.
        context: String,
        /// The field and the problem, e.g. `indices[42] = 9001 but only 886 vertices`.
        message: String,
    },
}

impl fmt::Display for ConvertError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, message } => write!(f, "{path}: {message}"),
            Self::Json { file, message } => write!(f, "{file}: invalid JSON: {message}"),
            Self::Invalid { file, context, message } => write!(f, "{file}: {context}: {message}"),
        }
    }
}

impl std::error::Error for ConvertError {}

/// Reads the `.babylon` file at `path`; textures and geometry side files are looked up in its
/// directory.
///
/// # Errors
/// When the file cannot be read or breaks the format; see [`read_babylon`].
pub fn read_babylon_file(path: &Path, opts: &ConvertOptions) -> Result<(Scene, Vec<Warning>), ConvertError> {
    let json = std::fs::read(path).map_err(|e| io_error(path, &e))?;
    let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
    let dir = path.parent().map(|d| if d.as_os_str().is_empty() { Path::new(".") } else { d });
    read_babylon(&json, dir, &name, opts)
}

/// Reads a `.babylon` scene from memory. `base_dir` is where texture and geometry side files
/// are looked up (without it, file textures are missing and side files an error); `file_name`
/// names the scene in messages. Never panics, whatever the bytes.
///
/// # Errors
/// Invalid JSON, a field of the wrong type, a non-finite number, inconsistent geometry (an
/// index out of range, a length that is not a multiple of the vertex size, a subMesh outside
/// the indices), a `parentId` cycle, or an unreadable geometry side file. Missing or
/// undecodable textures, unknown materials and unsupported lights are [`Warning`]s instead.
pub fn read_babylon(
    json: &[u8],
    base_dir: Option<&Path>,
    file_name: &str,
    opts: &ConvertOptions,
) -> Result<(Scene, Vec<Warning>), ConvertError> {
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    let root: Value = serde_json::from_slice(json)
        .map_err(|e| ConvertError::Json { file: file_name.to_owned(), message: e.to_string() })?;
    let mut reader = Reader::new(&root, base_dir, file_name, opts)?;
    reader.read_meshes()?;
    reader.read_lights()?;
    reader.read_camera()?;
    Ok((reader.scene, reader.warnings))
}

fn io_error(path: &Path, e: &std::io::Error) -> ConvertError {
    ConvertError::Io { path: path.display().to_string(), message: e.to_string() }
}

// ---------------------------------------------------------------------------------------------
// JSON field readers: each returns the field's problem as a message naming the field.

type Res<T> = Result<T, String>;

/// The object (`mesh "Suzanne"`) that field errors are reported against.
struct Ctx<'a> {
    file: &'a str,
    what: String,
}

impl Ctx<'_> {
    fn err(&self, message: impl Into<String>) -> ConvertError {
        ConvertError::Invalid { file: self.file.to_owned(), context: self.what.clone(), message: message.into() }
    }
}

/// `obj[key]`, with a missing key and `null` alike.
fn get<'v>(obj: &'v Value, key: &str) -> Option<&'v Value> {
    obj.get(key).filter(|v| !v.is_null())
}

/// A short description of a JSON value for messages.
fn show(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => format!("{:?}", s.chars().take(24).collect::<String>()),
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}

fn finite(v: &Value) -> Option<f32> {
    v.as_f64().map(|x| x as f32).filter(|x| x.is_finite())
}

fn whole(v: &Value) -> Option<u64> {
    v.as_u64().or_else(|| {
        let x = v.as_f64()?;
        (x >= 0.0 && x.fract() == 0.0 && x < 1.8e19).then_some(x as u64)
    })
}

/// The elements of an array field, or `&[]` when it is missing or null.
fn list<'v>(obj: &'v Value, key: &str) -> Res<&'v [Value]> {
    match get(obj, key) {
        None => Ok(&[]),
        Some(Value::Array(a)) => Ok(a),
        Some(v) => Err(format!("{key}: expected an array, found {}", show(v))),
    }
}

/// Maps the elements of an array field with `f`, naming the first bad element.
fn array<T>(obj: &Value, key: &str, what: &str, f: impl Fn(&Value) -> Option<T>) -> Res<Option<Vec<T>>> {
    let Some(v) = get(obj, key) else {
        return Ok(None);
    };
    let a = v.as_array().ok_or_else(|| format!("{key}: expected an array, found {}", show(v)))?;
    let bad = |(i, x): (usize, &Value)| format!("{key}[{i}]: expected {what}, found {}", show(x));
    a.iter().enumerate().map(|(i, x)| f(x).ok_or_else(|| bad((i, x)))).collect::<Res<_>>().map(Some)
}

fn floats(obj: &Value, key: &str) -> Res<Option<Vec<f32>>> {
    array(obj, key, "a finite number", finite)
}

fn uints(obj: &Value, key: &str) -> Res<Option<Vec<u32>>> {
    array(obj, key, "an index below 2^32", |x| whole(x).and_then(|n| u32::try_from(n).ok()))
}

/// A fixed-size numeric field (`position`, `diffuse`...); extra elements are ignored.
fn vector<const N: usize>(obj: &Value, key: &str) -> Res<Option<[f32; N]>> {
    let Some(v) = floats(obj, key)? else {
        return Ok(None);
    };
    let short = || format!("{key}: expected {N} numbers, found {}", v.len());
    v.get(..N).and_then(|s| <[f32; N]>::try_from(s).ok()).map(Some).ok_or_else(short)
}

fn scalar(obj: &Value, key: &str, default: f32) -> Res<f32> {
    get(obj, key)
        .map_or(Ok(default), |v| finite(v).ok_or_else(|| format!("{key}: expected a finite number, found {}", show(v))))
}

fn count(obj: &Value, key: &str, default: Option<u64>) -> Res<u64> {
    match get(obj, key) {
        None => default.ok_or_else(|| format!("{key}: missing")),
        Some(v) => whole(v).ok_or_else(|| format!("{key}: expected a whole number >= 0, found {}", show(v))),
    }
}

/// A boolean field; old exporters write `1.0`/`0.0`.
fn flag(obj: &Value, key: &str, default: bool) -> Res<bool> {
    match get(obj, key) {
        None => Ok(default),
        Some(Value::Bool(b)) => Ok(*b),
        Some(v) => finite(v).map(|x| x != 0.0).ok_or_else(|| format!("{key}: expected a boolean, found {}", show(v))),
    }
}

/// A string field; ids may be written as numbers.
fn text(obj: &Value, key: &str) -> Res<Option<String>> {
    match get(obj, key) {
        None => Ok(None),
        Some(Value::String(s)) => Ok(Some(s.clone())),
        Some(Value::Number(n)) => Ok(Some(n.to_string())),
        Some(v) => Err(format!("{key}: expected a string, found {}", show(v))),
    }
}

/// `kind "name"` for messages, from `name`, else `id`, else the array position.
fn label(obj: &Value, kind: &str, array: &str, i: usize) -> String {
    match text(obj, "name").ok().flatten().or_else(|| text(obj, "id").ok().flatten()) {
        Some(name) => format!("{kind} {name:?}"),
        None => format!("{array}[{i}]"),
    }
}

// ---------------------------------------------------------------------------------------------
// Matrices: Babylon row-vector layout, `p' = p · M`, translation in m[12..15].

fn mul(a: &Matrix, b: &Matrix) -> Matrix {
    core::array::from_fn(|i| (0..4).map(|k| a[i / 4 * 4 + k] * b[k * 4 + i % 4]).sum())
}

/// `[p, w] · m` (w = 1 for points, 0 for directions).
fn transform(m: &Matrix, p: [f32; 3], w: f32) -> [f32; 3] {
    core::array::from_fn(|c| p[0] * m[c] + p[1] * m[4 + c] + p[2] * m[8 + c] + w * m[12 + c])
}

/// Babylon's `RotationYawPitchRoll(ry, rx, rz)`: `R = Rz(rz) · Rx(rx) · Ry(ry)`.
#[rustfmt::skip]
fn euler_matrix([rx, ry, rz]: [f32; 3]) -> Matrix {
    let ((sx, cx), (sy, cy), (sz, cz)) = (libm::sincosf(rx), libm::sincosf(ry), libm::sincosf(rz));
    let x = [1., 0., 0., 0.,   0., cx, sx, 0.,   0., -sx, cx, 0.,   0., 0., 0., 1.];
    let y = [cy, 0., -sy, 0.,  0., 1., 0., 0.,   sy, 0., cy, 0.,    0., 0., 0., 1.];
    let z = [cz, sz, 0., 0.,   -sz, cz, 0., 0.,  0., 0., 1., 0.,    0., 0., 0., 1.];
    mul(&mul(&z, &x), &y)
}

/// Babylon's `Matrix.FromQuaternion` (the quaternion is used as written, not normalised).
#[rustfmt::skip]
fn quat_matrix([x, y, z, w]: [f32; 4]) -> Matrix {
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, xw, yw, zw) = (x * y, x * z, y * z, x * w, y * w, z * w);
    [
        1. - 2. * (yy + zz), 2. * (xy + zw),      2. * (xz - yw),      0.,
        2. * (xy - zw),      1. - 2. * (zz + xx), 2. * (yz + xw),      0.,
        2. * (xz + yw),      2. * (yz - xw),      1. - 2. * (yy + xx), 0.,
        0.,                  0.,                  0.,                  1.,
    ]
}

/// A node's position, rotation and scaling as written in the file.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Trs {
    position: [f32; 3],
    rotation: [f32; 3],
    quaternion: Option<[f32; 4]>,
    scaling: [f32; 3],
}

impl Trs {
    const IDENTITY: Trs = Trs { position: [0.; 3], rotation: [0.; 3], quaternion: None, scaling: [1.; 3] };

    /// Reads the fields of `obj`, taking the missing ones from `base`.
    fn read(obj: &Value, base: Trs) -> Res<Trs> {
        Ok(Trs {
            position: vector(obj, "position")?.unwrap_or(base.position),
            rotation: vector(obj, "rotation")?.unwrap_or(base.rotation),
            quaternion: vector(obj, "rotationQuaternion")?.or(base.quaternion),
            scaling: vector(obj, "scaling")?.unwrap_or(base.scaling),
        })
    }

    fn rotation_matrix(&self) -> Matrix {
        self.quaternion.map_or_else(|| euler_matrix(self.rotation), quat_matrix)
    }

    /// `Local = S · R · T`.
    fn matrix(&self) -> Matrix {
        let mut m = self.rotation_matrix();
        for (i, v) in m[..12].iter_mut().enumerate() {
            *v *= self.scaling[i / 4];
        }
        m[12..15].copy_from_slice(&self.position);
        m
    }

    /// Applies the first frame of `autoAnimate` animations (see the module documentation).
    fn animate(&mut self, obj: &Value) -> Res<()> {
        if !flag(obj, "autoAnimate", false)? {
            return Ok(());
        }
        let frame = scalar(obj, "autoAnimateFrom", 0.)?;
        for (i, anim) in list(obj, "animations")?.iter().enumerate() {
            let in_anim = |m: String| format!("animations[{i}].{m}");
            let Some(property) = text(anim, "property").map_err(in_anim)? else {
                continue;
            };
            let (base, component) = property.split_once('.').map_or((&*property, None), |(b, c)| (b, Some(c)));
            let Some(value) = key_value(anim, frame).map_err(in_anim)? else {
                continue;
            };
            let target: &mut [f32] = match base {
                "position" => &mut self.position,
                "rotation" => &mut self.rotation,
                "scaling" => &mut self.scaling,
                "rotationQuaternion" => self.quaternion.get_or_insert([0., 0., 0., 1.]),
                _ => continue,
            };
            match component.and_then(|c| ["x", "y", "z", "w"].iter().position(|&n| n == c)) {
                Some(k) => {
                    if let (Some(t), Some(v)) = (target.get_mut(k), value.first()) {
                        *t = *v;
                    }
                }
                None if component.is_none() => target.iter_mut().zip(&value).for_each(|(t, v)| *t = *v),
                None => {}
            }
        }
        Ok(())
    }
}

/// An animation's value at `frame`: linear between the surrounding keys, clamped at the ends.
fn key_value(anim: &Value, frame: f32) -> Res<Option<Vec<f32>>> {
    let mut prev: Option<(f32, Vec<f32>)> = None;
    for (i, key) in list(anim, "keys")?.iter().enumerate() {
        let in_key = |m: String| format!("keys[{i}].{m}");
        let f = scalar(key, "frame", 0.).map_err(in_key)?;
        let v = floats(key, "values").map_err(in_key)?.unwrap_or_default();
        if f >= frame {
            return Ok(Some(match prev {
                Some((pf, pv)) if f > pf && pv.len() == v.len() => {
                    let t = (frame - pf) / (f - pf);
                    pv.iter().zip(&v).map(|(a, b)| a + (b - a) * t).collect()
                }
                _ => v,
            }));
        }
        prev = Some((f, v));
    }
    Ok(prev.map(|(_, v)| v))
}

/// Babylon's texture matrix as `u' = m0·u + m1·v + m2`, `v' = m3·u + m4·v + m5`.
fn texture_matrix(tex: &Value) -> Res<[f32; 6]> {
    let f = |key, default| scalar(tex, key, default);
    let (us, vs) = (f("uScale", 1.)?, f("vScale", 1.)?);
    let (uo, vo) = (f("uOffset", 0.)?, f("vOffset", 0.)?);
    let angles = [f("uAng", 0.)?, f("vAng", 0.)?, f("wAng", 0.)?];
    let centre = [f("uRotationCenter", 0.5)?, f("vRotationCenter", 0.5)?, f("wRotationCenter", 0.5)?];
    let r = euler_matrix(angles); // RotationYawPitchRoll(vAng, uAng, wAng)
    let row = |x: f32, y: f32| {
        let p = [x * us - centre[0] * us, y * vs - centre[1] * vs, -centre[2]];
        let t = transform(&r, p, 1.);
        [t[0] + centre[0] * us + uo, t[1] + centre[1] * vs + vo]
    };
    let (t0, t1, t2) = (row(0., 0.), row(1., 0.), row(0., 1.));
    Ok([t1[0] - t0[0], t2[0] - t0[0], t0[0], t1[1] - t0[1], t2[1] - t0[1], t0[1]])
}

// ---------------------------------------------------------------------------------------------
// Geometry.

/// A mesh's vertex data before validation.
#[derive(Default)]
struct Geometry {
    positions: Vec<f32>,
    normals: Option<Vec<f32>>,
    uvs: [Option<Vec<f32>>; 2],
    colors: Option<Vec<f32>>,
    indices: Option<Vec<u32>>,
    /// `[materialIndex, indexStart, indexCount]`.
    submeshes: Option<Vec<[u64; 3]>>,
}

fn split_geometry(obj: &Value) -> Res<Geometry> {
    Ok(Geometry {
        positions: floats(obj, "positions")?.unwrap_or_default(),
        normals: floats(obj, "normals")?,
        uvs: [floats(obj, "uvs")?, floats(obj, "uvs2")?],
        colors: floats(obj, "colors")?,
        indices: uints(obj, "indices")?,
        submeshes: submeshes(obj)?,
    })
}

/// The 2013 layout: per vertex `[x,y,z, nx,ny,nz, (u,v) x uvCount]`.
fn legacy_geometry(obj: &Value) -> Res<Geometry> {
    let data = floats(obj, "vertices")?.unwrap_or_default();
    let uv_count = count(obj, "uvCount", Some(0))?;
    let stride = usize::try_from(uv_count).ok().filter(|&n| n <= 64).map(|n| 6 + 2 * n);
    let stride = stride.ok_or_else(|| format!("uvCount: {uv_count} is too large"))?;
    if data.len() % stride != 0 {
        return Err(format!(
            "vertices: {} numbers is not a multiple of the vertex size {stride} (6 + 2·uvCount)",
            data.len()
        ));
    }
    let pick = |start: usize, n: usize| {
        data.chunks_exact(stride).flat_map(|v| v[start..start + n].iter().copied()).collect::<Vec<_>>()
    };
    let uvs = |set: usize| (set < stride / 2 - 3).then(|| pick(6 + 2 * set, 2));
    Ok(Geometry {
        positions: pick(0, 3),
        normals: Some(pick(3, 3)),
        uvs: [uvs(0), uvs(1)],
        indices: uints(obj, "indices")?,
        submeshes: submeshes(obj)?,
        ..Geometry::default()
    })
}

/// A `.babylonbinarymeshdata` side file described by the mesh's `_binaryInfo`.
fn binary_geometry(data: &[u8], info: &Value) -> Res<Geometry> {
    let words = |key: &str, per: u64| -> Res<Option<Vec<[u8; 4]>>> {
        let Some(desc) = get(info, key) else {
            return Ok(None);
        };
        let in_desc = |m: String| format!("_binaryInfo.{key}.{m}");
        let (n, offset) = (count(desc, "count", None).map_err(in_desc)?, count(desc, "offset", None).map_err(in_desc)?);
        let range = n.checked_mul(4 * per).and_then(|len| Some(offset..offset.checked_add(len)?));
        let bytes = range.and_then(|r| data.get(usize::try_from(r.start).ok()?..usize::try_from(r.end).ok()?));
        let outside =
            || format!("_binaryInfo.{key}: {n} values at byte {offset} lie outside the {}-byte file", data.len());
        let bytes = bytes.ok_or_else(outside)?;
        Ok(Some(bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()))
    };
    let floats = |key: &str, name: &str| -> Res<Option<Vec<f32>>> {
        let Some(w) = words(key, 1)? else {
            return Ok(None);
        };
        let f: Vec<f32> = w.into_iter().map(f32::from_le_bytes).collect();
        match f.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(format!("{name}[{i}] = {} is not finite", f[i])),
            None => Ok(Some(f)),
        }
    };
    let ints = |key: &str, name: &str, per: u64| -> Res<Option<Vec<u32>>> {
        let Some(w) = words(key, per)? else {
            return Ok(None);
        };
        let ints = w.into_iter().map(i32::from_le_bytes);
        let bad = |(i, x): (usize, i32)| format!("{name}[{i}] = {x} is negative");
        ints.enumerate().map(|(i, x)| u32::try_from(x).map_err(|_| bad((i, x)))).collect::<Res<_>>().map(Some)
    };
    let subs = ints("subMeshesAttrDesc", "subMeshes", 5)?;
    Ok(Geometry {
        positions: floats("positionsAttrDesc", "positions")?.unwrap_or_default(),
        normals: floats("normalsAttrDesc", "normals")?,
        uvs: [floats("uvsAttrDesc", "uvs")?, floats("uvs2AttrDesc", "uvs2")?],
        colors: floats("colorsAttrDesc", "colors")?,
        indices: ints("indicesAttrDesc", "indices", 1)?,
        submeshes: subs.map(|s| s.chunks_exact(5).map(|r| [r[0], r[3], r[4]].map(u64::from)).collect()),
    })
}

/// The `subMeshes` field as `[materialIndex, indexStart, indexCount]`.
fn submeshes(obj: &Value) -> Res<Option<Vec<[u64; 3]>>> {
    if get(obj, "subMeshes").is_none() {
        return Ok(None);
    }
    let read = |(i, s): (usize, &Value)| -> Res<[u64; 3]> {
        let at = |m: String| format!("subMeshes[{i}].{m}");
        if !s.is_object() {
            return Err(format!("subMeshes[{i}]: expected an object, found {}", show(s)));
        }
        let [m, start, n] =
            [("materialIndex", Some(0)), ("indexStart", None), ("indexCount", None)].map(|(k, d)| count(s, k, d));
        Ok([m.map_err(at)?, start.map_err(at)?, n.map_err(at)?])
    };
    list(obj, "subMeshes")?.iter().enumerate().map(read).collect::<Res<_>>().map(Some)
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn unit(v: [f32; 3]) -> Option<[f32; 3]> {
    let len = libm::sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    (len > 0. && len.is_finite()).then(|| v.map(|x| x / len))
}

/// Smooth area-weighted normals, facets oriented as Babylon's `ComputeNormals`.
fn smooth_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![[0f32; 3]; positions.len()];
    for t in indices.chunks_exact(3) {
        let [p0, p1, p2] = [t[0], t[1], t[2]].map(|i| positions.get(i as usize).copied().unwrap_or_default());
        let (a, b) = (sub(p0, p1), sub(p2, p1));
        let n = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        for &i in t {
            if let Some(s) = acc.get_mut(i as usize) {
                *s = [s[0] + n[0], s[1] + n[1], s[2] + n[2]];
            }
        }
    }
    acc
}

// ---------------------------------------------------------------------------------------------
// The reader.

/// How a material's texture maps the mesh's UVs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvMap {
    matrix: [f32; 6],
    /// 0 = `uvs`, 1 = `uvs2` (`coordinatesIndex`).
    set: usize,
    /// `invertY: false`: store `1 - v`.
    flip: bool,
}

impl UvMap {
    fn apply(&self, [u, v]: [f32; 2]) -> [f32; 2] {
        let m = &self.matrix;
        let (u2, v2) = (m[0] * u + m[1] * v + m[2], m[3] * u + m[4] * v + m[5]);
        [u2, if self.flip { 1. - v2 } else { v2 }]
    }
}

/// A converted material: its index in `Scene::materials` and, when textured, its UV mapping.
#[derive(Clone, Copy)]
struct MatSlot {
    index: u16,
    uv: Option<UvMap>,
}

/// A mesh or transform node, possibly a parent of others.
struct Node<'v> {
    obj: &'v Value,
    what: String,
    /// As written (what instances inherit).
    trs: Trs,
    /// After `autoAnimate`.
    local: Matrix,
    parent: Option<usize>,
    world: Option<Matrix>,
    is_mesh: bool,
}

struct Reader<'a> {
    file: &'a str,
    base_dir: Option<&'a Path>,
    opts: &'a ConvertOptions,
    root: &'a Value,
    materials: HashMap<String, &'a Value>,
    multi: HashMap<String, Vec<Option<String>>>,
    mat_cache: HashMap<String, Option<MatSlot>>,
    tex_cache: HashMap<(String, bool), Option<u16>>,
    nodes: Vec<Node<'a>>,
    ids: HashMap<String, usize>,
    scene: Scene,
    warnings: Vec<Warning>,
}

impl<'a> Reader<'a> {
    fn new(
        root: &'a Value,
        base_dir: Option<&'a Path>,
        file: &'a str,
        opts: &'a ConvertOptions,
    ) -> Result<Self, ConvertError> {
        let cx = Ctx { file, what: "scene".into() };
        if !root.is_object() {
            return Err(cx.err(format!("expected a JSON object, found {}", show(root))));
        }
        let mut r = Reader {
            file,
            base_dir,
            opts,
            root,
            materials: HashMap::new(),
            multi: HashMap::new(),
            mat_cache: HashMap::new(),
            tex_cache: HashMap::new(),
            nodes: Vec::new(),
            ids: HashMap::new(),
            scene: Scene::default(),
            warnings: Vec::new(),
        };
        for (i, m) in list(root, "materials").map_err(|m| cx.err(m))?.iter().enumerate() {
            let id = text(m, "id")
                .and_then(|id| Ok(id.or(text(m, "name")?)))
                .map_err(|e| cx.err(format!("materials[{i}].{e}")))?;
            if !m.is_object() {
                return Err(cx.err(format!("materials[{i}]: expected an object, found {}", show(m))));
            }
            if let Some(id) = id {
                r.materials.entry(id).or_insert(m);
            }
        }
        for (i, mm) in list(root, "multiMaterials").map_err(|m| cx.err(m))?.iter().enumerate() {
            let at = |m: String| cx.err(format!("multiMaterials[{i}].{m}"));
            let subs = array(mm, "materials", "a material id or null", |s| match s {
                Value::Null => Some(None),
                Value::String(s) => Some(Some(s.clone())),
                Value::Number(n) => Some(Some(n.to_string())),
                _ => None,
            });
            if let Some(id) = text(mm, "id").map_err(at)? {
                r.multi.entry(id).or_insert(subs.map_err(at)?.unwrap_or_default());
            }
        }
        r.read_nodes()?;
        Ok(r)
    }

    fn ctx(&self, what: impl Into<String>) -> Ctx<'a> {
        Ctx { file: self.file, what: what.into() }
    }

    fn warn(&mut self, message: String) {
        self.warnings.push(Warning(message));
    }

    /// Collects meshes and transform nodes with their local matrices and parents.
    fn read_nodes(&mut self) -> Result<(), ConvertError> {
        let root = self.root;
        for (array, kind, is_mesh) in [("meshes", "mesh", true), ("transformNodes", "transform node", false)] {
            for (i, obj) in list(root, array).map_err(|m| self.ctx("scene").err(m))?.iter().enumerate() {
                let cx = self.ctx(label(obj, kind, array, i));
                if !obj.is_object() {
                    return Err(self
                        .ctx(format!("{array}[{i}]"))
                        .err(format!("expected an object, found {}", show(obj))));
                }
                let trs = Trs::read(obj, Trs::IDENTITY).map_err(|m| cx.err(m))?;
                let mut animated = trs;
                animated.animate(obj).map_err(|m| cx.err(m))?;
                if let Some(pivot) = floats(obj, "pivotMatrix").map_err(|m| cx.err(m))? {
                    if pivot != IDENTITY {
                        self.warn(format!("{}: pivotMatrix is not supported and was ignored", cx.what));
                    }
                }
                if let Some(id) = text(obj, "id").map_err(|m| cx.err(m))? {
                    self.ids.entry(id).or_insert(self.nodes.len());
                }
                let local = animated.matrix();
                self.nodes.push(Node { obj, what: cx.what, trs, local, parent: None, world: None, is_mesh });
            }
        }
        for i in 0..self.nodes.len() {
            let obj = self.nodes[i].obj;
            let parent = self.parent(obj, &self.nodes[i].what.clone())?;
            self.nodes[i].parent = parent;
        }
        Ok(())
    }

    /// The node named by `obj`'s `parentId`; an unknown parent is warned about and ignored.
    fn parent(&mut self, obj: &Value, what: &str) -> Result<Option<usize>, ConvertError> {
        let Some(id) = text(obj, "parentId").map_err(|m| self.ctx(what).err(m))? else {
            return Ok(None);
        };
        let found = self.ids.get(&id).copied();
        if found.is_none() {
            self.warn(format!("{what}: parent {id:?} not found, treated as a root"));
        }
        Ok(found)
    }

    /// The world matrix of node `i` (walking up iteratively, so deep hierarchies are fine).
    fn world(&mut self, i: usize) -> Result<Matrix, ConvertError> {
        let mut chain = vec![i];
        let mut base = IDENTITY;
        while let Some(&top) = chain.last() {
            if let Some(w) = self.nodes[top].world {
                base = w;
                chain.pop();
                break;
            }
            let Some(p) = self.nodes[top].parent else {
                break;
            };
            if chain.len() > self.nodes.len() {
                let names: Vec<&str> = chain.iter().rev().take(8).map(|&n| self.nodes[n].what.as_str()).collect();
                return Err(self
                    .ctx(self.nodes[i].what.clone())
                    .err(format!("parentId cycle through {}", names.join(" -> "))));
            }
            chain.push(p);
        }
        for &n in chain.iter().rev() {
            base = mul(&self.nodes[n].local, &base);
            self.nodes[n].world = Some(base);
        }
        Ok(base)
    }

    fn parent_world(&mut self, parent: Option<usize>) -> Result<Matrix, ConvertError> {
        parent.map_or(Ok(IDENTITY), |p| self.world(p))
    }

    fn read_meshes(&mut self) -> Result<(), ConvertError> {
        for i in 0..self.nodes.len() {
            if self.nodes[i].is_mesh {
                self.read_mesh(i)?;
            }
        }
        Ok(())
    }

    /// Finds a mesh's vertex data wherever the file keeps it.
    fn geometry(&self, obj: &Value, cx: &Ctx) -> Result<Geometry, ConvertError> {
        let e = |m: String| cx.err(m);
        if get(obj, "positions").is_some() {
            return split_geometry(obj).map_err(e);
        }
        if get(obj, "vertices").is_some() {
            return legacy_geometry(obj).map_err(e);
        }
        if let Some(name) = text(obj, "delayLoadingFile").map_err(e)? {
            let Some(dir) = self.base_dir else {
                return Err(cx.err(format!("delayLoadingFile {name:?}: no directory to read it from")));
            };
            let path = dir.join(&name);
            let data = std::fs::read(&path).map_err(|err| io_error(&path, &err))?;
            let in_file = |m: String| cx.err(format!("{name}: {m}"));
            let mut geom = match get(obj, "_binaryInfo") {
                Some(info) => binary_geometry(&data, info).map_err(in_file)?,
                None => {
                    let side: Value = serde_json::from_slice(&data).map_err(|err| in_file(err.to_string()))?;
                    split_geometry(&side).map_err(in_file)?
                }
            };
            if let Some(subs) = submeshes(obj).map_err(e)? {
                geom.submeshes = Some(subs);
            }
            return Ok(geom);
        }
        if let Some(id) = text(obj, "geometryId").map_err(e)? {
            let all = get(self.root, "geometries").map_or(Ok(&[][..]), |g| list(g, "vertexData"));
            let all = all.map_err(|m| self.ctx("scene").err(format!("geometries.{m}")))?;
            let data = all.iter().find(|g| text(g, "id").ok().flatten().as_deref() == Some(&*id));
            let data = data.ok_or_else(|| cx.err(format!("geometryId {id:?} is not in geometries.vertexData")))?;
            let mut geom = split_geometry(data).map_err(|m| cx.err(format!("geometry {id:?}: {m}")))?;
            geom.submeshes = submeshes(obj).map_err(e)?;
            return Ok(geom);
        }
        split_geometry(obj).map_err(e)
    }

    fn read_mesh(&mut self, node: usize) -> Result<(), ConvertError> {
        let obj = self.nodes[node].obj;
        let cx = self.ctx(self.nodes[node].what.clone());
        let e = |m: String| cx.err(m);
        let geom = self.geometry(obj, &cx)?;
        if geom.positions.is_empty() {
            let claimed = ["positions", "vertices", "indices", "normals", "uvs", "delayLoadingFile", "geometryId"];
            if claimed.iter().any(|k| get(obj, k).is_some()) {
                self.warn(format!("{}: has no vertices, treated as a transform node", cx.what));
            }
            return Ok(());
        }
        if !flag(obj, "isVisible", true).map_err(e)? || !flag(obj, "isEnabled", true).map_err(e)? {
            self.warn(format!("{}: hidden (isVisible/isEnabled false), skipped", cx.what));
            return Ok(());
        }

        // Vertex data.
        let p = &geom.positions;
        if p.len() % 3 != 0 {
            return Err(cx.err(format!("positions: {} numbers is not a multiple of 3", p.len())));
        }
        let n = p.len() / 3;
        if u32::try_from(n).is_err() {
            return Err(cx.err(format!("positions: {n} vertices is more than 2^32 - 1")));
        }
        let sizes = [("normals", &geom.normals, 3), ("uvs", &geom.uvs[0], 2), ("uvs2", &geom.uvs[1], 2)];
        for (key, data, per) in sizes {
            if let Some(d) = data.as_ref().filter(|d| d.len() != per * n) {
                return Err(cx.err(format!("{key}: {} numbers but {n} vertices need {}", d.len(), per * n)));
            }
        }
        let colors = match &geom.colors {
            None => None,
            Some(c) if c.len() == 4 * n => Some(c.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()),
            Some(c) if c.len() == 3 * n => Some(c.chunks_exact(3).map(|c| [c[0], c[1], c[2], 1.]).collect()),
            Some(c) => {
                return Err(cx.err(format!(
                    "colors: {} numbers but {n} vertices need {} (RGBA) or {} (RGB)",
                    c.len(),
                    4 * n,
                    3 * n
                )))
            }
        };
        let indices = match geom.indices {
            Some(ix) => ix,
            None if n % 3 == 0 => (0..n as u32).collect(),
            None => return Err(cx.err(format!("no indices, and the {n} vertices are not a whole number of triangles"))),
        };
        if indices.len() % 3 != 0 || u32::try_from(indices.len()).is_err() {
            return Err(cx.err(format!("indices: {} indices is not a multiple of 3 below 2^32", indices.len())));
        }
        if let Some((i, ix)) = indices.iter().enumerate().find(|(_, &ix)| ix as usize >= n) {
            return Err(cx.err(format!("indices[{i}] = {ix} but only {n} vertices")));
        }
        let positions: Vec<[f32; 3]> = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let normals = self.normals(&positions, &indices, geom.normals.as_deref(), &cx.what);

        // Sub-meshes and their materials.
        let material_id = text(obj, "materialId").map_err(e)?;
        let raw = geom.submeshes.unwrap_or_else(|| vec![[0, 0, indices.len() as u64]]);
        let (mut submeshes, mut slots, mut ranges) = (Vec::new(), Vec::new(), Vec::new());
        for (k, &[material_index, start, count]) in raw.iter().enumerate() {
            let end = start.saturating_add(count);
            if end > indices.len() as u64 {
                return Err(cx.err(format!(
                    "subMeshes[{k}]: indexStart {start} + indexCount {count} > {} indices",
                    indices.len()
                )));
            }
            if start % 3 != 0 || count % 3 != 0 {
                return Err(
                    cx.err(format!("subMeshes[{k}]: indexStart {start} and indexCount {count} must be multiples of 3"))
                );
            }
            if count == 0 {
                continue;
            }
            let slot = self.submesh_material(material_id.as_deref(), material_index, &cx.what)?;
            submeshes.push(SubMeshData {
                material: slot.map(|s| s.index),
                index_start: start as u32,
                index_count: count as u32,
            });
            slots.push(slot);
            ranges.push((start, end));
        }
        if submeshes.is_empty() {
            self.warn(format!("{}: no triangles to draw, skipped", cx.what));
            return Ok(());
        }
        ranges.sort_unstable();
        let mut covered = 0;
        for &(start, end) in &ranges {
            covered = if start == covered { end } else { u64::MAX };
        }
        if covered != indices.len() as u64 {
            self.warn(format!("{}: subMeshes do not cover each index exactly once (drawn as written)", cx.what));
        }

        let uvs = self.bake_uvs(&geom.uvs, &slots, &cx.what);
        let mesh = MeshData {
            name: text(obj, "name").map_err(e)?.or(text(obj, "id").map_err(e)?).unwrap_or_default(),
            world: self.world(node)?,
            positions,
            normals,
            uvs,
            colors,
            indices,
            submeshes,
        };
        let index = self.scene.meshes.len();
        self.scene.meshes.push(mesh);
        self.read_instances(node, index, &cx)
    }

    /// Unit normals: the file's (a zero one replaced by the smooth normal), else smooth ones.
    fn normals(&mut self, positions: &[[f32; 3]], indices: &[u32], given: Option<&[f32]>, what: &str) -> Vec<[f32; 3]> {
        let given: Vec<Option<[f32; 3]>> = match given {
            Some(g) => g.chunks_exact(3).map(|c| unit([c[0], c[1], c[2]])).collect(),
            None => vec![None; positions.len()],
        };
        let missing = given.iter().filter(|g| g.is_none()).count();
        if missing == 0 {
            return given.into_iter().flatten().collect();
        }
        if missing < positions.len() {
            self.warn(format!("{what}: {missing} zero-length normals replaced by computed ones"));
        }
        let smooth = smooth_normals(positions, indices);
        given.iter().zip(smooth).map(|(g, s)| g.or_else(|| unit(s)).unwrap_or([0., 1., 0.])).collect()
    }

    /// The mesh's UVs with the textured material's matrix and the UV origin applied.
    fn bake_uvs(
        &mut self,
        sets: &[Option<Vec<f32>>; 2],
        slots: &[Option<MatSlot>],
        what: &str,
    ) -> Option<Vec<[f32; 2]>> {
        let maps: Vec<UvMap> = slots.iter().flatten().filter_map(|s| s.uv).collect();
        let map = maps.first().copied();
        if maps.iter().any(|m| Some(*m) != map) {
            self.warn(format!("{what}: sub-meshes use different texture matrices; the first textured one is used"));
        }
        let mut set = map.map_or(0, |m| m.set);
        if set == 1 && sets[1].is_none() {
            self.warn(format!("{what}: texture uses coordinatesIndex 1 but the mesh has no uvs2; uvs used"));
            set = 0;
        }
        let top = self.opts.uv_origin == UvOrigin::Top;
        let uvs = sets[set].as_ref()?.chunks_exact(2).map(|c| {
            let [u, v] = map.map_or([c[0], c[1]], |m| m.apply([c[0], c[1]]));
            [u, if top { 1. - v } else { v }]
        });
        Some(uvs.collect())
    }

    fn read_instances(&mut self, node: usize, mesh: usize, mesh_cx: &Ctx) -> Result<(), ConvertError> {
        let (obj, base) = (self.nodes[node].obj, self.nodes[node].trs);
        for (k, inst) in list(obj, "instances").map_err(|m| mesh_cx.err(m))?.iter().enumerate() {
            let cx = self.ctx(format!("{}: {}", mesh_cx.what, label(inst, "instance", "instances", k)));
            if !inst.is_object() {
                return Err(cx.err(format!("expected an object, found {}", show(inst))));
            }
            if !flag(inst, "isEnabled", true).map_err(|m| cx.err(m))? {
                continue;
            }
            let trs = Trs::read(inst, base).map_err(|m| cx.err(m))?;
            let parent = match inst.get("parentId") {
                Some(_) => self.parent(inst, &cx.what)?,
                None => self.nodes[node].parent,
            };
            let world = mul(&trs.matrix(), &self.parent_world(parent)?);
            let mesh = u16::try_from(mesh).map_err(|_| cx.err("more than 65536 meshes with instances"))?;
            self.scene.instances.push(InstanceData { mesh, world });
        }
        Ok(())
    }

    // -----------------------------------------------------------------------------------------
    // Materials and textures.

    fn submesh_material(&mut self, id: Option<&str>, index: u64, what: &str) -> Result<Option<MatSlot>, ConvertError> {
        let Some(id) = id else { return Ok(None) };
        let Some(subs) = self.multi.get(id) else {
            return self.material(id, what);
        };
        match usize::try_from(index).ok().and_then(|i| subs.get(i)).cloned() {
            Some(Some(sub)) => self.material(&sub, what),
            Some(None) => Ok(None),
            None => {
                let len = subs.len();
                self.warn(format!("{what}: materialIndex {index} but multi-material {id:?} has {len} materials; default material used"));
                Ok(None)
            }
        }
    }

    fn material(&mut self, id: &str, what: &str) -> Result<Option<MatSlot>, ConvertError> {
        if let Some(slot) = self.mat_cache.get(id) {
            return Ok(*slot);
        }
        let slot = match self.materials.get(id).copied() {
            Some(obj) => Some(self.convert_material(obj, id, what)?),
            None => {
                self.warn(format!("{what}: material {id:?} not found, default material used"));
                None
            }
        };
        self.mat_cache.insert(id.to_owned(), slot);
        Ok(slot)
    }

    /// A StandardMaterial (`diffuse`, `diffuseTexture`) or a PBR material (`albedo`,
    /// `albedoColor`, `baseColor`, `albedoTexture`, `baseTexture`...).
    fn convert_material(&mut self, obj: &Value, id: &str, what: &str) -> Result<MatSlot, ConvertError> {
        let name = text(obj, "name").ok().flatten().unwrap_or_else(|| id.to_owned());
        let cx = self.ctx(format!("{what}: material {name:?}"));
        let e = |m: String| cx.err(m);
        let custom = text(obj, "customType").map_err(e)?.unwrap_or_default();
        let pbr_keys = ["albedo", "albedoColor", "albedoTexture", "baseColor", "baseTexture"];
        let pbr = custom.contains("PBR") || pbr_keys.iter().any(|k| get(obj, k).is_some());
        let (colour_keys, texture_keys): (&[&str], &[&str]) = if pbr {
            (
                &["albedo", "albedoColor", "baseColor", "diffuseColor"],
                &["albedoTexture", "baseTexture", "diffuseTexture"],
            )
        } else {
            (&["diffuse"], &["diffuseTexture"])
        };
        let mut diffuse = None;
        for k in colour_keys {
            diffuse = diffuse.or(vector(obj, k).map_err(e)?);
        }
        let mut data = MaterialData {
            name,
            diffuse: diffuse.unwrap_or([1.; 3]),
            alpha: scalar(obj, "alpha", 1.).map_err(e)?,
            back_face_culling: flag(obj, "backFaceCulling", true).map_err(e)?
                && !flag(obj, "doubleSided", false).map_err(e)?,
            ..MaterialData::default()
        };
        let mut uv = None;
        if let Some((key, tex)) = texture_keys.iter().find_map(|k| Some((k, get(obj, k)?))) {
            let at = |m: String| cx.err(format!("{key}.{m}"));
            if !tex.is_object() {
                return Err(cx.err(format!("{key}: expected an object, found {}", show(tex))));
            }
            let opaque = get(obj, "transparencyMode").and_then(finite) == Some(0.);
            let keep_alpha = flag(tex, "hasAlpha", false).map_err(at)? && !opaque;
            data.texture = self.texture(tex, keep_alpha, &cx)?;
            [data.wrap_u, data.wrap_v] = [wrap(tex, "wrapU").map_err(at)?, wrap(tex, "wrapV").map_err(at)?];
            if data.texture.is_some() {
                let mode = count(tex, "coordinatesMode", Some(0)).map_err(at)?;
                if mode != 0 {
                    self.warn(format!("{}: {key}.coordinatesMode {mode} is not supported, explicit UVs used", cx.what));
                }
                uv = Some(UvMap {
                    matrix: texture_matrix(tex).map_err(at)?,
                    set: usize::from(count(tex, "coordinatesIndex", Some(0)).map_err(at)? > 0),
                    flip: !flag(tex, "invertY", true).map_err(at)?,
                });
            }
        }
        let index = u16::try_from(self.scene.materials.len()).map_err(|_| cx.err("more than 65536 materials"))?;
        self.scene.materials.push(data);
        Ok(MatSlot { index, uv })
    }

    /// Decodes (once per name) a texture from its file or its `base64String`; a failure is a
    /// warning and `None`.
    fn texture(&mut self, tex: &Value, keep_alpha: bool, cx: &Ctx) -> Result<Option<u16>, ConvertError> {
        let at = |m: String| cx.err(m);
        let base64 = text(tex, "base64String").map_err(at)?;
        // Babylon.js ignores nameless textures, even embedded ones.
        let Some(name) = text(tex, "name").map_err(at)?.filter(|n| !n.is_empty()) else {
            return Ok(None);
        };
        let key = (name.clone(), keep_alpha);
        if let Some(&index) = self.tex_cache.get(&key) {
            return Ok(index);
        }
        let index = match self.load_image(&name, base64.as_deref()) {
            Ok(image) => Some(self.push_texture(name.clone(), image, keep_alpha, cx)?),
            Err(why) => {
                let shown: String = name.chars().take(60).collect();
                self.warn(format!("{}: texture {shown:?} {why}, using the diffuse colour", cx.what));
                None
            }
        };
        self.tex_cache.insert(key, index);
        Ok(index)
    }

    fn load_image(&self, name: &str, base64: Option<&str>) -> Result<image::RgbaImage, String> {
        let bytes = match base64.or_else(|| name.starts_with("data:").then_some(name)) {
            Some(b64) => decode_base64(b64).map_err(|e| format!("has invalid base64 data ({e})"))?,
            None => {
                let dir = self.base_dir.ok_or("not found (no directory to look in)")?;
                let path = dir.join(name);
                std::fs::read(&path).map_err(|e| format!("not found ({}: {e})", path.display()))?
            }
        };
        // The content decides (embedded JPEG names hide PNGs); TGA has no signature: use the name.
        let mut formats: Vec<image::ImageFormat> = image::guess_format(&bytes).into_iter().collect();
        formats.extend(image::ImageFormat::from_path(name).ok().filter(|f| !formats.contains(f)));
        let mut why = String::from("is in an unknown image format");
        for format in formats {
            match image::load_from_memory_with_format(&bytes, format) {
                Ok(img) if img.width() > 0 && img.height() > 0 => return Ok(img.into_rgba8()),
                Ok(_) => why = "is empty".into(),
                Err(e) => why = format!("could not be decoded ({e})"),
            }
        }
        Err(why)
    }

    fn push_texture(
        &mut self,
        name: String,
        image: image::RgbaImage,
        keep_alpha: bool,
        cx: &Ctx,
    ) -> Result<u16, ConvertError> {
        let (w, h) = texture_size(image.width(), image.height(), self.opts);
        let mut image = if (w, h) == image.dimensions() {
            image
        } else {
            image::imageops::resize(&image, w, h, image::imageops::FilterType::Triangle)
        };
        if !keep_alpha {
            image.pixels_mut().for_each(|p| p.0[3] = 255);
        }
        let index = u16::try_from(self.scene.textures.len()).map_err(|_| cx.err("more than 65536 textures"))?;
        let (width, height) = (w as u16, h as u16); // texture_size keeps both in 1..=65535
        self.scene.textures.push(TextureData { name, width, height, rgba: image.into_raw() });
        Ok(index)
    }

    // -----------------------------------------------------------------------------------------
    // Lights and camera.

    fn read_lights(&mut self) -> Result<(), ConvertError> {
        let lights = list(self.root, "lights").map_err(|m| self.ctx("scene").err(m))?;
        for (i, l) in lights.iter().enumerate() {
            let cx = self.ctx(label(l, "light", "lights", i));
            let e = |m: String| cx.err(m);
            let kind = match get(l, "type").and_then(whole) {
                Some(0) => LightKind::Point,
                Some(1) => LightKind::Directional,
                Some(3) => LightKind::Hemispheric,
                _ => {
                    let t = get(l, "type").map_or("missing".into(), show);
                    self.warn(format!("{}: light type {t} is not supported, skipped", cx.what));
                    continue;
                }
            };
            if !flag(l, "isEnabled", true).map_err(e)? {
                self.warn(format!("{}: disabled, skipped", cx.what));
                continue;
            }
            let data = vector(l, "data").map_err(e)?; // 2013 files: position or direction
            let (key, w, default) = match kind {
                LightKind::Point => ("position", 1., [0.; 3]),
                LightKind::Directional => ("direction", 0., [0., -1., 0.]),
                LightKind::Hemispheric => ("direction", 0., [0., 1., 0.]),
            };
            let vector3 = vector(l, key).map_err(e)?.or(data).unwrap_or(default);
            let parent = self.parent(l, &cx.what)?;
            let world = self.parent_world(parent)?;
            self.scene.lights.push(LightData {
                kind,
                vector: transform(&world, vector3, w),
                diffuse: vector(l, "diffuse").map_err(e)?.unwrap_or([1.; 3]),
                intensity: scalar(l, "intensity", 1.).map_err(e)?,
            });
        }
        Ok(())
    }

    fn read_camera(&mut self) -> Result<(), ConvertError> {
        let scx = self.ctx("scene");
        let cameras = list(self.root, "cameras").map_err(|m| scx.err(m))?;
        let active = match text(self.root, "activeCameraID").map_err(|m| scx.err(m))? {
            Some(id) => Some(id),
            None => text(self.root, "activeCamera").map_err(|m| scx.err(m))?,
        };
        let found = active
            .as_deref()
            .and_then(|id| cameras.iter().position(|c| text(c, "id").ok().flatten().as_deref() == Some(id)));
        if let (Some(id), None, false) = (&active, found, cameras.is_empty()) {
            self.warn(format!("active camera {id:?} not found, the first camera used"));
        }
        let Some(i) = found.or((!cameras.is_empty()).then_some(0)) else {
            return Ok(());
        };
        let c = &cameras[i];
        let cx = self.ctx(label(c, "camera", "cameras", i));
        let e = |m: String| cx.err(m);
        if !c.is_object() {
            return Err(cx.err(format!("expected an object, found {}", show(c))));
        }
        let position = vector(c, "position").map_err(e)?.unwrap_or([0.; 3]);
        let target = match (vector(c, "target").map_err(e)?, text(c, "lockedTargetId").map_err(e)?) {
            (Some(t), _) => t,
            (None, Some(id)) if self.ids.contains_key(&id) => {
                let w = self.world(self.ids[&id])?;
                [w[12], w[13], w[14]]
            }
            _ if text(c, "type").map_err(e)?.as_deref() == Some("ArcRotateCamera") => [0.; 3],
            _ => {
                let forward = transform(&Trs::read(c, Trs::IDENTITY).map_err(e)?.rotation_matrix(), [0., 0., 1.], 0.);
                core::array::from_fn(|k| position[k] + forward[k])
            }
        };
        let parent = self.parent(c, &cx.what)?;
        let world = self.parent_world(parent)?;
        self.scene.camera = Some(CameraData {
            position: transform(&world, position, 1.),
            target: transform(&world, target, 1.),
            fov: scalar(c, "fov", 0.8).map_err(e)?,
            near: scalar(c, "minZ", 1.).map_err(e)?,
            far: scalar(c, "maxZ", 10000.).map_err(e)?,
        });
        Ok(())
    }
}

/// `wrapU`/`wrapV`: 0 clamp, 1 repeat, 2 mirror; old files write booleans (true = repeat).
fn wrap(tex: &Value, key: &str) -> Res<Wrap> {
    Ok(match get(tex, key) {
        Some(Value::Bool(false)) => Wrap::Clamp,
        Some(v) if !v.is_boolean() => match finite(v).map(|x| x as i64) {
            Some(0) => Wrap::Clamp,
            Some(2) => Wrap::Mirror,
            Some(_) => Wrap::Repeat,
            None => return Err(format!("{key}: expected a wrap mode, found {}", show(v))),
        },
        _ => Wrap::Repeat,
    })
}

/// Decodes a base64 payload or a whole `data:...;base64,` URL.
fn decode_base64(s: &str) -> Result<Vec<u8>, base64::DecodeError> {
    const ENGINE: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new()
            .with_decode_padding_mode(DecodePaddingMode::Indifferent)
            .with_decode_allow_trailing_bits(true),
    );
    let payload = if s.starts_with("data:") { s.split_once(',').map_or("", |(_, p)| p) } else { s };
    let clean: String = payload.chars().filter(|c| !c.is_ascii_whitespace()).collect();
    ENGINE.decode(clean)
}

/// The size a `w` x `h` image is stored at: `max_texture`, then `power_of_two`, and never more
/// than 65535 on a side.
fn texture_size(w: u32, h: u32, opts: &ConvertOptions) -> (u32, u32) {
    let limit = opts.max_texture.unwrap_or(u32::MAX).clamp(1, u32::from(u16::MAX));
    let (mut w, mut h) = (w.max(1), h.max(1));
    if w.max(h) > limit {
        let scale = f64::from(limit) / f64::from(w.max(h));
        let fit = |x: u32| ((f64::from(x) * scale).round() as u32).clamp(1, limit);
        (w, h) = (fit(w), fit(h));
    }
    if opts.power_of_two {
        let floor_pow2 = |x: u32| 1 << (31 - x.leading_zeros());
        (w, h) = (floor_pow2(w), floor_pow2(h));
    }
    (w, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn rotation_y_follows_the_spec() {
        // Ry(a) = [c 0 -s; 0 1 0; s 0 c], p' = p · M.
        let m = euler_matrix([0., 0.5, 0.]);
        let p = transform(&m, [1., 0., 0.], 1.);
        assert!(close(&p, &[libm::cosf(0.5), 0., -libm::sinf(0.5)]), "{p:?}");
        // The same rotation as a quaternion (x, y, z, w) = (0, sin(a/2), 0, cos(a/2)).
        let q = quat_matrix([0., libm::sinf(0.25), 0., libm::cosf(0.25)]);
        assert!(close(&m, &q));
    }

    #[test]
    fn euler_order_is_z_then_x_then_y() {
        let (rx, ry, rz) = (0.3, -0.7, 1.1);
        let single = |r| euler_matrix(r);
        let expected = mul(&mul(&single([0., 0., rz]), &single([rx, 0., 0.])), &single([0., ry, 0.]));
        assert!(close(&euler_matrix([rx, ry, rz]), &expected));
        // Rz(a) maps x to (c, s, 0); Rx(a) maps y to (0, c, s).
        assert!(close(&transform(&single([0., 0., 0.4]), [1., 0., 0.], 0.), &[libm::cosf(0.4), libm::sinf(0.4), 0.]));
        assert!(close(&transform(&single([0.4, 0., 0.]), [0., 1., 0.], 0.), &[0., libm::cosf(0.4), libm::sinf(0.4)]));
    }

    #[test]
    fn local_matrix_is_scale_rotate_translate() {
        let trs = Trs {
            position: [1., 2., 3.],
            rotation: [0., core::f32::consts::FRAC_PI_2, 0.],
            quaternion: None,
            scaling: [2., 1., 1.],
        };
        // (1,0,0) scaled to (2,0,0), rotated by Ry(90°) to (0,0,-2), translated to (1,2,1).
        assert!(close(&transform(&trs.matrix(), [1., 0., 0.], 1.), &[1., 2., 1.]));
        // World = Local · World(parent): the child's transform applies first.
        let parent = Trs { position: [10., 0., 0.], ..Trs::IDENTITY }.matrix();
        assert!(close(&transform(&mul(&trs.matrix(), &parent), [1., 0., 0.], 1.), &[11., 2., 1.]));
    }

    #[test]
    fn texture_matrix_scales_and_offsets() {
        let tex = serde_json::json!({"uScale": 5, "vScale": -1, "uOffset": 0.25, "vOffset": 0.5});
        let m = texture_matrix(&tex).unwrap();
        assert!(close(&m, &[5., 0., 0.25, 0., -1., 0.5]), "{m:?}");
        // wAng rotates around the centre (0.5, 0.5): the centre stays put.
        let rot = texture_matrix(&serde_json::json!({"wAng": 1.0})).unwrap();
        let map = UvMap { matrix: rot, set: 0, flip: false };
        assert!(close(&map.apply([0.5, 0.5]), &[0.5, 0.5]));
    }

    #[test]
    fn base64_accepts_data_urls_and_bare_payloads() {
        assert_eq!(decode_base64("data:image/png;base64,aGk=").unwrap(), b"hi");
        assert_eq!(decode_base64("aGk").unwrap(), b"hi");
    }

    #[test]
    fn texture_sizes() {
        let o = |max_texture, power_of_two| ConvertOptions { max_texture, power_of_two, ..Default::default() };
        assert_eq!(texture_size(512, 256, &o(Some(128), false)), (128, 64));
        assert_eq!(texture_size(300, 100, &o(None, true)), (256, 64));
        assert_eq!(texture_size(1000, 3, &o(Some(100), true)), (64, 1));
    }
}
