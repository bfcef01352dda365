//! Node transforms in Babylon.js conventions: row-vector matrices (`p' = p · M`, translation in
//! `m[12..15]`), Babylon's Euler (`RotationYawPitchRoll`) and quaternion rotations, a node's
//! position/rotation/scaling ([`Trs`], `Local = S · R · T`) and the first frame of its
//! `autoAnimate` animations (what the still picture shows; the tracks themselves are read by
//! `animation`).
//!
//! The hierarchy (parents, world matrices) lives in `node`; texture matrices in `material`.

use std::format;
use std::string::String;
use std::vec::Vec;

use serde_json::Value;

use super::fields::{flag, leading_floats, list, scalar, text, vector, Res};
use crate::convert::scene::{Matrix, Rotation};

pub(super) fn mul(a: &Matrix, b: &Matrix) -> Matrix {
    core::array::from_fn(|i| (0..4).map(|k| a[i / 4 * 4 + k] * b[k * 4 + i % 4]).sum())
}

/// `[p, w] · m` (w = 1 for points, 0 for directions).
pub(super) fn transform(m: &Matrix, p: [f32; 3], w: f32) -> [f32; 3] {
    core::array::from_fn(|c| p[0] * m[c] + p[1] * m[4 + c] + p[2] * m[8 + c] + w * m[12 + c])
}

/// Babylon's `RotationYawPitchRoll(ry, rx, rz)`: `R = Rz(rz) · Rx(rx) · Ry(ry)`.
#[rustfmt::skip]
pub(super) fn euler_matrix([rx, ry, rz]: [f32; 3]) -> Matrix {
    let ((sx, cx), (sy, cy), (sz, cz)) = (libm::sincosf(rx), libm::sincosf(ry), libm::sincosf(rz));
    let x = [1., 0., 0., 0.,   0., cx, sx, 0.,   0., -sx, cx, 0.,   0., 0., 0., 1.];
    let y = [cy, 0., -sy, 0.,  0., 1., 0., 0.,   sy, 0., cy, 0.,    0., 0., 0., 1.];
    let z = [cz, sz, 0., 0.,   -sz, cz, 0., 0.,  0., 0., 1., 0.,    0., 0., 0., 1.];
    mul(&mul(&z, &x), &y)
}

/// Babylon's `Matrix.FromQuaternion` (the quaternion is used as written, not normalised).
#[rustfmt::skip]
pub(super) fn quat_matrix([x, y, z, w]: [f32; 4]) -> Matrix {
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, xw, yw, zw) = (x * y, x * z, y * z, x * w, y * w, z * w);
    [
        1. - 2. * (yy + zz), 2. * (xy + zw),      2. * (xz - yw),      0.,
        2. * (xy - zw),      1. - 2. * (zz + xx), 2. * (yz + xw),      0.,
        2. * (xz + yw),      2. * (yz - xw),      1. - 2. * (yy + xx), 0.,
        0.,                  0.,                  0.,                  1.,
    ]
}

/// A node's position, rotation and scaling as written in the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Trs {
    position: [f32; 3],
    rotation: [f32; 3],
    quaternion: Option<[f32; 4]>,
    scaling: [f32; 3],
}

impl Trs {
    pub(super) const IDENTITY: Trs = Trs { position: [0.; 3], rotation: [0.; 3], quaternion: None, scaling: [1.; 3] };

    /// Reads the fields of `obj`, taking the missing ones from `base`.
    pub(super) fn read(obj: &Value, base: Trs) -> Res<Trs> {
        Ok(Trs {
            position: vector(obj, "position")?.unwrap_or(base.position),
            rotation: vector(obj, "rotation")?.unwrap_or(base.rotation),
            quaternion: vector(obj, "rotationQuaternion")?.or(base.quaternion),
            scaling: vector(obj, "scaling")?.unwrap_or(base.scaling),
        })
    }

    /// Position, rotation (the quaternion when there is one, else the Euler angles) and scaling.
    pub(super) fn rest(&self) -> ([f32; 3], Rotation, [f32; 3]) {
        let rotation = self.quaternion.map_or(Rotation::Euler(self.rotation), Rotation::Quaternion);
        (self.position, rotation, self.scaling)
    }

    pub(super) fn rotation_matrix(&self) -> Matrix {
        self.quaternion.map_or_else(|| euler_matrix(self.rotation), quat_matrix)
    }

    /// `Local = S · R · T`.
    pub(super) fn matrix(&self) -> Matrix {
        let mut m = self.rotation_matrix();
        for (i, v) in m[..12].iter_mut().enumerate() {
            *v *= self.scaling[i / 4];
        }
        m[12..15].copy_from_slice(&self.position);
        m
    }

