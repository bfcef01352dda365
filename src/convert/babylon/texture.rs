//! Texture images: a material's texture read once per name (and alpha rule) from its file
//! (its name taken relative to the scene's folder, as Babylon.js takes it relative to the
//! scene's URL; where that fails, its bare file name next to the scene, then in the folder
//! above, with a warning naming what was tried and what was used), its `base64String` or a
//! `data:` URL name; decoded by content (TGA by name), resized to the [`ConvertOptions`]
//! limits and stored in `Scene::textures` as RGBA8. A texture that cannot be loaded is a
//! warning, not an error.
//!
//! Which material uses a texture, and its wrap modes and UV mapping, are `material`'s job.

use std::format;
use std::string::String;
use std::string::ToString;
use std::vec;
use std::vec::Vec;

use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use base64::Engine as _;
use serde_json::Value;

use super::fields::{text, Ctx};
use super::{ConvertError, ConvertOptions, Reader};
use crate::convert::scene::TextureData;

impl Reader<'_> {
    /// Decodes (once per name) a texture from its file or its `base64String`; a failure is a
    /// warning and `None`.
    pub(super) fn texture(&mut self, tex: &Value, keep_alpha: bool, cx: &Ctx) -> Result<Option<u16>, ConvertError> {
        let at = |m: String| cx.err(m);
        let base64 = text(tex, "base64String").map_err(at)?;
        // Babylon.js ignores nameless textures, even embedded ones.
        let Some(name) = text(tex, "name").map_err(at)?.filter(|n| !n.is_empty()) else {
            return Ok(None);
        };
        let key = (name.clone(), keep_alpha);
        if let Some(&index) = self.tex_cache.get(&key) {
            return Ok(index);
        }
        let index = match self.load_image(&name, base64.as_deref()) {
            Ok((image, fallback)) => {
                if let Some(note) = fallback {
                    self.warn(format!("{}: texture {name:?} {note}", cx.what));
                }
                Some(self.push_texture(name.clone(), image, keep_alpha, cx)?)
            }
            Err(why) => {
                let shown: String = name.chars().take(60).collect();
                self.warn(format!("{}: texture {shown:?} {why}, using the diffuse colour", cx.what));
                None
            }
        };
        self.tex_cache.insert(key, index);
        Ok(index)
    }

    /// The texture's image, and how it was found when not where its name says.
    fn load_image(&self, name: &str, base64: Option<&str>) -> Result<(image::RgbaImage, Option<String>), String> {
        let (bytes, fallback) = match base64.or_else(|| name.starts_with("data:").then_some(name)) {
            Some(b64) => (decode_base64(b64).map_err(|e| format!("has invalid base64 data ({e})"))?, None),
            None => self.read_texture_file(name)?,
        };
        decode(&bytes, name).map(|image| (image, fallback))
    }

    /// The bytes of texture file `name` (see the module documentation), and a note of the
    /// places tried when it was found by its bare name.
    fn read_texture_file(&self, name: &str) -> Result<(Vec<u8>, Option<String>), String> {
        let dir = self.base_dir.ok_or("not found (no directory to look in)")?;
        let named = dir.join(name);
        let mut tried = vec![named.clone()];
        // Exporters write Windows separators too; the bare name is what follows the last one.
        if let Some(bare) = name.rsplit(['/', '\\']).next().filter(|b| !b.is_empty() && *b != "." && *b != "..") {
            tried.push(dir.join(bare));
            tried.extend(dir.parent().map(|up| up.join(bare)));
        }
        tried.dedup();
        let shown =
            |paths: &[std::path::PathBuf]| paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        for (k, path) in tried.iter().enumerate() {
            if let Ok(bytes) = std::fs::read(path) {
                let note = (k > 0).then(|| format!("not found at {}: {} used", shown(&tried[..k]), path.display()));
                return Ok((bytes, note));
            }
        }
        let why = std::fs::read(&named).err().map_or_else(String::new, |e| format!(": {e}"));
        Err(format!("not found (tried {}{why})", shown(&tried)))
    }
}

