//! Skeletons: each drawn mesh's `skeletonId` names a skeleton whose bones become animated
//! nodes (in the mesh's own space), whose `_matrix` animations become their tracks, and whose
//! `matricesIndices` and `matricesWeights` become the mesh's [`SkinData`].
//!
//! The rules, after Babylon.js's `Skeleton.Parse`, `Bone` and the standard material's skinning:
//!
//! - **Bones**: `bones[k].matrix` is the bone's local matrix, its bind and rest pose;
//!   `parentBoneIndex` names an earlier bone of the array (a later or missing one: a root, with
//!   a warning for the later). A bone's absolute bind matrix is `matrix · absolute(parent)`;
//!   a vertex is moved by `Σ wᵢ · p · inverse(absolute bind)ᵢ · absoluteᵢ` (its mesh's world
//!   matrix after). The palette slot of a bone is its `index` (else its position).
//! - **Animations**: a bone's `animation` (or `animations`) with property `_matrix` and 16
//!   values a key. Babylon.js does not interpolate matrix keys unless an application sets
//!   `Animation.AllowMatricesInterpolation` (a key holds until the next one), so each key is
//!   decomposed here (`Matrix.decompose`) into three step tracks: position, rotation
//!   quaternion and scaling (with interpolation allowed, Babylon.js would lerp and slerp those
//!   by decomposition, `Matrix.DecomposeLerp`: clear the keys' `step` to get it). All a
//!   skeleton's tracks form one group named after it, over their keys, looping (as
//!   `scene.beginAnimation(skeleton, first, last, true)`).
//! - **Influences**: `matricesIndices` packs four 8-bit bone slots a vertex into one number
//!   (lowest byte first), or holds four numbers a vertex; `matricesWeights` four a vertex.
//!   The `Extra` pair (8 influences), `needInitialSkinMatrix` and bones linked to transform
//!   nodes are not played (a warning each); so are influences held in shared geometries.

use std::collections::HashMap;
use std::format;
use std::string::String;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{floats, get, list, number, text};
use super::track::loop_behavior;
use super::transform::mul;
use super::{ConvertError, Reader};
use crate::convert::scene::{
    GroupData, Influence, KeyData, Matrix, NodeData, NodeProperty, Rotation, SkinBone, SkinData, TrackData,
    TrackTarget, IDENTITY,
};
use crate::math::Mat4;

