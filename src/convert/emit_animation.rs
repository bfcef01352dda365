//! The animation half of the `.s3d` writer: [`emit_animation`] writes a scene's
//! [`AnimationData`] in `format`'s layout (the section the header's offset 48..52 points at;
//! its animated camera and lights are `emit_view`'s), [`read_animation`] reads it back, and
//! [`morph_reach`] gives the points a morphed mesh's bounding sphere must hold.

use std::string::String;
use std::vec::Vec;

use super::emit::{EmitError, Out};
use super::emit_view::{self, ViewSlots};
use super::scene::{self, AnimationData, Loop, NodeProperty, Rotation, Scene, SkinData, TrackTarget};
use crate::animation::{Animation, TrackTarget as StoredTarget};
use crate::format::layout::*;
use crate::format::Model;
use crate::math::Mat4;

/// Writes `scene`'s animation section; its offset.
pub(super) fn emit_animation(out: &mut Out, scene: &Scene) -> Result<u32, EmitError> {
    let a = &scene.animation;
    check_finite(a)?;
    let links_increase = a.links.windows(2).all(|w| w[0].mesh < w[1].mesh);
    let skins_increase = a.skins.windows(2).all(|w| w[0].mesh < w[1].mesh);
    if !links_increase || !skins_increase || !a.morphs.windows(2).all(|w| w[0].mesh < w[1].mesh) {
        return Err(EmitError(
            "animation: links, morphs and skins must be in increasing mesh order, one a mesh".into(),
        ));
    }
    let count = |n: usize, what: &str| {
        u16::try_from(n).ok().filter(|&n| n != NONE).ok_or_else(|| EmitError(std::format!("too many {what}: {n}")))
    };
    let slots = ViewSlots::of(a);
    let at = out.reserve(if slots.any() { animation::LEN_EXTENDED } else { animation::LEN });
    let counts = [
        (animation::NODE_COUNT, count(a.nodes.len(), "animated nodes")?),
        (animation::LINK_COUNT, count(a.links.len(), "mesh links")?),
        (animation::MORPH_COUNT, count(a.morphs.len(), "morphed meshes")?),
        (animation::TRACK_COUNT, count(a.tracks.len(), "tracks")?),
        (animation::GROUP_COUNT, count(a.groups.len(), "animation groups")?),
        (animation::WEIGHT_COUNT, count(slots.end, "weights (morph targets and slots)")?),
        (animation::SKIN_COUNT, count(a.skins.len(), "skins")?),
        (animation::PALETTE_COUNT, count(a.skins.iter().map(|s| s.bones.len()).sum(), "skin bones")?),
    ];
    for (field, n) in counts {
        out.put_u16(at + field.start, n);
    }
    let nodes = emit_nodes(out, a);
    out.put_u32(at + animation::NODES.start, nodes);
    let links = out.reserve(link::LEN * a.links.len());
    out.put_u32(at + animation::LINKS.start, links as u32);
    for (k, l) in a.links.iter().enumerate() {
        let r = links + k * link::LEN;
        out.put_u16(r + link::MESH.start, l.mesh);
        out.put_u16(r + link::NODE.start, l.node);
        out.put_affine(r + link::BELOW.start, &l.below);
    }
    let morphs = emit_morphs(out, scene)?;
    out.put_u32(at + animation::MORPHS.start, morphs);
    let tracks = emit_tracks(out, a)?;
    out.put_u32(at + animation::TRACKS.start, tracks);
    let groups = emit_groups(out, a)?;
    out.put_u32(at + animation::GROUPS.start, groups);
    let skins = emit_skins(out, scene)?;
    out.put_u32(at + animation::SKINS.start, skins);
    emit_view::emit_view(out, at, scene, &slots)?;
    Ok(at as u32)
}

