//! Animations: the tracks of meshes, transform nodes and morph target influences, the groups
//! that play them, the nodes they move with the meshes those nodes carry, and the meshes'
//! morph targets, read into [`AnimationData`] (the still picture, `MeshData::world`, keeps the
//! first frame of `autoAnimate` nodes that `transform` bakes).
//!
//! The rules, after Babylon.js's `Animation.Parse`, `AnimationGroup.Parse` and
//! `MorphTarget.Parse`, and the choices made where those are silent:
//!
//! - **Properties**: `position`, `rotation`, `scaling`, `rotationQuaternion` and their single
//!   components (`position.x`, `rotationQuaternion.w`) of meshes and transform nodes, and the
//!   `influence` of morph targets. Any other property (`_matrix`, `visibility`, a material's)
//!   and a `dataType` that does not match the property (0 float for a component or an
//!   influence, 1 vector3, 2 quaternion; a missing `dataType` is taken as the property's) are
//!   skipped with a warning naming the node and the animation.
//! - **Tracks**: `framePerSecond` defaults to 30 (Babylon.js has no default: its `Animation`
//!   takes the value as given), a track with a rate that is not positive is skipped with a
//!   warning; `loopBehavior` 0, 1 (the default), 2, any other value is played as 1 with a
//!   warning. A track without keys is skipped with a warning; keys out of frame order are
//!   sorted by frame (stably) with a warning.
//! - **Keys**: `frame` and `values` are required (a wrong type is an error naming the key).
//!   `values` holds the value's numbers (a float's may be a number alone) and may go on in
//!   Babylon.js's packed layout: for floats and vectors an in-tangent, an out-tangent (each
//!   `null`, a number or an array) and the interpolation; for quaternions 4 + 4 numbers of
//!   tangents (all zero: none) and the interpolation. `inTangent`, `outTangent` and
//!   `interpolation` keys, when present, win over the packed ones. `interpolation: 1` is a
//!   step. A key with one tangent only keeps that one: a span is Hermite when its first key
//!   has an out-tangent and its last an in-tangent, else linear, as in Babylon.js.
//! - **Groups**: `animationGroups[].targetedAnimations[]` name their target by `targetId`: the
//!   active camera or a light soft3d draws (by `id`, then `name`: their tracks are
//!   `view_tracks`'), else for an `influence` track a morph target (by `id`, then `name`), for
//!   any other a mesh or transform node (by `id`, then `name`); unknown targets, other cameras
//!   and lights, and skeleton bones are skipped with a warning. A group without `from`/`to`
//!   spans its tracks' keys, and loops when `loopAnimation` is true (Babylon.js's default:
//!   false). Then each node or morph target (and the camera and lights, `view_tracks`) with
//!   tracks of its own (its `animations`) gets a group of them named after it:
//!   with `autoAnimate`, from `autoAnimateFrom` (default 0) to `autoAnimateTo` (default: the
//!   last key), looping unless `autoAnimateLoop` is false; without, over its keys, looping.
//! - **Nodes and links**: every mesh or transform node with a track becomes a `NodeData`, after
//!   its nearest animated ancestor; each drawn mesh on a chain with an animated node is linked
//!   to the nearest one. Instances of moving meshes are drawn still (one warning).
//! - **Morph targets**: a drawn mesh's `morphTargetManagerId` (a number or string; negative
//!   for none) names a manager by its `id`; each target's `positions` and `normals` (absolute
//!   in the file) become differences from the mesh's own (the file's base normals, else the
//!   reader's computed ones); a target without `positions` moves no vertex. A target whose
//!   length is not the mesh's vertex count drops the manager for that mesh, with a warning.
//!   A manager shared by several meshes gives each mesh its `MorphData` and each influence
//!   track one track per mesh.

use std::format;
use std::string::String;
use std::vec;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{flag, floats, get, label, list, number, scalar, show, text, Ctx, Res};
use super::track::{parse_animation, Curve, Owner, Property};
use super::transform::mul;
use super::{ConvertError, Reader};
use crate::convert::scene::{
    AnimationData, CameraProperty, GroupData, KeyData, LightProperty, MeshLink, MorphData, MorphTargetData, NodeData,
    NodeProperty, TrackData, TrackTarget, IDENTITY,
};

