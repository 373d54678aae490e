//! The memory a scene file's load holds, counted before it is taken and refused above
//! [`LoadOptions::max_bytes`](super::LoadOptions::max_bytes).

use std::path::Path;

use super::LoadOptions;
use super::check::Item;
use crate::echo::{bytes, echo_path};
use crate::scene::{EncodedImage, Image, SceneError};

/// What the images loaded so far hold, against the cap.
#[derive(Debug, Clone, Copy)]
pub struct LoadBudget {
    max: Option<u64>,
    held: u64,
}

impl LoadBudget {
    /// Nothing held yet, capped at `max` bytes (none: no cap).
    pub fn new(max: Option<u64>) -> Self {
        Self { max, held: 0 }
    }

    /// Counts `image`, read but not decoded: refused (with the reason) when decoding it
    /// next to what is held already would go above the cap; else its decoded bytes
    /// stay counted.
    pub fn charge_image(&mut self, image: &EncodedImage) -> Result<(), String> {
        let peak = self.held.saturating_add(image.decoding_peak_bytes());
        if let Some(max) = self.max
            && peak > max
        {
            let (width, height) = image.dimensions();
            return Err(format!(
                "decoding this {width}x{height} image needs {} (with the {} of the images \
                 before it), more than the {} allowed (--max-memory); raise the cap if the \
                 machine has the memory",
                bytes(peak),
                bytes(self.held),
                bytes(max)
            ));
        }
        self.held = self.held.saturating_add(image.decoded_bytes());
        Ok(())
    }

    /// The bytes the cap leaves for the rest of the load (models), if there is a cap.
    pub fn left(&self) -> Option<u64> {
        self.max.map(|max| max.saturating_sub(self.held))
    }
}

/// Reads the image `file` that `item`'s `field` names (`path`: `file` in `base`),
/// opened beneath `base` in a sandbox, charges it to `budget` from its header and only
/// then decodes it. Errors name the field, the file as written and as resolved, and
/// the reason.
pub fn load_scene_image(
    item: &Item<'_>,
    field: &str,
    (file, path): (&str, &Path),
    base: &Path,
    options: &LoadOptions<'_>,
    budget: &mut LoadBudget,
) -> Result<Image, SceneError> {
    let what = || {
        format!(
            "{field} `{}` ({})",
            echo_path(Path::new(file)),
            echo_path(path)
        )
    };
    let encoded = if options.sandbox {
        // Opened beneath the folder: the caller's check and the open are one step.
        EncodedImage::read_confined(base, Path::new(file))
    } else {
        EncodedImage::read(path)
    }
    .map_err(|e| item.fail_image(what(), e))?;
    budget
        .charge_image(&encoded)
        .map_err(|reason| item.fail(format_args!("{}: {reason}", what())))?;
    encoded.decode().map_err(|e| item.fail_image(what(), e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(side: u32) -> EncodedImage {
        let mut bytes = Vec::new();
        image::RgbImage::new(side, side)
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .expect("encode");
        EncodedImage::from_bytes(std::path::Path::new("t.png"), bytes).expect("header")
    }

    #[test]
    fn images_are_refused_once_decoding_the_next_would_pass_the_cap() {
        let image = png(256);
        // 256² texels: 1 MiB held, 2.75 MiB (and the file) while decoding.
        assert_eq!(image.decoded_bytes(), 1 << 20);
        let mut budget = LoadBudget::new(Some(7 << 19));
        budget.charge_image(&image).expect("the first fits");
        assert_eq!(budget.left(), Some(5 << 19));
        let refused = budget
            .charge_image(&image)
            .expect_err("the second does not");
        assert!(
            refused.contains("256x256") && refused.contains("3.50 MiB allowed"),
            "{refused}"
        );
        assert_eq!(
            budget.left(),
            Some(5 << 19),
            "a refused image holds nothing"
        );
        let mut free = LoadBudget::new(None);
        for _ in 0..100 {
            free.charge_image(&image).expect("no cap");
        }
        assert_eq!(free.left(), None);
    }
}