fn check_finite(a: &AnimationData) -> Result<(), EmitError> {
    let nodes = a.nodes.iter().flat_map(|n| {
        let r = match n.rotation {
            Rotation::Euler(e) => [e[0], e[1], e[2], 0.0],
            Rotation::Quaternion(q) => q,
        };
        n.above.into_iter().chain(n.position).chain(r).chain(n.scaling)
    });
    let keys = a.tracks.iter().flat_map(|t| {
        t.keys.iter().flat_map(|k| {
            let tangents = k.tangents.iter().flat_map(|(i, o)| i.iter().chain(o).copied());
            core::iter::once(k.frame).chain(k.values.iter().copied()).chain(tangents)
        })
    });
    let morphs = a.morphs.iter().flat_map(|m| {
        m.targets.iter().flat_map(|t| {
            let normals = t.normals.iter().flatten().flatten().copied();
            core::iter::once(t.influence).chain(t.positions.iter().flatten().copied()).chain(normals)
        })
    });
    let groups = a.groups.iter().flat_map(|g| [g.from, g.to]);
    let links = a.links.iter().flat_map(|l| l.below);
    let fps = a.tracks.iter().map(|t| t.fps).chain(emit_view::aim_numbers(a.camera_aim));
    let skins = a
        .skins
        .iter()
        .flat_map(|s| s.bones.iter().flat_map(|b| b.inverse_bind).chain(s.vertices.iter().flat_map(|(_, w)| *w)));
    if nodes.chain(keys).chain(morphs).chain(groups).chain(links).chain(fps).chain(skins).all(f32::is_finite) {
        Ok(())
    } else {
        Err(EmitError("animation: non-finite number".into()))
    }
}

fn emit_nodes(out: &mut Out, a: &AnimationData) -> u32 {
    let table = out.reserve(node::LEN * a.nodes.len());
    for (k, n) in a.nodes.iter().enumerate() {
        let r = table + k * node::LEN;
        out.put_u16(r + node::PARENT.start, n.parent.unwrap_or(NONE));
        let (flags, rotation) = match n.rotation {
            Rotation::Euler(e) => (0, [e[0], e[1], e[2], 0.0]),
            Rotation::Quaternion(q) => (node::FLAG_QUATERNION, q),
        };
        out.put_u16(r + node::FLAGS.start, flags);
        out.put_f32s(r + node::POSITION.start, &n.position);
        out.put_f32s(r + node::ROTATION.start, &rotation);
        out.put_f32s(r + node::SCALING.start, &n.scaling);
        out.put_affine(r + node::ABOVE.start, &n.above);
    }
    table as u32
}

/// The units a mesh's stored positions are in (its quantization step per axis, 1 for f32).
fn stored_units(model_scale: [f32; 3]) -> [f32; 3] {
    model_scale.map(|s| if s > 0.0 { s } else { 1.0 })
}

fn emit_morphs(out: &mut Out, scene: &Scene) -> Result<u32, EmitError> {
    let a = &scene.animation;
    let table = out.reserve(morph::LEN * a.morphs.len());
    let mut first = 0u16;
    for (k, m) in a.morphs.iter().enumerate() {
        let r = table + k * morph::LEN;
        let mesh = scene
            .meshes
            .get(m.mesh as usize)
            .ok_or_else(|| EmitError(std::format!("morph {k}: no mesh {}", m.mesh)))?;
        let nv = mesh.positions.len();
        let normals = m.targets.iter().all(|t| t.normals.is_some());
        if m.targets.is_empty()
            || m.targets.iter().any(|t| t.positions.len() != nv || t.normals.as_ref().is_some_and(|n| n.len() != nv))
        {
            return Err(EmitError(std::format!(
                "morph of mesh \"{}\": targets must hold one delta a vertex",
                mesh.name
            )));
        }
        out.put_u16(r + morph::MESH.start, m.mesh);
        out.put_u16(r + morph::TARGET_COUNT.start, m.targets.len() as u16);
        out.put_u16(r + morph::FIRST_WEIGHT.start, first);
        out.put_u16(r + morph::FLAGS.start, u16::from(normals) * morph::FLAG_NORMALS);
        first = first.saturating_add(m.targets.len() as u16);
        let targets = out.reserve(morph_target::LEN * m.targets.len());
        out.put_u32(r + morph::TARGETS.start, targets as u32);
        let units = stored_units(out.mesh_pos_scale(m.mesh as usize));
        for (t, target) in m.targets.iter().enumerate() {
            let at = targets + t * morph_target::LEN;
            out.put_f32s(at + morph_target::INFLUENCE.start, &[target.influence]);
            let stored: Vec<[f32; 3]> = target.positions.iter().map(|d| [0, 1, 2].map(|c| d[c] / units[c])).collect();
            let (scale, offset) = emit_deltas(out, &stored);
            out.put_f32s(at + morph_target::POSITION_SCALE.start, &[scale]);
            out.put_u32(at + morph_target::POSITIONS.start, offset);
            if let (true, Some(n)) = (normals, &target.normals) {
                let (scale, offset) = emit_deltas(out, n);
                out.put_f32s(at + morph_target::NORMAL_SCALE.start, &[scale]);
                out.put_u32(at + morph_target::NORMALS.start, offset);
            }
        }
    }
    Ok(table as u32)
}

