//! Cameras: Babylon.js `LookAtLH` view with a `PerspectiveFovLH` or `OrthoLH` projection, as
//! the caller sets them up per frame. The matrices themselves are `math`'s; projecting vertices
//! is the pipeline's.

use crate::format::{Model, SceneCamera};
use crate::math::{look_at_lh, orthographic_lh, perspective_lh, Mat4, Vec3};

/// A camera: view and projection matrices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World to view space.
    pub view: Mat4,
    /// View to clip space.
    pub projection: Mat4,
    /// Eye position in world space.
    pub eye: Vec3,
    /// The point looked at.
    pub target: Vec3,
    /// Near clip distance.
    pub near: f32,
    /// Far clip distance.
    pub far: f32,
}

/// Why a camera could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraError {
    /// `eye == target`, or the view direction is parallel to +y (or to the given `up`), or a
    /// value is not finite.
    BadLookAt,
    /// Field of view not in (0, pi), aspect <= 0, near <= 0 (perspective) or far <= near.
    BadProjection,
}

impl core::fmt::Display for CameraError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            CameraError::BadLookAt => "camera: eye equals target, looks straight up/down, or is not finite",
            CameraError::BadProjection => "camera: field of view, aspect, near or far out of range",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for CameraError {}

impl Camera {
    /// A perspective camera at `eye` looking at `target` (up = +y) with vertical field of view
    /// `fov_y` (radians), `aspect` = width / height, and clip distances `near` < `far`.
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate look-at or out-of-range projection values.
    pub fn perspective(
        eye: Vec3,
        target: Vec3,
        fov_y: f32,
        aspect: f32,
        near: f32,
        far: f32,
    ) -> Result<Self, CameraError> {
        Self::perspective_up((eye, target, Vec3::Y), fov_y, aspect, near, far)
    }

    /// [`Camera::perspective`] with `up` (not parallel to the view) pointing up on screen: for
    /// a camera looking straight up or down, which +y cannot orient, or a tilted horizon.
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate look-at or out-of-range projection values.
    pub fn perspective_up(
        (eye, target, up): (Vec3, Vec3, Vec3),
        fov_y: f32,
        aspect: f32,
        near: f32,
        far: f32,
    ) -> Result<Self, CameraError> {
        let ok = fov_y > 0.0
            && fov_y < core::f32::consts::PI
            && aspect > 0.0
            && near > 0.0
            && far > near
            && far.is_finite()
            && aspect.is_finite();
        if !ok {
            return Err(CameraError::BadProjection);
        }
        let view = look_at(eye, target, up)?;
        Ok(Camera { view, projection: perspective_lh(fov_y, aspect, near, far), eye, target, near, far })
    }

    /// An orthographic camera showing a `width` x `height` (world units) window.
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate look-at or out-of-range values.
    pub fn orthographic(
        eye: Vec3,
        target: Vec3,
        width: f32,
        height: f32,
        near: f32,
        far: f32,
    ) -> Result<Self, CameraError> {
        Self::orthographic_up((eye, target, Vec3::Y), width, height, near, far)
    }

    /// [`Camera::orthographic`] with `up` pointing up on screen (see [`Camera::perspective_up`]).
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate look-at or out-of-range values.
    pub fn orthographic_up(
        (eye, target, up): (Vec3, Vec3, Vec3),
        width: f32,
        height: f32,
        near: f32,
        far: f32,
    ) -> Result<Self, CameraError> {
        let ok = width > 0.0
            && height > 0.0
            && far > near
            && (far - near).is_finite()
            && width.is_finite()
            && height.is_finite();
        if !ok {
            return Err(CameraError::BadProjection);
        }
        let view = look_at(eye, target, up)?;
        Ok(Camera { view, projection: orthographic_lh(width, height, near, far), eye, target, near, far })
    }

    /// The camera stored in a scene, for a frame of the given aspect ratio.
    ///
    /// # Errors
    /// [`CameraError`] when the stored camera is degenerate.
    pub fn from_scene(c: &SceneCamera, aspect: f32) -> Result<Self, CameraError> {
        Self::perspective(c.position, c.target, c.fov, aspect, c.near, c.far)
    }

