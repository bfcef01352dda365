//! The writing half of the `.s3d` layout: [`emit`] turns a converted [`Scene`] into `.s3d`
//! bytes with the offsets of `format`'s layout module, and [`to_scene`] reads a
//! [`Model`] back into a [`Scene`].

use crate::format::layout::*;
use core::fmt;

use super::emit_animation;
use crate::convert::scene::{self, Scene};
use crate::format::{encode_texel, Model, TextureFormat};
use crate::math::{Mat4, Vec3};
use std::string::String;
use std::vec::Vec;

/// How the converter stores textures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureChoice {
    /// RGB565, or RGBA5551 for textures with transparent texels (cut-outs).
    #[default]
    Auto,
    /// Always this format.
    Fixed(TextureFormat),
}

/// Options of [`emit`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EmitOptions {
    /// Texture storage.
    pub textures: TextureChoice,
    /// Store positions as exact f32 (12 bytes a vertex) instead of quantized u16 (6 bytes).
    pub float_positions: bool,
}

/// Why a scene cannot be written as `.s3d`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmitError(pub String);

impl fmt::Display for EmitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EmitError {}

/// A growing file whose fixed-size records are reserved first and filled in later.
pub(super) struct Out(Vec<u8>);

impl Out {
    /// The quantization step of mesh `i` already written (1 for f32 positions).
    pub(super) fn mesh_pos_scale(&self, i: usize) -> [f32; 3] {
        let table = u32_at(&self.0, header::MESHES.start) as usize;
        let at = table + i * mesh::LEN + mesh::POS_SCALE.start;
        [0, 1, 2].map(|c| f32_at(&self.0, at + 4 * c))
    }
    pub(super) fn reserve(&mut self, len: usize) -> usize {
        let at = self.0.len();
        self.0.resize(at + len, 0);
        at
    }
    pub(super) fn append(&mut self, bytes: &[u8]) -> u32 {
        let at = self.0.len();
        self.0.extend_from_slice(bytes);
        at as u32
    }
    pub(super) fn put(&mut self, at: usize, bytes: &[u8]) {
        self.0[at..at + bytes.len()].copy_from_slice(bytes);
    }
    pub(super) fn put_u16(&mut self, at: usize, v: u16) {
        self.put(at, &v.to_le_bytes());
    }
    pub(super) fn put_u32(&mut self, at: usize, v: u32) {
        self.put(at, &v.to_le_bytes());
    }
    pub(super) fn put_f32s(&mut self, at: usize, vs: &[f32]) {
        for (k, v) in vs.iter().enumerate() {
            self.put(at + 4 * k, &v.to_le_bytes());
        }
    }
    pub(super) fn put_affine(&mut self, at: usize, m: &scene::Matrix) {
        let rows: [f32; 12] = core::array::from_fn(|k| m[(k / 3) * 4 + k % 3]);
        self.put_f32s(at, &rows);
    }
}

fn count_u16(n: usize, what: &str) -> Result<u16, EmitError> {
    u16::try_from(n)
        .ok()
        .filter(|&n| n != NONE)
        .ok_or_else(|| EmitError(std::format!("too many {what}: {n} (at most 65534)")))
}

