//! The targets and their inputs: input `I` of seed `S` is a pure function of `(S, I)`.

use std::path::Path;

use super::rng::Rng;
use super::{gltf, mct_file, packed, ptex_file};

/// What is fuzzed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The packed-file reader, then unpacking, sampling and re-packing.
    Packed,
    /// The glTF importer, then welding, colouring and packing.
    Gltf,
    /// The MCT-file reader, then every block's texels, sampling and re-writing.
    Mct,
    /// The packed Ptex file reader, then every block's place, sampling and re-writing.
    Ptex,
    /// A target that panics, aborts, hangs and over-allocates on purpose, to test the
    /// supervisor itself.
    SelfTest,
}

impl Target {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Target::Packed => "packed",
            Target::Gltf => "gltf",
            Target::Mct => "mct",
            Target::Ptex => "ptex",
            Target::SelfTest => "selftest",
        }
    }

    /// The inverse of [`Target::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        [Target::Packed, Target::Gltf, Target::Mct, Target::Ptex, Target::SelfTest]
            .into_iter()
            .find(|t| t.name() == name)
    }
}

/// One generated input.
pub struct Input {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// The extension it is saved with.
    pub extension: &'static str,
    /// glTF: meant as binary glTF.
    glb: bool,
    /// glTF: the resolution the document is coloured at.
    resolution: u32,
}

/// A target's seeds.
pub enum Corpus {
    /// Packed seed files.
    Packed(Vec<Vec<u8>>),
    /// glTF seeds.
    Gltf(Vec<gltf::Seed>),
    /// MCT seed files.
    Mct(Vec<Vec<u8>>),
    /// Packed Ptex seed files.
    Ptex(Vec<Vec<u8>>),
    /// The self-test target.
    SelfTest,
}

/// Self-test inputs: `index % 16` selects the behaviour.
pub const SELFTEST_PANIC: u64 = 5;
/// Calls `std::process::abort`.
pub const SELFTEST_ABORT: u64 = 7;
/// Never returns.
pub const SELFTEST_HANG: u64 = 9;
/// Reserves 4 GiB (fails only under the memory limit: nothing is touched).
pub const SELFTEST_ALLOCATE: u64 = 11;

impl Corpus {
    /// The seeds of `target` (models are read from `models`).
    pub fn new(target: Target, models: &Path) -> Self {
        match target {
            Target::Packed => Corpus::Packed(packed::seeds(models)),
            Target::Gltf => Corpus::Gltf(gltf::seeds(models)),
            Target::Mct => Corpus::Mct(mct_file::seeds()),
            Target::Ptex => Corpus::Ptex(ptex_file::seeds()),
            Target::SelfTest => Corpus::SelfTest,
        }
    }

    /// Input `index` of the campaign with `seed`.
    pub fn input(&self, seed: u64, index: u64) -> Input {
        let mut rng = Rng::for_input(seed, index);
        match self {
            Corpus::Packed(seeds) => {
                Input { bytes: packed::mutate(seeds, &mut rng), extension: "mpk", glb: false, resolution: 0 }
            }
            Corpus::Mct(seeds) => {
                Input { bytes: mct_file::mutate(seeds, &mut rng), extension: "mct", glb: false, resolution: 0 }
            }
            Corpus::Ptex(seeds) => {
                Input { bytes: ptex_file::mutate(seeds, &mut rng), extension: "ptx", glb: false, resolution: 0 }
            }
            Corpus::Gltf(seeds) => {
                let resolution = rng.pick(&[1, 2, 4]);
                let (bytes, glb) = gltf::mutate(seeds, &mut rng);
                Input { bytes, extension: if glb { "glb" } else { "gltf" }, glb, resolution }
            }
            Corpus::SelfTest => {
                Input { bytes: (index % 16).to_le_bytes().to_vec(), extension: "bin", glb: false, resolution: 0 }
            }
        }
    }

    /// Runs `input`; returns its outcome's label (panics on a defect).
    pub fn run(&self, input: &Input) -> String {
        match self {
            Corpus::Packed(_) => packed::run(&input.bytes),
            Corpus::Gltf(_) => gltf::run(&input.bytes, input.glb, input.resolution),
            Corpus::Mct(_) => mct_file::run(&input.bytes),
            Corpus::Ptex(_) => ptex_file::run(&input.bytes),
            Corpus::SelfTest => {
                let behaviour = input.bytes.first().copied().map_or(0, u64::from);
                match behaviour {
                    SELFTEST_PANIC => panic!("self-test panic"),
                    SELFTEST_ABORT => std::process::abort(),
                    SELFTEST_HANG => loop {
                        std::thread::sleep(std::time::Duration::from_secs(1));
                    },
                    SELFTEST_ALLOCATE => {
                        let big: Vec<u8> = Vec::with_capacity(4 << 30);
                        std::hint::black_box(&big);
                        "allocated 4 GiB".to_owned()
                    }
                    _ => "ok".to_owned(),
                }
            }
        }
    }
}
