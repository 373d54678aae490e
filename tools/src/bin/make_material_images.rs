//! Writes the images the shipped scenes use: `scenes/brdf/plausible.png`,
//! `scenes/brdf/implausible.exr`, `scenes/brdf/glossy.exr`, `scenes/brdf/grazing.exr`
//! and `scenes/textures/checker.png`.
//!
//! ```sh
//! cargo run -p gpu-render-tools --bin make_material_images
//! ```
//!
//! A BRDF map texel `(x, y)` of an `N × N` map holds `π·f(θi, θr)` at
//! `θi = x/(N-1)·π/2`, `θr = y/(N-1)·π/2` (see `docs/materials.md`).

use std::f64::consts::FRAC_PI_2;

use gpu_render::low_level::color::{quantize_unorm8, srgb_encode};
use image::{ImageBuffer, Rgb, Rgb32FImage};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("scenes");
    let n = 32u32;
    let angle = |i: u32, n: u32| f64::from(i) / f64::from(n - 1) * FRAC_PI_2;
    // Plausible: π·f = tint·(0.5 + 0.4 sin θi sin θr), symmetric and at most 0.9, so
    // the directional albedo 2∫π·f cos θr sin θr dθr is at most 0.9.
    let tint = [1.0, 0.85, 0.7];
    let plausible = ImageBuffer::from_fn(n, n, |x, y| {
        let (a, b) = (angle(x.min(y), n), angle(x.max(y), n));
        let value = 0.5 + 0.4 * a.sin() * b.sin();
        Rgb(tint.map(|t| quantize_unorm8(srgb_encode(t * value))))
    });
    plausible.save(root.join("brdf/plausible.png"))?;
    // Implausible: negative near normal incidence, brighter than 1 (albedo up to ~1.6)
    // and not symmetric in θi and θr.
    let m = 16u32;
    let implausible = Rgb32FImage::from_fn(m, m, |x, y| {
        let (ti, tr) = (angle(x, m), angle(y, m));
        let value = (1.2 + 0.6 * ti - 0.3 * tr - if x + y < 2 { 1.5 } else { 0.0 }) as f32;
        Rgb([value, value, value])
    });
    implausible.save(root.join("brdf/implausible.exr"))?;
    // Glossy: π·f = 0.05 + 5 exp(−((θi − θr)/0.08)²), a narrow lobe along θi = θr
    // (azimuth-independent, so a ring around the normal), symmetric, directional albedo
    // at most 0.77. The same maps as the tests of src/cpu/path.rs and
    // tests/integration/sampler_chi2.rs; 65 × 65 puts the bands' edges on those tests' grids.
    let glossy = Rgb32FImage::from_fn(65, 65, |x, y| {
        let (ti, tr) = (angle(x, 65), angle(y, 65));
        let value = (0.05 + 5.0 * (-((ti - tr) / 0.08).powi(2)).exp()) as f32;
        Rgb([value, value, value])
    });
    glossy.save(root.join("brdf/glossy.exr"))?;
    // Grazing: π·f = 3.6 (sin θi sin θr)⁶, bright only where light and view both graze
    // (a sheen-like rim), symmetric, albedo 0.9 sin⁶ θr at most 0.9.
    let grazing = Rgb32FImage::from_fn(33, 33, |x, y| {
        let (ti, tr) = (angle(x, 33), angle(y, 33));
        let value = (3.6 * (ti.sin() * tr.sin()).powi(6)) as f32;
        Rgb([value, 0.8 * value, 0.6 * value])
    });
    grazing.save(root.join("brdf/grazing.exr"))?;
    // An 8×8 checkerboard of two colours, 8 texels per square.
    let checker = ImageBuffer::from_fn(64, 64, |x, y| {
        let colour: [f64; 3] = if (x / 8 + y / 8) % 2 == 0 {
            [0.8, 0.75, 0.6]
        } else {
            [0.15, 0.2, 0.35]
        };
        Rgb(colour.map(|c| quantize_unorm8(srgb_encode(c))))
    });
    checker.save(root.join("textures/checker.png"))?;
    Ok(())
}
