//! The packed Ptex file (docs/PTEX_FORMAT.md): round trips, and hostile inputs refused without
//! a panic — every truncation, every single-byte change (checksum kept right so the content
//! checks are reached), and each content rule broken on purpose.

use crate::common;
use crate::common::WriteThrough;

use common::Rng;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::ptex::file::{PtexFileError, from_bytes, to_bytes};
use meshpaint_core::ptex::{self, PackedPtex};
use meshpaint_core::synth::shapes::icosphere;

fn packed(format: ColorFormat) -> PackedMesh {
    let (positions, triangles) = icosphere(1);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(1 << (f % 4)).unwrap()).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(11);
    store.write_all(|_| rng.color());
    pack(&store, &positions, format).unwrap()
}

fn file_of(format: ColorFormat) -> (PackedMesh, PackedPtex, Vec<u8>) {
    let packed = packed(format);
    let texture = ptex::build(&packed, 4096, u64::MAX).unwrap();
    let bytes = to_bytes(&packed.positions, &packed.indices, &texture).unwrap();
    (packed, texture, bytes)
}

/// The CRC-32 of every byte but the checksum field, written into it (as the writer does).
fn fix_checksum(bytes: &mut [u8]) {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..140]);
    hasher.update(&bytes[144..]);
    let crc = hasher.finalize();
    bytes[140..144].copy_from_slice(&crc.to_le_bytes());
}

#[test]
fn a_packed_ptex_file_reads_back_what_was_written_in_every_format() {
    for format in ColorFormat::ALL {
        let (packed, texture, bytes) = file_of(format);
        assert_eq!(bytes.len() % 256, texture.texels.len() % 256, "sections at multiples of 256");
        let file = from_bytes(&bytes).unwrap();
        assert_eq!((file.positions.as_slice(), file.indices.as_slice()), (&packed.positions[..], &packed.indices[..]));
        assert_eq!(file.ptex.layout.records, texture.layout.records);
        assert_eq!(file.ptex.layout.tables, texture.layout.tables);
        assert_eq!((file.ptex.layout.width, file.ptex.layout.height), (texture.layout.width, texture.layout.height));
        assert_eq!(file.ptex.texels, texture.texels);
        assert_eq!(file.ptex.vertex_density, texture.vertex_density);
        for face in 0..packed.indices.len() as u32 {
            for level in 0..texture.layout.levels {
                let w = [0.2, 0.3, 0.5];
                assert_eq!(file.ptex.sample_level(face, w, level), texture.sample_level(face, w, level));
            }
        }
        // Written again from what was read: the same bytes.
        assert_eq!(to_bytes(&file.positions, &file.indices, &file.ptex).unwrap(), bytes, "{format:?}");
    }
}

#[test]
fn every_truncation_and_every_byte_change_is_refused_or_reads_safely() {
    let (_, _, bytes) = file_of(ColorFormat::Rgba8Srgb);
    for len in 0..bytes.len() {
        assert!(from_bytes(&bytes[..len]).is_err(), "truncated to {len}");
    }
    let mut checked_content = 0;
    // Every header and table byte, and a stride through the rest, each to a few values.
    let texels_start = bytes.len() - bytes.len() % 256;
    for at in (0..bytes.len()).filter(|&i| i < 1024 || i % 97 == 0 || i >= texels_start.saturating_sub(256)) {
        for value in [0u8, 1, 0x7f, 0xff, bytes[at] ^ 0x10] {
            let mut changed = bytes.clone();
            changed[at] = value;
            if (140..144).contains(&at) {
                assert!(from_bytes(&changed).is_err() || changed == bytes);
                continue;
            }
            fix_checksum(&mut changed);
            match from_bytes(&changed) {
                Ok(file) => {
                    // Whatever reads back samples every face at every level without a panic.
                    for face in 0..file.indices.len() as u32 {
                        for level in 0..file.ptex.layout.levels {
                            assert!(file.ptex.sample_level(face, [0.3, 0.3, 0.4], level).is_some());
                        }
                    }
                }
                Err(PtexFileError::Content { .. }) => checked_content += 1,
                Err(_) => {}
            }
        }
    }
    assert!(checked_content > 50, "the content checks were reached {checked_content} times");
}

#[test]
fn records_and_tables_that_leave_the_texture_are_refused() {
    let (packed, texture, _) = file_of(ColorFormat::Rgba8Srgb);
    let blocks = texture.layout.blocks.len() as u32;
    let refuse = |edit: &dyn Fn(&mut PackedPtex)| {
        let mut t = texture.clone();
        edit(&mut t);
        let error = to_bytes(&packed.positions, &packed.indices, &t).unwrap_err();
        assert!(matches!(error, PtexFileError::Content { .. } | PtexFileError::Header(_)), "{error}");
    };
    refuse(&|t| t.layout.records[0].0 |= 3);
    refuse(&|t| t.layout.records[0].0 = (blocks + 5) << 4);
    refuse(&|t| t.layout.tables.n_res[1] = t.layout.tables.n_res[2] + 1);
    refuse(&|t| t.layout.tables.n_row[0] += 1);
    refuse(&|t| t.layout.tables.per_row[0] += 1);
    refuse(&|t| t.layout.height += 1);
    refuse(&|t| t.vertex_density[0] = f32::NAN);
}
