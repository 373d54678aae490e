//! Measures how fast lavapipe loads data with per-lane indices from a storage
//! buffer, a uniform buffer and a float texture (a probe for the data layout).
use gpu_render::gpu::{AdapterChoice, HeadlessGpu};
use std::time::Instant;
use wgpu::util::DeviceExt;

const SHADER: &str = r"
@group(0) @binding(0) var<storage, read> data: array<vec4<f32>>;
@group(0) @binding(1) var<uniform> udata: array<vec4<f32>, 1024>;
@group(0) @binding(2) var tdata: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(256)
fn from_storage(@builtin(global_invocation_id) id: vec3<u32>) {
    var acc = vec4<f32>(0.0);
    var i = id.x * 7u;
    for (var k = 0u; k < 64u; k += 1u) {
        acc += data[i & 1023u];
        i = i * 1664525u + 1013904223u + u32(acc.x);
    }
    out[id.x] = acc;
}

@compute @workgroup_size(256)
fn from_uniform(@builtin(global_invocation_id) id: vec3<u32>) {
    var acc = vec4<f32>(0.0);
    var i = id.x * 7u;
    for (var k = 0u; k < 64u; k += 1u) {
        acc += udata[i & 1023u];
        i = i * 1664525u + 1013904223u + u32(acc.x);
    }
    out[id.x] = acc;
}

@compute @workgroup_size(256)
fn from_texture(@builtin(global_invocation_id) id: vec3<u32>) {
    var acc = vec4<f32>(0.0);
    var i = id.x * 7u;
    for (var k = 0u; k < 64u; k += 1u) {
        let j = i & 1023u;
        acc += textureLoad(tdata, vec2<u32>(j & 31u, j >> 5u), 0);
        i = i * 1664525u + 1013904223u + u32(acc.x);
    }
    out[id.x] = acc;
}

@compute @workgroup_size(256)
fn no_load(@builtin(global_invocation_id) id: vec3<u32>) {
    var acc = vec4<f32>(0.0);
    var i = id.x * 7u;
    for (var k = 0u; k < 64u; k += 1u) {
        acc += vec4<f32>(f32(i & 1023u));
        i = i * 1664525u + 1013904223u + u32(acc.x);
    }
    out[id.x] = acc;
}
";

fn main() {
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("gpu");
    let device = &gpu.device;
    let values: Vec<[f32; 4]> = (0..1024).map(|i| [i as f32 * 1e-6; 4]).collect();
    let storage = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&values),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&values),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: 32,
            height: 32,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&values),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(32 * 16),
            rows_per_image: Some(32),
        },
        wgpu::Extent3d {
            width: 32,
            height: 32,
            depth_or_array_layers: 1,
        },
    );
    let n = 1u32 << 18;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(n) * 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let view = texture.create_view(&Default::default());
    for entry in [
        "no_load",
        "from_storage",
        "from_uniform",
        "from_texture",
        "no_load",
        "from_storage",
        "from_uniform",
        "from_texture",
    ] {
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        let layout = pipeline.get_bind_group_layout(0);
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 3,
            resource: out.as_entire_binding(),
        }];
        match entry {
            "from_storage" => entries.push(wgpu::BindGroupEntry {
                binding: 0,
                resource: storage.as_entire_binding(),
            }),
            "from_uniform" => entries.push(wgpu::BindGroupEntry {
                binding: 1,
                resource: uniform.as_entire_binding(),
            }),
            "from_texture" => entries.push(wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&view),
            }),
            _ => {}
        }
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &entries,
        });
        let run = || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(n / 256, 1, 1);
            }
            gpu.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        };
        run();
        let t = Instant::now();
        for _ in 0..5 {
            run();
        }
        let per = t.elapsed().as_secs_f64() / 5.0;
        println!(
            "{entry}: {:.2} ms for {} loads of vec4 ({:.2} ns per lane-load)",
            per * 1e3,
            n as u64 * 64,
            per * 1e9 / (n as f64 * 64.0)
        );
    }
}
