//! The layers section of a version-2 packed file (docs/FORMAT.md, "Layers section"): the
//! layer records and every layer's content and mask samples, in the file's colour format.
//! Plain data: what a layer *means* is [`crate::layers`]' business; this module only
//! encodes, and refuses anything malformed before allocating more than the file justifies.

use crate::colors::format::ColorFormat;

use super::PackedFileError;

/// The most layers a file holds.
pub const MAX_LAYERS: u32 = 256;
/// Bytes of a layer's name field.
pub const NAME_BYTES: usize = 256;
/// Bytes before the first layer record.
pub const LAYERS_HEADER_SIZE: u64 = 16;
/// Bytes of one layer record.
pub const LAYER_RECORD_SIZE: u64 = 16 + NAME_BYTES as u64;

/// Layer flag: the layer is visible.
pub const LAYER_VISIBLE: u32 = 1;
/// Layer flag: the layer has a mask (its samples follow the content's).
pub const LAYER_HAS_MASK: u32 = 2;

/// One layer as stored.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerRecord {
    /// Its name (at most [`NAME_BYTES`] bytes of UTF-8).
    pub name: String,
    /// Whether it is composited.
    pub visible: bool,
    /// Opacity in `[0, 1]`.
    pub opacity: f32,
    /// Blend mode code (0 normal, 1 multiply, 2 add, 3 overlay).
    pub blend: u32,
    /// Content samples, encoded in the file's colour format, in store order.
    pub content: Vec<u8>,
    /// Mask samples likewise, if the layer has a mask.
    pub mask: Option<Vec<u8>>,
}

/// The layers of a document as stored: the stack bottom first and the active layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayersSection {
    /// The active layer's index.
    pub active: u32,
    /// Level-0 samples of every store (vertices, then edges in id order, then face
    /// interiors in face order, at the face resolutions of the face records).
    pub samples_per_store: u64,
    /// The layers, bottom first.
    pub layers: Vec<LayerRecord>,
}

fn bad(message: String) -> PackedFileError {
    PackedFileError::BadLayers(message)
}

impl LayersSection {
    /// Number of stores (contents and masks).
    fn store_count(&self) -> u64 {
        self.layers.iter().map(|layer| 1 + u64::from(layer.mask.is_some())).sum()
    }

    /// Checks everything [`LayersSection::parse`] checks (except the colours, which
    /// [`super::check_colors`]' rule covers per store).
    fn check(&self, format: ColorFormat) -> Result<(), PackedFileError> {
        let count = self.layers.len();
        if count == 0 || count > MAX_LAYERS as usize {
            return Err(bad(format!("{count} layers; a file holds 1 to {MAX_LAYERS}")));
        }
        if self.active as usize >= count {
            return Err(bad(format!("active layer {} of {count}", self.active)));
        }
        let store_bytes = self.samples_per_store.checked_mul(format.bytes_per_sample() as u64);
        for (index, layer) in self.layers.iter().enumerate() {
            if layer.name.len() > NAME_BYTES {
                return Err(bad(format!("layer {index}: name of {} bytes, at most {NAME_BYTES}", layer.name.len())));
            }
            if !(0.0..=1.0).contains(&layer.opacity) {
                return Err(bad(format!("layer {index}: opacity {} outside [0, 1]", layer.opacity)));
            }
            if layer.blend > 3 {
                return Err(bad(format!("layer {index}: unknown blend mode {}", layer.blend)));
            }
            for (what, samples) in
                std::iter::once(("content", &layer.content)).chain(layer.mask.as_ref().map(|m| ("mask", m)))
            {
                if Some(samples.len() as u64) != store_bytes {
                    return Err(bad(format!(
                        "layer {index}: {what} of {} bytes, expected {store_bytes:?}",
                        samples.len()
                    )));
                }
                check_samples(samples, format)
                    .map_err(|sample| bad(format!("layer {index}: {what} sample {sample} is not a storable colour")))?;
            }
        }
        Ok(())
    }

    /// The section's bytes (its length is a whole number of 4-byte words).
    pub fn to_bytes(&self, format: ColorFormat) -> Result<Vec<u8>, PackedFileError> {
        self.check(format)?;
        let mut out = Vec::new();
        out.extend_from_slice(&(self.layers.len() as u32).to_le_bytes());
        out.extend_from_slice(&self.active.to_le_bytes());
        out.extend_from_slice(&self.samples_per_store.to_le_bytes());
        for layer in &self.layers {
            let flags =
                if layer.visible { LAYER_VISIBLE } else { 0 } | if layer.mask.is_some() { LAYER_HAS_MASK } else { 0 };
            out.extend_from_slice(&flags.to_le_bytes());
            out.extend_from_slice(&layer.blend.to_le_bytes());
            out.extend_from_slice(&layer.opacity.to_le_bytes());
            out.extend_from_slice(&(layer.name.len() as u32).to_le_bytes());
            let mut name = [0u8; NAME_BYTES];
            name[..layer.name.len()].copy_from_slice(layer.name.as_bytes());
            out.extend_from_slice(&name);
        }
        for layer in &self.layers {
            out.extend_from_slice(&layer.content);
            if let Some(mask) = &layer.mask {
                out.extend_from_slice(mask);
            }
        }
        // Samples of 4, 8 or 16 bytes keep the section a whole number of words.
        Ok(out)
    }

