//! Times a scene on the GPU backend and on the CPU reference, alternating the two so
//! that both see the same machine load, and prints medians.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin bench -- scenes/showcase.toml --width 1920 --height 1080 --runs 3
//! ```
//!
//! With `--specialisation`, it instead compares the trace pipeline specialised to the
//! scene with the general one that contains every feature: pipeline creation, time to
//! the first (tiny) frame, which on lavapipe includes the LLVM compile that happens at
//! the first dispatch, and the median trace time of alternating runs.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin bench -- scenes/glass.toml --width 640 --height 480 --specialisation
//! ```
//!
//! "trace" is the tracing work alone (`RenderStats::elapsed`: wall time of the GPU
//! submissions of the trace pass, or of the CPU threads); "GPU timestamps" is the GPU's
//! own time of the trace passes (`RenderStats::gpu_time`), printed where the device has
//! timestamp queries; "total" adds the display pass and readback on the GPU. Rays are
//! counted by the tracers as they trace them, not estimated.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Parser;
use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, Schedule};
use gpu_render::gpu::{RendererOptions, Traversal};
use gpu_render::scene::{RenderOverrides, load_scene};

#[derive(Parser)]
struct Args {
    /// Scene file, `generated:million` for the million-triangle terrain, or
    /// `generated:instances` for 100 placements of one million-triangle mesh.
    scene: PathBuf,
    /// Image width override.
    #[arg(long)]
    width: Option<u32>,
    /// Image height override.
    #[arg(long)]
    height: Option<u32>,
    /// Samples-per-pixel override.
    #[arg(long)]
    spp: Option<u32>,
    /// Timed runs per backend (after one warm-up run of each).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Skip the CPU reference.
    #[arg(long)]
    gpu_only: bool,
    /// Compare the specialised trace pipeline with the general one.
    #[arg(long)]
    specialisation: bool,
    /// Compare the fused and the wavefront schedule of the GPU kernels.
    #[arg(long)]
    schedules: bool,
    /// Print each trace kernel's compile (its first dispatch, at upload) and its WGSL
    /// size, for the scene's kernels; run it with an empty driver cache
    /// (`MESA_SHADER_CACHE_DIR`) for a cold compile.
    #[arg(long)]
    compile: bool,
    /// With `--compile`: the general kernels (every feature) rather than the scene's.
    #[arg(long)]
    general: bool,
    /// The GPU schedule: `fused` or `wavefront` (default: the adapter's).
    #[arg(long)]
    schedule: Option<String>,
    /// Keep the scene records in storage buffers, not in uniform buffers where they
    /// fit on a CPU device nor the BVH nodes in a texture (and the small records in
    /// uniform buffers) where they do not
    /// (`RendererOptions::uniform_records` false).
    #[arg(long)]
    storage_records: bool,
    /// The fused kernel's traversals give way to finished lanes where the device has
    /// subgroup operations (`RendererOptions::refill_lanes`, off by default).
    #[arg(long)]
    refill: bool,
    /// The fused kernel's Whitted samples do not start in lockstep
    /// (`RendererOptions::lockstep_samples` false).
    #[arg(long)]
    no_lockstep: bool,
    /// Small scenes walk their BVH too (`RendererOptions::unrolled` false).
    #[arg(long)]
    no_unrolled: bool,
    /// Path slots of the GPU trace (default: the adapter's, `default_slot_count`).
    #[arg(long)]
    slots: Option<u32>,
    /// Print the BVH's build figures and the nodes and primitives a camera ray and a
    /// shadow ray (to the first light) visit on average, counted by the CPU traversal
    /// at one ray per pixel.
    #[arg(long)]
    traversal: bool,
    /// How the GPU finds the triangles: `auto`, `software` or `hardware` (ray queries;
    /// `RendererOptions::traversal`).
    #[arg(long, default_value = "auto")]
    gpu_traversal: String,
    /// Placements in `generated:instances`.
    #[arg(long, default_value_t = 100)]
    copies: usize,
    /// Flatten `generated:instances` by hand (every placement a world-space mesh of
    /// its own, placed once), to compare with instancing.
    #[arg(long)]
    flatten: bool,
    /// Quads per side of the mesh of `generated:instances` (708: 1,001,112 triangles).
    #[arg(long, default_value_t = 708)]
    mesh_quads: usize,
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// The million-triangle benchmark scene, generated: a terrain of 708 x 708 quads (two
/// triangles each, 1,002,528 triangles) under a sun and a point light, three Lambert
/// spheres, a mirror sphere and a glass sphere; 1920x1080, 1 spp, depth 4.
fn million_triangle_scene() -> gpu_render::scene::Scene {
    use glam::DVec3;
    use gpu_render::scene::{
        Camera, Environment, Light, LightingSpace, Material, MaterialKind, RenderSettings, Scene,
        Shape,
    };
    let n = 708;
    let size = 40.0;
    let height = |i: usize, j: usize| {
        let (x, z) = (
            i as f64 / n as f64 * size - size / 2.0,
            j as f64 / n as f64 * size - size / 2.0,
        );
        0.6 * (0.35 * x).sin() * (0.3 * z).cos()
            + 0.15 * (1.7 * x + 0.4).sin() * (1.3 * z).sin()
            + 0.04 * (7.0 * x).cos() * (6.0 * z + 1.0).sin()
    };
    let point = |i: usize, j: usize| {
        DVec3::new(
            i as f64 / n as f64 * size - size / 2.0,
            height(i, j) - 1.0,
            j as f64 / n as f64 * size - size / 2.0,
        )
    };
    let mut shapes = Vec::with_capacity(2 * n * n + 8);
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            shapes.push(Shape::Triangle {
                vertices: [a, d, c],
                material: 0,
            });
            shapes.push(Shape::Triangle {
                vertices: [a, c, b],
                material: 0,
            });
        }
    }
    for (k, (x, z)) in [(-3.0, -2.0), (0.0, -4.0), (3.0, -2.5)]
        .into_iter()
        .enumerate()
    {
        shapes.push(Shape::Sphere {
            center: DVec3::new(x, 0.2, z),
            radius: 0.9,
            material: 1 + k as u32 % 2,
        });
    }
    shapes.push(Shape::Sphere {
        center: DVec3::new(-1.2, 0.3, 0.5),
        radius: 0.8,
        material: 3,
    });
    shapes.push(Shape::Sphere {
        center: DVec3::new(1.5, 0.3, 0.8),
        radius: 0.8,
        material: 4,
    });
    let lambert = |r, g, b| Material::lambert(DVec3::new(r, g, b));
    Scene {
        render: RenderSettings {
            width: 1920,
            height: 1080,
            samples_per_pixel: 1,
            max_depth: 4,
            stack_size: 5,
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: gpu_render::scene::Integrator::Whitted,
            texture_filtering: gpu_render::scene::TextureFiltering::default(),
        },
        camera: Camera {
            eye: DVec3::new(0.0, 2.5, 7.0),
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_y_degrees: 55.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment {
            background: DVec3::new(0.35, 0.45, 0.6),
            ambient: DVec3::ZERO,
            map: None,
        },
        materials: vec![
            lambert(0.45, 0.5, 0.35),
            lambert(0.8, 0.3, 0.25),
            lambert(0.25, 0.4, 0.8),
            Material {
                reflectance: DVec3::splat(0.9),
                ..Material::blank(MaterialKind::Mirror)
            },
            Material {
                ior: 1.5,
                ..Material::blank(MaterialKind::Dielectric)
            },
        ],
        material_names: ["terrain", "red", "blue", "mirror", "glass"]
            .map(String::from)
            .to_vec(),
        lights: vec![
            Light::Directional {
                direction: DVec3::new(-0.4, -1.0, -0.3).normalize(),
                irradiance: DVec3::splat(2.5),
            },
            Light::Point {
                position: DVec3::new(2.0, 4.0, 3.0),
                intensity: DVec3::splat(15.0),
            },
        ],
        shapes,
        meshes: vec![],
        images: vec![],
    }
}

