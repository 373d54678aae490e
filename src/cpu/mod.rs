//! The CPU reference tracer: the same model as the WGSL shaders, with the same function
//! names, written plainly in `f64`.
//!
//! It is the oracle of the GPU tests and the fallback when no GPU adapter exists. It
//! computes in `f64` so that its own rounding error is negligible next to the GPU's
//! `f32`: the difference between the two images is then the GPU's error budget.
//!
//! Whole renders are here; the internals (ray and hit records, the BVH queries, the
//! BxDFs, the integrators' steps) are public under [`crate::low_level::cpu`], for tests
//! and tools.

pub(crate) mod aov;
pub(crate) mod bxdf;
pub(crate) mod coverage;
pub(crate) mod intersect;
pub(crate) mod path;
pub(crate) mod tabulated;
pub(crate) mod trace;
pub(crate) mod traverse;

use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::Instant;

use crate::film::{LinearImage, ProgressFn, RenderStats, Rendered};
use crate::noise::{NoiseEstimate, standard_error};
use crate::scene::Scene;
pub use aov::render_aovs;
pub use trace::{PreparedScene, trace_pixel};

/// Renders `scene` on all CPU cores, rows handed out one at a time. `progress` is told
/// the number of finished rows after each row.
///
/// ```
/// # use gpu_render::scene::parse_scene;
/// # fn main() -> Result<(), gpu_render::scene::SceneError> {
/// let scene = parse_scene(
///     "[render]\nwidth = 8\nheight = 6\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n",
///     std::path::Path::new("<inline>"),
/// )?;
/// let rendered = gpu_render::cpu::render(&scene, None);
/// assert_eq!(rendered.image.pixels.len(), 48);
/// # Ok(())
/// # }
/// ```
pub fn render(scene: &Scene, progress: Option<ProgressFn<'_>>) -> Rendered {
    let (width, height) = (scene.render.width, scene.render.height);
    render_window(scene, 0..width, 0..height, progress, false)
}

/// [`render`], and each pixel's noise estimate ([`Rendered::noise`]: the standard error
/// of its mean luminance, from the spread of its samples; 8 more bytes per pixel).
/// The image is the same.
pub fn render_with_noise(scene: &Scene, progress: Option<ProgressFn<'_>>) -> Rendered {
    let (width, height) = (scene.render.width, scene.render.height);
    render_window(scene, 0..width, 0..height, progress, true)
}

/// A region handed to [`render_region`] that is empty or does not lie inside the image.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "region columns {columns:?}, rows {rows:?} is empty or lies outside the {width}x{height} image"
)]
pub struct RegionOutsideImage {
    /// The columns asked for.
    pub columns: Range<u32>,
    /// The rows asked for.
    pub rows: Range<u32>,
    /// The image's width.
    pub width: u32,
    /// The image's height.
    pub height: u32,
}

