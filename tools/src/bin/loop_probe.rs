//! Does the driver cut long loops? Runs a loop of N iterations and reads the count.
use gpu_render::gpu::{AdapterChoice, HeadlessGpu};
const SHADER: &str = r"
@group(0) @binding(0) var<storage, read_write> out: array<u32>;
@compute @workgroup_size(1)
fn count(@builtin(global_invocation_id) id: vec3<u32>) {
    var n = 0u;
    loop {
        if n >= out[0] { break; }
        n += 1u;
    }
    out[1] = n;
}
";
fn main() {
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("gpu");
    let d = &gpu.device;
    let buf = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 8,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let m = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let p = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &m,
        entry_point: Some("count"),
        compilation_options: Default::default(),
        cache: None,
    });
    let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &p.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buf.as_entire_binding(),
        }],
    });
    for n in [1000u32, 65_535, 65_536, 100_000, 10_000_000] {
        gpu.queue
            .write_buffer(&buf, 0, bytemuck::cast_slice(&[n, 0u32]));
        let mut e = d.create_command_encoder(&Default::default());
        {
            let mut pass = e.begin_compute_pass(&Default::default());
            pass.set_pipeline(&p);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        e.copy_buffer_to_buffer(&buf, 0, &read, 0, 8);
        gpu.queue.submit([e.finish()]);
        read.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        let v: Vec<u32> = bytemuck::pod_collect_to_vec(&read.slice(..).get_mapped_range().unwrap());
        read.unmap();
        println!("asked {n}, counted {}", v[1]);
    }
    println!("{:?}", gpu.adapter_info());
}