/// The instancing benchmark scene, generated: one smooth bumpy sphere of 708 x 708
/// quads (1,001,112 triangles, vertex normals) placed 100 times on a 10 x 10 grid,
/// each rotated and scaled differently (every seventh mirrored), in four materials,
/// over a ground plane under a sun and a point light; 1920x1080, 1 spp, depth 4.
fn instanced_million_scene(
    copies: usize,
    flatten: bool,
    mesh_quads: usize,
) -> gpu_render::scene::Scene {
    use glam::{DMat3, DMat4, DVec3};
    use gpu_render::scene::{Mesh, Shape};
    let mut scene = million_triangle_scene();
    let n = mesh_quads.max(2);
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    let mut normals = Vec::with_capacity((n + 1) * (n + 1));
    for r in 0..=n {
        let theta = std::f64::consts::PI * r as f64 / n as f64;
        for s in 0..=n {
            let phi = std::f64::consts::TAU * s as f64 / n as f64;
            let direction = DVec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            let radius = 1.0 + 0.08 * (9.0 * theta).sin() * (7.0 * phi).cos();
            positions.push(direction * radius * 0.5);
            normals.push(direction);
        }
    }
    let index = |r: usize, s: usize| (r * (n + 1) + s) as u32;
    let mut triangles = Vec::with_capacity(2 * n * n);
    for r in 0..n {
        for s in 0..n {
            let (a, b, c, d) = (
                index(r, s),
                index(r + 1, s),
                index(r + 1, s + 1),
                index(r, s + 1),
            );
            if r > 0 {
                triangles.push([a, d, c]);
            }
            if r + 1 < n {
                triangles.push([a, c, b]);
            }
        }
    }
    let mut meshes: Vec<Mesh> = Vec::new();
    for k in 0..copies {
        let (i, j) = ((k % 10) as f64, (k / 10) as f64);
        let mirror = if k % 7 == 3 { -1.0 } else { 1.0 };
        let scale = DVec3::new(mirror * (0.8 + 0.04 * i), 0.7 + 0.05 * j, 0.9);
        let transform = DMat4::from_scale_rotation_translation(
            scale,
            glam::DQuat::from_rotation_y(0.37 * k as f64),
            DVec3::new(1.4 * i - 6.3, -0.4, -1.4 * j + 1.0),
        );
        let material = (k % 4) as u32 + 1;
        if flatten {
            let linear = DMat3::from_mat4(transform);
            let normal_matrix = linear.inverse().transpose();
            let mirrored = linear.determinant() < 0.0;
            meshes.push(Mesh {
                name: format!("bumpy sphere {k}"),
                positions: positions
                    .iter()
                    .map(|p| transform.transform_point3(*p))
                    .collect(),
                normals: Some(
                    normals
                        .iter()
                        .map(|n| (normal_matrix * *n).normalize())
                        .collect(),
                ),
                uvs: None,
                uvs1: None,
                colors: None,
                tangents: None,
                triangles: triangles
                    .iter()
                    .map(|&[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] })
                    .collect(),
                material,
                instances: vec![DMat4::IDENTITY],
            });
            continue;
        }
        match meshes.iter_mut().find(|m| m.material == material) {
            Some(mesh) => mesh.instances.push(transform),
            None => meshes.push(Mesh {
                name: "bumpy sphere".into(),
                positions: positions.clone(),
                normals: Some(normals.clone()),
                uvs: None,
                uvs1: None,
                colors: None,
                tangents: None,
                triangles: triangles.clone(),
                material,
                instances: vec![transform],
            }),
        }
    }
    scene.shapes = vec![Shape::Plane {
        normal: DVec3::Y,
        offset: -1.0,
        material: 0,
    }];
    scene.meshes = meshes;
    scene.camera.eye = DVec3::new(0.0, 4.0, 7.0);
    scene.camera.look_at = DVec3::new(0.0, -0.5, -4.0);
    scene
}

