//! The container: the GLB chunks, and the bytes of buffers and images (the GLB BIN chunk,
//! base64 data URIs and external files relative to the glTF), read with checked
//! arithmetic and bounds checks.

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};

use gltf::json;

use super::{Fail, invalid};

/// Largest external image file read.
const MAX_IMAGE_FILE: u64 = 256 << 20;

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
pub(super) fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let header = bytes.get(0..12).ok_or_else(|| "truncated GLB header (shorter than 12 bytes)".to_owned())?;
    let version = read_u32(header, 4).unwrap_or(0);
    let length = read_u32(header, 8).unwrap_or(0) as usize;
    if version != 2 {
        return Err(format!("unsupported GLB version {version} (only 2 is supported)"));
    }
    if length < 12 {
        return Err(format!("GLB header declares a length of {length} bytes, less than the header"));
    }
    let data = bytes
        .get(12..length)
        .ok_or_else(|| format!("truncated GLB: the header declares {length} bytes but the file has {}", bytes.len()))?;
    let mut json: Option<&[u8]> = None;
    let mut bin: Option<&[u8]> = None;
    let mut pos = 0usize;
    while pos < data.len() {
        let chunk_header = data
            .get(pos..pos.saturating_add(8))
            .ok_or_else(|| format!("truncated GLB chunk header at byte {}", pos + 12))?;
        let chunk_len = read_u32(chunk_header, 0).unwrap_or(0) as usize;
        let chunk_type = chunk_header.get(4..8).unwrap_or(&[]);
        let start = pos + 8;
        let end = start.checked_add(chunk_len).filter(|&end| end <= data.len());
        let Some(end) = end else {
            return Err(format!(
                "truncated GLB: chunk at byte {} declares {chunk_len} bytes but only {} remain",
                pos + 12,
                data.len() - start
            ));
        };
        let chunk = data.get(start..end).unwrap_or(&[]);
        match chunk_type {
            b"JSON" => {
                if json.is_some() {
                    return Err("GLB has more than one JSON chunk".to_owned());
                }
                if chunk.is_empty() {
                    return Err("GLB JSON chunk is empty".to_owned());
                }
                json = Some(chunk);
            }
            b"BIN\0" => {
                if json.is_none() {
                    return Err("GLB's first chunk is BIN, not JSON".to_owned());
                }
                if bin.is_some() {
                    return Err("GLB has more than one BIN chunk".to_owned());
                }
                bin = Some(chunk);
            }
            other => {
                if json.is_none() {
                    return Err(format!("GLB's first chunk has type {:?}, not JSON", String::from_utf8_lossy(other)));
                }
                // Unknown chunks after the JSON chunk are ignored, as the spec requires.
            }
        }
        pos = end;
    }
    let json = json.ok_or_else(|| "GLB has no JSON chunk".to_owned())?;
    Ok((json, bin))
}

fn read_u32(bytes: &[u8], offset: usize) -> Option<u32> {
    let raw: [u8; 4] = bytes.get(offset..offset.checked_add(4)?)?.try_into().ok()?;
    Some(u32::from_le_bytes(raw))
}

/// The GLB BIN chunk must hold at least what buffer 0 declares (checked even when no
/// accessor reads it: a mismatch means a corrupt container).
pub(super) fn check_glb_buffer(root: &json::Root, bin: Option<&[u8]>) -> Result<(), Fail> {
    if let (Some(bin), Some(buffer)) = (bin, root.buffers.first())
        && buffer.uri.is_none()
        && buffer.byte_length.0 > bin.len() as u64
    {
        return invalid(format!(
            "buffer 0 declares {} bytes but the GLB BIN chunk holds only {}",
            buffer.byte_length.0,
            bin.len()
        ));
    }
    Ok(())
}

/// Loads buffer `i`: the GLB BIN chunk, a data URI or an external file.
pub(super) fn load_buffer<'a>(
    root: &json::Root,
    i: usize,
    bin: Option<&'a [u8]>,
    base_dir: Option<&Path>,
) -> Result<Cow<'a, [u8]>, Fail> {
    let Some(buffer) = root.buffers.get(i) else {
        return invalid(format!("buffer {i} does not exist"));
    };
    {
        let declared = buffer.byte_length.0;
        let data: Cow<'a, [u8]> = match buffer.uri.as_deref() {
            None => {
                let Some(bin) = bin.filter(|_| i == 0) else {
                    return invalid(format!("buffer {i} has no uri and there is no GLB BIN chunk for it"));
                };
                Cow::Borrowed(bin)
            }
            Some(uri) => load_uri(uri, base_dir, &format!("buffer {i}"), Some(declared))?,
        };
        let Some(data) = usize::try_from(declared).ok().and_then(|len| slice_cow(data, len)) else {
            return invalid(format!(
                "buffer {i} declares {declared} bytes but its data is shorter (missing or truncated data)"
            ));
        };
        Ok(data)
    }
}

