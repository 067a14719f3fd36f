//! A camera, pinhole or orthographic, and the per-pixel ray basis that the
//! CPU tracers and the GPU shaders share.

use glam::{DVec3, IVec3, Vec3};

/// The vertical fields of view octovox draws, in degrees: the CLI, scripts
/// and the window refuse others, and every projection uses this range.
pub const FOV_RANGE_DEG: std::ops::RangeInclusive<f32> = 1.0..=179.0;

/// `fov` clamped into [`FOV_RANGE_DEG`] (NaN becomes the narrowest), for
/// values that were not checked on the way in.
pub fn clamp_fov(fov: f32) -> f32 {
    if fov.is_nan() { *FOV_RANGE_DEG.start() } else { fov.clamp(*FOV_RANGE_DEG.start(), *FOV_RANGE_DEG.end()) }
}

/// How far from the origin a camera's eye and target may be, per axis:
/// 2^28, sixteen times the coordinate limit. Past it the ray basis loses
/// the precision of f32 on the GPU (1e39 is infinite there and drew sky).
pub const CAMERA_LIMIT: f64 = (1 << 28) as f64;

/// Why a camera given by the user is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error("camera {what} {at} is outside ±2^28 (±{CAMERA_LIMIT}) on some axis")]
    OutOfRange { what: &'static str, at: DVec3 },
    #[error("camera eye and target are the same point")]
    SamePoint,
    #[error("field of view {0} must be {lo}..={hi} degrees", lo = FOV_RANGE_DEG.start(), hi = FOV_RANGE_DEG.end())]
    Fov(f32),
    #[error("orthographic height {0} must be {lo}..={hi} voxels", lo = ORTHO_RANGE.start(), hi = ORTHO_RANGE.end())]
    Ortho(f32),
}

/// Checks a camera given by the user: eye and target finite, within
/// [`CAMERA_LIMIT`], and apart.
///
/// # Errors
/// Which of these fails, in words.
pub fn check_camera(eye: DVec3, target: DVec3) -> Result<(), CameraError> {
    for (what, v) in [("eye", eye), ("target", target)] {
        if !v.is_finite() || v.abs().max_element() > CAMERA_LIMIT {
            return Err(CameraError::OutOfRange { what, at: v });
        }
    }
    if eye == target {
        return Err(CameraError::SamePoint);
    }
    Ok(())
}

/// Checks a field of view given by the user.
pub fn check_fov(fov: f32) -> Result<f32, CameraError> {
    if FOV_RANGE_DEG.contains(&fov) { Ok(fov) } else { Err(CameraError::Fov(fov)) }
}

/// The world heights an orthographic view may show (voxels).
pub const ORTHO_RANGE: std::ops::RangeInclusive<f32> = 0.5..=65536.0;

/// How far behind the target the rays of an orthographic view start
/// (voxels), whatever the eye's distance: so two views from one direction
/// at different distances are the same picture, and what lies behind the
/// eye is seen as MagicaVoxel's and Goxel's orthographic views show it. At
/// 4096 the f32 ray origins keep 1/2048 of a voxel.
pub const ORTHO_DEPTH: f64 = 4096.0;

/// Checks an orthographic view height given by the user.
pub fn check_ortho(height: f32) -> Result<f32, CameraError> {
    if ORTHO_RANGE.contains(&height) { Ok(height) } else { Err(CameraError::Ortho(height)) }
}

/// Eye, target and projection, in world coordinates (y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    /// The vertical field of view of the perspective projection.
    pub fov_y_deg: f32,
    /// `Some(height)`: an orthographic projection showing `height` world
    /// voxels from the bottom of the image to the top, looking from the eye
    /// to the target; `None`: perspective.
    pub ortho: Option<f32>,
}

