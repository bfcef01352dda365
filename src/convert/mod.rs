//! Host-side conversion of Babylon.js scenes (feature `convert`).
//!
//! [`babylon`] reads a `.babylon` file into a [`scene::Scene`], applying every Babylon.js rule
//! (hierarchy, rotations, texture matrices, UV origin) on the way.

pub mod babylon;
pub mod scene;

pub use babylon::{read_babylon, read_babylon_file, ConvertError, ConvertOptions, UvOrigin, Warning};
