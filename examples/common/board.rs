//! What both board firmwares share (included with `#[path]` by `examples/rp2040` and
//! `examples/stm32f411`): the frame and band geometry, the DMA-ready band buffer, the ST7789
//! command codes, and the scene — the reference frame's camera, lights and options
//! (`soft3d::testing::reference`), Suzanne turned by an angle, drawn band by band into `Rgb565Be`
//! pixels that go to the display's DMA as they are.

use soft3d::testing::reference;
use soft3d::{Band, Camera, FrameColor, Lights, Mat4, Model, RenderOptions, Renderer, Rgb565Be, Scratch};

/// Frame width (the ST7789's 240x240).
pub const WIDTH: u16 = reference::WIDTH;
/// Frame height.
pub const HEIGHT: u16 = reference::HEIGHT;
/// Bands a frame is drawn in.
pub const BANDS: usize = 8;
/// Rows a band.
pub const BAND_ROWS: usize = HEIGHT as usize / BANDS;
/// Pixels a band.
pub const BAND_PIXELS: usize = WIDTH as usize * BAND_ROWS;
const _: () = assert!(BAND_ROWS * BANDS == HEIGHT as usize, "BANDS must divide HEIGHT");

/// A band of pixels, ready for SPI.
pub type Pixels = [Rgb565Be; BAND_PIXELS];
/// A band of depth.
pub type Depth = [u16; BAND_PIXELS];

// `Rgb565Be` is a one-field struct around `[u8; 2]`. Its size being exactly 2 means the field
// fills it (offset 0, no padding), and alignment 1 means a `[Rgb565Be; N]` is exactly the
// `2 * N` bytes of the pixels in order: what the DMA reads in `BandBuf::read_buffer`.
const _: () = assert!(core::mem::size_of::<Rgb565Be>() == 2 && core::mem::align_of::<Rgb565Be>() == 1);

/// A colour band buffer, owned: whoever holds this value is the only one touching the pixels
/// (the renderer, the DMA engine, or the other core).
pub struct BandBuf(pub &'static mut Pixels);

// SAFETY: the pointer and length describe `self.0`, a `'static` array of `BAND_PIXELS` pixels
// of 2 bytes each (asserted above), i.e. `2 * BAND_PIXELS` initialised bytes. The array does
// not move when the `BandBuf` moves, it is never freed, and nothing else can touch it while
// the DMA transfer owns the `BandBuf` (it is a unique `&'static mut`).
unsafe impl embedded_dma::ReadBuffer for BandBuf {
    type Word = u8;

    unsafe fn read_buffer(&self) -> (*const u8, usize) {
        (self.0.as_ptr().cast::<u8>(), core::mem::size_of::<Pixels>())
    }
}

/// ST7789 command codes.
pub mod cmd {
    pub const SWRESET: u8 = 0x01;
    pub const SLPOUT: u8 = 0x11;
    pub const NORON: u8 = 0x13;
    pub const INVON: u8 = 0x21;
    pub const DISPON: u8 = 0x29;
    pub const CASET: u8 = 0x2A;
    pub const RASET: u8 = 0x2B;
    pub const RAMWR: u8 = 0x2C;
    pub const MADCTL: u8 = 0x36;
    pub const COLMOD: u8 = 0x3A;
}

/// The `CASET` and `RASET` parameters that open band `band` (full width) for `RAMWR`.
pub fn band_window(band: usize) -> [(u8, [u8; 4]); 2] {
    let be = |a: u16, b: u16| [(a >> 8) as u8, a as u8, (b >> 8) as u8, b as u8];
    let (y0, y1) = ((band * BAND_ROWS) as u16, ((band + 1) * BAND_ROWS - 1) as u16);
    [(cmd::CASET, be(0, WIDTH - 1)), (cmd::RASET, be(y0, y1))]
}

/// The ST7789 start-up after its hardware reset: `(command, parameters, then wait ms)`.
pub const INIT: &[(u8, &[u8], u32)] = &[
    (cmd::SWRESET, &[], 150),
    (cmd::SLPOUT, &[], 120),   // 5 ms before the next command, 120 ms before any SLPIN
    (cmd::COLMOD, &[0x55], 0), // 65k colours, 16 bits a pixel
    (cmd::MADCTL, &[0x00], 0), // top to bottom, left to right, RGB order
    (cmd::INVON, &[], 0),
    (cmd::NORON, &[], 10),
    (cmd::DISPON, &[], 10),
];

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
            camera: reference::camera(WIDTH, HEIGHT),
            lights: reference::lights(),
            // The RP2040's Cortex-M0+ has no FPU: vertices in integers (RenderOptions).
            opts: RenderOptions { fixed_vertices: cfg!(target_abi = "eabi"), ..reference::options() },
            background: Rgb565Be::from_rgb888([0, 0, 0]),
        }
    }

    /// Renders the band starting at `first_row` with the model turned by `angle` radians.
    ///
    /// # Panics
    /// If the slices do not make a band of the 240x240 frame (a constant error in the firmware).
    pub fn render(&self, color: &mut [Rgb565Be], depth: &mut [u16], first_row: u16, angle: f32) {
        let mut band = Band::new(color, depth, WIDTH, HEIGHT, first_row).expect("band fits the frame");
        band.clear(self.background);
        let turn = Mat4::from_rotation_y(angle);
        let renderer = Renderer::new(&self.camera, &self.lights, self.opts);
        renderer.draw(&mut band, &self.model, turn, &mut Scratch::none()).expect("no scratch is needed in stored order");
    }
}