impl Default for Camera {
    fn default() -> Camera {
        Camera { eye: DVec3::new(40.0, 30.0, 50.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None }
    }
}

impl Camera {
    /// A camera looking at the box `min..=max` (voxel corners) from the
    /// front-right-top so that all of it is in view.
    pub fn framing(min: IVec3, max: IVec3, fov_y_deg: f32) -> Camera {
        let lo = min.as_dvec3();
        let hi = max.as_dvec3() + DVec3::ONE;
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1.0);
        let half_fov = f64::from(clamp_fov(fov_y_deg)).to_radians() * 0.5;
        // The bounding sphere just fills the view at radius / sin(fov / 2);
        // a little closer crops its empty rim. Never inside the sphere.
        let distance = (radius / half_fov.sin() * 0.85).max(radius * 1.1);
        let dir = DVec3::new(0.55, 0.45, 0.7).normalize();
        Camera { eye: center + dir * distance, target: center, fov_y_deg, ortho: None }
    }

    /// A camera looking at the box `min..=max` (voxel corners) from where
    /// [`Camera::framing`] looks, as close as it can be with every point of
    /// `points` (the corners of the voxels, or of the box) inside `FILL` of
    /// an image of `aspect` (width / height): the model fills the frame, as
    /// a final render wants (the bounding sphere [`Camera::framing`] fits
    /// left a model about 40 % of it).
    pub fn filling(min: IVec3, max: IVec3, points: &[DVec3], fov_y_deg: f32, aspect: f64) -> Camera {
        /// The part of the half-frame the farthest point may reach.
        const FILL: f64 = 0.9;
        let framed = Camera::framing(min, max, fov_y_deg);
        let (lo, hi) = (min.as_dvec3(), max.as_dvec3() + DVec3::ONE);
        let center = (lo + hi) * 0.5;
        let back = (framed.eye - framed.target).normalize();
        let (forward, right, up) = Camera { eye: center + back, target: center, ..framed }.axes();
        let tan_y = (f64::from(clamp_fov(fov_y_deg)).to_radians() * 0.5).tan();
        let tan_x = tan_y * aspect.max(1e-3);
        // Each point in the camera's axes, once: (along forward, right, up).
        let relative: Vec<(f64, f64, f64)> =
            points.iter().map(|p| *p - center).map(|c| (c.dot(forward), c.dot(right).abs(), c.dot(up).abs())).collect();
        let fits = |distance: f64| {
            relative.iter().all(|&(f, r, u)| {
                let depth = distance + f;
                depth > 0.0 && r <= FILL * depth * tan_x && u <= FILL * depth * tan_y
            })
        };
        // The framing distance holds the whole box: bisect down to the
        // nearest that still holds every point, never inside the box.
        let radius = (hi - lo).length() * 0.5;
        let (mut near, mut far) = (radius, (framed.eye - framed.target).length().max(radius * 4.0));
        for _ in 0..40 {
            let mid = 0.5 * (near + far);
            if fits(mid) {
                far = mid;
            } else {
                near = mid;
            }
        }
        Camera { eye: center + back * far, target: center, fov_y_deg, ortho: None }
    }

    /// This camera moved to show the whole box `min..=max` (voxel corners),
    /// as [`Camera::framing`] does, but keeping its viewing direction (and
    /// projection: an orthographic one gets the height that shows the box).
    pub fn reframed(&self, min: IVec3, max: IVec3) -> Camera {
        let framed = Camera::framing(min, max, self.fov_y_deg);
        let distance = (framed.eye - framed.target).length();
        let back = (self.eye - self.target).try_normalize().unwrap_or((framed.eye - framed.target) / distance);
        let ortho = self.ortho.map(|_| framed.view_height() as f32);
        Camera { eye: framed.target + back * distance, target: framed.target, fov_y_deg: self.fov_y_deg, ortho }
    }

    /// The world height the view shows at the target: the orthographic
    /// height, or what the field of view spans at the target's distance
    /// (what a switch between the two keeps).
    pub fn view_height(&self) -> f64 {
        match self.ortho {
            Some(height) => f64::from(height),
            None => {
                let half_fov = f64::from(clamp_fov(self.fov_y_deg)).to_radians() * 0.5;
                2.0 * (self.target - self.eye).length() * half_fov.tan()
            }
        }
    }

