//! Tests of the MCT file (crates/core/src/mct/file/, docs/MCT_FORMAT.md).
//!
//! Header offsets and the worked example's sizes are hard-coded here from
//! docs/MCT_FORMAT.md, so these tests check the documented layout, not just that the writer
//! and the reader agree. Refusals are crafted byte by byte (the CRC-32 recomputed here with
//! `crc32fast`, so each check past the checksum is reached); read-back files are compared
//! with the built texture and with the CPU sampler on it.

use crate::common;
use crate::common::WriteThrough;

use common::{Rng, TempDir};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mct::file::{
    MAGIC, MAX_ATLAS_SIDE, MctFile, MctFileError, VERSION, from_bytes, looks_like_mct, read_mct, to_bytes, write_mct,
};
use meshpaint_core::mct::layout::{GROUPS, MctFaceRecord};
use meshpaint_core::mct::{self, MctStats, MeshColorTexture};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::synth::shapes::icosphere;

// Header field offsets (docs/MCT_FORMAT.md).
const VERSION_AT: usize = 8;
const HEADER_SIZE_AT: usize = 12;
const FILE_SIZE_AT: usize = 16;
const FLAGS_AT: usize = 24;
const FORMAT_AT: usize = 28;
const VERTEX_COUNT_AT: usize = 32;
const FACE_COUNT_AT: usize = 36;
const WIDTH_AT: usize = 40;
const HEIGHT_AT: usize = 44;
const LEVELS_AT: usize = 48;
const RESERVED_52_AT: usize = 52;
const SECTIONS_AT: usize = 56;
const RESERVED_136_AT: usize = 136;
const CHECKSUM_AT: usize = 140;
const HEADER_SIZE: usize = 144;
const POSITIONS: usize = 0;
const INDICES: usize = 1;
const RECORDS: usize = 2;
const BANDS: usize = 3;
const TEXELS: usize = 4;
const BANDS_BYTES: u64 = 169 * 16;

const MAX_DIM: u32 = 16384;

fn packed_icosphere(levels: u32, resolution: impl Fn(usize) -> u64, format: ColorFormat, seed: u64) -> PackedMesh {
    let (positions, triangles) = icosphere(levels);
    packed(positions, &triangles, resolution, format, seed)
}

fn packed(
    positions: Vec<[f32; 3]>,
    triangles: &[[u32; 3]],
    resolution: impl Fn(usize) -> u64,
    format: ColorFormat,
    seed: u64,
) -> PackedMesh {
    let topology = Topology::build(positions.len() as u32, triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(resolution(f)).unwrap()).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
    pack(&store, &positions, format).unwrap()
}

fn mixed(face: usize) -> u64 {
    1 << ((face * 7 + face / 5) % 6)
}

/// The mixed-R icosphere (320 faces, R = 1…16; block resolutions 4, 8 and 16, with pairs and
/// lone faces in each; 5 levels; a 168×418 atlas), its MCT and its file bytes.
fn mixed_file(format: ColorFormat) -> (PackedMesh, MeshColorTexture, Vec<u8>) {
    let packed = packed_icosphere(2, mixed, format, 11);
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let bytes = to_bytes(&packed.positions, &packed.indices, &mct).unwrap();
    (packed, mct, bytes)
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

fn set_u32(bytes: &mut [u8], at: usize, value: u32) {
    bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

fn set_u64(bytes: &mut [u8], at: usize, value: u64) {
    bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
}

/// `(offset, length)` of section `k` from the header's table.
fn section(bytes: &[u8], k: usize) -> (usize, usize) {
    (u64_at(bytes, SECTIONS_AT + 16 * k) as usize, u64_at(bytes, SECTIONS_AT + 16 * k + 8) as usize)
}

/// The CRC-32 of the file as documented: bytes 0..140, then 144..end.
fn crc_of(bytes: &[u8]) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..CHECKSUM_AT]);
    hasher.update(&bytes[CHECKSUM_AT + 4..]);
    hasher.finalize()
}

fn fix_crc(bytes: &mut [u8]) {
    let crc = crc_of(bytes);
    set_u32(bytes, CHECKSUM_AT, crc);
}

/// `bytes` edited by `edit`, with the checksum recomputed.
fn craft(bytes: &[u8], edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut out = bytes.to_vec();
    edit(&mut out);
    fix_crc(&mut out);
    out
}

fn refused(bytes: &[u8]) -> MctFileError {
    match from_bytes(bytes) {
        Ok(_) => panic!("a crafted file was accepted"),
        Err(error) => error,
    }
}

