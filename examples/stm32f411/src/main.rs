//! soft3d on an STM32F411 "Black Pill": Suzanne, textured and Gouraud-lit, turning on a
//! 240x240 ST7789 over SPI1 at 50 MHz.
//!
//! The frame is drawn in eight 240x30 bands. Each band is rendered into one of two colour band
//! buffers (`Rgb565Be`, big-endian RGB565: the ST7789's byte order, so a band goes to the
//! display as it is) with a `u16` depth band, then sent by DMA (DMA2 stream 3, channel 3 =
//! SPI1_TX) into the address window of its rows while the CPU renders the next band into the
//! other buffer (ping-pong).
//!
//! The SPI is set up by stm32f4xx-hal (`Spi::new_bidi`: clock, pins, mode, prescaler) and then
//! released to its PAC register block, which the hal's DMA `Transfer` accepts as a peripheral
//! (`pac::SPI1: DMASet<Stream3<DMA2>, 3, MemoryToPeripheral>`) and hands back at `release`.
//! Between transfers the driver writes the few command bytes through the same register block,
//! so no `unsafe` is needed anywhere in this file except the one `ReadBuffer` impl.
//!
//! Wiring (see README.md): SCK PA5, MOSI PA7, CS PA4, DC PA3, RST PA2, backlight to 3V3.
#![no_std]
#![no_main]

use core::f32::consts::TAU;

use cortex_m::peripheral::DWT;
use cortex_m_rt::entry;
use embedded_hal::delay::DelayNs;
use panic_halt as _;
use soft3d::Rgb565Be;
use stm32f4xx_hal::dma::{config::DmaConfig, MemoryToPeripheral, Stream3, StreamsTuple, Transfer};
use stm32f4xx_hal::gpio::{Output, Speed, PA2, PA3, PA4};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::spi::{Mode, Phase, Polarity, Spi};

/// Suzanne, converted at build time (see build.rs) and read in place from flash.
static SUZANNE: &[u8] = soft3d::include_s3d!(concat!(env!("OUT_DIR"), "/suzanne.s3d"));

/// The Black Pill's crystal.
const HSE_HZ: u32 = 25_000_000;
/// Core clock: the F411's maximum. APB2 (SPI1's bus) runs at it too.
const SYSCLK_HZ: u32 = 100_000_000;
/// SPI clock: PCLK2 / 2, the SPI's fastest, and within the ST7789's 16 ns minimum write cycle.
const SPI_HZ: u32 = 50_000_000;

// The DMA's transfer count register is 16 bits wide.
const _: () = assert!(BAND_PIXELS * 2 <= u16::MAX as usize, "a band must fit one DMA transfer");
/// One full turn every this many seconds, whatever the frame rate.
const TURN_SECONDS: f32 = 8.0;

#[path = "../../common/board.rs"]
mod board;
use board::{cmd, BandBuf, Depth, Pixels, Scene, BANDS, BAND_PIXELS, BAND_ROWS};

type DmaStream = Stream3<pac::DMA2>;
/// DMA2 stream 3, channel 3: SPI1_TX (RM0383 table 28).
type BandTransfer = Transfer<DmaStream, 3, pac::SPI1, MemoryToPeripheral, BandBuf>;

/// A minimal ST7789 driver: init, address window, and band transfers by DMA.
///
/// The link is either idle (`idle` holds the DMA stream and the SPI) or busy (`busy` holds the
/// running transfer, which owns stream, SPI and the band being sent); never both, never
/// neither.
struct Display {
    idle: Option<(DmaStream, pac::SPI1)>,
    busy: Option<BandTransfer>,
    dc: PA3<Output>,
    cs: PA4<Output>,
}

impl Display {
    /// Hardware reset, then the init sequence: 16-bit colour, default orientation (240x240
    /// panels start at RAM row 0 there), colour inversion (IPS panels), display on.
    fn new(
        spi: pac::SPI1,
        stream: DmaStream,
        dc: PA3<Output>,
        mut cs: PA4<Output>,
        rst: &mut PA2<Output>,
        delay: &mut impl DelayNs,
    ) -> Self {
        // The SPI asks the DMA for a byte whenever its transmit buffer is empty; the request
        // only takes effect while a stream is enabled for it.
        spi.cr2().modify(|_, w| w.txdmaen().set_bit());
        cs.set_high();
        rst.set_high();
        delay.delay_ms(1);
        rst.set_low();
        delay.delay_us(20); // reset pulse >= 10 us
        rst.set_high();
        delay.delay_ms(120); // reset cancel, up to 120 ms
        let mut d = Display { idle: Some((stream, spi)), busy: None, dc, cs };
        for &(command, params, wait_ms) in board::INIT {
            d.command(command, params);
            delay.delay_ms(wait_ms);
        }
        d
    }

    /// Sends a command byte (DC low) and its parameters (DC high) with CS low around both.
    fn command(&mut self, command: u8, params: &[u8]) {
        self.cs.set_low();
        self.dc.set_low();
        self.write(&[command]);
        self.dc.set_high();
        if !params.is_empty() {
            self.write(params);
        }
        self.cs.set_high();
    }

