//! The converter's in-memory scene: what a `.babylon` file means once every Babylon.js rule
//! (hierarchy, rotations, texture matrices, UV origin) has been applied. `convert::emit`
//! writes it as `.s3d`; the `.babylon` reader produces it.

use std::string::String;
use std::vec::Vec;

/// A row-vector 4x4 matrix in Babylon.js layout: `m[12..15]` is the translation,
/// `p' = [x y z 1] · m`.
pub type Matrix = [f32; 16];

/// The identity [`Matrix`].
pub const IDENTITY: Matrix = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// A whole converted scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// Geometry, each with the world transform of the mesh itself.
    pub meshes: Vec<MeshData>,
    /// Materials referenced by sub-meshes.
    pub materials: Vec<MaterialData>,
    /// Decoded textures referenced by materials.
    pub textures: Vec<TextureData>,
    /// Extra copies of meshes with their own world transform (`instances`).
    pub instances: Vec<InstanceData>,
    /// Scene lights.
    pub lights: Vec<LightData>,
    /// The active camera, when the file has one.
    pub camera: Option<CameraData>,
    /// What makes the scene move: empty for a still scene.
    pub animation: AnimationData,
    /// The scene's fog, when it has some.
    pub fog: Option<FogData>,
}

/// A scene's animations: the nodes its tracks move, the meshes those nodes carry, the meshes'
/// morph targets, the tracks and their groups.
///
/// Matrices are Babylon.js row-vector matrices. A mesh linked to an animated node is drawn with
/// the world matrix `below · World(node)` instead of its [`MeshData::world`], where
/// `World(node) = Local(node at the frame) · above · World(parent node)` (`World` of no node is
/// the identity): `above` is the product of the still nodes' local matrices between a node and
/// its animated parent (or the world matrix of its still ancestors when it has none), `below`
/// that of the still nodes between the mesh (itself included) and its animated node (the
/// identity when the mesh's own node is the animated one).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnimationData {
    /// Nodes moved by tracks, each after its animated parent.
    pub nodes: Vec<NodeData>,
    /// Meshes whose world matrix follows an animated node.
    pub links: Vec<MeshLink>,
    /// Meshes with morph targets.
    pub morphs: Vec<MorphData>,
    /// Skinned meshes: the bones (nodes) that move their vertices.
    pub skins: Vec<SkinData>,
    /// Every animation track (of nodes and of morph target influences).
    pub tracks: Vec<TrackData>,
    /// Named sets of tracks played together (`animationGroups`, and one group for the tracks
    /// of each node, morph target, camera or light that are in no file group: `autoAnimate`
    /// ranges and animations a scene starts with `beginAnimation`).
    pub groups: Vec<GroupData>,
    /// How the camera aims while tracks move it ([`TrackTarget::Camera`]): the rest values are
    /// [`Scene::camera`]'s, and a light's rest values its [`Scene::lights`] entry's.
    pub camera_aim: CameraAim,
}

/// How the point an animated camera looks at follows it (Babylon.js: an `ArcRotateCamera` or a
/// locked target keeps looking at its target, a `FreeCamera` keeps its rotation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum CameraAim {
    /// At [`CameraData::target`], or where target tracks put it.
    #[default]
    Target,
    /// Along a fixed direction: `position + (target - position)` of [`Scene::camera`].
    Direction,
    /// By its rotation: `position + distance · forward(rotation)`, forward being `(0, 0, 1)`
    /// turned by `RotationYawPitchRoll(y, x, z)`; rotation tracks turn it.
    Rotation {
        /// The Euler rotation at rest (x, y, z), radians.
        rotation: [f32; 3],
        /// How far ahead of the eye the target lies.
        distance: f32,
    },
}

impl AnimationData {
    /// True when nothing moves.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty() && self.morphs.is_empty() && self.skins.is_empty()
    }
}

