//! The perspective (pinhole) camera, generating rays with differentials.
//!
//! Camera space is glTF's: the camera looks down its local -z, +x is right on the image, +y up.
//! Image pixel (0, 0) is the top-left one.

use crate::error::{Error, Result};
use crate::geometry::{Ray, RayDifferential};
use glam::{Mat4, Vec2, Vec3};

/// Which image axis the field of view spans.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FovAxis {
    /// Horizontal field of view (Mitsuba's default).
    X,
    /// Vertical field of view (glTF's `yfov`, tessera's default).
    Y,
}

/// A pinhole camera.
#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    to_world: Mat4,
    position: Vec3,
    width: u32,
    height: u32,
    /// The field of view as given, in degrees, and the axis it spans.
    fov: (f32, FovAxis),
    /// tan of half the field of view along x and y: the film spans [-x, x] x [-y, y] at unit
    /// distance in camera space.
    tan_half: Vec2,
    /// World direction (not normalised) through the film's top-left corner, and its change
    /// for one pixel right and one pixel down: directions are affine in the film position.
    corner_direction: Vec3,
    pixel_step: [Vec3; 2],
    /// Scale of the ray differentials: max(1/8, 1/sqrt(spp)) (pbrt-v4), since the footprint of a
    /// pixel is covered by spp samples rather than one.
    differential_scale: f32,
    /// Smallest change of the unit ray direction for a one-pixel step, over the image (pbrt-v4
    /// `CameraBase::FindMinimumDifferentials`), used by [`Self::approximate_dp_dxy`].
    min_direction_step: Vec2,
}

