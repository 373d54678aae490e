//! Triage aid for the pipeline fuzzer's finds: prints one pixel of a scene file on both
//! backends at every depth from 0 to the scene's, and the CPU reference's ray tree of
//! that pixel (every ray, its hit, its weight and what it added), so that the bounce
//! where the backends part can be found. The tree is traced with the tracer's own
//! `shade_hit` and weight cutoff, in its order (reflection before refraction), but
//! without the bounce stack's capacity: a scene whose `stack_size` drops branches
//! shows them here.
//!
//! ```sh
//! cargo run -p gpu-render-tools --bin fuzz_probe -- FILE X Y [SAMPLE]
//! ```

use glam::DVec3;
use gpu_render::cpu::PreparedScene;
use gpu_render::gpu::RendererOptions;
use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer};
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::trace::shade_hit;
use gpu_render::low_level::cpu::traverse::intersect_scene;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, x, y, rest @ ..] = args.as_slice() else {
        eprintln!("usage: fuzz_probe FILE X Y [SAMPLE]");
        std::process::exit(2);
    };
    let (x, y): (u32, u32) = match (x.parse(), y.parse()) {
        (Ok(x), Ok(y)) => (x, y),
        _ => {
            eprintln!("X and Y must be pixel coordinates");
            std::process::exit(2);
        }
    };
    let only_sample: Option<u32> = rest.first().and_then(|s| s.parse().ok());
    let path = std::path::Path::new(path);
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{e}"));
    let scene = gpu_render::scene::parse_scene(&text, path).unwrap_or_else(|e| panic!("{e}"));
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("a GPU adapter");
    let renderer = Renderer::new(
        &gpu.device,
        RendererOptions {
            specialise: false,
            ..RendererOptions::default()
        },
    )
    .expect("renderer");
    for depth in 0..=scene.render.max_depth {
        let mut s = scene.clone();
        s.render.max_depth = depth;
        let cpu = gpu_render::cpu::render(&s, None).image;
        let g = renderer
            .render(&gpu.device, &gpu.queue, &s, None)
            .expect("GPU render")
            .image;
        let i = (y * cpu.width + x) as usize;
        println!(
            "depth {depth}: cpu {:?} gpu {:?}",
            &cpu.pixels[i][..3],
            &g.pixels[i][..3]
        );
    }
    let prepared = PreparedScene::new(&scene);
    println!("offset_scale {}", prepared.geometry.offset_scale);
    let settings = prepared.settings;
    for index in 0..settings.samples_per_pixel {
        if only_sample.is_some_and(|s| s != index) {
            continue;
        }
        let (dx, dy) = prepared.samples.offset(x, y, index);
        let direction = prepared.camera.ray_direction(
            f64::from(x) + dx,
            f64::from(y) + dy,
            settings.width,
            settings.height,
        );
        println!("sample {index}");
        let mut stack = vec![(
            Ray {
                origin: prepared.camera.eye,
                direction,
            },
            DVec3::ONE,
            0u32,
            prepared.camera_medium,
        )];
        while let Some((ray, weight, depth, medium)) = stack.pop() {
            let indent = "  ".repeat(depth as usize + 1);
            let Some(hit) = intersect_scene(&prepared.geometry, &ray, f64::INFINITY) else {
                println!(
                    "{indent}d{depth} o {:?} u {:?} w {:?}: miss, adds {:?}",
                    ray.origin,
                    ray.direction,
                    weight,
                    weight * prepared.background
                );
                continue;
            };
            let shaded = shade_hit(
                &prepared,
                &ray,
                &hit,
                &medium,
                gpu_render::low_level::texture::ConeFootprint::NONE,
            );
            println!(
                "{indent}d{depth} o {:?} u {:?} w {:?}: {:?} t {:e} at {:?} n {:?} cos {:.6e}, adds {:?}",
                ray.origin,
                ray.direction,
                weight,
                hit.prim,
                hit.t,
                hit.position,
                hit.normal,
                -ray.direction.dot(hit.normal),
                weight * shaded.radiance
            );
            if depth >= settings.max_depth {
                continue;
            }
            for ((w, r), m) in [
                (shaded.transmitted, shaded.transmitted_medium),
                (shaded.reflected, medium),
            ] {
                let w = weight * w;
                if w.max_element() > settings.min_ray_weight.max(f64::from(f32::MIN_POSITIVE)) {
                    stack.push((r, w, depth + 1, m));
                }
            }
        }
    }
}
