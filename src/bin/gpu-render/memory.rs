//! The memory a render will need, estimated before it starts, and the cap on it.
//!
//! The figures are peak resident memory measured with `/usr/bin/time -v` on this
//! project's machines (see `docs/reliability.md` for the table and the commands):
//! a fixed part, plus so many bytes per pixel for each backend and output format, plus
//! the scene itself. They must be measured again when the GPU engine or the writers
//! change how many copies of the image they hold.

use std::fmt;

use gpu_render::low_level::echo::bytes;
use gpu_render::output::OutputFormat;
use gpu_render::scene::Scene;

/// The default of `--max-memory`, in GiB.
pub const DEFAULT_MAX_MEMORY_GIB: f64 = 4.0;

/// Resident memory of the program apart from the image: code, the scene's loader and,
/// for the GPU, the device, its pipelines and the shader compiler's working memory.
/// Measured at a 1x1 image: 7 MB on the CPU; on lavapipe 105-157 MiB with the shader
/// cache warm, and up to 181 MiB more while a kernel compiles cold (every scene of
/// `scenes/` at 16x16, `MESA_SHADER_CACHE_DIR` empty; `env-materials.toml` the
/// largest: 338 MiB against 157 MiB warm; the compile adds the same at 2048x2048, on
/// top of the image's buffers, 2026-12-07). A GPU `--compare-gamma` keeps about
/// 240 MB more, measured as the offset of its peaks at 2048x2048 and 4096x4096.
fn fixed_bytes(backend: BackendKind, compare_gamma: bool) -> u64 {
    match (backend, compare_gamma) {
        (BackendKind::Cpu, _) => 16 << 20,
        (BackendKind::Gpu, false) => 384 << 20,
        (BackendKind::Gpu, true) => 512 << 20,
    }
}

/// The process's peak resident memory so far in bytes (Linux: `VmHWM` of
/// `/proc/self/status`, the high-water mark of this program's own memory, not of the
/// process it was started from), or `None` where the system does not tell.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kilobytes: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kilobytes * 1024)
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
        let scene_bytes = scene_bytes(scene, backend, compare_gamma);
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
        let scene_bytes = scene_bytes(scene, backend, false);
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
            bytes(self.total),
            self.pixels,
            self.per_pixel,
            bytes(self.scene),
            bytes(self.fixed)
        )
    }
}

/// Bytes of the scene the render holds: its geometry ([`geometry_bytes`]) and its
/// images as `backend` holds them ([`image_bytes`]).
fn scene_bytes(scene: &Scene, backend: BackendKind, compare_gamma: bool) -> u64 {
    geometry_bytes(scene) + image_bytes(scene, backend, compare_gamma)
}