impl Reader<'_> {
    /// Reads the skeletons of the drawn meshes into `scene.animation` (after `read_animation`).
    pub(super) fn read_skeletons(&mut self) -> Result<(), ConvertError> {
        let root = self.root;
        let skeletons = list(root, "skeletons").map_err(|m| self.ctx("scene").err(m))?;
        let mut palettes: HashMap<usize, Vec<SkinBone>> = HashMap::new();
        for n in 0..self.nodes.len() {
            let Some(mesh) = self.drawn_mesh(n) else { continue };
            let (obj, what) = (self.nodes[n].obj, self.nodes[n].what.clone());
            let Some(id) = number(obj, "skeletonId").map_err(|m| self.ctx(what.clone()).err(m))? else { continue };
            if id < 0.0 {
                continue;
            }
            let Some(k) = skeletons.iter().position(|s| number(s, "id").ok().flatten() == Some(id)) else {
                self.warn(format!("{what}: skeleton {id} not found, drawn in its bind pose"));
                continue;
            };
            if let std::collections::hash_map::Entry::Vacant(e) = palettes.entry(k) {
                e.insert(self.read_bones(&skeletons[k], k)?);
            }
            let bones = palettes.get(&k).cloned().unwrap_or_default();
            let nv = self.scene.meshes.get(mesh).map_or(0, |m| m.positions.len());
            let Some(vertices) = self.influences(obj, &what, (nv, bones.len()))? else { continue };
            let mesh = u16::try_from(mesh).map_err(|_| self.ctx(what).err("more than 65536 meshes"))?;
            self.scene.animation.skins.push(SkinData { mesh, bones, vertices });
        }
        Ok(())
    }

    /// Skeleton `skel`'s bones as nodes, their tracks and group; the palette (by slot).
    fn read_bones(&mut self, skel: &Value, k: usize) -> Result<Vec<SkinBone>, ConvertError> {
        let name = text(skel, "name").ok().flatten().unwrap_or_else(|| format!("skeleton {k}"));
        let cx = self.ctx(format!("skeleton \"{name}\""));
        if get(skel, "needInitialSkinMatrix").and_then(Value::as_bool) == Some(true) {
            self.warn(format!("{}: needInitialSkinMatrix is not played", cx.what));
        }
        let bones = list(skel, "bones").map_err(|m| cx.err(m))?;
        let first_node = self.scene.animation.nodes.len();
        let (mut absolute, mut slots, mut group) = (Vec::new(), Vec::new(), Vec::new());
        for (b, bone) in bones.iter().enumerate() {
            let in_bone = |m: String| cx.err(format!("bones[{b}].{m}"));
            let local: Matrix = match floats(bone, "matrix").map_err(in_bone)? {
                Some(m) if m.len() == 16 => core::array::from_fn(|i| m[i]),
                Some(_) => return Err(cx.err(format!("bones[{b}].matrix: expected 16 numbers"))),
                None => IDENTITY,
            };
            let parent = number(bone, "parentBoneIndex").map_err(in_bone)?.filter(|&p| p >= 0.0).map(|p| p as usize);
            let parent = match parent {
                Some(p) if p < b => Some(p),
                Some(_) => {
                    self.warn(format!("{}: bones[{b}]: parent is not an earlier bone, treated as a root", cx.what));
                    None
                }
                None => None,
            };
            let bind = parent.and_then(|p| absolute.get(p)).map_or(local, |pa| mul(&local, pa));
            absolute.push(bind);
            if get(bone, "linkedTransformNodeId").is_some() {
                self.warn(format!("{}: bones[{b}]: bones linked to transform nodes are not played", cx.what));
            }
            let node = self.small_index(first_node + b)?;
            let (position, rotation, scaling) = decompose(&local);
            let bone_name = text(bone, "name").ok().flatten().unwrap_or_default();
            let parent = parent.map(|p| self.small_index(first_node + p)).transpose()?;
            let data = NodeData { name: bone_name, parent, above: IDENTITY, position, rotation, scaling };
            self.scene.animation.nodes.push(data);
            group.extend(self.bone_tracks(bone, node, &cx.what, b)?);
            let slot = number(bone, "index").ok().flatten().filter(|&s| s >= 0.0).map_or(b, |s| s as usize);
            let inverse = Mat4::from_cols_array(&bind).inverse().to_cols_array();
            slots.push((slot, SkinBone { node, inverse_bind: inverse }));
        }
        self.skeleton_group(name, group)?;
        Ok(palette(slots))
    }

    /// `n` as a u16 node index.
    fn small_index(&self, n: usize) -> Result<u16, ConvertError> {
        u16::try_from(n).map_err(|_| self.ctx("scene").err("more than 65536 animated nodes and bones"))
    }

    /// Bone `b`'s `_matrix` animations as position, quaternion and scaling tracks of `node`;
    /// their indices.
    fn bone_tracks(&mut self, bone: &Value, node: u16, what: &str, b: usize) -> Result<Vec<u16>, ConvertError> {
        let single = get(bone, "animation").filter(|a| a.is_object()).into_iter();
        let many = list(bone, "animations").map_err(|m| self.ctx(what).err(m))?.iter();
        let mut made = Vec::new();
        for anim in single.chain(many) {
            if text(anim, "property").ok().flatten().as_deref() != Some("_matrix") {
                self.warn(format!("{what}: bones[{b}]: only _matrix animations of bones are played"));
                continue;
            }
            let fps = number(anim, "framePerSecond").ok().flatten().filter(|&f| f > 0.0).unwrap_or(30.0);
            let mut notes = Vec::new();
            let looping =
                loop_behavior(anim, &mut notes).map_err(|m| self.ctx(what).err(format!("bones[{b}].animation.{m}")))?;
            for note in notes {
                self.warn(format!("{what}: bones[{b}].animation: {note}"));
            }
            let keys = matrix_keys(anim).map_err(|m| self.ctx(what).err(format!("bones[{b}].animation.{m}")))?;
            if keys.is_empty() {
                continue;
            }
            for (property, count) in
                [(NodeProperty::Position, 3), (NodeProperty::RotationQuaternion, 4), (NodeProperty::Scaling, 3)]
            {
                let keys = keys
                    .iter()
                    .map(|(frame, (t, r, s))| {
                        let values = match property {
                            NodeProperty::Position => t.to_vec(),
                            NodeProperty::RotationQuaternion => match r {
                                Rotation::Quaternion(q) => q.to_vec(),
                                Rotation::Euler(e) => e.to_vec(),
                            },
                            _ => s.to_vec(),
                        };
                        // Babylon.js holds a matrix key until the next one:
                        // `Animation.AllowMatricesInterpolation` is false unless an app sets it.
                        KeyData { frame: *frame, values, tangents: None, step: true }
                    })
                    .collect();
                let target = TrackTarget::Node { node, property, first: 0, count };
                made.push(self.small_index(self.scene.animation.tracks.len())?);
                self.scene.animation.tracks.push(TrackData { target, fps, looping, keys });
            }
        }
        Ok(made)
    }

    /// The group of a skeleton's tracks (none without tracks).
    fn skeleton_group(&mut self, name: String, tracks: Vec<u16>) -> Result<(), ConvertError> {
        let frames = tracks
            .iter()
            .filter_map(|&t| self.scene.animation.tracks.get(t as usize))
            .flat_map(|t| t.keys.first().map(|k| k.frame).into_iter().chain(t.keys.last().map(|k| k.frame)));
        let (from, to) = frames.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), f| (lo.min(f), hi.max(f)));
        if !tracks.is_empty() {
            self.scene.animation.groups.push(GroupData { name, from, to, looping: true, tracks });
        }
        Ok(())
    }

    /// Mesh `obj`'s four bones and weights a vertex for `nv` vertices and `bones` palette slots;
    /// `None`, with a warning, when it has none or they do not fit.
    fn influences(
        &mut self,
        obj: &Value,
        what: &str,
        (nv, bones): (usize, usize),
    ) -> Result<Option<Vec<Influence>>, ConvertError> {
        let cx = self.ctx(what);
        for extra in ["matricesIndicesExtra", "matricesWeightsExtra"] {
            if get(obj, extra).is_some() {
                self.warn(format!("{what}: {extra} (bone influences 5 to 8) is not played"));
            }
        }
        let indices = floats(obj, "matricesIndices").map_err(|m| cx.err(m))?;
        let weights = floats(obj, "matricesWeights").map_err(|m| cx.err(m))?;
        let (Some(indices), Some(weights)) = (indices, weights) else {
            self.warn(format!(
                "{what}: skinned, but its matricesIndices and matricesWeights are not inline: drawn in its bind pose"
            ));
            return Ok(None);
        };
        let packed = indices.len() == nv;
        if !(packed || indices.len() == 4 * nv) || weights.len() != 4 * nv {
            self.warn(format!(
                "{what}: matricesIndices or matricesWeights do not match its {nv} vertices: drawn in its bind pose"
            ));
            return Ok(None);
        }
        let slot = |v: usize, k: usize| -> usize {
            if packed {
                (indices[v] as u32 >> (8 * k) & 0xff) as usize
            } else {
                indices[4 * v + k] as usize
            }
        };
        let mut out = Vec::with_capacity(nv);
        for v in 0..nv {
            let b: [usize; 4] = core::array::from_fn(|k| slot(v, k));
            if b.iter().any(|&s| s >= bones.min(256)) {
                self.warn(format!(
                    "{what}: vertex {v} names a bone the skeleton does not have: drawn in its bind pose"
                ));
                return Ok(None);
            }
            out.push((b.map(|s| s as u8), core::array::from_fn(|k| weights[4 * v + k])));
        }
        Ok(Some(out))
    }
}

