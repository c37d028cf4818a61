//! The camera: perspective (a pinhole, or a thin lens with depth of field) or orthographic,
//! generating rays with differentials.
//!
//! Camera space is glTF's: the camera looks down its local -z, +x is right on the image, +y up.
//! Image pixel (0, 0) is the top-left one. Every ray is affine in the film position f (pixels):
//! its origin is `corner_origin + origin_step . f` and its direction `corner_direction +
//! direction_step . f`. A perspective camera's origins are all its position; an orthographic
//! one's directions are all its view axis. That makes the differentials exact: the ray one
//! pixel right starts `origin_step[0]` further and points `direction_step[0]` further.
//!
//! Rays start at the near clip plane, `near_clip` in front of the camera along its view axis
//! (Mitsuba's convention; 0 by default). A thin lens (pbrt-v4 and Mitsuba's `thinlens`) starts
//! each ray at a uniform point of its aperture disc, aimed at the point that the pinhole ray meets
//! on the plane of focus.

use crate::error::{Error, Result};
use crate::geometry::{Ray, RayDifferential};
use crate::sampling::warp;
use glam::{Mat4, Vec2, Vec3};

/// Which image axis the field of view (or an orthographic camera's extent) spans.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FovAxis {
    /// Horizontal field of view (Mitsuba's default).
    X,
    /// Vertical field of view (glTF's `yfov`, tessera's default).
    Y,
}

/// How the camera maps the film to rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Rays from one point: `fov` degrees across the image along `axis`.
    Perspective {
        /// Field of view in degrees, in (0, 180).
        fov: f32,
        /// The image axis it spans.
        axis: FovAxis,
    },
    /// Parallel rays along the view axis from a film `extent` world units across along `axis`.
    Orthographic {
        /// Size of the image in camera-space units, > 0.
        extent: f32,
        /// The image axis it spans.
        axis: FovAxis,
    },
}

/// A thin lens in front of a perspective camera: depth of field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Radius of the aperture disc, camera-space units.
    pub aperture_radius: f32,
    /// Distance of the plane in focus along the view axis.
    pub focus_distance: f32,
}

/// What a camera is, apart from where it is and its image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraModel {
    /// The projection.
    pub projection: Projection,
    /// A thin lens (perspective only); None for a pinhole.
    pub lens: Option<ThinLens>,
    /// Distance along the view axis where rays start (>= 0).
    pub near_clip: f32,
}

impl CameraModel {
    /// A pinhole perspective camera with `fov` degrees along `axis`, no near clip.
    pub fn pinhole(fov: f32, axis: FovAxis) -> Self {
        CameraModel { projection: Projection::Perspective { fov, axis }, lens: None, near_clip: 0.0 }
    }

    /// Check the parameters: an error names the one that is wrong.
    fn check(&self) -> Result<()> {
        match self.projection {
            Projection::Perspective { fov, .. } if !(fov > 0.0 && fov < 180.0) => {
                return Err(Error::param("camera.fov", format!("{fov} degrees is outside (0, 180)")));
            }
            Projection::Orthographic { extent, .. } if !(extent > 0.0 && extent.is_finite()) => {
                return Err(Error::param("camera.extent", format!("{extent} must be a finite number > 0")));
            }
            Projection::Orthographic { .. } if self.lens.is_some() => {
                return Err(Error::param("camera.aperture_radius", "a thin lens needs a perspective camera"));
            }
            _ => {}
        }
        if let Some(lens) = self.lens {
            if !(lens.aperture_radius > 0.0 && lens.aperture_radius.is_finite()) {
                let msg = format!("{} must be a finite number > 0", lens.aperture_radius);
                return Err(Error::param("camera.aperture_radius", msg));
            }
            if !(lens.focus_distance > 0.0 && lens.focus_distance.is_finite()) {
                let msg = format!("{} must be a finite number > 0", lens.focus_distance);
                return Err(Error::param("camera.focus_distance", msg));
            }
        }
        if !(self.near_clip >= 0.0 && self.near_clip.is_finite()) {
            return Err(Error::param("camera.near_clip", format!("{} must be a finite number >= 0", self.near_clip)));
        }
        Ok(())
    }
}

