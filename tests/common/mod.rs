//! Helpers shared by the integration tests: the asset list, conversion, a seeded PRNG, and
//! [`mock::CheckedTarget`], a render target that fails on overdraw and on writes outside the band.
#![allow(dead_code)] // each test file uses a different part

pub mod mock;

use std::path::PathBuf;

use soft3d::convert::scene::Scene;
use soft3d::convert::{read_babylon_file, ConvertOptions, UvOrigin};

/// Every `.babylon` scene in `assets/`.
pub const ASSETS: &[&str] = &[
    "suzanne/monkey.babylon",
    "blender-legacy/blender.babylon",
    "blender-split/blender.babylon",
    "teapot/teapot.babylon",
    "tree/tree.babylon",
    "double-sided/DoubleSidedMaterial.babylon",
    "instances/Instances.babylon",
    "opaque/Opaque.babylon",
    "opaque/Opaque.binary.babylon",
    "shapekey/shapekeyAnimation.babylon",
];

/// Path of an asset, relative to `assets/`.
pub fn asset(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets").join(rel)
}

/// An asset converted with its right UV origin (the tutorial's Suzanne needs `Top`).
pub fn scene(rel: &str) -> Scene {
    let origin = if rel.starts_with("suzanne") { UvOrigin::Top } else { UvOrigin::Bottom };
    read_babylon_file(&asset(rel), &ConvertOptions { uv_origin: origin, ..Default::default() }).unwrap().0
}

/// SplitMix64: tiny, seeded, good enough for test data.
pub struct Rng(pub u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        assert!(lo <= hi);
        lo + (self.next_u64() % ((hi - lo) as u64 + 1)) as i64
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    pub fn byte(&mut self) -> u8 {
        self.next_u64() as u8
    }
}
