//! Meshes from parametric patches: a grid of quads over `(s, t) ∈ [0, 1]²` whose vertices
//! a closure places (position, normal, UV, optional colour). Triangles whose corners share a
//! position (a cone's apex, a sphere's pole) are skipped, so the written triangle count is
//! the count the importer keeps; every triangle is wound so its geometric normal agrees with
//! the normals given (outward when the closure's normals are).

use glam::DVec3;

use crate::mesh::scene::SourceMesh;

/// One vertex of a patch.
#[derive(Debug, Clone, Copy)]
pub struct PatchVertex {
    /// Position.
    pub position: DVec3,
    /// Outward normal (normalised by the builder).
    pub normal: DVec3,
    /// glTF UV.
    pub uv: [f32; 2],
    /// Linear RGBA vertex colour (`None`: white where the mesh has colours).
    pub color: Option<[f32; 4]>,
}

/// A mesh being built.
#[derive(Debug, Default)]
pub struct MeshBuilder {
    mesh: SourceMesh,
    colors: Vec<Option<[f32; 4]>>,
}

impl MeshBuilder {
    /// An empty mesh called `name`.
    pub fn new(name: &str) -> MeshBuilder {
        MeshBuilder { mesh: SourceMesh { name: name.to_owned(), ..SourceMesh::default() }, colors: Vec::new() }
    }

    /// Triangles so far.
    pub fn triangle_count(&self) -> usize {
        self.mesh.triangles.len()
    }

    /// Adds a vertex and returns its id.
    pub fn vertex(&mut self, v: PatchVertex) -> u32 {
        let id = self.mesh.positions_local.len() as u32;
        self.mesh.positions_local.push(v.position.as_vec3().to_array());
        let n = v.normal.normalize_or(DVec3::Z);
        self.mesh.normals_local.push(n.as_vec3().to_array());
        self.mesh.uvs.push(v.uv);
        self.colors.push(v.color);
        id
    }

