//! The animation section's validation, once, from `Model::parse`: every count, offset,
//! reference and float of its records, and their order (links, morphs and skins by increasing
//! mesh, animated lights by increasing light; keys, group lists and names each after the
//! previous), so that no accessor of `Animation` can read outside the file and no pass over it
//! takes longer than one over the file.

use core::ops::Range;

use super::super::error::{ParseError, Part};
use super::super::layout::*;
use super::{Aim, AnimatedCamera, AnimatedLight, Animation, Morph, Track};

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

/// The mesh references that open link, morph and skin records (a u16 at the record's start),
/// checked in increasing order: at most one record a mesh, in one pass.
struct MeshOrder {
    meshes: usize,
    last: Option<usize>,
}

impl MeshOrder {
    fn new(vertices: &impl Fn(usize) -> Option<u32>) -> Self {
        MeshOrder { meshes: (0..).take_while(|&m| vertices(m).is_some()).count(), last: None }
    }

    /// The mesh the record at `at` names, checked (in range, after the previous one's).
    fn next(&mut self, data: &[u8], at: usize, part: Part) -> Result<usize, ParseError> {
        let mesh = reference(data, at, self.meshes, part)?;
        if self.last.is_some_and(|l| l >= mesh) {
            return Err(invalid(part, at));
        }
        self.last = Some(mesh);
        Ok(mesh)
    }
}

impl<'a> Animation<'a> {
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

    /// Checks the section at `at` of `data`, for a model whose meshes have `vertices(m)`
    /// vertices (`None` past the last mesh), with `lights` lights and a camera record or not
    /// (`camera`). The header's flags are checked already (`Model::parse`).
    pub(in crate::format) fn validate(
        data: &'a [u8],
        at: u32,
        vertices: impl Fn(usize) -> Option<u32>,
        (lights, camera): (usize, bool),
    ) -> Result<Self, ParseError> {
        let len = if (Animation { data, at: 0 }).extended() { animation::LEN_EXTENDED } else { animation::LEN };
        let head = records(data, at, (1, len), Part::Animation, header::ANIMATION.start)?;
        let a = Animation { data, at: head.start };
        a.validate_nodes()?;
        a.validate_links(&vertices)?;
        a.validate_morphs(&vertices)?;
        a.validate_camera(camera)?;
        a.validate_lights(lights)?;
        a.validate_tracks()?;
        a.validate_groups()?;
        a.validate_skins(&vertices)?;
        Ok(a)
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
        let mut order = MeshOrder::new(vertices);
        for at in links.step_by(link::LEN) {
            order.next(d, at, Part::Link)?;
            reference(d, at + link::NODE.start, self.node_count(), Part::Link)?;
            finite(d, at + link::BELOW.start..at + link::LEN, Part::Link)?;
        }
        Ok(())
    }

