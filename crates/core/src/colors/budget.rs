//! The sample and memory budget: every operation that creates samples (opening a mesh at
//! `R`, "set R for all", the resolution brush, undo / redo of resolution changes) counts
//! what it would hold *first* and refuses, naming the needed and the allowed numbers,
//! before it allocates anything.
//!
//! # Counts
//!
//! [`SampleCounts`] holds, for a per-face resolution assignment, the level-0 samples
//! (`V + Σ_e (R_e − 1) + Σ_f (R_f − 1)(R_f − 2)/2`), the samples of the packed layout with
//! MIP chains (`V · (1 + log2 max R_f) + Σ_e edge chain + Σ_f interior chain`, exactly what
//! [`crate::packing::packer::PackLayout`] allocates) and the samples of the paint-mode layout
//! (every element in a power-of-two block). Uniform resolutions are closed form
//! ([`SampleCounts::uniform`]); a per-face assignment is one pass over the edges and faces
//! without allocating ([`SampleCounts::of_resolutions`]); one face's change is O(its three
//! edges) ([`SampleTracker`]).
//!
//! # Limits
//!
//! | limit | value | why |
//! |---|---|---|
//! | samples with MIP chains | `2^28` | face records address samples with 28-bit bases ([`MAX_SAMPLES`]) |
//! | GPU atlas | `min(16384, D) · D` samples, `D` = the device's `max_texture_dimension_2d` | the colour atlas is one 2D texture (passed in by the app as [`GpuLimits`]) |
//! | GPU data textures | `4096 · D` vertices and faces | positions, indices and face records are 4096-wide textures |
//! | memory | half of the machine's RAM (`MemTotal` in `/proc/meminfo`; 4 GiB when it cannot be read), or `MESHPAINT_MEMORY_BUDGET` | see the cost model below |
//! | triangles | memory / [`BYTES_PER_TRIANGLE`], at most `2^32 − 1` | face ids are `u32` |
//!
//! # Cost model (bytes)
//!
//! `estimate = 32 · samples + (16 + 2 · B) · samples_with_mips + BYTES_PER_TRIANGLE · faces`
//! with `B` the bytes per sample of the colour format (4, 8, 16): the store and the paint
//! mode's base snapshot hold level 0 as linear `f32` RGBA (16 B each), packing builds every
//! chain in `f32` (16 B) and encodes it (`B`), and the GPU copy (system memory on a software
//! rasteriser) holds the encoded chains again (`B`). `BYTES_PER_TRIANGLE` covers the welded
//! mesh, topology, picking BVH and face records.

use std::fmt;

use thiserror::Error;

use crate::colors::format::ColorFormat;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::mesh::topology::Topology;

/// Largest colour-buffer size in samples (28-bit bases in face records); equal to
/// [`crate::packing::linear::MAX_SAMPLES`] (the packer's own check).
pub const MAX_SAMPLES: u64 = 1 << 28;

/// Bytes of one level-0 sample in the store (linear `f32` RGBA).
pub const STORE_BYTES_PER_SAMPLE: u64 = 16;

/// Memory one triangle costs beyond its samples (welded mesh with corner UVs and normals,
/// topology, BVH, face records, GPU index data), bytes: `meshpaint pack` of Bunny144k at
/// R = 1 peaks at 69 MB, about 400 B per triangle above the process's own 11 MB; the rest
/// is room for the editor's picking BVH and GPU copies.
pub const BYTES_PER_TRIANGLE: u64 = 600;

/// The part of the machine's RAM the budget allows: `numerator / denominator`.
pub const MEMORY_FRACTION: (u64, u64) = (1, 2);

/// The memory budget when the machine's RAM cannot be read: 4 GiB.
pub const FALLBACK_MEMORY_BYTES: u64 = 4 << 30;

/// The environment variable that sets the memory budget (bytes, or with a `K`, `M`, `G`
/// suffix, powers of 1024).
pub const MEMORY_ENV: &str = "MESHPAINT_MEMORY_BUDGET";

/// The colour-atlas width the GPU uses: `min(16384, max_texture_dimension_2d)`.
pub const ATLAS_MAX_WIDTH: u64 = 16384;

