//! What an engine or a batch job needs from meshpaint, with nothing but `meshpaint-core`
//! (no wgpu, egui or winit in its dependency tree): read a packed file, check it, and look
//! up a colour anywhere on the mesh with the CPU reference sampler — the same value the
//! editor's GPU shader shows there.
//! `cargo run -p meshpaint-core --example read_packed -- painted.mpk`

use std::path::{Path, PathBuf};

use meshpaint_core::packing::file::{PackedFileError, read_file};
use meshpaint_core::packing::sampler::{Filter, sample};

/// What [`read_packed`] found in a packed file.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Triangles.
    pub faces: usize,
    /// Samples in the colour buffer, MIP chains included.
    pub samples: u64,
    /// Faces per `log2 R` (index 0: R = 1).
    pub faces_per_log2: Vec<u64>,
    /// The linear-filtered colour at the centre of face 0, level 0 (linear RGBA).
    pub centre_of_face_0: [f32; 4],
}

/// Reads `path` (checksums and layout are verified by the reader) and summarises it.
pub fn read_packed(path: &Path) -> Result<Summary, PackedFileError> {
    let mesh = read_file(path)?;
    let mut faces_per_log2 = Vec::new();
    for record in &mesh.face_records {
        let log2 = record.resolution().map_or(0, |r| r.log2() as usize);
        faces_per_log2.resize(faces_per_log2.len().max(log2 + 1), 0);
        faces_per_log2[log2] += 1;
    }
    let third = 1.0 / 3.0;
    let centre_of_face_0 = sample(&mesh, 0, [third; 3], Filter::Linear, 0).unwrap_or([0.0; 4]);
    Ok(Summary { faces: mesh.face_records.len(), samples: mesh.sample_count(), faces_per_log2, centre_of_face_0 })
}

fn main() -> Result<(), PackedFileError> {
    let Some(path) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: read_packed FILE.mpk");
        std::process::exit(2);
    };
    let summary = read_packed(&path)?;
    println!("{}: {} faces, {} samples with MIP chains", path.display(), summary.faces, summary.samples);
    for (log2, count) in summary.faces_per_log2.iter().enumerate().filter(|(_, n)| **n > 0) {
        println!("  R = {:>4}: {count} faces", 1u32 << log2);
    }
    println!("  colour at the centre of face 0: {:?}", summary.centre_of_face_0);
    Ok(())
}
