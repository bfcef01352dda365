//! [`CheckedTarget`]: a render target that checks what the renderer writes, in the spirit of
//! embedded-graphics' `MockDisplay`.
//!
//! soft3d promises an exact top-left fill rule (no gaps and no double writes between triangles
//! that share edges) and that nothing is written outside the band being drawn. This target
//! makes both visible:
//!
//! - **Overdraw.** Its depth cells ([`Stores`]) pass every depth test and count their `store`
//!   calls. The renderer stores depth exactly once for each pixel it writes, together with the
//!   colour (`Shader::span` in `src/pipeline/span/mod.rs`, `put` in `src/pipeline/line.rs`), so every covered fragment of every
//!   triangle is counted, and a count above 1 means two triangles (or one triangle twice)
//!   wrote the pixel: [`CheckedTarget::assert_no_overdraw`]. Colour and depth must agree: a
//!   pixel whose colour changed without a depth store (or the reverse) fails there too.
//! - **Writes outside the band.** The target owns the whole frame of colour, plus [`PAD_ROWS`]
//!   sentinel rows above and below it, and a parallel buffer of depth cells. A band gets
//!   sub-slices of both, so [`CheckedTarget::assert_untouched_outside`] can compare every cell
//!   around it (the rest of the frame and the sentinel rows) with a snapshot taken when the band
//!   was handed out. The band's depth buffer also records requests for cells beyond its slice:
//!   the renderer clips every fragment to the band itself, so such a request means it computed
//!   a pixel outside the band and relied on the buffer to refuse it.
//! - **Pictures.** [`CheckedTarget::picture`] shows the store counts as ASCII (`'.'` never
//!   written, `'#'` once, `'2'`..=`'9'` that many times, `'*'` more, `'!'` where colour and depth
//!   disagree), and [`CheckedTarget::assert_pattern`] compares it with an expected picture.
//!
//! Everything starts as [`SENTINEL`] colour and zero stores. Do not call `Band::clear` on its
//! bands: that writes colour without storing depth.

use std::ops::Range;

use embedded_graphics_core::pixelcolor::Rgb888;
use soft3d::{Band, DepthBuffer, DepthCell};

/// The colour of every cell nobody wrote (no mesh in the tests has this colour).
pub const SENTINEL: Rgb888 = Rgb888::new(0x5A, 0x0F, 0xA5);

/// Sentinel rows above and below the frame.
pub const PAD_ROWS: usize = 2;

/// A depth cell that counts its stores and passes every depth test.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stores(pub u32);

impl DepthCell for &mut Stores {
    fn passes(&self, _: u32) -> bool {
        true
    }
    fn store(&mut self, _: u32) {
        self.0 += 1;
    }
}

/// The depth buffer of one band of a [`CheckedTarget`]: its rows' [`Stores`] cells.
pub struct CountingDepth<'a> {
    cells: &'a mut [Stores],
    /// Requests for cells beyond `cells` (refused, as the trait demands, and remembered).
    refused: &'a mut Vec<Range<usize>>,
}

impl DepthBuffer for CountingDepth<'_> {
    type Cells<'b>
        = std::slice::IterMut<'b, Stores>
    where
        Self: 'b;
    fn depth_len(&self) -> Option<usize> {
        Some(self.cells.len())
    }
    fn cells(&mut self, start: usize, len: usize) -> Option<Self::Cells<'_>> {
        let end = start.saturating_add(len);
        if end > self.cells.len() {
            self.refused.push(start..end);
            return None;
        }
        Some(self.cells[start..end].iter_mut())
    }
    /// Keeps the counts: they are the evidence.
    fn clear_depth(&mut self) {}
}

/// The band type [`CheckedTarget::band`] hands out.
pub type CheckedBand<'a> = Band<'a, Rgb888, CountingDepth<'a>>;

/// A whole frame of colour and store-counting depth, with sentinel rows around it, that hands
/// out bands and checks afterwards what was written (see the module documentation).
pub struct CheckedTarget {
    /// Prefix of every failure message: which case this is.
    name: String,
    width: u16,
    height: u16,
    /// `PAD_ROWS + height + PAD_ROWS` rows of `width`.
    color: Vec<Rgb888>,
    depth: Vec<Stores>,
    refused: Vec<Range<usize>>,
    /// The rows of the band handed out last, and colour and depth as they were then.
    snapshot: Option<(Range<u16>, Vec<Rgb888>, Vec<Stores>)>,
}

impl CheckedTarget {
    /// A `width` x `height` frame, all [`SENTINEL`] and never stored.
    pub fn new(width: u16, height: u16) -> Self {
        let len = (height as usize + 2 * PAD_ROWS) * width as usize;
        CheckedTarget {
            name: String::new(),
            width,
            height,
            color: vec![SENTINEL; len],
            depth: vec![Stores(0); len],
            refused: Vec::new(),
            snapshot: None,
        }
    }

