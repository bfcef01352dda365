//! The scene both board firmwares draw (included with `#[path]` by `examples/rp2040` and
//! `examples/stm32f411`): the reference frame's camera, lights and options
//! (`soft3d::reference`), Suzanne turned by an angle, drawn band by band into `Rgb565Be`
//! pixels that go to the display's DMA as they are.

use soft3d::format::Model;
use soft3d::math::Mat4;
use soft3d::{reference, Band, Camera, FrameColor, Lights, RenderOptions, Rgb565Be};

/// Everything needed to render a band.
#[derive(Clone)]
pub struct Scene {
    model: Model<'static>,
    camera: Camera,
    lights: Lights<1>,
    opts: RenderOptions,
    background: Rgb565Be,
}

impl Scene {
    /// Parses the embedded `.s3d`.
    ///
    /// # Panics
    /// If the embedded model does not parse (a build error, caught on the first boot).
    pub fn new(s3d: &'static [u8]) -> Self {
        let model = Model::parse(s3d).expect("embedded .s3d parses");
        Scene {
            model,
            camera: reference::camera(reference::WIDTH, reference::HEIGHT),
            lights: reference::lights(),
            opts: reference::options(),
            background: Rgb565Be::from_rgb888([0, 0, 0]),
        }
    }

    /// Renders the band starting at `first_row` with the model turned by `angle` radians.
    ///
    /// # Panics
    /// If the slices do not make a band of the 240x240 frame (a constant error in the firmware).
    pub fn render(&self, color: &mut [Rgb565Be], depth: &mut [u16], first_row: u16, angle: f32) {
        let (w, h) = (reference::WIDTH, reference::HEIGHT);
        let mut band = Band::new(color, depth, w, h, first_row).expect("band fits the frame");
        band.clear(self.background);
        let turn = Mat4::from_rotation_y(angle);
        soft3d::draw_model(&mut band, &self.model, turn, &self.camera, &self.lights, &self.opts);
    }
}
