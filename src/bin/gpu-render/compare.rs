//! `--compare-gamma`: two renders of one scene placed side by side.

use anyhow::{Result, bail};
use gpu_render::film::LinearImage;

use crate::backend::Frame;

/// `left` and `right` (same size) side by side in one image twice as wide: the linear
/// images and the display images both.
pub fn side_by_side(left: &Frame, right: &Frame) -> Result<Frame> {
    let (w, h) = (left.image.width as usize, left.image.height as usize);
    for frame in [left, right] {
        let size = (frame.image.width, frame.image.height);
        if size != (left.image.width, left.image.height)
            || frame.image.pixels.len() != w * h
            || frame.display_rgba8.len() != w * h * 4
        {
            bail!("the two gamma renders differ in size; cannot place them side by side");
        }
    }
    let mut image = LinearImage::new(left.image.width * 2, left.image.height);
    image.pixels.clear();
    let mut display_rgba8 = Vec::with_capacity(w * h * 8);
    for y in 0..h {
        let row = y * w..(y + 1) * w;
        image
            .pixels
            .extend_from_slice(&left.image.pixels[row.clone()]);
        image.pixels.extend_from_slice(&right.image.pixels[row]);
        let bytes = y * w * 4..(y + 1) * w * 4;
        display_rgba8.extend_from_slice(&left.display_rgba8[bytes.clone()]);
        display_rgba8.extend_from_slice(&right.display_rgba8[bytes]);
    }
    Ok(Frame {
        image,
        display_rgba8,
        stats: crate::summary::add_stats(left.stats, right.stats),
        // --compare-gamma and --standard-error exclude each other.
        noise: None,
        aov: None,
        compile: left.compile.zip(right.compile).map(|(a, b)| a + b),
        hardware_traversal: left.hardware_traversal || right.hardware_traversal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpu_render::film::RenderStats;

    fn frame(value: f32, byte: u8) -> Frame {
        let mut image = LinearImage::new(2, 2);
        for p in &mut image.pixels {
            *p = [value, value, value, 1.0];
        }
        Frame {
            image,
            display_rgba8: vec![byte; 16],
            stats: RenderStats::default(),
            noise: None,
            aov: None,
            compile: None,
            hardware_traversal: false,
        }
    }

    #[test]
    fn left_then_right_on_every_row() {
        let joined = side_by_side(&frame(0.25, 10), &frame(0.75, 200)).expect("same size");
        assert_eq!((joined.image.width, joined.image.height), (4, 2));
        for y in 0..2 {
            assert_eq!(joined.image.pixel(0, y)[0], 0.25);
            assert_eq!(joined.image.pixel(1, y)[0], 0.25);
            assert_eq!(joined.image.pixel(2, y)[0], 0.75);
            assert_eq!(joined.image.pixel(3, y)[0], 0.75);
            let row = &joined.display_rgba8[y as usize * 16..(y as usize + 1) * 16];
            assert_eq!(&row[..8], &[10; 8]);
            assert_eq!(&row[8..], &[200; 8]);
        }
    }

    #[test]
    fn refuses_frames_of_different_sizes() {
        let mut small = frame(0.5, 1);
        small.display_rgba8.pop();
        assert!(side_by_side(&frame(0.5, 1), &small).is_err());
    }
}
