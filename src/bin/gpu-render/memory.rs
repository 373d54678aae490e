//! The memory a render will need, estimated before it starts, and the cap on it.
//!
//! The figures are peak resident memory measured with `/usr/bin/time -v` on this
//! project's machines (see `docs/reliability.md` for the table and the commands):
//! a fixed part, plus so many bytes per pixel for each backend and output format, plus
//! the scene itself. They must be measured again when the GPU engine or the writers
//! change how many copies of the image they hold.

use std::fmt;

use gpu_render::output::OutputFormat;
use gpu_render::scene::Scene;

/// The default of `--max-memory`, in GiB.
pub const DEFAULT_MAX_MEMORY_GIB: f64 = 4.0;

/// Resident memory of the program apart from the image: code, the scene's loader and,
/// for the GPU, the device and its pipelines (measured at a 1x1 image: 7 MB on the CPU,
/// 84-115 MB on lavapipe; a GPU `--compare-gamma` keeps about 240 MB more, measured as
/// the offset of its peaks at 2048x2048 and 4096x4096).
fn fixed_bytes(backend: BackendKind, compare_gamma: bool) -> u64 {
    match (backend, compare_gamma) {
        (BackendKind::Cpu, _) => 16 << 20,
        (BackendKind::Gpu, false) => 128 << 20,
        (BackendKind::Gpu, true) => 256 << 20,
    }
}

/// Where the render runs, as far as memory goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BackendKind {
    /// The wgpu tracer (on lavapipe its textures and buffers are host memory too).
    Gpu,
    /// The CPU reference.
    Cpu,
}

/// Peak bytes per pixel of one render written as `format`, and of a `--compare-gamma`
/// render per pixel of each half: the growth of the peak from 2048x2048 to 4096x4096
/// (see `docs/reliability.md`). The CPU holds the linear image (16 bytes) and the
/// display image (4); `.hdr` adds its RGB copy (12); `--compare-gamma` holds both
/// renders and the joined image. On lavapipe the GPU's textures and buffers are host
/// memory too, so its figure is the upper bound for a discrete GPU's host memory.
fn bytes_per_pixel(backend: BackendKind, format: OutputFormat, compare_gamma: bool) -> u64 {
    match (backend, compare_gamma, format) {
        (BackendKind::Cpu, false, OutputFormat::Png | OutputFormat::Exr) => 20,
        (BackendKind::Cpu, false, OutputFormat::Hdr) => 32,
        (BackendKind::Cpu, true, _) => 80,
        (BackendKind::Gpu, false, _) => 86,
        (BackendKind::Gpu, true, _) => 99,
    }
}

/// Bytes per pixel a `--standard-error` render adds, counted from what it holds, an
/// upper bound: the estimate's two `f32` per pixel (8), its grey image for the EXR
/// (16) and an encoder's copy of it (16); on the GPU also the accumulation buffer of
/// one `vec4<f32>` per pixel (16) and its readback (16). Measured (`minimal.toml`,
/// 2 spp, growth of the peak from 2048² to 4096², 2026-12-01): 24 on the CPU; on
/// lavapipe no more than without the estimate (its smaller tiles hold less).
fn noise_bytes_per_pixel(backend: BackendKind) -> u64 {
    match backend {
        BackendKind::Cpu => 40,
        BackendKind::Gpu => 72,
    }
}

/// Bytes per pixel an `--aov` (or `--denoise`) render adds, counted, not measured:
/// the passes' seven `f32` (28) and on the CPU their `f64` means (56), on the GPU the
/// accumulation buffer's two `vec4<f32>` (32) and their readback (32), and the EXR
/// encoder's copy of the channels with its compressed blocks (56).
const AOV_BYTES_PER_PIXEL: u64 = 148;

/// Bytes per pixel `--denoise oidn` adds: OIDN's own buffers for its network (its CPU
/// device, no tiling below its memory limit) and the binding's copies of the colour,
/// albedo, normal and output images (48). Measured (Cornell box, 1 spp, CPU backend,
/// growth of the peak over an `--aov` render from 960x540 to 1920x1080, OIDN 2.5.1,
/// 2026-12-04): 572; its fixed part (the library, its weights) about 8 MB.
const OIDN_BYTES_PER_PIXEL: u64 = 576;