impl PerspectiveCamera {
    /// A camera with the given camera-to-world transform, `fov` in degrees along `fov_axis`,
    /// an image of `width` x `height` pixels and `spp` samples per pixel.
    pub fn new(to_world: Mat4, fov_degrees: f32, fov_axis: FovAxis, width: u32, height: u32, spp: u32) -> Result<Self> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(Error::param("camera.fov", format!("{fov_degrees} degrees is outside (0, 180)")));
        }
        if !to_world.is_finite() || to_world.determinant().abs() < 1e-12 {
            return Err(Error::param("camera.transform", "the camera transform is singular or not finite"));
        }
        let aspect = width as f32 / height as f32;
        let t = (fov_degrees.to_radians() * 0.5).tan();
        let tan_half = match fov_axis {
            FovAxis::X => Vec2::new(t, t / aspect),
            FovAxis::Y => Vec2::new(t * aspect, t),
        };
        let mut camera = PerspectiveCamera {
            to_world,
            position: to_world.transform_point3(Vec3::ZERO),
            width,
            height,
            fov: (fov_degrees, fov_axis),
            tan_half,
            corner_direction: to_world.transform_vector3(Vec3::new(-tan_half.x, tan_half.y, -1.0)),
            pixel_step: [
                to_world.transform_vector3(Vec3::new(2.0 * tan_half.x / width as f32, 0.0, 0.0)),
                to_world.transform_vector3(Vec3::new(0.0, -2.0 * tan_half.y / height as f32, 0.0)),
            ],
            differential_scale: (1.0 / (spp.max(1) as f32).sqrt()).max(0.125),
            min_direction_step: Vec2::ZERO,
        };
        camera.min_direction_step = camera.find_min_direction_step();
        Ok(camera)
    }

    /// A camera at `eye` looking at `target`, with `up` roughly up on the image.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Result<Mat4> {
        let back = eye - target;
        let right = up.cross(back);
        if !(back.length_squared() > 0.0)
            || !(right.length_squared() > 1e-12 * back.length_squared() * up.length_squared())
        {
            return Err(Error::param(
                "camera",
                format!("eye {eye}, target {target} and up {up} do not define a view (coincident or parallel)"),
            ));
        }
        let z = back.normalize();
        let x = right.normalize();
        let y = z.cross(x);
        Ok(Mat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), eye.extend(1.0)))
    }

    /// The camera's position.
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Camera-to-world transform.
    pub fn to_world(&self) -> Mat4 {
        self.to_world
    }

    /// Field of view in degrees and the image axis it spans.
    pub fn fov(&self) -> (f32, FovAxis) {
        self.fov
    }

    /// Image size in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The same view at another image size, with one sample per pixel (ray differentials of
    /// one pixel).
    pub fn with_resolution(&self, width: u32, height: u32) -> Result<Self> {
        Self::new(self.to_world, self.fov.0, self.fov.1, width, height, 1)
    }

    /// The world directions (not normalised) through the film's top-left corner and, added per
    /// pixel, one pixel right and one pixel down: the ray through film point f (in pixels)
    /// points along `corner + steps[0] f.x + steps[1] f.y`.
    pub fn film_directions(&self) -> (Vec3, [Vec3; 2]) {
        (self.corner_direction, self.pixel_step)
    }

    /// The projection of a rasteriser that sees what [`Self::generate_ray`] sees: world to clip
    /// space, with reversed infinite depth (points at distance `near` in front of the camera
    /// get depth 1, infinitely far ones 0). NDC x runs from -1 on the image's left edge to 1
    /// on its right, y from 1 at the top to -1 at the bottom, so that the pixel centre
    /// (x + 1/2, y + 1/2) of a WebGPU or Vulkan framebuffer is film point (x + 1/2, y + 1/2).
    pub fn clip_from_world(&self, near: f32) -> Mat4 {
        let projection = Mat4::from_cols(
            glam::Vec4::new(1.0 / self.tan_half.x, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 1.0 / self.tan_half.y, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
            glam::Vec4::new(0.0, 0.0, near, 0.0),
        );
        projection * self.to_world.inverse()
    }

    /// World direction (not normalised) through the film point `film` in pixels
    /// ((0, 0) = top-left corner of the image).
    #[inline]
    fn direction(&self, film: Vec2) -> Vec3 {
        self.corner_direction + self.pixel_step[0] * film.x + self.pixel_step[1] * film.y
    }

    /// The ray through the film point `film` (in pixels), with differentials to the points one
    /// pixel right and one pixel down, scaled by max(1/8, 1/sqrt(spp)).
    pub fn generate_ray(&self, film: Vec2) -> (Ray, RayDifferential) {
        let d = self.direction(film);
        let ray = Ray::new(self.position, d.normalize());
        let diff = RayDifferential {
            d,
            dx_o: Vec3::ZERO,
            dx_d: self.pixel_step[0],
            dy_o: Vec3::ZERO,
            dy_d: self.pixel_step[1],
        };
        (ray, diff.scaled(self.differential_scale))
    }

    fn find_min_direction_step(&self) -> Vec2 {
        let mut min = Vec2::splat(f32::INFINITY);
        let n = 32;
        for i in 0..=n {
            for j in 0..=n {
                let film = Vec2::new(i as f32 / n as f32 * self.width as f32, j as f32 / n as f32 * self.height as f32);
                let d = self.direction(film).normalize();
                let sx = (self.direction(film + Vec2::X).normalize() - d).length();
                let sy = (self.direction(film + Vec2::Y).normalize() - d).length();
                min = min.min(Vec2::new(sx, sy));
            }
        }
        min
    }

    /// Approximate footprint on the tangent plane (point `p`, normal `n`) of a one-pixel step,
    /// for hits after the first bounce, where no ray differential is tracked: as if the camera
    /// looked straight at `p` with its smallest per-pixel direction change (pbrt-v4
    /// `CameraBase::Approximate_dp_dxy`). Returns zero vectors at grazing angles.
    pub fn approximate_dp_dxy(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let v = p - self.position;
        let dist = v.length();
        if !(dist > 0.0) {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let dir = v / dist;
        let right = self.to_world.x_axis.truncate();
        let ex = (right - dir * dir.dot(right))
            .try_normalize()
            .unwrap_or_else(|| crate::geometry::Frame::from_normal(dir).s);
        let ey = dir.cross(ex);
        let diff = RayDifferential {
            d: dir,
            dx_o: Vec3::ZERO,
            dx_d: ex * self.min_direction_step.x,
            dy_o: Vec3::ZERO,
            dy_d: ey * self.min_direction_step.y,
        };
        match diff.scaled(self.differential_scale).steps_on_plane(self.position, p, n) {
            Some(steps) => steps,
            None => (Vec3::ZERO, Vec3::ZERO),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> PerspectiveCamera {
        let m = PerspectiveCamera::look_at(Vec3::new(0.0, 2.0, 4.6), Vec3::new(0.0, -0.3, 0.0), Vec3::Y).unwrap();
        PerspectiveCamera::new(m, 40.0, FovAxis::X, 64, 32, 1).unwrap()
    }

    #[test]
    fn camera_centre_ray_hits_target_and_x_is_right() {
        let c = camera();
        let (ray, _) = c.generate_ray(Vec2::new(32.0, 16.0));
        let to_target = (Vec3::new(0.0, -0.3, 0.0) - ray.o).normalize();
        assert!(ray.d.distance(to_target) < 1e-6);
        // Pixels to the right look towards world +x (Mitsuba's scene: the seam shows at x > 0).
        let (right, _) = c.generate_ray(Vec2::new(63.0, 16.0));
        assert!(right.d.x > 0.0);
        // Pixels at the top look up.
        let (top, _) = c.generate_ray(Vec2::new(32.0, 0.0));
        assert!(top.d.y > ray.d.y);
    }

    #[test]
    fn camera_fov_spans_the_image_width() {
        let c = camera();
        let (l, _) = c.generate_ray(Vec2::new(0.0, 16.0));
        let (r, _) = c.generate_ray(Vec2::new(64.0, 16.0));
        assert!((l.d.angle_between(r.d).to_degrees() - 40.0).abs() < 1e-3);
    }

    #[test]
    fn the_rasteriser_projection_sees_what_the_rays_see() {
        let c = camera();
        let clip_from_world = c.clip_from_world(0.01);
        for film in [Vec2::new(0.5, 0.5), Vec2::new(63.5, 2.5), Vec2::new(20.25, 31.5)] {
            let (ray, _) = c.generate_ray(film);
            for distance in [0.5, 3.0, 40.0] {
                let clip = clip_from_world * ray.at(distance).extend(1.0);
                let ndc = clip.truncate() / clip.w;
                let pixel = Vec2::new((ndc.x + 1.0) * 0.5 * 64.0, (1.0 - ndc.y) * 0.5 * 32.0);
                assert!(pixel.distance(film) < 1e-3, "{film} at {distance}: {pixel}");
                // Depth: 1 at the near plane, falling as 1 / distance along the view axis.
                let view_depth = -(c.to_world().inverse().transform_point3(ray.at(distance))).z;
                assert!((ndc.z - 0.01 / view_depth).abs() < 1e-6, "depth {}", ndc.z);
            }
        }
    }

    #[test]
    fn camera_rejects_degenerate_views() {
        assert!(PerspectiveCamera::look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y).is_err());
        assert!(PerspectiveCamera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y).is_err());
        assert!(PerspectiveCamera::new(Mat4::IDENTITY, 180.0, FovAxis::Y, 4, 4, 1).is_err());
    }

    #[test]
    fn camera_approximate_footprint_uses_the_smallest_pixel_step() {
        // Looking straight at a plane 10 units away, the approximation spans 10 times the
        // image's smallest per-pixel direction change (at the corners: pbrt-v4's choice, which
        // errs towards sharper lookups), and never more than the exact centre footprint.
        let c = PerspectiveCamera::new(Mat4::IDENTITY, 60.0, FovAxis::Y, 100, 100, 1).unwrap();
        let (ray, diff) = c.generate_ray(Vec2::new(50.0, 50.0));
        let p = ray.at(10.0 / -ray.d.z);
        let (dx_o, dx_d) = (ray.o + diff.dx_o, diff.d + diff.dx_d);
        let px = dx_o + dx_d * ((dx_o.z - p.z) / -dx_d.z);
        let (dpdx, dpdy) = c.approximate_dp_dxy(p, Vec3::Z);
        let expected = 10.0 * c.min_direction_step.x;
        assert!((dpdx.length() - expected).abs() < 1e-3 * expected, "{} vs {expected}", dpdx.length());
        assert!(dpdx.length() <= (px - p).length());
        assert!(dpdx.dot(dpdy).abs() < 1e-6 * expected * expected, "x and y steps are orthogonal");
        // With 64 spp the footprint shrinks by 1/sqrt(64).
        let c64 = PerspectiveCamera::new(Mat4::IDENTITY, 60.0, FovAxis::Y, 100, 100, 64).unwrap();
        assert!((c64.approximate_dp_dxy(p, Vec3::Z).0.length() - expected / 8.0).abs() < 1e-3 * expected);
    }
}
