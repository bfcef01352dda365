//! embedded-graphics integration (feature `embedded-graphics`): the boundary between drawing
//! and a display. It renders nothing 3D itself and owns no buffer.
//!
//! - [`present`] sends a rendered band to any [`DrawTarget`] with one `fill_contiguous` over
//!   the band's rectangle (a display driver turns that into one window + one burst).
//! - [`Band`] is itself a [`DrawTarget`] in frame coordinates, so 2D primitives and text (an FPS
//!   counter, a HUD) can be drawn over the 3D picture before it is presented. Pixels outside the
//!   band are dropped, so drawing the same HUD into every band builds the whole overlay.

use embedded_graphics::prelude::*;
use embedded_graphics::primitives::Rectangle;

use crate::target::{Band, DepthBuffer, FrameColor};

/// Draws `band`'s pixels at their place in the frame on `display`.
///
/// # Errors
/// Whatever `display` returns.
pub fn present<C, D, T>(band: &Band<'_, C, D>, display: &mut T) -> Result<(), T::Error>
where
    C: FrameColor + PixelColor,
    D: DepthBuffer,
    T: DrawTarget<Color = C>,
{
    let area =
        Rectangle::new(Point::new(0, band.first_row() as i32), Size::new(band.width() as u32, band.rows() as u32));
    display.fill_contiguous(&area, band.pixels().iter().copied())
}

impl<C: FrameColor + PixelColor, D: DepthBuffer> OriginDimensions for Band<'_, C, D> {
    /// The whole frame's size: the band is addressed in frame coordinates.
    fn size(&self) -> Size {
        Size::new(self.width as u32, self.height as u32)
    }
}

impl<C: FrameColor + PixelColor, D: DepthBuffer> DrawTarget for Band<'_, C, D> {
    type Color = C;
    type Error = core::convert::Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = Pixel<C>>,
    {
        let area = self.area();
        for Pixel(p, c) in pixels {
            if let Some(px) = area.run_start(p.x, p.y, 1).and_then(|i| self.color.get_mut(i)) {
                *px = c;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::NoDepth;
    use embedded_graphics::mock_display::MockDisplay;
    use embedded_graphics::pixelcolor::BinaryColor;
    use embedded_graphics::primitives::{Line, PrimitiveStyle};

    #[test]
    fn band_presents_at_its_rows() {
        let mut pixels = [BinaryColor::Off; 4 * 2];
        pixels[1] = BinaryColor::On;
        pixels[6] = BinaryColor::On;
        let band = Band::new(&mut pixels[..], NoDepth, 4, 5, 2).unwrap();
        let mut display = MockDisplay::new();
        present(&band, &mut display).unwrap();
        display.assert_pattern(&[
            "    ", //
            "    ", ".#..", "..#.",
        ]);
    }

    #[test]
    fn primitives_draw_into_the_band_only() {
        let mut pixels = [BinaryColor::Off; 4 * 2];
        let mut band = Band::new(&mut pixels[..], NoDepth, 4, 5, 1).unwrap();
        // A diagonal over the whole 4x5 frame: only rows 1 and 2 land in this band.
        Line::new(Point::new(0, 0), Point::new(3, 3))
            .into_styled(PrimitiveStyle::with_stroke(BinaryColor::On, 1))
            .draw(&mut band)
            .unwrap();
        let mut display = MockDisplay::new();
        present(&band, &mut display).unwrap();
        display.assert_pattern(&[
            "    ", //
            ".#..", "..#.",
        ]);
    }
}