    /// Applies the first frame of `autoAnimate` animations (see the module documentation).
    pub(super) fn animate(&mut self, obj: &Value) -> Res<()> {
        if !flag(obj, "autoAnimate", false)? {
            return Ok(());
        }
        let frame = scalar(obj, "autoAnimateFrom", 0.)?;
        for (i, anim) in list(obj, "animations")?.iter().enumerate() {
            let in_anim = |m: String| format!("animations[{i}].{m}");
            let Some(property) = text(anim, "property").map_err(in_anim)? else {
                continue;
            };
            let (base, component) = property.split_once('.').map_or((&*property, None), |(b, c)| (b, Some(c)));
            let Some(value) = key_value(anim, frame).map_err(in_anim)? else {
                continue;
            };
            let target: &mut [f32] = match base {
                "position" => &mut self.position,
                "rotation" => &mut self.rotation,
                "scaling" => &mut self.scaling,
                "rotationQuaternion" => self.quaternion.get_or_insert([0., 0., 0., 1.]),
                _ => continue,
            };
            match component.and_then(|c| ["x", "y", "z", "w"].iter().position(|&n| n == c)) {
                Some(k) => {
                    if let (Some(t), Some(v)) = (target.get_mut(k), value.first()) {
                        *t = *v;
                    }
                }
                None if component.is_none() => target.iter_mut().zip(&value).for_each(|(t, v)| *t = *v),
                None => {}
            }
        }
        Ok(())
    }
}

/// An animation's value at `frame`: linear between the surrounding keys, clamped at the ends
/// (the numbers each key's `values` starts with: tangents packed after them are ignored).
fn key_value(anim: &Value, frame: f32) -> Res<Option<Vec<f32>>> {
    let mut prev: Option<(f32, Vec<f32>)> = None;
    for (i, key) in list(anim, "keys")?.iter().enumerate() {
        let in_key = |m: String| format!("keys[{i}].{m}");
        let f = scalar(key, "frame", 0.).map_err(in_key)?;
        let v = leading_floats(key, "values").map_err(in_key)?;
        if f >= frame {
            return Ok(Some(match prev {
                Some((pf, pv)) if f > pf && pv.len() == v.len() => {
                    let t = (frame - pf) / (f - pf);
                    pv.iter().zip(&v).map(|(a, b)| a + (b - a) * t).collect()
                }
                _ => v,
            }));
        }
        prev = Some((f, v));
    }
    Ok(prev.map(|(_, v)| v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn rotation_y_follows_the_spec() {
        // Ry(a) = [c 0 -s; 0 1 0; s 0 c], p' = p · M.
        let m = euler_matrix([0., 0.5, 0.]);
        let p = transform(&m, [1., 0., 0.], 1.);
        assert!(close(&p, &[libm::cosf(0.5), 0., -libm::sinf(0.5)]), "{p:?}");
        // The same rotation as a quaternion (x, y, z, w) = (0, sin(a/2), 0, cos(a/2)).
        let q = quat_matrix([0., libm::sinf(0.25), 0., libm::cosf(0.25)]);
        assert!(close(&m, &q));
    }

    #[test]
    fn euler_order_is_z_then_x_then_y() {
        let (rx, ry, rz) = (0.3, -0.7, 1.1);
        let single = |r| euler_matrix(r);
        let expected = mul(&mul(&single([0., 0., rz]), &single([rx, 0., 0.])), &single([0., ry, 0.]));
        assert!(close(&euler_matrix([rx, ry, rz]), &expected));
        // Rz(a) maps x to (c, s, 0); Rx(a) maps y to (0, c, s).
        assert!(close(&transform(&single([0., 0., 0.4]), [1., 0., 0.], 0.), &[libm::cosf(0.4), libm::sinf(0.4), 0.]));
        assert!(close(&transform(&single([0.4, 0., 0.]), [0., 1., 0.], 0.), &[0., libm::cosf(0.4), libm::sinf(0.4)]));
    }

    #[test]
    fn local_matrix_is_scale_rotate_translate() {
        let trs = Trs {
            position: [1., 2., 3.],
            rotation: [0., core::f32::consts::FRAC_PI_2, 0.],
            quaternion: None,
            scaling: [2., 1., 1.],
        };
        // (1,0,0) scaled to (2,0,0), rotated by Ry(90°) to (0,0,-2), translated to (1,2,1).
        assert!(close(&transform(&trs.matrix(), [1., 0., 0.], 1.), &[1., 2., 1.]));
        // World = Local · World(parent): the child's transform applies first.
        let parent = Trs { position: [10., 0., 0.], ..Trs::IDENTITY }.matrix();
        assert!(close(&transform(&mul(&trs.matrix(), &parent), [1., 0., 0.], 1.), &[11., 2., 1.]));
    }
}