/// Prints what instancing stores for `scene` and how long its geometry takes to build.
fn instancing_figures(scene: &gpu_render::scene::Scene) {
    let started = Instant::now();
    let geometry = gpu_render::low_level::accel::SceneGeometry::new(scene);
    let built = started.elapsed().as_secs_f64();
    if geometry.instances.is_empty() {
        return;
    }
    let stored: usize = geometry
        .instanced_meshes
        .iter()
        .map(|m| m.triangles.len())
        .sum();
    // What the instanced meshes' triangles take on the GPU (records, attributes, their
    // trees' nodes and references), and what flattening every placement would take.
    let mesh_bytes: usize =
        geometry
            .instanced_meshes
            .iter()
            .map(|m| {
                m.triangles.len()
                    * std::mem::size_of::<gpu_render::low_level::gpu::layout::GpuTriangle>()
                    + m.triangle_attributes.len()
                        * std::mem::size_of::<
                            gpu_render::low_level::gpu::layout::GpuTriangleAttributes,
                        >()
                    + m.bvh.wide.len()
                        * std::mem::size_of::<gpu_render::low_level::accel::WideNode>()
                    + m.bvh.prims.len() * 4
            })
            .sum();
    let flattened =
        mesh_bytes as f64 / stored.max(1) as f64 * geometry.instanced_triangle_count() as f64;
    println!(
        "instancing: {} instances of {} mesh(es), {stored} triangles stored for {} placed; \
         geometry (every BVH) built in {:.0} ms; the stored meshes take {mesh_bytes} bytes \
         on the GPU, flattened they would take about {:.2} GB",
        geometry.instances.len(),
        geometry.instanced_meshes.len(),
        geometry.instanced_triangle_count(),
        built * 1e3,
        flattened / 1e9
    );
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut scene = if args.scene.as_os_str() == "generated:million" {
        million_triangle_scene()
    } else if args.scene.as_os_str() == "generated:instances" {
        instanced_million_scene(args.copies, args.flatten, args.mesh_quads)
    } else {
        load_scene(&args.scene)?
    };
    scene.render = scene
        .render
        .with_overrides(&RenderOverrides {
            width: args.width,
            height: args.height,
            samples_per_pixel: args.spp,
            ..RenderOverrides::default()
        })
        .map_err(anyhow::Error::msg)?;
    if args.traversal {
        traversal_figures(&scene);
    }
    instancing_figures(&scene);
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).context("no GPU adapter")?;
    let schedule = match args.schedule.as_deref() {
        None => None,
        Some("fused") => Some(Schedule::Fused),
        Some("wavefront") => Some(Schedule::Wavefront),
        Some(other) => anyhow::bail!("--schedule must be fused or wavefront, not {other}"),
    };
    let traversal = match args.gpu_traversal.as_str() {
        "auto" => Traversal::Auto,
        "software" => Traversal::Software,
        "hardware" => Traversal::Hardware,
        other => anyhow::bail!("--gpu-traversal must be auto, software or hardware, not {other}"),
    };
    let renderer = Renderer::new(
        &gpu.device,
        RendererOptions {
            uniform_records: !args.storage_records,
            refill_lanes: args.refill,
            lockstep_samples: !args.no_lockstep,
            unrolled: !args.no_unrolled,
            slot_count: args.slots,
            schedule,
            traversal,
            ..RendererOptions::default()
        },
    )?;
    let info = gpu.adapter_info();
    println!(
        "scene {} at {}x{}, {} spp, max depth {}; adapter: {} ({:?}); CPU threads: {}",
        args.scene.display(),
        scene.render.width,
        scene.render.height,
        scene.render.samples_per_pixel,
        scene.render.max_depth,
        info.name,
        info.backend,
        std::thread::available_parallelism().map_or(1, usize::from)
    );
    if args.specialisation {
        return compare_specialisation(&gpu, &scene, args.runs, !args.no_lockstep);
    }
    if args.schedules {
        return compare_schedules(&gpu, &scene, args.runs);
    }
    if args.compile {
        let options = RendererOptions {
            specialise: !args.general,
            uniform_records: !args.storage_records,
            lockstep_samples: !args.no_lockstep,
            unrolled: !args.no_unrolled,
            schedule,
            traversal,
            ..RendererOptions::default()
        };
        return compile_figures(&gpu, &scene, options);
    }
    // Warm-up: the first dispatch compiles the pipeline (lavapipe runs LLVM then).
    renderer.render(&gpu.device, &gpu.queue, &scene, None)?;
    let prepared = renderer.upload(&gpu.device, &gpu.queue, &scene)?;
    let primitives = gpu_render::low_level::accel::SceneGeometry::new(&scene).bounded_count();
    println!(
        "GPU scene buffers: {} bytes for {primitives} bounded primitives ({:.1} bytes each, \
         BVH included); BVH built in {:.1} ms; records in {} buffers{}; closest hit {}; \
         triangles by {}",
        prepared.scene_bytes(),
        prepared.scene_bytes() as f64 / primitives.max(1) as f64,
        prepared.bvh_stats().build_time.as_secs_f64() * 1e3,
        if prepared.features().uniform_records {
            "uniform"
        } else {
            "storage"
        },
        if prepared.features().node_texture {
            " (planes, materials and lights uniform), BVH nodes in a storage texture"
        } else {
            ""
        },
        if prepared.features().unrolled.is_some() {
            "unrolled"
        } else {
            "by the BVH"
        },
        if prepared.features().hardware_traversal {
            "ray query"
        } else {
            "the software BVH walk"
        }
    );
    drop(prepared);
    if !args.gpu_only {
        gpu_render::cpu::render(&scene, None);
    }
    let (mut gpu_trace, mut gpu_total, mut cpu_trace) = (vec![], vec![], vec![]);
    // GPU timestamp times, `None` for a run without them.
    let mut gpu_timestamps = vec![];
    let (mut gpu_rays, mut cpu_rays) = (0, 0);
    for _ in 0..args.runs {
        let started = Instant::now();
        let rendered = renderer.render(&gpu.device, &gpu.queue, &scene, None)?;
        gpu_total.push(started.elapsed().as_secs_f64());
        gpu_trace.push(rendered.stats.elapsed.as_secs_f64());
        gpu_timestamps.push(rendered.stats.gpu_time.map(|t| t.as_secs_f64()));
        gpu_rays = rendered.stats.rays_traced;
        if !args.gpu_only {
            let rendered = gpu_render::cpu::render(&scene, None);
            cpu_trace.push(rendered.stats.elapsed.as_secs_f64());
            cpu_rays = rendered.stats.rays_traced;
        }
    }
    let samples = f64::from(scene.render.width)
        * f64::from(scene.render.height)
        * f64::from(scene.render.samples_per_pixel);
    let report = |name: &str, trace: f64, total: Option<f64>, rays: u64| {
        let total = total.map_or(String::new(), |t| format!(", total {:.3} s", t));
        println!(
            "{name}: trace {:.3} s (wall clock){total}; {rays} rays; {:.1} Mrays/s; {:.2} M \
             samples/s",
            trace,
            rays as f64 / trace / 1e6,
            samples / trace / 1e6
        );
    };
    report(
        "GPU",
        median(gpu_trace.clone()),
        Some(median(gpu_total)),
        gpu_rays,
    );
    // Timestamps come from the device's features, so every run has them or none does.
    match gpu_timestamps.into_iter().collect::<Option<Vec<f64>>>() {
        Some(times) if !times.is_empty() => {
            let gpu = median(times);
            println!(
                "GPU: trace passes {:.3} s (GPU timestamps); {:.1} Mrays/s",
                gpu,
                gpu_rays as f64 / gpu / 1e6
            );
        }
        _ => println!("GPU: no GPU timestamps (the device lacks TIMESTAMP_QUERY)"),
    }
    if !args.gpu_only {
        report("CPU reference", median(cpu_trace.clone()), None, cpu_rays);
        println!(
            "median GPU/CPU trace-time ratio: {:.2} ({} runs each, alternating)",
            median(gpu_trace) / median(cpu_trace),
            args.runs
        );
    }
    Ok(())
}