/// The width of the GPU's data textures (positions, indices, face records).
pub const GPU_DATA_WIDTH: u64 = 4096;

/// Errors of a budget check: what was asked, how much it needs, how much is allowed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum BudgetError {
    /// Too many samples for a hard limit (packed format, GPU atlas).
    #[error("{what} needs {} samples {layout}, more than the {} allowed by {limit}", thousands(*needed), thousands(*allowed))]
    Samples {
        /// What was asked (e.g. "R = 64 on every face").
        what: String,
        /// Samples needed (the larger of the two layouts).
        needed: u64,
        /// Which layout needs them: "with MIP chains" or "in the paint-mode layout".
        layout: &'static str,
        /// Samples allowed.
        allowed: u64,
        /// Which limit.
        limit: String,
    },
    /// More memory than the budget.
    #[error("{what} needs about {} of memory ({} samples, {} with MIP chains), more than the budget of {} ({origin})", bytes_text(*needed), thousands(*samples), thousands(*samples_with_mips), bytes_text(*allowed))]
    Memory {
        /// What was asked.
        what: String,
        /// Estimated bytes.
        needed: u64,
        /// Budget in bytes.
        allowed: u64,
        /// Level-0 samples.
        samples: u64,
        /// Samples with MIP chains.
        samples_with_mips: u64,
        /// Where the budget comes from.
        origin: MemorySource,
    },
    /// Too many triangles (after instancing) for memory or 32-bit ids.
    #[error("{what} has {} triangles, more than the {} allowed ({limit})", thousands(*needed), thousands(*allowed))]
    Triangles {
        /// What was counted.
        what: String,
        /// Triangles.
        needed: u64,
        /// Triangles allowed.
        allowed: u64,
        /// Which limit.
        limit: String,
    },
    /// An output format's own limit (e.g. the 4 GiB of a GLB file).
    #[error("{0}")]
    Output(String),
}

/// Where the memory budget comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemorySource {
    /// A fraction ([`MEMORY_FRACTION`]) of the machine's RAM.
    Machine {
        /// `MemTotal` in bytes.
        total: u64,
    },
    /// [`MEMORY_ENV`].
    Environment,
    /// The RAM could not be read: [`FALLBACK_MEMORY_BYTES`].
    Fallback,
    /// Set by the program (e.g. a test).
    Set,
}

impl fmt::Display for MemorySource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MemorySource::Machine { total } => {
                write!(f, "{}/{} of the machine's {} RAM", MEMORY_FRACTION.0, MEMORY_FRACTION.1, bytes_text(*total))
            }
            MemorySource::Environment => write!(f, "set by {MEMORY_ENV}"),
            MemorySource::Fallback => write!(f, "the machine's RAM is unknown: default"),
            MemorySource::Set => write!(f, "set by the program"),
        }
    }
}

/// The GPU limits the budget respects (the app passes the device's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuLimits {
    /// `max_texture_dimension_2d` of the device.
    pub max_texture_dimension_2d: u32,
}

impl GpuLimits {
    /// Samples the colour atlas can hold: `min(16384, D) · D`.
    pub fn atlas_samples(&self) -> u64 {
        let d = u64::from(self.max_texture_dimension_2d);
        d.min(ATLAS_MAX_WIDTH) * d
    }

    /// Entries (vertices, faces) a data texture can hold: `4096 · D`.
    pub fn data_entries(&self) -> u64 {
        GPU_DATA_WIDTH * u64::from(self.max_texture_dimension_2d)
    }
}

/// An output format's own limit, checked with the counts (e.g. the GLB size of a
/// tessellated export): `Err` holds the message.
pub type OutputCheck = fn(&SampleCounts) -> Result<(), String>;

/// The limits of one process: see the module documentation.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Memory the samples and triangles may take, bytes.
    pub memory_bytes: u64,
    /// Where `memory_bytes` comes from.
    pub memory_source: MemorySource,
    /// Samples with MIP chains allowed by the packed format ([`MAX_SAMPLES`]; tests lower it).
    pub max_samples: u64,
    /// The GPU's limits, when the document is shown.
    pub gpu: Option<GpuLimits>,
    /// The colour format the samples will be packed in, when it is not the document's own
    /// (the memory estimate depends on it).
    pub format: Option<ColorFormat>,
    /// An output format's limit, checked after the others.
    pub output_check: Option<OutputCheck>,
}