/// What a track moves, before the animated nodes and the morphed meshes are numbered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Target {
    /// Components of a property of a node (an index into `Reader::nodes`).
    Node { node: usize, property: NodeProperty, first: u8, count: u8 },
    /// The influence of a morph target: indices into the managers and their targets.
    Morph { manager: usize, target: usize },
    /// Components of a property of the stored camera (keys in world space).
    Camera { property: CameraProperty, first: u8, count: u8 },
    /// Components of a property of a stored light (an index into `Scene::lights`; keys in
    /// world space).
    Light { light: u16, property: LightProperty, first: u8, count: u8 },
}

/// A track as read, with its target not yet numbered.
pub(super) struct Track {
    pub(super) target: Target,
    pub(super) curve: Curve,
}

/// A group as read: indices into the read tracks; `None` ends span the tracks' keys.
pub(super) struct Group {
    name: String,
    from: Option<f32>,
    to: Option<f32>,
    looping: bool,
    tracks: Vec<usize>,
}

/// The tracks and groups read so far.
#[derive(Default)]
pub(super) struct Read {
    pub(super) tracks: Vec<Track>,
    pub(super) groups: Vec<Group>,
}

/// A morph target manager (`morphTargetManagers[]`).
struct Manager<'v> {
    id: Option<String>,
    what: String,
    targets: Vec<MorphTarget<'v>>,
}

/// One target of a manager, as written (positions and normals absolute).
struct MorphTarget<'v> {
    obj: &'v Value,
    name: String,
    id: Option<String>,
    influence: f32,
    positions: Option<Vec<f32>>,
    normals: Option<Vec<f32>>,
}

impl<'a> Reader<'a> {
    /// Fills `Scene::animation`; runs after `read_meshes` (it links the meshes drawn).
    pub(super) fn read_animation(&mut self) -> Result<(), ConvertError> {
        let managers = self.morph_managers()?;
        let mut read = Read::default();
        self.read_groups(&managers, &mut read)?;
        self.read_node_tracks(&mut read)?;
        self.read_morph_tracks(&managers, &mut read)?;
        self.read_view_tracks(&mut read)?;
        let camera_aim = self.camera_aim(&read.tracks);
        let order = self.animated_nodes(&read.tracks)?;
        let mut index = vec![None; self.nodes.len()];
        for (k, &n) in order.iter().enumerate() {
            index[n] = Some(self.small(k, "animated nodes")?);
        }
        let nodes = self.node_data(&order, &index)?;
        let links = self.links(&index)?;
        let (morphs, used) = self.morphs(&managers)?;
        let (tracks, groups) = self.number(read, &index, &used, &managers)?;
        self.warn_instances(&links, &morphs);
        self.scene.animation = AnimationData { nodes, links, morphs, tracks, groups, skins: Vec::new(), camera_aim };
        Ok(())
    }

    /// `n` as a `u16` index, or an error naming what there are too many of.
    fn small(&self, n: usize, what: &str) -> Result<u16, ConvertError> {
        u16::try_from(n).map_err(|_| self.ctx("scene").err(format!("more than 65536 {what}")))
    }