/// An estimate of a render's peak memory, with its parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Estimate {
    /// Pixels of one pass.
    pub pixels: u64,
    /// Bytes per pixel for this backend and format.
    pub per_pixel: u64,
    /// Bytes of the scene's shapes and images.
    pub scene: u64,
    /// Bytes of the program apart from the image and the scene.
    pub fixed: u64,
    /// The whole estimate in bytes.
    pub total: u64,
}

impl Estimate {
    /// The estimate for rendering `scene` (at its settings) on `backend` into `format`.
    pub fn new(
        scene: &Scene,
        backend: BackendKind,
        format: OutputFormat,
        compare_gamma: bool,
    ) -> Self {
        let pixels = u64::from(scene.render.width) * u64::from(scene.render.height);
        let per_pixel = bytes_per_pixel(backend, format, compare_gamma);
        let scene_bytes = scene_bytes(scene);
        let fixed = fixed_bytes(backend, compare_gamma);
        Self {
            pixels,
            per_pixel,
            scene: scene_bytes,
            fixed,
            total: fixed + scene_bytes + pixels * per_pixel,
        }
    }
}

impl Estimate {
    /// The estimate with the noise estimate's bytes per pixel added
    /// (`--standard-error`).
    pub fn with_noise_estimate(self, backend: BackendKind) -> Self {
        let extra = noise_bytes_per_pixel(backend);
        Self {
            per_pixel: self.per_pixel + extra,
            total: self.total + self.pixels * extra,
            ..self
        }
    }

    /// The estimate with the auxiliary passes' bytes per pixel added (`--aov`).
    pub fn with_aov(self) -> Self {
        Self {
            per_pixel: self.per_pixel + AOV_BYTES_PER_PIXEL,
            total: self.total + self.pixels * AOV_BYTES_PER_PIXEL,
            ..self
        }
    }

    /// The estimate with Intel Open Image Denoise's bytes per pixel added
    /// (`--denoise oidn`).
    pub fn with_oidn(self) -> Self {
        Self {
            per_pixel: self.per_pixel + OIDN_BYTES_PER_PIXEL,
            total: self.total + self.pixels * OIDN_BYTES_PER_PIXEL,
            ..self
        }
    }

    /// The estimate for rendering `pixels` of `scene`'s image as a tile (`--tile`,
    /// `--crop`): the `.exr` figure per pixel of the window, plus the tile's eight
    /// channels as the `exr` encoder holds them (32 bytes per pixel) and as much
    /// again for its compressed blocks. Those 64 bytes are counted, not measured.
    pub fn for_tile(scene: &Scene, backend: BackendKind, pixels: u64) -> Self {
        let per_pixel = bytes_per_pixel(backend, OutputFormat::Exr, false) + 64;
        let scene_bytes = scene_bytes(scene);
        let fixed = fixed_bytes(backend, false);
        Self {
            pixels,
            per_pixel,
            scene: scene_bytes,
            fixed,
            total: fixed + scene_bytes + pixels * per_pixel,
        }
    }
}

impl fmt::Display for Estimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({} pixels x {} bytes, scene {}, program {})",
            gib(self.total),
            self.pixels,
            self.per_pixel,
            gib(self.scene),
            gib(self.fixed)
        )
    }
}

/// Bytes of the scene the render holds: shapes, polygon vertices, image texels and
/// mesh triangles (a mesh placed once in world space with its attributes, one placed
/// more than once stored once plus a record per placement, as the geometry holds them;
/// `gpu_render::low_level::accel::instance`), in the model and (for the GPU) once more in upload
/// form.
fn scene_bytes(scene: &Scene) -> u64 {
    use gpu_render::scene::Shape;
    let vertices: usize = scene
        .shapes
        .iter()
        .map(|shape| match shape {
            Shape::Polygon { vertices, .. } => vertices.len(),
            _ => 0,
        })
        .sum();
    // With texture filtering every image keeps its mip chain too, about a third more
    // (the CPU's PreparedScene::image_levels, the GPU array's levels).
    let texels: usize = scene
        .images
        .iter()
        .map(|image| {
            if scene.render.texture_filtering.filters() {
                gpu_render::low_level::texture::mip_chain_texels(image.width, image.height) as usize
            } else {
                image.texels.len()
            }
        })
        .sum();
    // A world-space mesh triangle: 3 f64 corners plus a material and attribute index
    // (80 B), its attributes (3 normals and 3 UVs, 128 B) and its BVH share (~40 B).
    let (mut mesh_triangles, mut instances) = (0, 0);
    for group in gpu_render::low_level::accel::instance::mesh_groups(&scene.meshes) {
        let placements: usize = group.iter().map(|&i| scene.meshes[i].instances.len()).sum();
        let triangles = scene.meshes[group[0]].triangles.len();
        if placements > 1 {
            mesh_triangles += triangles;
            instances += placements;
        } else {
            mesh_triangles += triangles * placements;
        }
    }
    // An instance: its transforms, bounds and material (~250 B), and its records.
    let bytes = scene.shapes.len() * std::mem::size_of::<Shape>()
        + vertices * 24
        + texels * 16
        + mesh_triangles * 248
        + instances * 400;
    2 * bytes as u64
}