    /// The same target, naming the case in every failure message.
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = name.into() + ": ";
        self
    }

    /// Frame height in pixels.
    pub fn height(&self) -> u16 {
        self.height
    }

    /// Frame width in pixels.
    pub fn width(&self) -> u16 {
        self.width
    }

    /// Indices into the padded buffers of frame rows `rows`.
    fn window(&self, rows: &Range<u16>) -> Range<usize> {
        let w = self.width as usize;
        (PAD_ROWS + rows.start as usize) * w..(PAD_ROWS + rows.end as usize) * w
    }

    /// Frame coordinates of padded index `i` (`y` is negative or `>= height` in sentinel rows).
    fn xy(&self, i: usize) -> (usize, isize) {
        let w = self.width as usize;
        (i % w, (i / w) as isize - PAD_ROWS as isize)
    }

    /// A band of frame rows `first..first + rows`: sub-slices of the frame's colour and depth.
    /// Remembers the state of everything for [`assert_untouched_outside`](Self::assert_untouched_outside).
    pub fn band(&mut self, first: u16, rows: u16) -> CheckedBand<'_> {
        let band_rows = first..first + rows;
        let window = self.window(&band_rows);
        self.refused.clear();
        self.snapshot = Some((band_rows, self.color.clone(), self.depth.clone()));
        let depth = CountingDepth { cells: &mut self.depth[window.clone()], refused: &mut self.refused };
        Band::new(&mut self.color[window], depth, self.width, self.height, first).expect("band geometry")
    }

    /// Draws the frame band by band, `rows` rows each (the last may be shorter; 0 means the whole
    /// frame), checking after each band that nothing outside it changed.
    pub fn draw_in_bands(&mut self, rows: u16, mut draw: impl FnMut(&mut CheckedBand<'_>)) {
        let rows = if rows == 0 { self.height } else { rows };
        let mut first = 0;
        while first < self.height {
            let n = rows.min(self.height - first);
            draw(&mut self.band(first, n));
            self.assert_untouched_outside(first..first + n);
            first += n;
        }
    }

    /// Panics unless, since the last [`band`](Self::band) was handed out, nothing outside frame
    /// rows `rows` changed (colour or store counts, the sentinel rows included) and its depth
    /// buffer was never asked for cells beyond its slice.
    pub fn assert_untouched_outside(&self, rows: Range<u16>) {
        let (band, color, depth) = self.snapshot.as_ref().expect("no band was handed out");
        if let Some(r) = self.refused.first() {
            panic!(
                "{}the band of rows {band:?} was asked for depth cells {r:?} beyond its {} cells \
                 ({} such requests): the renderer computed pixels outside the band",
                self.name,
                self.window(band).len(),
                self.refused.len()
            );
        }
        let window = self.window(&rows);
        for i in (0..self.color.len()).filter(|i| !window.contains(i)) {
            if self.color[i] != color[i] || self.depth[i] != depth[i] {
                let (x, y) = self.xy(i);
                let what = if y < 0 || y >= self.height as isize { " (a sentinel row)" } else { "" };
                panic!(
                    "{}write outside band rows {rows:?}: pixel ({x}, {y}){what} changed while band {band:?} was drawn: \
                     colour {:?} -> {:?}, depth stores {} -> {}",
                    self.name,
                    color[i],
                    self.color[i],
                    depth[i].0,
                    self.depth[i].0
                );
            }
        }
    }

    /// How many times pixel `(x, y)` stored depth.
    pub fn stores(&self, x: usize, y: usize) -> u32 {
        assert!(x < self.width as usize && y < self.height as usize, "({x}, {y}) outside the frame");
        self.depth[(PAD_ROWS + y) * self.width as usize + x].0
    }

    /// Frame pixels written at least once.
    pub fn written(&self) -> usize {
        self.depth[self.window(&(0..self.height))].iter().filter(|s| s.0 > 0).count()
    }

    /// The picture's character for padded index `i`.
    fn mark(&self, i: usize) -> char {
        match (self.depth[i].0, self.color[i] != SENTINEL) {
            (0, false) => '.',
            (0, true) | (_, false) => '!',
            (1, true) => '#',
            (n @ 2..=9, true) => char::from_digit(n, 10).unwrap(),
            _ => '*',
        }
    }

    /// The frame as ASCII, one string per row: `'.'` never written, `'#'` once, `'2'`..=`'9'`
    /// that many times, `'*'` more, `'!'` where colour and depth disagree.
    pub fn picture(&self) -> Vec<String> {
        let w = self.width as usize;
        let window = self.window(&(0..self.height));
        window.step_by(w).map(|row| (row..row + w).map(|i| self.mark(i)).collect()).collect()
    }

    /// Panics at the first pixel written more than once (or whose colour and depth disagree),
    /// naming its coordinates, with the picture.
    pub fn assert_no_overdraw(&self) {
        let window = self.window(&(0..self.height));
        let bad = |i: &usize| !matches!(self.mark(*i), '.' | '#');
        if let Some(i) = window.clone().find(bad) {
            let (x, y) = (self.xy(i).0, self.xy(i).1);
            let total = window.filter(bad).count();
            let what = match self.mark(i) {
                '!' => "colour and depth disagree".to_string(),
                _ => format!("overdraw: stored {} times", self.depth[i].0),
            };
            panic!(
                "{}{what} at pixel ({x}, {y}) ({total} bad pixels in all):\n{}",
                self.name,
                self.picture().join("\n")
            );
        }
    }

    /// Panics unless [`picture`](Self::picture) equals `expected`, showing both and the first
    /// differing pixel.
    pub fn assert_pattern<S: AsRef<str>>(&self, expected: &[S]) {
        let got = self.picture();
        let expected: Vec<&str> = expected.iter().map(AsRef::as_ref).collect();
        if got != expected {
            let first = (0..got.len().max(expected.len())).find_map(|y| {
                let (g, e) = (got.get(y).map_or("", |s| s.as_str()), expected.get(y).copied().unwrap_or(""));
                let x = g.chars().zip(e.chars()).position(|(a, b)| a != b).unwrap_or(g.len().min(e.len()));
                (g != e).then_some((x, y))
            });
            panic!(
                "{}picture differs, first at pixel {first:?}:\nexpected:\n{}\ngot:\n{}",
                self.name,
                expected.join("\n"),
                got.join("\n")
            );
        }
    }
}
