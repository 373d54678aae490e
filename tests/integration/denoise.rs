//! The built-in denoiser on the GPU (`shaders/denoise.wgsl`) against its CPU twin
//! (`src/denoise.rs`, whose unit tests hold the filter's properties on the CPU):
//!
//! - the GPU filter equals the CPU's per pixel, on synthetic guides and on a
//!   path-traced Cornell box's own passes and noise estimate, and a film denoised in
//!   the frame loop equals its image denoised in one call;
//! - on the GPU: a converged image passes through unchanged within 1e-3, a noisy
//!   constant image converges to the constant, nothing blurs across an albedo edge (a
//!   checker) or a depth edge;
//! - progressive accumulation with the denoiser on in every frame stays bit-identical
//!   to the same film without it: the display changes, the film does not.

use gpu_render::film::LinearImage;
use gpu_render::gpu::{HeadlessGpu, Renderer, RendererOptions};
use gpu_render::low_level::denoise::{DenoiseSettings, GuidePasses, denoise};
use gpu_render::scene::RenderOverrides;

/// GPU against CPU per channel: f32 on both, but exp, pow and the luminance (f64 on
/// the CPU) round differently.
const ABSOLUTE: f32 = 1e-4;
const RELATIVE: f32 = 1e-3;

fn renderer(gpu: &HeadlessGpu) -> Renderer {
    crate::support::gpu::renderer_with(
        gpu,
        RendererOptions {
            aov: true,
            noise_estimate: true,
            ..RendererOptions::default()
        },
    )
}

fn flat_guides(width: u32, height: u32) -> GuidePasses {
    let n = (width * height) as usize;
    GuidePasses {
        width,
        height,
        albedo: vec![[0.5; 3]; n],
        normal: vec![[0.0, 0.0, 1.0]; n],
        depth: vec![2.0; n],
    }
}

/// A fixed pseudo-random sequence in [0, 1).
fn noise(i: usize) -> f32 {
    let h = (i as u32 ^ 0x9e37_79b9)
        .wrapping_mul(0x85eb_ca6b)
        .rotate_left(13);
    let h = h.wrapping_mul(0xc2b2_ae35);
    (h >> 8) as f32 / (1u32 << 24) as f32
}

fn image_of(width: u32, height: u32, values: &[[f32; 3]]) -> LinearImage {
    LinearImage {
        width,
        height,
        pixels: values.iter().map(|v| [v[0], v[1], v[2], 1.0]).collect(),
    }
}

