//! The WGSL BRDFs (`shaders/bxdf.wgsl`) against their CPU twins (`src/cpu/bxdf.rs`):
//! a test kernel (`shaders/bxdf_eval.wgsl`, composed with `types.wgsl`,
//! `texture.wgsl` and `bxdf.wgsl`) evaluates `eval_brdf` for every model on a grid of
//! direction pairs and parameters (14,400 cases), and each channel must match the
//! CPU's within `|gpu - cpu| <= 2e-4·|cpu| + 1e-6` (measured on lavapipe: largest
//! relative difference 1.5e-4, recorded in docs/materials.md). The CPU evaluates the
//! f32-rounded directions in f64, so the difference is the GPU's own rounding.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use gpu_render::low_level::accel::BrdfMapCdfs;
use gpu_render::low_level::cpu::bxdf::eval_brdf;
use gpu_render::low_level::gpu::shaders::{BXDF_EVAL_ENTRY_POINT, bxdf_eval_shader_source};
use gpu_render::low_level::gpu::upload::{image_layers, material_record};
use gpu_render::scene::{
    CONDUCTOR_PRESETS, FresnelModel, Image, Material, MaterialKind, MicrofacetDistribution,
    load_image,
};
use wgpu::util::DeviceExt;

/// Relative tolerance on each channel: `|gpu - cpu| <= REL·|cpu| + ABS`.
const REL: f64 = 2e-4;
/// Absolute floor, for values near zero (1/sr).
const ABS: f64 = 1e-6;

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct BrdfCase {
    material: u32,
    _pad: [u32; 3],
    n: [f32; 4],
    wi: [f32; 4],
    wo: [f32; 4],
}

fn materials() -> Vec<Material> {
    let mut list = vec![Material::lambert(DVec3::new(0.8, 0.5, 0.2))];
    list.push(Material {
        diffuse: DVec3::splat(0.4),
        specular: DVec3::splat(0.5),
        shininess: 40.0,
        ..Material::blank(MaterialKind::BlinnPhong)
    });
    for sigma in [0.0, 25.0, 60.0] {
        list.push(Material {
            diffuse: DVec3::new(0.9, 0.6, 0.3),
            sigma: f64::to_radians(sigma),
            ..Material::blank(MaterialKind::OrenNayar)
        });
    }
    for roughness in [0.2, 0.5, 0.9] {
        for distribution in [
            MicrofacetDistribution::Ggx,
            MicrofacetDistribution::Beckmann,
        ] {
            for fresnel in [FresnelModel::Exact, FresnelModel::Schlick] {
                for (_, eta, k) in CONDUCTOR_PRESETS {
                    list.push(Material {
                        conductor: true,
                        eta: DVec3::from_array(*eta),
                        k: DVec3::from_array(*k),
                        roughness,
                        distribution,
                        fresnel,
                        ..Material::blank(MaterialKind::CookTorrance)
                    });
                }
                list.push(Material {
                    ior: 1.5,
                    diffuse: DVec3::new(0.5, 0.1, 0.1),
                    roughness,
                    distribution,
                    fresnel,
                    ..Material::blank(MaterialKind::CookTorrance)
                });
            }
        }
        for metallic in [0.0, 0.5, 1.0] {
            list.push(Material {
                diffuse: DVec3::new(0.9, 0.6, 0.5),
                metallic,
                roughness,
                ..Material::blank(MaterialKind::Pbr)
            });
        }
    }
    // The near-Lambertian map and the glossy one, whose steep lobe amplifies any error
    // in the angles.
    for map in [0, 1] {
        list.push(Material {
            brdf_map: Some(map),
            ..Material::blank(MaterialKind::Tabulated)
        });
    }
    list
}

fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

fn f32x4(v: DVec3) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, 0.0]
}

/// The direction as the GPU sees it, rounded to f32, back in f64 for the CPU.
fn rounded(v: [f32; 4]) -> DVec3 {
    DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}

#[test]
fn wgsl_brdfs_match_the_cpu_reference() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/brdf");
    let images: Vec<Image> = ["plausible.png", "glossy.exr"]
        .iter()
        .map(|file| load_image(&maps.join(file)).expect("map loads"))
        .collect();
    let materials = materials();
    // A tilted normal, so that no axis is special.
    let n = DVec3::new(0.2, 1.0, -0.1).normalize();
    let to_world = glam::DQuat::from_rotation_arc(DVec3::Y, n);
    let mut cases = Vec::new();
    for (index, _) in materials.iter().enumerate() {
        for a in 0..8 {
            for b in 0..8 {
                for p in 0..3 {
                    let wi = to_world * direction(f64::from(a) * 0.19 + 0.05, 0.3);
                    let wo =
                        to_world * direction(f64::from(b) * 0.19 + 0.07, 0.3 + f64::from(p) * 1.2);
                    cases.push(BrdfCase {
                        material: index as u32,
                        _pad: [0; 3],
                        n: f32x4(n),
                        wi: f32x4(wi),
                        wo: f32x4(wo),
                    });
                }
            }
        }
    }
    let records: Vec<_> = materials
        .iter()
        .map(|m| material_record(m, &images))
        .collect();
    let gpu_values = evaluate(device, queue, &records, &cases, &images);

    let mut worst_relative: f64 = 0.0;
    for (case, value) in cases.iter().zip(&gpu_values) {
        let m = &materials[case.material as usize];
        let cpu = eval_brdf(
            m,
            &images,
            rounded(case.n),
            rounded(case.wi),
            rounded(case.wo),
        );
        for c in 0..3 {
            let (g, e) = (f64::from(value[c]), cpu[c]);
            let error = (g - e).abs();
            assert!(
                error <= REL * e.abs() + ABS,
                "{:?} (material {}): channel {c}: GPU {g}, CPU {e}",
                m.kind,
                case.material
            );
            if e.abs() > 1e-3 {
                worst_relative = worst_relative.max(error / e.abs());
            }
        }
    }
    eprintln!(
        "{} BRDF values: largest relative GPU-CPU difference {worst_relative:.2e}",
        cases.len() * 3
    );
}

fn evaluate(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    materials: &[gpu_render::low_level::gpu::layout::GpuMaterial],
    cases: &[BrdfCase],
    images: &[Image],
) -> Vec<[f32; 4]> {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("bxdf eval"),
        source: wgpu::ShaderSource::Wgsl(bxdf_eval_shader_source().into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("bxdf eval"),
        layout: None,
        module: &module,
        entry_point: Some(BXDF_EVAL_ENTRY_POINT),
        compilation_options: Default::default(),
        cache: None,
    });
    let storage = |label, bytes: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage,
        })
    };
    let material_buffer = storage(
        "materials",
        bytemuck::cast_slice(materials),
        wgpu::BufferUsages::STORAGE,
    );
    let case_buffer = storage(
        "cases",
        bytemuck::cast_slice(cases),
        wgpu::BufferUsages::STORAGE,
    );
    let size = (cases.len() * 16) as u64;
    let values = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("values"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    // The BRDFs read no inverse-CDF tables.
    let (width, height, layers, texels) = image_layers(images, &BrdfMapCdfs::default());
    let extent = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: layers,
    };
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("images"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&texels),
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bxdf eval"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: material_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: case_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: values.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 11,
                resource: wgpu::BindingResource::TextureView(&view),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&values, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("maps"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("device polls");
    let data = readback.slice(..).get_mapped_range().expect("mapped");
    bytemuck::pod_collect_to_vec(&data)
}