/// `bytes` as GiB with two decimals.
pub fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / f64::from(1u32 << 30))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpu_render::scene::parse_scene;

    fn scene(width: u32, height: u32) -> Scene {
        let text = format!(
            "[render]\nwidth = {width}\nheight = {height}\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n"
        );
        parse_scene(&text, std::path::Path::new("<test>")).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn compare_gamma_at_the_largest_size_on_the_cpu_passes_the_default_cap() {
        let estimate = Estimate::new(
            &scene(16384, 8192),
            BackendKind::Cpu,
            OutputFormat::Png,
            true,
        );
        let cap = (DEFAULT_MAX_MEMORY_GIB * f64::from(1u32 << 30)) as u64;
        assert!(estimate.total > cap, "{estimate}");
        let single = Estimate::new(
            &scene(16384, 8192),
            BackendKind::Cpu,
            OutputFormat::Png,
            false,
        );
        assert!(single.total < cap, "{single}");
    }

    #[test]
    fn the_estimate_matches_the_measured_peaks() {
        // Peaks measured at 2048x2048 and 4096x4096 (docs/reliability.md), in kB; the
        // estimate may be above by at most 15%, never below.
        let cases = [
            (BackendKind::Cpu, OutputFormat::Png, false, 2048, 89_676),
            (BackendKind::Cpu, OutputFormat::Png, false, 4096, 335_820),
            (BackendKind::Cpu, OutputFormat::Exr, false, 4096, 335_352),
            (BackendKind::Cpu, OutputFormat::Hdr, false, 2048, 138_108),
            (BackendKind::Cpu, OutputFormat::Hdr, false, 4096, 531_544),
            (BackendKind::Cpu, OutputFormat::Png, true, 2048, 334_612),
            (BackendKind::Cpu, OutputFormat::Png, true, 4096, 1_317_764),
            (BackendKind::Gpu, OutputFormat::Png, false, 2048, 478_068),
            (BackendKind::Gpu, OutputFormat::Exr, false, 4096, 1_528_196),
            (BackendKind::Gpu, OutputFormat::Hdr, false, 4096, 1_528_220),
            (BackendKind::Gpu, OutputFormat::Png, true, 2048, 642_248),
            (BackendKind::Gpu, OutputFormat::Png, true, 4096, 1_855_856),
        ];
        for (backend, format, compare, side, kilobytes) in cases {
            let measured = kilobytes as f64 * 1024.0;
            let estimate = Estimate::new(&scene(side, side), backend, format, compare).total as f64;
            assert!(
                estimate >= measured && estimate <= 1.15 * measured,
                "{backend:?} {format} {compare} {side}: estimate {estimate}, measured {measured}"
            );
        }
    }

    #[test]
    fn the_noise_estimate_adds_its_bytes_per_pixel() {
        let plain = Estimate::new(&scene(64, 32), BackendKind::Cpu, OutputFormat::Exr, false);
        let noisy = plain.with_noise_estimate(BackendKind::Cpu);
        assert_eq!(noisy.total - plain.total, 64 * 32 * 40);
        assert_eq!(noisy.per_pixel, plain.per_pixel + 40);
    }

    #[test]
    fn estimate_grows_with_pixels_and_names_its_parts() {
        let small = Estimate::new(&scene(64, 64), BackendKind::Gpu, OutputFormat::Exr, false);
        let large = Estimate::new(
            &scene(4096, 4096),
            BackendKind::Gpu,
            OutputFormat::Exr,
            false,
        );
        assert!(large.total > small.total);
        assert_eq!(
            large.total - small.total,
            (4096 * 4096 - 64 * 64) * large.per_pixel
        );
        let shown = large.to_string();
        assert!(
            shown.contains("16777216 pixels") && shown.contains("GiB"),
            "{shown}"
        );
    }
}