/// Denoises on the GPU and on the CPU, asserts that they agree per pixel and returns
/// the GPU's result.
fn denoise_both(
    label: &str,
    gpu: &HeadlessGpu,
    renderer: &Renderer,
    image: &LinearImage,
    variance: &[f32],
    guides: &GuidePasses,
) -> Vec<[f32; 3]> {
    let settings = DenoiseSettings::default();
    let radiance: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let cpu = denoise(&radiance, variance, guides, &settings);
    let gpu_image = renderer
        .denoise_image(&gpu.device, &gpu.queue, image, variance, guides, &settings)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let mut largest = 0.0f32;
    for (i, (c, g)) in cpu.iter().zip(&gpu_image.pixels).enumerate() {
        for k in 0..3 {
            let difference = (c[k] - g[k]).abs();
            largest = largest.max(difference);
            assert!(
                difference <= ABSOLUTE + RELATIVE * c[k].abs(),
                "{label} pixel {i}: CPU {c:?}, GPU {g:?}"
            );
        }
    }
    eprintln!("{label}: GPU against CPU largest difference {largest:.2e}");
    gpu_image
        .pixels
        .iter()
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

#[test]
fn the_gpu_filter_equals_its_cpu_twin_and_keeps_the_filters_properties() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = renderer(&gpu);
    // A converged (noise-free) image passes through unchanged within 1e-3.
    let (w, h) = (16u32, 12u32);
    let values: Vec<[f32; 3]> = (0..w * h).map(|i| [0.1 + 0.004 * i as f32; 3]).collect();
    let out = denoise_both(
        "converged",
        &gpu,
        &renderer,
        &image_of(w, h, &values),
        &vec![0.0; (w * h) as usize],
        &flat_guides(w, h),
    );
    for (a, b) in values.iter().zip(&out) {
        assert!(
            (a[0] - b[0]).abs() <= 1e-3 * a[0].max(1.0),
            "{a:?} -> {b:?}"
        );
    }
    // A noisy constant image converges to the constant.
    let n = 32 * 32;
    let values: Vec<[f32; 3]> = (0..n).map(|i| [0.25 + 0.4 * (noise(i) - 0.5); 3]).collect();
    let out = denoise_both(
        "noisy constant",
        &gpu,
        &renderer,
        &image_of(32, 32, &values),
        &vec![0.4 * 0.4 / 12.0; n],
        &flat_guides(32, 32),
    );
    let error = |img: &[[f32; 3]]| {
        (img.iter().map(|p| (p[0] - 0.25).powi(2)).sum::<f32>() / n as f32).sqrt()
    };
    assert!(
        error(&out) < error(&values) / 5.0,
        "rms error {} -> {}",
        error(&values),
        error(&out)
    );
    // No blur across a checker of albedo 0.1 and 0.9 under uniform light.
    let (w, h) = (24u32, 8u32);
    let n = (w * h) as usize;
    let mut guides = flat_guides(w, h);
    let mut values = Vec::with_capacity(n);
    for i in 0..n {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let a = if (x / 4 + y / 4) % 2 == 0 { 0.1 } else { 0.9 };
        guides.albedo[i] = [a; 3];
        values.push([a * (1.0 + 0.1 * (noise(i) - 0.5)); 3]);
    }
    let variance = vec![0.01 / 12.0; n];
    let out = denoise_both(
        "albedo edge",
        &gpu,
        &renderer,
        &image_of(w, h, &values),
        &variance,
        &guides,
    );
    for (i, (pixel, albedo)) in out.iter().zip(&guides.albedo).enumerate() {
        let a = albedo[0];
        assert!(
            (pixel[0] - a).abs() < 0.05 * a + 0.01,
            "pixel {i}: {} for albedo {a}",
            pixel[0]
        );
    }
    // No blur across a depth edge: depth 1 in light 1 against depth 10 in light 0.2.
    let mut guides = flat_guides(w, h);
    let mut values = Vec::with_capacity(n);
    for i in 0..n {
        let left = (i as u32 % w) < w / 2;
        guides.depth[i] = if left { 1.0 } else { 10.0 };
        guides.albedo[i] = [1.0; 3];
        let light = if left { 1.0 } else { 0.2 };
        values.push([light * (1.0 + 0.1 * (noise(i) - 0.5)); 3]);
    }
    let out = denoise_both(
        "depth edge",
        &gpu,
        &renderer,
        &image_of(w, h, &values),
        &variance,
        &guides,
    );
    for (i, pixel) in out.iter().enumerate() {
        let light = if (i as u32 % w) < w / 2 { 1.0 } else { 0.2 };
        assert!(
            (pixel[0] - light).abs() < 0.06 * light,
            "pixel {i}: {} for {light}",
            pixel[0]
        );
    }
}

