//! Internals that soft3d's own integration tests, benches and firmware examples reach into: not
//! part of the API (hidden from the docs, free to change in any release). Users draw through
//! [`Renderer`](crate::Renderer) and the types `lib.rs` re-exports.

pub use crate::light::{FixedLights, PixelLights, PreparedLights};
/// The float maths and conversions of [`crate`]'s `math` module.
pub mod math {
    pub use crate::math::*;
}
pub use crate::pipeline::raster::{
    facing, step_varyings, Reject, ScreenVertex, Setup, Span, SpanSink, Window, MAX_COORD, MAX_EXTENT,
};
pub use crate::pipeline::{
    clip_triangle, posed_position, ClipResult, ClipVertex, GuardBand, Polygon, MAX_VARYINGS, VARYING_FRAC,
};
pub use crate::texture::{modulate, modulate565, Repeat565, Sampler};

pub mod reference {
    //! The reference "Suzanne frame" shared by the benchmarks, the QEMU firmware and the host
    //! comparison test, so that every figure is measured on the same picture:
    //! `assets/suzanne/monkey.babylon` (converted with the UV origin at the top, as that file
    //! needs) yawed 0.5 rad, camera at (0, 0, -4) looking at the origin with a vertical field of
    //! view of 0.8 rad, near 0.1, far 100; ambient 0.2 plus one directional light along
    //! (0.5, -0.5, 1) with intensity 0.8; textured (nearest, wrap), Gouraud, z-buffered, back faces
    //! culled. At 240x240 it covers 14,457 pixels (with exact f32 positions).

    use crate::camera::Camera;
    use crate::light::Lights;
    use crate::math::{Mat4, Vec3};
    use crate::pipeline::RenderOptions;

    /// Frame width of the reference frame.
    pub const WIDTH: u16 = 240;
    /// Frame height of the reference frame.
    pub const HEIGHT: u16 = 240;
    /// Pixels the reference frame covers at 240x240.
    pub const COVERED_PIXELS: u32 = 14_457;

    /// The reference camera for a frame of `width` x `height`.
    ///
    /// # Panics
    /// Never for a non-zero size: the camera's constants are valid.
    #[must_use]
    pub fn camera(width: u16, height: u16) -> Camera {
        let aspect = width as f32 / height.max(1) as f32;
        Camera::perspective(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, 0.8, aspect, 0.1, 100.0)
            .unwrap_or_else(|_| unreachable!("constant camera is valid"))
    }

    /// The reference lights: ambient 0.2 and a directional light of intensity 0.8.
    #[must_use]
    pub fn lights() -> Lights<1> {
        let mut lights = Lights::new(Vec3::splat(0.2));
        let _ = lights.push(Lights::<1>::directional(Vec3::new(0.5, -0.5, 1.0), 0.8));
        lights
    }

    /// The model transform: the mesh yawed by 0.5 rad (Babylon's `RotationY`).
    #[must_use]
    pub fn transform() -> Mat4 {
        Mat4::from_rotation_y(0.5)
    }

    /// Textured nearest, Gouraud, exact perspective correction.
    #[must_use]
    pub fn options() -> RenderOptions {
        RenderOptions::default()
    }
}