    /// Decodes a layers section, refusing anything malformed; allocates no more than
    /// `bytes.len()` (every length is checked against it first).
    pub fn parse(bytes: &[u8], format: ColorFormat) -> Result<Self, PackedFileError> {
        let word = |at: u64| -> Option<u32> {
            let at = usize::try_from(at).ok()?;
            Some(u32::from_le_bytes(*bytes.get(at..at.checked_add(4)?)?.first_chunk::<4>()?))
        };
        let too_short = || bad(format!("{} bytes, shorter than its records", bytes.len()));
        let count = word(0).ok_or_else(too_short)?;
        let active = word(4).ok_or_else(too_short)?;
        let samples_per_store =
            u64::from(word(8).ok_or_else(too_short)?) | (u64::from(word(12).ok_or_else(too_short)?) << 32);
        if count == 0 || count > MAX_LAYERS {
            return Err(bad(format!("{count} layers; a file holds 1 to {MAX_LAYERS}")));
        }
        let records_end = LAYERS_HEADER_SIZE + u64::from(count) * LAYER_RECORD_SIZE;
        if records_end > bytes.len() as u64 {
            return Err(too_short());
        }
        let mut heads = Vec::with_capacity(count as usize);
        for index in 0..u64::from(count) {
            let at = LAYERS_HEADER_SIZE + index * LAYER_RECORD_SIZE;
            let [flags, blend, opacity, name_len] = [0, 4, 8, 12].map(|o| word(at + o).unwrap_or_default());
            if flags & !(LAYER_VISIBLE | LAYER_HAS_MASK) != 0 {
                let unknown = flags & !(LAYER_VISIBLE | LAYER_HAS_MASK);
                return Err(bad(format!("layer {index}: unknown flag bits {unknown:#x}")));
            }
            let name_at = (at + 16) as usize;
            let field = bytes.get(name_at..name_at + NAME_BYTES).ok_or_else(too_short)?;
            let len = name_len as usize;
            if len > NAME_BYTES || field[len.min(NAME_BYTES)..].iter().any(|&b| b != 0) {
                return Err(bad(format!("layer {index}: name length {name_len} or padding not zero")));
            }
            let name = std::str::from_utf8(&field[..len])
                .map_err(|_| bad(format!("layer {index}: name is not UTF-8")))?
                .to_owned();
            heads.push((name, flags, blend, f32::from_bits(opacity)));
        }
        let stores: u64 = heads.iter().map(|h| 1 + u64::from(h.1 & LAYER_HAS_MASK != 0)).sum();
        let store_bytes = samples_per_store.checked_mul(format.bytes_per_sample() as u64);
        let expected = store_bytes.and_then(|b| b.checked_mul(stores)).and_then(|b| b.checked_add(records_end));
        if expected != Some(bytes.len() as u64) {
            return Err(bad(format!(
                "{} bytes, but {stores} stores of {samples_per_store} samples need {expected:?}",
                bytes.len()
            )));
        }
        let store_bytes = store_bytes.unwrap_or_default() as usize;
        let mut cursor = records_end as usize;
        let mut take = || {
            let slice = bytes.get(cursor..cursor + store_bytes).unwrap_or_default().to_vec();
            cursor += store_bytes;
            slice
        };
        let layers = heads
            .into_iter()
            .map(|(name, flags, blend, opacity)| LayerRecord {
                name,
                visible: flags & LAYER_VISIBLE != 0,
                opacity,
                blend,
                content: take(),
                mask: (flags & LAYER_HAS_MASK != 0).then(&mut take),
            })
            .collect();
        let section = LayersSection { active, samples_per_store, layers };
        section.check(format)?;
        debug_assert_eq!(section.store_count(), stores);
        Ok(section)
    }
}

/// The first sample of `samples` (encoded in `format`) that is not storable, if any.
fn check_samples(samples: &[u8], format: ColorFormat) -> Result<(), u64> {
    if format == ColorFormat::Rgba8Srgb {
        return Ok(());
    }
    let size = format.bytes_per_sample();
    match (0u64..).zip(samples.chunks_exact(size)).find(|(_, b)| !crate::colors::format::is_storable(format.decode(b)))
    {
        Some((sample, _)) => Err(sample),
        None => Ok(()),
    }
}