    fn validate_morphs(&self, vertices: &impl Fn(usize) -> Option<u32>) -> Result<(), ParseError> {
        let d = self.data;
        let morphs = self.table(animation::MORPHS, animation::MORPH_COUNT, morph::LEN, Part::Morph)?;
        let mut order = MeshOrder::new(vertices);
        for at in morphs.step_by(morph::LEN) {
            let mesh = order.next(d, at, Part::Morph)?;
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
        let mut order = MeshOrder::new(vertices);
        for at in skins.step_by(skin::LEN) {
            let mesh = order.next(d, at, Part::Skin)?;
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

    /// Checks that `slots` lie inside the weight count (`at`: the record's first-slot field).
    fn slots_fit(&self, slots: Range<usize>, at: usize, part: Part) -> Result<(), ParseError> {
        if slots.end > self.weight_count() {
            return Err(invalid(part, at));
        }
        Ok(())
    }

    /// The animated camera record, for a model with a camera record (`camera`) or not.
    fn validate_camera(&self, camera: bool) -> Result<(), ParseError> {
        let (d, field) = (self.data, self.at + animation::CAMERA.start);
        let at = self.extended_u32(animation::CAMERA);
        if at == 0 {
            return Ok(());
        }
        if !camera {
            return Err(invalid(Part::AnimatedCamera, field));
        }
        records(d, at as u32, (1, animated_camera::LEN), Part::AnimatedCamera, field)?;
        finite(d, at + animated_camera::POSITION.start..at + animated_camera::LEN, Part::AnimatedCamera)?;
        let c = AnimatedCamera { data: d, at };
        let aim = u16_at(d, at + animated_camera::AIM.start);
        let fov_ok = c.fov() > 0.0 && c.fov() < core::f32::consts::PI;
        if Aim::from_code(aim).is_none() || !fov_ok || c.distance() < 0.0 {
            return Err(invalid(Part::AnimatedCamera, at));
        }
        self.slots_fit(c.slots(), at + animated_camera::FIRST_SLOT.start, Part::AnimatedCamera)
    }

    /// The animated light records, for a model with `lights` lights.
    fn validate_lights(&self, lights: usize) -> Result<(), ParseError> {
        if !self.extended() {
            return Ok(());
        }
        let d = self.data;
        let table = self.table(animation::LIGHTS, animation::LIGHT_COUNT, animated_light::LEN, Part::AnimatedLight)?;
        let mut last = None;
        for at in table.step_by(animated_light::LEN) {
            let light = reference(d, at + animated_light::LIGHT.start, lights, Part::AnimatedLight)?;
            if last.is_some_and(|l| l >= light) {
                return Err(invalid(Part::AnimatedLight, at));
            }
            last = Some(light);
            finite(d, at + animated_light::VECTOR.start..at + animated_light::LEN, Part::AnimatedLight)?;
            let l = AnimatedLight { data: d, at };
            self.slots_fit(l.slots(), at + animated_light::FIRST_SLOT.start, Part::AnimatedLight)?;
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
        let kind = u8_at(d, at + track::KIND);
        let (targets, fits) = self.track_kind(kind, (first, count)).ok_or(invalid(Part::Track, at + track::KIND))?;
        let flags = u8_at(d, at + track::FLAGS);
        if !fits || flags & track::LOOP_MASK == 3 || flags > (track::LOOP_MASK | track::FLAG_TANGENTS) {
            return Err(invalid(Part::Track, at + track::FIRST));
        }
        let target = reference(d, at + track::TARGET.start, targets, Part::Track)?;
        let light = matches!(kind, track::KIND_LIGHT_VECTOR | track::KIND_LIGHT_DIFFUSE | track::KIND_LIGHT_INTENSITY);
        if light && self.animated_light_of(target).is_none() {
            return Err(invalid(Part::Track, at + track::TARGET.start));
        }
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
            if frame < last || u32_at(d, k + key::FLAGS.start) & !key::FLAGS_ALL != 0 {
                return Err(invalid(Part::Track, k));
            }
            last = frame;
        }
        Ok(keys)
    }

    /// For a track of `kind` setting components `first..first + count`: how many targets it
    /// may name (a light kind names a light, which must have an animated light record) and
    /// whether the components fit; `None` for an unknown kind.
    fn track_kind(&self, kind: u8, (first, count): (usize, usize)) -> Option<(usize, bool)> {
        let vector = count >= 1 && first + count <= 3;
        let scalar = first == 0 && count == 1;
        let camera = usize::from(self.camera().is_some());
        Some(match kind {
            track::KIND_POSITION | track::KIND_ROTATION | track::KIND_SCALING => (self.node_count(), vector),
            track::KIND_QUATERNION => (self.node_count(), first == 0 && count == 4),
            track::KIND_INFLUENCE => (self.weight_count(), scalar),
            track::KIND_CAMERA_POSITION | track::KIND_CAMERA_TARGET | track::KIND_CAMERA_ROTATION => (camera, vector),
            track::KIND_CAMERA_FOV => (camera, scalar),
            track::KIND_LIGHT_VECTOR | track::KIND_LIGHT_DIFFUSE => (NONE as usize, vector),
            track::KIND_LIGHT_INTENSITY => (NONE as usize, scalar),
            _ => return None,
        })
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
}
