//! Per-pixel comparison of two linear float images with a stated tolerance and a stated
//! fraction of allowed outliers. On failure both images and a difference image are
//! written under `target/test-output/`.

use std::path::PathBuf;

use gpu_render::film::LinearImage;

/// How far two images may differ.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    /// A channel passes when `|actual - expected| <= absolute + relative * |expected|`.
    pub absolute: f32,
    /// See `absolute`.
    pub relative: f32,
    /// Largest fraction of pixels allowed to fail (silhouettes, shadow edges: a sample
    /// that grazes an edge may land on either side in f32 and f64).
    pub outlier_fraction: f64,
}

impl Tolerance {
    /// Whether one channel passes; a NaN on either side never does.
    pub fn channel_passes(&self, expected: f32, actual: f32) -> bool {
        let difference = (actual - expected).abs();
        !difference.is_nan() && difference <= self.absolute + self.relative * expected.abs()
    }
}

/// What a comparison measured.
#[derive(Debug, Clone, Copy)]
pub struct Comparison {
    /// Pixels with at least one channel outside the tolerance.
    pub outliers: usize,
    /// Pixels compared.
    pub pixels: usize,
    /// Largest absolute channel difference.
    pub max_abs_error: f32,
    /// Root-mean-square channel difference.
    pub rmse: f64,
}

/// The directory failing comparisons write into.
pub fn output_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| super::repo_root().to_path_buf().join("target"));
    target.join("test-output")
}

/// The largest difference of one colour channel between two images of the same size
/// (alpha left out): 0 when they are bit-identical in colour.
pub fn max_channel_difference(a: &LinearImage, b: &LinearImage) -> f32 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0f32, f32::max)
}

/// Measures the difference between `actual` and `expected`.
pub fn measure(expected: &LinearImage, actual: &LinearImage, tolerance: Tolerance) -> Comparison {
    assert_eq!(
        (expected.width, expected.height),
        (actual.width, actual.height),
        "image sizes differ"
    );
    let mut outliers = 0;
    let mut max_abs_error = 0.0f32;
    let mut squared_sum = 0.0f64;
    for (e, a) in expected.pixels.iter().zip(&actual.pixels) {
        let mut outlier = false;
        for c in 0..3 {
            let difference = (a[c] - e[c]).abs();
            outlier |= !tolerance.channel_passes(e[c], a[c]);
            max_abs_error = max_abs_error.max(if difference.is_nan() {
                f32::INFINITY
            } else {
                difference
            });
            squared_sum += f64::from(difference) * f64::from(difference);
        }
        outliers += usize::from(outlier);
    }
    let pixels = expected.pixels.len();
    Comparison {
        outliers,
        pixels,
        max_abs_error,
        rmse: (squared_sum / (3 * pixels.max(1)) as f64).sqrt(),
    }
}

/// Compares `actual` with `expected` and panics, after writing `NAME-expected.png`,
/// `NAME-actual.png`, `NAME-diff.png` (outliers red, others grey by error) and both
/// linear EXRs, when more than the allowed fraction of pixels is out of tolerance.
pub fn assert_images_match(
    name: &str,
    expected: &LinearImage,
    actual: &LinearImage,
    tolerance: Tolerance,
) -> Comparison {
    let comparison = measure(expected, actual, tolerance);
    let fraction = comparison.outliers as f64 / comparison.pixels.max(1) as f64;
    if fraction > tolerance.outlier_fraction {
        let dir = output_dir();
        let written = write_failure_images(&dir, name, expected, actual, tolerance);
        panic!(
            "{name}: {} of {} pixels ({:.3}%) differ beyond |Δ| <= {} + {}·|expected| \
             (allowed {:.3}%); max |Δ| = {}, RMSE = {:.3e}. Images: {}",
            comparison.outliers,
            comparison.pixels,
            100.0 * fraction,
            tolerance.absolute,
            tolerance.relative,
            100.0 * tolerance.outlier_fraction,
            comparison.max_abs_error,
            comparison.rmse,
            written
        );
    }
    comparison
}

fn write_failure_images(
    dir: &std::path::Path,
    name: &str,
    expected: &LinearImage,
    actual: &LinearImage,
    tolerance: Tolerance,
) -> String {
    if let Err(e) = std::fs::create_dir_all(dir) {
        return format!("(could not create {}: {e})", dir.display());
    }
    let (w, h) = (expected.width, expected.height);
    let to_png = |image: &LinearImage| {
        image::RgbaImage::from_raw(w, h, image.to_display_rgba8(true)).expect("size")
    };
    let to_exr = |image: &LinearImage| {
        let data: Vec<f32> = image.pixels.iter().flatten().copied().collect();
        image::Rgba32FImage::from_raw(w, h, data).expect("size")
    };
    let mut diff = image::RgbaImage::new(w, h);
    for (i, (e, a)) in expected.pixels.iter().zip(&actual.pixels).enumerate() {
        let mut worst = 0.0f32;
        let mut outlier = false;
        for c in 0..3 {
            let difference = (a[c] - e[c]).abs();
            worst = worst.max(if difference.is_nan() { 1.0 } else { difference });
            outlier |= !tolerance.channel_passes(e[c], a[c]);
        }
        let grey = (worst.sqrt().min(1.0) * 255.0) as u8;
        let pixel = if outlier {
            [255, 0, 0, 255]
        } else {
            [grey, grey, grey, 255]
        };
        diff.put_pixel(i as u32 % w, i as u32 / w, image::Rgba(pixel));
    }
    let base = dir.join(name).display().to_string();
    let path = |suffix: &str| format!("{base}-{suffix}");
    let outcomes = [
        ("expected.png", to_png(expected).save(path("expected.png"))),
        ("actual.png", to_png(actual).save(path("actual.png"))),
        ("diff.png", diff.save(path("diff.png"))),
        ("expected.exr", to_exr(expected).save(path("expected.exr"))),
        ("actual.exr", to_exr(actual).save(path("actual.exr"))),
    ];
    outcomes
        .iter()
        .map(|(suffix, result)| match result {
            Ok(()) => path(suffix),
            Err(e) => format!("{} (not written: {e})", path(suffix)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}
