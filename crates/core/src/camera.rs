//! The orbit camera shared by the renderer, headless `render`, picking and stroke replay.
//!
//! Right-handed, +Y up by default. The camera orbits `target` at `distance`, `yaw_degrees`
//! around +Y (0 looks along −Z, i.e. the eye is on +Z) and `pitch_degrees` up from the
//! horizon. With [`UpAxis::Z`] (scans and CAD files are often Z-up) the same angles are
//! turned by +90° about X: +Z is up, yaw turns around +Z and yaw 0 looks along +Y from −Y
//! (Blender's front view). Only the view turns; the geometry is never changed.
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

/// Which world axis points up on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum UpAxis {
    /// +Y up (glTF, OBJ from most modelling tools).
    #[default]
    Y,
    /// +Z up (many scans, CAD, Blender's own axes).
    Z,
}

impl UpAxis {
    /// Both axes.
    pub const ALL: [UpAxis; 2] = [UpAxis::Y, UpAxis::Z];

    /// The world-space unit vector pointing up.
    pub fn vector(self) -> DVec3 {
        match self {
            UpAxis::Y => DVec3::Y,
            UpAxis::Z => DVec3::Z,
        }
    }

    /// A direction of the Y-up orbit frame in world space (+90° about X for Z-up).
    pub fn to_world(self, v: DVec3) -> DVec3 {
        match self {
            UpAxis::Y => v,
            UpAxis::Z => DVec3::new(v.x, -v.z, v.y),
        }
    }

    /// The name (`y`, `z`).
    pub fn name(self) -> &'static str {
        match self {
            UpAxis::Y => "y",
            UpAxis::Z => "z",
        }
    }

    /// Parses a name given by [`UpAxis::name`] (either case).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name().eq_ignore_ascii_case(name))
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
    /// The world axis that is up on screen (yaw turns around it).
    pub up: UpAxis,
}

/// Camera yaw of a newly opened document and of `meshpaint render`, degrees.
pub const DEFAULT_YAW_DEGREES: f64 = 30.0;
/// Camera pitch of a newly opened document and of `meshpaint render`, degrees.
pub const DEFAULT_PITCH_DEGREES: f64 = 20.0;

/// The camera a document opens with: [`OrbitCamera::framing`] of its bounding `sphere` at
/// `yaw`/`pitch` (degrees), with `distance` (when finite and positive) overriding the framing
/// distance.
pub fn default_camera(sphere: BoundingSphere, yaw: f64, pitch: f64, distance: Option<f64>) -> OrbitCamera {
    let mut camera = OrbitCamera::framing(sphere, yaw, pitch);
    if let Some(distance) = distance.filter(|d| d.is_finite() && *d > 0.0) {
        camera.distance = distance;
    }
    camera
}