/// A camera placed in the world, with its image size.
#[derive(Clone, Debug)]
pub struct Camera {
    to_world: Mat4,
    position: Vec3,
    width: u32,
    height: u32,
    model: CameraModel,
    /// Half the film's size at unit distance (perspective: tan of half the field of view) or
    /// in camera space (orthographic), along x and y.
    half_size: Vec2,
    /// The ray through the film's top-left corner, and its change for one pixel right and
    /// one pixel down (module documentation).
    corner_origin: Vec3,
    origin_step: [Vec3; 2],
    corner_direction: Vec3,
    direction_step: [Vec3; 2],
    /// Scale of the ray differentials: max(1/8, 1/sqrt(spp)) (pbrt-v4), since the footprint of a
    /// pixel is covered by spp samples rather than one.
    differential_scale: f32,
    /// Smallest change of the unit ray direction for a one-pixel step, over the image (pbrt-v4
    /// `CameraBase::FindMinimumDifferentials`), used by [`Self::approximate_dp_dxy`].
    min_direction_step: Vec2,
}

impl Camera {
    /// A camera with the given camera-to-world transform and model, an image of `width` x
    /// `height` pixels and `spp` samples per pixel.
    pub fn new(to_world: Mat4, model: CameraModel, width: u32, height: u32, spp: u32) -> Result<Self> {
        model.check()?;
        if !to_world.is_finite() || to_world.determinant().abs() < 1e-12 {
            return Err(Error::param("camera.transform", "the camera transform is singular or not finite"));
        }
        let aspect = width as f32 / height as f32;
        let (half, axis) = match model.projection {
            Projection::Perspective { fov, axis } => ((fov.to_radians() * 0.5).tan(), axis),
            Projection::Orthographic { extent, axis } => (0.5 * extent, axis),
        };
        let half_size = match axis {
            FovAxis::X => Vec2::new(half, half / aspect),
            FovAxis::Y => Vec2::new(half * aspect, half),
        };
        let position = to_world.transform_point3(Vec3::ZERO);
        let steps = [
            to_world.transform_vector3(Vec3::new(2.0 * half_size.x / width as f32, 0.0, 0.0)),
            to_world.transform_vector3(Vec3::new(0.0, -2.0 * half_size.y / height as f32, 0.0)),
        ];
        let corner = to_world.transform_vector3(Vec3::new(-half_size.x, half_size.y, 0.0));
        let forward = to_world.transform_vector3(Vec3::NEG_Z);
        let (corner_origin, origin_step, corner_direction, direction_step) = match model.projection {
            Projection::Perspective { .. } => {
                let corner_direction = to_world.transform_vector3(Vec3::new(-half_size.x, half_size.y, -1.0));
                (position, [Vec3::ZERO; 2], corner_direction, steps)
            }
            Projection::Orthographic { .. } => (position + corner, steps, forward, [Vec3::ZERO; 2]),
        };
        let mut camera = Camera {
            to_world,
            position,
            width,
            height,
            model,
            half_size,
            corner_origin,
            origin_step,
            corner_direction,
            direction_step,
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

    /// The projection, lens and near clip.
    pub fn model(&self) -> &CameraModel {
        &self.model
    }

    /// Image size in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Whether this is a pinhole perspective camera with no near clip, the one camera that
    /// [`Self::film_directions`] and [`Self::clip_from_world`] describe (the GPU port's); the
    /// error names what this camera has instead.
    pub fn require_pinhole(&self, user: &str) -> Result<()> {
        let m = &self.model;
        let other = match m.projection {
            Projection::Orthographic { .. } => Some("an orthographic projection"),
            Projection::Perspective { .. } if m.lens.is_some() => Some("a thin lens"),
            Projection::Perspective { .. } if m.near_clip > 0.0 => Some("a near clip"),
            Projection::Perspective { .. } => None,
        };
        match other {
            Some(what) => Err(Error::param("camera", format!("{user} needs a pinhole perspective camera, not {what}"))),
            None => Ok(()),
        }
    }

    /// The same view at another image size, with one sample per pixel (ray differentials of
    /// one pixel).
    pub fn with_resolution(&self, width: u32, height: u32) -> Result<Self> {
        Self::new(self.to_world, self.model, width, height, 1)
    }

    /// The world directions (not normalised) through the film's top-left corner and, added per
    /// pixel, one pixel right and one pixel down: the ray through film point f (in pixels)
    /// points along `corner + steps[0] f.x + steps[1] f.y` (a pinhole camera's rays; see
    /// [`Self::require_pinhole`]).
    pub fn film_directions(&self) -> (Vec3, [Vec3; 2]) {
        (self.corner_direction, self.direction_step)
    }

    /// The projection of a rasteriser that sees what a pinhole camera's [`Self::generate_ray`]
    /// sees: world to clip space, with reversed infinite depth (points at distance `near` in
    /// front of the camera get depth 1, infinitely far ones 0). NDC x runs from -1 on the
    /// image's left edge to 1 on its right, y from 1 at the top to -1 at the bottom, so that the
    /// pixel centre (x + 1/2, y + 1/2) of a WebGPU or Vulkan framebuffer is film point
    /// (x + 1/2, y + 1/2).
    pub fn clip_from_world(&self, near: f32) -> Mat4 {
        let projection = Mat4::from_cols(
            glam::Vec4::new(1.0 / self.half_size.x, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 1.0 / self.half_size.y, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
            glam::Vec4::new(0.0, 0.0, near, 0.0),
        );
        projection * self.to_world.inverse()
    }

    /// Whether [`Self::generate_ray`] uses its lens sample.
    pub fn needs_lens_sample(&self) -> bool {
        self.model.lens.is_some()
    }

    /// The ray through the film point `film` (in pixels), with differentials to the points one
    /// pixel right and one pixel down, scaled by max(1/8, 1/sqrt(spp)); `lens` in [0, 1)^2
    /// picks the point on a thin lens' aperture (unused by other cameras). Inlined: returned
    /// through memory, its fields were read back wider than they were written, a stall a ray.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> (Ray, RayDifferential) {
        let mut o = self.corner_origin + self.origin_step[0] * film.x + self.origin_step[1] * film.y;
        let mut d = self.corner_direction + self.direction_step[0] * film.x + self.direction_step[1] * film.y;
        let [mut dx_d, mut dy_d] = self.direction_step;
        // Camera-space depth gained per unit of the ray parameter along d.
        let mut depth_rate = 1.0;
        if let Some(thin) = self.model.lens {
            // Aim from the aperture point at where the pinhole ray meets the plane in focus.
            let disc = warp::square_to_uniform_disk_concentric(lens) * thin.aperture_radius;
            let aperture = self.to_world.transform_point3(disc.extend(0.0));
            let focus = o + d * thin.focus_distance;
            d = focus - aperture;
            o = aperture;
            (dx_d, dy_d) = (dx_d * thin.focus_distance, dy_d * thin.focus_distance);
            depth_rate = thin.focus_distance;
        }
        let [mut dx_o, mut dy_o] = self.origin_step;
        if self.model.near_clip > 0.0 {
            let t = self.model.near_clip / depth_rate;
            o += d * t;
            (dx_o, dy_o) = (dx_o + dx_d * t, dy_o + dy_d * t);
        }
        let diff = RayDifferential { d, dx_o, dx_d, dy_o, dy_d };
        (Ray::new(o, d.normalize()), diff.scaled(self.differential_scale))
    }

    fn find_min_direction_step(&self) -> Vec2 {
        let direction = |f: Vec2| self.corner_direction + self.direction_step[0] * f.x + self.direction_step[1] * f.y;
        let mut min = Vec2::splat(f32::INFINITY);
        let n = 32;
        for i in 0..=n {
            for j in 0..=n {
                let film = Vec2::new(i as f32 / n as f32 * self.width as f32, j as f32 / n as f32 * self.height as f32);
                let d = direction(film).normalize();
                let sx = (direction(film + Vec2::X).normalize() - d).length();
                let sy = (direction(film + Vec2::Y).normalize() - d).length();
                min = min.min(Vec2::new(sx, sy));
            }
        }
        min
    }

    /// Approximate footprint on the tangent plane (point `p`, normal `n`) of a one-pixel step,
    /// for hits after the first bounce, where no ray differential is tracked: as if the camera
    /// looked straight at `p` with its smallest per-pixel direction change (pbrt-v4
    /// `CameraBase::Approximate_dp_dxy`; an orthographic camera's steps are its origins', the
    /// same everywhere). Returns zero vectors at grazing angles.
    pub fn approximate_dp_dxy(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let (origin, diff) = if let Projection::Orthographic { .. } = self.model.projection {
            let d = self.corner_direction;
            let [dx_o, dy_o] = self.origin_step;
            (p - d, RayDifferential { d, dx_o, dx_d: Vec3::ZERO, dy_o, dy_d: Vec3::ZERO })
        } else {
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
            (self.position, diff)
        };
        match diff.scaled(self.differential_scale).steps_on_plane(origin, p, n) {
            Some(steps) => steps,
            None => (Vec3::ZERO, Vec3::ZERO),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        let m = Camera::look_at(Vec3::new(0.0, 2.0, 4.6), Vec3::new(0.0, -0.3, 0.0), Vec3::Y).unwrap();
        Camera::new(m, CameraModel::pinhole(40.0, FovAxis::X), 64, 32, 1).unwrap()
    }

    #[test]
    fn camera_centre_ray_hits_target_and_x_is_right() {
        let c = camera();
        let (ray, _) = c.generate_ray(Vec2::new(32.0, 16.0), Vec2::ZERO);
        let to_target = (Vec3::new(0.0, -0.3, 0.0) - ray.o).normalize();
        assert!(ray.d.distance(to_target) < 1e-6);
        // Pixels to the right look towards world +x (Mitsuba's scene: the seam shows at x > 0).
        let (right, _) = c.generate_ray(Vec2::new(63.0, 16.0), Vec2::ZERO);
        assert!(right.d.x > 0.0);
        // Pixels at the top look up.
        let (top, _) = c.generate_ray(Vec2::new(32.0, 0.0), Vec2::ZERO);
        assert!(top.d.y > ray.d.y);
    }

    #[test]
    fn camera_fov_spans_the_image_width() {
        let c = camera();
        let (l, _) = c.generate_ray(Vec2::new(0.0, 16.0), Vec2::ZERO);
        let (r, _) = c.generate_ray(Vec2::new(64.0, 16.0), Vec2::ZERO);
        assert!((l.d.angle_between(r.d).to_degrees() - 40.0).abs() < 1e-3);
    }

    #[test]
    fn the_rasteriser_projection_sees_what_the_rays_see() {
        let c = camera();
        let clip_from_world = c.clip_from_world(0.01);
        for film in [Vec2::new(0.5, 0.5), Vec2::new(63.5, 2.5), Vec2::new(20.25, 31.5)] {
            let (ray, _) = c.generate_ray(film, Vec2::ZERO);
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
    fn orthographic_rays_are_parallel_and_span_the_extent() {
        let m = Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::new(1.0, 2.0, 0.0), Vec3::Y).unwrap();
        let model = CameraModel {
            projection: Projection::Orthographic { extent: 4.0, axis: FovAxis::Y },
            lens: None,
            near_clip: 0.5,
        };
        let c = Camera::new(m, model, 200, 100, 1).unwrap();
        let (centre, diff) = c.generate_ray(Vec2::new(100.0, 50.0), Vec2::ZERO);
        // Rays start on the near plane, looking down -z; the image is 8 x 4 units.
        assert!(centre.o.distance(Vec3::new(1.0, 2.0, 4.5)) < 1e-5 && centre.d.distance(Vec3::NEG_Z) < 1e-6);
        let (corner, _) = c.generate_ray(Vec2::ZERO, Vec2::ZERO);
        assert!(corner.o.distance(Vec3::new(-3.0, 4.0, 4.5)) < 1e-5 && corner.d == centre.d, "{}", corner.o);
        // The neighbouring pixel's ray starts one pixel (0.04 units) to the right.
        assert!(diff.dx_o.distance(Vec3::new(0.04, 0.0, 0.0)) < 1e-6 && diff.dx_d == Vec3::ZERO);
        // Its approximate footprint on a facing plane is that step, anywhere.
        let (dpdx, dpdy) = c.approximate_dp_dxy(Vec3::new(7.0, -3.0, -20.0), Vec3::Z);
        assert!(dpdx.distance(Vec3::new(0.04, 0.0, 0.0)) < 1e-6 && dpdy.distance(Vec3::new(0.0, -0.04, 0.0)) < 1e-6);
    }

    #[test]
    fn thin_lens_rays_meet_on_the_plane_in_focus() {
        let m = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y).unwrap();
        let lens = Some(ThinLens { aperture_radius: 0.2, focus_distance: 3.0 });
        let model = CameraModel { lens, near_clip: 0.1, ..CameraModel::pinhole(40.0, FovAxis::X) };
        let c = Camera::new(m, model, 64, 32, 1).unwrap();
        let pinhole = Camera::new(m, CameraModel::pinhole(40.0, FovAxis::X), 64, 32, 1).unwrap();
        for film in [Vec2::new(32.0, 16.0), Vec2::new(3.5, 30.25)] {
            let (through_pinhole, _) = pinhole.generate_ray(film, Vec2::ZERO);
            let in_focus = through_pinhole.at(3.0 / -through_pinhole.d.z);
            for lens in [Vec2::new(0.1, 0.9), Vec2::new(0.8, 0.3), Vec2::new(0.5, 0.5)] {
                let (ray, diff) = c.generate_ray(film, lens);
                // Starts 0.1 in front of the lens plane, within the aperture, aimed at the focus.
                assert!((ray.o.z - 2.9).abs() < 1e-5 && ray.o.truncate().length() < 0.2 + 1e-3);
                let t = (ray.o.z - 0.0) / -ray.d.z;
                assert!(ray.at(t).distance(in_focus) < 1e-4, "{film} {lens}: {}", ray.at(t));
                // The differentials are the pinhole's, scaled to the focus distance.
                let (_, pinhole_diff) = pinhole.generate_ray(film, Vec2::ZERO);
                assert!(diff.dx_d.distance(pinhole_diff.dx_d * 3.0) < 1e-6);
            }
        }
        assert!(c.require_pinhole("test").is_err() && pinhole.require_pinhole("test").is_ok());
    }

    #[test]
    fn camera_rejects_degenerate_views() {
        assert!(Camera::look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y).is_err());
        assert!(Camera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y).is_err());
        assert!(Camera::new(Mat4::IDENTITY, CameraModel::pinhole(180.0, FovAxis::Y), 4, 4, 1).is_err());
        let ortho = |extent| CameraModel {
            projection: Projection::Orthographic { extent, axis: FovAxis::Y },
            ..CameraModel::pinhole(1.0, FovAxis::Y)
        };
        assert!(Camera::new(Mat4::IDENTITY, ortho(0.0), 4, 4, 1).is_err());
        let lens = Some(ThinLens { aperture_radius: 0.1, focus_distance: 1.0 });
        assert!(Camera::new(Mat4::IDENTITY, CameraModel { lens, ..ortho(1.0) }, 4, 4, 1).is_err(), "ortho lens");
        let no_focus = Some(ThinLens { aperture_radius: 0.1, focus_distance: f32::NAN });
        assert!(Camera::new(Mat4::IDENTITY, CameraModel { lens: no_focus, ..ortho(1.0) }, 4, 4, 1).is_err());
        let near = CameraModel { near_clip: -1.0, ..CameraModel::pinhole(40.0, FovAxis::Y) };
        assert!(Camera::new(Mat4::IDENTITY, near, 4, 4, 1).is_err());
    }

    #[test]
    fn camera_approximate_footprint_uses_the_smallest_pixel_step() {
        // Looking straight at a plane 10 units away, the approximation spans 10 times the
        // image's smallest per-pixel direction change (at the corners: pbrt-v4's choice, which
        // errs towards sharper lookups), and never more than the exact centre footprint.
        let c = Camera::new(Mat4::IDENTITY, CameraModel::pinhole(60.0, FovAxis::Y), 100, 100, 1).unwrap();
        let (ray, diff) = c.generate_ray(Vec2::new(50.0, 50.0), Vec2::ZERO);
        let p = ray.at(10.0 / -ray.d.z);
        let (dx_o, dx_d) = (ray.o + diff.dx_o, diff.d + diff.dx_d);
        let px = dx_o + dx_d * ((dx_o.z - p.z) / -dx_d.z);
        let (dpdx, dpdy) = c.approximate_dp_dxy(p, Vec3::Z);
        let expected = 10.0 * c.min_direction_step.x;
        assert!((dpdx.length() - expected).abs() < 1e-3 * expected, "{} vs {expected}", dpdx.length());
        assert!(dpdx.length() <= (px - p).length());
        assert!(dpdx.dot(dpdy).abs() < 1e-6 * expected * expected, "x and y steps are orthogonal");
        // With 64 spp the footprint shrinks by 1/sqrt(64).
        let c64 = Camera::new(Mat4::IDENTITY, CameraModel::pinhole(60.0, FovAxis::Y), 100, 100, 64).unwrap();
        assert!((c64.approximate_dp_dxy(p, Vec3::Z).0.length() - expected / 8.0).abs() < 1e-3 * expected);
    }
}