    /// Adds a triangle (skipped when two corners share a position; wound to agree with
    /// the corner normals). Returns whether it was added.
    pub fn triangle(&mut self, corners: [u32; 3], material: Option<u32>) -> bool {
        let p = corners.map(|v| glam::Vec3::from_array(self.mesh.positions_local[v as usize]).as_dvec3());
        if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
            return false;
        }
        let n: DVec3 =
            corners.iter().map(|&v| glam::Vec3::from_array(self.mesh.normals_local[v as usize]).as_dvec3()).sum();
        let geometric = (p[1] - p[0]).cross(p[2] - p[0]);
        let corners = if geometric.dot(n) < 0.0 { [corners[0], corners[2], corners[1]] } else { corners };
        self.mesh.triangles.push(corners);
        self.mesh.triangle_materials.push(material);
        true
    }

    /// A grid of `nu × nv` quads (two triangles each) over `(s, t) ∈ [0, 1]²`.
    pub fn patch(&mut self, nu: u32, nv: u32, material: Option<u32>, vertex: impl Fn(f64, f64) -> PatchVertex) {
        let base = self.mesh.positions_local.len() as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                self.vertex(vertex(f64::from(i) / f64::from(nu), f64::from(j) / f64::from(nv)));
            }
        }
        let id = |i: u32, j: u32| base + j * (nu + 1) + i;
        for j in 0..nv {
            for i in 0..nu {
                self.triangle([id(i, j), id(i + 1, j), id(i + 1, j + 1)], material);
                self.triangle([id(i, j), id(i + 1, j + 1), id(i, j + 1)], material);
            }
        }
    }

    /// A flat rectangle `origin + s·du + t·dv` as `nu × nv` quads whose UVs span `uv`
    /// (`[u0, v0, u1, v1]`, `s` along u, `t` along v); the normal faces `du × dv`, or the
    /// opposite when `flip`.
    #[allow(clippy::too_many_arguments)]
    pub fn quad(
        &mut self,
        origin: DVec3,
        du: DVec3,
        dv: DVec3,
        (nu, nv): (u32, u32),
        uv: [f32; 4],
        material: Option<u32>,
        color: Option<[f32; 4]>,
    ) {
        let normal = du.cross(dv);
        self.patch(nu, nv, material, |s, t| PatchVertex {
            position: origin + du * s + dv * t,
            normal,
            uv: lerp_uv(uv, s, t),
            color,
        });
    }

    /// An axis-aligned box from `min` to `max`, each face `n × n` quads; face `k` (+x, −x,
    /// +y, −y, +z, −z) maps to `uv_of_face(k)`.
    pub fn cuboid(
        &mut self,
        min: DVec3,
        max: DVec3,
        n: u32,
        material: Option<u32>,
        uv_of_face: impl Fn(usize) -> [f32; 4],
    ) {
        let d = max - min;
        let faces = [
            (DVec3::new(max.x, min.y, max.z), DVec3::new(0.0, 0.0, -d.z), DVec3::new(0.0, d.y, 0.0)),
            (DVec3::new(min.x, min.y, min.z), DVec3::new(0.0, 0.0, d.z), DVec3::new(0.0, d.y, 0.0)),
            (DVec3::new(min.x, max.y, max.z), DVec3::new(d.x, 0.0, 0.0), DVec3::new(0.0, 0.0, -d.z)),
            (DVec3::new(min.x, min.y, min.z), DVec3::new(d.x, 0.0, 0.0), DVec3::new(0.0, 0.0, d.z)),
            (DVec3::new(min.x, min.y, max.z), DVec3::new(d.x, 0.0, 0.0), DVec3::new(0.0, d.y, 0.0)),
            (DVec3::new(max.x, min.y, min.z), DVec3::new(-d.x, 0.0, 0.0), DVec3::new(0.0, d.y, 0.0)),
        ];
        for (k, (origin, du, dv)) in faces.into_iter().enumerate() {
            self.quad(origin, du, dv, (n, n), uv_of_face(k), material, None);
        }
    }

    /// A cylinder of `radius` around the axis from `a` to `b`: `segments` around, `rings`
    /// along, with flat caps; side UVs span `side_uv`, caps map to `cap_uv` (a disc in it).
    #[allow(clippy::too_many_arguments)]
    pub fn cylinder(
        &mut self,
        (a, b): (DVec3, DVec3),
        radius: f64,
        (segments, rings): (u32, u32),
        side_uv: [f32; 4],
        cap_uv: [f32; 4],
        material: Option<u32>,
        color: &dyn Fn(DVec3) -> Option<[f32; 4]>,
    ) {
        let axis = (b - a).normalize_or(DVec3::Y);
        let (x, y) = axis.any_orthonormal_pair();
        let around = |s: f64| {
            // The angle of s = 1 is exactly that of s = 0, so the seam welds.
            let k = (s * f64::from(segments)).round() as u32 % segments.max(1);
            let angle = std::f64::consts::TAU * f64::from(k) / f64::from(segments.max(1));
            x * angle.cos() + y * angle.sin()
        };
        self.patch(segments, rings, material, |s, t| {
            let position = a + (b - a) * t + around(s) * radius;
            PatchVertex { position, normal: around(s), uv: lerp_uv(side_uv, s, t), color: color(position) }
        });
        for (centre, normal) in [(a, -axis), (b, axis)] {
            self.patch(segments, 1, material, |s, t| {
                let dir = around(s);
                let position = centre + dir * radius * t;
                let local = [0.5 + 0.5 * t * dir.dot(x), 0.5 + 0.5 * t * dir.dot(y)];
                PatchVertex { position, normal, uv: lerp_uv(cap_uv, local[0], local[1]), color: color(position) }
            });
        }
    }

    /// The mesh (vertex colours kept when any vertex has one; the others white).
    pub fn finish(self) -> SourceMesh {
        let MeshBuilder { mut mesh, colors } = self;
        if colors.iter().any(Option::is_some) {
            mesh.colors = colors.into_iter().map(|c| c.unwrap_or([1.0; 4])).collect();
        }
        mesh
    }
}

/// The point at `(s, t)` of `rect` (`[u0, v0, u1, v1]`).
pub fn lerp_uv(rect: [f32; 4], s: f64, t: f64) -> [f32; 2] {
    let s = s as f32;
    let t = t as f32;
    [rect[0] + (rect[2] - rect[0]) * s, rect[1] + (rect[3] - rect[1]) * t]
}