/// Decodes texture `name`'s `bytes`: the content decides (embedded JPEG names hide PNGs); TGA
/// has no signature: the name does.
fn decode(bytes: &[u8], name: &str) -> Result<image::RgbaImage, String> {
    let mut formats: Vec<image::ImageFormat> = image::guess_format(bytes).into_iter().collect();
    formats.extend(image::ImageFormat::from_path(name).ok().filter(|f| !formats.contains(f)));
    let mut why = String::from("is in an unknown image format");
    for format in formats {
        match image::load_from_memory_with_format(bytes, format) {
            Ok(img) if img.width() > 0 && img.height() > 0 => return Ok(img.into_rgba8()),
            Ok(_) => why = "is empty".into(),
            Err(e) => why = format!("could not be decoded ({e})"),
        }
    }
    Err(why)
}

impl Reader<'_> {
    fn push_texture(
        &mut self,
        name: String,
        image: image::RgbaImage,
        keep_alpha: bool,
        cx: &Ctx,
    ) -> Result<u16, ConvertError> {
        let (w, h) = texture_size(image.width(), image.height(), self.opts);
        let mut image = if (w, h) == image.dimensions() {
            image
        } else {
            image::imageops::resize(&image, w, h, image::imageops::FilterType::Triangle)
        };
        if !keep_alpha {
            image.pixels_mut().for_each(|p| p.0[3] = 255);
        }
        let index = u16::try_from(self.scene.textures.len()).map_err(|_| cx.err("more than 65536 textures"))?;
        let (width, height) = (w as u16, h as u16); // texture_size keeps both in 1..=65535
        self.scene.textures.push(TextureData { name, width, height, rgba: image.into_raw() });
        Ok(index)
    }
}

/// Decodes a base64 payload or a whole `data:...;base64,` URL.
fn decode_base64(s: &str) -> Result<Vec<u8>, base64::DecodeError> {
    const ENGINE: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new()
            .with_decode_padding_mode(DecodePaddingMode::Indifferent)
            .with_decode_allow_trailing_bits(true),
    );
    let payload = if s.starts_with("data:") { s.split_once(',').map_or("", |(_, p)| p) } else { s };
    let clean: String = payload.chars().filter(|c| !c.is_ascii_whitespace()).collect();
    ENGINE.decode(clean)
}

/// The size a `w` x `h` image is stored at: `max_texture`, then `power_of_two`, and never more
/// than 65535 on a side.
fn texture_size(w: u32, h: u32, opts: &ConvertOptions) -> (u32, u32) {
    let limit = opts.max_texture.unwrap_or(u32::MAX).clamp(1, u32::from(u16::MAX));
    let (mut w, mut h) = (w.max(1), h.max(1));
    if w.max(h) > limit {
        let scale = f64::from(limit) / f64::from(w.max(h));
        let fit = |x: u32| ((f64::from(x) * scale).round() as u32).clamp(1, limit);
        (w, h) = (fit(w), fit(h));
    }
    if opts.power_of_two {
        let floor_pow2 = |x: u32| 1 << (31 - x.leading_zeros());
        (w, h) = (floor_pow2(w), floor_pow2(h));
    }
    (w, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_accepts_data_urls_and_bare_payloads() {
        assert_eq!(decode_base64("data:image/png;base64,aGk=").unwrap(), b"hi");
        assert_eq!(decode_base64("aGk").unwrap(), b"hi");
    }

    #[test]
    fn texture_sizes() {
        let o = |max_texture, power_of_two| ConvertOptions { max_texture, power_of_two, ..Default::default() };
        assert_eq!(texture_size(512, 256, &o(Some(128), false)), (128, 64));
        assert_eq!(texture_size(300, 100, &o(None, true)), (256, 64));
        assert_eq!(texture_size(1000, 3, &o(Some(100), true)), (64, 1));
    }
}
