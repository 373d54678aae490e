//! The WGSL sample pattern (`shaders/camera.wgsl`) against its CPU twin
//! (`src/camera.rs`): a test kernel calls `sample_offset` for two rounds of every sample
//! (the pattern and the progressive samples past it) of a few
//! pixels at every sample count 1..=300 and at large counts (sample indices up to
//! 2^17 − 1, where the Sobol sequence's higher direction numbers come in), and
//! each offset must equal the CPU's exactly: both take the same 24 bits of the same
//! integers, which f32 holds exactly. That the CPU pattern covers the pixel uniformly
//! (a (0,k,2)-net for power-of-two counts) is tested in `src/camera.rs`.

use gpu_render::gpu::ShaderFeatures;
use gpu_render::low_level::camera::sample_offset;
use gpu_render::low_level::gpu::layout::FrameUniforms;
use gpu_render::low_level::gpu::shaders::compose_source;
use gpu_render::scene::RenderSettings;
use wgpu::util::DeviceExt;

/// The kernel: one invocation per (pixel, sample index).
const KERNEL: &str = r"
#import bindings
#import camera

@group(0) @binding(1) var<storage, read> pixels: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read_write> offsets: array<vec2<f32>>;

@compute @workgroup_size(64)
fn sample_offsets(@builtin(global_invocation_id) id: vec3<u32>) {
    // Two rounds of the pattern: the progressive samples past it too.
    let n = frame.samples_per_pixel * 2u;
    if id.x >= arrayLength(&pixels) * n {
        return;
    }
    let pixel = pixels[id.x / n];
    offsets[id.x] = sample_offset(pixel.x, pixel.y, id.x % n);
}
";

/// Rounds of each pattern compared: the kernel's `* 2u`.
const ROUNDS: u32 = 2;
/// Image width the pixel index is computed with.
const WIDTH: u32 = 1920;
/// Pixels whose samples are compared.
const PIXELS: [[u32; 2]; 4] = [[0, 0], [5, 2], [1919, 7], [640, 1079]];
/// An offset is 24 bits of an integer times 2^-24 on both backends: exact in f32.
const TOLERANCE: f64 = 0.0;

fn sample_counts() -> Vec<u32> {
    let mut counts: Vec<u32> = (1..=300).collect();
    counts.extend([1024, 4096, 65_535, 65_536]);
    counts
}

#[test]
fn gpu_sample_offsets_match_the_cpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let source = compose_source(KERNEL, &ShaderFeatures::ALL).expect("the kernel composes");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("sample offsets"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("sample offsets"),
        layout: None,
        module: &module,
        entry_point: Some("sample_offsets"),
        compilation_options: Default::default(),
        cache: None,
    });
    let pixel_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("pixels"),
        contents: bytemuck::cast_slice(&PIXELS),
        usage: wgpu::BufferUsages::STORAGE,
    });

    let counts = sample_counts();
    let total: u64 = counts
        .iter()
        .map(|&n| u64::from(ROUNDS * n) * PIXELS.len() as u64)
        .sum();
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: total * 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    let mut keep_alive = Vec::new();
    let mut offset = 0;
    for &n in &counts {
        let invocations = ROUNDS * n * PIXELS.len() as u32;
        let uniforms = FrameUniforms {
            width: WIDTH,
            height: 1080,
            samples_per_pixel: n,
            ..bytemuck::Zeroable::zeroed()
        };
        let uniform_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("frame"),
            contents: bytemuck::bytes_of(&uniforms),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let size = u64::from(invocations) * 8;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("offsets"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sample offsets"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: pixel_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(invocations.div_ceil(64), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &readback, offset, size);
        offset += size;
        keep_alive.push((uniform_buffer, output));
    }
    queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("maps"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("device polls");
    let data = readback.slice(..).get_mapped_range().expect("mapped");
    let gpu_offsets: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&data);

    let mut worst: f64 = 0.0;
    let mut results = gpu_offsets.iter();
    for &n in &counts {
        let settings = RenderSettings {
            width: WIDTH,
            height: 1080,
            samples_per_pixel: n,
            ..RenderSettings::default()
        };
        for [px, py] in PIXELS {
            for index in 0..ROUNDS * n {
                let Some(&[gx, gy]) = results.next() else {
                    panic!("the GPU returned too few offsets");
                };
                let (cx, cy) = sample_offset(px, py, index, &settings);
                let error = (f64::from(gx) - cx).abs().max((f64::from(gy) - cy).abs());
                assert!(
                    error <= TOLERANCE,
                    "n={n} pixel ({px}, {py}) sample {index}: GPU ({gx}, {gy}), CPU ({cx}, {cy})"
                );
                worst = worst.max(error);
            }
        }
    }
    eprintln!(
        "{} sample offsets: largest GPU-CPU difference {worst:.2e}",
        gpu_offsets.len()
    );
}
