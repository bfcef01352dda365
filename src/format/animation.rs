//! A model's animation section, read in place: its validation (once, from `Model::parse`) and
//! typed views of its records ([`Animation`], [`Node`], [`Track`], [`Group`], [`Morph`]). The
//! byte layout is `layout`'s; what a pose at a frame is, is `crate::animation`'s.

use core::ops::Range;

use super::error::{ParseError, Part};
use super::layout::*;
use crate::math::{Mat4, Vec3, Vec4};

/// The animation section of a [`Model`](super::Model): every count, offset and reference in it
/// was checked by `Model::parse`.
#[derive(Clone, Copy, Debug)]
pub struct Animation<'a> {
    data: &'a [u8],
    at: usize,
}

/// An animated node (see `convert::scene::NodeData`).
#[derive(Clone, Copy, Debug)]
pub struct Node<'a> {
    data: &'a [u8],
    at: usize,
}

/// One track: what it moves and its keys.
#[derive(Clone, Copy, Debug)]
pub struct Track<'a> {
    data: &'a [u8],
    at: usize,
}

/// What a [`Track`] sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackTarget {
    /// Components `first..first + count` of a node's position.
    Position(u16),
    /// Components of a node's Euler rotation.
    Rotation(u16),
    /// Components of a node's scaling.
    Scaling(u16),
    /// A node's quaternion.
    Quaternion(u16),
    /// A morph weight (an index over every mesh's targets).
    Influence(u16),
}

/// A group of tracks played together.
#[derive(Clone, Copy, Debug)]
pub struct Group<'a> {
    data: &'a [u8],
    at: usize,
}

/// A skinned mesh: its bones (palette) and each vertex's four bones and weights.
#[derive(Clone, Copy, Debug)]
pub struct Skin<'a> {
    data: &'a [u8],
    at: usize,
}

/// A mesh's morph targets.
#[derive(Clone, Copy, Debug)]
pub struct Morph<'a> {
    data: &'a [u8],
    at: usize,
}

fn records(
    data: &[u8],
    start: u32,
    (count, len): (usize, usize),
    part: Part,
    at: usize,
) -> Result<Range<usize>, ParseError> {
    let start = start as usize;
    let bytes = count.checked_mul(len).ok_or(ParseError::OutOfBounds { part, offset: at })?;
    match start.checked_add(bytes) {
        Some(end) if end <= data.len() => Ok(start..end),
        _ => Err(ParseError::OutOfBounds { part, offset: at }),
    }
}

fn finite(data: &[u8], range: Range<usize>, part: Part) -> Result<(), ParseError> {
    match range.step_by(4).find(|&at| !f32_at(data, at).is_finite()) {
        Some(offset) => Err(ParseError::NotFinite { part, offset }),
        None => Ok(()),
    }
}

fn reference(data: &[u8], at: usize, count: usize, part: Part) -> Result<usize, ParseError> {
    let index = u16_at(data, at);
    if (index as usize) < count {
        Ok(index as usize)
    } else {
        Err(ParseError::BadReference { part, offset: at, index, count: count as u16 })
    }
}

fn invalid(part: Part, offset: usize) -> ParseError {
    ParseError::Invalid { part, offset }
}

impl<'a> Animation<'a> {
    /// The section at `at` of `data`, which [`Animation::validate`] accepted (in `Model::parse`).
    pub(super) fn validated(data: &'a [u8], at: u32) -> Self {
        Animation { data, at: at as usize }
    }

    /// Checks the section at `at` of `data`, for a model whose meshes have `vertices(m)`
    /// vertices (`None` past the last mesh).
    pub(super) fn validate(
        data: &'a [u8],
        at: u32,
        vertices: impl Fn(usize) -> Option<u32>,
    ) -> Result<Self, ParseError> {
        let head = records(data, at, (1, animation::LEN), Part::Animation, header::ANIMATION.start)?;
        let a = Animation { data, at: head.start };
        a.validate_nodes()?;
        a.validate_links(&vertices)?;
        a.validate_morphs(&vertices)?;
        a.validate_tracks()?;
        a.validate_groups()?;
        a.validate_skins(&vertices)?;
        Ok(a)
    }