impl OrbitCamera {
    /// Default vertical field of view.
    pub const DEFAULT_FOV_Y_DEGREES: f64 = 40.0;
    /// The closest [`OrbitCamera::zoom`] gets, as a fraction of the scene radius.
    pub const MIN_DISTANCE_FRACTION: f64 = 1e-3;

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
            up: UpAxis::Y,
        }
    }

    /// Unit vector from the target towards the eye.
    pub fn eye_direction(&self) -> DVec3 {
        let (yaw, pitch) = (self.yaw_degrees.to_radians(), self.pitch_degrees.clamp(-89.0, 89.0).to_radians());
        self.up.to_world(DVec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos()))
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
        glam::dcamera::rh::view::look_at_mat4(
            self.eye() - origin,
            DVec3::from_array(self.target) - origin,
            self.up.vector(),
        )
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

    /// Turns the eye around the target: `delta_yaw` degrees around the up axis, `delta_pitch` degrees
    /// up (the pitch stays within ±89°, the yaw within (−180°, 180°]).
    pub fn orbit(&mut self, delta_yaw_degrees: f64, delta_pitch_degrees: f64) {
        let yaw = (self.yaw_degrees + delta_yaw_degrees).rem_euclid(360.0);
        self.yaw_degrees = if yaw > 180.0 { yaw - 360.0 } else { yaw };
        self.pitch_degrees = (self.pitch_degrees + delta_pitch_degrees).clamp(-89.0, 89.0);
    }

    /// Unit vectors pointing right and up on screen, world space.
    pub fn right_up(&self) -> (DVec3, DVec3) {
        let towards_eye = self.eye_direction();
        let right = self.up.vector().cross(towards_eye).normalize_or(DVec3::X);
        let up = towards_eye.cross(right).normalize_or(self.up.vector());
        (right, up)
    }

    /// World units per pixel at the target's depth, in an image `height` pixels tall.
    pub fn world_per_pixel(&self, height: f64) -> f64 {
        2.0 * self.distance * (self.fov_y_degrees.to_radians() * 0.5).tan() / height.max(1.0)
    }

    /// Moves target and eye together so that the scene follows a pointer moved by
    /// `(dx, dy)` pixels (x right, y down) in an image `height` pixels tall.
    pub fn pan_pixels(&mut self, dx: f64, dy: f64, height: f64) {
        let (right, up) = self.right_up();
        let scale = self.world_per_pixel(height);
        let target = DVec3::from_array(self.target) - right * (dx * scale) + up * (dy * scale);
        if target.is_finite() {
            self.target = target.to_array();
        }
    }

    /// Multiplies the eye distance by `factor` (below 1 zooms in). The distance never drops
    /// below [`OrbitCamera::MIN_DISTANCE_FRACTION`] of the scene radius, so the target
    /// always stays beyond the near plane.
    pub fn zoom(&mut self, factor: f64) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let min = self.scene_radius.max(1e-12) * Self::MIN_DISTANCE_FRACTION;
        self.distance = (self.distance * factor).max(min);
    }

    /// Zooms by `factor` (as [`OrbitCamera::zoom`]) towards pixel `(x, y)` of a
    /// `width × height` view: the point of the target's view plane under that pixel stays
    /// under it (Blender's "zoom to mouse position"). Target and eye move along the lines
    /// to that point, scaled by the factor the distance clamp allows; the view direction
    /// is kept.
    pub fn zoom_towards_pixel(&mut self, factor: f64, x: f64, y: f64, width: u32, height: u32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let (origin, direction) = self.ray_through_pixel(x, y, width, height);
        let target = DVec3::from_array(self.target);
        let normal = self.eye_direction();
        let along = direction.dot(normal);
        let before = self.distance;
        self.zoom(factor);
        if along.abs() < 1e-12 || before <= 0.0 {
            return;
        }
        // The cursor ray meets the plane through the target facing the eye at `point`.
        let point = origin + direction * ((target - origin).dot(normal) / along);
        let scale = self.distance / before;
        let moved = point + (target - point) * scale;
        if moved.is_finite() {
            self.target = moved.to_array();
        }
    }

    /// Looks at `point` from `distance` (clamped as in [`OrbitCamera::zoom`]), keeping the
    /// viewing direction.
    pub fn look_at_point(&mut self, point: DVec3, distance: f64) {
        if !(point.is_finite() && distance.is_finite() && distance > 0.0) {
            return;
        }
        self.target = point.to_array();
        self.distance = distance;
        self.zoom(1.0);
    }

    /// Widens the depth range so that `sphere` (the scene) lies between the near and far
    /// planes wherever the target went (after a pan or [`OrbitCamera::look_at_point`]):
    /// the scene lies within `radius + |target − centre|` of the target.
    pub fn fit_depth_to(&mut self, sphere: BoundingSphere) {
        let offset = (DVec3::from_array(self.target) - DVec3::from_array(sphere.center)).length();
        let radius = sphere.radius + if offset.is_finite() { offset } else { 0.0 };
        if radius.is_finite() && radius > 0.0 {
            self.scene_radius = radius;
        }
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

    /// With Z up the same angles look at the scene turned +90° about X: the eye's direction
    /// is the Y-up one turned, +Z projects upwards on screen, and rays and projection agree.
    #[test]
    fn z_up_turns_the_view_and_keeps_plus_z_up_on_screen() {
        let sphere = BoundingSphere { center: [1.0, 2.0, 3.0], radius: 2.0 };
        let y_up = OrbitCamera::framing(sphere, 30.0, 20.0);
        let z_up = OrbitCamera { up: UpAxis::Z, ..y_up };
        let d = y_up.eye_direction();
        assert!((z_up.eye_direction() - DVec3::new(d.x, -d.z, d.y)).length() < 1e-12);
        let center = DVec3::from_array(sphere.center);
        for (camera, up) in [(y_up, DVec3::Y), (z_up, DVec3::Z)] {
            let (_, y0) = camera.project(center, 640, 480).unwrap();
            let (_, y1) = camera.project(center + up * 0.5, 640, 480).unwrap();
            assert!(y1 < y0 - 10.0, "{:?}: up moved from {y0} to {y1}", camera.up);
            assert!(camera.right_up().1.dot(up) > 0.9);
            let (x, y) = camera.project(center + DVec3::new(0.3, -0.2, 0.4), 640, 480).unwrap();
            let (origin, direction) = camera.ray_through_pixel(x, y, 640, 480);
            let to_point = center + DVec3::new(0.3, -0.2, 0.4) - origin;
            assert!((to_point - direction * to_point.dot(direction)).length() < 1e-9);
        }
        // Front view with Z up looks along +Y (the eye on −Y), as in Blender.
        let front = OrbitCamera { up: UpAxis::Z, yaw_degrees: 0.0, pitch_degrees: 0.0, ..y_up };
        assert!((front.eye_direction() - DVec3::NEG_Y).length() < 1e-12);
        assert_eq!(UpAxis::from_name("Z"), Some(UpAxis::Z));
    }

    #[test]
    fn orbit_wraps_yaw_and_clamps_pitch() {
        let mut camera = OrbitCamera::framing(BoundingSphere { center: [0.0; 3], radius: 1.0 }, 170.0, 80.0);
        camera.orbit(20.0, 30.0);
        assert!((camera.yaw_degrees - -170.0).abs() < 1e-9, "{}", camera.yaw_degrees);
        assert_eq!(camera.pitch_degrees, 89.0);
    }

    #[test]
    fn pan_moves_the_target_with_the_pointer() {
        let sphere = BoundingSphere { center: [1e6, 2.0, -3.0], radius: 0.5 };
        let mut camera = OrbitCamera::framing(sphere, 30.0, 20.0);
        let point = DVec3::from_array(sphere.center);
        let (x0, y0) = camera.project(point, 800, 600).unwrap();
        camera.pan_pixels(40.0, -25.0, 600.0);
        let (x1, y1) = camera.project(point, 800, 600).unwrap();
        assert!((x1 - x0 - 40.0).abs() < 1e-3 && (y1 - y0 + 25.0).abs() < 1e-3, "{x0},{y0} → {x1},{y1}");
    }

    #[test]
    fn zoom_stops_before_the_near_plane_and_depth_follows_the_target() {
        let sphere = BoundingSphere { center: [0.0; 3], radius: 2.0 };
        let mut camera = OrbitCamera::framing(sphere, 0.0, 0.0);
        camera.zoom(1e-9);
        assert!((camera.distance - 2.0 * OrbitCamera::MIN_DISTANCE_FRACTION).abs() < 1e-12);
        assert!(camera.near_far().0 < camera.distance);
        // Panned far off the scene: after fitting, the whole sphere is between near and far.
        let mut camera = OrbitCamera::framing(sphere, 0.0, 0.0);
        camera.pan_pixels(5000.0, 0.0, 600.0);
        camera.fit_depth_to(sphere);
        let (near, far) = camera.near_far();
        let centre_depth = (camera.eye() - DVec3::ZERO).length();
        assert!(near < centre_depth - sphere.radius && far > centre_depth + sphere.radius);
    }

    /// Zooming towards a pixel keeps the point of the target's view plane under it at that
    /// pixel (forward projection as the truth), in and out, off-centre and at the clamp;
    /// at the view's centre it is a plain zoom.
    #[test]
    fn zoom_towards_a_pixel_keeps_the_point_under_it() {
        let sphere = BoundingSphere { center: [1.0, -2.0, 0.5], radius: 2.0 };
        let (w, h) = (800u32, 600u32);
        for (x, y) in [(100.0, 80.0), (700.5, 520.25), (400.0, 300.0)] {
            for factor in [0.5, 0.9, 1.25, 1e-9] {
                let mut camera = OrbitCamera::framing(sphere, 30.0, 20.0);
                let (origin, direction) = camera.ray_through_pixel(x, y, w, h);
                let target = DVec3::from_array(camera.target);
                let normal = camera.eye_direction();
                let point = origin + direction * ((target - origin).dot(normal) / direction.dot(normal));
                let (yaw, pitch) = (camera.yaw_degrees, camera.pitch_degrees);
                camera.zoom_towards_pixel(factor, x, y, w, h);
                let (px, py) = camera.project(point, w, h).unwrap();
                assert!((px - x).abs() < 1e-6 && (py - y).abs() < 1e-6, "{x},{y} ×{factor}: now at {px},{py}");
                assert_eq!((camera.yaw_degrees, camera.pitch_degrees), (yaw, pitch));
            }
        }
        let mut plain = OrbitCamera::framing(sphere, 30.0, 20.0);
        let mut towards = plain;
        plain.zoom(0.5);
        towards.zoom_towards_pixel(0.5, 400.0, 300.0, w, h);
        let moved = (DVec3::from_array(plain.target) - DVec3::from_array(towards.target)).length();
        assert!(moved < 1e-9 && (plain.distance - towards.distance).abs() < 1e-12);
    }
}