/// A node that tracks move: its position, rotation and scaling at rest (what no track sets).
#[derive(Clone, Debug, PartialEq)]
pub struct NodeData {
    /// The node's `name` (or `id`).
    pub name: String,
    /// Its nearest animated ancestor: an index into [`AnimationData::nodes`], lower than its own.
    pub parent: Option<u16>,
    /// The still nodes between it and `parent` (see [`AnimationData`]).
    pub above: Matrix,
    /// Position at rest.
    pub position: [f32; 3],
    /// Rotation at rest.
    pub rotation: Rotation,
    /// Scaling at rest.
    pub scaling: [f32; 3],
}

/// A node's rotation, as Babylon.js stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rotation {
    /// `rotation`: Euler angles (x, y, z) in radians, `RotationYawPitchRoll(y, x, z)`.
    Euler([f32; 3]),
    /// `rotationQuaternion` (x, y, z, w): when a node has one, its `rotation` is ignored.
    Quaternion([f32; 4]),
}

/// A mesh whose world matrix follows an animated node.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshLink {
    /// Index into [`Scene::meshes`].
    pub mesh: u16,
    /// Index into [`AnimationData::nodes`].
    pub node: u16,
    /// The still nodes between the mesh and the node (see [`AnimationData`]).
    pub below: Matrix,
}

/// A skinned mesh: Babylon.js's linear blend skinning, `p' = Σ wᵢ · p · Sᵢ` (then the mesh's
/// world matrix) with `Sᵢ = inverse_bind · World(bone node)`, bones being nodes in the mesh's
/// own space (a root bone's `above` is the identity).
#[derive(Clone, Debug, PartialEq)]
pub struct SkinData {
    /// Index into [`Scene::meshes`].
    pub mesh: u16,
    /// The palette: what each vertex's bone indices name.
    pub bones: Vec<SkinBone>,
    /// One a vertex: four bone indices (into `bones`) and their weights.
    pub vertices: Vec<Influence>,
}

/// A skinned vertex's four bones (indices into [`SkinData::bones`]) and their weights.
pub type Influence = ([u8; 4], [f32; 4]);

/// A bone of a skin's palette.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinBone {
    /// Index into [`AnimationData::nodes`]: the bone's node.
    pub node: u16,
    /// The inverse of the bone's absolute bind matrix.
    pub inverse_bind: Matrix,
}

/// A mesh's morph targets.
#[derive(Clone, Debug, PartialEq)]
pub struct MorphData {
    /// Index into [`Scene::meshes`].
    pub mesh: u16,
    /// Its targets, in the manager's order.
    pub targets: Vec<MorphTargetData>,
}

/// One morph target: what it adds to each vertex at influence 1.
#[derive(Clone, Debug, PartialEq)]
pub struct MorphTargetData {
    /// The target's `name`.
    pub name: String,
    /// Its influence when no track sets it.
    pub influence: f32,
    /// Target position minus base position, one per mesh vertex (local space).
    pub positions: Vec<[f32; 3]>,
    /// Target normal minus base normal, one per vertex, when the target has normals.
    pub normals: Option<Vec<[f32; 3]>>,
}

/// What a track animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackTarget {
    /// Components `first..first + count` of a node property (`position.x` is `first` 0,
    /// `count` 1; `position` is 0 and 3; a quaternion 0 and 4).
    Node {
        /// Index into [`AnimationData::nodes`].
        node: u16,
        /// The property.
        property: NodeProperty,
        /// Its first component.
        first: u8,
        /// How many components the keys hold.
        count: u8,
    },
    /// A morph target's influence (keys of one value).
    Morph {
        /// Index into [`AnimationData::morphs`].
        morph: u16,
        /// Index into that mesh's targets.
        target: u16,
    },
    /// Components `first..first + count` of a property of [`Scene::camera`] (world space).
    Camera {
        /// The property.
        property: CameraProperty,
        /// Its first component.
        first: u8,
        /// How many components the keys hold.
        count: u8,
    },
    /// Components `first..first + count` of a property of a light (world space).
    Light {
        /// Index into [`Scene::lights`].
        light: u16,
        /// The property.
        property: LightProperty,
        /// Its first component.
        first: u8,
        /// How many components the keys hold.
        count: u8,
    },
}

