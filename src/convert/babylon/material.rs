//! Materials: the `materials[]` and `multiMaterials[]` tables, a sub-mesh's material (through
//! a multi-material when the mesh names one), StandardMaterial and PBR colours, alpha and
//! culling, the sampler state of the diffuse texture (`wrapU`/`wrapV`) and how that texture
//! maps the mesh's UVs ([`UvMap`]: `Texture.getTextureMatrix`, `coordinatesIndex`, `invertY`).
//!
//! Loading and decoding the texture image is `texture`'s job; applying a [`UvMap`] to a
//! mesh's UVs is `mesh`'s.

use std::borrow::ToOwned;
use std::collections::HashMap;
use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use serde_json::Value;

use super::fields::{array, count, finite, flag, get, list, scalar, show, text, vector, Ctx, Res};
use super::transform::{euler_matrix, transform};
use super::{ConvertError, Reader};
use crate::convert::scene::{MaterialData, Wrap};

/// How a material's texture maps the mesh's UVs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvMap {
    matrix: [f32; 6],
    /// 0 = `uvs`, 1 = `uvs2` (`coordinatesIndex`).
    pub(super) set: usize,
    /// `invertY: false`: store `1 - v`.
    flip: bool,
}

impl UvMap {
    pub(super) fn apply(&self, [u, v]: [f32; 2]) -> [f32; 2] {
        let m = &self.matrix;
        let (u2, v2) = (m[0] * u + m[1] * v + m[2], m[3] * u + m[4] * v + m[5]);
        [u2, if self.flip { 1. - v2 } else { v2 }]
    }
}

/// A converted material: its index in `Scene::materials` and, when textured, its UV mapping.
#[derive(Clone, Copy)]
pub(super) struct MatSlot {
    pub(super) index: u16,
    pub(super) uv: Option<UvMap>,
}

/// The scene's `materials[]` by `id` (else `name`); the first of equal ids wins.
pub(super) fn material_table<'v>(root: &'v Value, cx: &Ctx) -> Result<HashMap<String, &'v Value>, ConvertError> {
    let mut materials = HashMap::new();
    for (i, m) in list(root, "materials").map_err(|m| cx.err(m))?.iter().enumerate() {
        let id = text(m, "id")
            .and_then(|id| Ok(id.or(text(m, "name")?)))
            .map_err(|e| cx.err(format!("materials[{i}].{e}")))?;
        if !m.is_object() {
            return Err(cx.err(format!("materials[{i}]: expected an object, found {}", show(m))));
        }
        if let Some(id) = id {
            materials.entry(id).or_insert(m);
        }
    }
    Ok(materials)
}

/// The scene's `multiMaterials[]` by `id`: the material id of each sub-material (`None` for
/// the default material); the first of equal ids wins.
pub(super) fn multi_material_table(
    root: &Value,
    cx: &Ctx,
) -> Result<HashMap<String, Vec<Option<String>>>, ConvertError> {
    let mut multi = HashMap::new();
    for (i, mm) in list(root, "multiMaterials").map_err(|m| cx.err(m))?.iter().enumerate() {
        let at = |m: String| cx.err(format!("multiMaterials[{i}].{m}"));
        let subs = array(mm, "materials", "a material id or null", |s| match s {
            Value::Null => Some(None),
            Value::String(s) => Some(Some(s.clone())),
            Value::Number(n) => Some(Some(n.to_string())),
            _ => None,
        });
        if let Some(id) = text(mm, "id").map_err(at)? {
            multi.entry(id).or_insert(subs.map_err(at)?.unwrap_or_default());
        }
    }
    Ok(multi)
}