/// Renders only the pixels in `columns × rows` of `scene`'s image, on all CPU cores,
/// rows handed out one at a time. The result is the region's: its image is
/// `columns.len() × rows.len()` pixels whose (0, 0) is pixel `(columns.start,
/// rows.start)` of the whole image, each bit-identical to that pixel of [`render`]
/// (a pixel's samples depend only on the pixel and the sample index). `progress` is
/// told the number of finished rows of the region after each row.
///
/// ```
/// # use gpu_render::scene::parse_scene;
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let scene = parse_scene(
///     "[render]\nwidth = 8\nheight = 6\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n",
///     std::path::Path::new("<inline>"),
/// )?;
/// let whole = gpu_render::cpu::render(&scene, None);
/// let corner = gpu_render::cpu::render_region(&scene, 4..8, 3..6, None)?;
/// assert_eq!((corner.image.width, corner.image.height), (4, 3));
/// assert_eq!(corner.image.pixel(0, 0), whole.image.pixel(4, 3));
/// # Ok(())
/// # }
/// ```
///
/// Errors: [`RegionOutsideImage`] for an empty region or one past the image's edge.
pub fn render_region(
    scene: &Scene,
    columns: Range<u32>,
    rows: Range<u32>,
    progress: Option<ProgressFn<'_>>,
) -> Result<Rendered, RegionOutsideImage> {
    render_region_with(scene, columns, rows, progress, false)
}

/// [`render_region`], and the region's noise estimate (as [`render_with_noise`]).
///
/// Errors: [`RegionOutsideImage`] for an empty region or one past the image's edge.
pub fn render_region_with_noise(
    scene: &Scene,
    columns: Range<u32>,
    rows: Range<u32>,
    progress: Option<ProgressFn<'_>>,
) -> Result<Rendered, RegionOutsideImage> {
    render_region_with(scene, columns, rows, progress, true)
}

fn render_region_with(
    scene: &Scene,
    columns: Range<u32>,
    rows: Range<u32>,
    progress: Option<ProgressFn<'_>>,
    noise: bool,
) -> Result<Rendered, RegionOutsideImage> {
    let (width, height) = (scene.render.width, scene.render.height);
    if columns.is_empty() || rows.is_empty() || columns.end > width || rows.end > height {
        return Err(RegionOutsideImage {
            columns,
            rows,
            width,
            height,
        });
    }
    Ok(render_window(scene, columns, rows, progress, noise))
}

/// Prepares `scene` and traces the window, timing both.
fn render_window(
    scene: &Scene,
    columns: Range<u32>,
    rows: Range<u32>,
    progress: Option<ProgressFn<'_>>,
    noise: bool,
) -> Rendered {
    let started = Instant::now();
    let prepared = PreparedScene::new(scene);
    trace_window(&prepared, columns, rows, progress, noise, started)
}

/// Traces the pixels in `columns × rows` on all CPU cores, rows handed out one at a
/// time, into an image of the window's size (and with `noise` its noise estimate);
/// `progress` is told the finished rows.
fn trace_window(
    prepared: &PreparedScene,
    columns: Range<u32>,
    rows: Range<u32>,
    progress: Option<ProgressFn<'_>>,
    noise: bool,
    started: Instant,
) -> Rendered {
    let region_width = columns.end - columns.start;
    let region_height = rows.end - rows.start;
    let mut image = LinearImage::new(region_width, region_height);
    let samples = prepared.settings.samples_per_pixel;
    // Each pixel's mean luminance and standard error, when asked for.
    let noise_pixels = if noise { image.pixels.len() } else { 0 };
    let mut estimate = NoiseEstimate {
        width: region_width,
        height: region_height,
        samples,
        mean_luminance: vec![0.0; noise_pixels],
        standard_error: vec![0.0; noise_pixels],
    };
    let mut noise_rows = estimate
        .mean_luminance
        .chunks_mut(region_width as usize)
        .zip(estimate.standard_error.chunks_mut(region_width as usize));
    type Row<'a> = (
        u32,
        &'a mut [[f32; 4]],
        Option<(&'a mut [f32], &'a mut [f32])>,
    );
    let pending: Vec<Row<'_>> = image
        .pixels
        .chunks_mut(region_width as usize)
        .zip(rows.clone())
        .map(|(row, y)| (y, row, noise_rows.next()))
        .collect();
    let queue = Mutex::new(pending);
    let rays = AtomicU64::new(0);
    let rows_done = AtomicU32::new(0);
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let next = queue
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .pop();
                    let Some((y, row, mut row_noise)) = next else {
                        break;
                    };
                    let mut row_rays = 0;
                    for (i, (x, pixel)) in columns.clone().zip(row.iter_mut()).enumerate() {
                        let result = trace_pixel(prepared, x, y);
                        *pixel = [
                            result.radiance.x as f32,
                            result.radiance.y as f32,
                            result.radiance.z as f32,
                            1.0,
                        ];
                        if let Some((mean, error)) = &mut row_noise {
                            mean[i] = crate::color::luminance(result.radiance) as f32;
                            error[i] = standard_error(result.luminance_m2, samples) as f32;
                        }
                        row_rays += result.rays;
                    }
                    rays.fetch_add(row_rays, Ordering::Relaxed);
                    let done = rows_done.fetch_add(1, Ordering::Relaxed) + 1;
                    if let Some(report) = progress {
                        report(done, region_height);
                    }
                }
            });
        }
    });
    let noise = noise.then_some(estimate);
    Rendered {
        image,
        noise,
        stats: RenderStats {
            rays_traced: rays.into_inner(),
            elapsed: started.elapsed(),
            gpu_time: None,
        },
    }
}
