//! Tests of the packed file format (crates/core/src/packing/file/, docs/FORMAT.md).
//!
//! Header offsets are hard-coded here from docs/FORMAT.md, so these tests check the
//! documented layout, not just that the writer and the reader agree.

use std::collections::BTreeMap;
use std::path::PathBuf;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::{Resolution, edge_chain_len, interior_chain_len};
use meshpaint_core::packing::file::{
    MAGIC, PackedFileError, VERSION, from_bytes, looks_like_packed, read_file, read_summary, to_bytes, write_file,
};
use meshpaint_core::packing::linear::{FaceRecord, PackedMesh, pack_word};

// Header field offsets (docs/FORMAT.md).
const VERSION_AT: usize = 8;
const HEADER_SIZE_AT: usize = 12;
const FILE_SIZE_AT: usize = 16;
const FLAGS_AT: usize = 24;
const FORMAT_AT: usize = 28;
const VERTEX_COUNT_AT: usize = 32;
const FACE_COUNT_AT: usize = 36;
const VERTEX_LEVELS_AT: usize = 40;
const RESERVED_44_AT: usize = 44;
const SAMPLE_COUNT_AT: usize = 48;
const SECTIONS_AT: usize = 56;
const RESERVED_120_AT: usize = 120;
const CHECKSUM_AT: usize = 124;
const POSITIONS: usize = 0;
const INDICES: usize = 1;
const RECORDS: usize = 2;
const COLORS: usize = 3;

/// A tetrahedron with faces at R = 1, 2, 4, 8, a colour buffer laid out as
/// vertices | edge chains (edge order by (low, high) id) | interior chains, filled with
/// distinct-ish bytes.
fn tetrahedron(format: ColorFormat) -> PackedMesh {
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, -0.0], [0.0, 1.5, 0.0], [0.25, 0.25, -2.0e-7]];
    let indices: Vec<[u32; 3]> = vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]];
    let face_log2 = [0u32, 1, 2, 3];
    let vertex_levels = 4;

    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut edge_log2: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for (tri, &log2) in indices.iter().zip(&face_log2) {
        for k in 0..3 {
            let entry = edge_log2.entry(key(tri[k], tri[(k + 1) % 3])).or_insert(0);
            *entry = (*entry).max(log2);
        }
    }
    let mut next = positions.len() as u32 * vertex_levels;
    let mut edge_base = BTreeMap::new();
    for (&edge, &log2) in &edge_log2 {
        edge_base.insert(edge, next);
        next += edge_chain_len(Resolution::from_log2(log2).unwrap());
    }
    let mut face_records = Vec::new();
    for (tri, &log2) in indices.iter().zip(&face_log2) {
        let r = Resolution::from_log2(log2).unwrap();
        let interior_base = if r.get() >= 4 { next } else { 0 };
        next += interior_chain_len(r);
        let edge = |k: usize| {
            let e = key(tri[k], tri[(k + 1) % 3]);
            pack_word(edge_base[&e], edge_log2[&e])
        };
        face_records.push(FaceRecord { interior: pack_word(interior_base, log2), edges: [edge(0), edge(1), edge(2)] });
    }
    let sample_count = next as usize;
    // Varied colours every format holds (docs/FORMAT.md "Colour values"): any bytes for
    // RGBA8, channel values in [0, 1] encoded for the float formats.
    let colors = match format {
        ColorFormat::Rgba8Srgb => (0..sample_count * 4).map(|i| (i * 7 + i / 251) as u8).collect(),
        _ => {
            let channel = |i: usize| ((i * 7 + i / 251) % 256) as f32 / 255.0;
            let mut out = Vec::new();
            for k in 0..sample_count {
                format.encode_into(std::array::from_fn(|c| channel(4 * k + c)), &mut out);
            }
            out
        }
    };
    PackedMesh { positions, indices, vertex_levels, face_records, format, colors }
}

fn get_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn get_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