/// Appends `deltas` as i16 over their largest magnitude; the scale and offset.
fn emit_deltas(out: &mut Out, deltas: &[[f32; 3]]) -> (f32, u32) {
    let largest = deltas.iter().flatten().fold(0.0f32, |m, d| m.max(d.abs()));
    let scale = if largest > 0.0 { largest / 32767.0 } else { 1.0 };
    let bytes: Vec<u8> = deltas
        .iter()
        .flatten()
        .flat_map(|d| (libm::roundf(d / scale).clamp(-32767.0, 32767.0) as i16).to_le_bytes())
        .collect();
    (scale, out.append(&bytes))
}

fn emit_tracks(out: &mut Out, a: &AnimationData) -> Result<u32, EmitError> {
    let table = out.reserve(track::LEN * a.tracks.len());
    let weight_base: Vec<usize> = a
        .morphs
        .iter()
        .scan(0, |first, m| {
            let base = *first;
            *first += m.targets.len();
            Some(base)
        })
        .collect();
    for (k, t) in a.tracks.iter().enumerate() {
        let r = table + k * track::LEN;
        let bad = || EmitError(std::format!("track {k}: target or keys out of range"));
        let (kind, first, count, target) = match t.target {
            TrackTarget::Node { node, property, first, count } => {
                let kind = match property {
                    NodeProperty::Position => track::KIND_POSITION,
                    NodeProperty::Rotation => track::KIND_ROTATION,
                    NodeProperty::Scaling => track::KIND_SCALING,
                    NodeProperty::RotationQuaternion => track::KIND_QUATERNION,
                };
                (kind, first, count, node)
            }
            TrackTarget::Morph { morph, target } => {
                let targets = a.morphs.get(morph as usize).map_or(0, |m| m.targets.len());
                let base = *weight_base.get(morph as usize).filter(|_| (target as usize) < targets).ok_or_else(bad)?;
                (track::KIND_INFLUENCE, 0, 1, u16::try_from(base + target as usize).map_err(|_| bad())?)
            }
            view => emit_view::track_fields(view).ok_or_else(bad)?,
        };
        // Tangents are stored for a whole track when a key has one (zeros where a key has
        // none, with a key flag saying so).
        let n = count as usize;
        let tangents = t.keys.iter().any(|k| k.tangents.as_ref().is_some_and(|(i, o)| !i.is_empty() || !o.is_empty()));
        if t.keys.iter().flat_map(|k| &k.tangents).any(|(i, o)| ![i, o].iter().all(|v| v.is_empty() || v.len() == n)) {
            return Err(bad());
        }
        let looping = match t.looping {
            Loop::Relative => 0,
            Loop::Cycle => 1,
            Loop::Constant => 2,
        };
        out.put(r + track::KIND, &[kind, first, count, looping | if tangents { track::FLAG_TANGENTS } else { 0 }]);
        out.put_u16(r + track::TARGET.start, target);
        out.put_u32(r + track::KEY_COUNT.start, t.keys.len() as u32);
        out.put_f32s(r + track::FPS.start, &[t.fps]);
        let mut keys = Vec::new();
        for key in &t.keys {
            if key.values.len() != count as usize {
                return Err(bad());
            }
            keys.extend(key.frame.to_le_bytes());
            let (tin, tout) = key.tangents.as_ref().map_or((&[][..], &[][..]), |(i, o)| (&i[..], &o[..]));
            let flags = u32::from(key.step)
                | if tangents && tin.is_empty() { key::FLAG_NO_IN_TANGENT } else { 0 }
                | if tangents && tout.is_empty() { key::FLAG_NO_OUT_TANGENT } else { 0 };
            keys.extend(flags.to_le_bytes());
            let mut floats: Vec<f32> = key.values.clone();
            if tangents {
                for t in [tin, tout] {
                    floats.extend(t);
                    floats.resize(floats.len() + n - t.len(), 0.0);
                }
            }
            keys.extend(floats.iter().flat_map(|v| v.to_le_bytes()));
        }
        let o = out.append(&keys);
        out.put_u32(r + track::KEYS.start, o);
    }
    Ok(table as u32)
}

