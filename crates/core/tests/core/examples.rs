//! The core's examples run and do what they say: `read_packed` (an engine's view of a
//! packed file, with nothing but meshpaint-core) reads what the packer wrote.

use crate::common::{TempDir, WriteThrough, model};

#[path = "../../examples/read_packed.rs"]
#[allow(dead_code)] // the example's `main`
mod read_packed;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::file::write_file;
use meshpaint_core::packing::sampler::{Filter, sample};

/// The summary against the store it was packed from: face count, resolutions per face and
/// the colour at a face centre (RGBA32F, so the packed level 0 is the store's colours
/// exactly), all read from the store, not the file.
#[test]
fn read_packed_reads_what_the_packer_wrote() {
    let dir = TempDir::new("read-packed");
    let mut document = Document::open(&model("Duck/Duck.glb"), Resolution::new(4).unwrap()).unwrap();
    for face in (0..document.store.topology().face_count()).step_by(5) {
        document.store.write_resolution(face, Resolution::new(8).unwrap()).unwrap();
    }
    document.store.write_resolution(0, Resolution::new(16).unwrap()).unwrap();
    let packed = document.pack(ColorFormat::Rgba32F).unwrap();
    let path = dir.join("duck.mpk");
    write_file(&path, &packed).unwrap();

    let summary = read_packed::read_packed(&path).unwrap();
    let resolutions = document.store.face_resolutions();
    assert_eq!(summary.faces, resolutions.len());
    assert_eq!(summary.samples, packed.sample_count());
    let count = |r: u32| resolutions.iter().filter(|x| x.get() == r).count() as u64;
    assert_eq!(summary.faces_per_log2, vec![0, 0, count(4), count(8), count(16)]);
    let third = 1.0 / 3.0;
    let expected = sample(&document.store, 0, [third; 3], Filter::Linear, 0).unwrap();
    assert_eq!(summary.centre_of_face_0, expected);
}