fn put_u32(bytes: &mut [u8], at: usize, value: u32) {
    bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

fn put_u64(bytes: &mut [u8], at: usize, value: u64) {
    bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
}

/// `(offset, length)` of section `k` as the header says.
fn section(bytes: &[u8], k: usize) -> (usize, usize) {
    let at = SECTIONS_AT + 16 * k;
    (get_u64(bytes, at) as usize, get_u64(bytes, at + 8) as usize)
}

/// Recomputes the CRC-32 over everything but the checksum field, as FORMAT.md says.
fn reseal(bytes: &mut [u8]) {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..CHECKSUM_AT]);
    hasher.update(&bytes[CHECKSUM_AT + 4..]);
    let crc = hasher.finalize();
    put_u32(bytes, CHECKSUM_AT, crc);
}

/// Applies `patch` to a valid file, reseals it and returns the reader's error message.
fn hostile(format: ColorFormat, patch: impl FnOnce(&mut Vec<u8>)) -> String {
    let mut bytes = to_bytes(&tetrahedron(format)).unwrap();
    patch(&mut bytes);
    reseal(&mut bytes);
    match from_bytes(&bytes) {
        Ok(_) => panic!("hostile file accepted"),
        Err(error) => error.to_string(),
    }
}

fn assert_contains(message: &str, needles: &[&str]) {
    for needle in needles {
        assert!(message.contains(needle), "{message:?} does not mention {needle:?}");
    }
}