fn emit_skins(out: &mut Out, scene: &Scene) -> Result<u32, EmitError> {
    let a = &scene.animation;
    let table = out.reserve(skin::LEN * a.skins.len());
    let mut first = 0usize;
    for (k, s) in a.skins.iter().enumerate() {
        let r = table + k * skin::LEN;
        let nv = scene.meshes.get(s.mesh as usize).map_or(0, |m| m.positions.len());
        let bad = |what: &str| EmitError(std::format!("skin {k} (mesh {}): {what}", s.mesh));
        if s.bones.is_empty() || s.bones.len() > 256 || s.vertices.len() != nv {
            return Err(bad("1 to 256 bones and one influence record a vertex"));
        }
        if s.bones.iter().any(|b| b.node as usize >= a.nodes.len())
            || s.vertices.iter().any(|(b, _)| b.iter().any(|&b| b as usize >= s.bones.len()))
        {
            return Err(bad("a bone out of range"));
        }
        out.put_u16(r + skin::MESH.start, s.mesh);
        out.put_u16(r + skin::BONE_COUNT.start, s.bones.len() as u16);
        out.put_u16(r + skin::FIRST_SLOT.start, first as u16);
        first += s.bones.len();
        let bones = out.reserve(skin::BONE_LEN * s.bones.len());
        out.put_u32(r + skin::BONES.start, bones as u32);
        for (b, bone) in s.bones.iter().enumerate() {
            out.put_u16(bones + b * skin::BONE_LEN + skin::BONE_NODE.start, bone.node);
            out.put_affine(bones + b * skin::BONE_LEN + skin::BONE_INVERSE_BIND.start, &bone.inverse_bind);
        }
        let vertices: Vec<u8> = s
            .vertices
            .iter()
            .flat_map(|(b, w)| {
                let q = w.map(|w| (libm::roundf(w.clamp(0.0, 1.0) * 65535.0) as u16).to_le_bytes());
                b.iter().copied().chain(q.into_iter().flatten()).collect::<Vec<u8>>()
            })
            .collect();
        let o = out.append(&vertices);
        out.put_u32(r + skin::VERTICES.start, o);
    }
    Ok(table as u32)
}

fn emit_groups(out: &mut Out, a: &AnimationData) -> Result<u32, EmitError> {
    let table = out.reserve(group::LEN * a.groups.len());
    for (k, g) in a.groups.iter().enumerate() {
        let r = table + k * group::LEN;
        out.put_f32s(r + group::FROM.start, &[g.from, g.to.max(g.from)]);
        let n = u16::try_from(g.tracks.len())
            .map_err(|_| EmitError(std::format!("group \"{}\": too many tracks", g.name)))?;
        out.put_u16(r + group::TRACK_COUNT.start, n);
        out.put(r + group::FLAGS, &[u8::from(g.looping)]);
        let list: Vec<u8> = g.tracks.iter().flat_map(|t| t.to_le_bytes()).collect();
        let o = out.append(&list);
        out.put_u32(r + group::TRACKS.start, o);
        let name: String = g.name.chars().take(1000).collect();
        out.put_u16(r + group::NAME_LEN.start, name.len() as u16);
        let o = out.append(name.as_bytes());
        out.put_u32(r + group::NAME.start, o);
    }
    Ok(table as u32)
}

/// The extreme positions mesh `mesh`'s morph targets reach with weights in 0..=1 (each
/// vertex's box corners), for its bounding sphere.
pub(super) fn morph_reach(scene: &Scene, mesh: usize) -> Vec<[f32; 3]> {
    let (Some(m), Some(data)) =
        (scene.animation.morphs.iter().find(|m| m.mesh as usize == mesh), scene.meshes.get(mesh))
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (i, p) in data.positions.iter().enumerate() {
        let (mut lo, mut hi) = (*p, *p);
        for t in &m.targets {
            if let Some(d) = t.positions.get(i) {
                for c in 0..3 {
                    lo[c] += d[c].min(0.0);
                    hi[c] += d[c].max(0.0);
                }
            }
        }
        out.extend([lo, hi]);
    }
    out
}

/// `model`'s animation as a scene's (positions' deltas back in local units).
pub(super) fn read_animation(model: &Model<'_>) -> AnimationData {
    let Some(a) = model.animation() else { return AnimationData::default() };
    let cols = |m: Mat4| -> scene::Matrix { m.to_cols_array() };
    let nodes = (0..a.node_count())
        .filter_map(|i| a.node(i))
        .map(|n| {
            let (r, quaternion) = n.rotation();
            scene::NodeData {
                name: String::new(),
                parent: n.parent().map(|p| p as u16),
                above: cols(n.above()),
                position: n.position().to_array(),
                rotation: if quaternion {
                    Rotation::Quaternion(r.to_array())
                } else {
                    Rotation::Euler([r.x, r.y, r.z])
                },
                scaling: n.scaling().to_array(),
            }
        })
        .collect();
    let links = (0..model.mesh_count())
        .filter_map(|m| {
            a.link_of(m).map(|(node, below)| scene::MeshLink { mesh: m as u16, node: node as u16, below: cols(below) })
        })
        .collect();
    let (morphs, tracks, groups) = (read_morphs(model, &a), read_tracks(&a), read_groups(&a));
    let camera_aim = emit_view::read_camera_aim(&a);
    AnimationData { nodes, links, morphs, tracks, groups, skins: read_skins(model, &a), camera_aim }
}

