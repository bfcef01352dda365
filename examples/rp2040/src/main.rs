//! soft3d on a Raspberry Pi Pico (RP2040): Suzanne, textured and Gouraud-lit, turning on a
//! 240x240 ST7789 over SPI0 at 62.5 MHz.
//!
//! The frame is drawn in eight 240x30 bands. Each band is rendered into one of several colour
//! band buffers (`Rgb565Be`, big-endian RGB565: the ST7789's byte order, so a band goes to the
//! display as it is) with a `u16` depth band, then sent by DMA into the address window of its
//! rows while the CPU renders the next band into another buffer (ping-pong).
//!
//! With the `dual-core` feature, core 1 renders the odd bands and core 0 the even ones, each
//! into buffers it owns at the time and with its own depth band; core 0 alone drives the SPI
//! and DMA. Buffers change hands through the SIO FIFOs (see [`dual`] for why that is sound).
//!
//! Wiring (see README.md): SCK GP18, MOSI GP19, CS GP17, DC GP16, RST GP20, backlight GP21.
#![no_std]
#![no_main]

use core::f32::consts::TAU;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{OutputPin, StatefulOutputPin};
use embedded_hal::spi::SpiBus;
use panic_halt as _;
use rp2040_hal as hal;

use hal::clocks::Clock;
use hal::dma::{single_buffer, DMAExt};
use hal::fugit::RateExtU32;
use hal::gpio::bank0::{Gpio16, Gpio17, Gpio18, Gpio19};
use hal::gpio::{FunctionSio, FunctionSpi, OutputDriveStrength, OutputSlewRate, Pin, PullDown, SioOutput};
use hal::pac;
use soft3d::Rgb565Be;

/// The second-stage bootloader for the Pico's W25Q16JV flash (W25Q080-compatible), placed at
/// the start of flash by memory.x.
#[link_section = ".boot2"]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

/// Suzanne, converted at build time (see build.rs) and read in place from flash.
static SUZANNE: &[u8] = soft3d::include_s3d!(concat!(env!("OUT_DIR"), "/suzanne.s3d"));

/// The Pico's crystal.
const XTAL_FREQ_HZ: u32 = 12_000_000;
/// SPI clock: clk_peri (= clk_sys, 125 MHz) / 2, the PL022's fastest, and within the
/// ST7789's 16 ns minimum write cycle.
const SPI_HZ: u32 = 62_500_000;

/// One full turn every this many microseconds, whatever the frame rate.
const TURN_US: u64 = 8_000_000;

/// Colour band buffers: two for ping-pong on one core; four with `dual-core` (at most one
/// being rendered on each core, one being sent by DMA, and one spare).
#[cfg(not(feature = "dual-core"))]
const COLOR_BUFFERS: usize = 2;
#[cfg(feature = "dual-core")]
const COLOR_BUFFERS: usize = 4;

#[path = "../../common/board.rs"]
mod board;
use board::{cmd, BandBuf, Depth, Pixels, Scene, BANDS, BAND_PIXELS, BAND_ROWS};

type SpiPins = (Pin<Gpio19, FunctionSpi, PullDown>, Pin<Gpio18, FunctionSpi, PullDown>);
type Spi0 = hal::Spi<hal::spi::Enabled, pac::SPI0, SpiPins, 8>;
type DmaCh = hal::dma::Channel<hal::dma::CH0>;
type OutPin<I> = Pin<I, FunctionSio<SioOutput>, PullDown>;

/// A minimal ST7789 driver: init, address window, and band transfers by DMA.
///
/// The link is either idle (`idle` holds the DMA channel and the SPI) or busy (`busy` holds the
/// running transfer, which owns channel, SPI and the band being sent); never both, never
/// neither.
struct Display {
    idle: Option<(DmaCh, Spi0)>,
    busy: Option<single_buffer::Transfer<DmaCh, BandBuf, Spi0>>,
    dc: OutPin<Gpio16>,
    cs: OutPin<Gpio17>,
}

impl Display {
    /// Hardware reset, then the init sequence: 16-bit colour, default orientation (240x240
    /// panels start at RAM row 0 there), colour inversion (IPS panels), display on.
    fn new(
        spi: Spi0,
        ch: DmaCh,
        dc: OutPin<Gpio16>,
        mut cs: OutPin<Gpio17>,
        rst: &mut impl OutputPin,
        delay: &mut impl DelayNs,
    ) -> Self {
        let _ = cs.set_high();
        let _ = rst.set_high();
        delay.delay_ms(1);
        let _ = rst.set_low();
        delay.delay_us(20); // reset pulse >= 10 us
        let _ = rst.set_high();
        delay.delay_ms(120); // reset cancel, up to 120 ms
        let mut d = Display { idle: Some((ch, spi)), busy: None, dc, cs };
        for &(command, params, wait_ms) in board::INIT {
            d.command(command, params);
            delay.delay_ms(wait_ms);
        }
        d
    }

