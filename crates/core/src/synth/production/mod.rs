//! Test assets that look like production, generated procedurally and deterministically (the
//! same options give the same bytes): one file per asset class, written as binary glTF with
//! embedded PNG textures by [`crate::io::export_scene`]. `meshpaint synth CLASS -o FILE.glb`
//! writes them (docs/CLI.md).
//!
//! - [`AssetClass::Truck`] ([`truck`]): large faces carrying fine detail, a box truck whose
//!   two box sides (two triangles each) carry text and a logo on most of a 2048² texture,
//!   while the cab, chassis and wheels are many small faces with a smooth texture.
//! - [`AssetClass::Materials`] ([`materials`]): nine materials, textured at different sizes
//!   (one texture shared by two materials), texture-less factors, vertex colours, a
//!   primitive without a material, and a mesh placed twice.
//! - [`AssetClass::Islands`] ([`islands`]): a displaced cube-sphere boulder of exactly the
//!   asked triangle count (even) whose 24 UV islands have texel densities 1/8…2× apart.
//!
//! Building blocks: [`builder`] (meshes from parametric patches), [`canvas`] (textures),
//! [`font`] (a 5×7 bitmap font drawn anti-aliased).

pub mod builder;
pub mod canvas;
pub mod font;
pub mod islands;
pub mod materials;
pub mod truck;

use thiserror::Error;

use crate::io::export_gltf::ExportError;
use crate::mesh::scene::Scene;

/// Errors of the generators.
#[derive(Debug, Error)]
pub enum SynthError {
    /// An option is out of range.
    #[error("{0}")]
    Options(String),
    /// Writing the glTF failed.
    #[error(transparent)]
    Export(#[from] ExportError),
}

/// The asset classes (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssetClass {
    /// Large faces carrying text and a logo.
    Truck,
    /// Many materials, with and without textures.
    Materials,
    /// A dense mesh whose UV islands have very different texel densities.
    Islands,
}

impl AssetClass {
    /// Every class.
    pub const ALL: [AssetClass; 3] = [AssetClass::Truck, AssetClass::Materials, AssetClass::Islands];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            AssetClass::Truck => "truck",
            AssetClass::Materials => "materials",
            AssetClass::Islands => "islands",
        }
    }

    /// The class called `name`.
    pub fn from_name(name: &str) -> Option<AssetClass> {
        AssetClass::ALL.into_iter().find(|class| class.name() == name)
    }
}

/// Generator options; `None` takes the class's default.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Options {
    /// Triangles: exact for `islands` (must be even), approximate for `truck` (scales the
    /// small faces), ignored by `materials`.
    pub triangles: Option<u32>,
    /// Side of the main texture (`truck`, `islands`; a power of two, 64..=8192).
    pub texture_size: Option<u32>,
}

/// A rectangle on the surface: where a test should look.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// What is there.
    pub name: String,
    /// Face ids (in the file's triangle order, which the importer keeps) carrying it.
    pub faces: Vec<u32>,
    /// The rectangle in texture space: `[u_min, v_min, u_max, v_max]` (glTF UVs).
    pub uv_rect: [f32; 4],
    /// Its centre in world space.
    pub center: [f32; 3],
    /// The outward normal of the faces.
    pub normal: [f32; 3],
    /// Its width and height in world units.
    pub size: [f32; 2],
}

impl Region {
    /// The region as JSON (the fields by their names).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.name,
            "faces": self.faces,
            "uv_rect": self.uv_rect,
            "center": self.center,
            "normal": self.normal,
            "size": self.size,
        })
    }
}

/// A generated asset: the scene, what to look at, and the counts a test checks.
#[derive(Debug, Clone)]
pub struct Asset {
    /// The scene as the importer would read it back (before welding).
    pub scene: Scene,
    /// Regions of fine detail (the truck's logo and text).
    pub regions: Vec<Region>,
}

impl Asset {
    /// Triangles over every instance.
    pub fn triangles(&self) -> usize {
        self.scene.instanced_triangle_count()
    }
}

/// Generates `class` with `options`.
pub fn generate(class: AssetClass, options: Options) -> Result<Asset, SynthError> {
    let size = options.texture_size.unwrap_or(2048);
    if !size.is_power_of_two() || !(64..=8192).contains(&size) {
        return Err(SynthError::Options(format!("the texture size must be a power of two in 64..=8192, got {size}")));
    }
    match class {
        AssetClass::Truck => Ok(truck::truck(options.triangles.unwrap_or(6000), size)),
        AssetClass::Materials => Ok(materials::materials()),
        AssetClass::Islands => islands::islands(options.triangles.unwrap_or(50_000), size),
    }
}

/// The binary glTF of `asset`.
pub fn glb(asset: &Asset) -> Result<Vec<u8>, SynthError> {
    Ok(crate::io::export_scene::scene_glb(&asset.scene)?)
}