/// A camera property a track sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraProperty {
    /// The eye's position.
    Position,
    /// The point looked at ([`CameraAim::Target`]).
    Target,
    /// The Euler rotation ([`CameraAim::Rotation`]).
    Rotation,
    /// The vertical field of view, radians.
    Fov,
}

/// A light property a track sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightProperty {
    /// [`LightData::vector`]: a point light's position, another's direction.
    Vector,
    /// The diffuse colour.
    Diffuse,
    /// The intensity.
    Intensity,
}

/// A node property a track sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeProperty {
    /// `position`.
    Position,
    /// `rotation` (Euler angles).
    Rotation,
    /// `scaling`.
    Scaling,
    /// `rotationQuaternion` (slerp between keys).
    RotationQuaternion,
}

/// What a track does past its last key (Babylon.js's `loopBehavior`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Loop {
    /// 0: starts again, offset by the change over one loop (played as [`Loop::Cycle`]).
    Relative,
    /// 1: starts again.
    #[default]
    Cycle,
    /// 2: keeps the last value.
    Constant,
}

/// One animation track.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackData {
    /// What it moves.
    pub target: TrackTarget,
    /// Frames a second.
    pub fps: f32,
    /// Past the last key.
    pub looping: Loop,
    /// At least one key, by increasing frame.
    pub keys: Vec<KeyData>,
}

/// A key of a track.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyData {
    /// Its frame.
    pub frame: f32,
    /// Its value (the track's `count` components).
    pub values: Vec<f32>,
    /// Hermite tangents (in, out) when the key has them, an empty one where it has the other
    /// only: Babylon.js interpolates a span with them when its first key has an out tangent and
    /// its last an in tangent (else linearly).
    pub tangents: Option<(Vec<f32>, Vec<f32>)>,
    /// `interpolation: 1` (step): the value holds until the next key.
    pub step: bool,
}

/// Tracks played together.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupData {
    /// The group's name (for a node's or morph target's own tracks, that node's or target's).
    pub name: String,
    /// First frame.
    pub from: f32,
    /// Last frame.
    pub to: f32,
    /// Whether it plays again from `from` after `to`.
    pub looping: bool,
    /// Indices into [`AnimationData::tracks`].
    pub tracks: Vec<u16>,
}

/// One mesh: indexed triangles in the mesh's local space plus its world matrix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// The mesh's `name` (or `id`).
    pub name: String,
    /// Local-to-world matrix, parents already applied.
    pub world: Matrix,
    /// Local-space positions.
    pub positions: Vec<[f32; 3]>,
    /// Local-space unit normals, one per position (computed smooth normals when the file has none).
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates, one per position, texture matrix and UV origin already applied:
    /// (0,0) is the bottom-left of the image. `None` when the mesh has no UVs.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Vertex colours RGBA in 0..=1, one per position, when the file has them.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Triangle list, three indices per triangle, each `< positions.len()`.
    pub indices: Vec<u32>,
    /// Ranges of `indices` drawn with one material (at least one, covering all indices).
    pub submeshes: Vec<SubMeshData>,
}

/// A range of a mesh's indices drawn with one material.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SubMeshData {
    /// Index into [`Scene::materials`], or `None` for the default material.
    pub material: Option<u16>,
    /// First index (a multiple of 3).
    pub index_start: u32,
    /// Number of indices (a multiple of 3).
    pub index_count: u32,
}

/// How texture coordinates outside 0..1 are folded back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Clamp to the edge texel (Babylon `wrapU = 0`).
    Clamp,
    /// Repeat (Babylon's default, `wrapU = 1`); negative coordinates repeat too.
    #[default]
    Repeat,
    /// Mirror every other repetition (Babylon `wrapU = 2`).
    Mirror,
}

