//! Materials: the base-colour factor and the decoded base-colour image (embedded in a
//! bufferView, a data URI or an external file). Image failures become warnings.

use std::borrow::Cow;

use crate::mesh::scene::{Material, Texture};

use super::container::load_uri;
use super::{Fail, Importer, invalid};

/// Largest decoded texture side.
const MAX_TEXTURE_SIDE: u32 = 16384;

impl Importer<'_, '_> {
    /// The scene material for glTF material `index`, built on first use.
    pub(super) fn material_for(&mut self, index: usize) -> Result<u32, Fail> {
        if let Some(&known) = self.material_map.get(&index) {
            return Ok(known);
        }
        let root = self.root;
        let Some(gltf_material) = root.materials.get(index) else {
            return invalid(format!("material {index} does not exist"));
        };
        let pbr = &gltf_material.pbr_metallic_roughness;
        let mut factor = pbr.base_color_factor.0;
        if !factor.iter().all(|c| c.is_finite()) {
            self.scene.warnings.push(format!("material {index}: non-finite baseColorFactor replaced by white"));
            factor = [1.0; 4];
        }
        let factor = factor.map(|c| c.clamp(0.0, 1.0));
        let texture = match &pbr.base_color_texture {
            Some(info) => {
                if info.tex_coord != 0 {
                    self.scene.warnings.push(format!(
                        "material {index}: base-colour texture uses TEXCOORD_{}; TEXCOORD_0 is used instead",
                        info.tex_coord
                    ));
                }
                self.texture_for(info.index.value(), index)
            }
            None => None,
        };
        let Ok(slot) = u32::try_from(self.scene.materials.len()) else {
            return invalid("too many materials");
        };
        self.scene.materials.push(Material { base_color_factor: factor, base_color_texture: texture });
        self.material_map.insert(index, slot);
        Ok(slot)
    }

    /// Decodes the image of glTF texture `texture_index`; failures become warnings.
    fn texture_for(&mut self, texture_index: usize, material: usize) -> Option<u32> {
        let root = self.root;
        let Some(texture) = root.textures.get(texture_index) else {
            self.scene.warnings.push(format!(
                "material {material}: texture {texture_index} does not exist; base-colour texture skipped"
            ));
            return None;
        };
        let image_index = texture.source.value();
        if let Some(&known) = self.image_map.get(&image_index) {
            return known;
        }
        let result = match self.decode_image(image_index) {
            Ok(decoded) => match u32::try_from(self.scene.textures.len()) {
                Ok(slot) => {
                    self.scene.textures.push(decoded);
                    Some(slot)
                }
                Err(_) => None,
            },
            Err(message) => {
                self.scene
                    .warnings
                    .push(format!("image {image_index} (base colour of material {material}) skipped: {message}"));
                None
            }
        };
        self.image_map.insert(image_index, result);
        result
    }

    fn decode_image(&self, index: usize) -> Result<Texture, String> {
        let Some(image) = self.root.images.get(index) else {
            return Err("the image does not exist".to_owned());
        };
        let what = format!("image {index}");
        let bytes: Cow<'_, [u8]> = if let Some(view) = image.buffer_view {
            let (bytes, _) = self.view_bytes(view.value(), &what).map_err(fail_message)?;
            Cow::Borrowed(bytes)
        } else if let Some(uri) = image.uri.as_deref() {
            load_uri(uri, self.base_dir, &what, None).map_err(fail_message)?
        } else {
            return Err("it has neither a uri nor a bufferView".to_owned());
        };
        // The size from the header, checked against the texel budget before decoding.
        let (width, height) = image::ImageReader::new(std::io::Cursor::new(bytes.as_ref()))
            .with_guessed_format()
            .map_err(|err| err.to_string())?
            .into_dimensions()
            .map_err(|err| err.to_string())?;
        let texels = u64::from(width) * u64::from(height);
        let allowed = self.limits.max_texels.saturating_sub(self.texels.get());
        if texels > allowed {
            return Err(format!(
                "{width}×{height} = {texels} texels, more than the {allowed} left of the {} allowed ({})",
                self.limits.max_texels, self.limits.reason
            ));
        }
        self.texels.set(self.texels.get() + texels);
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes.as_ref()))
            .with_guessed_format()
            .map_err(|err| err.to_string())?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_TEXTURE_SIDE);
        limits.max_image_height = Some(MAX_TEXTURE_SIDE);
        reader.limits(limits);
        let decoded = reader.decode().map_err(|err| err.to_string())?;
        let rgba = decoded.to_rgba8();
        Ok(Texture { width: rgba.width(), height: rgba.height(), rgba8_srgb: rgba.into_raw() })
    }
}

fn fail_message(fail: Fail) -> String {
    match fail {
        Fail::Io { what, source } => format!("cannot read {what}: {source}"),
        Fail::Gltf(message) | Fail::Invalid(message) => message,
    }
}