fn read_skins(model: &Model<'_>, a: &Animation<'_>) -> Vec<SkinData> {
    (0..a.skin_count())
        .filter_map(|i| a.skin_at(i))
        .map(|s| {
            let n = model.mesh(s.mesh()).map_or(0, |m| m.vertex_count());
            let bones = (0..s.bone_count())
                .map(|b| scene::SkinBone {
                    node: s.bone_node(b).unwrap_or(0) as u16,
                    inverse_bind: s.inverse_bind(b).to_cols_array(),
                })
                .collect();
            SkinData { mesh: s.mesh() as u16, bones, vertices: (0..n).map(|i| s.influences(i)).collect() }
        })
        .collect()
}

fn read_morphs(model: &Model<'_>, a: &Animation<'_>) -> Vec<scene::MorphData> {
    (0..a.morph_count())
        .filter_map(|i| a.morph_at(i))
        .map(|m| {
            let mesh = model.mesh(m.mesh());
            let n = mesh.map_or(0, |mesh| mesh.vertex_count());
            let units = mesh.map_or(crate::math::Vec3::ONE, |mesh| mesh.dequantization().0);
            let targets = (0..m.target_count() as usize)
                .map(|t| scene::MorphTargetData {
                    name: String::new(),
                    influence: m.default_influence(t),
                    positions: (0..n).map(|i| (m.delta(t, i, false) * units).to_array()).collect(),
                    normals: m.has_normals().then(|| (0..n).map(|i| m.delta(t, i, true).to_array()).collect()),
                })
                .collect();
            scene::MorphData { mesh: m.mesh() as u16, targets }
        })
        .collect()
}

fn read_tracks(a: &Animation<'_>) -> Vec<scene::TrackData> {
    let morph_of_weight = |w: usize| {
        (0..a.morph_count()).filter_map(|i| a.morph_at(i).map(|m| (i, m.weights()))).find(|(_, r)| r.contains(&w))
    };
    (0..a.track_count())
        .filter_map(|i| a.track(i))
        .map(|t| {
            let (first, count) = (t.first_component() as u8, t.component_count() as u8);
            let node = |node: u16, property| TrackTarget::Node { node, property, first, count };
            let target = match t.target() {
                StoredTarget::Position(n) => node(n, NodeProperty::Position),
                StoredTarget::Rotation(n) => node(n, NodeProperty::Rotation),
                StoredTarget::Scaling(n) => node(n, NodeProperty::Scaling),
                StoredTarget::Quaternion(n) => node(n, NodeProperty::RotationQuaternion),
                StoredTarget::Influence(w) => {
                    let (morph, range) = morph_of_weight(w as usize).unwrap_or((0, 0..0));
                    TrackTarget::Morph { morph: morph as u16, target: (w as usize - range.start) as u16 }
                }
                view => {
                    emit_view::scene_target(view, first, count).unwrap_or(TrackTarget::Morph { morph: 0, target: 0 })
                }
            };
            let n = count as usize;
            let keys = (0..t.key_count())
                .map(|k| scene::KeyData {
                    frame: t.frame(k),
                    values: t.value(k, 0).to_array()[..n].to_vec(),
                    tangents: t
                        .has_tangents()
                        .then(|| {
                            let [tin, tout] =
                                [(1, t.has_in_tangent(k)), (2, t.has_out_tangent(k))].map(|(set, has)| {
                                    if has {
                                        t.value(k, set).to_array()[..n].to_vec()
                                    } else {
                                        Vec::new()
                                    }
                                });
                            (tin, tout)
                        })
                        .filter(|(i, o)| !i.is_empty() || !o.is_empty()),
                    step: t.is_step(k),
                })
                .collect();
            let looping = [Loop::Relative, Loop::Cycle, Loop::Constant][t.loop_mode() as usize % 3];
            scene::TrackData { target, fps: t.fps(), looping, keys }
        })
        .collect()
}

fn read_groups(a: &Animation<'_>) -> Vec<scene::GroupData> {
    (0..a.group_count())
        .filter_map(|i| a.group(i))
        .map(|g| {
            let (from, to) = g.range();
            scene::GroupData {
                name: g.name().into(),
                from,
                to,
                looping: g.loops(),
                tracks: g.tracks().map(|t| t as u16).collect(),
            }
        })
        .collect()
}
