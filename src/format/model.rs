//! [`Model`]: a validated `.s3d` file borrowed in place, its validation (done once, in
//! [`Model::parse`]) and its per-file records (materials, textures, instances, lights, camera).
//! Meshes are [`super::mesh`]'s; the byte offsets are `layout`'s. It never writes a file.

use core::ops::Range;

use super::animation::Animation;
use super::error::{ParseError, Part};
use super::layout::*;
use super::mesh::Mesh;
use super::texel::{Texture, TextureFormat};
use crate::fog::{Fog, FogMode};
use crate::math::{Mat4, Vec3};

/// Where a draw's world matrix lies in a model's bytes (validated finite by `parse`): see
/// [`Model::placed_draws`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct WorldAt(pub(super) usize);

// ---------------------------------------------------------------------------------------------
// Validation helpers used by `parse`.

/// Checks that `len` bytes at `start` lie in a file of `file_len` bytes and returns the range.
fn section(start: u32, len: usize, file_len: usize, part: Part, at: usize) -> Result<Range<usize>, ParseError> {
    let start = start as usize;
    match start.checked_add(len) {
        Some(end) if end <= file_len => Ok(start..end),
        _ => Err(ParseError::OutOfBounds { part, offset: at }),
    }
}

/// The range of `count` records of `record_len` bytes from `start` (see [`section`]), the product
/// checked: on a 32-bit target a count from the file times a record's length can pass
/// `usize::MAX`, and a wrapped length would validate a section the data does not hold.
fn records(
    start: u32,
    (count, record_len): (usize, usize),
    file_len: usize,
    part: Part,
    at: usize,
) -> Result<Range<usize>, ParseError> {
    let len = count.checked_mul(record_len).ok_or(ParseError::OutOfBounds { part, offset: at })?;
    section(start, len, file_len, part, at)
}

/// Checks that every f32 in `range` is finite.
fn check_finite(data: &[u8], range: Range<usize>, part: Part) -> Result<(), ParseError> {
    for at in range.step_by(4) {
        if !f32_at(data, at).is_finite() {
            return Err(ParseError::NotFinite { part, offset: at });
        }
    }
    Ok(())
}

fn check_ref(data: &[u8], at: usize, count: u16, part: Part, allow_none: bool) -> Result<(), ParseError> {
    let index = u16_at(data, at);
    if index < count || (allow_none && index == NONE) {
        Ok(())
    } else {
        Err(ParseError::BadReference { part, offset: at, index, count })
    }
}

fn invalid(part: Part, offset: usize) -> ParseError {
    ParseError::Invalid { part, offset }
}

/// A validated `.s3d` file, borrowed in place. Every accessor is infallible: [`Model::parse`]
/// checked every offset, count, index and float once.
#[derive(Clone, Copy, Debug)]
pub struct Model<'a> {
    data: &'a [u8],
}

impl<'a> Model<'a> {
    /// Validates `data` as an `.s3d` file.
    ///
    /// # Errors
    /// A [`ParseError`] naming the first problem found and its byte offset.
    pub fn parse(data: &'a [u8]) -> Result<Self, ParseError> {
        if data.len() < header::LEN {
            return Err(ParseError::Truncated { expected: header::LEN, actual: data.len() });
        }
        if data[header::MAGIC] != MAGIC {
            return Err(ParseError::BadMagic);
        }
        let version = u16_at(data, header::VERSION.start);
        if !(MIN_VERSION..=VERSION).contains(&version) {
            return Err(ParseError::UnsupportedVersion(version));
        }
        let header_len = match version {
            1 => header::LEN,
            2 => header::LEN_V2,
            _ => header::LEN_V3,
        };
        if data.len() < header_len {
            return Err(ParseError::Truncated { expected: header_len, actual: data.len() });
        }
        let file_len = u32_at(data, header::FILE_LEN.start) as usize;
        if file_len != data.len() {
            return Err(ParseError::Truncated { expected: file_len, actual: data.len() });
        }
        let model = Model { data };
        model.validate()?;
        Ok(model)
    }