impl Default for Budget {
    fn default() -> Self {
        Self::from_environment()
    }
}

impl Budget {
    /// The budget of this machine: [`MEMORY_ENV`] when set and valid, else
    /// [`MEMORY_FRACTION`] of `MemTotal`, else [`FALLBACK_MEMORY_BYTES`]. No GPU limits.
    pub fn from_environment() -> Self {
        if let Some(bytes) = std::env::var(MEMORY_ENV).ok().as_deref().and_then(parse_bytes) {
            return Budget::with_memory(bytes, MemorySource::Environment);
        }
        match std::fs::read_to_string("/proc/meminfo").ok().as_deref().and_then(mem_total_bytes) {
            Some(total) => {
                Budget::with_memory(total / MEMORY_FRACTION.1 * MEMORY_FRACTION.0, MemorySource::Machine { total })
            }
            None => Budget::with_memory(FALLBACK_MEMORY_BYTES, MemorySource::Fallback),
        }
    }

    /// A budget of `memory_bytes` (the packed limit, no GPU).
    pub fn with_memory(memory_bytes: u64, memory_source: MemorySource) -> Self {
        Budget { memory_bytes, memory_source, max_samples: MAX_SAMPLES, gpu: None, format: None, output_check: None }
    }

    /// The same budget respecting `gpu` too.
    pub fn with_gpu(self, gpu: GpuLimits) -> Self {
        Budget { gpu: Some(gpu), ..self }
    }

    /// The largest number of samples with MIP chains (packed format and GPU atlas), with
    /// the name of the limit that decides.
    pub fn sample_limit(&self) -> (u64, String) {
        let packed = (self.max_samples, "the packed format (28-bit sample addresses)".to_owned());
        match self.gpu {
            Some(gpu) if gpu.atlas_samples() < packed.0 => (
                gpu.atlas_samples(),
                format!("the GPU's colour atlas (textures of at most {0}×{0})", gpu.max_texture_dimension_2d),
            ),
            _ => packed,
        }
    }

    /// The largest triangle count (after instancing), with the limit that decides.
    pub fn triangle_limit(&self) -> (u64, String) {
        let mut best = (
            self.memory_bytes / BYTES_PER_TRIANGLE,
            format!("{} of memory at {BYTES_PER_TRIANGLE} B per triangle", bytes_text(self.memory_bytes)),
        );
        let ids = u64::from(u32::MAX);
        if ids < best.0 {
            best = (ids, "32-bit face ids".to_owned());
        }
        if let Some(gpu) = self.gpu
            && gpu.data_entries() < best.0
        {
            best = (gpu.data_entries(), format!("the GPU's data textures (4096 × {})", gpu.max_texture_dimension_2d));
        }
        best
    }

    /// Refuses `triangles` (counted after instancing, before any are built) past
    /// [`Budget::triangle_limit`]; `what` names the file.
    pub fn check_triangles(&self, what: &str, triangles: u64) -> Result<(), BudgetError> {
        let (allowed, limit) = self.triangle_limit();
        if triangles > allowed {
            return Err(BudgetError::Triangles { what: what.to_owned(), needed: triangles, allowed, limit });
        }
        Ok(())
    }

    /// Refuses giving the faces of `store` the `resolutions` (one per face) when that grows a
    /// count past the budget; a change that grows no count always passes (so a document past
    /// a lowered budget can still shrink). Counts in one pass, allocates nothing.
    pub fn check_resolutions(
        &self,
        what: &str,
        store: &ColorStore,
        resolutions: &[Resolution],
        format: ColorFormat,
    ) -> Result<(), BudgetError> {
        let topology = store.topology();
        let after =
            SampleCounts::of_resolutions(topology, |f| resolutions.get(f as usize).copied().unwrap_or(Resolution::ONE));
        let now = SampleCounts::of_store(store);
        if after.samples <= now.samples
            && after.samples_with_mips <= now.samples_with_mips
            && after.paint_samples <= now.paint_samples
        {
            return Ok(());
        }
        self.check(what, &after, format)
    }

