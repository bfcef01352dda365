//! The node hierarchy: meshes and transform nodes with their local matrices, `parentId` links
//! and world matrices (`World = Local · World(parent)`, computed once per node, iteratively so
//! deep hierarchies are fine, with cycles reported as errors).
//!
//! How a local matrix is built from a node's fields is `transform`'s job; what is drawn from a
//! mesh node is `mesh`'s.

use std::format;
use std::string::String;
use std::vec;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{floats, label, list, show, text};
use super::transform::{mul, Trs};
use super::{ConvertError, Reader};
use crate::convert::scene::{Matrix, IDENTITY};

/// A mesh or transform node, possibly a parent of others.
pub(super) struct Node<'v> {
    pub(super) obj: &'v Value,
    pub(super) what: String,
    /// As written (what instances inherit).
    pub(super) trs: Trs,
    /// After `autoAnimate`.
    local: Matrix,
    pub(super) parent: Option<usize>,
    world: Option<Matrix>,
    pub(super) is_mesh: bool,
}

impl Reader<'_> {
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
    pub(super) fn parent(&mut self, obj: &Value, what: &str) -> Result<Option<usize>, ConvertError> {
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
    pub(super) fn world(&mut self, i: usize) -> Result<Matrix, ConvertError> {
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

    pub(super) fn parent_world(&mut self, parent: Option<usize>) -> Result<Matrix, ConvertError> {
        parent.map_or(Ok(IDENTITY), |p| self.world(p))
    }
}