    /// Reads `morphTargetManagers` (a field of the wrong type is an error).
    fn morph_managers(&mut self) -> Result<Vec<Manager<'a>>, ConvertError> {
        let root = self.root;
        let all = list(root, "morphTargetManagers").map_err(|m| self.ctx("scene").err(m))?;
        let mut managers = Vec::with_capacity(all.len());
        for (i, obj) in all.iter().enumerate() {
            let cx = self.ctx(format!("morphTargetManagers[{i}]"));
            if !obj.is_object() {
                return Err(cx.err(format!("expected an object, found {}", show(obj))));
            }
            let id = text(obj, "id").map_err(|m| cx.err(m))?;
            let what = id.as_ref().map_or(cx.what.clone(), |id| format!("morph target manager {id:?}"));
            let cx = self.ctx(what.clone());
            let targets = list(obj, "targets").map_err(|m| cx.err(m))?;
            let targets: Vec<MorphTarget> = targets
                .iter()
                .enumerate()
                .map(|(k, t)| morph_target(t, k))
                .collect::<Res<_>>()
                .map_err(|m| cx.err(m))?;
            for t in targets.iter().filter(|t| get(t.obj, "uvs").is_some() || get(t.obj, "tangents").is_some()) {
                self.warn(format!("{what}: target {:?}: uvs and tangents of morph targets are not played", t.name));
            }
            managers.push(Manager { id, what, targets });
        }
        Ok(managers)
    }

    /// Reads one animation object of `owner` (`at` is where it lies in `cx`'s object, for
    /// errors; `here` names it in warnings): its property and curve, `None` (warned) when
    /// soft3d skips it.
    pub(super) fn animation(
        &mut self,
        anim: &Value,
        owner: Owner,
        here: &str,
        at: &str,
        cx: &Ctx,
    ) -> Result<Option<(Property, Curve)>, ConvertError> {
        if !anim.is_object() {
            return Err(cx.err(format!("{at}: expected an object, found {}", show(anim))));
        }
        let mut notes = Vec::new();
        let parsed = parse_animation(anim, owner, &mut notes).map_err(|m| cx.err(format!("{at}.{m}")))?;
        for note in notes {
            self.warn(format!("{here}: {note}"));
        }
        match parsed {
            Ok(p) => Ok(Some(p)),
            Err(reason) => {
                self.warn(format!("{here}: {reason}, skipped"));
                Ok(None)
            }
        }
    }

    /// Reads `animationGroups`.
    fn read_groups(&mut self, managers: &[Manager<'a>], read: &mut Read) -> Result<(), ConvertError> {
        let root = self.root;
        for (g, group) in list(root, "animationGroups").map_err(|m| self.ctx("scene").err(m))?.iter().enumerate() {
            let cx = self.ctx(label(group, "animation group", "animationGroups", g));
            if !group.is_object() {
                return Err(cx.err(format!("expected an object, found {}", show(group))));
            }
            let e = |m: String| cx.err(m);
            let mut tracks = Vec::new();
            for (k, targeted) in list(group, "targetedAnimations").map_err(e)?.iter().enumerate() {
                if let Some(track) = self.targeted(managers, targeted, k, &cx, read)? {
                    tracks.push(track);
                }
            }
            let name = text(group, "name").map_err(e)?.unwrap_or_else(|| format!("animationGroups[{g}]"));
            let (from, to) = (number(group, "from").map_err(e)?, number(group, "to").map_err(e)?);
            let looping = flag(group, "loopAnimation", false).map_err(e)?;
            if !tracks.is_empty() {
                read.groups.push(Group { name, from, to, looping, tracks });
            }
        }
        Ok(())
    }

    /// Reads `targetedAnimations[k]` of a group into `read`: the index of its track, `None`
    /// (warned) when skipped.
    fn targeted(
        &mut self,
        managers: &[Manager<'a>],
        targeted: &Value,
        k: usize,
        cx: &Ctx,
        read: &mut Read,
    ) -> Result<Option<usize>, ConvertError> {
        let at = format!("targetedAnimations[{k}]");
        let id = text(targeted, "targetId").map_err(|m| cx.err(format!("{at}.{m}")))?;
        let (Some(id), Some(anim)) = (id, get(targeted, "animation")) else {
            self.warn(format!("{}: {at}: no targetId or no animation, skipped", cx.what));
            return Ok(None);
        };
        let here = format!("{}: {at} (target {id:?})", cx.what);
        let view = match self.view_named(&id) {
            Ok(view) => view,
            Err(reason) => {
                self.warn(format!("{here}: {reason}, skipped"));
                return Ok(None);
            }
        };
        let owner = if view.is_some() { Owner::View } else { Owner::Node };
        let Some((property, mut curve)) = self.animation(anim, owner, &here, &format!("{at}.animation"), cx)? else {
            return Ok(None);
        };
        let target = match (view, property) {
            (Some(view), property) => self.view_target(view, property, &mut curve),
            (None, Property::Influence) => find_morph_target(managers, &id)
                .map(|(manager, target)| Target::Morph { manager, target })
                .ok_or_else(|| "no morph target has this id or name".into()),
            (None, Property::Node { property, first, count }) => {
                self.find_node(&id).map(|node| Target::Node { node, property, first, count })
            }
            (None, Property::View { .. }) => Err("not a camera or light".into()),
        };
        match target {
            Ok(target) => {
                read.tracks.push(Track { target, curve });
                Ok(Some(read.tracks.len() - 1))
            }
            Err(reason) => {
                self.warn(format!("{here}: {reason}, skipped"));
                Ok(None)
            }
        }
    }

    /// The mesh or transform node with `id` (by `id`, then `name`), or why there is none
    /// (cameras and lights are `view_tracks`', skeleton bones are not played).
    fn find_node(&self, id: &str) -> Result<usize, String> {
        match self.ids.get(id).or_else(|| self.names.get(id)).copied() {
            Some(node) if self.nodes[node].movable => Ok(node),
            Some(node) => Err(format!("{}: a camera or light, not a mesh or transform node", self.nodes[node].what)),
            None if self.is_bone(id) => Err("a skeleton bone: skeletons are not played yet".into()),
            None => Err("no mesh or transform node has this id or name".into()),
        }
    }

    /// Whether a skeleton bone has `id` as its `id` or `name`.
    fn is_bone(&self, id: &str) -> bool {
        let skeletons = list(self.root, "skeletons").unwrap_or_default();
        let bones = skeletons.iter().flat_map(|s| list(s, "bones").unwrap_or_default());
        bones.into_iter().any(|b| ["id", "name"].iter().any(|k| text(b, k).ok().flatten().as_deref() == Some(id)))
    }

    /// Reads the `animations` of meshes and transform nodes, each node's in a group of its own.
    fn read_node_tracks(&mut self, read: &mut Read) -> Result<(), ConvertError> {
        for n in 0..self.nodes.len() {
            if !self.nodes[n].movable {
                continue;
            }
            let (obj, what) = (self.nodes[n].obj, self.nodes[n].what.clone());
            let cx = self.ctx(what.clone());
            let mut own = Vec::new();
            for (k, anim) in list(obj, "animations").map_err(|m| cx.err(m))?.iter().enumerate() {
                let at = format!("animations[{k}]");
                let here = named(&what, &at, anim);
                let Some((property, curve)) = self.animation(anim, Owner::Node, &here, &at, &cx)? else {
                    continue;
                };
                let Property::Node { property, first, count } = property else {
                    self.warn(format!("{here}: influence is a morph target's property, skipped"));
                    continue;
                };
                read.tracks.push(Track { target: Target::Node { node: n, property, first, count }, curve });
                own.push(read.tracks.len() - 1);
            }
            if !own.is_empty() {
                read.groups.push(own_group(obj, node_name(obj), own).map_err(|m| cx.err(m))?);
            }
        }
        Ok(())
    }

    /// Reads the `animations` of morph targets, each target's in a group of its own.
    fn read_morph_tracks(&mut self, managers: &[Manager<'a>], read: &mut Read) -> Result<(), ConvertError> {
        for (m, manager) in managers.iter().enumerate() {
            let cx = self.ctx(manager.what.clone());
            for (t, target) in manager.targets.iter().enumerate() {
                let in_target = |e: String| cx.err(format!("targets[{t}].{e}"));
                let mut own = Vec::new();
                for (k, anim) in list(target.obj, "animations").map_err(in_target)?.iter().enumerate() {
                    let at = format!("targets[{t}].animations[{k}]");
                    let here = named(&manager.what, &at, anim);
                    let Some((property, curve)) = self.animation(anim, Owner::Node, &here, &at, &cx)? else {
                        continue;
                    };
                    if property != Property::Influence {
                        self.warn(format!("{here}: a morph target has only an influence to animate, skipped"));
                        continue;
                    }
                    read.tracks.push(Track { target: Target::Morph { manager: m, target: t }, curve });
                    own.push(read.tracks.len() - 1);
                }
                if !own.is_empty() {
                    read.groups.push(own_group(target.obj, target.name.clone(), own).map_err(in_target)?);
                }
            }
        }
        Ok(())
    }

    /// The nodes that tracks move, each after its nearest animated ancestor.
    fn animated_nodes(&self, tracks: &[Track]) -> Result<Vec<usize>, ConvertError> {
        let mut animated = vec![false; self.nodes.len()];
        for track in tracks {
            if let Target::Node { node, .. } = track.target {
                animated[node] = true;
            }
        }
        let mut order = Vec::new();
        for n in (0..self.nodes.len()).filter(|&n| animated[n]) {
            let depth = self.ancestors(n)?.iter().filter(|&&a| animated[a]).count();
            order.push((depth, n));
        }
        order.sort_unstable();
        Ok(order.into_iter().map(|(_, n)| n).collect())
    }

    /// The animated nodes (`order`; `index` maps a reader node to its place there).
    fn node_data(&mut self, order: &[usize], index: &[Option<u16>]) -> Result<Vec<NodeData>, ConvertError> {
        let mut nodes = Vec::with_capacity(order.len());
        for &n in order {
            let chain = self.ancestors(n)?;
            let (parent, above) = match chain.iter().position(|&a| index[a].is_some()) {
                Some(k) => (index[chain[k]], self.still_product(&chain[..k])),
                None => {
                    let parent = self.nodes[n].parent;
                    (None, self.parent_world(parent)?)
                }
            };
            let (position, rotation, scaling) = self.nodes[n].trs.rest();
            nodes.push(NodeData { name: node_name(self.nodes[n].obj), parent, above, position, rotation, scaling });
        }
        Ok(nodes)
    }

    /// The product of the local matrices of `chain`, nearest the node first.
    fn still_product(&self, chain: &[usize]) -> [f32; 16] {
        chain.iter().fold(IDENTITY, |m, &a| mul(&m, &self.nodes[a].local))
    }

    /// The links of the drawn meshes that have an animated node on their chain.
    fn links(&self, index: &[Option<u16>]) -> Result<Vec<MeshLink>, ConvertError> {
        let mut links = Vec::new();
        if index.iter().all(Option::is_none) {
            return Ok(links);
        }
        for n in 0..self.nodes.len() {
            let Some(mesh) = self.drawn_mesh(n) else {
                continue;
            };
            let chain: Vec<usize> = core::iter::once(n).chain(self.ancestors(n)?).collect();
            if let Some(k) = chain.iter().position(|&a| index[a].is_some()) {
                let (mesh, node) = (self.small(mesh, "meshes")?, index[chain[k]].unwrap_or_default());
                links.push(MeshLink { mesh, node, below: self.still_product(&chain[..k]) });
            }
        }
        Ok(links)
    }

    /// The morph targets of the drawn meshes, and for each manager the `MorphData` made of it.
    fn morphs(&mut self, managers: &[Manager<'a>]) -> Result<(Vec<MorphData>, Vec<Vec<u16>>), ConvertError> {
        let (mut morphs, mut used) = (Vec::new(), vec![Vec::new(); managers.len()]);
        for n in 0..self.nodes.len() {
            let Some(mesh) = self.drawn_mesh(n) else {
                continue;
            };
            let (obj, what) = (self.nodes[n].obj, self.nodes[n].what.clone());
            let cx = self.ctx(what.clone());
            let Some(id) = text(obj, "morphTargetManagerId").map_err(|m| cx.err(m))? else {
                continue;
            };
            if get(obj, "morphTargetManagerId").and_then(Value::as_f64).is_some_and(|x| x < 0.0) {
                continue;
            }
            let Some(m) = managers.iter().position(|g| g.id.as_deref() == Some(&*id)) else {
                self.warn(format!("{what}: morph target manager {id:?} not found, drawn in its base shape"));
                continue;
            };
            let Some(targets) = self.morph_deltas(n, mesh, &managers[m])? else {
                continue;
            };
            used[m].push(self.small(morphs.len(), "morphed meshes")?);
            morphs.push(MorphData { mesh: self.small(mesh, "meshes")?, targets });
        }
        Ok((morphs, used))
    }

    /// The targets of `manager` as differences from scene mesh `mesh` (drawn from node
    /// `node`); `None`, with a warning, when a target's length is not the mesh's.
    fn morph_deltas(
        &mut self,
        node: usize,
        mesh: usize,
        manager: &Manager<'a>,
    ) -> Result<Option<Vec<MorphTargetData>>, ConvertError> {
        let cx = self.ctx(self.nodes[node].what.clone());
        let Some(base) = self.scene.meshes.get(mesh) else {
            return Ok(None);
        };
        let n = base.positions.len();
        let mut normals = base.normals.clone();
        if manager.targets.iter().any(|t| t.normals.is_some()) {
            let file = self.geometry(self.nodes[node].obj, &cx)?.normals;
            if let Some(file) = file.filter(|f| f.len() == 3 * n) {
                normals = file.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            }
        }
        let deltas = manager.targets.iter().map(|t| target_deltas(t, &base.positions, &normals)).collect();
        match deltas {
            Ok(targets) => Ok(Some(targets)),
            Err(problem) => {
                self.warn(format!("{}: {}: {problem}: drawn without its morph targets", cx.what, manager.what));
                Ok(None)
            }
        }
    }

    /// Numbers the read tracks and groups: node tracks by `index`, morph tracks one per mesh
    /// that uses their manager (`used`).
    fn number(
        &mut self,
        read: Read,
        index: &[Option<u16>],
        used: &[Vec<u16>],
        managers: &[Manager<'a>],
    ) -> Result<(Vec<TrackData>, Vec<GroupData>), ConvertError> {
        let ranges: Vec<(f32, f32)> = read.tracks.iter().map(|t| key_range(&t.curve.keys)).collect();
        let (mut tracks, mut numbered) = (Vec::new(), Vec::with_capacity(read.tracks.len()));
        let mut unused = vec![false; managers.len()];
        for Track { target, curve } in read.tracks {
            let targets: Vec<TrackTarget> = match target {
                Target::Node { node, property, first, count } => {
                    index[node].map(|node| TrackTarget::Node { node, property, first, count }).into_iter().collect()
                }
                Target::Morph { manager, target } => {
                    let target = self.small(target, "morph targets in a manager")?;
                    unused[manager] |= used[manager].is_empty();
                    used[manager].iter().map(|&morph| TrackTarget::Morph { morph, target }).collect()
                }
                Target::Camera { property, first, count } => vec![TrackTarget::Camera { property, first, count }],
                Target::Light { light, property, first, count } => {
                    vec![TrackTarget::Light { light, property, first, count }]
                }
            };
            let mut ids = Vec::with_capacity(targets.len());
            for target in targets {
                ids.push(self.small(tracks.len(), "animation tracks")?);
                tracks.push(TrackData { target, fps: curve.fps, looping: curve.looping, keys: curve.keys.clone() });
            }
            numbered.push(ids);
        }
        for (manager, _) in managers.iter().zip(&unused).filter(|(_, u)| **u) {
            self.warn(format!("{}: no drawn mesh uses it: its animations are skipped", manager.what));
        }
        let groups = read.groups.into_iter().filter_map(|g| number_group(g, &numbered, &ranges)).collect();
        Ok((tracks, groups))
    }

    /// Warns once when a moving mesh has instances (they are drawn still).
    fn warn_instances(&mut self, links: &[MeshLink], morphs: &[MorphData]) {
        let moving = |mesh: u16| links.iter().any(|l| l.mesh == mesh) || morphs.iter().any(|m| m.mesh == mesh);
        let first = self.scene.instances.iter().find(|i| moving(i.mesh));
        let name = first.and_then(|i| self.scene.meshes.get(usize::from(i.mesh))).map(|m| m.name.clone());
        if let Some(name) = name {
            self.warn(format!("mesh {name:?}: instances of animated meshes are drawn still"));
        }
    }
}

/// `what: at` with the animation's `name` when it has one, for warnings.
pub(super) fn named(what: &str, at: &str, anim: &Value) -> String {
    match text(anim, "name").ok().flatten() {
        Some(name) => format!("{what}: {at} ({name:?})"),
        None => format!("{what}: {at}"),
    }
}

/// A node's `name`, else its `id`.
fn node_name(obj: &Value) -> String {
    text(obj, "name").ok().flatten().or_else(|| text(obj, "id").ok().flatten()).unwrap_or_default()
}

/// `targets[k]` of a manager.
fn morph_target(obj: &Value, k: usize) -> Res<MorphTarget<'_>> {
    let at = |m: String| format!("targets[{k}].{m}");
    if !obj.is_object() {
        return Err(format!("targets[{k}]: expected an object, found {}", show(obj)));
    }
    let id = text(obj, "id").map_err(at)?;
    let name = text(obj, "name").map_err(at)?.or_else(|| id.clone()).unwrap_or_else(|| format!("targets[{k}]"));
    Ok(MorphTarget {
        obj,
        name,
        id,
        influence: scalar(obj, "influence", 0.).map_err(at)?,
        positions: floats(obj, "positions").map_err(at)?,
        normals: floats(obj, "normals").map_err(at)?,
    })
}

/// The manager and target with `id` (by `id` first, then by `name`).
fn find_morph_target(managers: &[Manager], id: &str) -> Option<(usize, usize)> {
    let find = |by_name: bool| {
        managers.iter().enumerate().find_map(|(m, manager)| {
            let hit = |t: &MorphTarget| if by_name { t.name == id } else { t.id.as_deref() == Some(id) };
            manager.targets.iter().position(hit).map(|t| (m, t))
        })
    };
    find(false).or_else(|| find(true))
}

/// A target's positions and normals minus the mesh's, or why they do not fit.
fn target_deltas(t: &MorphTarget, positions: &[[f32; 3]], normals: &[[f32; 3]]) -> Result<MorphTargetData, String> {
    let n = positions.len();
    let minus = |key: &str, given: &[f32], base: &[[f32; 3]]| {
        if given.len() != 3 * n || base.len() != n {
            let needed = 3 * n;
            return Err(format!(
                "target {:?}: {key} has {} numbers but {n} vertices need {needed}",
                t.name,
                given.len()
            ));
        }
        Ok(given.chunks_exact(3).zip(base).map(|(g, b)| [g[0] - b[0], g[1] - b[1], g[2] - b[2]]).collect::<Vec<_>>())
    };
    let positions = match &t.positions {
        Some(p) => minus("positions", p, positions)?,
        None => vec![[0.; 3]; n],
    };
    let normals = t.normals.as_deref().map(|g| minus("normals", g, normals)).transpose()?;
    Ok(MorphTargetData { name: t.name.clone(), influence: t.influence, positions, normals })
}

/// The group of a node's, morph target's, camera's or light's own tracks (see the module
/// documentation).
pub(super) fn own_group(obj: &Value, name: String, tracks: Vec<usize>) -> Res<Group> {
    if !flag(obj, "autoAnimate", false)? {
        return Ok(Group { name, from: None, to: None, looping: true, tracks });
    }
    let from = Some(scalar(obj, "autoAnimateFrom", 0.)?);
    Ok(Group { name, from, to: number(obj, "autoAnimateTo")?, looping: flag(obj, "autoAnimateLoop", true)?, tracks })
}

/// A group with its tracks numbered (`numbered[r]`: the tracks made of read track `r`), its
/// missing ends the range of its tracks' keys; `None` when no track is left.
fn number_group(group: Group, numbered: &[Vec<u16>], ranges: &[(f32, f32)]) -> Option<GroupData> {
    let tracks: Vec<u16> = group.tracks.iter().flat_map(|&r| numbered.get(r).into_iter().flatten().copied()).collect();
    if tracks.is_empty() {
        return None;
    }
    let spans = group.tracks.iter().filter_map(|&r| ranges.get(r));
    let (first, last) = spans.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &(f, l)| (a.min(f), b.max(l)));
    let from = group.from.unwrap_or(first);
    let to = group.to.unwrap_or(last);
    Some(GroupData { name: group.name, from, to, looping: group.looping, tracks })
}

/// The first and last frames of keys (in frame order, at least one).
fn key_range(keys: &[KeyData]) -> (f32, f32) {
    (keys.first().map_or(0., |k| k.frame), keys.last().map_or(0., |k| k.frame))
}
