//! Where a mesh's vertex data lives and how it is laid out: split `positions/normals/uvs/...`
//! arrays, the 2013 interleaved `vertices` + `uvCount`, shared `geometries.vertexData[]`
//! referenced by `geometryId`, and `delayLoadingFile` side files (binary
//! `.babylonbinarymeshdata` or JSON). The result is a raw [`Geometry`].
//!
//! Checking the data (lengths, index ranges), computing normals and building the mesh is
//! `mesh`'s job, not this module's.

use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use serde_json::Value;

use super::fields::{count, floats, get, list, show, text, uints, Ctx, Res};
use super::{io_error, ConvertError, Reader};

/// A mesh's vertex data before validation.
#[derive(Default)]
pub(super) struct Geometry {
    pub(super) positions: Vec<f32>,
    pub(super) normals: Option<Vec<f32>>,
    pub(super) uvs: [Option<Vec<f32>>; 2],
    pub(super) colors: Option<Vec<f32>>,
    pub(super) indices: Option<Vec<u32>>,
    /// `[materialIndex, indexStart, indexCount]`.
    pub(super) submeshes: Option<Vec<[u64; 3]>>,
}

fn split_geometry(obj: &Value) -> Res<Geometry> {
    Ok(Geometry {
        positions: floats(obj, "positions")?.unwrap_or_default(),
        normals: floats(obj, "normals")?,
        uvs: [floats(obj, "uvs")?, floats(obj, "uvs2")?],
        colors: floats(obj, "colors")?,
        indices: uints(obj, "indices")?,
        submeshes: submeshes(obj)?,
    })
}

/// The 2013 layout: per vertex `[x,y,z, nx,ny,nz, (u,v) x uvCount]`.
fn legacy_geometry(obj: &Value) -> Res<Geometry> {
    let data = floats(obj, "vertices")?.unwrap_or_default();
    let uv_count = count(obj, "uvCount", Some(0))?;
    let stride = usize::try_from(uv_count).ok().filter(|&n| n <= 64).map(|n| 6 + 2 * n);
    let stride = stride.ok_or_else(|| format!("uvCount: {uv_count} is too large"))?;
    if data.len() % stride != 0 {
        return Err(format!(
            "vertices: {} numbers is not a multiple of the vertex size {stride} (6 + 2·uvCount)",
            data.len()
        ));
    }
    let pick = |start: usize, n: usize| {
        data.chunks_exact(stride).flat_map(|v| v[start..start + n].iter().copied()).collect::<Vec<_>>()
    };
    let uvs = |set: usize| (set < stride / 2 - 3).then(|| pick(6 + 2 * set, 2));
    Ok(Geometry {
        positions: pick(0, 3),
        normals: Some(pick(3, 3)),
        uvs: [uvs(0), uvs(1)],
        indices: uints(obj, "indices")?,
        submeshes: submeshes(obj)?,
        ..Geometry::default()
    })
}

/// A `.babylonbinarymeshdata` side file described by the mesh's `_binaryInfo`.
fn binary_geometry(data: &[u8], info: &Value) -> Res<Geometry> {
    let words = |key: &str, per: u64| -> Res<Option<Vec<[u8; 4]>>> {
        let Some(desc) = get(info, key) else {
            return Ok(None);
        };
        let in_desc = |m: String| format!("_binaryInfo.{key}.{m}");
        let (n, offset) = (count(desc, "count", None).map_err(in_desc)?, count(desc, "offset", None).map_err(in_desc)?);
        let range = n.checked_mul(4 * per).and_then(|len| Some(offset..offset.checked_add(len)?));
        let bytes = range.and_then(|r| data.get(usize::try_from(r.start).ok()?..usize::try_from(r.end).ok()?));
        let outside =
            || format!("_binaryInfo.{key}: {n} values at byte {offset} lie outside the {}-byte file", data.len());
        let bytes = bytes.ok_or_else(outside)?;
        Ok(Some(bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()))
    };
    let floats = |key: &str, name: &str| -> Res<Option<Vec<f32>>> {
        let Some(w) = words(key, 1)? else {
            return Ok(None);
        };
        let f: Vec<f32> = w.into_iter().map(f32::from_le_bytes).collect();
        match f.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(format!("{name}[{i}] = {} is not finite", f[i])),
            None => Ok(Some(f)),
        }
    };
    let ints = |key: &str, name: &str, per: u64| -> Res<Option<Vec<u32>>> {
        let Some(w) = words(key, per)? else {
            return Ok(None);
        };
        let ints = w.into_iter().map(i32::from_le_bytes);
        let bad = |(i, x): (usize, i32)| format!("{name}[{i}] = {x} is negative");
        ints.enumerate().map(|(i, x)| u32::try_from(x).map_err(|_| bad((i, x)))).collect::<Res<_>>().map(Some)
    };
    let subs = ints("subMeshesAttrDesc", "subMeshes", 5)?;
    Ok(Geometry {
        positions: floats("positionsAttrDesc", "positions")?.unwrap_or_default(),
        normals: floats("normalsAttrDesc", "normals")?,
        uvs: [floats("uvsAttrDesc", "uvs")?, floats("uvs2AttrDesc", "uvs2")?],
        colors: floats("colorsAttrDesc", "colors")?,
        indices: ints("indicesAttrDesc", "indices", 1)?,
        submeshes: subs.map(|s| s.chunks_exact(5).map(|r| [r[0], r[3], r[4]].map(u64::from)).collect()),
    })
}