/// Times the specialised and the general trace pipeline on `scene`, with Whitted
/// samples in lockstep where the device can or not (`lockstep_samples`).
fn compare_specialisation(
    gpu: &HeadlessGpu,
    scene: &gpu_render::scene::Scene,
    runs: usize,
    lockstep_samples: bool,
) -> Result<()> {
    let features = gpu_render::gpu::ShaderFeatures::for_scene(scene);
    println!("scene features: {}", features.label());
    let tiny = tiny_copy(scene)?;
    let mut renderers = Vec::new();
    for (name, specialise) in [("specialised", true), ("general", false)] {
        let renderer = Renderer::new(
            &gpu.device,
            RendererOptions {
                specialise,
                lockstep_samples,
                ..RendererOptions::default()
            },
        )?;
        let used = if specialise {
            features
        } else {
            gpu_render::gpu::ShaderFeatures::ALL
        };
        let started = Instant::now();
        renderer.trace_pipelines(&gpu.device, &used)?;
        let create = started.elapsed().as_secs_f64();
        let started = Instant::now();
        renderer.render(&gpu.device, &gpu.queue, &tiny, None)?;
        let first = started.elapsed().as_secs_f64();
        let source = gpu_render::low_level::gpu::shaders::trace_shader_source(&used)
            .map_err(anyhow::Error::msg)?;
        println!(
            "{name}: {} lines of WGSL; create_compute_pipeline {:.1} ms; first 8x8 frame {:.1} ms",
            source.lines().count(),
            create * 1e3,
            first * 1e3
        );
        renderers.push((name, renderer));
    }
    let mut times = [Vec::new(), Vec::new()];
    for _ in 0..runs {
        for (index, (_, renderer)) in renderers.iter().enumerate() {
            let rendered = renderer.render(&gpu.device, &gpu.queue, scene, None)?;
            times[index].push(rendered.stats.elapsed.as_secs_f64());
        }
    }
    let specialised = median(times[0].clone());
    let general = median(times[1].clone());
    println!(
        "trace time, median of {runs} alternating runs: specialised {:.3} s, general {:.3} s, ratio {:.2}",
        specialised,
        general,
        specialised / general
    );
    Ok(())
}