    /// Refuses `counts` of a document in `format` (or in [`Budget::format`] when set) past
    /// any limit; `what` names the request.
    pub fn check(&self, what: &str, counts: &SampleCounts, format: ColorFormat) -> Result<(), BudgetError> {
        let format = self.format.unwrap_or(format);
        let (allowed, limit) = self.sample_limit();
        let (needed, layout) = if counts.paint_samples > counts.samples_with_mips {
            (counts.paint_samples, "in the paint-mode layout")
        } else {
            (counts.samples_with_mips, "with MIP chains")
        };
        if needed > allowed {
            return Err(BudgetError::Samples { what: what.to_owned(), needed, layout, allowed, limit });
        }
        if let Some(gpu) = self.gpu {
            let entries = counts.vertices.max(counts.faces);
            if entries > gpu.data_entries() {
                return Err(BudgetError::Triangles {
                    what: what.to_owned(),
                    needed: entries,
                    allowed: gpu.data_entries(),
                    limit: format!("the GPU's data textures (4096 × {})", gpu.max_texture_dimension_2d),
                });
            }
        }
        let bytes = counts.estimated_bytes(format);
        if bytes > self.memory_bytes {
            return Err(BudgetError::Memory {
                what: what.to_owned(),
                needed: bytes,
                allowed: self.memory_bytes,
                samples: counts.samples,
                samples_with_mips: counts.samples_with_mips,
                origin: self.memory_source,
            });
        }
        if let Some(check) = self.output_check {
            check(counts).map_err(|message| BudgetError::Output(format!("{what}: {message}")))?;
        }
        Ok(())
    }
}

/// Bytes one texel of a base-colour texture costs while it is converted (RGBA8 as decoded,
/// plus its linear `f32` MIP pyramid, `16 · 4/3`), rounded up.
pub const BYTES_PER_TEXEL: u64 = 26;

/// Bytes one glTF node costs while a scene is read (the parsed JSON node, its instance and
/// the traversal state), rounded up generously.
pub const BYTES_PER_NODE: u64 = 1024;

/// Sample counts of one resolution assignment (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SampleCounts {
    /// Vertices.
    pub vertices: u64,
    /// Edges.
    pub edges: u64,
    /// Faces.
    pub faces: u64,
    /// Level-0 samples.
    pub samples: u64,
    /// Samples of the packed layout with MIP chains.
    pub samples_with_mips: u64,
    /// Samples of the paint-mode layout (power-of-two blocks, no slack beyond them).
    pub paint_samples: u64,
    /// Triangles of the tessellated glTF export (`Σ R_f²`, before fans at fine sides).
    pub tessellated_triangles: u64,
}

/// Power-of-two block of `samples` (0 for none), as the paint layout allocates.
fn block(samples: u64) -> u64 {
    if samples == 0 { 0 } else { samples.next_power_of_two() }
}

impl SampleCounts {
    /// Every face at `r`: closed form (the edges take `r` too).
    pub fn uniform(r: Resolution, vertices: u64, edges: u64, faces: u64) -> Self {
        let counts = layout::uniform_counts(r, vertices, edges, faces);
        let (edge, interior) = (u64::from(layout::edge_sample_count(r)), u64::from(layout::interior_sample_count(r)));
        let square = u64::from(r.get()) * u64::from(r.get());
        SampleCounts {
            vertices,
            edges,
            faces,
            samples: counts.samples,
            samples_with_mips: counts.samples_with_mips,
            paint_samples: vertices
                .saturating_add(edges.saturating_mul(block(edge)))
                .saturating_add(faces.saturating_mul(block(interior))),
            tessellated_triangles: faces.saturating_mul(square),
        }
    }

    /// Every face of `topology` at `r`.
    pub fn uniform_on(topology: &Topology, r: Resolution) -> Self {
        Self::uniform(
            r,
            u64::from(topology.vertex_count),
            u64::from(topology.edge_count()),
            u64::from(topology.face_count()),
        )
    }

