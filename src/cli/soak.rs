//! The hidden `meshpaint autosave-soak` test helper (used by tests/app/autosave.rs).

use std::path::PathBuf;

use anyhow::Result;

use meshpaint_core::colors::store::SampleRef;
use meshpaint_core::packing::file as packed_file;
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};

use super::args::{ResolutionArg, budget, open};

/// Arguments of the hidden `meshpaint autosave-soak` (used by tests/app/autosave.rs).
#[derive(Debug, clap::Args)]
pub(super) struct SoakArgs {
    /// The document (glTF or packed).
    file: PathBuf,
    /// The recovery file to write in a loop.
    #[arg(long)]
    recovery: PathBuf,
    /// A file saved normally every few generations.
    #[arg(long)]
    saved: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// The first generation written.
    #[arg(long, default_value_t = 1)]
    start_generation: u64,
    /// Stop after this many generations (0: until killed).
    #[arg(long, default_value_t = 0)]
    iterations: u64,
}

/// Writes generation `g` (vertex 0's red channel is `g`, and a band of samples changes) to the
/// recovery file, and every third generation to the saved file too, printing
/// `recovery G` / `saved G` after each write returns.
pub(super) fn run(args: SoakArgs) -> Result<()> {
    use std::io::Write;
    let mut document = open(&args.file, args.resolution, &budget(None))?;
    let mut stdout = std::io::stdout();
    let vertices = document.store.topology().vertex_count;
    anyhow::ensure!(vertices > 0, "{}: no vertices", args.file.display());
    let mut generation = args.start_generation;
    let last = args.start_generation.saturating_add(args.iterations.saturating_sub(1));
    loop {
        let marker = generation as f32;
        let mut history = UndoHistory::new(0);
        let mut writer = StoreWriter::new(&mut document.store, &mut history);
        writer.set(SampleRef::Vertex(0), [marker, 0.0, 0.0, 1.0]);
        for face in (0..writer.store().topology().face_count()).step_by(7) {
            let len = writer.store().interior_samples(face).len() as u32;
            for offset in 0..len {
                let shade = ((generation + u64::from(offset)) % 17) as f32 / 16.0;
                writer.set(SampleRef::Interior { face, offset }, [shade, 0.5, 1.0 - shade, 1.0]);
            }
        }
        meshpaint_core::io::autosave::write_recovery(&args.recovery, &document)?;
        writeln!(stdout, "recovery {generation}")?;
        stdout.flush()?;
        if generation.is_multiple_of(3) {
            let packed = document.pack(meshpaint_core::io::autosave::RECOVERY_FORMAT)?;
            packed_file::write_file(&args.saved, &packed)?;
            writeln!(stdout, "saved {generation}")?;
            stdout.flush()?;
        }
        if args.iterations != 0 && generation >= last {
            return Ok(());
        }
        generation += 1;
    }
}