    fn count(&self, field: Range<usize>) -> usize {
        u16_at(self.data, self.at + field.start) as usize
    }

    fn table(
        &self,
        offset: Range<usize>,
        count: Range<usize>,
        len: usize,
        part: Part,
    ) -> Result<Range<usize>, ParseError> {
        let start = u32_at(self.data, self.at + offset.start);
        records(self.data, start, (self.count(count), len), part, self.at + offset.start)
    }

    fn validate_nodes(&self) -> Result<(), ParseError> {
        let d = self.data;
        let nodes = self.table(animation::NODES, animation::NODE_COUNT, node::LEN, Part::Node)?;
        for (k, at) in nodes.step_by(node::LEN).enumerate() {
            let parent = u16_at(d, at + node::PARENT.start);
            if parent != NONE && parent as usize >= k {
                return Err(ParseError::BadReference { part: Part::Node, offset: at, index: parent, count: k as u16 });
            }
            if u16_at(d, at + node::FLAGS.start) > node::FLAG_QUATERNION {
                return Err(invalid(Part::Node, at + node::FLAGS.start));
            }
            finite(d, at + node::POSITION.start..at + node::LEN, Part::Node)?;
        }
        Ok(())
    }

    fn validate_links(&self, vertices: &impl Fn(usize) -> Option<u32>) -> Result<(), ParseError> {
        let d = self.data;
        let links = self.table(animation::LINKS, animation::LINK_COUNT, link::LEN, Part::Link)?;
        let meshes = (0..).take_while(|&m| vertices(m).is_some()).count();
        let mut last = None;
        for at in links.step_by(link::LEN) {
            let mesh = reference(d, at + link::MESH.start, meshes, Part::Link)?;
            reference(d, at + link::NODE.start, self.node_count(), Part::Link)?;
            finite(d, at + link::BELOW.start..at + link::LEN, Part::Link)?;
            // By increasing mesh: at most one link a mesh, checked in one pass.
            if last.is_some_and(|l| l >= mesh) {
                return Err(invalid(Part::Link, at));
            }
            last = Some(mesh);
        }
        Ok(())
    }

    fn validate_morphs(&self, vertices: &impl Fn(usize) -> Option<u32>) -> Result<(), ParseError> {
        let d = self.data;
        let morphs = self.table(animation::MORPHS, animation::MORPH_COUNT, morph::LEN, Part::Morph)?;
        let meshes = (0..).take_while(|&m| vertices(m).is_some()).count();
        let mut last = None;
        for at in morphs.step_by(morph::LEN) {
            let mesh = reference(d, at + morph::MESH.start, meshes, Part::Morph)?;
            // By increasing mesh, as links.
            if last.is_some_and(|l| l >= mesh) {
                return Err(invalid(Part::Morph, at));
            }
            last = Some(mesh);
            let m = Morph { data: d, at };
            let (targets, flags) = (m.target_count() as usize, u16_at(d, at + morph::FLAGS.start));
            let first = u16_at(d, at + morph::FIRST_WEIGHT.start) as usize;
            if targets == 0 || first + targets > self.weight_count() || flags > morph::FLAG_NORMALS {
                return Err(invalid(Part::Morph, at + morph::TARGET_COUNT.start));
            }
            let nv = vertices(mesh).unwrap_or(0) as usize;
            let table_at = at + morph::TARGETS.start;
            let table = records(d, u32_at(d, table_at), (targets, morph_target::LEN), Part::Morph, table_at)?;
            for t in table.step_by(morph_target::LEN) {
                self.validate_target(t, nv, flags & morph::FLAG_NORMALS != 0)?;
            }
        }
        Ok(())
    }

    fn validate_target(&self, at: usize, vertices: usize, normals: bool) -> Result<(), ParseError> {
        let d = self.data;
        finite(d, at..at + morph_target::POSITIONS.start, Part::Morph)?;
        let deltas = (vertices, morph_target::DELTA_LEN);
        let positions = at + morph_target::POSITIONS.start;
        records(d, u32_at(d, positions), deltas, Part::Morph, positions)?;
        if normals {
            let normals = at + morph_target::NORMALS.start;
            records(d, u32_at(d, normals), deltas, Part::Morph, normals)?;
        }
        Ok(())
    }

