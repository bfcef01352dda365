//! The build-script entry point: [`build_script_convert`] converts a `.babylon` scene into an
//! `.s3d` file from a firmware's `build.rs`, speaking cargo's `cargo:` protocol, and
//! [`BuildError`] says which step failed on which file.
//!
//! Reading the scene is `babylon`'s job and writing the bytes `emit`'s; this module only chains
//! them, reports to cargo and writes the file atomically.

use core::fmt;
use std::io;
use std::path::{Path, PathBuf};

use super::babylon::{read_babylon_file, ConvertError, ConvertOptions};
use super::emit::{emit, EmitError, EmitOptions};

/// Why [`build_script_convert`] failed: the step, the file it was working on and the cause.
///
/// The messages are those a build script prints when it panics with the error: the scene's
/// [`ConvertError`] (which names the file), or the file's path followed by the cause.
#[derive(Debug)]
pub enum BuildError {
    /// The `.babylon` scene could not be read or converted.
    Read {
        /// The scene file.
        path: PathBuf,
        /// What was wrong with it.
        source: ConvertError,
    },
    /// The converted scene could not be written as `.s3d` (too many meshes, say).
    Emit {
        /// The scene file.
        path: PathBuf,
        /// What could not be written.
        source: EmitError,
    },
    /// The `.s3d` file could not be written (or its temporary file renamed).
    Write {
        /// The output file.
        path: PathBuf,
        /// The operating system's error.
        source: io::Error,
    },
}

impl BuildError {
    /// The file the failed step was working on: the scene, or the `.s3d` output for
    /// [`BuildError::Write`].
    #[must_use]
    pub fn path(&self) -> &Path {
        match self {
            Self::Read { path, .. } | Self::Emit { path, .. } | Self::Write { path, .. } => path,
        }
    }
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // A `ConvertError` already starts with the scene's path or file name.
            Self::Read { source, .. } => write!(f, "{source}"),
            Self::Emit { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Write { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

impl std::error::Error for BuildError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Read { source, .. } => Some(source),
            Self::Emit { source, .. } => Some(source),
            Self::Write { source, .. } => Some(source),
        }
    }
}

/// Converts `input` (a `.babylon` file) into the `.s3d` file `output`, for a firmware's
/// `build.rs`: prints `cargo:rerun-if-changed` for the scene and its folder (textures) and each
/// converter warning as `cargo:warning`. The output is written to a temporary file and renamed,
/// so a failed build never leaves a partial `.s3d` behind. Beside it, `output` with the
/// extension `rs` holds the constants a firmware sizes a [`Pose`](crate::animation::Pose)'s
/// memory with (`POSE_MATRICES` matrices and `POSE_WEIGHTS` weights: see
/// [`pose_memory`](crate::animation::pose_memory)), for `include!`.
///
/// ```no_run
/// // build.rs
/// use soft3d::convert::{build_script_convert, ConvertOptions, UvOrigin};
/// use soft3d::convert::EmitOptions;
/// let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap()).join("scene.s3d");
/// let opts = ConvertOptions { uv_origin: UvOrigin::Bottom, max_texture: Some(128), power_of_two: true };
/// build_script_convert("assets/scene.babylon".as_ref(), &out, &opts, &EmitOptions::default()).unwrap();
/// ```
///
/// # Errors
/// A [`BuildError`] naming the step (conversion, emission or writing), the file and the cause.
pub fn build_script_convert(
    input: &Path,
    output: &Path,
    opts: &ConvertOptions,
    emit_opts: &EmitOptions,
) -> Result<(), BuildError> {
    std::println!("cargo:rerun-if-changed={}", input.display());
    if let Some(dir) = input.parent() {
        std::println!("cargo:rerun-if-changed={}", dir.display());
    }
    let (scene, warnings) =
        read_babylon_file(input, opts).map_err(|source| BuildError::Read { path: input.to_path_buf(), source })?;
    for w in warnings {
        std::println!("cargo:warning={}: {w}", input.display());
    }
    let bytes = emit(&scene, emit_opts).map_err(|source| BuildError::Emit { path: input.to_path_buf(), source })?;
    let a = &scene.animation;
    let bones = a.skins.iter().map(|s| s.bones.len()).sum();
    let weights = super::emit_view::ViewSlots::of(a).end;
    let (nodes, weights) = crate::animation::pose_memory(a.nodes.len(), bones, weights);
    let constants = std::format!(
        "// Written by soft3d::convert::build_script_convert for {}.\n\
         /// Matrices a `soft3d::animation::Pose` of this scene needs.\npub const POSE_MATRICES: usize = {nodes};\n\
         /// Weights (morph targets, animated camera and lights) a `soft3d::animation::Pose` of this scene needs.\npub const POSE_WEIGHTS: usize = {weights};\n",
        input.display()
    );
    write_atomically(output, &bytes)?;
    write_atomically(&output.with_extension("rs"), constants.as_bytes())
}

/// Writes `bytes` to `path` through a temporary file renamed into place.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), BuildError> {
    let mut tmp = std::ffi::OsString::from(path.as_os_str());
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|source| BuildError::Write { path: path.to_path_buf(), source })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;
    use std::string::ToString;

    #[test]
    fn a_missing_scene_is_a_read_error_naming_it() {
        let input = Path::new("no/such/scene.babylon");
        let err =
            build_script_convert(input, Path::new("unused.s3d"), &ConvertOptions::default(), &EmitOptions::default())
                .unwrap_err();
        assert!(matches!(err, BuildError::Read { source: ConvertError::Io { .. }, .. }), "{err:?}");
        assert_eq!(err.path(), input);
        let source = err.source().expect("a source").to_string();
        assert_eq!(err.to_string(), source);
        assert!(source.starts_with("no/such/scene.babylon: "), "{source}");
    }

    #[test]
    fn the_pose_constants_are_written_beside_the_model() {
        let input = Path::new("../shared/assets/morph-cube/AnimatedMorphCube.babylon");
        if !input.exists() {
            return;
        }
        let dir = std::env::temp_dir().join(std::format!("soft3d-build-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let output = dir.join("cube.s3d");
        build_script_convert(input, &output, &ConvertOptions::default(), &EmitOptions::default()).unwrap();
        let constants = std::fs::read_to_string(dir.join("cube.rs")).unwrap();
        // Two meshes of two morph targets each, no animated node.
        assert!(constants.contains("pub const POSE_MATRICES: usize = 0;"), "{constants}");
        assert!(constants.contains("pub const POSE_WEIGHTS: usize = 4;"), "{constants}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unwritable_output_is_a_write_error_naming_it() {
        let input = Path::new("assets/instances/Instances.babylon");
        let output = Path::new("no/such/dir/out.s3d");
        let err = build_script_convert(input, output, &ConvertOptions::default(), &EmitOptions::default()).unwrap_err();
        assert!(matches!(err, BuildError::Write { .. }), "{err:?}");
        assert_eq!(err.path(), output);
        let cause = err.source().expect("a source").to_string();
        assert_eq!(err.to_string(), std::format!("no/such/dir/out.s3d: {cause}"));
    }
}