    /// A perspective camera that shows every mesh and instance of `model` (by their bounding
    /// spheres), looking slightly down along +z; for scenes that have no camera of their own.
    ///
    /// # Errors
    /// [`CameraError`] when the model has no finite bounds or the projection values are bad.
    pub fn framing(model: &Model<'_>, fov_y: f32, aspect: f32) -> Result<Self, CameraError> {
        let (centre, radius) = model.bounds().ok_or(CameraError::BadLookAt)?;
        // Far enough that the bounding sphere fits the vertical field of view.
        let distance = radius / crate::math::sin(fov_y * 0.5).max(1e-3);
        let eye = centre + Vec3::new(0.0, 0.3, -1.0).normalize() * distance;
        Self::perspective(eye, centre, fov_y, aspect, distance * 0.01, distance + radius * 2.0)
    }

    /// A perspective camera looking along `direction` (with `up` up on screen) from as close
    /// as it can while every vertex of `model` (meshes and instances) is in view: the model's
    /// projected bounds fill `fill` (in (0, 1], e.g. 0.95) of the frame's limiting dimension,
    /// centred, and the near and far planes hug its depth (1% to spare). The bounding sphere
    /// of [`Camera::framing`] leaves most models at a third of the frame; this fits their
    /// vertices.
    ///
    /// # Errors
    /// [`CameraError::BadLookAt`] when the model has no vertices or `direction` is zero or
    /// parallel to `up`; [`CameraError::BadProjection`] for an out-of-range field of view,
    /// aspect or `fill`.
    pub fn fit(
        model: &Model<'_>,
        (direction, up): (Vec3, Vec3),
        fov_y: f32,
        aspect: f32,
        fill: f32,
    ) -> Result<Self, CameraError> {
        let fov_ok = fov_y > 0.0 && fov_y < core::f32::consts::PI && aspect > 0.0 && aspect.is_finite();
        if !(fov_ok && fill > 0.0 && fill <= 1.0) {
            return Err(CameraError::BadProjection);
        }
        let axes = view_axes(direction, up)?;
        let (x, y, z) = axes;
        // The half-extents' slopes, narrowed so that the model fills `fill` of them.
        let ty = crate::math::sin(fov_y * 0.5) / crate::math::cos(fov_y * 0.5) * fill;
        let tx = ty * aspect;
        // Every vertex `p` (in the camera's axes) must satisfy |p.y - e.y| <= ty (p.z - e.z)
        // and the same along x: the closest eye has e.z = (a + b) / 2t and e.y = (b - a) / 2,
        // with a = min(t p.z - p.y) and b = min(t p.z + p.y) over the vertices.
        let [ax, bx, ay, by, nearest, minus_farthest] = view_bounds(model, axes, (tx, ty))?;
        let ez = ((ax + bx) / (2.0 * tx)).min((ay + by) / (2.0 * ty));
        let eye = x * ((bx - ax) / 2.0) + y * ((by - ay) / 2.0) + z * ez;
        let (near, far) = ((nearest - ez) * 0.99, (-minus_farthest - ez) * 1.01);
        let far = far.max(1e-6);
        let near = if near > far * 1e-4 { near } else { far * 1e-4 };
        let target = eye + z * ((near + far) * 0.5);
        Self::perspective_up((eye, target, up), fov_y, aspect, near, far)
    }

    /// [`Camera::fit`] for an orthographic camera: looking along `direction` (with `up` up on
    /// screen) at the centre of `model`'s projected bounds, its height (and width, `aspect`
    /// times it) chosen so that they fill `fill` of the frame's limiting dimension, and the eye
    /// just in front of the nearest vertex. [`Camera::orthographic_size`] tells the size.
    ///
    /// # Errors
    /// As [`Camera::fit`]'s (without a field of view).
    pub fn fit_orthographic(
        model: &Model<'_>,
        (direction, up): (Vec3, Vec3),
        aspect: f32,
        fill: f32,
    ) -> Result<Self, CameraError> {
        if !(aspect > 0.0 && aspect.is_finite() && fill > 0.0 && fill <= 1.0) {
            return Err(CameraError::BadProjection);
        }
        let axes = view_axes(direction, up)?;
        let (x, y, z) = axes;
        // With zero slopes the bounds are -max x, min x, -max y, min y, min z, -max z.
        let [ax, bx, ay, by, nearest, minus_farthest] = view_bounds(model, axes, (0.0, 0.0))?;
        let (width, height, depth) = (-(ax + bx), -(ay + by), -minus_farthest - nearest);
        let size = (height.max(width / aspect) / fill).max(1e-6);
        // 1% of the depth (or of the size, for a flat model) in front and behind.
        let margin = (depth.max(size) * 0.01).max(1e-6);
        let eye = x * ((bx - ax) / 2.0) + y * ((by - ay) / 2.0) + z * (nearest - 2.0 * margin);
        let target = eye + z * (depth * 0.5 + 2.0 * margin);
        Self::orthographic_up((eye, target, up), size * aspect, size, margin, depth + 3.0 * margin)
    }