    fn validate_skins(&self, vertices: &impl Fn(usize) -> Option<u32>) -> Result<(), ParseError> {
        let d = self.data;
        let skins = self.table(animation::SKINS, animation::SKIN_COUNT, skin::LEN, Part::Skin)?;
        let meshes = (0..).take_while(|&m| vertices(m).is_some()).count();
        let mut last = None;
        for at in skins.step_by(skin::LEN) {
            let mesh = reference(d, at + skin::MESH.start, meshes, Part::Skin)?;
            if last.is_some_and(|l| l >= mesh) {
                return Err(invalid(Part::Skin, at));
            }
            last = Some(mesh);
            let (bones, first) = (u16_at(d, at + skin::BONE_COUNT.start), u16_at(d, at + skin::FIRST_SLOT.start));
            if bones == 0 || first as usize + bones as usize > self.palette_count() {
                return Err(invalid(Part::Skin, at + skin::BONE_COUNT.start));
            }
            let bones_at = at + skin::BONES.start;
            let table = records(d, u32_at(d, bones_at), (bones as usize, skin::BONE_LEN), Part::Skin, bones_at)?;
            for b in table.step_by(skin::BONE_LEN) {
                reference(d, b + skin::BONE_NODE.start, self.node_count(), Part::Skin)?;
                finite(d, b + skin::BONE_INVERSE_BIND.start..b + skin::BONE_LEN, Part::Skin)?;
            }
            let nv = vertices(mesh).unwrap_or(0) as usize;
            let vertices_at = at + skin::VERTICES.start;
            let list = records(d, u32_at(d, vertices_at), (nv, skin::VERTEX_LEN), Part::Skin, vertices_at)?;
            for v in list.step_by(skin::VERTEX_LEN) {
                if (0..4).any(|k| u16::from(u8_at(d, v + k)) >= bones) {
                    return Err(invalid(Part::Skin, v));
                }
            }
        }
        Ok(())
    }

    fn validate_tracks(&self) -> Result<(), ParseError> {
        let tracks = self.table(animation::TRACKS, animation::TRACK_COUNT, track::LEN, Part::Track)?;
        // Each track's keys after the previous track's: their checks (and every later pass
        // over them) take at most one pass over the file, whatever the counts claim.
        let mut end = 0;
        for at in tracks.step_by(track::LEN) {
            let keys = self.validate_track(at)?;
            if keys.start < end {
                return Err(invalid(Part::Track, at + track::KEYS.start));
            }
            end = keys.end;
        }
        Ok(())
    }

    /// Checks the track at `at`; the range of its keys.
    fn validate_track(&self, at: usize) -> Result<Range<usize>, ParseError> {
        let (d, t) = (self.data, Track { data: self.data, at });
        let (first, count) = (u8_at(d, at + track::FIRST) as usize, t.component_count());
        let (targets, fits) = match u8_at(d, at + track::KIND) {
            track::KIND_POSITION | track::KIND_ROTATION | track::KIND_SCALING => {
                (self.node_count(), count >= 1 && first + count <= 3)
            }
            track::KIND_QUATERNION => (self.node_count(), first == 0 && count == 4),
            track::KIND_INFLUENCE => (self.weight_count(), first == 0 && count == 1),
            _ => return Err(invalid(Part::Track, at + track::KIND)),
        };
        let flags = u8_at(d, at + track::FLAGS);
        if !fits || flags & track::LOOP_MASK == 3 || flags > (track::LOOP_MASK | track::FLAG_TANGENTS) {
            return Err(invalid(Part::Track, at + track::FIRST));
        }
        reference(d, at + track::TARGET.start, targets, Part::Track)?;
        let fps = f32_at(d, at + track::FPS.start);
        if !(fps.is_finite() && fps > 0.0) || t.key_count() == 0 {
            return Err(invalid(Part::Track, at + track::KEY_COUNT.start));
        }
        let keys_at = at + track::KEYS.start;
        let keys = records(d, u32_at(d, keys_at), (t.key_count(), t.key_len()), Part::Track, keys_at)?;
        finite(d, keys.clone(), Part::Track)?;
        let mut last = f32::NEG_INFINITY;
        for k in keys.clone().step_by(t.key_len()) {
            let frame = f32_at(d, k + key::FRAME.start);
            if frame < last || u32_at(d, k + key::FLAGS.start) > key::FLAG_STEP {
                return Err(invalid(Part::Track, k));
            }
            last = frame;
        }
        Ok(keys)
    }

