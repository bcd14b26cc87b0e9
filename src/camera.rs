//! The orbit camera shared by the renderer, headless `render`, picking and stroke replay.
//!
//! Right-handed, +Y up. The camera orbits `target` at `distance`, `yaw_degrees` around +Y
//! (0 looks along −Z, i.e. the eye is on +Z) and `pitch_degrees` up from the horizon.
//! Projection is perspective with reversed-Z-free standard depth `[0, 1]` (wgpu); near and
//! far planes follow the scene's bounding sphere so depth precision holds at tiny and huge
//! scales. Positions can be far from the origin (1e6): matrices are built relative to the
//! target in `f64` and rounded once.

use glam::{DMat4, DVec3, Mat4, Vec3};

/// A bounding sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingSphere {
    /// Centre, world space.
    pub center: [f64; 3],
    /// Radius, world units (> 0 for any non-empty scene).
    pub radius: f64,
}

impl BoundingSphere {
    /// The sphere around the axis-aligned bounds of `positions` (a unit sphere when empty).
    pub fn of_points(positions: &[[f32; 3]]) -> Self {
        if positions.is_empty() {
            return BoundingSphere { center: [0.0; 3], radius: 1.0 };
        }
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for p in positions {
            let p = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            min = min.min(p);
            max = max.max(p);
        }
        let center = (min + max) * 0.5;
        let radius = positions
            .iter()
            .map(|p| (DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - center).length())
            .fold(0.0, f64::max);
        // A single point or a degenerate scene still gets a visible extent.
        let radius = if radius > 0.0 { radius } else { center.length().max(1.0) * 1e-6 };
        BoundingSphere { center: center.to_array(), radius }
    }
}

/// A perspective orbit camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// The point orbited and looked at, world space.
    pub target: [f64; 3],
    /// Eye distance from the target, world units.
    pub distance: f64,
    /// Rotation around +Y, degrees.
    pub yaw_degrees: f64,
    /// Elevation above the horizon, degrees, clamped to ±89.
    pub pitch_degrees: f64,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f64,
    /// Radius of the scene, used for the near and far planes.
    pub scene_radius: f64,
}

impl OrbitCamera {
    /// Default vertical field of view.
    pub const DEFAULT_FOV_Y_DEGREES: f64 = 40.0;

    /// A camera that frames `sphere` from `yaw`/`pitch` (degrees), the whole sphere in view.
    pub fn framing(sphere: BoundingSphere, yaw_degrees: f64, pitch_degrees: f64) -> Self {
        let fov = Self::DEFAULT_FOV_Y_DEGREES;
        // Distance at which the sphere fits the vertical field of view, with a margin.
        let distance = sphere.radius / (fov.to_radians() * 0.5).sin() * 1.1;
        OrbitCamera {
            target: sphere.center,
            distance,
            yaw_degrees,
            pitch_degrees: pitch_degrees.clamp(-89.0, 89.0),
            fov_y_degrees: fov,
            scene_radius: sphere.radius,
        }
    }

    /// Unit vector from the target towards the eye.
    pub fn eye_direction(&self) -> DVec3 {
        let (yaw, pitch) = (self.yaw_degrees.to_radians(), self.pitch_degrees.clamp(-89.0, 89.0).to_radians());
        DVec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos())
    }

    /// Eye position, world space.
    pub fn eye(&self) -> DVec3 {
        DVec3::from_array(self.target) + self.eye_direction() * self.distance
    }

    /// Near and far plane distances: a window around the scene sphere as seen from the eye.
    pub fn near_far(&self) -> (f64, f64) {
        let radius = self.scene_radius.max(1e-12);
        let center_distance = (DVec3::from_array(self.target) - self.eye()).length().max(self.distance);
        let far = center_distance + radius * 2.0;
        let near = (center_distance - radius * 2.0).max(far * 1e-5).max(radius * 1e-4);
        (near, far)
    }

    /// View matrix relative to `origin` (render positions as `p − origin` for precision).
    pub fn view_from_world_relative(&self, origin: DVec3) -> DMat4 {
        glam::dcamera::rh::view::look_at_mat4(self.eye() - origin, DVec3::from_array(self.target) - origin, DVec3::Y)
    }

    /// Projection matrix for a `width × height` image (depth range 0..1).
    pub fn clip_from_view(&self, width: u32, height: u32) -> DMat4 {
        let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
        let (near, far) = self.near_far();
        glam::dcamera::rh::proj::directx::perspective(self.fov_y_degrees.to_radians(), aspect, near, far)
    }

    /// `clip_from_world` for positions given relative to `origin`, as `f32`.
    pub fn clip_from_world_relative(&self, origin: DVec3, width: u32, height: u32) -> Mat4 {
        (self.clip_from_view(width, height) * self.view_from_world_relative(origin)).as_mat4()
    }

    /// The world-space ray through pixel coordinates `(x, y)` (origin top-left, pixel
    /// centres at `+0.5`) of a `width × height` image: `(origin, unit direction)`.
    pub fn ray_through_pixel(&self, x: f64, y: f64, width: u32, height: u32) -> (DVec3, DVec3) {
        let ndc_x = 2.0 * x / f64::from(width.max(1)) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / f64::from(height.max(1));
        let target = DVec3::from_array(self.target);
        let clip_from_world = self.clip_from_view(width, height) * self.view_from_world_relative(target);
        let world_from_clip = clip_from_world.inverse();
        let near = world_from_clip.project_point3(DVec3::new(ndc_x, ndc_y, 0.0));
        let far = world_from_clip.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
        let direction = (far - near).normalize();
        let eye = self.eye();
        (eye, direction)
    }

    /// The pixel position `(x, y)` of a world point, if it lies in front of the camera.
    pub fn project(&self, world: DVec3, width: u32, height: u32) -> Option<(f64, f64)> {
        let target = DVec3::from_array(self.target);
        let clip =
            self.clip_from_view(width, height) * self.view_from_world_relative(target) * (world - target).extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(((ndc.x + 1.0) * 0.5 * f64::from(width), (1.0 - ndc.y) * 0.5 * f64::from(height)))
    }

    /// Target as `f32` (for shaders that take the render origin).
    pub fn target_f32(&self) -> Vec3 {
        DVec3::from_array(self.target).as_vec3()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_rays_hit_the_points_that_project_to_them() {
        let camera = OrbitCamera::framing(BoundingSphere { center: [1e6, -3.0, 2.0], radius: 2.5 }, 30.0, 20.0);
        for world in [DVec3::new(1e6, -3.0, 2.0), DVec3::new(1e6 + 1.0, -2.0, 2.5)] {
            let (x, y) = camera.project(world, 640, 480).unwrap();
            let (origin, direction) = camera.ray_through_pixel(x, y, 640, 480);
            let to_point = world - origin;
            let off_ray = (to_point - direction * to_point.dot(direction)).length();
            assert!(off_ray < 1e-6 * to_point.length(), "{off_ray}");
        }
    }

    #[test]
    fn framing_keeps_the_sphere_between_near_and_far() {
        for radius in [1e-4, 1.0, 1e5] {
            let camera = OrbitCamera::framing(BoundingSphere { center: [0.0; 3], radius }, 0.0, 0.0);
            let (near, far) = camera.near_far();
            assert!(near > 0.0 && near < camera.distance - radius);
            assert!(far > camera.distance + radius);
        }
    }
}