/// `scene` at 8x8 and 1 spp: enough to build and dispatch its kernels.
fn tiny_copy(scene: &gpu_render::scene::Scene) -> Result<gpu_render::scene::Scene> {
    Ok(gpu_render::scene::Scene {
        render: scene
            .render
            .with_overrides(&RenderOverrides {
                width: Some(8),
                height: Some(8),
                samples_per_pixel: Some(1),
                ..RenderOverrides::default()
            })
            .map_err(anyhow::Error::msg)?,
        ..scene.clone()
    })
}

/// Prints each trace kernel's compile time and its module's size: the upload of a
/// tiny copy of `scene` on a new renderer builds the kernels and dispatches each once
/// ([`gpu_render::gpu::GpuScene::kernel_compiles`]).
fn compile_figures(
    gpu: &HeadlessGpu,
    scene: &gpu_render::scene::Scene,
    options: RendererOptions,
) -> Result<()> {
    let renderer = Renderer::new(&gpu.device, options)?;
    let tiny = tiny_copy(scene)?;
    let started = Instant::now();
    let uploaded = renderer.upload(&gpu.device, &gpu.queue, &tiny)?;
    let upload = started.elapsed().as_secs_f64();
    let source = gpu_render::low_level::gpu::shaders::trace_shader_source(&uploaded.features())
        .map_err(anyhow::Error::msg)?;
    println!(
        "kernels ({}): {} lines of WGSL",
        uploaded.features().label(),
        source.lines().count()
    );
    for kernel in uploaded.kernel_compiles() {
        println!(
            "  {}: {:.2} s",
            kernel.entry_point,
            kernel.time.as_secs_f64()
        );
    }
    println!(
        "compile {:.2} s of an upload of {upload:.2} s",
        uploaded.compile_time().as_secs_f64()
    );
    Ok(())
}