    fn validate_groups(&self) -> Result<(), ParseError> {
        let d = self.data;
        let groups = self.table(animation::GROUPS, animation::GROUP_COUNT, group::LEN, Part::Group)?;
        // Track lists and names each after the previous group's (see `validate_tracks`).
        let (mut list_end, mut name_end) = (0, 0);
        for at in groups.step_by(group::LEN) {
            finite(d, at..at + group::TO.end, Part::Group)?;
            if f32_at(d, at + group::TO.start) < f32_at(d, at + group::FROM.start) || u8_at(d, at + group::FLAGS) > 1 {
                return Err(invalid(Part::Group, at));
            }
            let n = u16_at(d, at + group::TRACK_COUNT.start) as usize;
            let list_at = at + group::TRACKS.start;
            let list = records(d, u32_at(d, list_at), (n, 2), Part::Group, list_at)?;
            if list.start < list_end {
                return Err(invalid(Part::Group, list_at));
            }
            list_end = list.end;
            for k in list.step_by(2) {
                reference(d, k, self.track_count(), Part::Group)?;
            }
            let name_at = at + group::NAME.start;
            let len = u16_at(d, at + group::NAME_LEN.start) as usize;
            let name = records(d, u32_at(d, name_at), (len, 1), Part::Group, name_at)?;
            if name.start < name_end || d.get(name.clone()).is_none_or(|b| core::str::from_utf8(b).is_err()) {
                return Err(invalid(Part::Group, name_at));
            }
            name_end = name.end;
        }
        Ok(())
    }

    /// Number of animated nodes.
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.count(animation::NODE_COUNT)
    }

    /// Number of morph weights (every morphed mesh's targets).
    #[must_use]
    pub fn weight_count(&self) -> usize {
        self.count(animation::WEIGHT_COUNT)
    }

    /// Number of tracks.
    #[must_use]
    pub fn track_count(&self) -> usize {
        self.count(animation::TRACK_COUNT)
    }

    /// Number of groups.
    #[must_use]
    pub fn group_count(&self) -> usize {
        self.count(animation::GROUP_COUNT)
    }

    /// Number of morphed meshes.
    #[must_use]
    pub fn morph_count(&self) -> usize {
        self.count(animation::MORPH_COUNT)
    }

    /// Number of skinned meshes.
    #[must_use]
    pub fn skin_count(&self) -> usize {
        self.count(animation::SKIN_COUNT)
    }

    /// Number of bone matrices in a pose's palette (every skin's bones).
    #[must_use]
    pub fn palette_count(&self) -> usize {
        self.count(animation::PALETTE_COUNT)
    }

    /// Skinned mesh `i` of [`Animation::skin_count`].
    #[must_use]
    pub fn skin_at(&self, i: usize) -> Option<Skin<'a>> {
        let at = self.record(animation::SKINS, animation::SKIN_COUNT, skin::LEN, i)?;
        Some(Skin { data: self.data, at })
    }

    /// The skin of mesh `mesh`, if it has one.
    #[must_use]
    pub fn skin_of(&self, mesh: usize) -> Option<Skin<'a>> {
        (0..self.skin_count()).filter_map(|i| self.skin_at(i)).find(|s| s.mesh() == mesh)
    }

    /// Number of meshes linked to animated nodes.
    #[must_use]
    pub fn link_count(&self) -> usize {
        self.count(animation::LINK_COUNT)
    }

    fn record(&self, table: Range<usize>, count: Range<usize>, len: usize, i: usize) -> Option<usize> {
        (i < self.count(count)).then(|| u32_at(self.data, self.at + table.start) as usize + i * len)
    }

    /// Node `i`.
    #[must_use]
    pub fn node(&self, i: usize) -> Option<Node<'a>> {
        let at = self.record(animation::NODES, animation::NODE_COUNT, node::LEN, i)?;
        Some(Node { data: self.data, at })
    }

    /// Track `i`.
    #[must_use]
    pub fn track(&self, i: usize) -> Option<Track<'a>> {
        let at = self.record(animation::TRACKS, animation::TRACK_COUNT, track::LEN, i)?;
        Some(Track { data: self.data, at })
    }

    /// Group `i`.
    #[must_use]
    pub fn group(&self, i: usize) -> Option<Group<'a>> {
        let at = self.record(animation::GROUPS, animation::GROUP_COUNT, group::LEN, i)?;
        Some(Group { data: self.data, at })
    }

    /// The group named `name`.
    #[must_use]
    pub fn group_named(&self, name: &str) -> Option<usize> {
        (0..self.group_count()).find(|&g| self.group(g).is_some_and(|g| g.name() == name))
    }

    /// Morphed mesh `i` of [`Animation::morph_count`].
    #[must_use]
    pub fn morph_at(&self, i: usize) -> Option<Morph<'a>> {
        let at = self.record(animation::MORPHS, animation::MORPH_COUNT, morph::LEN, i)?;
        Some(Morph { data: self.data, at })
    }

    /// The morph targets of mesh `mesh`, if it has some.
    #[must_use]
    pub fn morph_of(&self, mesh: usize) -> Option<Morph<'a>> {
        (0..self.morph_count()).filter_map(|i| self.morph_at(i)).find(|m| m.mesh() == mesh)
    }

    /// The node mesh `mesh` follows and the `below` matrix between them, if it follows one.
    #[must_use]
    pub fn link_of(&self, mesh: usize) -> Option<(usize, Mat4)> {
        (0..self.link_count()).find_map(|i| {
            let at = self.record(animation::LINKS, animation::LINK_COUNT, link::LEN, i)?;
            (u16_at(self.data, at + link::MESH.start) as usize == mesh).then(|| {
                (u16_at(self.data, at + link::NODE.start) as usize, affine_at(self.data, at + link::BELOW.start))
            })
        })
    }
}

