//! The node hierarchy: meshes, transform nodes, cameras and lights with their local matrices,
//! `parentId` links and world matrices (`World = Local · World(parent)`, computed once per
//! node, iteratively so deep hierarchies are fine, with cycles reported as errors).
//!
//! A `parentId` names its parent as Babylon.js's loader finds it: a number is a node's
//! `uniqueId` (what the serializer writes), a string a node's `id` (meshes first, then
//! transform nodes, cameras and lights), and where no `id` matches, a node's `name`. A camera
//! as a parent places its children as Babylon.js's `getWorldMatrix` does: turned to look at its
//! target (up +y) when it has one, else by its `rotation`, and moved to its position; a light
//! moves them to its position.
//!
//! How a local matrix is built from a node's fields is `transform`'s job; what is drawn from a
//! mesh node is `mesh`'s; which nodes move, and how, `animation`'s (which learns from `world`
//! which mesh of the scene each mesh node became).

use std::format;
use std::string::String;
use std::vec;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{floats, get, label, list, show, text, vector, Res};
use super::transform::{mul, Trs};
use super::{ConvertError, Reader};
use crate::convert::scene::{Matrix, IDENTITY};

/// A mesh, transform node, camera or light, possibly a parent of others.
pub(super) struct Node<'v> {
    pub(super) obj: &'v Value,
    pub(super) what: String,
    /// As written (what instances inherit, and an animated node's rest).
    pub(super) trs: Trs,
    /// After `autoAnimate`.
    pub(super) local: Matrix,
    pub(super) parent: Option<usize>,
    world: Option<Matrix>,
    pub(super) is_mesh: bool,
    /// A mesh or transform node: what animation tracks may move (cameras and lights are not).
    pub(super) movable: bool,
    /// The index in `Scene::meshes` of the mesh drawn from this node, as [`Reader::world`]
    /// recorded it (read it through [`Reader::drawn_mesh`]).
    drawn: Option<usize>,
}