    /// The animation section's offset (version 2 and not 0).
    fn animation_at(&self) -> Option<u32> {
        let v2 = u16_at(self.data, header::VERSION.start) >= 2;
        Some(u32_at(self.data, header::ANIMATION.start)).filter(|&at| v2 && at != 0)
    }

    /// The fog record's offset (version 3 and not 0).
    fn fog_at(&self) -> Option<usize> {
        let v3 = u16_at(self.data, header::VERSION.start) >= 3;
        Some(u32_at(self.data, header::FOG.start) as usize).filter(|&at| v3 && at != 0)
    }

    /// The scene's fog, when it has some (for [`RenderOptions::fog`](crate::RenderOptions::fog)).
    #[must_use]
    pub fn fog(&self) -> Option<Fog> {
        let at = self.fog_at()?;
        let d = self.data;
        Some(Fog {
            // `parse` validated the mode.
            mode: FogMode::from_code(u8_at(d, at + fog::MODE))?,
            color: vec3_at(d, at + fog::COLOR.start),
            density: f32_at(d, at + fog::DENSITY.start),
            start: f32_at(d, at + fog::START.start),
            end: f32_at(d, at + fog::END.start),
        })
    }

    /// The model's animations (node tracks, morph targets), if it has some.
    #[must_use]
    pub fn animation(&self) -> Option<Animation<'a>> {
        // `parse` validated it.
        Some(Animation::validated(self.data, self.animation_at()?))
    }

    fn count(&self, field: Range<usize>) -> u16 {
        u16_at(self.data, field.start)
    }

    fn table(
        &self,
        field: Range<usize>,
        count: Range<usize>,
        record_len: usize,
        part: Part,
    ) -> Result<Range<usize>, ParseError> {
        let n = self.count(count) as usize;
        let start = u32_at(self.data, field.start);
        records(start, (n, record_len), self.data.len(), part, field.start)
    }

    fn validate(&self) -> Result<(), ParseError> {
        let d = self.data;
        let n_materials = self.count(header::MATERIAL_COUNT);
        let n_textures = self.count(header::TEXTURE_COUNT);
        let n_meshes = self.count(header::MESH_COUNT);

        let meshes = self.table(header::MESHES, header::MESH_COUNT, mesh::LEN, Part::Mesh)?;
        for at in meshes.step_by(mesh::LEN) {
            self.validate_mesh(at, n_materials)?;
        }
        let materials = self.table(header::MATERIALS, header::MATERIAL_COUNT, material::LEN, Part::Material)?;
        for at in materials.step_by(material::LEN) {
            check_ref(d, at + material::TEXTURE.start, n_textures, Part::Material, true)?;
            for wrap in [material::WRAP_U, material::WRAP_V] {
                if Wrap::from_u8(u8_at(d, at + wrap)).is_none() {
                    return Err(invalid(Part::Material, at + wrap));
                }
            }
        }
        let textures = self.table(header::TEXTURES, header::TEXTURE_COUNT, texture::LEN, Part::Texture)?;
        for at in textures.step_by(texture::LEN) {
            let format = TextureFormat::from_u8(u8_at(d, at + texture::FORMAT))
                .ok_or(invalid(Part::Texture, at + texture::FORMAT))?;
            let (w, h) = (u16_at(d, at + texture::WIDTH.start), u16_at(d, at + texture::HEIGHT.start));
            if w == 0 || h == 0 {
                return Err(invalid(Part::Texture, at));
            }
            // `w·h` below 2^32: fits usize on every target.
            let texels = (w as usize * h as usize, format.bytes_per_texel());
            records(u32_at(d, at + texture::DATA.start), texels, d.len(), Part::Texture, at + texture::DATA.start)?;
        }
        let instances = self.table(header::INSTANCES, header::INSTANCE_COUNT, instance::LEN, Part::Instance)?;
        for at in instances.step_by(instance::LEN) {
            check_ref(d, at + instance::MESH.start, n_meshes, Part::Instance, false)?;
            check_finite(d, at + instance::WORLD.start..at + instance::WORLD.end, Part::Instance)?;
        }
        let lights = self.table(header::LIGHTS, header::LIGHT_COUNT, light::LEN, Part::Light)?;
        for at in lights.step_by(light::LEN) {
            if LightKind::from_u8(u8_at(d, at + light::KIND)).is_none() {
                return Err(invalid(Part::Light, at + light::KIND));
            }
            check_finite(d, at + light::VECTOR.start..at + light::LEN, Part::Light)?;
        }
        self.validate_flags()?;
        if let Some(at) = self.animation_at() {
            let scene = (self.light_count(), u32_at(d, header::CAMERA.start) != 0);
            Animation::validate(d, at, |m| self.mesh(m).map(|mesh| mesh.vertex_count()), scene)?;
        }
        let camera_at = u32_at(d, header::CAMERA.start);
        if camera_at != 0 {
            let cam = section(camera_at, camera::LEN, d.len(), Part::Camera, header::CAMERA.start)?;
            check_finite(d, cam.clone(), Part::Camera)?;
            let c = cam.start;
            let (fov, near, far) =
                (f32_at(d, c + camera::FOV.start), f32_at(d, c + camera::NEAR.start), f32_at(d, c + camera::FAR.start));
            if !(fov > 0.0 && fov < core::f32::consts::PI && near > 0.0 && far > near) {
                return Err(invalid(Part::Camera, c + camera::FOV.start));
            }
        }
        self.validate_fog()
    }

    fn validate_fog(&self) -> Result<(), ParseError> {
        let d = self.data;
        if let Some(at) = self.fog_at() {
            let fog = section(at as u32, fog::LEN, d.len(), Part::Fog, header::FOG.start)?;
            check_finite(d, fog.start + fog::COLOR.start..fog.end, Part::Fog)?;
            if FogMode::from_code(u8_at(d, at + fog::MODE)).is_none() {
                return Err(invalid(Part::Fog, at + fog::MODE));
            }
            if f32_at(d, at + fog::DENSITY.start) < 0.0 {
                return Err(invalid(Part::Fog, at + fog::DENSITY.start));
            }
        }
        Ok(())
    }

    /// The header's flags (version 2 and later; version 1 keeps the field reserved): known bits only,
    /// and the extended animation section only where there is a section to extend.
    fn validate_flags(&self) -> Result<(), ParseError> {
        if u16_at(self.data, header::VERSION.start) < 2 {
            return Ok(());
        }
        let flags = u16_at(self.data, header::FLAGS.start);
        let extended = flags & header::FLAG_EXTENDED_ANIMATION != 0;
        if flags & !header::FLAG_EXTENDED_ANIMATION != 0 || (extended && self.animation_at().is_none()) {
            return Err(invalid(Part::Header, header::FLAGS.start));
        }
        Ok(())
    }

    fn validate_mesh(&self, at: usize, n_materials: u16) -> Result<(), ParseError> {
        let d = self.data;
        check_finite(d, at..at + mesh::BOUNDS.end, Part::Mesh)?;
        let nonneg = |r: Range<usize>| r.step_by(4).all(|o| f32_at(d, at + o) >= 0.0);
        if !nonneg(mesh::POS_SCALE) || !nonneg(mesh::UV_SCALE) || f32_at(d, at + mesh::BOUNDS.end - 4) < 0.0 {
            return Err(invalid(Part::Mesh, at + mesh::POS_SCALE.start));
        }
        let vertices = u32_at(d, at + mesh::VERTEX_COUNT.start);
        let indices = u32_at(d, at + mesh::INDEX_COUNT.start);
        let flags = u16_at(d, at + mesh::FLAGS.start);
        if vertices == 0 || !indices.is_multiple_of(3) || flags > 15 {
            return Err(invalid(Part::Mesh, at + mesh::VERTEX_COUNT.start));
        }
        let nv = vertices as usize;
        let field = |f: Range<usize>| (u32_at(d, at + f.start), at + f.start);
        let (o, r) = field(mesh::POSITIONS);
        if flags & mesh::FLAG_F32_POSITIONS != 0 {
            check_finite(d, records(o, (nv, 12), d.len(), Part::Positions, r)?, Part::Positions)?;
        } else {
            records(o, (nv, POSITION_LEN), d.len(), Part::Positions, r)?;
        }
        let (o, r) = field(mesh::NORMALS);
        records(o, (nv, NORMAL_LEN), d.len(), Part::Normals, r)?;
        if flags & mesh::FLAG_UVS != 0 {
            let (o, r) = field(mesh::UVS);
            records(o, (nv, UV_LEN), d.len(), Part::Uvs, r)?;
        }
        if flags & mesh::FLAG_COLORS != 0 {
            let (o, r) = field(mesh::COLORS);
            records(o, (nv, COLOR_LEN), d.len(), Part::Colors, r)?;
        }
        let (o, r) = field(mesh::NAME);
        let name = section(o, u16_at(d, at + mesh::NAME_LEN.start) as usize, d.len(), Part::Name, r)?;
        if core::str::from_utf8(&d[name]).is_err() {
            return Err(invalid(Part::Name, r));
        }
        let index_len = if flags & mesh::FLAG_U32_INDICES != 0 { 4 } else { 2 };
        let (o, r) = field(mesh::INDICES);
        let index_range = records(o, (indices as usize, index_len), d.len(), Part::Indices, r)?;
        for i_at in index_range.step_by(index_len) {
            let index = if index_len == 4 { u32_at(d, i_at) } else { u16_at(d, i_at) as u32 };
            if index >= vertices {
                return Err(ParseError::IndexOutOfRange { offset: i_at, index, vertex_count: vertices });
            }
        }
        let n_sub = u16_at(d, at + mesh::SUBMESH_COUNT.start) as usize;
        if n_sub == 0 {
            return Err(invalid(Part::Mesh, at + mesh::SUBMESH_COUNT.start));
        }
        let (o, r) = field(mesh::SUBMESHES);
        for s in section(o, n_sub * submesh::LEN, d.len(), Part::SubMesh, r)?.step_by(submesh::LEN) {
            check_ref(d, s + submesh::MATERIAL.start, n_materials, Part::SubMesh, true)?;
            let start = u32_at(d, s + submesh::INDEX_START.start);
            let count = u32_at(d, s + submesh::INDEX_COUNT.start);
            let in_range = start.checked_add(count).is_some_and(|end| end <= indices);
            if !in_range || !start.is_multiple_of(3) || !count.is_multiple_of(3) {
                return Err(invalid(Part::SubMesh, s + submesh::INDEX_START.start));
            }
        }
        Ok(())
    }

    /// The raw bytes of the file.
    #[must_use]
    pub fn bytes(&self) -> &'a [u8] {
        self.data
    }

    fn record(&self, table: Range<usize>, count: Range<usize>, len: usize, i: usize) -> Option<usize> {
        (i < self.count(count) as usize).then(|| u32_at(self.data, table.start) as usize + i * len)
    }

    /// Number of meshes.
    #[must_use]
    pub fn mesh_count(&self) -> usize {
        self.count(header::MESH_COUNT) as usize
    }

    /// Mesh `i`, or `None` if `i >= mesh_count()`.
    #[must_use]
    pub fn mesh(&self, i: usize) -> Option<Mesh<'a>> {
        let at = self.record(header::MESHES, header::MESH_COUNT, mesh::LEN, i)?;
        Some(Mesh { data: self.data, at })
    }

    /// All meshes.
    pub fn meshes(&self) -> impl Iterator<Item = Mesh<'a>> + 'a {
        let model = *self;
        (0..self.mesh_count()).filter_map(move |i| model.mesh(i))
    }

    /// Number of materials.
    #[must_use]
    pub fn material_count(&self) -> usize {
        self.count(header::MATERIAL_COUNT) as usize
    }

    /// Material `i`, or `None` if out of range (including [`NONE`]).
    #[must_use]
    pub fn material(&self, i: u16) -> Option<Material> {
        let at = self.record(header::MATERIALS, header::MATERIAL_COUNT, material::LEN, i as usize)?;
        let d = self.data;
        let texture = u16_at(d, at + material::TEXTURE.start);
        Some(Material {
            rgba: bytes_at(d, at + material::RGBA.start),
            cull_back_faces: u8_at(d, at + material::FLAGS) & material::FLAG_CULL_BACK != 0,
            wrap_u: Wrap::from_u8(u8_at(d, at + material::WRAP_U)).unwrap_or_default(),
            wrap_v: Wrap::from_u8(u8_at(d, at + material::WRAP_V)).unwrap_or_default(),
            texture: (texture != NONE).then_some(texture),
        })
    }

    /// Number of textures.
    #[must_use]
    pub fn texture_count(&self) -> usize {
        self.count(header::TEXTURE_COUNT) as usize
    }

    /// Texture `i`, or `None` if out of range.
    #[must_use]
    pub fn texture(&self, i: u16) -> Option<Texture<'a>> {
        let at = self.record(header::TEXTURES, header::TEXTURE_COUNT, texture::LEN, i as usize)?;
        let d = self.data;
        let width = u16_at(d, at + texture::WIDTH.start);
        let height = u16_at(d, at + texture::HEIGHT.start);
        let format = TextureFormat::from_u8(u8_at(d, at + texture::FORMAT))?;
        let start = u32_at(d, at + texture::DATA.start) as usize;
        let len = width as usize * height as usize * format.bytes_per_texel();
        Some(Texture { width, height, format, texels: d.get(start..start + len)? })
    }

    /// Number of instances.
    #[must_use]
    pub fn instance_count(&self) -> usize {
        self.count(header::INSTANCE_COUNT) as usize
    }

    /// Instance `i`: `(mesh index, world matrix)`.
    #[must_use]
    pub fn instance(&self, i: usize) -> Option<(usize, Mat4)> {
        self.placed_instance(i).map(|(mesh, world)| (mesh, self.world(world)))
    }

    /// [`Model::instance`] with where its world matrix lies instead of the matrix.
    fn placed_instance(&self, i: usize) -> Option<(usize, WorldAt)> {
        let at = self.record(header::INSTANCES, header::INSTANCE_COUNT, instance::LEN, i)?;
        Some((u16_at(self.data, at) as usize, WorldAt(at + instance::WORLD.start)))
    }

    /// Triangles and vertices of everything [`Model::draws`] yields (instances counted again):
    /// the entries a [`Scratch`](crate::Scratch) needs.
    #[must_use]
    pub fn draw_counts(&self) -> (usize, usize) {
        // Saturating: instances can pass `usize::MAX` on a 32-bit target (no scratch holds that).
        self.draws().fold((0usize, 0usize), |(t, v), (m, _)| {
            (t.saturating_add(m.triangle_count() as usize), v.saturating_add(m.vertex_count() as usize))
        })
    }

    /// Everything to draw: each mesh with its own world matrix, then each instance.
    pub fn draws(&self) -> impl Iterator<Item = (Mesh<'a>, Mat4)> + 'a {
        let model = *self;
        self.placed_draws().map(move |(m, world)| (m, model.world(world)))
    }

    /// [`Model::draws`] with where each world matrix lies instead of the matrix: a draw reads it
    /// when it needs it ([`Model::world`]) and holds no copy while it draws (stack).
    pub(crate) fn placed_draws(&self) -> impl Iterator<Item = (Mesh<'a>, WorldAt)> + 'a {
        let model = *self;
        (0..self.draw_count()).filter_map(move |d| model.placed_draw(d))
    }

    /// How many draws [`Model::draws`] yields: the meshes, then the instances (every one:
    /// `parse` checked their references).
    pub(crate) fn draw_count(&self) -> usize {
        self.mesh_count().saturating_add(self.instance_count())
    }

    /// Draw `d` of [`Model::placed_draws`] (`None` past the last): a loop over draws by index
    /// keeps no iterator's state in the draw's frame (stack).
    pub(crate) fn placed_draw(&self, d: usize) -> Option<(Mesh<'a>, WorldAt)> {
        match d.checked_sub(self.mesh_count()) {
            None => self.mesh(d).map(|m| (m, m.world_at())),
            Some(i) => {
                let (mesh, world) = self.placed_instance(i)?;
                Some((self.mesh(mesh)?, world))
            }
        }
    }

    /// The world matrix at `world` (from [`Model::placed_draws`]).
    #[must_use]
    pub(crate) fn world(&self, world: WorldAt) -> Mat4 {
        affine_at(self.data, world.0)
    }

    /// World-space sphere `(centre, radius)` around every draw's bounding sphere, or `None`
    /// when the model has nothing finite to draw.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, f32)> {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (mesh, world) in self.draws() {
            let (c, r) = mesh.bounding_sphere();
            let r = Vec3::splat(r * crate::math::max_axis_scale(&world));
            let c = world.transform_point3(c);
            lo = lo.min(c - r);
            hi = hi.max(c + r);
        }
        (lo.is_finite() && hi.is_finite()).then(|| ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-3)))
    }

    /// Number of lights.
    #[must_use]
    pub fn light_count(&self) -> usize {
        self.count(header::LIGHT_COUNT) as usize
    }

    /// Light `i`, or `None` if out of range.
    #[must_use]
    pub fn light(&self, i: usize) -> Option<Light> {
        let at = self.record(header::LIGHTS, header::LIGHT_COUNT, light::LEN, i)?;
        let d = self.data;
        Some(Light {
            kind: LightKind::from_u8(u8_at(d, at + light::KIND))?,
            vector: vec3_at(d, at + light::VECTOR.start),
            diffuse: vec3_at(d, at + light::DIFFUSE.start),
            intensity: f32_at(d, at + light::INTENSITY.start),
        })
    }

    /// All lights.
    pub fn lights(&self) -> impl Iterator<Item = Light> + 'a {
        let model = *self;
        (0..self.light_count()).filter_map(move |i| model.light(i))
    }

    /// The scene's camera, when the file has one.
    #[must_use]
    pub fn camera(&self) -> Option<SceneCamera> {
        let at = u32_at(self.data, header::CAMERA.start) as usize;
        (at != 0).then(|| SceneCamera {
            position: vec3_at(self.data, at + camera::POSITION.start),
            target: vec3_at(self.data, at + camera::TARGET.start),
            fov: f32_at(self.data, at + camera::FOV.start),
            near: f32_at(self.data, at + camera::NEAR.start),
            far: f32_at(self.data, at + camera::FAR.start),
        })
    }
}