    /// The SPI while the link is idle.
    fn spi(&mut self) -> &mut Spi0 {
        &mut self.idle.as_mut().expect("display link idle").1
    }

    /// Sends a command byte (DC low) and its parameters (DC high) with CS low around both.
    /// Each part is flushed (the shifter is empty) before DC or CS moves.
    fn command(&mut self, command: u8, params: &[u8]) {
        let _ = self.cs.set_low();
        let _ = self.dc.set_low();
        self.write(&[command]);
        let _ = self.dc.set_high();
        if !params.is_empty() {
            self.write(params);
        }
        let _ = self.cs.set_high();
    }

    fn write(&mut self, bytes: &[u8]) {
        let spi = self.spi();
        // Infallible.
        let _ = SpiBus::<u8>::write(spi, bytes);
        // `write` may return with bytes still in the TX FIFO (after a DMA transfer the RX FIFO
        // holds stale bytes, so its per-byte RX wait does not pace it): wait for BSY to clear.
        let _ = SpiBus::<u8>::flush(spi);
    }

    /// Waits for the transfer in flight, if any, and returns its band buffer.
    fn wait(&mut self) -> Option<BandBuf> {
        let transfer = self.busy.take()?;
        let (ch, buf, mut spi) = transfer.wait();
        // The DMA has pushed the last byte into the TX FIFO; wait until it has been shifted out
        // before CS goes high.
        let _ = SpiBus::<u8>::flush(&mut spi);
        let _ = self.cs.set_high();
        self.idle = Some((ch, spi));
        Some(buf)
    }

    /// Starts sending `buf` as band `band` of the frame and returns the buffer of the previous
    /// transfer (waiting for it first), if there was one.
    fn present(&mut self, buf: BandBuf, band: usize) -> Option<BandBuf> {
        let done = self.wait();
        for (command, params) in board::band_window(band) {
            self.command(command, &params);
        }
        // RAMWR, then the pixels as its parameters: CS stays low until `wait` raises it.
        let _ = self.cs.set_low();
        let _ = self.dc.set_low();
        self.write(&[cmd::RAMWR]);
        let _ = self.dc.set_high();
        let (ch, spi) = self.idle.take().expect("display link idle");
        self.busy = Some(single_buffer::Config::new(ch, buf, spi).start());
        done
    }
}

/// Free colour band buffers (not being rendered, not in flight, not on the other core).
type Pool = heapless::Vec<BandBuf, COLOR_BUFFERS>;