/// The face record at `face` (from the records section).
fn record_at(bytes: &[u8], face: usize) -> MctFaceRecord {
    MctFaceRecord(u32_at(bytes, section(bytes, RECORDS).0 + 4 * face))
}

fn set_record(bytes: &mut [u8], face: usize, record: u32) {
    let at = section(bytes, RECORDS).0 + 4 * face;
    set_u32(bytes, at, record);
}

/// Byte offset of word `word` of the band entry of group `g` at `level`.
fn band_word_at(bytes: &[u8], g: usize, level: usize, word: usize) -> usize {
    section(bytes, BANDS).0 + 16 * (g * GROUPS + level) + 4 * word
}

// ---------------------------------------------------------------------------------------
// Round trip, layout, determinism

#[test]
fn a_written_file_reads_back_as_the_built_texture_and_samples_the_same_everywhere() {
    for format in ColorFormat::ALL {
        let (packed, mct, bytes) = mixed_file(format);
        assert!(looks_like_mct(&bytes));
        let file = from_bytes(&bytes).unwrap();
        assert_eq!(file.positions, packed.positions);
        assert_eq!(file.indices, packed.indices);
        // Everything but the builder's counts, which the file does not store.
        assert_eq!(file.mct, MeshColorTexture { stats: MctStats::default(), ..mct.clone() });
        assert_eq!(file.mct.layout.pairs, mct.layout.pairs);
        // The CPU sampler on the read texture: every face, level and a grid of points.
        let mut checked = 0u64;
        for face in 0..packed.indices.len() as u32 {
            for level in 0..mct.layout.levels + 1 {
                for i in 0..=8u32 {
                    for j in 0..=8 - i {
                        let w = [(8 - i - j) as f32 / 8.0, i as f32 / 8.0, j as f32 / 8.0];
                        let (a, b) = (file.mct.sample_level(face, w, level), mct.sample_level(face, w, level));
                        assert_eq!(a.map(|c| c.map(f32::to_bits)), b.map(|c| c.map(f32::to_bits)));
                        checked += 1;
                    }
                }
                let lod = level as f32 + 0.3;
                let w = [0.2, 0.3, 0.5];
                assert_eq!(file.mct.sample_trilinear(face, w, lod), mct.sample_trilinear(face, w, lod));
            }
        }
        assert_eq!(checked, 320 * 6 * 45);
        // Writing the read file gives the same bytes.
        assert_eq!(to_bytes(&file.positions, &file.indices, &file.mct).unwrap(), bytes);
    }
}

