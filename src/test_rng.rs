//! The tests' random numbers: a small LCG (Knuth's MMIX constants), reproducible without a
//! dependency.

/// The generator; its state is the seed.
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// The next 32 bits (the state's upper half).
    pub(crate) fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    /// Uniform in `0..n`.
    pub(crate) fn below(&mut self, n: u32) -> u32 {
        self.next() % n
    }

    /// Uniform in `0..1`.
    pub(crate) fn unit(&mut self) -> f64 {
        f64::from(self.next()) / 2f64.powi(32)
    }
}