/// Bytes of the scene's geometry: shapes, polygon vertices and mesh triangles (a mesh
/// placed once in world space with its attributes, one placed more than once stored
/// once plus a record per placement, as the geometry holds them;
/// `gpu_render::low_level::accel::instance`), in the model and once more in the
/// prepared or upload form.
fn geometry_bytes(scene: &Scene) -> u64 {
    use gpu_render::scene::Shape;
    let vertices: usize = scene
        .shapes
        .iter()
        .map(|shape| match shape {
            Shape::Polygon { vertices, .. } => vertices.len(),
            _ => 0,
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
        + mesh_triangles * 248
        + instances * 400;
    2 * bytes as u64
}

/// Bytes a texel of the scene's images adds for what the allocator keeps of the load's
/// and the mip chains' freed buffers (those below glibc's 32 MiB mmap threshold stay
/// in the heap): measured on the CPU over the counted copies, 0.6 B a texel with 4 and
/// 16 textures of 2048x2048 and 4 B with 4 of 1024x1024 (smaller buffers, more of
/// them in the heap); rounded up.
const ALLOCATOR_SLACK_PER_TEXEL: u64 = 6;

/// Bytes of linear RGBA `f32`, a texel.
const TEXEL: u64 = gpu_render::scene::DECODED_BYTES_PER_TEXEL;

/// Bytes a texel of the environment map adds to the map itself, counted from what is
/// made of it: the sampling tables (a function value and a cumulative value a texel,
/// `f64`, and the luminance they are made from: 24 B) on both backends, and on the GPU
/// its buffer of five `f32` a texel (radiance, function, cumulative: 20 B) three times
/// (the upload's copy, wgpu's staging, and the buffer, host memory on lavapipe).
fn environment_bytes_per_texel(backend: BackendKind) -> u64 {
    match backend {
        BackendKind::Cpu => 24,
        BackendKind::Gpu => 24 + 3 * 20,
    }
}

/// Bytes of the scene's images at the render's peak, counted from the copies made
/// (`docs/reliability.md`, "Memory"), or at the load's peak where that is higher:
///
/// - the scene's own images (16 B a texel), held by the program throughout;
/// - the CPU reference: its prepared copy of each image and, with texture filtering,
///   each image's mip chain (a third more);
/// - the GPU: the texture array (every layer as large as the largest image, with the
///   array's mip chain where textures are filtered: on lavapipe host memory) and,
///   while a layer is uploaded, that layer's texels with their chain in the upload's
///   copy and in wgpu's staging; with naive-gamma lighting (`--compare-gamma`'s second
///   render) a copy of the scene's images while they upload;
/// - the environment map, with what is made of it ([`environment_bytes_per_texel`]);
/// - the load, which decodes one image at a time next to those before it (at most
///   [`gpu_render::scene::DECODING_BYTES_PER_TEXEL`] a texel with its file), when that
///   is more than the render holds;
/// - and [`ALLOCATOR_SLACK_PER_TEXEL`].
fn image_bytes(scene: &Scene, backend: BackendKind, compare_gamma: bool) -> u64 {
    use gpu_render::low_level::texture::mip_chain_texels;
    let filters = scene.render.texture_filtering.filters();
    let texels = |width: u32, height: u32| {
        if filters {
            mip_chain_texels(width, height)
        } else {
            u64::from(width) * u64::from(height)
        }
    };
    let level0: u64 = scene.images.iter().map(|i| i.texels.len() as u64).sum();
    let environment = scene.environment.map.as_ref().map_or(0, |map| {
        map.image.texels.len() as u64 * (TEXEL + environment_bytes_per_texel(backend))
    });
    let largest = scene
        .images
        .iter()
        .chain(scene.environment.map.as_ref().map(|map| &map.image))
        .map(|i| i.texels.len() as u64)
        .max()
        .unwrap_or(0);
    let loading = TEXEL * level0
        + scene
            .environment
            .map
            .as_ref()
            .map_or(0, |map| TEXEL * map.image.texels.len() as u64)
        + (gpu_render::scene::DECODING_BYTES_PER_TEXEL - TEXEL) * largest;
    let rendering = match backend {
        BackendKind::Cpu => {
            let prepared: u64 = scene.images.iter().map(|i| texels(i.width, i.height)).sum();
            TEXEL * (level0 + prepared) + environment
        }
        BackendKind::Gpu => {
            let width = scene.images.iter().map(|i| i.width).max().unwrap_or(1);
            let height = scene.images.iter().map(|i| i.height).max().unwrap_or(1);
            let layers = scene.images.len().max(1) as u64;
            let array = layers * texels(width, height);
            let uploading = 2 * texels(width, height);
            let naive_copy = if compare_gamma
                || scene.render.lighting_space == gpu_render::scene::LightingSpace::NaiveGamma
            {
                level0
            } else {
                0
            };
            TEXEL * (level0 + array + uploading + naive_copy) + environment
        }
    };
    rendering.max(loading) + ALLOCATOR_SLACK_PER_TEXEL * level0
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
        // estimate may be above by at most 15% on the CPU and 60% on the GPU (whose
        // fixed part holds a cold shader compile, which these peaks did not take),
        // never below.
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
            let slack = match backend {
                BackendKind::Cpu => 1.15,
                BackendKind::Gpu => 1.6,
            };
            assert!(
                estimate >= measured && estimate <= slack * measured,
                "{backend:?} {format} {compare} {side}: estimate {estimate}, measured {measured}"
            );
        }
    }

    /// A 2048x2048 image whose texels are zero pages (never touched, never resident).
    fn large_image() -> gpu_render::scene::Image {
        gpu_render::scene::Image {
            path: "t.png".into(),
            width: 2048,
            height: 2048,
            texels: vec![[0.0; 4]; 2048 * 2048],
        }
    }

    /// A 64x64 scene with `count` albedo textures of 2048x2048 and, if `environment`,
    /// an environment map of that size, as the measurements below rendered it.
    fn textured(count: usize, environment: bool) -> Scene {
        let mut scene = scene(64, 64);
        scene.images = (0..count).map(|_| large_image()).collect();
        if environment {
            scene.environment.map = Some(std::sync::Arc::new(gpu_render::scene::EnvironmentMap {
                image: large_image(),
                rotation_degrees: 0.0,
                scale: glam::DVec3::ONE,
            }));
        }
        scene
    }

    #[test]
    fn the_estimate_of_textured_scenes_matches_the_measured_peaks() {
        // Peaks measured with 1, 4 and 16 different 2048x2048 PNG albedo textures
        // (docs/reliability.md, "Memory"), in kB, with the shader cache warm; the
        // estimate may be above by at most 35% on the CPU and 110% on the GPU (whose
        // fixed part holds a cold compile), never below.
        // No texture and a 2048x2048 environment map (path traced): the map's row.
        let cases = [
            (BackendKind::Cpu, 1, false, 166_544),
            (BackendKind::Cpu, 4, false, 637_708),
            (BackendKind::Cpu, 16, false, 2_472_736),
            (BackendKind::Cpu, 0, true, 173_808),
            (BackendKind::Gpu, 1, false, 359_600),
            (BackendKind::Gpu, 4, false, 889_728),
            (BackendKind::Gpu, 16, false, 2_740_508),
            (BackendKind::Gpu, 0, true, 497_204),
        ];
        for (backend, count, environment, kilobytes) in cases {
            let measured = kilobytes as f64 * 1024.0;
            let scene = textured(count, environment);
            let estimate = Estimate::new(&scene, backend, OutputFormat::Png, false).total as f64;
            let slack = match backend {
                BackendKind::Cpu => 1.35,
                BackendKind::Gpu => 2.1,
            };
            assert!(
                estimate >= measured && estimate <= slack * measured,
                "{backend:?} {count} textures, map {environment}: estimate {estimate}, \
                 measured {measured}"
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