#[test]
fn writing_is_deterministic_and_goes_through_the_atomic_write() {
    let (packed, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    // A second build of the same mesh, written again: the same bytes.
    let again = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    assert_eq!(to_bytes(&packed.positions, &packed.indices, &again).unwrap(), bytes);
    let dir = TempDir::new("mct-file");
    let path = dir.join("sphere.mct");
    write_mct(&path, &packed.positions, &packed.indices, &mct).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    let file: MctFile = read_mct(&path).unwrap();
    assert_eq!(file.mct.texels, mct.texels);
    // Only the file itself is left in the directory (no temporary file).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // Errors name the path.
    let missing = dir.join("missing.mct");
    let error = read_mct(&missing).unwrap_err().to_string();
    assert!(error.starts_with(&missing.display().to_string()) && error.contains("cannot read the file"), "{error}");
    let bad = dir.join("bad.mct");
    std::fs::write(&bad, &bytes[..bytes.len() - 1]).unwrap();
    let error = read_mct(&bad).unwrap_err().to_string();
    assert!(error.starts_with(&bad.display().to_string()) && error.contains("truncated"), "{error}");
}

#[test]
fn header_fields_and_sections_are_where_the_format_document_says() {
    let (packed, mct, bytes) = mixed_file(ColorFormat::Rgba16F);
    assert_eq!(&bytes[..8], b"MESHMCT\0");
    assert_eq!(MAGIC, *b"MESHMCT\0");
    assert_eq!(u32_at(&bytes, VERSION_AT), 3);
    assert_eq!(VERSION, 3);
    assert_eq!(u32_at(&bytes, HEADER_SIZE_AT), HEADER_SIZE as u32);
    assert_eq!(u64_at(&bytes, FILE_SIZE_AT), bytes.len() as u64);
    assert_eq!(u32_at(&bytes, FLAGS_AT), 0);
    assert_eq!(u32_at(&bytes, FORMAT_AT), 1);
    assert_eq!(u32_at(&bytes, VERTEX_COUNT_AT) as usize, packed.positions.len());
    assert_eq!(u32_at(&bytes, FACE_COUNT_AT) as usize, packed.indices.len());
    assert_eq!(u32_at(&bytes, WIDTH_AT), mct.layout.width);
    assert_eq!(u32_at(&bytes, HEIGHT_AT), mct.layout.height);
    assert_eq!(u32_at(&bytes, LEVELS_AT), mct.layout.levels);
    assert_eq!(mct.layout.levels, 5, "R up to 16");
    assert_eq!(u32_at(&bytes, RESERVED_52_AT), 0);
    assert_eq!(u32_at(&bytes, RESERVED_136_AT), 0);
    assert_eq!(u32_at(&bytes, CHECKSUM_AT), crc_of(&bytes));
    assert!(bytes[HEADER_SIZE..256].iter().all(|&b| b == 0));
    // Sections: aligned, in order, each at the first multiple of 256 after the previous.
    let (v, f) = (packed.positions.len(), packed.indices.len());
    let texel_bytes = (mct.layout.width * mct.layout.height) as usize * 8;
    let lengths = [16 * v, 12 * f, 4 * (f + mct.layout.masks.len()), BANDS_BYTES as usize, texel_bytes];
    let mut cursor = HEADER_SIZE;
    for (k, length) in lengths.into_iter().enumerate() {
        let (offset, len) = section(&bytes, k);
        assert_eq!((offset, len), (cursor.div_ceil(256) * 256, length), "section {k}");
        assert!(bytes[cursor..offset].iter().all(|&b| b == 0), "gap before section {k}");
        cursor = offset + len;
    }
    assert_eq!(cursor, bytes.len());
    // Section contents, decoded here by hand.
    let (at, _) = section(&bytes, POSITIONS);
    assert_eq!(f32::from_le_bytes(bytes[at + 20..at + 24].try_into().unwrap()), packed.positions[1][1]);
    // Each vertex's fourth word is its level-of-detail density, as the GPU mesh computes it.
    let density = meshpaint_core::packing::lod::VertexLod::of(&packed).density;
    assert_eq!(f32::from_le_bytes(bytes[at + 28..at + 32].try_into().unwrap()), density[1]);
    assert_eq!(mct.vertex_density, density);
    let (at, _) = section(&bytes, INDICES);
    assert_eq!(u32_at(&bytes, at + 12 * 7 + 8), packed.indices[7][2]);
    for face in [0, 100, 319] {
        assert_eq!(record_at(&bytes, face), mct.layout.records[face]);
    }
    // The strip-row masks follow the records.
    assert!(!mct.layout.masks.is_empty());
    for (k, &mask) in mct.layout.masks.iter().enumerate() {
        assert_eq!(record_at(&bytes, f + k).0, mask);
    }
    for (g, level) in [(0, 0), (5, 0), (3, 2), (5, 5)] {
        let (y, per_row) = mct.layout.bands.band(g as u32, level as u32);
        assert_eq!(u32_at(&bytes, band_word_at(&bytes, g, level, 0)), y);
        assert_eq!(u32_at(&bytes, band_word_at(&bytes, g, level, 1)), per_row);
    }
    let (at, len) = section(&bytes, TEXELS);
    assert_eq!(&bytes[at..at + len], &mct.texels[..]);
}

/// The two-triangle example of docs/MCT_FORMAT.md ("Worked example").
#[test]
fn the_worked_example_has_the_documented_size_and_offsets() {
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let packed = packed(positions, &[[0, 1, 2], [0, 2, 3]], |_| 2, ColorFormat::Rgba8Srgb, 3);
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let bytes = to_bytes(&packed.positions, &packed.indices, &mct).unwrap();
    assert_eq!((mct.layout.width, mct.layout.height, mct.layout.levels), (10, 5, 2));
    let sections: Vec<(usize, usize)> = (0..5).map(|k| section(&bytes, k)).collect();
    assert_eq!(sections, [(256, 64), (512, 24), (768, 12), (1024, 2704), (3840, 200)]);
    assert_eq!(bytes.len(), 4040);
    // Both faces in pair 0 of group 1 (R_b = 2), sharing the edge 0 → 2; the square has p at
    // vertex 2, but these random colours clamp fewer rings with the tents' right angle at
    // vertex 0 (swap).
    assert_eq!(mct.layout.pairs[1], [[0, 1]]);
    let [a, b] = [mct.layout.records[0], mct.layout.records[1]];
    assert_eq!((a.0, b.0), (0x210, 0x21c), "{a:?} {b:?}");
    assert!(a.swap() && b.swap() && !a.flip());
    let (c0, c1) = (packed.indices[0], packed.indices[1]);
    assert_eq!(([c0[a.corner_p()], c0[a.corner_q()]]), [c1[b.corner_p()], c1[b.corner_q()]]);
    assert_eq!([c0[a.corner_p()], c0[a.corner_q()]], [0, 2]);
    // Band table: group 1 level 0 at y = 0, one tent period per row (the atlas is one period
    // wide: the down tent crosses the right edge); level 1 at y = 3, one strip row per row;
    // strip rows of 8 pairs, at most 1 piece, masks from 0; one mask (no piece starts).
    assert_eq!(mct.layout.bands.band(1, 0), (0, 1));
    assert_eq!(mct.layout.bands.band(1, 1), (3, 1));
    assert_eq!(mct.layout.bands.strip_rows(1), (0, 3, 1));
    assert_eq!(u32_at(&bytes, 1024 + 16 * GROUPS + 12), 3 | (1 << 3));
    assert_eq!(mct.layout.masks, [0]);
    assert_eq!(u32_at(&bytes, 768 + 8), 0);
    assert_eq!(u32_at(&bytes, 1024 + 16 * GROUPS + 4), 1);
    assert_eq!(u32_at(&bytes, 1024 + 16 * (GROUPS + 1)), 3);
    // The documented frames.
    let frames: Vec<_> = (0..2u32)
        .flat_map(|face| (0..2).map(move |level| (face, level)))
        .map(|(face, level)| {
            let f = mct.layout.frame(face, level).unwrap();
            (f.origin, f.ex, f.ey, f.corners, f.r)
        })
        .collect();
    assert_eq!(
        frames,
        [
            ([3, 0], [1, 0], [0, 1], [0, 1, 2], 2),
            ([0, 3], [1, 0], [0, 1], [1, 2, 0], 1),
            ([3, 0], [-1, 0], [0, 1], [0, 2, 1], 2),
            ([1, 4], [0, -1], [-1, 0], [2, 1, 0], 1),
        ],
        "{frames:?}"
    );
}

/// The atlas check covers the texels a block uses, not its frame's `(r + 1, 0)` and
/// `(0, r + 1)`, and lets x wrap around once (tents cross the right edge and continue at the
/// left): valid layouts have both, which must be accepted.
#[test]
fn blocks_at_the_atlas_edge_are_accepted() {
    let (_, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    assert!(from_bytes(&bytes).is_ok());
    let (w, h) = (i64::from(mct.layout.width), i64::from(mct.layout.height));
    let outside = |t: [i64; 2]| !(0..2 * w).contains(&t[0]) || !(0..h).contains(&t[1]);
    let (mut frame_corner_outside, mut wrapping) = (0, 0);
    for face in 0..mct.layout.records.len() as u32 {
        for level in 0..mct.layout.levels {
            let frame = mct.layout.frame(face, level).unwrap();
            let r = frame.r;
            for (alpha, beta) in [(0, 0), (r, 0), (0, r), (r, 1), (1, r)] {
                assert!(!outside(frame.texel(alpha, beta)), "face {face} level {level} ({alpha}, {beta})");
                wrapping += u32::from(frame.texel(alpha, beta)[0] >= w);
            }
            if outside(frame.texel(r + 1, 0)) || outside(frame.texel(0, r + 1)) {
                frame_corner_outside += 1;
            }
        }
    }
    assert!(frame_corner_outside > 0, "no block at the atlas edge: the test mesh does not exercise the case");
    assert!(wrapping > 0, "no tent crosses the right edge: the test mesh does not exercise the case");
}

// ---------------------------------------------------------------------------------------
// Refusals: header, sections, checksum

#[test]
fn refuses_a_bad_magic_version_header_size_flags_and_reserved_fields() {
    let (_, _, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let error = refused(&craft(&bytes, |b| b[3] = b'X'));
    assert!(matches!(error, MctFileError::NotMct { .. }), "{error:?}");
    assert!(error.to_string().contains("not a meshpaint MCT file"), "{error}");
    // A packed file is not an MCT file.
    let error = refused(b"MESHPAK\0 and more bytes");
    assert!(matches!(error, MctFileError::NotMct { .. }), "{error:?}");
    // A prefix of the magic, or a header cut short: truncated.
    for len in [3, 8, 100, HEADER_SIZE - 1] {
        let error = refused(&bytes[..len]);
        assert!(matches!(error, MctFileError::Truncated { end: 144, .. }), "{len}: {error:?}");
        assert!(error.to_string().contains("truncated"), "{error}");
    }
    let error = refused(&craft(&bytes, |b| set_u32(b, VERSION_AT, 4)));
    assert!(matches!(error, MctFileError::UnsupportedVersion(4)), "{error:?}");
    assert!(error.to_string().contains("version 4"), "{error}");
    // Versions 1 (squares without strips) and 2 (no density per vertex) are refused with what
    // to do.
    for old in [1, 2] {
        let error = refused(&craft(&bytes, |b| set_u32(b, VERSION_AT, old)));
        assert!(matches!(error, MctFileError::OldVersion(v) if v == old), "{error:?}");
        assert!(error.to_string().contains("export it again"), "{error}");
    }
    let error = refused(&craft(&bytes, |b| set_u32(b, HEADER_SIZE_AT, 128)));
    assert!(matches!(error, MctFileError::HeaderSize(128)), "{error:?}");
    let error = refused(&craft(&bytes, |b| set_u32(b, FLAGS_AT, 4)));
    assert!(matches!(error, MctFileError::UnknownFlags(4)), "{error:?}");
    assert!(error.to_string().contains("flag"), "{error}");
    for at in [RESERVED_52_AT, RESERVED_136_AT] {
        let error = refused(&craft(&bytes, |b| set_u32(b, at, 9)));
        assert!(matches!(error, MctFileError::ReservedNotZero { offset, value: 9 } if offset == at), "{error:?}");
        assert!(error.to_string().contains(&format!("byte {at}")), "{error}");
    }
    let error = refused(&craft(&bytes, |b| b[200] = 1));
    assert!(matches!(error, MctFileError::NonZeroPadding { offset: 200, value: 1 }), "{error:?}");
    let (bands_at, bands_len) = section(&bytes, BANDS);
    let after_bands = bands_at + bands_len + 5;
    assert!(after_bands < section(&bytes, TEXELS).0);
    let error = refused(&craft(&bytes, |b| b[after_bands] = 0x80));
    assert!(matches!(error, MctFileError::NonZeroPadding { value: 0x80, .. }), "{error:?}");
    assert!(error.to_string().contains(&format!("offset {after_bands}")), "{error}");
    let error = refused(&craft(&bytes, |b| set_u32(b, FORMAT_AT, 3)));
    assert!(matches!(error, MctFileError::UnknownColorFormat(3)), "{error:?}");
    assert!(error.to_string().contains("colour format code 3"), "{error}");
}

#[test]
fn refuses_a_bad_section_table_truncation_trailing_bytes_and_a_bad_checksum() {
    let (_, _, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let (texels_at, _) = section(&bytes, TEXELS);
    let error = refused(&craft(&bytes, |b| set_u64(b, SECTIONS_AT + 16 * TEXELS, texels_at as u64 + 4)));
    assert!(matches!(error, MctFileError::SectionMisaligned { section: "texels", .. }), "{error:?}");
    let error = refused(&craft(&bytes, |b| set_u64(b, SECTIONS_AT + 16 * INDICES, 0)));
    assert!(
        matches!(error, MctFileError::SectionOverlap { section: "indices", previous: "positions", .. }),
        "{error:?}"
    );
    let error = refused(&craft(&bytes, |b| set_u64(b, SECTIONS_AT + 16 * BANDS + 8, u64::MAX - 100)));
    assert!(matches!(error, MctFileError::SectionOverflow { section: "band table", .. }), "{error:?}");
    // Truncated: the texels end past the end of the file.
    let short = craft(&bytes[..bytes.len() - 1], |_| {});
    let error = refused(&short);
    assert!(matches!(error, MctFileError::Truncated { .. }), "{error:?}");
    assert!(error.to_string().contains("texels end"), "{error}");
    // Trailing bytes: after the header's file size, and after the last section.
    let error = refused(&craft(&bytes, |b| b.push(0)));
    assert!(matches!(error, MctFileError::TrailingBytes { what: "file", extra: 1, .. }), "{error:?}");
    let error = refused(&craft(&bytes, |b| {
        b.extend([0; 3]);
        let len = b.len() as u64;
        set_u64(b, FILE_SIZE_AT, len);
    }));
    assert!(matches!(error, MctFileError::TrailingBytes { what: "last section", extra: 3, .. }), "{error:?}");
    assert!(error.to_string().contains("3 unexpected bytes"), "{error}");
    // One texel byte changed, the checksum left alone.
    let mut corrupt = bytes.clone();
    corrupt[texels_at + 10] ^= 1;
    let error = refused(&corrupt);
    assert!(matches!(error, MctFileError::ChecksumMismatch { .. }), "{error:?}");
    assert!(error.to_string().contains("checksum mismatch"), "{error}");
}

#[test]
fn refuses_sizes_that_do_not_match_the_counts_before_allocating() {
    let (packed, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let v = packed.positions.len() as u32;
    // Counts that disagree with their sections, including absurd ones in a small file.
    for (at, value, section_name) in [
        (VERTEX_COUNT_AT, v + 1, "positions"),
        (VERTEX_COUNT_AT, u32::MAX, "positions"),
        (FACE_COUNT_AT, u32::MAX, "indices"),
        (WIDTH_AT, mct.layout.width + 1, "texels"),
        (HEIGHT_AT, MAX_ATLAS_SIDE, "texels"),
    ] {
        let error = refused(&craft(&bytes, |b| set_u32(b, at, value)));
        assert!(matches!(error, MctFileError::SectionLength { section, .. } if section == section_name), "{error:?}");
        assert!(error.to_string().contains(&format!("{section_name} section is")), "{error}");
    }
    // The records section's length shortened by one word (its last bytes zeroed, so they
    // read as the gap's padding): one strip-row mask fewer than the records need.
    let error = refused(&craft(&bytes, |b| {
        let k = SECTIONS_AT + 16 * RECORDS + 8;
        let len = u64_at(b, k);
        set_u64(b, k, len - 4);
        let (at, _) = section(b, RECORDS);
        b[at + len as usize - 4..at + len as usize].fill(0);
    }));
    let masks = mct.layout.masks.len() as u64;
    assert!(
        matches!(error, MctFileError::MaskCount { stored, expected } if stored == masks - 1 && expected == masks),
        "{error:?}"
    );
    assert!(error.to_string().contains("strip-row masks"), "{error}");
    let error = refused(&craft(&bytes, |b| {
        let k = SECTIONS_AT + 16 * BANDS + 8;
        set_u64(b, k, BANDS_BYTES - 16);
        let (at, _) = section(b, BANDS);
        b[at + BANDS_BYTES as usize - 16..at + BANDS_BYTES as usize].fill(0);
    }));
    assert!(matches!(error, MctFileError::SectionLength { section: "band table", .. }), "{error:?}");
    // Atlas sides and levels out of range.
    for (width, height) in [(0, 5), (5, 0), (MAX_ATLAS_SIDE + 1, 1)] {
        let error = refused(&craft(&bytes, |b| {
            set_u32(b, WIDTH_AT, width);
            set_u32(b, HEIGHT_AT, height);
        }));
        assert!(matches!(error, MctFileError::AtlasSize { .. }), "{error:?}");
        assert!(error.to_string().contains(&format!("{width}×{height}")), "{error}");
    }
    for levels in [0, 14, u32::MAX] {
        let error = refused(&craft(&bytes, |b| set_u32(b, LEVELS_AT, levels)));
        assert!(matches!(error, MctFileError::Levels(l) if l == levels), "{error:?}");
        assert!(error.to_string().contains(&format!("levels is {levels}")), "{error}");
    }
}

// ---------------------------------------------------------------------------------------
// Refusals: content

#[test]
fn refuses_non_finite_positions_and_indices_out_of_range() {
    let (packed, _, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    for value in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let error = refused(&craft(&bytes, |b| {
            let (at, _) = section(b, POSITIONS);
            b[at + 16 * 5 + 4..at + 16 * 5 + 8].copy_from_slice(&value.to_le_bytes());
        }));
        assert!(matches!(error, MctFileError::NonFinitePosition { vertex: 5, .. }), "{error:?}");
        assert!(error.to_string().contains("vertex 5 is not finite"), "{error}");
    }
    for value in [f32::NAN, f32::INFINITY, -1.0] {
        let error = refused(&craft(&bytes, |b| {
            let (at, _) = section(b, POSITIONS);
            b[at + 16 * 6 + 12..at + 16 * 6 + 16].copy_from_slice(&value.to_le_bytes());
        }));
        assert!(matches!(error, MctFileError::BadDensity { vertex: 6, .. }), "{error:?}");
        assert!(error.to_string().contains("level-of-detail density"), "{error}");
    }
    let v = packed.positions.len() as u32;
    for index in [v, u32::MAX] {
        let error = refused(&craft(&bytes, |b| {
            let (at, _) = section(b, INDICES);
            set_u32(b, at + 12 * 9 + 4, index);
        }));
        assert!(
            matches!(error, MctFileError::IndexOutOfRange { triangle: 9, corner: 1, index: i, .. } if i == index),
            "{error:?}"
        );
        assert!(error.to_string().contains(&format!("is {index} but there are {v} vertices")), "{error}");
    }
}

#[test]
fn refuses_records_with_a_bad_corner_resolution_level_or_pair() {
    let (_, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let face = 17;
    let record = mct.layout.records[face].0;
    let error = refused(&craft(&bytes, |b| set_record(b, face, record | 3)));
    assert!(matches!(error, MctFileError::RecordCorner { face: 17, corner: 3, .. }), "{error:?}");
    assert!(error.to_string().contains("names corner 3 as p"), "{error}");
    for log2 in [13u32, 15] {
        let error = refused(&craft(&bytes, |b| set_record(b, face, (record & !0xf0) | (log2 << 4))));
        assert!(matches!(error, MctFileError::RecordResolution { face: 17, log2: l, .. } if l == log2), "{error:?}");
        assert!(error.to_string().contains(&format!("log2 R_b = {log2}")), "{error}");
    }
    // Block resolution 16 (log2 4) with only 4 levels.
    let error = refused(&craft(&bytes, |b| set_u32(b, LEVELS_AT, 4)));
    assert!(matches!(error, MctFileError::RecordLevels { resolution: 16, needed: 5, levels: 4, .. }), "{error:?}");
    // A pair index past the faces of its group.
    let g = mct.layout.records[face].log2_block() as usize;
    let faces_in_group = mct.layout.records.iter().filter(|r| r.log2_block() as usize == g).count() as u32;
    let error = refused(&craft(&bytes, |b| set_record(b, face, (record & 0x3ff) | (faces_in_group << 10))));
    assert!(
        matches!(error, MctFileError::PairIndex { face: 17, pair, faces, .. } if pair == faces_in_group && faces == u64::from(faces_in_group)),
        "{error:?}"
    );
    let error = refused(&craft(&bytes, |b| set_record(b, face, (record & 0x3ff) | (0x3f_ffff << 10))));
    assert!(matches!(error, MctFileError::PairIndex { pair: 0x3f_ffff, .. }), "{error:?}");
    assert!(error.to_string().contains("pairs are numbered from 0"), "{error}");
}

#[test]
fn refuses_a_band_table_with_reserved_words_or_an_empty_band_that_faces_use() {
    let (_, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let error = refused(&craft(&bytes, |b| {
        let at = band_word_at(b, 12, 12, 3);
        set_u32(b, at, 1);
    }));
    assert!(
        matches!(error, MctFileError::BandReserved { resolution: 4096, level: 12, word: 3, value: 1 }),
        "{error:?}"
    );
    // Per row = 0 in a band faces read, at level 0 (tent periods) and above (squares).
    for (g, level) in [(3, 0), (2, 4), (4, 2)] {
        assert!(mct.layout.pairs[g].len() > 1);
        let error = refused(&craft(&bytes, |b| {
            let at = band_word_at(b, g, level, 1);
            set_u32(b, at, 0);
        }));
        assert!(
            matches!(error, MctFileError::EmptyBand { resolution, level: l, .. } if resolution == 1 << g && l == level as u32),
            "{error:?}"
        );
        assert!(error.to_string().contains("0 blocks per row"), "{error}");
    }
    // An unused band (no face at R_b = 64) may hold anything in words 0 and 1.
    assert!(mct.layout.pairs[6].is_empty());
    let unused = craft(&bytes, |b| {
        let at = band_word_at(b, 6, 0, 1);
        set_u32(b, at, 0);
        let at = band_word_at(b, 6, 0, 0);
        set_u32(b, at, 77);
    });
    assert!(from_bytes(&unused).is_ok());
}

/// A pair `[first, second]` and a lone face of the test mesh.
fn pair_and_lone(mct: &MeshColorTexture) -> ([u32; 2], u32) {
    let pair = mct.layout.pairs.iter().flatten().copied().find(|p| p[1] != u32::MAX).unwrap();
    let lone = mct.layout.pairs.iter().flatten().find(|p| p[1] == u32::MAX).unwrap()[0];
    (pair, lone)
}

#[test]
fn refuses_two_faces_on_one_slot_a_pair_without_a_first_face_and_pairs_not_sharing_their_edge() {
    let (_, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let ([first, second], lone) = pair_and_lone(&mct);
    // The second face claims the first's side.
    let error = refused(&craft(&bytes, |b| {
        let record = record_at(b, second as usize).0 & !8;
        set_record(b, second as usize, record);
    }));
    assert!(
        matches!(error, MctFileError::DuplicateSlot { face, other, side: 0, .. }
            if (face, other) == (u64::from(first.max(second)), u64::from(first.min(second)))),
        "{error:?}"
    );
    assert!(error.to_string().contains("both claim side 0"), "{error}");
    // A lone face turned second: its pair has no first face.
    let error = refused(&craft(&bytes, |b| {
        let record = record_at(b, lone as usize).0 | 8;
        set_record(b, lone as usize, record);
    }));
    let lone_record = mct.layout.records[lone as usize];
    assert!(
        matches!(error, MctFileError::MissingFirst { resolution, pair }
            if resolution == 1 << lone_record.log2_block() && pair == u64::from(lone_record.pair())),
        "{error:?}"
    );
    assert!(error.to_string().contains("has no first face"), "{error}");
    // The second face's record names another corner as p.
    let error = refused(&craft(&bytes, |b| {
        let record = record_at(b, second as usize).0;
        let corner = ((record & 3) + 1) % 3;
        set_record(b, second as usize, (record & !3) | corner);
    }));
    assert!(
        matches!(error, MctFileError::PairEdge { first: f, second: s, .. } if (f, s) == (u64::from(first), u64::from(second))),
        "{error:?}"
    );
    assert!(error.to_string().contains("do not share their edge"), "{error}");
}

#[test]
fn refuses_any_block_outside_the_atlas() {
    let (_, mct, bytes) = mixed_file(ColorFormat::Rgba8Srgb);
    let height = mct.layout.height;
    // A band moved down past the atlas, at level 0 and at the last level.
    for (g, level) in [(4usize, 0usize), (2, 4)] {
        let error = refused(&craft(&bytes, |b| {
            let at = band_word_at(b, g, level, 0);
            let y = u32_at(b, at);
            set_u32(b, at, y + height);
        }));
        assert!(matches!(error, MctFileError::OutsideAtlas { level: l, .. } if l == level as u32), "{error:?}");
        assert!(error.to_string().contains("outside the"), "{error}");
    }
    // More blocks per row than the width holds: the last ones run off the right edge.
    let error = refused(&craft(&bytes, |b| {
        let at = band_word_at(b, 4, 1, 1);
        set_u32(b, at, 100_000);
    }));
    assert!(
        matches!(error, MctFileError::OutsideAtlas { level: 1, texel, width, .. } if texel[0] >= i64::from(width)),
        "{error:?}"
    );
    // The band placed last ends exactly at the atlas's last row; one row lower, its blocks'
    // far row is the first row past the atlas.
    let last = mct.layout.levels as usize - 1;
    let g = (0..GROUPS)
        .filter(|&g| !mct.layout.pairs[g].is_empty())
        .max_by_key(|&g| mct.layout.bands.band(g as u32, last as u32).0)
        .unwrap();
    let shifted = craft(&bytes, |b| {
        let at = band_word_at(b, g, last, 0);
        let y = u32_at(b, at);
        set_u32(b, at, y + 1);
    });
    let error = refused(&shifted);
    assert!(
        matches!(error, MctFileError::OutsideAtlas { level, texel, height: h, .. } if texel[1] == i64::from(h) && h == height && level == last as u32),
        "{error:?}"
    );
}

// ---------------------------------------------------------------------------------------
// The writer

#[test]
fn the_writer_refuses_what_the_reader_would() {
    let (packed, mct, _) = mixed_file(ColorFormat::Rgba8Srgb);
    let (p, i) = (&packed.positions, &packed.indices);
    let error = to_bytes(p, &i[..10], &mct).unwrap_err();
    assert!(matches!(error, MctFileError::FaceCountMismatch { indices: 10, records: 320 }), "{error:?}");
    let mut short = mct.clone();
    short.texels.pop();
    let error = to_bytes(p, i, &short).unwrap_err();
    assert!(matches!(error, MctFileError::TexelBytes { .. }), "{error:?}");
    assert!(error.to_string().contains("texels of rgba8 need"), "{error}");
    let mut wide = mct.clone();
    wide.layout.width = MAX_ATLAS_SIDE + 1;
    assert!(matches!(to_bytes(p, i, &wide).unwrap_err(), MctFileError::AtlasSize { .. }));
    let mut swapped = mct.clone();
    let list = swapped.layout.pairs.iter_mut().find(|l| l.len() > 1).unwrap();
    list.swap(0, 1);
    let error = to_bytes(p, i, &swapped).unwrap_err();
    assert!(matches!(error, MctFileError::PairsMismatch { pair: 0, .. }), "{error:?}");
    assert!(error.to_string().contains("pair lists disagree"), "{error}");
    let mut positions = p.clone();
    positions[3][0] = f32::NAN;
    assert!(matches!(to_bytes(&positions, i, &mct).unwrap_err(), MctFileError::NonFinitePosition { vertex: 3, .. }));
    // Errors of write_mct name the path, and nothing is written.
    let dir = TempDir::new("mct-writer");
    let path = dir.join("x.mct");
    let error = write_mct(&path, &positions, i, &mct).unwrap_err().to_string();
    assert!(error.starts_with(&path.display().to_string()) && error.contains("not finite"), "{error}");
    assert!(!path.exists());
}