#[hal::entry]
fn main() -> ! {
    let mut pac = pac::Peripherals::take().expect("peripherals");
    let mut watchdog = hal::Watchdog::new(pac.WATCHDOG);
    let clocks = hal::clocks::init_clocks_and_plls(
        XTAL_FREQ_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    )
    .unwrap_or_else(|_| panic!("clocks"));
    let mut timer = hal::Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);
    #[allow(unused_mut)]
    let mut sio = hal::Sio::new(pac.SIO);
    let pins = hal::gpio::Pins::new(pac.IO_BANK0, pac.PADS_BANK0, sio.gpio_bank0, &mut pac.RESETS);

    // Statics, handed out once as `&'static mut` (in .bss, so they count as static RAM).
    let pixels: [&'static mut Pixels; COLOR_BUFFERS] = [
        cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 0"),
        cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 1"),
        #[cfg(feature = "dual-core")]
        cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 2"),
        #[cfg(feature = "dual-core")]
        cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 3"),
    ];
    let mut pool = Pool::new();
    for p in pixels {
        let _ = pool.push(BandBuf(p));
    }
    let depth: &'static mut Depth = cortex_m::singleton!(: Depth = [0; BAND_PIXELS]).expect("depth band");

    let scene = Scene::new(SUZANNE);

    // The display.
    let mut backlight = pins.gpio21.into_push_pull_output();
    let mut rst = pins.gpio20.into_push_pull_output();
    let dc = pins.gpio16.into_push_pull_output();
    let cs = pins.gpio17.into_push_pull_output();
    let mut mosi = pins.gpio19.into_function::<FunctionSpi>();
    let mut sck = pins.gpio18.into_function::<FunctionSpi>();
    // 62.5 MHz edges: fast slew and 8 mA drive (the pads default to slow slew, 4 mA).
    mosi.set_slew_rate(OutputSlewRate::Fast);
    mosi.set_drive_strength(OutputDriveStrength::EightMilliAmps);
    sck.set_slew_rate(OutputSlewRate::Fast);
    sck.set_drive_strength(OutputDriveStrength::EightMilliAmps);
    // Mode 3 (clock idles high, sample on the rising edge) works with and without CS, and is
    // what the CS-less 240x240 modules need.
    let spi = hal::Spi::<_, _, _, 8>::new(pac.SPI0, (mosi, sck)).init(
        &mut pac.RESETS,
        clocks.peripheral_clock.freq(),
        SPI_HZ.Hz(),
        embedded_hal::spi::MODE_3,
    );
    let dma = pac.DMA.split(&mut pac.RESETS);
    let mut display = Display::new(spi, dma.ch0, dc, cs, &mut rst, &mut timer);
    let _ = backlight.set_high();
    // The on-board LED toggles once a frame.
    let mut led = pins.gpio25.into_push_pull_output();

    #[cfg(feature = "dual-core")]
    let mut core1 = dual::start(&mut pac.PSM, &mut pac.PPB, &mut sio.fifo, scene.clone());

    loop {
        let t = timer.get_counter().ticks();
        let angle = (t % TURN_US) as f32 * (TAU / TURN_US as f32);
        #[cfg(not(feature = "dual-core"))]
        for band in 0..BANDS {
            let buf = pool.pop().expect("a free colour band");
            scene.render(&mut buf.0[..], &mut depth[..], (band * BAND_ROWS) as u16, angle);
            if let Some(sent) = display.present(buf, band) {
                let _ = pool.push(sent);
            }
        }
        #[cfg(feature = "dual-core")]
        dual::frame(&mut core1, &mut sio.fifo, &scene, depth, &mut pool, &mut display, angle);
        let _ = led.toggle();
    }
}

/// Feature `dual-core`: core 1 renders the odd bands.
///
/// Why this is sound:
/// - Nothing is shared mutably. Core 1 gets, at spawn, its own copy of the [`Scene`] (the
///   model is a `&'static [u8]` in flash, read only) and its own depth band (a `&'static mut`
///   that core 0 never sees again). The SPI, the DMA channel and the display pins stay on
///   core 0.
/// - Colour band buffers move between the cores by value: core 0 sends a [`BandBuf`]'s address
///   down the SIO FIFO and forgets it (`into_raw`); core 1 rebuilds the `BandBuf` from it,
///   renders, and sends the address back the same way. At any time exactly one party (core 0's
///   pool, the renderer on either core, the DMA transfer, or the FIFO in between) holds each
///   buffer, so no two `&mut` to one buffer ever exist.
/// - Ordering: the FIFO registers are device memory on the SIO, reached with volatile accesses,
///   and the RP2040 has no data caches. A `fence(SeqCst)` (a `dmb`) before each send and after
///   each receive keeps the compiler and the core from moving the pixel writes of the sender
///   after the send, or the receiver's accesses before the receive.
/// - The FIFOs carry nothing else once `spawn` has returned (it waits for core 1's start-up
///   word), and each direction's protocol has fixed-length messages that fit the 8-word FIFO.
/// - What both cores call: soft3d is pure code on its arguments; rp2040-hal's float and
///   division intrinsics use the ROM float library (reentrant) and each core's own SIO hardware
///   divider; `rom-func-cache` caches ROM function pointers in atomics that both cores may fill
///   with the same value.
/// - Core 1's stack is a `Stack` static handed out once; rp2040-hal puts an MPU guard region at
///   its bottom, so an overflow faults instead of corrupting `.bss`.
#[cfg(feature = "dual-core")]
mod dual {
    use core::sync::atomic::{fence, Ordering};

    use hal::multicore::{Multicore, Stack};
    use hal::sio::SioFifo;

    use super::*;

    /// Core 1's stack: 16 KiB (a draw needs about 4 KiB on thumbv6m).
    static CORE1_STACK: Stack<4096> = Stack::new();

    impl BandBuf {
        /// Gives up the buffer as an address for the FIFO.
        fn into_raw(self) -> u32 {
            self.0.as_mut_ptr() as u32
        }

        /// Takes back a buffer from an address made by [`BandBuf::into_raw`].
        ///
        /// # Safety
        /// `raw` comes from `into_raw` and is used once: the `BandBuf` it stood for was given
        /// up, so this is again the only reference to the buffer.
        unsafe fn from_raw(raw: u32) -> Self {
            // SAFETY: see the function's contract; the address is that of a `'static` `Pixels`.
            BandBuf(unsafe { &mut *(raw as *mut Pixels) })
        }
    }