fn slice_cow(data: Cow<'_, [u8]>, len: usize) -> Option<Cow<'_, [u8]>> {
    if data.len() < len {
        return None;
    }
    Some(match data {
        Cow::Borrowed(slice) => Cow::Borrowed(slice.get(..len)?),
        Cow::Owned(mut vec) => {
            vec.truncate(len);
            Cow::Owned(vec)
        }
    })
}

/// Reads a URI's bytes: a base64 data URI or a relative path. `limit` caps how much of
/// an external file is read.
pub(super) fn load_uri(
    uri: &str,
    base_dir: Option<&Path>,
    what: &str,
    limit: Option<u64>,
) -> Result<Cow<'static, [u8]>, Fail> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            return invalid(format!("{what}: malformed data URI (no comma)"));
        };
        let Some(mime) = header.strip_suffix(";base64") else {
            return invalid(format!("{what}: data URI is not base64-encoded"));
        };
        if what.starts_with("buffer") && !matches!(mime, "application/octet-stream" | "application/gltf-buffer") {
            return invalid(format!(
                "{what}: data URI has media type {mime:?}, not application/octet-stream or application/gltf-buffer"
            ));
        }
        let Some(decoded) = decode_base64(payload) else {
            return invalid(format!("{what}: data URI holds invalid base64"));
        };
        return Ok(Cow::Owned(decoded));
    }
    let scheme_end = uri.find(':');
    let path_sep = uri.find(['/', '\\']);
    if let Some(colon) = scheme_end
        && path_sep.is_none_or(|sep| colon < sep)
    {
        return invalid(format!(
            "{what}: URI {uri:?} uses a scheme that is not supported (only data URIs and relative paths are)"
        ));
    }
    let Some(relative) = percent_decode(uri) else {
        return invalid(format!("{what}: URI {uri:?} has invalid percent-encoding"));
    };
    let Some(base_dir) = base_dir else {
        return invalid(format!("{what}: refers to external file {relative:?} but no base directory was given"));
    };
    if relative.starts_with(['/', '\\']) || Path::new(&relative).is_absolute() {
        return invalid(format!("{what}: URI {uri:?} is an absolute path; only relative paths are supported"));
    }
    let full: PathBuf = base_dir.join(&relative);
    let label = format!("{what} file {relative:?} ({})", full.display());
    let metadata = std::fs::metadata(&full).map_err(|source| Fail::Io { what: label.clone(), source })?;
    if !metadata.is_file() {
        return invalid(format!("{label} is not a regular file"));
    }
    // Never read more than the file holds (a buffer's declared length is only a claim)
    // nor, for images, more than MAX_IMAGE_FILE.
    let cap = match limit {
        Some(limit) => limit.min(metadata.len()),
        None if metadata.len() > MAX_IMAGE_FILE => {
            return invalid(format!(
                "{label} is {} bytes, larger than the {MAX_IMAGE_FILE} accepted for an image",
                metadata.len()
            ));
        }
        None => metadata.len(),
    };
    let mut data = Vec::new();
    std::fs::File::open(&full)
        .and_then(|file| file.take(cap).read_to_end(&mut data))
        .map_err(|source| Fail::Io { what: label.clone(), source })?;
    Ok(Cow::Owned(data))
}

fn decode_base64(text: &str) -> Option<Vec<u8>> {
    fn value(c: u8) -> Option<u32> {
        match c {
            b'A'..=b'Z' => Some(u32::from(c - b'A')),
            b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
            b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
            b'+' | b'-' => Some(62),
            b'/' | b'_' => Some(63),
            _ => None,
        }
    }
    let trimmed = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(trimmed.len() / 4 * 3 + 3);
    let mut acc = 0u32;
    let mut bits = 0u32;
    for &c in trimmed {
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push(((acc >> bits) & 0xff) as u8);
        }
    }
    if bits >= 6 {
        return None;
    }
    Some(out)
}

fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip() {
        assert_eq!(decode_base64("aGVsbG8=").as_deref(), Some(&b"hello"[..]));
        assert_eq!(decode_base64("aGVsbA==").as_deref(), Some(&b"hell"[..]));
        assert_eq!(decode_base64("").as_deref(), Some(&b""[..]));
        assert!(decode_base64("a").is_none());
        assert!(decode_base64("a*bc").is_none());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin").as_deref(), Some("a b.bin"));
        assert!(percent_decode("a%2").is_none());
    }

    #[test]
    fn glb_truncations_are_errors() {
        assert!(split_glb(b"glTF").is_err());
        let mut header = b"glTF".to_vec();
        header.extend(2u32.to_le_bytes());
        header.extend(4u32.to_le_bytes());
        assert!(split_glb(&header).is_err());
    }
}
