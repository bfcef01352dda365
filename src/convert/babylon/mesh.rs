//! Meshes as drawn: a mesh node's vertex data checked (lengths, index ranges, optional
//! colours and indices), its unit normals (the file's, else smooth ones with Babylon's facet
//! orientation), its sub-meshes with their materials, its UVs with the texture matrix and UV
//! origin applied, and its instances. Hidden meshes and meshes without triangles are skipped
//! with a warning.
//!
//! Where the vertex data comes from is `geometry`'s job, materials are `material`'s and world
//! matrices `node`'s.

use std::format;
use std::string::String;
use std::vec;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{flag, get, label, list, show, text, Ctx};
use super::geometry::Geometry;
use super::material::{MatSlot, UvMap};
use super::transform::{mul, Trs};
use super::{ConvertError, Reader, UvOrigin};
use crate::convert::scene::{InstanceData, MeshData, SubMeshData};

/// A mesh's vertex data once checked against itself.
struct Vertices {
    positions: Vec<[f32; 3]>,
    colors: Option<Vec<[f32; 4]>>,
    indices: Vec<u32>,
}

/// The sub-meshes of a mesh that have triangles, and the material of each.
struct SubMeshes {
    submeshes: Vec<SubMeshData>,
    slots: Vec<Option<MatSlot>>,
}

impl Reader<'_> {
    /// Converts every visible mesh node (and its instances) into `Scene::meshes`.
    pub(super) fn read_meshes(&mut self) -> Result<(), ConvertError> {
        for i in 0..self.nodes.len() {
            if self.nodes[i].is_mesh {
                self.read_mesh(i)?;
            }
        }
        Ok(())
    }

    fn read_mesh(&mut self, node: usize) -> Result<(), ConvertError> {
        let obj = self.nodes[node].obj;
        let cx = self.ctx(self.nodes[node].what.clone());
        let e = |m: String| cx.err(m);
        let mut geom = self.geometry(obj, &cx)?;
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
        let Vertices { positions, colors, indices } = check_vertices(&mut geom, &cx)?;
        let normals = self.normals(&positions, &indices, geom.normals.as_deref(), &cx.what);
        let Some(SubMeshes { submeshes, slots }) =
            self.read_submeshes(obj, geom.submeshes.take(), indices.len(), &cx)?
        else {
            return Ok(());
        };
        let uvs = self.bake_uvs(&geom.uvs, &slots, &cx.what);
        // The 2013 exporters wrote V either way up: say which choice could be wrong, once.
        let textured = slots.iter().flatten().any(|s| s.uv.is_some());
        if textured && uvs.is_some() && get(obj, "vertices").is_some() && self.opts.uv_origin == UvOrigin::Bottom {
            self.legacy_uvs.get_or_insert_with(|| cx.what.clone());
        }
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

    /// The sub-meshes (`raw`, else one over all `n_indices` indices) checked against the
    /// indices, with their materials; `None`, with a warning, when none has triangles.
    fn read_submeshes(
        &mut self,
        obj: &Value,
        raw: Option<Vec<[u64; 3]>>,
        n_indices: usize,
        cx: &Ctx,
    ) -> Result<Option<SubMeshes>, ConvertError> {
        let material_id = text(obj, "materialId").map_err(|m| cx.err(m))?;
        let raw = raw.unwrap_or_else(|| vec![[0, 0, n_indices as u64]]);
        let (mut submeshes, mut slots, mut ranges) = (Vec::new(), Vec::new(), Vec::new());
        for (k, &[material_index, start, count]) in raw.iter().enumerate() {
            let end = start.saturating_add(count);
            if end > n_indices as u64 {
                return Err(
                    cx.err(format!("subMeshes[{k}]: indexStart {start} + indexCount {count} > {n_indices} indices"))
                );
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
            return Ok(None);
        }
        if !covers_each_index_once(ranges, n_indices) {
            self.warn(format!("{}: subMeshes do not cover each index exactly once (drawn as written)", cx.what));
        }
        Ok(Some(SubMeshes { submeshes, slots }))
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
}

/// Checks the vertex data against itself (taking `geom.indices`): whole vertices, attribute
/// lengths, colours as RGBA or RGB, indices (or implicit ones) a whole number of triangles
/// within the vertices.
fn check_vertices(geom: &mut Geometry, cx: &Ctx) -> Result<Vertices, ConvertError> {
    let p = &geom.positions;
    if !p.len().is_multiple_of(3) {
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
    let indices = match geom.indices.take() {
        Some(ix) => ix,
        None if n.is_multiple_of(3) => (0..n as u32).collect(),
        None => return Err(cx.err(format!("no indices, and the {n} vertices are not a whole number of triangles"))),
    };
    if indices.len() % 3 != 0 || u32::try_from(indices.len()).is_err() {
        return Err(cx.err(format!("indices: {} indices is not a multiple of 3 below 2^32", indices.len())));
    }
    if let Some((i, ix)) = indices.iter().enumerate().find(|(_, &ix)| ix as usize >= n) {
        return Err(cx.err(format!("indices[{i}] = {ix} but only {n} vertices")));
    }
    let positions = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok(Vertices { positions, colors, indices })
}

/// Whether the `[start, end)` index ranges cover `0..n_indices` exactly once.
fn covers_each_index_once(mut ranges: Vec<(u64, u64)>, n_indices: usize) -> bool {
    ranges.sort_unstable();
    let mut covered = 0;
    for &(start, end) in &ranges {
        covered = if start == covered { end } else { u64::MAX };
    }
    covered == n_indices as u64
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