impl Node<'_> {
    /// The nearest animated ancestor (a lower index).
    #[must_use]
    pub fn parent(&self) -> Option<usize> {
        let p = u16_at(self.data, self.at + node::PARENT.start);
        (p != NONE).then_some(p as usize)
    }

    /// The still nodes between it and its parent (a glam matrix: column-vector convention).
    #[must_use]
    pub fn above(&self) -> Mat4 {
        affine_at(self.data, self.at + node::ABOVE.start)
    }

    /// Position at rest.
    #[must_use]
    pub fn position(&self) -> Vec3 {
        vec3_at(self.data, self.at + node::POSITION.start)
    }

    /// Rotation at rest: Euler angles (x, y, z, 0) or a quaternion (x, y, z, w).
    #[must_use]
    pub fn rotation(&self) -> (Vec4, bool) {
        let at = self.at + node::ROTATION.start;
        let v = vec3_at(self.data, at).extend(f32_at(self.data, at + 12));
        (v, u16_at(self.data, self.at + node::FLAGS.start) & node::FLAG_QUATERNION != 0)
    }

    /// Scaling at rest.
    #[must_use]
    pub fn scaling(&self) -> Vec3 {
        vec3_at(self.data, self.at + node::SCALING.start)
    }
}

impl Track<'_> {
    /// What it moves.
    #[must_use]
    pub fn target(&self) -> TrackTarget {
        let t = u16_at(self.data, self.at + track::TARGET.start);
        match u8_at(self.data, self.at + track::KIND) {
            track::KIND_POSITION => TrackTarget::Position(t),
            track::KIND_ROTATION => TrackTarget::Rotation(t),
            track::KIND_SCALING => TrackTarget::Scaling(t),
            track::KIND_QUATERNION => TrackTarget::Quaternion(t),
            _ => TrackTarget::Influence(t),
        }
    }

    /// The first component it sets.
    #[must_use]
    pub fn first_component(&self) -> usize {
        u8_at(self.data, self.at + track::FIRST) as usize
    }

    /// How many components a key holds (1 to 4).
    #[must_use]
    pub fn component_count(&self) -> usize {
        u8_at(self.data, self.at + track::COUNT) as usize
    }

    /// Babylon.js's loop behaviour: 0 relative, 1 cycle, 2 constant.
    #[must_use]
    pub fn loop_mode(&self) -> u8 {
        u8_at(self.data, self.at + track::FLAGS) & track::LOOP_MASK
    }

    /// Whether keys carry Hermite tangents.
    #[must_use]
    pub fn has_tangents(&self) -> bool {
        u8_at(self.data, self.at + track::FLAGS) & track::FLAG_TANGENTS != 0
    }

    /// Frames a second.
    #[must_use]
    pub fn fps(&self) -> f32 {
        f32_at(self.data, self.at + track::FPS.start)
    }

    /// Number of keys (>= 1).
    #[must_use]
    pub fn key_count(&self) -> usize {
        u32_at(self.data, self.at + track::KEY_COUNT.start) as usize
    }

    fn key_len(&self) -> usize {
        key::VALUES + 4 * self.component_count() * if self.has_tangents() { 3 } else { 1 }
    }

    /// Where key `k` lies (past the data for a key beyond the last: it reads as zeros).
    fn key_at(&self, k: usize) -> usize {
        if k >= self.key_count() {
            return usize::MAX;
        }
        u32_at(self.data, self.at + track::KEYS.start) as usize + k * self.key_len()
    }

    /// Key `k`'s frame.
    #[must_use]
    pub fn frame(&self, k: usize) -> f32 {
        f32_at(self.data, self.key_at(k).saturating_add(key::FRAME.start))
    }

    /// Whether key `k` holds its value until the next key.
    #[must_use]
    pub fn is_step(&self, k: usize) -> bool {
        u32_at(self.data, self.key_at(k).saturating_add(key::FLAGS.start)) & key::FLAG_STEP != 0
    }

    /// Key `k`'s value (`set` 0), in tangent (1) or out tangent (2), components beyond
    /// [`Track::component_count`] zero.
    #[must_use]
    pub fn value(&self, k: usize, set: usize) -> Vec4 {
        let n = self.component_count();
        let at = self.key_at(k).saturating_add(key::VALUES + 4 * n * set.min(2));
        Vec4::from_array(core::array::from_fn(
            |c| if c < n { f32_at(self.data, at.saturating_add(4 * c)) } else { 0.0 },
        ))
    }
}