    /// Face `f` at `resolution(f)`, each edge at the maximum of its faces: one pass over
    /// edges and faces, nothing allocated.
    pub fn of_resolutions(topology: &Topology, resolution: impl Fn(u32) -> Resolution) -> Self {
        let vertices = u64::from(topology.vertex_count);
        let mut counts = SampleCounts {
            vertices,
            edges: u64::from(topology.edge_count()),
            faces: u64::from(topology.face_count()),
            samples: vertices,
            paint_samples: vertices,
            ..SampleCounts::default()
        };
        let mut max_log2 = 0;
        for face in 0..topology.face_count() {
            let r = resolution(face);
            max_log2 = max_log2.max(r.log2());
            counts.add_interior(r, 1);
        }
        for edge in 0..topology.edge_count() {
            let r = topology.faces_of_edge(edge).iter().map(|&(f, _)| resolution(f)).max().unwrap_or(Resolution::ONE);
            counts.add_edge(r, 1);
        }
        counts.samples_with_mips += vertices * u64::from(max_log2 + 1);
        counts
    }

    /// The counts of `store` as it is.
    pub fn of_store(store: &ColorStore) -> Self {
        let resolutions = store.face_resolutions();
        Self::of_resolutions(store.topology(), |f| resolutions.get(f as usize).copied().unwrap_or(Resolution::ONE))
    }

    /// Adds (`sign = 1`) or removes (`-1`) one face interior at `r`.
    fn add_interior(&mut self, r: Resolution, sign: i64) {
        let n = u64::from(layout::interior_sample_count(r));
        let square = u64::from(r.get()) * u64::from(r.get());
        apply(&mut self.samples, n, sign);
        apply(&mut self.samples_with_mips, u64::from(layout::interior_chain_len(r)), sign);
        apply(&mut self.paint_samples, block(n), sign);
        apply(&mut self.tessellated_triangles, square, sign);
    }

    /// Adds or removes one edge at `r`.
    fn add_edge(&mut self, r: Resolution, sign: i64) {
        let n = u64::from(layout::edge_sample_count(r));
        apply(&mut self.samples, n, sign);
        apply(&mut self.samples_with_mips, u64::from(layout::edge_chain_len(r)), sign);
        apply(&mut self.paint_samples, block(n), sign);
    }

    /// Estimated peak memory in bytes (see the module documentation), saturating.
    pub fn estimated_bytes(&self, format: ColorFormat) -> u64 {
        let per_chain_sample = STORE_BYTES_PER_SAMPLE + 2 * format.bytes_per_sample() as u64;
        self.samples
            .saturating_mul(2 * STORE_BYTES_PER_SAMPLE)
            .saturating_add(self.samples_with_mips.saturating_mul(per_chain_sample))
            .saturating_add(self.faces.saturating_mul(BYTES_PER_TRIANGLE))
    }
}

fn apply(total: &mut u64, amount: u64, sign: i64) {
    *total = if sign >= 0 { total.saturating_add(amount) } else { total.saturating_sub(amount) };
}

/// Counts kept up to date while faces change resolution one by one (the resolution brush):
/// built once from the store, then each change is checked in O(its three edges).
#[derive(Debug, Clone)]
pub struct SampleTracker {
    counts: SampleCounts,
    /// Faces per `log2 R` (for the vertex levels of the packed layout).
    faces_per_log2: [u64; layout::MAX_LOG2_RESOLUTION as usize + 1],
}

impl SampleTracker {
    /// The tracker of `store` as it is (one pass over its faces and edges).
    pub fn new(store: &ColorStore) -> Self {
        let mut faces_per_log2 = [0u64; layout::MAX_LOG2_RESOLUTION as usize + 1];
        for r in store.face_resolutions() {
            faces_per_log2[r.log2() as usize] += 1;
        }
        SampleTracker { counts: SampleCounts::of_store(store), faces_per_log2 }
    }

    /// The current counts.
    pub fn counts(&self) -> SampleCounts {
        self.counts
    }

    fn max_log2(&self) -> u32 {
        self.faces_per_log2.iter().rposition(|&n| n > 0).unwrap_or(0) as u32
    }