/// Times the fused and the wavefront schedule on `scene`, alternating, and checks that
/// they trace the same rays.
fn compare_schedules(
    gpu: &HeadlessGpu,
    scene: &gpu_render::scene::Scene,
    runs: usize,
) -> Result<()> {
    let schedules = [Schedule::Fused, Schedule::Wavefront];
    let renderers: Vec<Renderer> = schedules
        .iter()
        .map(|&schedule| {
            let options = RendererOptions {
                schedule: Some(schedule),
                ..RendererOptions::default()
            };
            Ok(Renderer::new(&gpu.device, options)?)
        })
        .collect::<Result<_>>()?;
    for renderer in &renderers {
        renderer.render(&gpu.device, &gpu.queue, scene, None)?;
    }
    let mut times = [Vec::new(), Vec::new()];
    let mut rays = [0, 0];
    for _ in 0..runs {
        for (index, renderer) in renderers.iter().enumerate() {
            let rendered = renderer.render(&gpu.device, &gpu.queue, scene, None)?;
            let (time, _) = rendered.stats.trace_time();
            times[index].push(time.as_secs_f64());
            rays[index] = rendered.stats.rays_traced;
        }
    }
    anyhow::ensure!(
        rays[0] == rays[1],
        "the schedules traced different rays: {rays:?}"
    );
    let (fused, wavefront) = (median(times[0].clone()), median(times[1].clone()));
    println!(
        "trace time, median of {runs} alternating runs: fused {fused:.3} s ({:.1} Mrays/s), \
         wavefront {wavefront:.3} s ({:.1} Mrays/s), wavefront/fused {:.2}",
        rays[0] as f64 / fused / 1e6,
        rays[1] as f64 / wavefront / 1e6,
        wavefront / fused
    );
    Ok(())
}

