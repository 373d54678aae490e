//! How a GPU device pays for scattered reads: a probe for the engine's speed on CPU
//! devices (issue 8, BENCHMARKS.md "Scattered reads on lavapipe").
//!
//! Every invocation follows a chain of dependent random indices into a table of
//! `SIDE`² `vec4<f32>` (the argument, a power of two; 1024 by default: 16 MiB; 64:
//! 64 KiB, which stays in the caches), as a BVH traversal follows its nodes, and sums
//! what it reads. The same chain runs four ways: from a storage buffer or with `textureLoad`
//! from an `Rgba32Float` texture, with indices that differ per lane (divergent, as
//! rays' nodes do) or that every lane shares (uniform, the best case). The median
//! of five timed dispatches of each is printed, in nanoseconds per read per
//! invocation.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin gather_probe          # 16 MiB table
//! cargo run --release -p gpu-render-tools --bin gather_probe -- 64    # 64 KiB table
//! ```

use std::time::Instant;

use anyhow::{Context, Result};
use gpu_render::gpu::{AdapterChoice, HeadlessGpu};
use wgpu::util::DeviceExt;

/// Invocations per dispatch.
const INVOCATIONS: u32 = 1 << 16;
/// Dependent reads per invocation.
const READS: u32 = 256;
/// Timed dispatches per variant.
const RUNS: usize = 5;

const SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> table: array<vec4<f32>>;
@group(0) @binding(1) var image: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> sums: array<f32>;

const SIDE: u32 = SIDE_VALUEu;
const READS: u32 = 256u;

// PCG's RXS-M-XS output permutation as a hash (Jarzynski and Olano, JCGT 9(3), 2020).
fn hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The next index of the chain: from the value read (so that each read depends on the
// one before, as a traversal's does) and, when divergent, the invocation.
fn next_index(previous: vec4<f32>, lane: u32, step: u32) -> u32 {
    return hash(bitcast<u32>(previous.x) ^ lane ^ step) & (SIDE * SIDE - 1u);
}

@compute @workgroup_size(64)
fn buffer_divergent(@builtin(global_invocation_id) id: vec3<u32>) {
    var value = vec4<f32>(0.0);
    var sum = 0.0;
    for (var i = 0u; i < READS; i += 1u) {
        value = table[next_index(value, id.x, i)];
        sum += value.y;
    }
    sums[id.x] = sum;
}

@compute @workgroup_size(64)
fn buffer_uniform(@builtin(global_invocation_id) id: vec3<u32>) {
    var value = vec4<f32>(0.0);
    var sum = 0.0;
    for (var i = 0u; i < READS; i += 1u) {
        value = table[next_index(value, 0u, i)];
        sum += value.y;
    }
    sums[id.x] = sum;
}

@compute @workgroup_size(64)
fn texture_divergent(@builtin(global_invocation_id) id: vec3<u32>) {
    var value = vec4<f32>(0.0);
    var sum = 0.0;
    for (var i = 0u; i < READS; i += 1u) {
        let k = next_index(value, id.x, i);
        value = textureLoad(image, vec2<u32>(k % SIDE, k / SIDE), 0);
        sum += value.y;
    }
    sums[id.x] = sum;
}

@compute @workgroup_size(64)
fn texture_uniform(@builtin(global_invocation_id) id: vec3<u32>) {
    var value = vec4<f32>(0.0);
    var sum = 0.0;
    for (var i = 0u; i < READS; i += 1u) {
        let k = next_index(value, 0u, i);
        value = textureLoad(image, vec2<u32>(k % SIDE, k / SIDE), 0);
        sum += value.y;
    }
    sums[id.x] = sum;
}
"#;

fn main() -> Result<()> {
    let side: u32 = match std::env::args().nth(1) {
        Some(text) => text
            .parse()
            .context("the table side must be a whole number")?,
        None => 1024,
    };
    anyhow::ensure!(
        side.is_power_of_two() && (8..=4096).contains(&side),
        "the table side must be a power of two from 8 to 4096, not {side}"
    );
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).context("no GPU adapter")?;
    let info = gpu.adapter_info();
    println!(
        "adapter: {} ({}); table {side}x{side} vec4<f32>",
        info.name, info.driver_info
    );
    let (device, queue) = (&gpu.device, &gpu.queue);

    let entries = (side * side) as usize;
    let data: Vec<[f32; 4]> = (0..entries)
        .map(|i| {
            let x = i as f32;
            [x, 1.0 / (1.0 + x), x * 0.5, 1.0]
        })
        .collect();
    let table = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("gather probe table"),
        contents: bytemuck::cast_slice(&data),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = wgpu::Extent3d {
        width: side,
        height: side,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("gather probe image"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&data),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(side * 16),
            rows_per_image: Some(side),
        },
        size,
    );
    let view = texture.create_view(&Default::default());
    let sums = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("gather probe sums"),
        size: u64::from(INVOCATIONS) * 4,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("gather probe"),
        source: wgpu::ShaderSource::Wgsl(SHADER.replace("SIDE_VALUE", &side.to_string()).into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gather probe layout"),
        entries: &[
            storage_entry(0, true),
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            storage_entry(2, false),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("gather probe pipeline layout"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("gather probe bind group"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: table.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: sums.as_entire_binding(),
            },
        ],
    });
    let variants = [
        "buffer_divergent",
        "texture_divergent",
        "buffer_uniform",
        "texture_uniform",
    ];
    let pipelines: Vec<wgpu::ComputePipeline> = variants
        .iter()
        .map(|entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            })
        })
        .collect();
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); variants.len()];
    // One untimed round, then alternating timed rounds.
    for round in 0..=RUNS {
        for (pipeline, variant_times) in pipelines.iter().zip(times.iter_mut()) {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(INVOCATIONS / 64, 1, 1);
            }
            let start = Instant::now();
            let index = queue.submit([encoder.finish()]);
            device
                .poll(wgpu::PollType::Wait {
                    submission_index: Some(index),
                    timeout: None,
                })
                .context("the device was lost")?;
            if round > 0 {
                variant_times.push(start.elapsed().as_secs_f64());
            }
        }
    }
    let reads = f64::from(INVOCATIONS) * f64::from(READS);
    for (variant, variant_times) in variants.iter().zip(times.iter_mut()) {
        variant_times.sort_by(f64::total_cmp);
        let median = variant_times[variant_times.len() / 2];
        println!(
            "{variant:18} median {:.1} ms, {:.2} ns per read ({} runs: {})",
            median * 1e3,
            median / reads * 1e9,
            variant_times.len(),
            variant_times
                .iter()
                .map(|t| format!("{:.1}", t * 1e3))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    Ok(())
}

/// A compute-stage storage-buffer entry of the probe's layout.
fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