    /// The counts after `face` of `store` (as it is now) changes to `target`.
    pub fn after(&self, store: &ColorStore, face: u32, target: Resolution) -> SampleCounts {
        let mut counts = self.counts;
        let Some(current) = store.face_resolution(face) else {
            return counts;
        };
        let topology = store.topology();
        counts.add_interior(current, -1);
        counts.add_interior(target, 1);
        for &edge in topology.face_edges.get(face as usize).map_or(&[][..], |e| &e[..]) {
            let old = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            let new = topology
                .faces_of_edge(edge)
                .iter()
                .map(|&(f, _)| if f == face { target } else { store.face_resolution(f).unwrap_or(Resolution::ONE) })
                .max()
                .unwrap_or(Resolution::ONE);
            if new != old {
                counts.add_edge(old, -1);
                counts.add_edge(new, 1);
            }
        }
        let mut levels = self.faces_per_log2;
        levels[current.log2() as usize] -= 1;
        levels[target.log2() as usize] += 1;
        let new_max = levels.iter().rposition(|&n| n > 0).unwrap_or(0) as u32;
        let vertices = counts.vertices;
        counts.samples_with_mips = counts
            .samples_with_mips
            .saturating_sub(vertices * u64::from(self.max_log2() + 1))
            .saturating_add(vertices * u64::from(new_max + 1));
        counts
    }

    /// Checks the change of `face` to `target` against `budget` and, when allowed, records it
    /// (the caller then makes the change).
    pub fn admit(
        &mut self,
        store: &ColorStore,
        face: u32,
        target: Resolution,
        budget: &Budget,
        format: ColorFormat,
    ) -> Result<(), BudgetError> {
        let Some(current) = store.face_resolution(face) else {
            return Ok(());
        };
        let after = self.after(store, face, target);
        if after.samples_with_mips > self.counts.samples_with_mips
            || after.paint_samples > self.counts.paint_samples
            || after.samples > self.counts.samples
        {
            budget.check(&format!("raising face {face} to R = {target}"), &after, format)?;
        }
        self.counts = after;
        self.faces_per_log2[current.log2() as usize] -= 1;
        self.faces_per_log2[target.log2() as usize] += 1;
        Ok(())
    }
}

/// `MemTotal` of `/proc/meminfo` text, in bytes.
pub fn mem_total_bytes(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|line| line.starts_with("MemTotal:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    let unit = match words.next() {
        Some("kB") | Some("KB") => 1024,
        None => 1,
        Some(_) => return None,
    };
    value.checked_mul(unit).filter(|&bytes| bytes > 0)
}

/// Parses a byte count: digits with an optional `K`, `M`, `G` or `T` suffix (powers of 1024,
/// an optional trailing `B` or `iB`). `None` for anything else or zero.
pub fn parse_bytes(text: &str) -> Option<u64> {
    let text = text.trim();
    let upper = text.to_ascii_uppercase();
    let stripped = upper.strip_suffix("IB").or_else(|| upper.strip_suffix('B')).unwrap_or(&upper);
    let (digits, shift) = match stripped.chars().last()? {
        'K' => (&stripped[..stripped.len() - 1], 10),
        'M' => (&stripped[..stripped.len() - 1], 20),
        'G' => (&stripped[..stripped.len() - 1], 30),
        'T' => (&stripped[..stripped.len() - 1], 40),
        _ => (stripped, 0),
    };
    let value: u64 = digits.trim().parse().ok()?;
    value.checked_mul(1u64 << shift).filter(|&bytes| bytes > 0)
}

/// `n` with thin thousands separators (`1 234 567`).
pub fn thousands(n: u64) -> String {
    thousands_with(n, ' ')
}

/// `n` with `separator` between groups of three digits (the editor uses `,`).
pub fn thousands_with(n: u64, separator: char) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(separator);
        }
        out.push(c);
    }
    out
}

/// Bytes in binary units (`1.5 GiB`).
pub fn bytes_text(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 { format!("{bytes} B") } else { format!("{value:.1} {}", UNITS[unit]) }
}