/// Builds `scene`'s BVH with both builders and prints their figures, then the average
/// work of one camera ray per pixel (through the pixel centre) and of one shadow ray
/// from each hit to the scene's first light.
fn traversal_figures(scene: &gpu_render::scene::Scene) {
    use gpu_render::low_level::accel::{BuildMethod, SceneGeometry};
    use gpu_render::low_level::cpu::intersect::{Ray, hit_record_keyed};
    use gpu_render::low_level::cpu::traverse::{
        TraversalCounts, closest_hit_counted, occluded_counted,
    };
    for method in [BuildMethod::Sah, BuildMethod::MedianSplit] {
        let geometry = SceneGeometry::with_method(scene, method);
        let stats = geometry.bvh.stats;
        let prims = geometry.bounded_count();
        let camera = gpu_render::low_level::camera::CameraFrame::new(
            &scene.camera,
            scene.render.width,
            scene.render.height,
        );
        let (mut primary, mut shadow) = (TraversalCounts::default(), TraversalCounts::default());
        let (mut primary_rays, mut shadow_rays) = (0u64, 0u64);
        let traced = Instant::now();
        for y in 0..scene.render.height {
            for x in 0..scene.render.width {
                let ray = Ray {
                    origin: camera.eye,
                    direction: camera.ray_direction(
                        f64::from(x) + 0.5,
                        f64::from(y) + 0.5,
                        scene.render.width,
                        scene.render.height,
                    ),
                };
                primary_rays += 1;
                let Some((t, prim)) =
                    closest_hit_counted(&geometry, &ray, f64::INFINITY, &mut primary)
                else {
                    continue;
                };
                let hit = hit_record_keyed(&geometry, prim, &ray, t);
                let n = if ray.direction.dot(hit.normal) < 0.0 {
                    hit.normal
                } else {
                    -hit.normal
                };
                let origin = gpu_render::low_level::cpu::intersect::offset_ray_origin(
                    hit.position,
                    n,
                    geometry.offset_scale,
                );
                let (direction, distance) = match scene.lights.first() {
                    Some(
                        gpu_render::scene::Light::Point { position, .. }
                        | gpu_render::scene::Light::Spot { position, .. },
                    ) => {
                        let to_light = *position - origin;
                        (to_light.normalize(), to_light.length())
                    }
                    Some(gpu_render::scene::Light::Directional { direction, .. }) => {
                        (-*direction, f64::INFINITY)
                    }
                    None => continue,
                };
                shadow_rays += 1;
                occluded_counted(&geometry, &Ray { origin, direction }, distance, &mut shadow);
            }
        }
        let traced = traced.elapsed().as_secs_f64();
        let per = |count: u64, rays: u64| count as f64 / rays.max(1) as f64;
        println!(
            "BVH {method:?}: {prims} primitives, built in {:.1} ms ({:.2} M primitives/s), {} nodes, \
             depth {}, SAH cost {:.1}; camera rays visit {:.1} nodes and test {:.1} primitives, \
             shadow rays {:.1} nodes and {:.1} primitives; those {} rays in {:.3} s on one \
             CPU thread ({:.2} Mrays/s)",
            stats.build_time.as_secs_f64() * 1e3,
            prims as f64 / stats.build_time.as_secs_f64().max(1e-9) / 1e6,
            stats.nodes,
            stats.depth,
            stats.sah_cost,
            per(primary.nodes, primary_rays),
            per(primary.primitives, primary_rays),
            per(shadow.nodes, shadow_rays),
            per(shadow.primitives, shadow_rays),
            primary_rays + shadow_rays,
            traced,
            (primary_rays + shadow_rays) as f64 / traced / 1e6,
        );
    }
}