/// The `subMeshes` field as `[materialIndex, indexStart, indexCount]`.
fn submeshes(obj: &Value) -> Res<Option<Vec<[u64; 3]>>> {
    if get(obj, "subMeshes").is_none() {
        return Ok(None);
    }
    let read = |(i, s): (usize, &Value)| -> Res<[u64; 3]> {
        let at = |m: String| format!("subMeshes[{i}].{m}");
        if !s.is_object() {
            return Err(format!("subMeshes[{i}]: expected an object, found {}", show(s)));
        }
        let [m, start, n] =
            [("materialIndex", Some(0)), ("indexStart", None), ("indexCount", None)].map(|(k, d)| count(s, k, d));
        Ok([m.map_err(at)?, start.map_err(at)?, n.map_err(at)?])
    };
    list(obj, "subMeshes")?.iter().enumerate().map(read).collect::<Res<_>>().map(Some)
}

impl Reader<'_> {
    /// Finds a mesh's vertex data wherever the file keeps it.
    pub(super) fn geometry(&self, obj: &Value, cx: &Ctx) -> Result<Geometry, ConvertError> {
        let e = |m: String| cx.err(m);
        if get(obj, "positions").is_some() {
            return split_geometry(obj).map_err(e);
        }
        if get(obj, "vertices").is_some() {
            return legacy_geometry(obj).map_err(e);
        }
        if let Some(name) = text(obj, "delayLoadingFile").map_err(e)? {
            let Some(dir) = self.base_dir else {
                return Err(cx.err(format!("delayLoadingFile {name:?}: no directory to read it from")));
            };
            let path = dir.join(&name);
            let data = std::fs::read(&path).map_err(|err| io_error(&path, &err))?;
            let in_file = |m: String| cx.err(format!("{name}: {m}"));
            let mut geom = match get(obj, "_binaryInfo") {
                Some(info) => binary_geometry(&data, info).map_err(in_file)?,
                None => {
                    let side: Value = serde_json::from_slice(&data).map_err(|err| in_file(err.to_string()))?;
                    split_geometry(&side).map_err(in_file)?
                }
            };
            if let Some(subs) = submeshes(obj).map_err(e)? {
                geom.submeshes = Some(subs);
            }
            return Ok(geom);
        }
        if let Some(id) = text(obj, "geometryId").map_err(e)? {
            let all = get(self.root, "geometries").map_or(Ok(&[][..]), |g| list(g, "vertexData"));
            let all = all.map_err(|m| self.ctx("scene").err(format!("geometries.{m}")))?;
            let data = all.iter().find(|g| text(g, "id").ok().flatten().as_deref() == Some(&*id));
            let data = data.ok_or_else(|| cx.err(format!("geometryId {id:?} is not in geometries.vertexData")))?;
            let mut geom = split_geometry(data).map_err(|m| cx.err(format!("geometry {id:?}: {m}")))?;
            geom.submeshes = submeshes(obj).map_err(e)?;
            return Ok(geom);
        }
        split_geometry(obj).map_err(e)
    }
}
