//! The GPU display pass against its CPU twin (`srgb_encode` + `quantize_unorm8`, via
//! `LinearImage::to_display_rgba8`), on a ramp that includes the curve's knee
//! (0.0031308), negative values, values above 1, infinities and NaN.
//!
//! Tolerance: exact, except ±1 LSB where the exact f64 value `255 · encode(x)` lies
//! within 1e-4 of a rounding boundary (`k + 0.5`). The shader quantises itself (so
//! the driver's float-to-unorm rounding does not matter), but its `pow` is f32 and
//! may land on the other side of such a boundary. The ramp deliberately probes all
//! 255 boundaries; measured on lavapipe, every disagreement was within 7.2e-6 of one.

use std::time::Duration;

use gpu_render::film::LinearImage;
use gpu_render::gpu::read_texture;
use gpu_render::low_level::color::srgb_encode;

const WIDTH: u32 = 37; // 37 * 4 bytes is not a multiple of 256: exercises row padding

fn ramp() -> Vec<f32> {
    let mut values = vec![
        -1.0,
        -0.0,
        0.0,
        1e-7,
        0.001,
        0.003_130_7,
        0.003_130_8,
        0.003_130_9,
        0.04,
        0.18,
        0.5,
        0.999,
        1.0,
        1.000_1,
        1.5,
        1e30,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
    ];
    // A dense ramp over [0, 1] plus every 8-bit rounding boundary of the curve, where
    // the f32 shader and the f64 reference are most likely to disagree.
    values.extend((0..=4096).map(|i| i as f32 / 4096.0));
    values.extend((0..255).map(|k| {
        let encoded = (f64::from(k) + 0.5) / 255.0;
        gpu_render::low_level::color::srgb_decode(encoded) as f32
    }));
    values
}

/// Packs the ramp into RGB (rotated per channel so each channel sees every value);
/// alpha carries junk to check that the pass writes alpha 1.
fn image(values: &[f32]) -> LinearImage {
    let pixel_count = values.len().div_ceil(WIDTH as usize) * WIDTH as usize;
    let height = (pixel_count / WIDTH as usize) as u32;
    let at = |i: usize| values[i % values.len()];
    let pixels = (0..pixel_count)
        .map(|i| [at(i), at(i + 7), at(i + 13), -3.0])
        .collect();
    LinearImage {
        width: WIDTH,
        height,
        pixels,
    }
}

fn run_display_pass(encode_srgb: bool) -> Option<(LinearImage, Vec<u8>)> {
    let gpu = crate::support::gpu::headless_gpu()?;
    let renderer = crate::support::gpu::renderer(&gpu);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let image = image(&ramp());
    let size = wgpu::Extent3d {
        width: image.width,
        height: image.height,
        depth_or_array_layers: 1,
    };
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let linear = texture(
        "ramp",
        wgpu::TextureFormat::Rgba32Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    let display = texture(
        "display",
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
    );
    queue.write_texture(
        linear.as_image_copy(),
        bytemuck::cast_slice(&image.pixels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(image.width * 16),
            rows_per_image: Some(image.height),
        },
        size,
    );
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    renderer
        .encode_display_texture(
            device,
            &mut encoder,
            &linear.create_view(&Default::default()),
            &display.create_view(&Default::default()),
            encode_srgb,
        )
        .expect("display pass records");
    queue.submit([encoder.finish()]);
    let bytes = read_texture(device, queue, &display, 4, Some(Duration::from_secs(60)))
        .expect("display texture reads back");
    Some((image, bytes))
}

fn compare(encode_srgb: bool) {
    let Some((image, gpu)) = run_display_pass(encode_srgb) else {
        return;
    };
    let cpu = image.to_display_rgba8(encode_srgb);
    assert_eq!(gpu.len(), cpu.len());
    let mut at_boundary = 0;
    for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        let pixel = i / 4;
        let channel = i % 4;
        let input = image.pixels[pixel][channel];
        if channel == 3 {
            assert_eq!(*g, 255, "alpha of pixel {pixel}");
            continue;
        }
        let exact = if encode_srgb {
            srgb_encode(f64::from(input))
        } else {
            f64::from(input)
        } * 255.0;
        let near_boundary = (exact.fract() - 0.5).abs() < 1e-4;
        let allowed = if near_boundary { 1 } else { 0 };
        let diff = g.abs_diff(*c);
        assert!(
            diff <= allowed,
            "pixel {pixel} channel {channel}: input {input:e} (255·encode = {exact}) \
             -> GPU {g}, CPU {c}"
        );
        if diff == 1 {
            at_boundary += 1;
        }
    }
    eprintln!(
        "{at_boundary} of {} channels differ by 1 LSB at a rounding boundary",
        image.pixels.len() * 3
    );
}

#[test]
fn display_pass_matches_cpu_srgb_encode() {
    compare(true);
}

#[test]
fn display_pass_clamps_only_in_naive_gamma_mode() {
    compare(false);
}