impl<'a> Group<'a> {
    /// Its name.
    #[must_use]
    pub fn name(&self) -> &'a str {
        let start = u32_at(self.data, self.at + group::NAME.start) as usize;
        let len = u16_at(self.data, self.at + group::NAME_LEN.start) as usize;
        self.data.get(start..start + len).and_then(|b| core::str::from_utf8(b).ok()).unwrap_or("")
    }

    /// First and last frame.
    #[must_use]
    pub fn range(&self) -> (f32, f32) {
        (f32_at(self.data, self.at + group::FROM.start), f32_at(self.data, self.at + group::TO.start))
    }

    /// Whether it plays again from the first frame after the last.
    #[must_use]
    pub fn loops(&self) -> bool {
        u8_at(self.data, self.at + group::FLAGS) & group::FLAG_LOOP != 0
    }

    /// Its tracks (indices for [`Animation::track`]).
    pub fn tracks(&self) -> impl Iterator<Item = usize> + 'a {
        let (d, start) = (self.data, u32_at(self.data, self.at + group::TRACKS.start) as usize);
        let n = u16_at(d, self.at + group::TRACK_COUNT.start) as usize;
        (0..n).map(move |k| u16_at(d, start + 2 * k) as usize)
    }
}

impl<'a> Morph<'a> {
    /// The mesh it morphs.
    #[must_use]
    pub fn mesh(&self) -> usize {
        u16_at(self.data, self.at + morph::MESH.start) as usize
    }

    /// Number of targets (>= 1).
    #[must_use]
    pub fn target_count(&self) -> u16 {
        u16_at(self.data, self.at + morph::TARGET_COUNT.start)
    }

