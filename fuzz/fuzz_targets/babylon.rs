//! The `.babylon` reader and the `.s3d` writer on arbitrary JSON-ish bytes: never panic, and
//! whatever `emit` writes, `Model::parse` accepts.
#![no_main]
use libfuzzer_sys::fuzz_target;
use soft3d::convert::{read_babylon, ConvertOptions};
use soft3d::format::{emit, EmitOptions, Model};

fuzz_target!(|data: &[u8]| {
    let Ok((scene, _)) = read_babylon(data, None, "fuzz.babylon", &ConvertOptions::default()) else { return };
    if let Ok(bytes) = emit(&scene, &EmitOptions::default()) {
        Model::parse(&bytes).expect("emit output parses");
    }
});