/// A material of a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Material {
    /// Diffuse colour and alpha, 8 bits each.
    pub rgba: [u8; 4],
    /// Whether back faces are culled.
    pub cull_back_faces: bool,
    /// Horizontal wrap.
    pub wrap_u: Wrap,
    /// Vertical wrap.
    pub wrap_v: Wrap,
    /// Texture index.
    pub texture: Option<u16>,
}

impl Default for Material {
    /// White, opaque, back faces culled, untextured (Babylon's default material).
    fn default() -> Self {
        Self { rgba: [255; 4], cull_back_faces: true, wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, texture: None }
    }
}

/// A light of a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// The light kind.
    pub kind: LightKind,
    /// Position (point) or direction.
    pub vector: Vec3,
    /// Diffuse colour.
    pub diffuse: Vec3,
    /// Intensity.
    pub intensity: f32,
}

/// The camera stored in a [`Model`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneCamera {
    /// Eye position.
    pub position: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, radians.
    pub fov: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A section of records whose length passes `usize::MAX` (a count from a file on a 32-bit
    /// target: `0x2AAA_AAAB` vertices of 12 bytes wrap to 4) is out of bounds, not a short
    /// range and not an overflow.
    #[test]
    fn records_whose_length_overflows_are_out_of_bounds() {
        let huge = usize::MAX / 6 + 1;
        let r = records(0, (huge, 12), 100, Part::Positions, 8);
        assert_eq!(r, Err(ParseError::OutOfBounds { part: Part::Positions, offset: 8 }));
        assert_eq!(records(4, (3, 12), 40, Part::Positions, 8), Ok(4..40));
        assert!(records(4, (3, 12), 39, Part::Positions, 8).is_err());
    }
}