/// A material: StandardMaterial's diffuse or PBR's albedo.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialData {
    /// The material's name.
    pub name: String,
    /// Diffuse (albedo) colour, linear 0..=1 as stored in the file.
    pub diffuse: [f32; 3],
    /// Opacity 0..=1.
    pub alpha: f32,
    /// Whether back faces are culled (Babylon's default: true).
    pub back_face_culling: bool,
    /// Index into [`Scene::textures`].
    pub texture: Option<u16>,
    /// Horizontal wrap mode.
    pub wrap_u: Wrap,
    /// Vertical wrap mode.
    pub wrap_v: Wrap,
}

impl Default for MaterialData {
    fn default() -> Self {
        Self {
            name: String::new(),
            diffuse: [1.0; 3],
            alpha: 1.0,
            back_face_culling: true,
            texture: None,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
        }
    }
}

/// A decoded texture, RGBA8, rows from the top of the image file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureData {
    /// The file name (or a description for embedded images).
    pub name: String,
    /// Width in texels (>= 1).
    pub width: u16,
    /// Height in texels (>= 1).
    pub height: u16,
    /// `width * height * 4` bytes, RGBA, row 0 = top row of the image file.
    pub rgba: Vec<u8>,
}

impl TextureData {
    /// True when some texel is not fully opaque (the texture needs a cut-out format).
    #[must_use]
    pub fn has_alpha(&self) -> bool {
        self.rgba.chunks_exact(4).any(|t| t[3] != 255)
    }
}

/// Another placement of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceData {
    /// Index into [`Scene::meshes`].
    pub mesh: u16,
    /// The instance's local-to-world matrix.
    pub world: Matrix,
}

/// Light types, numbered as in `.babylon` files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    /// Type 0: from a position, no distance falloff.
    Point = 0,
    /// Type 1: along a direction.
    Directional = 1,
    /// Type 3: sky/ground ambient (`vector` is the up direction).
    Hemispheric = 3,
}

/// A light source.
#[derive(Clone, Debug, PartialEq)]
pub struct LightData {
    /// The light type.
    pub kind: LightKind,
    /// World position (point) or direction (directional, hemispheric).
    pub vector: [f32; 3],
    /// Diffuse colour 0..=1.
    pub diffuse: [f32; 3],
    /// Intensity multiplier (Babylon default 1).
    pub intensity: f32,
}

/// The scene's active camera.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraData {
    /// Eye position in world space.
    pub position: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Vertical field of view in radians.
    pub fov: f32,
    /// Near clip distance (`minZ`).
    pub near: f32,
    /// Far clip distance (`maxZ`).
    pub far: f32,
}

/// The scene's fog (see [`Fog`](crate::Fog), which it becomes).
#[derive(Clone, Debug, PartialEq)]
pub struct FogData {
    /// Babylon.js's `fogMode`: 1 exp, 2 exp2, 3 linear.
    pub mode: u8,
    /// Colour, 0..=1 a channel.
    pub color: [f32; 3],
    /// Density of the exponential modes.
    pub density: f32,
    /// Where linear fog starts.
    pub start: f32,
    /// Where linear fog is full.
    pub end: f32,
}

impl Scene {
    /// A cube from -1 to 1 on each axis, white, drawn from both sides, with no lights (so
    /// [`Lights::from_model`](crate::Lights::from_model) gives Babylon's default hemispheric
    /// light): a scene to try the renderer with, as the API docs do.
    #[must_use]
    pub fn cube() -> Scene {
        use std::vec;
        let mut positions = vec![];
        let mut normals = vec![];
        let mut indices = vec![];
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                let base = positions.len() as u32;
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[u] = a;
                    p[v] = b * side;
                    let mut n = [0.0; 3];
                    n[axis] = side;
                    positions.push(p);
                    normals.push(n);
                }
                indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            }
        }
        let mesh = MeshData {
            name: "cube".into(),
            world: IDENTITY,
            positions,
            normals,
            submeshes: vec![SubMeshData { material: Some(0), index_start: 0, index_count: indices.len() as u32 }],
            indices,
            ..MeshData::default()
        };
        Scene {
            meshes: vec![mesh],
            materials: vec![MaterialData { back_face_culling: false, ..MaterialData::default() }],
            ..Scene::default()
        }
    }
}
