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
//! - **Animations** are read into `Scene::animation` by `animation` (its module documentation
//!   has the rules): tracks of meshes' and transform nodes' position, rotation and scaling
//!   (whole or one component) and of morph target influences, the groups that play them
//!   (`animationGroups`, then one for each node's or morph target's own tracks), the nodes
//!   they move with the meshes those carry, and the meshes' morph targets; the active camera's
//!   and the drawn lights' tracks are `view_tracks`' (keys in world space, the camera's aim).
//!   A missing `framePerSecond` is 30; keys out of frame order are sorted, with a warning.
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
//!
//! This module owns the reader's public face ([`read_babylon`], [`read_babylon_file`],
//! [`ConvertOptions`], [`UvOrigin`], [`Warning`], [`ConvertError`]) and the reader's state; the
//! work is split by concern into `fields` (JSON field access), `transform` (matrices, rotations,
//! first frames), `node` (hierarchy), `geometry` (where vertex data lives), `mesh` (meshes,
//! sub-meshes, instances), `animation` (groups, animated nodes, morph targets), `track` (one
//! animation's property and keys), `view_tracks` (the camera's and lights' animations),
//! `skeleton` (bones, their matrix keys, skin influences),
//! `material`, `texture`, `light`, `camera` and `unsupported` (a warning for each feature the
//! file has and soft3d does not draw or play). Writing the result as
//! `.s3d` is not its job (that is `convert::emit`).

mod animation;
mod camera;
mod fields;
mod fog;
mod geometry;
mod light;
mod material;
mod mesh;
mod node;
mod skeleton;
mod texture;
mod track;
mod transform;
mod unsupported;
mod view_tracks;

use std::borrow::ToOwned;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use serde_json::Value;

use super::scene::Scene;
use fields::{show, Ctx};
use material::{material_table, multi_material_table, MatSlot};
use node::Node;

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
    // The camera and lights before the animations, which move them.
    reader.read_lights()?;
    reader.read_camera()?;
    reader.read_fog()?;
    reader.read_animation()?;
    reader.read_skeletons()?;
    reader.warn_unsupported();
    if let Some(what) = reader.legacy_uvs.take() {
        reader.warn(std::format!(
            "{what}: textured in the 2013 interleaved layout, whose exporters wrote V either way up: \
             if the texture looks upside down, convert with the UV origin at the top (--uv-origin top)"
        ));
    }
    Ok((reader.scene, reader.warnings))
}

fn io_error(path: &Path, e: &std::io::Error) -> ConvertError {
    ConvertError::Io { path: path.display().to_string(), message: e.to_string() }
}

/// One scene being read: the JSON root, the material tables and caches, the node hierarchy,
/// and the [`Scene`] and [`Warning`]s being built.
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
    /// Nodes by `id`, `name` and `uniqueId` (see `node`).
    ids: HashMap<String, usize>,
    names: HashMap<String, usize>,
    unique_ids: HashMap<String, usize>,
    scene: Scene,
    warnings: Vec<Warning>,
    /// The first textured mesh in the 2013 layout read with the UV origin at the bottom (see
    /// `read_babylon`'s hint).
    legacy_uvs: Option<String>,
    /// The camera and lights stored, for their animations (see `view_tracks`).
    view: view_tracks::Stored,
}

impl<'a> Reader<'a> {
    /// Checks that the root is an object, indexes the materials and multi-materials and reads
    /// the node hierarchy.
    fn new(
        root: &'a Value,
        base_dir: Option<&'a Path>,
        file: &'a str,
        opts: &'a ConvertOptions,
    ) -> Result<Self, ConvertError> {
        let cx = Ctx { file, what: "scene".into() };
        if !root.is_object() {
            return Err(cx.err(std::format!("expected a JSON object, found {}", show(root))));
        }
        let materials = material_table(root, &cx)?;
        let multi = multi_material_table(root, &cx)?;
        let mut r = Reader {
            file,
            base_dir,
            opts,
            root,
            materials,
            multi,
            mat_cache: HashMap::new(),
            tex_cache: HashMap::new(),
            nodes: Vec::new(),
            ids: HashMap::new(),
            names: HashMap::new(),
            unique_ids: HashMap::new(),
            scene: Scene::default(),
            warnings: Vec::new(),
            legacy_uvs: None,
            view: view_tracks::Stored::default(),
        };
        r.read_nodes()?;
        Ok(r)
    }

    fn ctx(&self, what: impl Into<String>) -> Ctx<'a> {
        Ctx { file: self.file, what: what.into() }
    }

    /// Records `message` once (a node read as a parent and as itself would say it twice).
    fn warn(&mut self, message: String) {
        if self.warnings.iter().all(|w| w.0 != message) {
            self.warnings.push(Warning(message));
        }
    }
}
