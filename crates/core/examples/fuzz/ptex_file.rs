//! The packed Ptex file target (docs/PTEX_FORMAT.md): seeds, a structure-aware mutator and
//! the oracle.
//!
//! The mutator sets header fields (counts, sizes, levels, format, section offsets and
//! lengths), face-record and table words to interesting values, or edits raw bytes, and then
//! — almost always — recomputes the CRC-32, so the mutants reach the content checks.
//!
//! The oracle ([`run`]): the reader must not panic; a file it accepts must keep every face's
//! block, border included, at every level inside the texture, sample at every level and level
//! of detail, and write and read back unchanged.

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};
use meshpaint_core::ptex;
use meshpaint_core::ptex::file::{self as ptex_file, PtexFile};
use meshpaint_core::synth::SplitMix64;
use meshpaint_core::synth::shapes::{OCTAHEDRON_TRIANGLES, icosphere, octahedron_positions};

use super::packed::variant;
use super::rng::Rng;

const CHECKSUM_AT: usize = 140;

fn seed(
    positions: Vec<[f32; 3]>,
    triangles: &[[u32; 3]],
    resolution: impl Fn(usize) -> u64,
    format: ColorFormat,
) -> Option<Vec<u8>> {
    let topology = Topology::build(positions.len() as u32, triangles).ok()?;
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(resolution(f)).unwrap_or(Resolution::ONE)).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).ok()?;
    let mut rng = SplitMix64(triangles.len() as u64);
    StoreWriter::new(&mut store, &mut UndoHistory::new(0)).fill_with(|_| rng.color());
    let packed = pack(&store, &positions, format).ok()?;
    let texture = ptex::build(&packed, 4096, 64 << 20).ok()?;
    ptex_file::to_bytes(&packed.positions, &packed.indices, &texture).ok()
}

/// Small meshes built in code (a quad, the octahedron and an open part of it, an icosphere at
/// mixed resolutions: pairs, lone faces, several slices) in every colour format.
pub fn seeds() -> Vec<Vec<u8>> {
    let quad = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let (sphere, sphere_triangles) = icosphere(1);
    let mixed = |face: usize| 1u64 << ((face * 7 + face / 5) % 4);
    [
        seed(quad, &[[0, 1, 2], [0, 2, 3]], |_| 2, ColorFormat::Rgba8Srgb),
        seed(octahedron_positions(), &OCTAHEDRON_TRIANGLES, |f| 1 << (f % 3), ColorFormat::Rgba16F),
        seed(octahedron_positions(), &OCTAHEDRON_TRIANGLES[..5], |_| 1, ColorFormat::Rgba32F),
        seed(sphere.clone(), &sphere_triangles, mixed, ColorFormat::Rgba8Srgb),
        seed(sphere, &sphere_triangles, mixed, ColorFormat::Rgba16F),
    ]
    .into_iter()
    .flatten()
    .collect()
}

fn read_u32(bytes: &[u8], at: usize) -> u32 {
    bytes.get(at..at + 4).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn put_u32(bytes: &mut [u8], at: usize, value: u32) {
    if let Some(slot) = bytes.get_mut(at..at + 4) {
        slot.copy_from_slice(&value.to_le_bytes());
    }
}

/// One mutant of a seed.
pub fn mutate(seeds: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let mut bytes = seeds[rng.index(seeds.len())].clone();
    for _ in 0..1 + rng.below(3) {
        match rng.below(4) {
            // A header word (version … section table … reserved).
            0 => {
                let at = 8 + 4 * rng.index(32);
                let new = rng.interesting_u32(read_u32(&bytes, at));
                put_u32(&mut bytes, at, new);
            }
            // A face-record or table word (section 2 or 3).
            1 | 2 => {
                let section = 2 + rng.index(2);
                let offset = read_u32(&bytes, 56 + 16 * section) as usize;
                let length = read_u32(&bytes, 64 + 16 * section) as usize;
                if length >= 4 {
                    let at = offset + 4 * rng.index(length / 4);
                    let new = rng.interesting_u32(read_u32(&bytes, at));
                    put_u32(&mut bytes, at, new);
                }
            }
            _ => rng.mutate_bytes(&mut bytes),
        }
    }
    if !rng.chance(1, 16) && bytes.len() >= CHECKSUM_AT + 4 {
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&bytes[..CHECKSUM_AT]);
        hasher.update(&bytes[CHECKSUM_AT + 4..]);
        let crc = hasher.finalize();
        put_u32(&mut bytes, CHECKSUM_AT, crc);
    }
    bytes
}

/// Every face's block, border included, at every level inside the texture; the CPU sampler
/// answers at every level and level of detail.
fn check_blocks(file: &PtexFile) {
    let layout = &file.ptex.layout;
    let (w, h) = (i64::from(layout.width), i64::from(layout.height));
    for face in 0..layout.records.len() as u32 {
        for level in 0..layout.levels {
            let frame = layout.frame(face, level).expect("a face of the file has no block");
            let n = i64::from(frame.n);
            let [x, y] = frame.origin;
            assert!(
                x >= 1 && y >= 1 && x + n < w + 1 && y + n < h + 1,
                "face {face} level {level}: block at ({x}, {y}) of side {n} leaves the {w}×{h} texture"
            );
            for bary in [[1.0, 0.0, 0.0], [0.2, 0.3, 0.5], [0.0, 0.5, 0.5]] {
                assert!(file.ptex.sample_level(face, bary, level).is_some());
                assert!(file.ptex.sample_trilinear(face, bary, level as f32 + 0.5).is_some());
            }
        }
    }
}

/// Runs one input through the reader and everything after it; returns the outcome's label.
pub fn run(bytes: &[u8]) -> String {
    let file = match ptex_file::from_bytes(bytes) {
        Ok(file) => file,
        Err(error) => return format!("refused: {}", variant(&format!("{error:?}"))),
    };
    check_blocks(&file);
    let written = ptex_file::to_bytes(&file.positions, &file.indices, &file.ptex)
        .expect("the writer refuses a file the reader accepted");
    let reread = ptex_file::from_bytes(&written).expect("the writer's output of an accepted file is refused");
    assert!(reread == file, "an accepted file does not survive write + read");
    if written == bytes { "accepted, rewritten byte for byte".to_owned() } else { "accepted, rewritten".to_owned() }
}