impl Reader<'_> {
    /// The material of a sub-mesh whose mesh names material `id` and whose `materialIndex` is
    /// `index`; `None` is the default material.
    pub(super) fn submesh_material(
        &mut self,
        id: Option<&str>,
        index: u64,
        what: &str,
    ) -> Result<Option<MatSlot>, ConvertError> {
        let Some(id) = id else { return Ok(None) };
        let Some(subs) = self.multi.get(id) else {
            return self.material(id, what);
        };
        match usize::try_from(index).ok().and_then(|i| subs.get(i)).cloned() {
            Some(Some(sub)) => self.material(&sub, what),
            Some(None) => Ok(None),
            None => {
                let len = subs.len();
                self.warn(format!("{what}: materialIndex {index} but multi-material {id:?} has {len} materials; default material used"));
                Ok(None)
            }
        }
    }

    fn material(&mut self, id: &str, what: &str) -> Result<Option<MatSlot>, ConvertError> {
        if let Some(slot) = self.mat_cache.get(id) {
            return Ok(*slot);
        }
        let slot = match self.materials.get(id).copied() {
            Some(obj) => Some(self.convert_material(obj, id, what)?),
            None => {
                self.warn(format!("{what}: material {id:?} not found, default material used"));
                None
            }
        };
        self.mat_cache.insert(id.to_owned(), slot);
        Ok(slot)
    }

    /// A StandardMaterial (`diffuse`, `diffuseTexture`) or a PBR material (`albedo`,
    /// `albedoColor`, `baseColor`, `albedoTexture`, `baseTexture`...).
    fn convert_material(&mut self, obj: &Value, id: &str, what: &str) -> Result<MatSlot, ConvertError> {
        let name = text(obj, "name").ok().flatten().unwrap_or_else(|| id.to_owned());
        let cx = self.ctx(format!("{what}: material {name:?}"));
        let e = |m: String| cx.err(m);
        let custom = text(obj, "customType").map_err(e)?.unwrap_or_default();
        let pbr_keys = ["albedo", "albedoColor", "albedoTexture", "baseColor", "baseTexture"];
        let pbr = custom.contains("PBR") || pbr_keys.iter().any(|k| get(obj, k).is_some());
        let (colour_keys, texture_keys): (&[&str], &[&str]) = if pbr {
            (
                &["albedo", "albedoColor", "baseColor", "diffuseColor"],
                &["albedoTexture", "baseTexture", "diffuseTexture"],
            )
        } else {
            (&["diffuse"], &["diffuseTexture"])
        };
        let mut diffuse = None;
        for k in colour_keys {
            diffuse = diffuse.or(vector(obj, k).map_err(e)?);
        }
        let mut data = MaterialData {
            name,
            diffuse: diffuse.unwrap_or([1.; 3]),
            alpha: scalar(obj, "alpha", 1.).map_err(e)?,
            back_face_culling: flag(obj, "backFaceCulling", true).map_err(e)?
                && !flag(obj, "doubleSided", false).map_err(e)?,
            ..MaterialData::default()
        };
        let mut uv = None;
        if let Some((key, tex)) = texture_keys.iter().find_map(|k| Some((*k, get(obj, k)?))) {
            uv = self.material_texture(obj, key, tex, &mut data, &cx)?;
        }
        let index = u16::try_from(self.scene.materials.len()).map_err(|_| cx.err("more than 65536 materials"))?;
        self.scene.materials.push(data);
        Ok(MatSlot { index, uv })
    }

    /// The texture `tex` (field `key` of material `obj`) into `data`: its image, its wrap modes
    /// and, when the image could be loaded, how it maps the mesh's UVs.
    fn material_texture(
        &mut self,
        obj: &Value,
        key: &str,
        tex: &Value,
        data: &mut MaterialData,
        cx: &Ctx,
    ) -> Result<Option<UvMap>, ConvertError> {
        let at = |m: String| cx.err(format!("{key}.{m}"));
        if !tex.is_object() {
            return Err(cx.err(format!("{key}: expected an object, found {}", show(tex))));
        }
        let opaque = get(obj, "transparencyMode").and_then(finite) == Some(0.);
        let keep_alpha = flag(tex, "hasAlpha", false).map_err(at)? && !opaque;
        data.texture = self.texture(tex, keep_alpha, cx)?;
        [data.wrap_u, data.wrap_v] = [wrap(tex, "wrapU").map_err(at)?, wrap(tex, "wrapV").map_err(at)?];
        if data.texture.is_none() {
            return Ok(None);
        }
        let mode = count(tex, "coordinatesMode", Some(0)).map_err(at)?;
        if mode != 0 {
            self.warn(format!("{}: {key}.coordinatesMode {mode} is not supported, explicit UVs used", cx.what));
        }
        Ok(Some(UvMap {
            matrix: texture_matrix(tex).map_err(at)?,
            set: usize::from(count(tex, "coordinatesIndex", Some(0)).map_err(at)? > 0),
            flip: !flag(tex, "invertY", true).map_err(at)?,
        }))
    }
}

/// Babylon's texture matrix as `u' = m0·u + m1·v + m2`, `v' = m3·u + m4·v + m5`.
fn texture_matrix(tex: &Value) -> Res<[f32; 6]> {
    let f = |key, default| scalar(tex, key, default);
    let (us, vs) = (f("uScale", 1.)?, f("vScale", 1.)?);
    let (uo, vo) = (f("uOffset", 0.)?, f("vOffset", 0.)?);
    let angles = [f("uAng", 0.)?, f("vAng", 0.)?, f("wAng", 0.)?];
    let centre = [f("uRotationCenter", 0.5)?, f("vRotationCenter", 0.5)?, f("wRotationCenter", 0.5)?];
    let r = euler_matrix(angles); // RotationYawPitchRoll(vAng, uAng, wAng)
    let row = |x: f32, y: f32| {
        let p = [x * us - centre[0] * us, y * vs - centre[1] * vs, -centre[2]];
        let t = transform(&r, p, 1.);
        [t[0] + centre[0] * us + uo, t[1] + centre[1] * vs + vo]
    };
    let (t0, t1, t2) = (row(0., 0.), row(1., 0.), row(0., 1.));
    Ok([t1[0] - t0[0], t2[0] - t0[0], t0[0], t1[1] - t0[1], t2[1] - t0[1], t0[1]])
}

/// `wrapU`/`wrapV`: 0 clamp, 1 repeat, 2 mirror; old files write booleans (true = repeat).
fn wrap(tex: &Value, key: &str) -> Res<Wrap> {
    Ok(match get(tex, key) {
        Some(Value::Bool(false)) => Wrap::Clamp,
        Some(v) if !v.is_boolean() => match finite(v).map(|x| x as i64) {
            Some(0) => Wrap::Clamp,
            Some(2) => Wrap::Mirror,
            Some(_) => Wrap::Repeat,
            None => return Err(format!("{key}: expected a wrap mode, found {}", show(v))),
        },
        _ => Wrap::Repeat,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn texture_matrix_scales_and_offsets() {
        let tex = serde_json::json!({"uScale": 5, "vScale": -1, "uOffset": 0.25, "vOffset": 0.5});
        let m = texture_matrix(&tex).unwrap();
        assert!(close(&m, &[5., 0., 0.25, 0., -1., 0.5]), "{m:?}");
        // wAng rotates around the centre (0.5, 0.5): the centre stays put.
        let rot = texture_matrix(&serde_json::json!({"wAng": 1.0})).unwrap();
        let map = UvMap { matrix: rot, set: 0, flip: false };
        assert!(close(&map.apply([0.5, 0.5]), &[0.5, 0.5]));
    }
}