    /// The width and height an orthographic camera shows (in world units), `None` for a
    /// perspective one.
    #[must_use]
    pub fn orthographic_size(&self) -> Option<(f32, f32)> {
        let p = &self.projection;
        (p.w_axis.w == 1.0).then(|| (2.0 / p.x_axis.x, 2.0 / p.y_axis.y))
    }

    /// `projection · view`: world to clip space.
    #[must_use]
    pub fn view_projection(&self) -> Mat4 {
        self.projection * self.view
    }
}

/// The camera's right, up and forward axes for a view along `direction` with `up` up.
fn view_axes(direction: Vec3, up: Vec3) -> Result<(Vec3, Vec3, Vec3), CameraError> {
    let z = crate::math::normalize_or_zero(direction);
    let x = crate::math::normalize_or_zero(up.cross(z));
    if z == Vec3::ZERO || x == Vec3::ZERO || !(z.is_finite() && x.is_finite()) {
        return Err(CameraError::BadLookAt);
    }
    Ok((x, z.cross(x), z))
}

/// Over every vertex `p` of `model` (meshes and instances), in the camera's `axes`, with the
/// half-extents' slopes `(tx, ty)`: the minimum of tx p.z - p.x, tx p.z + p.x, ty p.z - p.y,
/// ty p.z + p.y, p.z and -p.z. `BadLookAt` when the model has no finite vertex.
fn view_bounds(
    model: &Model<'_>,
    (x, y, z): (Vec3, Vec3, Vec3),
    (tx, ty): (f32, f32),
) -> Result<[f32; 6], CameraError> {
    let mut bounds = [f32::INFINITY; 6];
    for (mesh, world) in model.draws() {
        let to_world = world * mesh.dequantize();
        for i in 0..mesh.vertex_count() {
            let p = to_world.transform_point3(mesh.position_stored(i));
            let (px, py, pz) = (p.dot(x), p.dot(y), p.dot(z));
            let values = [tx * pz - px, tx * pz + px, ty * pz - py, ty * pz + py, pz, -pz];
            for (b, v) in bounds.iter_mut().zip(values) {
                *b = b.min(v);
            }
        }
    }
    if bounds.iter().all(|b| b.is_finite()) {
        Ok(bounds)
    } else {
        Err(CameraError::BadLookAt)
    }
}

fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Result<Mat4, CameraError> {
    if !eye.is_finite() || !target.is_finite() || !up.is_finite() {
        return Err(CameraError::BadLookAt);
    }
    look_at_lh(eye, target, up).ok_or(CameraError::BadLookAt)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera straight above its target cannot be oriented by +y; with +z up it sees the
    /// target at the centre, +z towards the top of the frame and +x to the right.
    #[test]
    fn an_up_vector_orients_a_camera_looking_straight_down() {
        let (eye, target) = (Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO);
        assert_eq!(Camera::perspective(eye, target, 0.8, 1.0, 0.1, 100.0), Err(CameraError::BadLookAt));
        let camera = Camera::perspective_up((eye, target, Vec3::Z), 0.8, 1.0, 0.1, 100.0).unwrap();
        let ndc = |p: Vec3| camera.view_projection().project_point3(p);
        assert!(ndc(target).x.abs() < 1e-6 && ndc(target).y.abs() < 1e-6);
        assert!(ndc(Vec3::Z).y > 0.0 && ndc(Vec3::Z).x.abs() < 1e-6, "{:?}", ndc(Vec3::Z));
        assert!(ndc(Vec3::X).x > 0.0 && ndc(Vec3::X).y.abs() < 1e-6, "{:?}", ndc(Vec3::X));
        let ortho = Camera::orthographic_up((eye, target, Vec3::Z), 4.0, 4.0, 0.1, 100.0).unwrap();
        assert!((ortho.view_projection().project_point3(Vec3::Z).y - 0.5).abs() < 1e-6);
        for up in [Vec3::Y, Vec3::ZERO, Vec3::NAN] {
            assert_eq!(Camera::perspective_up((eye, target, up), 0.8, 1.0, 0.1, 100.0), Err(CameraError::BadLookAt));
        }
    }
}
