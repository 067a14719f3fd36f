//! Intel Open Image Denoise (OIDN) for final renders: its "RT" filter, a
//! neural network, over the accumulation's light (the mean divided by the
//! mean albedo of the first hits, as the à-trous filter takes it), guided
//! by the centre ray's face normal, the albedo multiplied back after: given
//! the colour and the albedo instead, it blurred voxel-sharp colour edges
//! (a one-voxel checker lost a sixth of its contrast). On the CPU, after
//! the samples are read back; the window keeps the à-trous filter
//! (`crate::trace::denoise`). Built only with the cargo feature `oidn`
//! (docs/rendering.md says how to get the library); without it,
//! [`denoise`] says so.

use glam::Vec3;
use image::RgbaImage;

use super::denoise::{Guide, Sums};

/// This build can denoise with OIDN.
pub const AVAILABLE: bool = cfg!(feature = "oidn");

#[derive(Debug, thiserror::Error)]
pub enum OidnError {
    #[error(
        "this octovox was built without Intel Open Image Denoise: build it with `--features oidn` \
         and OIDN_DIR set to the library's folder (docs/rendering.md), or denoise with --denoise"
    )]
    NotBuilt,
    #[error("Open Image Denoise: {0}")]
    Library(String),
    #[error("{pixels} pixels of samples for a {width}x{height} image")]
    Size { pixels: usize, width: u32, height: u32 },
}

/// The denoised image, displayed as the path tracer's is.
///
/// # Errors
/// [`OidnError::NotBuilt`] in a build without the feature; a size that
/// does not match; anything the library reports.
pub fn denoised_image(sums: &[Sums], guides: &[Guide], width: u32, height: u32) -> Result<RgbaImage, OidnError> {
    Ok(super::path::to_image(&denoise(sums, guides, width, height)?, width, height))
}

/// The denoised mean radiance of every pixel, row-major.
///
/// # Errors
/// As [`denoised_image`].
pub fn denoise(sums: &[Sums], guides: &[Guide], width: u32, height: u32) -> Result<Vec<Vec3>, OidnError> {
    let pixels = width as usize * height as usize;
    if sums.len() != pixels || guides.len() != pixels {
        return Err(OidnError::Size { pixels: sums.len().min(guides.len()), width, height });
    }
    let out = library::filter(sums, guides, width as usize, height as usize)?;
    Ok(out.chunks_exact(3).zip(sums).map(|(light, s)| Vec3::from_slice(light) * s.albedo()).collect())
}

#[cfg(feature = "oidn")]
mod library {
    use glam::Vec3;

    use super::OidnError;
    use crate::trace::denoise::{Guide, Sums};

    /// The three images OIDN reads, three floats a pixel: the light
    /// ([`Sums::light`]), white for the albedo (OIDN takes a normal only
    /// beside an albedo; the real one, beside the light, left the noise in)
    /// and the centre ray's face normal (zero where the guide has none: sky,
    /// lamps, glass, metal).
    struct Inputs {
        color: Vec<f32>,
        albedo: Vec<f32>,
        normal: Vec<f32>,
    }

    fn inputs(sums: &[Sums], guides: &[Guide]) -> Inputs {
        let color = sums.iter().flat_map(|s| s.light().to_array()).collect();
        let albedo = vec![1.0; 3 * sums.len()];
        let normal = guides
            .iter()
            .flat_map(|g| {
                let n = if g.is_filtered() { g.normal() } else { Vec3::ZERO };
                n.to_array()
            })
            .collect();
        Inputs { color, albedo, normal }
    }

    pub fn filter(sums: &[Sums], guides: &[Guide], width: usize, height: usize) -> Result<Vec<f32>, OidnError> {
        let inputs = inputs(sums, guides);
        let library = |e: oidn::Error| OidnError::Library(e.to_string());
        let device = oidn::Device::cpu().map_err(library)?;
        let albedo = device.create_buffer(&inputs.albedo).map_err(library)?;
        let normal = device.create_buffer(&inputs.normal).map_err(library)?;
        let mut output = vec![0.0; inputs.color.len()];
        oidn::RayTracing::try_new(&device)
            .map_err(library)?
            .hdr(true)
            .image_dimensions(width, height)
            .albedo_normal_buffer(albedo, normal)
            .map_err(library)?
            .filter(&inputs.color, &mut output)
            .map_err(library)?;
        Ok(output)
    }
}

#[cfg(not(feature = "oidn"))]
mod library {
    use super::OidnError;
    use crate::trace::denoise::{Guide, Sums};

    pub fn filter(_: &[Sums], _: &[Guide], _: usize, _: usize) -> Result<Vec<f32>, OidnError> {
        Err(OidnError::NotBuilt)
    }
}