    fn send(fifo: &mut SioFifo, words: &[u32]) {
        fence(Ordering::SeqCst);
        for &w in words {
            fifo.write_blocking(w);
        }
    }

    fn receive(fifo: &mut SioFifo) -> u32 {
        let w = fifo.read_blocking();
        fence(Ordering::SeqCst);
        w
    }

    /// Core 1 as seen from core 0: whether it is rendering a band, and which.
    pub struct Core1 {
        rendering: Option<usize>,
    }

    /// Spawns core 1's renderer.
    pub fn start(psm: &mut pac::PSM, ppb: &mut pac::PPB, fifo: &mut SioFifo, scene: Scene) -> Core1 {
        let depth: &'static mut Depth = cortex_m::singleton!(: Depth = [0; BAND_PIXELS]).expect("core 1 depth band");
        let mut mc = Multicore::new(psm, ppb, fifo);
        let cores = mc.cores();
        let stack = CORE1_STACK.take().expect("core 1 stack");
        if cores[1].spawn(stack, move || core1_main(scene, depth)).is_err() {
            panic!("core 1 does not start");
        }
        Core1 { rendering: None }
    }

    /// Core 1: render the band it is given into the buffer it is given, hand the buffer back.
    /// Message down: [angle as f32 bits, band, buffer]; message up: [buffer].
    fn core1_main(scene: Scene, depth: &'static mut Depth) {
        // SAFETY: only core 1 uses its side of the FIFO (the SIO is banked per core, and core 0
        // keeps its own `SioFifo`); nothing else of the SIO is touched here.
        let pac = unsafe { pac::Peripherals::steal() };
        let mut fifo = hal::Sio::new(pac.SIO).fifo;
        loop {
            let angle = f32::from_bits(receive(&mut fifo));
            let band = receive(&mut fifo) as usize;
            // SAFETY: core 0 sent this address with `into_raw` and forgot the buffer.
            let buf = unsafe { BandBuf::from_raw(receive(&mut fifo)) };
            scene.render(&mut buf.0[..], &mut depth[..], (band * BAND_ROWS) as u16, angle);
            send(&mut fifo, &[buf.into_raw()]);
        }
    }

    /// Hands band `band` and a free buffer to core 1.
    fn give(core1: &mut Core1, fifo: &mut SioFifo, pool: &mut Pool, band: usize, angle: f32) {
        let buf = pool.pop().expect("a free colour band for core 1");
        send(fifo, &[angle.to_bits(), band as u32, buf.into_raw()]);
        core1.rendering = Some(band);
    }

    /// One frame: core 0 renders bands 0, 2, 4, 6 and core 1 bands 1, 3, 5, 7; core 0 sends each
    /// to the display as soon as it is ready (each band has its own address window, so order
    /// does not matter).
    pub fn frame(
        core1: &mut Core1,
        fifo: &mut SioFifo,
        scene: &Scene,
        depth: &mut Depth,
        pool: &mut Pool,
        display: &mut Display,
        angle: f32,
    ) {
        let mut odd = (1..BANDS).step_by(2);
        let mut even = (0..BANDS).step_by(2);
        if let Some(band) = odd.next() {
            give(core1, fifo, pool, band, angle);
        }
        loop {
            let mine = even.next();
            if let Some(band) = mine {
                let buf = pool.pop().expect("a free colour band");
                scene.render(&mut buf.0[..], &mut depth[..], (band * BAND_ROWS) as u16, angle);
                if let Some(sent) = display.present(buf, band) {
                    let _ = pool.push(sent);
                }
            }
            if let Some(band) = core1.rendering {
                // Collect core 1's band if it is ready, or wait for it when core 0 has nothing
                // left to render.
                let ready = if mine.is_none() { Some(receive(fifo)) } else { poll(fifo) };
                if let Some(raw) = ready {
                    core1.rendering = None;
                    // SAFETY: core 1 sent this address with `into_raw` and forgot the buffer.
                    let buf = unsafe { BandBuf::from_raw(raw) };
                    if let Some(sent) = display.present(buf, band) {
                        let _ = pool.push(sent);
                    }
                    if let Some(next) = odd.next() {
                        give(core1, fifo, pool, next, angle);
                    }
                }
            } else if mine.is_none() {
                break;
            }
        }
    }

    fn poll(fifo: &mut SioFifo) -> Option<u32> {
        let w = fifo.read()?;
        fence(Ordering::SeqCst);
        Some(w)
    }
}