fn unique_temp_dir(tag: &str) -> PathBuf {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos();
    let dir = std::env::temp_dir().join(format!("meshpaint-packed-file-{tag}-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn round_trip_is_exact_and_deterministic_for_every_format() {
    for format in ColorFormat::ALL {
        let mesh = tetrahedron(format);
        let bytes = to_bytes(&mesh).unwrap();
        assert_eq!(from_bytes(&bytes).unwrap(), mesh, "{format:?}");
        assert_eq!(to_bytes(&mesh).unwrap(), bytes, "{format:?}: not deterministic");
        // -0.0 survives bit-exactly.
        let back = from_bytes(&bytes).unwrap();
        assert_eq!(back.positions[1][2].to_bits(), (-0.0f32).to_bits());

        // Documented header fields.
        assert!(looks_like_packed(&bytes));
        assert_eq!(bytes[..8], MAGIC);
        assert_eq!(&MAGIC, b"MESHPAK\0");
        assert_eq!(VERSION, 2, "the newest version");
        assert_eq!(get_u32(&bytes, VERSION_AT), 1, "a file without layers is version 1");
        assert_eq!(get_u32(&bytes, HEADER_SIZE_AT), 128);
        assert_eq!(get_u64(&bytes, FILE_SIZE_AT), bytes.len() as u64);
        assert_eq!(get_u32(&bytes, FLAGS_AT), 0);
        assert_eq!(get_u32(&bytes, FORMAT_AT), format.code());
        assert_eq!(get_u32(&bytes, VERTEX_COUNT_AT), 4);
        assert_eq!(get_u32(&bytes, FACE_COUNT_AT), 4);
        assert_eq!(get_u32(&bytes, VERTEX_LEVELS_AT), 4);
        assert_eq!(get_u32(&bytes, RESERVED_44_AT), 0);
        assert_eq!(get_u64(&bytes, SAMPLE_COUNT_AT), mesh.sample_count());
        assert_eq!(get_u32(&bytes, RESERVED_120_AT), 0);
        assert!(bytes[128..256].iter().all(|&b| b == 0), "header padding");

        // Sections: aligned, in order, zero gaps, content little-endian as documented.
        let mut previous_end = 128;
        for k in 0..4 {
            let (offset, length) = section(&bytes, k);
            assert_eq!(offset % 256, 0, "section {k} aligned");
            assert!(offset >= previous_end);
            assert!(bytes[previous_end..offset].iter().all(|&b| b == 0), "gap zero");
            previous_end = offset + length;
        }
        assert_eq!(previous_end, bytes.len(), "file ends at the colour section's end");
        let (positions, _) = section(&bytes, POSITIONS);
        assert_eq!(get_u32(&bytes, positions + 4 * 7), 1.5f32.to_bits());
        let (indices, _) = section(&bytes, INDICES);
        assert_eq!(get_u32(&bytes, indices + 4 * 4), 3);
        let (records, length) = section(&bytes, RECORDS);
        assert_eq!(length, 64);
        assert_eq!(get_u32(&bytes, records + 16 * 3), mesh.face_records[3].interior);
        assert_eq!(get_u32(&bytes, records + 16 * 2 + 8), mesh.face_records[2].edges[1]);
        let (colors, length) = section(&bytes, COLORS);
        assert_eq!(&bytes[colors..colors + length], &mesh.colors[..]);
    }
}

#[test]
fn documented_example_layout() {
    // docs/FORMAT.md: the tetrahedron with 85 RGBA8 samples.
    let mesh = tetrahedron(ColorFormat::Rgba8Srgb);
    assert_eq!(mesh.sample_count(), 85);
    let bytes = to_bytes(&mesh).unwrap();
    assert_eq!(bytes.len(), 1364);
    let table: Vec<_> = (0..4).map(|k| section(&bytes, k)).collect();
    assert_eq!(table, [(256, 48), (512, 48), (768, 64), (1024, 340)]);
}

#[test]
fn empty_mesh_round_trips() {
    for format in ColorFormat::ALL {
        let mesh = PackedMesh { format, ..PackedMesh::default() };
        let bytes = to_bytes(&mesh).unwrap();
        assert_eq!(bytes.len(), 256);
        assert_eq!(from_bytes(&bytes).unwrap(), mesh);
    }
}

#[test]
fn file_round_trip_is_atomic_and_leaves_no_temporary_file() {
    let dir = unique_temp_dir("roundtrip");
    let path = dir.join("tetra.mpk");
    for format in ColorFormat::ALL {
        let mesh = tetrahedron(format);
        write_file(&path, &mesh).unwrap(); // also overwrites the previous format
        assert_eq!(read_file(&path).unwrap(), mesh);
        assert_eq!(std::fs::read(&path).unwrap(), to_bytes(&mesh).unwrap());
    }
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|entry| entry.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("tetra.mpk")]);

    // A refused mesh leaves the existing file untouched and names the path.
    let mut bad = tetrahedron(ColorFormat::Rgba8Srgb);
    bad.positions[0][0] = f32::NAN;
    let message = write_file(&path, &bad).unwrap_err().to_string();
    assert_contains(&message, &["tetra.mpk", "not finite"]);
    assert_eq!(read_file(&path).unwrap(), tetrahedron(ColorFormat::Rgba32F));

    // Errors name the path.
    let missing = dir.join("missing.mpk");
    let message = read_file(&missing).unwrap_err().to_string();
    assert_contains(&message, &["missing.mpk", "cannot read"]);
    let junk = dir.join("junk.mpk");
    std::fs::write(&junk, b"definitely not a packed file").unwrap();
    let message = read_file(&junk).unwrap_err().to_string();
    assert_contains(&message, &["junk.mpk", "not a meshpaint packed file"]);
    let message = write_file(&dir.join("no-such-dir").join("x.mpk"), &bad).unwrap_err();
    assert_contains(&message.to_string(), &["x.mpk"]);
    let good = tetrahedron(ColorFormat::Rgba8Srgb);
    let message = write_file(&dir.join("no-such-dir").join("x.mpk"), &good).unwrap_err();
    assert!(matches!(message, PackedFileError::Io { .. }), "{message:?}");
    assert_contains(&message.to_string(), &["no-such-dir"]);

    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn content_sniffing() {
    let bytes = to_bytes(&tetrahedron(ColorFormat::Rgba16F)).unwrap();
    assert!(looks_like_packed(&bytes));
    assert!(looks_like_packed(&bytes[..8]));
    assert!(!looks_like_packed(&bytes[..7]));
    assert!(!looks_like_packed(b"glTF\x02\x00\x00\x00"));
    assert!(!looks_like_packed(b""));
    let message = from_bytes(b"glTF\x02\x00\x00\x00 and more bytes").unwrap_err();
    assert!(matches!(message, PackedFileError::NotPacked { .. }), "{message:?}");
}

#[test]
fn every_truncation_is_refused() {
    for format in ColorFormat::ALL {
        let bytes = to_bytes(&tetrahedron(format)).unwrap();
        for len in 0..bytes.len() {
            let error = from_bytes(&bytes[..len]).expect_err("truncated file accepted");
            if len >= 8 {
                assert!(error.to_string().starts_with("truncated"), "{len}: {error}");
            }
        }
        let (colors, _) = section(&bytes, COLORS);
        let message = from_bytes(&bytes[..colors + 5]).unwrap_err().to_string();
        assert_eq!(
            message,
            format!("truncated: header says colors end at byte {} but the file has {} bytes", bytes.len(), colors + 5)
        );
    }
    let empty = to_bytes(&PackedMesh::default()).unwrap();
    for len in 0..empty.len() {
        assert!(from_bytes(&empty[..len]).is_err());
    }
}

#[test]
fn every_byte_flip_is_refused() {
    for format in ColorFormat::ALL {
        let bytes = to_bytes(&tetrahedron(format)).unwrap();
        for mask in [0xFF, 0x01] {
            for at in 0..bytes.len() {
                let mut flipped = bytes.clone();
                flipped[at] ^= mask;
                assert!(from_bytes(&flipped).is_err(), "{format:?}: flip {mask:#x} at byte {at} accepted");
            }
        }
        // A flip in a padding byte or the checksum itself is a checksum mismatch.
        for at in [200, CHECKSUM_AT, bytes.len() - 1] {
            let mut flipped = bytes.clone();
            flipped[at] ^= 0x01;
            let message = from_bytes(&flipped).unwrap_err().to_string();
            assert_contains(&message, &["checksum mismatch"]);
        }
    }
}

#[test]
fn resealed_byte_flips_are_refused_or_within_bounds() {
    // With the checksum recomputed, a flip reaches the content checks: the reader must
    // refuse it or return a mesh that satisfies every bound (which the writer re-checks).
    for format in ColorFormat::ALL {
        let bytes = to_bytes(&tetrahedron(format)).unwrap();
        let mut accepted = 0;
        for mask in [0xFF, 0x01, 0x80, 0x10] {
            for at in (0..bytes.len()).filter(|&at| !(CHECKSUM_AT..CHECKSUM_AT + 4).contains(&at)) {
                let mut flipped = bytes.clone();
                flipped[at] ^= mask;
                reseal(&mut flipped);
                if let Ok(mesh) = from_bytes(&flipped) {
                    accepted += 1;
                    let again = to_bytes(&mesh).unwrap_or_else(|e| panic!("byte {at} ^ {mask:#x}: {e}"));
                    assert_eq!(from_bytes(&again).unwrap(), mesh);
                }
            }
        }
        // Colour bytes and some position bits are free data, so some flips are accepted.
        assert!(accepted > 0);
    }
}

#[test]
fn appended_bytes_are_refused() {
    let mut bytes = to_bytes(&tetrahedron(ColorFormat::Rgba8Srgb)).unwrap();
    bytes.extend_from_slice(&[0; 4]);
    let message = from_bytes(&bytes).unwrap_err().to_string();
    assert_contains(&message, &["4 unexpected bytes"]);
    // Even with the file size and checksum updated, the last section must end the file.
    let len = bytes.len() as u64;
    put_u64(&mut bytes, FILE_SIZE_AT, len);
    reseal(&mut bytes);
    let message = from_bytes(&bytes).unwrap_err().to_string();
    assert_contains(&message, &["4 unexpected bytes", "last section"]);
}

#[test]
fn absurd_header_counts_are_refused_without_allocating() {
    let f = ColorFormat::Rgba8Srgb;
    let message = hostile(f, |b| put_u32(b, VERTEX_COUNT_AT, u32::MAX));
    assert_contains(&message, &["positions section is 48 bytes", "4294967295 vertices"]);
    let message = hostile(f, |b| put_u32(b, FACE_COUNT_AT, u32::MAX));
    assert_contains(&message, &["indices section is 48 bytes", "4294967295 faces"]);
    let message = hostile(f, |b| put_u64(b, SAMPLE_COUNT_AT, u64::MAX));
    assert_contains(&message, &["sample count 18446744073709551615 exceeds"]);
    let message = hostile(f, |b| put_u64(b, SAMPLE_COUNT_AT, (1 << 28) + 1));
    assert_contains(&message, &["exceeds the limit"]);
    // Within the sample limit but inconsistent with the colour section.
    let message = hostile(f, |b| put_u64(b, SAMPLE_COUNT_AT, 1 << 28));
    assert_contains(&message, &["colors section is", "268435456 samples need 1073741824"]);
    let message = hostile(f, |b| put_u32(b, VERTEX_LEVELS_AT, u32::MAX));
    assert_contains(&message, &["vertex_levels is 4294967295"]);

    // Section offsets and lengths near u64::MAX.
    let colors_length = SECTIONS_AT + 16 * COLORS + 8;
    let message = hostile(f, |b| put_u64(b, colors_length, u64::MAX - 100));
    assert_contains(&message, &["colors section", "overflows"]);
    let message = hostile(f, |b| put_u64(b, colors_length, u64::MAX / 2));
    assert_contains(&message, &["truncated: header says colors end"]);
    let message = hostile(f, |b| put_u64(b, SECTIONS_AT + 16 * COLORS, u64::MAX - 255));
    assert_contains(&message, &["colors section", "overflows"]);
    let message = hostile(f, |b| put_u64(b, SECTIONS_AT, 1 << 62));
    assert_contains(&message, &["truncated: header says positions end"]);
    let message = hostile(f, |b| put_u64(b, FILE_SIZE_AT, u64::MAX));
    assert_contains(&message, &["truncated: header says the file ends"]);

    // A huge, self-consistent count with a small file: the section table is checked
    // against the file length first.
    let message = hostile(f, |b| {
        put_u32(b, FACE_COUNT_AT, u32::MAX);
        put_u64(b, SECTIONS_AT + 16 * INDICES + 8, 12 * u64::from(u32::MAX));
    });
    assert_contains(&message, &["truncated: header says indices end"]);
}

#[test]
fn malformed_headers_are_refused() {
    let f = ColorFormat::Rgba16F;
    let message = hostile(f, |b| put_u32(b, VERSION_AT, 3));
    assert_contains(&message, &["unsupported packed file version 3"]);
    let message = hostile(f, |b| put_u32(b, VERSION_AT, 2));
    assert_contains(&message, &["version-2 file must set flag bit 0"]);
    let message = hostile(f, |b| put_u32(b, FLAGS_AT, 1));
    assert_contains(&message, &["unknown flag bits 0x00000001"]);
    let message = hostile(f, |b| put_u32(b, HEADER_SIZE_AT, 256));
    assert_contains(&message, &["header size is 256"]);
    let message = hostile(f, |b| put_u32(b, FLAGS_AT, 1 << 5));
    assert_contains(&message, &["unknown flag bits 0x00000020"]);
    let message = hostile(f, |b| put_u32(b, FORMAT_AT, 3));
    assert_contains(&message, &["unknown colour format code 3"]);
    // A known but different format makes the colour section the wrong length.
    let message = hostile(f, |b| put_u32(b, FORMAT_AT, 2));
    assert_contains(&message, &["colors section is"]);
    let message = hostile(f, |b| put_u32(b, RESERVED_44_AT, 9));
    assert_contains(&message, &["reserved header field at byte 44"]);
    let message = hostile(f, |b| put_u32(b, RESERVED_120_AT, 9));
    assert_contains(&message, &["reserved header field at byte 120"]);

    let message = hostile(f, |b| {
        let at = SECTIONS_AT + 16 * RECORDS;
        let offset = get_u64(b, at);
        put_u64(b, at, offset + 4);
    });
    assert_contains(&message, &["face records section offset", "not a multiple of 256"]);
    let message = hostile(f, |b| {
        let (indices, _) = section(b, INDICES);
        put_u64(b, SECTIONS_AT + 16 * RECORDS, indices as u64);
    });
    assert_contains(&message, &["face records section starts", "before the end of the indices"]);
    let message = hostile(f, |b| b[200] = 1);
    assert_contains(&message, &["padding byte at offset 200 is 0x01"]);
    let message = hostile(f, |b| {
        let (_, length) = section(b, INDICES);
        let (offset, _) = section(b, RECORDS);
        b[offset - 1] = 0xAB;
        assert!(length < 255);
    });
    assert_contains(&message, &["padding byte at offset", "0xab"]);
    let message = hostile(f, |b| put_u64(b, SECTIONS_AT, 0));
    assert_contains(&message, &["before the end of the header"]);
}

#[test]
fn hostile_content_is_refused_with_a_clear_message() {
    for f in ColorFormat::ALL {
        let mesh = tetrahedron(f);
        let samples = mesh.sample_count() as u32;

        let message = hostile(f, |b| {
            let (indices, _) = section(b, INDICES);
            put_u32(b, indices + 4 * (3 * 3 + 1), 99);
        });
        assert_eq!(message, "index 1 of triangle 3 is 99 but there are 4 vertices");

        let message = hostile(f, |b| {
            let (indices, _) = section(b, INDICES);
            put_u32(b, indices + 4 * (3 + 2), 0);
        });
        assert_contains(&message, &["triangle 1 repeats a corner", "[0, 3, 0]"]);

        let message = hostile(f, |b| {
            let (positions, _) = section(b, POSITIONS);
            put_u32(b, positions + 4 * 7, f32::NAN.to_bits());
        });
        assert_contains(&message, &["position of vertex 2 is not finite"]);
        let message = hostile(f, |b| {
            let (positions, _) = section(b, POSITIONS);
            put_u32(b, positions, f32::NEG_INFINITY.to_bits());
        });
        assert_contains(&message, &["position of vertex 0 is not finite"]);

        // Interior chain of the R = 8 face (24 samples) starting too late.
        let message = hostile(f, |b| {
            let (records, _) = section(b, RECORDS);
            put_u32(b, records + 16 * 3, pack_word(samples - 23, 3));
        });
        assert_contains(&message, &["face record 3: interior chain (R = 8)", "runs past the"]);
        // Edge chain of an R = 8 edge running past the buffer.
        let message = hostile(f, |b| {
            let (records, _) = section(b, RECORDS);
            put_u32(b, records + 16 * 3 + 4, pack_word(samples - 1, 3));
        });
        assert_contains(&message, &["face record 3: edge 0 chain (R = 8)", "runs past"]);

        // log2 = 15 in the face word, and in an edge word.
        let message = hostile(f, |b| {
            let (records, _) = section(b, RECORDS);
            put_u32(b, records + 16, pack_word(0, 15));
        });
        assert_contains(&message, &["face record 1: log2 R = 15 exceeds 12"]);
        let message = hostile(f, |b| {
            let (records, _) = section(b, RECORDS);
            put_u32(b, records + 16 + 8, pack_word(0, 13));
        });
        assert_contains(&message, &["face record 1, edge 1: log2 R_e = 13"]);
        // An edge coarser than its face.
        let message = hostile(f, |b| {
            let (records, _) = section(b, RECORDS);
            put_u32(b, records + 16 * 2 + 12, pack_word(0, 1));
        });
        assert_contains(&message, &["face record 2, edge 2: log2 R_e = 1 must be in 2..=12"]);

        // vertex_levels too small for the R = 4 face.
        let message = hostile(f, |b| put_u32(b, VERTEX_LEVELS_AT, 2));
        assert_contains(&message, &["face record 2: log2 R = 2 needs vertex_levels >= 3 but it is 2"]);
    }
    // Vertex section larger than the colour buffer, with consistent lengths.
    let mut small =
        PackedMesh { positions: vec![[0.0; 3]; 3], vertex_levels: 1, colors: vec![7; 12], ..PackedMesh::default() };
    let mut bytes = to_bytes(&small).unwrap();
    put_u32(&mut bytes, VERTEX_LEVELS_AT, 2);
    reseal(&mut bytes);
    let message = from_bytes(&bytes).unwrap_err().to_string();
    assert_eq!(message, "3 vertices × 2 levels need 6 samples but there are 3");
    small.vertex_levels = 2;
    assert!(to_bytes(&small).is_err());
}

#[test]
fn writer_refuses_meshes_the_reader_would_refuse() {
    let good = tetrahedron(ColorFormat::Rgba8Srgb);
    let refuse = |change: &dyn Fn(&mut PackedMesh), needle: &str| {
        let mut mesh = good.clone();
        change(&mut mesh);
        let message = to_bytes(&mesh).unwrap_err().to_string();
        assert_contains(&message, &[needle]);
    };
    refuse(&|m| m.positions[3][1] = f32::INFINITY, "vertex 3 is not finite");
    refuse(&|m| m.indices[0][2] = 4, "index 2 of triangle 0 is 4");
    refuse(&|m| m.indices[2] = [1, 1, 2], "triangle 2 repeats a corner");
    refuse(
        &|m| {
            m.face_records.pop();
        },
        "4 triangles",
    );
    refuse(&|m| m.colors.push(0), "not a whole number of 4-byte samples");
    refuse(&|m| m.vertex_levels = 3, "needs vertex_levels >= 4");
    refuse(&|m| m.vertex_levels = 14, "vertex_levels is 14");
    refuse(&|m| m.face_records[0].interior = pack_word(0, 13), "log2 R = 13");
    refuse(
        &|m| {
            let len = m.colors.len();
            m.colors.truncate(len - 4);
        },
        "runs past",
    );
    // The writer's refusal and the reader's refusal agree: nothing refused is writable.
    assert!(from_bytes(&to_bytes(&good).unwrap()).is_ok());
}

/// The header summary (what the recovery prompt shows) states what the file holds — the
/// mesh's own counts and the file's length on disk — from the 128-byte header; it refuses what is
/// not a packed file of this version, a truncated header, and a missing file, naming it.
#[test]
fn the_header_summary_states_what_the_file_holds() {
    let dir = unique_temp_dir("summary");
    let path = dir.join("tetra.mpk");
    for format in ColorFormat::ALL {
        let mesh = tetrahedron(format);
        write_file(&path, &mesh).unwrap();
        let summary = read_summary(&path).unwrap();
        assert_eq!(summary.face_count as usize, mesh.face_records.len());
        assert_eq!(summary.vertex_count as usize, mesh.positions.len());
        assert_eq!(summary.sample_count, mesh.sample_count());
        assert_eq!(summary.file_size, std::fs::metadata(&path).unwrap().len());
    }
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..100]).unwrap();
    assert!(matches!(read_summary(&path), Err(PackedFileError::Truncated { .. })));
    std::fs::write(&path, b"glTF....").unwrap();
    assert!(matches!(read_summary(&path), Err(PackedFileError::NotPacked { .. })));
    let mut other_version = bytes.clone();
    put_u32(&mut other_version, 8, VERSION + 1);
    std::fs::write(&path, &other_version).unwrap();
    assert!(matches!(read_summary(&path), Err(PackedFileError::UnsupportedVersion(v)) if v == VERSION + 1));
    let missing = dir.join("missing.mpk");
    let message = read_summary(&missing).unwrap_err().to_string();
    assert!(message.contains("missing.mpk"), "{message}");
    let _ = std::fs::remove_dir_all(&dir);
}