#[test]
fn a_denoised_film_equals_the_cpu_twin_on_its_own_passes_and_noise() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = renderer(&gpu);
    let scene = crate::support::scenes::reduced(
        crate::support::scenes::shipped("cornell-box.toml"),
        40,
        RenderOverrides {
            samples_per_pixel: Some(4),
            ..RenderOverrides::default()
        },
    );
    let uploaded = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("uploads");
    let mut film = renderer
        .create_film(
            &gpu.device,
            &uploaded,
            scene.render.width,
            scene.render.height,
        )
        .expect("film");
    let settings = DenoiseSettings::default();
    let image = renderer
        .render_to_image(&gpu.device, &gpu.queue, &uploaded, &mut film)
        .expect("renders")
        .image;
    let noise = renderer
        .read_noise(&gpu.device, &gpu.queue, &uploaded, &mut film)
        .expect("noise");
    let guides = renderer
        .read_aov(&gpu.device, &gpu.queue, &uploaded, &mut film)
        .expect("passes");
    let variance: Vec<f32> = noise.standard_error.iter().map(|se| se * se).collect();
    let in_one_call = denoise_both("Cornell box", &gpu, &renderer, &image, &variance, &guides);
    let in_the_loop = renderer
        .read_denoised(&gpu.device, &gpu.queue, &uploaded, &mut film, &settings)
        .expect("denoises");
    for (i, (a, b)) in in_one_call.iter().zip(&in_the_loop.pixels).enumerate() {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() <= ABSOLUTE + RELATIVE * a[k].abs(),
                "pixel {i}: one call {a:?}, frame loop {b:?}"
            );
        }
    }
}

#[test]
fn progressive_accumulation_stays_bit_identical_with_the_denoiser_on() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = renderer(&gpu);
    let scene = crate::support::scenes::reduced(
        crate::support::scenes::shipped("cornell-box.toml"),
        32,
        RenderOverrides {
            samples_per_pixel: Some(4),
            ..RenderOverrides::default()
        },
    );
    let uploaded = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("uploads");
    let (w, h) = (scene.render.width, scene.render.height);
    let display = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("display"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: gpu_render::gpu::DISPLAY_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let display_view = display.create_view(&wgpu::TextureViewDescriptor::default());
    let settings = DenoiseSettings::default();
    let mut results = Vec::new();
    for denoised in [false, true] {
        let mut film = renderer
            .create_film(&gpu.device, &uploaded, w, h)
            .expect("film");
        // Frames of one sample each, the denoised display recorded in every frame
        // (while passes are still in flight) and after the last.
        for frame in 0..6 {
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            let samples = u32::from(frame < 4);
            renderer
                .encode_samples(
                    &gpu.device,
                    &gpu.queue,
                    &mut encoder,
                    &uploaded,
                    &mut film,
                    samples,
                )
                .expect("encodes");
            if denoised {
                renderer
                    .encode_denoised_display(
                        &gpu.device,
                        &gpu.queue,
                        &mut encoder,
                        &uploaded,
                        &mut film,
                        &settings,
                        &display_view,
                    )
                    .expect("denoises");
            }
            gpu.queue.submit([encoder.finish()]);
        }
        renderer
            .finish(&gpu.device, &gpu.queue, &uploaded, &mut film)
            .expect("finishes");
        let image = renderer
            .read_film(&gpu.device, &gpu.queue, &uploaded, &film)
            .expect("reads");
        let noise = renderer
            .read_noise(&gpu.device, &gpu.queue, &uploaded, &mut film)
            .expect("noise");
        let denoised_image = renderer
            .read_denoised(&gpu.device, &gpu.queue, &uploaded, &mut film, &settings)
            .expect("denoises");
        results.push((image, noise, denoised_image));
    }
    let (plain, with_denoiser) = (&results[0], &results[1]);
    assert_eq!(plain.0.samples, 4);
    assert_eq!(plain.0.image, with_denoiser.0.image, "the film's mean");
    assert_eq!(plain.0.display_rgba8, with_denoiser.0.display_rgba8);
    assert_eq!(plain.1, with_denoiser.1, "the film's noise estimate");
    // The denoised image differs from the film's (it did filter).
    let changed = plain
        .0
        .image
        .pixels
        .iter()
        .zip(&with_denoiser.2.pixels)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 1e-3)
        .count();
    assert!(changed > 100, "only {changed} pixels changed");
}