    /// The view's forward, right and up unit vectors. Up is world y, except
    /// looking straight down (or up), where it is −z (+z): a top view has x
    /// to the right and the front (+z) at the bottom, as the front view has
    /// x to the right.
    pub fn axes(&self) -> (DVec3, DVec3, DVec3) {
        let forward = (self.target - self.eye).try_normalize().unwrap_or(DVec3::NEG_Z);
        let world_up = if forward.y.abs() > 0.999 { DVec3::new(0.0, 0.0, forward.y.signum()) } else { DVec3::Y };
        let right = forward.cross(world_up).normalize();
        (forward, right, right.cross(forward))
    }

    /// Ray basis for a viewport, with the eye relative to `origin` (the tree's
    /// origin) so that far-away cameras keep f32 precision.
    pub fn basis(&self, width: u32, height: u32, origin: IVec3) -> RayBasis {
        let (forward, right, up) = self.axes();
        let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
        // Perspective: the image plane one unit ahead, tan(fov / 2) high.
        // Orthographic: rays along `forward` from a plane `height` high.
        let (eye, half) = match self.ortho {
            Some(height) => (self.target - forward * ORTHO_DEPTH, f64::from(height) * 0.5),
            None => (self.eye, (f64::from(clamp_fov(self.fov_y_deg)).to_radians() * 0.5).tan()),
        };
        RayBasis {
            eye: (eye - origin.as_dvec3()).as_vec3(),
            forward: forward.as_vec3(),
            right: (right * half * aspect).as_vec3(),
            up: (up * half).as_vec3(),
            width: width.max(1),
            height: height.max(1),
            ortho: self.ortho.is_some(),
        }
    }
}

/// Everything needed to make the ray of any pixel, in tree-local coordinates.
/// The WGSL twin is the camera part of `FrameUniforms` in `shaders/common.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayBasis {
    /// The eye; orthographic: the centre of the plane the rays start from.
    pub eye: Vec3,
    pub forward: Vec3,
    /// Right vector scaled by tan(fov/2) · aspect (orthographic: by half
    /// the view's width).
    pub right: Vec3,
    /// Up vector scaled by tan(fov/2) (orthographic: by half its height).
    pub up: Vec3,
    pub width: u32,
    pub height: u32,
    /// Rays start across the image plane, all along `forward`.
    pub ortho: bool,
}

impl RayBasis {
    /// Origin and (unnormalised) direction through the centre of pixel (x, y),
    /// with (0, 0) the top-left pixel. Same arithmetic as `pixel_ray` in WGSL.
    pub fn ray(&self, x: u32, y: u32) -> (Vec3, Vec3) {
        self.ray_through(x as f32 + 0.5, y as f32 + 0.5)
    }

    /// Where the (tree-local) point `p` lands on the image, in pixels; `None`
    /// behind the eye. The inverse of [`RayBasis::ray_through`].
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        if depth <= 0.0 {
            return None;
        }
        let scale = if self.ortho { 1.0 } else { depth };
        let ndc_x = d.dot(self.right) / self.right.length_squared() / scale;
        let ndc_y = d.dot(self.up) / self.up.length_squared() / scale;
        Some(((ndc_x + 1.0) * 0.5 * self.width as f32, (1.0 - ndc_y) * 0.5 * self.height as f32))
    }

    /// Origin and direction through a point of the image given in pixels
    /// (pixel (x, y) spans x..x + 1, y..y + 1).
    pub fn ray_through(&self, px: f32, py: f32) -> (Vec3, Vec3) {
        let ndc_x = 2.0 * px / self.width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * py / self.height as f32;
        let offset = self.right * ndc_x + self.up * ndc_y;
        if self.ortho { (self.eye + offset, self.forward) } else { (self.eye, self.forward + offset) }
    }
}