    /// Its targets' weights in a pose: `first..first + target_count`.
    #[must_use]
    pub fn weights(&self) -> Range<usize> {
        let first = u16_at(self.data, self.at + morph::FIRST_WEIGHT.start) as usize;
        first..first + self.target_count() as usize
    }

    /// Whether its targets move normals too.
    #[must_use]
    pub fn has_normals(&self) -> bool {
        u16_at(self.data, self.at + morph::FLAGS.start) & morph::FLAG_NORMALS != 0
    }

    /// Where target `t`'s record lies (past the data beyond the last target: zeros).
    fn target_at(&self, t: usize) -> usize {
        if t >= self.target_count() as usize {
            return usize::MAX;
        }
        u32_at(self.data, self.at + morph::TARGETS.start) as usize + t * morph_target::LEN
    }

    /// Target `t`'s influence at rest.
    #[must_use]
    pub fn default_influence(&self, t: usize) -> f32 {
        f32_at(self.data, self.target_at(t).saturating_add(morph_target::INFLUENCE.start))
    }

    /// Target `t`'s delta of vertex `i`: position (stored units) or normal (`normal`), zero
    /// out of range.
    #[must_use]
    pub fn delta(&self, t: usize, i: u32, normal: bool) -> Vec3 {
        if normal && !self.has_normals() {
            return Vec3::ZERO;
        }
        let at = self.target_at(t);
        let (scale, table) = if normal {
            (morph_target::NORMAL_SCALE, morph_target::NORMALS)
        } else {
            (morph_target::POSITION_SCALE, morph_target::POSITIONS)
        };
        if at == usize::MAX {
            return Vec3::ZERO;
        }
        // Saturating: past the deltas (an index beyond the vertices) reads zeros.
        let d = (u32_at(self.data, at + table.start) as usize)
            .saturating_add((i as usize).saturating_mul(morph_target::DELTA_LEN));
        let c = |k: usize| i16_at(self.data, d.saturating_add(k)) as f32;
        Vec3::new(c(0), c(2), c(4)) * f32_at(self.data, at + scale.start)
    }
}

impl Skin<'_> {
    /// The mesh it skins.
    #[must_use]
    pub fn mesh(&self) -> usize {
        u16_at(self.data, self.at + skin::MESH.start) as usize
    }

    /// Number of bones (>= 1).
    #[must_use]
    pub fn bone_count(&self) -> usize {
        u16_at(self.data, self.at + skin::BONE_COUNT.start) as usize
    }

    /// Its bones' matrices in a pose's palette: `first..first + bone_count`.
    #[must_use]
    pub fn palette(&self) -> Range<usize> {
        let first = u16_at(self.data, self.at + skin::FIRST_SLOT.start) as usize;
        first..first + self.bone_count()
    }

    fn bone_at(&self, b: usize) -> Option<usize> {
        (b < self.bone_count()).then(|| u32_at(self.data, self.at + skin::BONES.start) as usize + b * skin::BONE_LEN)
    }

    /// Bone `b`'s node (an index for [`Animation::node`]), `None` past the last bone.
    #[must_use]
    pub fn bone_node(&self, b: usize) -> Option<usize> {
        self.bone_at(b).map(|at| u16_at(self.data, at + skin::BONE_NODE.start) as usize)
    }

    /// Bone `b`'s inverse bind matrix (identity past the last bone).
    #[must_use]
    pub fn inverse_bind(&self, b: usize) -> Mat4 {
        self.bone_at(b).map_or(Mat4::IDENTITY, |at| affine_at(self.data, at + skin::BONE_INVERSE_BIND.start))
    }

    /// Vertex `i`'s four bones and weights (zero weights past the last vertex).
    #[must_use]
    pub fn influences(&self, i: u32) -> ([u8; 4], [f32; 4]) {
        let at = (u32_at(self.data, self.at + skin::VERTICES.start) as usize)
            .saturating_add((i as usize).saturating_mul(skin::VERTEX_LEN));
        let bones = core::array::from_fn(|k| u8_at(self.data, at.saturating_add(k)));
        let weights = core::array::from_fn(|k| f32::from(u16_at(self.data, at.saturating_add(4 + 2 * k))) / 65535.0);
        (bones, weights)
    }
}