impl<'a> Reader<'a> {
    /// Collects meshes and transform nodes with their local matrices and parents.
    pub(super) fn read_nodes(&mut self) -> Result<(), ConvertError> {
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
                let local = animated.matrix();
                let (parent, world, movable, drawn) = (None, None, true, None);
                self.add_node(Node { obj, what: cx.what, trs, local, parent, world, is_mesh, movable, drawn })?;
            }
        }
        // Cameras and lights, as parents of others (they are read as such by `camera` and
        // `light`).
        for (array, kind) in [("cameras", "camera"), ("lights", "light")] {
            let first = self.nodes.len();
            if kind == "camera" {
                self.view.cameras_at = first;
            } else {
                self.view.lights_at = first;
            }
            for (i, obj) in list(root, array).map_err(|m| self.ctx("scene").err(m))?.iter().enumerate() {
                let cx = self.ctx(label(obj, kind, array, i));
                let local =
                    if kind == "camera" { camera_matrix(obj) } else { light_matrix(obj) }.map_err(|m| cx.err(m))?;
                let (trs, parent, world, is_mesh, movable, drawn) = (Trs::IDENTITY, None, None, false, false, None);
                self.add_node(Node { obj, what: cx.what, trs, local, parent, world, is_mesh, movable, drawn })?;
            }
        }
        for i in 0..self.nodes.len() {
            let obj = self.nodes[i].obj;
            let parent = self.parent(obj, &self.nodes[i].what.clone())?;
            self.nodes[i].parent = parent;
        }
        Ok(())
    }

    /// Indexes `node` by its `id`, `name` and `uniqueId` (the first node of each wins), and
    /// appends it.
    fn add_node(&mut self, node: Node<'a>) -> Result<(), ConvertError> {
        let (obj, n) = (node.obj, self.nodes.len());
        let cx = self.ctx(node.what.clone());
        for (key, map) in [("id", &mut self.ids), ("name", &mut self.names), ("uniqueId", &mut self.unique_ids)] {
            if let Some(value) = text(obj, key).map_err(|m| cx.err(m))? {
                map.entry(value).or_insert(n);
            }
        }
        self.nodes.push(node);
        Ok(())
    }

    /// The node named by `obj`'s `parentId` (see the module documentation); an unknown parent
    /// is warned about and ignored.
    pub(super) fn parent(&mut self, obj: &Value, what: &str) -> Result<Option<usize>, ConvertError> {
        let Some(id) = text(obj, "parentId").map_err(|m| self.ctx(what).err(m))? else {
            return Ok(None);
        };
        // An empty id is no parent to Babylon.js (falsy in its loader), not a missing one.
        if id.is_empty() {
            return Ok(None);
        }
        let numeric = get(obj, "parentId").is_some_and(Value::is_number);
        let by_unique = numeric.then(|| self.unique_ids.get(&id).copied()).flatten();
        let found = by_unique.or_else(|| self.ids.get(&id).copied()).or_else(|| self.names.get(&id).copied());
        if found.is_none() {
            self.warn(format!("{what}: parent {id:?} not found, treated as a root"));
        }
        Ok(found)
    }

    /// The world matrix of node `i`.
    ///
    /// `mesh` asks for a mesh's world matrix here just before it appends the mesh to
    /// `Scene::meshes`, so the first call for a mesh node records the index the mesh gets there
    /// (see [`Reader::drawn_mesh`]); parents and instances go through
    /// [`Reader::parent_world`], which records nothing.
    pub(super) fn world(&mut self, i: usize) -> Result<Matrix, ConvertError> {
        let world = self.world_of(i)?;
        let next = self.scene.meshes.len();
        if self.nodes[i].is_mesh {
            self.nodes[i].drawn.get_or_insert(next);
        }
        Ok(world)
    }

    /// The index in `Scene::meshes` of the mesh drawn from node `i`, if one was: the index
    /// [`Reader::world`] recorded, checked against the mesh there (same world matrix).
    pub(super) fn drawn_mesh(&self, i: usize) -> Option<usize> {
        let node = self.nodes.get(i)?;
        node.drawn.filter(|&m| self.scene.meshes.get(m).is_some_and(|mesh| node.world == Some(mesh.world)))
    }

    /// The ancestors of node `i`, nearest first; a `parentId` cycle is an error.
    pub(super) fn ancestors(&self, i: usize) -> Result<Vec<usize>, ConvertError> {
        let mut chain: Vec<usize> = Vec::new();
        let mut at = self.nodes.get(i).and_then(|n| n.parent);
        while let Some(p) = at {
            if chain.len() >= self.nodes.len() {
                let names: Vec<&str> = chain.iter().take(8).map(|&n| self.nodes[n].what.as_str()).collect();
                return Err(self
                    .ctx(self.nodes[i].what.clone())
                    .err(format!("parentId cycle through {}", names.join(" -> "))));
            }
            chain.push(p);
            at = self.nodes.get(p).and_then(|n| n.parent);
        }
        Ok(chain)
    }

    /// The world matrix of node `i` (walking up iteratively, so deep hierarchies are fine).
    fn world_of(&mut self, i: usize) -> Result<Matrix, ConvertError> {
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

    /// The world matrix of node `parent` (the identity for none), recording nothing.
    pub(super) fn parent_world(&mut self, parent: Option<usize>) -> Result<Matrix, ConvertError> {
        parent.map_or(Ok(IDENTITY), |p| self.world_of(p))
    }
}

/// A camera's matrix as a parent (see the module documentation).
fn camera_matrix(obj: &Value) -> Res<Matrix> {
    let trs = Trs::read(obj, Trs::IDENTITY)?;
    let position = vector(obj, "position")?.unwrap_or([0.; 3]);
    let arc = text(obj, "type")?.as_deref() == Some("ArcRotateCamera");
    let target = vector(obj, "target")?.or(arc.then_some([0.; 3]));
    let looking = target.and_then(|t| look_at_matrix(position, t));
    Ok(looking.unwrap_or_else(|| {
        let mut m = trs.rotation_matrix();
        m[12..15].copy_from_slice(&position);
        m
    }))
}

/// A light's matrix as a parent: a move to its position (none for directional and hemispheric
/// lights, which have none).
fn light_matrix(obj: &Value) -> Res<Matrix> {
    let mut m = IDENTITY;
    if let Some(p) = vector::<3>(obj, "position")? {
        m[12..15].copy_from_slice(&p);
    }
    Ok(m)
}

/// The world matrix of a camera at `eye` looking at `target` with up +y (the inverse of
/// `LookAtLH`): rows x, y, z (the view direction) and the position; `None` when degenerate.
fn look_at_matrix(eye: [f32; 3], target: [f32; 3]) -> Option<Matrix> {
    let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross =
        |a: [f32; 3], b: [f32; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let unit = |a: [f32; 3]| {
        let n = libm::sqrtf(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        (n > 1e-12 && n.is_finite()).then(|| a.map(|c| c / n))
    };
    let z = unit(sub(target, eye))?;
    let x = unit(cross([0., 1., 0.], z))?;
    let y = cross(z, x);
    Some([x[0], x[1], x[2], 0., y[0], y[1], y[2], 0., z[0], z[1], z[2], 0., eye[0], eye[1], eye[2], 1.])
}