/// Quantization of a set of values: `value = offset + q * scale`, `q` in 0..=65535.
fn quantizer<const N: usize>(values: impl Iterator<Item = [f32; N]>) -> ([f32; N], [f32; N]) {
    let mut lo = [f32::INFINITY; N];
    let mut hi = [f32::NEG_INFINITY; N];
    for v in values {
        for k in 0..N {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let mut scale = [0.0; N];
    for k in 0..N {
        if !lo[k].is_finite() {
            lo[k] = 0.0;
            hi[k] = 0.0;
        }
        scale[k] = (hi[k] - lo[k]) / QUANT_MAX;
        if !scale[k].is_finite() {
            // The span of two huge finite values overflows f32: take it in f64.
            scale[k] = ((hi[k] as f64 - lo[k] as f64) / QUANT_MAX as f64).min(f32::MAX as f64) as f32;
        }
    }
    (lo, scale)
}

fn quantize(v: f32, offset: f32, scale: f32) -> u16 {
    if scale > 0.0 {
        libm::roundf((v - offset) / scale).clamp(0.0, QUANT_MAX) as u16
    } else {
        0
    }
}

fn bounding_sphere(positions: &[[f32; 3]]) -> [f32; 4] {
    let (lo, scale) = quantizer(positions.iter().copied());
    let centre = Vec3::from(lo) + Vec3::from(scale) * (QUANT_MAX / 2.0);
    // In f64: squares of coordinates above ~1e19 overflow f32.
    let length = |v: [f64; 3]| libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    let radius =
        positions.iter().map(|p| length([0, 1, 2].map(|k| p[k] as f64 - centre[k] as f64))).fold(0.0f64, f64::max);
    // Grow by the quantization error so the sphere holds the decoded positions too.
    let slack = length(scale.map(f64::from));
    [centre.x, centre.y, centre.z, (radius + slack).min(f32::MAX as f64) as f32]
}

fn check_finite_scene(scene: &Scene) -> Result<(), EmitError> {
    for m in &scene.meshes {
        let nums = m.world.iter().chain(m.positions.iter().flatten()).chain(m.normals.iter().flatten());
        let uvs = m.uvs.iter().flatten().flatten();
        if !nums.chain(uvs).all(|v| v.is_finite()) {
            return Err(EmitError(std::format!("mesh \"{}\": non-finite number", m.name)));
        }
    }
    if let Some(f) = &scene.fog {
        if !f.color.iter().chain(&[f.density, f.start, f.end]).all(|v| v.is_finite()) {
            return Err(EmitError("fog: non-finite number".into()));
        }
    }
    Ok(())
}

/// Writes `scene` as an `.s3d` file.
///
/// # Errors
/// When a count does not fit the format, or a mesh is inconsistent (lengths, indices).
pub fn emit(scene: &Scene, opts: &EmitOptions) -> Result<Vec<u8>, EmitError> {
    check_finite_scene(scene)?;
    let mut out = Out(Vec::new());
    // The lowest version that holds the scene (version 1 every reader since the first reads).
    let animated = !scene.animation.is_empty();
    let (version, header_len) = match (&scene.fog, animated) {
        (Some(_), _) => (VERSION, header::LEN_V3),
        (None, true) => (2, header::LEN_V2),
        (None, false) => (1, header::LEN),
    };
    out.reserve(header_len);
    out.put(header::MAGIC.start, &MAGIC);
    out.put_u16(header::VERSION.start, version);
    let counts = [
        (header::MESH_COUNT, scene.meshes.len(), "meshes"),
        (header::MATERIAL_COUNT, scene.materials.len(), "materials"),
        (header::TEXTURE_COUNT, scene.textures.len(), "textures"),
        (header::INSTANCE_COUNT, scene.instances.len(), "instances"),
        (header::LIGHT_COUNT, scene.lights.len(), "lights"),
    ];
    for (field, n, what) in counts {
        let n = count_u16(n, what)?;
        out.put_u16(field.start, n);
    }
    let meshes = out.reserve(mesh::LEN * scene.meshes.len());
    out.put_u32(header::MESHES.start, meshes as u32);
    for (k, m) in scene.meshes.iter().enumerate() {
        let reach = emit_animation::morph_reach(scene, k);
        emit_mesh(&mut out, meshes + k * mesh::LEN, (m, &reach), scene.materials.len(), opts.float_positions)?;
    }
    let materials = out.reserve(material::LEN * scene.materials.len());
    out.put_u32(header::MATERIALS.start, materials as u32);
    for (k, m) in scene.materials.iter().enumerate() {
        emit_material(&mut out, materials + k * material::LEN, m, scene.textures.len())?;
    }
    let textures = out.reserve(texture::LEN * scene.textures.len());
    out.put_u32(header::TEXTURES.start, textures as u32);
    for (k, t) in scene.textures.iter().enumerate() {
        emit_texture(&mut out, textures + k * texture::LEN, t, opts)?;
    }
    let instances = out.reserve(instance::LEN * scene.instances.len());
    out.put_u32(header::INSTANCES.start, instances as u32);
    for (k, inst) in scene.instances.iter().enumerate() {
        if inst.mesh as usize >= scene.meshes.len() {
            return Err(EmitError(std::format!("instance {k}: mesh {} does not exist", inst.mesh)));
        }
        let at = instances + k * instance::LEN;
        out.put_u16(at + instance::MESH.start, inst.mesh);
        out.put_affine(at + instance::WORLD.start, &inst.world);
    }
    let lights = out.reserve(light::LEN * scene.lights.len());
    out.put_u32(header::LIGHTS.start, lights as u32);
    for (k, l) in scene.lights.iter().enumerate() {
        let at = lights + k * light::LEN;
        out.put(at + light::KIND, &[l.kind as u8]);
        out.put_f32s(at + light::VECTOR.start, &l.vector);
        out.put_f32s(at + light::DIFFUSE.start, &l.diffuse);
        out.put_f32s(at + light::INTENSITY.start, &[l.intensity]);
    }
    if let Some(c) = &scene.camera {
        let at = out.reserve(camera::LEN);
        out.put_u32(header::CAMERA.start, at as u32);
        out.put_f32s(at + camera::POSITION.start, &c.position);
        out.put_f32s(at + camera::TARGET.start, &c.target);
        out.put_f32s(at + camera::FOV.start, &[c.fov, c.near, c.far]);
    }
    if let Some(f) = &scene.fog {
        let at = out.reserve(fog::LEN);
        out.put_u32(header::FOG.start, at as u32);
        out.put(at + fog::MODE, &[f.mode]);
        out.put_f32s(at + fog::COLOR.start, &f.color);
        out.put_f32s(at + fog::DENSITY.start, &[f.density, f.start, f.end]);
    }
    if animated {
        let at = emit_animation::emit_animation(&mut out, scene)?;
        out.put_u32(header::ANIMATION.start, at);
    }
    let len = u32::try_from(out.0.len()).map_err(|_| EmitError("scene larger than 4 GiB".into()))?;
    out.put_u32(header::FILE_LEN.start, len);
    // The writer must only produce what the reader accepts.
    Model::parse(&out.0).map_err(|e| EmitError(std::format!("internal error, emitted file invalid: {e}")))?;
    Ok(out.0)
}

/// Decodes a parsed model back into a [`Scene`]: the inverse of [`emit`] up to
/// quantization (a second `emit` of the result gives the same bytes).
#[must_use]
pub fn to_scene(model: &Model<'_>) -> Scene {
    let matrix = |m: Mat4| m.to_cols_array();
    let wrap = |w: Wrap| match w {
        Wrap::Clamp => scene::Wrap::Clamp,
        Wrap::Repeat => scene::Wrap::Repeat,
        Wrap::Mirror => scene::Wrap::Mirror,
    };
    let meshes = model
        .meshes()
        .map(|m| {
            let n = m.vertex_count();
            scene::MeshData {
                name: m.name().into(),
                world: matrix(m.world()),
                positions: (0..n).map(|i| m.position(i).to_array()).collect(),
                normals: (0..n).map(|i| m.normal(i).to_array()).collect(),
                uvs: m.has_uvs().then(|| (0..n).map(|i| m.uv(i)).collect()),
                colors: m.has_colors().then(|| (0..n).map(|i| m.color(i).map(|c| c as f32 / 255.0)).collect()),
                indices: (0..3 * m.triangle_count()).map(|k| m.index(k)).collect(),
                submeshes: m
                    .submeshes()
                    .map(|s| scene::SubMeshData {
                        material: s.material,
                        index_start: 3 * s.first_triangle,
                        index_count: 3 * s.triangle_count,
                    })
                    .collect(),
            }
        })
        .collect();
    let materials = (0..model.material_count() as u16)
        .filter_map(|i| model.material(i))
        .map(|m| scene::MaterialData {
            name: String::new(),
            diffuse: [0, 1, 2].map(|k| m.rgba[k] as f32 / 255.0),
            alpha: m.rgba[3] as f32 / 255.0,
            back_face_culling: m.cull_back_faces,
            texture: m.texture,
            wrap_u: wrap(m.wrap_u),
            wrap_v: wrap(m.wrap_v),
        })
        .collect();
    let textures = (0..model.texture_count() as u16)
        .filter_map(|i| model.texture(i))
        .map(|t| scene::TextureData {
            name: String::new(),
            width: t.width,
            height: t.height,
            // Back to rows from the top of the image.
            rgba: (0..t.height as u32)
                .rev()
                .flat_map(|j| (0..t.width as u32).flat_map(move |i| t.rgba(i, j)))
                .collect(),
        })
        .collect();
    let instances = (0..model.instance_count())
        .filter_map(|i| model.instance(i))
        .map(|(mesh, world)| scene::InstanceData { mesh: mesh as u16, world: matrix(world) })
        .collect();
    let (lights, camera, fog) = read_view(model);
    let animation = emit_animation::read_animation(model);
    Scene { meshes, materials, textures, instances, lights, camera, animation, fog }
}

/// A parsed model's lights, camera and fog, as [`to_scene`] gives them back.
fn read_view(model: &Model<'_>) -> (Vec<scene::LightData>, Option<scene::CameraData>, Option<scene::FogData>) {
    let lights = model
        .lights()
        .map(|l| scene::LightData {
            kind: match l.kind {
                LightKind::Point => scene::LightKind::Point,
                LightKind::Directional => scene::LightKind::Directional,
                LightKind::Hemispheric => scene::LightKind::Hemispheric,
            },
            vector: l.vector.to_array(),
            diffuse: l.diffuse.to_array(),
            intensity: l.intensity,
        })
        .collect();
    let camera = model.camera().map(|c| scene::CameraData {
        position: c.position.to_array(),
        target: c.target.to_array(),
        fov: c.fov,
        near: c.near,
        far: c.far,
    });
    let fog = model.fog().map(|f| scene::FogData {
        mode: f.mode as u8,
        color: f.color.to_array(),
        density: f.density,
        start: f.start,
        end: f.end,
    });
    (lights, camera, fog)
}

/// Writes mesh `m`'s record at `at` and its arrays; its bounding sphere holds `reach` too (the
/// positions its morph targets reach).
fn emit_mesh(
    out: &mut Out,
    at: usize,
    (m, reach): (&scene::MeshData, &[[f32; 3]]),
    n_materials: usize,
    float_positions: bool,
) -> Result<(), EmitError> {
    check_mesh(m)?;
    let nv = m.positions.len();
    out.put_affine(at + mesh::WORLD.start, &m.world);
    let (pos_offset, pos_scale) =
        // Over the positions the morph targets reach too: an axis flat at rest but not when
        // morphed keeps a step (its deltas are stored in steps).
        if float_positions { ([0.0; 3], [1.0; 3]) } else { quantizer(m.positions.iter().chain(reach).copied()) };
    out.put_f32s(at + mesh::POS_OFFSET.start, &pos_offset);
    out.put_f32s(at + mesh::POS_SCALE.start, &pos_scale);
    let sphere = if reach.is_empty() { bounding_sphere(&m.positions) } else { bounding_sphere(reach) };
    out.put_f32s(at + mesh::BOUNDS.start, &sphere);
    out.put_u32(at + mesh::VERTEX_COUNT.start, nv as u32);
    out.put_u32(at + mesh::INDEX_COUNT.start, m.indices.len() as u32);
    let wide = nv > u16::MAX as usize + 1;
    let flags = u16::from(wide) * mesh::FLAG_U32_INDICES
        + u16::from(m.uvs.is_some()) * mesh::FLAG_UVS
        + u16::from(m.colors.is_some()) * mesh::FLAG_COLORS
        + u16::from(float_positions) * mesh::FLAG_F32_POSITIONS;
    out.put_u16(at + mesh::FLAGS.start, flags);

    emit_mesh_name(out, at, &m.name);
    let positions: Vec<u8> = if float_positions {
        m.positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
    } else {
        m.positions
            .iter()
            .flat_map(|p| (0..3).flat_map(move |k| quantize(p[k], pos_offset[k], pos_scale[k]).to_le_bytes()))
            .collect()
    };
    let o = out.append(&positions);
    out.put_u32(at + mesh::POSITIONS.start, o);
    emit_attributes(out, at, m);
    let indices: Vec<u8> = if wide {
        m.indices.iter().flat_map(|i| i.to_le_bytes()).collect()
    } else {
        m.indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect()
    };
    let o = out.append(&indices);
    out.put_u32(at + mesh::INDICES.start, o);
    emit_submeshes(out, at, m, n_materials)
}

/// The mesh error `what`, naming the mesh.
fn mesh_error(m: &scene::MeshData, what: &str) -> EmitError {
    EmitError(std::format!("mesh \"{}\": {what}", m.name))
}

/// Checks a mesh against itself: vertices, attribute lengths, whole triangles, index range.
fn check_mesh(m: &scene::MeshData) -> Result<(), EmitError> {
    let nv = m.positions.len();
    if nv == 0 || nv > u32::MAX as usize {
        return Err(mesh_error(m, &std::format!("{nv} vertices")));
    }
    if m.normals.len() != nv
        || m.uvs.as_ref().is_some_and(|u| u.len() != nv)
        || m.colors.as_ref().is_some_and(|c| c.len() != nv)
    {
        return Err(mesh_error(m, "normals/uvs/colors and positions differ in length"));
    }
    if !m.indices.len().is_multiple_of(3) {
        return Err(mesh_error(m, &std::format!("{} indices is not a multiple of 3", m.indices.len())));
    }
    if let Some((k, i)) = m.indices.iter().enumerate().find(|(_, &i)| i as usize >= nv) {
        return Err(mesh_error(m, &std::format!("indices[{k}] = {i} but only {nv} vertices")));
    }
    Ok(())
}

/// The mesh's name, cut to at most 65535 bytes at a character boundary.
fn emit_mesh_name(out: &mut Out, at: usize, name: &str) {
    let name = name.as_bytes();
    let name = &name[..name.len().min(u16::MAX as usize)];
    let name = match core::str::from_utf8(name) {
        Ok(s) => s.as_bytes(),
        Err(e) => &name[..e.valid_up_to()],
    };
    let name_at = out.append(name);
    out.put_u32(at + mesh::NAME.start, name_at);
    out.put_u16(at + mesh::NAME_LEN.start, name.len() as u16);
}

/// The mesh's normals, then its UVs and vertex colours when it has them.
fn emit_attributes(out: &mut Out, at: usize, m: &scene::MeshData) {
    let normals: Vec<u8> = m
        .normals
        .iter()
        .flat_map(|n| n.map(|c| (libm::roundf(c.clamp(-1.0, 1.0) * NORMAL_ONE) as i16).to_le_bytes()))
        .flatten()
        .collect();
    let o = out.append(&normals);
    out.put_u32(at + mesh::NORMALS.start, o);
    if let Some(uvs) = &m.uvs {
        let (uv_offset, uv_scale) = quantizer(uvs.iter().copied());
        out.put_f32s(at + mesh::UV_OFFSET.start, &uv_offset);
        out.put_f32s(at + mesh::UV_SCALE.start, &uv_scale);
        let bytes: Vec<u8> = uvs
            .iter()
            .flat_map(|uv| (0..2).flat_map(move |k| quantize(uv[k], uv_offset[k], uv_scale[k]).to_le_bytes()))
            .collect();
        let o = out.append(&bytes);
        out.put_u32(at + mesh::UVS.start, o);
    }
    if let Some(colors) = &m.colors {
        let bytes: Vec<u8> = colors.iter().flat_map(|c| c.map(unit_to_u8)).collect();
        let o = out.append(&bytes);
        out.put_u32(at + mesh::COLORS.start, o);
    }
}

/// The mesh's sub-mesh records (one over all indices when it has none).
fn emit_submeshes(out: &mut Out, at: usize, m: &scene::MeshData, n_materials: usize) -> Result<(), EmitError> {
    let whole = [scene::SubMeshData { material: None, index_start: 0, index_count: m.indices.len() as u32 }];
    let subs = if m.submeshes.is_empty() { &whole[..] } else { &m.submeshes[..] };
    let n_sub = count_u16(subs.len(), "sub-meshes")?;
    out.put_u16(at + mesh::SUBMESH_COUNT.start, n_sub);
    let s_at = out.reserve(subs.len() * submesh::LEN);
    out.put_u32(at + mesh::SUBMESHES.start, s_at as u32);
    for (k, s) in subs.iter().enumerate() {
        let r = s_at + k * submesh::LEN;
        if s.material.is_some_and(|mi| mi as usize >= n_materials) {
            return Err(mesh_error(m, &std::format!("sub-mesh {k}: material {:?} does not exist", s.material)));
        }
        out.put_u16(r + submesh::MATERIAL.start, s.material.unwrap_or(NONE));
        out.put_u32(r + submesh::INDEX_START.start, s.index_start);
        out.put_u32(r + submesh::INDEX_COUNT.start, s.index_count);
    }
    Ok(())
}

/// 0..=1 to 0..=255, `floor(v * 255 + 0.5)` as Babylon does.
fn unit_to_u8(v: f32) -> u8 {
    libm::floorf(v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

fn emit_material(out: &mut Out, at: usize, m: &scene::MaterialData, n_textures: usize) -> Result<(), EmitError> {
    let [r, g, b] = m.diffuse.map(unit_to_u8);
    out.put(at + material::RGBA.start, &[r, g, b, unit_to_u8(m.alpha)]);
    out.put(at + material::FLAGS, &[u8::from(m.back_face_culling) * material::FLAG_CULL_BACK]);
    let wrap = |w: scene::Wrap| match w {
        scene::Wrap::Clamp => Wrap::Clamp as u8,
        scene::Wrap::Repeat => Wrap::Repeat as u8,
        scene::Wrap::Mirror => Wrap::Mirror as u8,
    };
    out.put(at + material::WRAP_U, &[wrap(m.wrap_u), wrap(m.wrap_v)]);
    if m.texture.is_some_and(|t| t as usize >= n_textures) {
        return Err(EmitError(std::format!("material \"{}\": texture {:?} does not exist", m.name, m.texture)));
    }
    out.put_u16(at + material::TEXTURE.start, m.texture.unwrap_or(NONE));
    Ok(())
}

fn emit_texture(out: &mut Out, at: usize, t: &scene::TextureData, opts: &EmitOptions) -> Result<(), EmitError> {
    let (w, h) = (t.width as usize, t.height as usize);
    if w == 0 || h == 0 || t.rgba.len() != w * h * 4 {
        return Err(EmitError(std::format!("texture \"{}\": {}x{} with {} bytes", t.name, w, h, t.rgba.len())));
    }
    let format = match opts.textures {
        TextureChoice::Fixed(f) => f,
        TextureChoice::Auto if t.has_alpha() => TextureFormat::Rgba5551,
        TextureChoice::Auto => TextureFormat::Rgb565,
    };
    out.put_u16(at + texture::WIDTH.start, t.width);
    out.put_u16(at + texture::HEIGHT.start, t.height);
    out.put(at + texture::FORMAT, &[format as u8]);
    let n = format.bytes_per_texel();
    // Stored bottom row first, so that j = floor(v * height) indexes rows directly.
    let texels: Vec<u8> = t
        .rgba
        .chunks_exact(w * 4)
        .rev()
        .flat_map(|row| row.chunks_exact(4))
        .flat_map(|c| encode_texel(format, [c[0], c[1], c[2], c[3]]).into_iter().take(n))
        .collect();
    // At a multiple of 4 in the file: a file placed at an address aligned to 4 (`include_s3d!`)
    // has its texels there too, which the Armv6-M span loop's halfword loads need (it leaves
    // texels at an odd address to the Rust loop).
    out.reserve(out.0.len().next_multiple_of(4) - out.0.len());
    let o = out.append(&texels);
    out.put_u32(at + texture::DATA.start, o);
    Ok(())
}