    /// Writes bytes by the CPU (the link must be idle) and returns once the last one has left
    /// the shift register, so DC or CS may move.
    fn write(&mut self, bytes: &[u8]) {
        let (_, spi) = self.idle.as_ref().expect("display link idle");
        for &b in bytes {
            while spi.sr().read().txe().bit_is_clear() {}
            spi.dr().write(|w| w.dr().set(u16::from(b)));
        }
        wait_sent(spi);
    }

    /// Waits for the transfer in flight, if any, and returns its band buffer.
    fn wait(&mut self) -> Option<BandBuf> {
        let transfer = self.busy.take()?;
        transfer.wait();
        let (stream, spi, buf, _) = transfer.release();
        // The DMA has written the last byte into the SPI's data register; wait until it has been
        // shifted out before CS goes high.
        wait_sent(&spi);
        self.cs.set_high();
        self.idle = Some((stream, spi));
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
        self.cs.set_low();
        self.dc.set_low();
        self.write(&[cmd::RAMWR]);
        self.dc.set_high();
        let (stream, spi) = self.idle.take().expect("display link idle");
        let mut transfer =
            Transfer::init_memory_to_peripheral(stream, spi, buf, None, DmaConfig::default().memory_increment(true));
        transfer.start(|_| {});
        self.busy = Some(transfer);
        done
    }
}

/// Waits until the SPI has nothing left to send: transmit buffer empty, then not busy (the
/// order RM0383 section 20.3.8 gives for a transmit-only master).
fn wait_sent(spi: &pac::SPI1) {
    while spi.sr().read().txe().bit_is_clear() {}
    while spi.sr().read().bsy().bit_is_set() {}
}

#[entry]
fn main() -> ! {
    let dp = pac::Peripherals::take().expect("peripherals");
    let mut cp = cortex_m::Peripherals::take().expect("core peripherals");
    let mut rcc = dp.RCC.freeze(Config::hse(HSE_HZ.Hz()).sysclk(SYSCLK_HZ.Hz()));
    let mut delay = cp.SYST.delay(&rcc.clocks);
    // The cycle counter times the rotation.
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();

    // Statics, handed out once as `&'static mut` (in .bss, so they count as static RAM).
    let mut spare =
        Some(BandBuf(cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 0")));
    let mut next = BandBuf(cortex_m::singleton!(: Pixels = [Rgb565Be([0; 2]); BAND_PIXELS]).expect("colour band 1"));
    let depth: &'static mut Depth = cortex_m::singleton!(: Depth = [0; BAND_PIXELS]).expect("depth band");

    let scene = Scene::new(SUZANNE);

    // The display.
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpioc = dp.GPIOC.split(&mut rcc);
    let mut rst = gpioa.pa2.into_push_pull_output();
    let dc = gpioa.pa3.into_push_pull_output();
    let cs = gpioa.pa4.into_push_pull_output();
    // 50 MHz edges need the fastest output drivers.
    let sck = gpioa.pa5.into_alternate().speed(Speed::VeryHigh);
    let mosi = gpioa.pa7.into_alternate().speed(Speed::VeryHigh);
    // Transmit-only (one data line, MOSI): nothing is received, so there is no receive overrun
    // while the DMA writes. Mode 3 (clock idles high, sample on the rising edge) works with and
    // without CS, and is what the CS-less 240x240 modules need.
    let mode = Mode { polarity: Polarity::IdleHigh, phase: Phase::CaptureOnSecondTransition };
    let spi = Spi::new_bidi(dp.SPI1, (Some(sck), Some(mosi)), mode, SPI_HZ.Hz(), &mut rcc);
    let (spi, _pins) = spi.release();
    let streams = StreamsTuple::new(dp.DMA2, &mut rcc);
    let mut display = Display::new(spi, streams.3, dc, cs, &mut rst, &mut delay);
    // The on-board LED (PC13, active low) toggles once a frame.
    let mut led = gpioc.pc13.into_push_pull_output();

    let mut cycles = 0u64;
    let mut last = DWT::cycle_count();
    loop {
        let now = DWT::cycle_count();
        cycles += u64::from(now.wrapping_sub(last));
        last = now;
        let seconds = (cycles % (TURN_SECONDS as u64 * SYSCLK_HZ as u64)) as f32 / SYSCLK_HZ as f32;
        let angle = seconds * (TAU / TURN_SECONDS);
        for band in 0..BANDS {
            scene.render(&mut next.0[..], &mut depth[..], (band * BAND_ROWS) as u16, angle);
            let sent = display.present(next, band);
            // The buffer just handed to the DMA comes back at the next `present`; meanwhile the
            // other one (free from the start, then the one whose transfer just finished) is
            // rendered into.
            next = sent.or_else(|| spare.take()).expect("a free colour band");
        }
        led.toggle();
    }
}