/// The palette: each bone at its slot (a slot no bone takes: the first bone's, which no vertex
/// should name).
fn palette(slots: Vec<(usize, SkinBone)>) -> Vec<SkinBone> {
    let len = slots.iter().map(|(s, _)| s + 1).max().unwrap_or(0).min(256);
    let fill = slots.first().map(|(_, b)| b.clone());
    let mut out: Vec<Option<SkinBone>> = vec_of(len);
    for (s, b) in slots {
        if let Some(slot) = out.get_mut(s) {
            *slot = Some(b);
        }
    }
    out.into_iter().filter_map(|b| b.or_else(|| fill.clone())).collect()
}

fn vec_of<T>(len: usize) -> Vec<Option<T>> {
    (0..len).map(|_| None).collect()
}

/// A `_matrix` animation's keys, each decomposed (see [`decompose`]), by frame.
fn matrix_keys(anim: &Value) -> Result<Vec<(f32, Decomposed)>, String> {
    let mut keys = Vec::new();
    for (i, key) in list(anim, "keys")?.iter().enumerate() {
        let frame = number(key, "frame").map_err(|m| format!("keys[{i}].{m}"))?.unwrap_or(0.0);
        let values = floats(key, "values").map_err(|m| format!("keys[{i}].{m}"))?.unwrap_or_default();
        if values.len() < 16 {
            return Err(format!("keys[{i}].values: expected 16 numbers, found {}", values.len()));
        }
        let m: Matrix = core::array::from_fn(|k| values[k]);
        keys.push((frame, decompose(&m)));
    }
    keys.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(keys)
}

