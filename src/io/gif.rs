//! Looping GIFs of rendered animations (`render --frames … -o NAME.gif`).

use std::path::Path;

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};

use crate::io::atomic::WriteOptions;
use crate::io::png::{PngError, save_encoded};

/// The fastest a GIF plays: two hundredths of a second a frame.
pub const MAX_GIF_FPS: u32 = 50;

/// Writes `frames` as a GIF that loops for ever, `fps` frames a second
/// (at most [`MAX_GIF_FPS`]: a GIF counts delays in hundredths of a second
/// and browsers play shorter ones slowly), atomically like every file
/// octovox writes. Each frame is quantised to its own 256 colours (the
/// `gif` crate's NeuQuant).
pub fn save_gif(frames: &[RgbaImage], fps: u32, path: &Path, options: WriteOptions) -> Result<(), PngError> {
    save_encoded(path, options, |out| {
        let mut encoder = GifEncoder::new_with_speed(out, 10);
        encoder.set_repeat(Repeat::Infinite)?;
        let delay = Delay::from_numer_denom_ms(1000, fps.clamp(1, MAX_GIF_FPS));
        for image in frames {
            encoder.encode_frame(Frame::from_parts(image.clone(), 0, 0, delay))?;
        }
        Ok(())
    })
}
