//! `Camera::fit` frames a real model: every vertex in view, the model filling the asked-for
//! share of the frame, from any direction. (Here, not beside `Camera`: the model comes from the
//! host converter, which the `no_std` core does not use.)

use soft3d::{Camera, CameraError, Model, Vec3};

/// A fitted camera sees every vertex, and the model fills the asked-for share of the
/// frame's limiting dimension, from any direction.
#[test]
fn a_fitted_camera_fills_the_frame_with_the_whole_model() {
    let bytes = soft3d::convert::emit(&soft3d::convert::Scene::cube(), &Default::default()).unwrap();
    let model = Model::parse(&bytes).unwrap();
    let views = [(Vec3::Z, 1.0), (Vec3::new(1.0, -0.7, 0.4), 4.0 / 3.0), (Vec3::NEG_X, 0.5)];
    for ((direction, aspect), ortho) in views.into_iter().flat_map(|v| [(v, false), (v, true)]) {
        let camera = if ortho {
            Camera::fit_orthographic(&model, (direction, Vec3::Y), aspect, 0.95).unwrap()
        } else {
            Camera::fit(&model, (direction, Vec3::Y), 0.8, aspect, 0.95).unwrap()
        };
        assert_eq!(camera.orthographic_size().is_some(), ortho);
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for (mesh, world) in model.draws() {
            for i in 0..mesh.vertex_count() {
                let p = (world * mesh.dequantize()).transform_point3(mesh.position_stored(i));
                let ndc = camera.view_projection().project_point3(p);
                (lo, hi) = (lo.min(ndc), hi.max(ndc));
            }
        }
        let within = |v: f32| (-1.0..=1.0).contains(&v);
        assert!([lo.x, lo.y, lo.z, hi.x, hi.y, hi.z].into_iter().all(within), "{direction} ortho {ortho}: {lo} {hi}");
        let filled = ((hi.x - lo.x) / 2.0).max((hi.y - lo.y) / 2.0);
        assert!((filled - 0.95).abs() < 1e-3, "{direction} ortho {ortho}: fills {filled}");
        // Centred along the limiting dimension.
        let centre = if hi.x - lo.x > hi.y - lo.y { lo.x + hi.x } else { lo.y + hi.y };
        assert!(centre.abs() < 1e-3, "{direction} ortho {ortho}: centre {centre}");
    }
    assert_eq!(Camera::fit(&model, (Vec3::Y, Vec3::Y), 0.8, 1.0, 0.95), Err(CameraError::BadLookAt));
    assert_eq!(Camera::fit(&model, (Vec3::Z, Vec3::Y), 0.8, 1.0, 0.0), Err(CameraError::BadProjection));
    assert_eq!(Camera::fit_orthographic(&model, (Vec3::Y, Vec3::Y), 1.0, 0.95), Err(CameraError::BadLookAt));
    assert_eq!(Camera::fit_orthographic(&model, (Vec3::Z, Vec3::Y), 0.0, 0.95), Err(CameraError::BadProjection));
}