/// A matrix as translation, rotation and scaling.
type Decomposed = ([f32; 3], Rotation, [f32; 3]);

/// Babylon.js's `Matrix.decompose`: translation, rotation (as `Quaternion.FromRotationMatrix`)
/// and scaling (the rows' lengths, y negated when the determinant is not positive).
fn decompose(m: &Matrix) -> Decomposed {
    let row = |r: usize| [m[4 * r], m[4 * r + 1], m[4 * r + 2]];
    let length = |v: [f32; 3]| libm::sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    let mut scale = [length(row(0)), length(row(1)), length(row(2))];
    if Mat4::from_cols_array(m).determinant() <= 0.0 {
        scale[1] = -scale[1];
    }
    let translation = [m[12], m[13], m[14]];
    if scale.contains(&0.0) {
        return (translation, Rotation::Quaternion([0.0, 0.0, 0.0, 1.0]), scale);
    }
    let r: [[f32; 3]; 3] = core::array::from_fn(|i| row(i).map(|c| c / scale[i]));
    (translation, Rotation::Quaternion(quaternion_of(r)), scale)
}

/// Babylon.js's `Quaternion.FromRotationMatrix` of rows `r` (row vectors).
fn quaternion_of(r: [[f32; 3]; 3]) -> [f32; 4] {
    let (m11, m12, m13) = (r[0][0], r[1][0], r[2][0]);
    let (m21, m22, m23) = (r[0][1], r[1][1], r[2][1]);
    let (m31, m32, m33) = (r[0][2], r[1][2], r[2][2]);
    let trace = m11 + m22 + m33;
    if trace > 0.0 {
        let s = 0.5 / libm::sqrtf(trace + 1.0);
        [(m32 - m23) * s, (m13 - m31) * s, (m21 - m12) * s, 0.25 / s]
    } else if m11 > m22 && m11 > m33 {
        let s = 2.0 * libm::sqrtf(1.0 + m11 - m22 - m33);
        [0.25 * s, (m12 + m21) / s, (m13 + m31) / s, (m32 - m23) / s]
    } else if m22 > m33 {
        let s = 2.0 * libm::sqrtf(1.0 + m22 - m11 - m33);
        [(m12 + m21) / s, 0.25 * s, (m23 + m32) / s, (m13 - m31) / s]
    } else {
        let s = 2.0 * libm::sqrtf(1.0 + m33 - m11 - m22);
        [(m13 + m31) / s, (m23 + m32) / s, 0.25 * s, (m21 - m12) / s]
    }
}

#[cfg(test)]
mod tests {
    use super::super::transform::{quat_matrix, Trs};
    use super::*;
    use serde_json::json;

    #[test]
    fn decomposing_and_composing_gives_the_matrix_back() {
        let node = json!({"position": [1.0, -2.0, 3.0], "rotation": [0.3, -0.7, 1.1], "scaling": [2.0, 0.5, 1.5]});
        let trs = Trs::read(&node, Trs::IDENTITY).unwrap();
        let m = trs.matrix();
        let (t, r, s) = decompose(&m);
        let Rotation::Quaternion(q) = r else { panic!("a quaternion") };
        let mut back = quat_matrix(q);
        for (i, v) in back[..12].iter_mut().enumerate() {
            *v *= s[i / 4];
        }
        back[12..15].copy_from_slice(&t);
        assert!(back.iter().zip(m).all(|(a, b)| (a - b).abs() < 1e-5), "{back:?} vs {m:?}");
    }
}
