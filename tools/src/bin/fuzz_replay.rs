//! Replays scene files through the whole-pipeline check of `tests/integration/fuzz_pipeline.rs`
//! and prints each result: for triaging the finds of `tools/src/bin/fuzz_campaign.rs`.
//!
//! ```sh
//! cargo run -p gpu-render-tools --bin fuzz_replay -- tests/fixtures/pipeline-open/*.toml
//! ```
//!
//! With `--perturb E` it also renders each scene on the CPU with the camera moved by
//! a relative `E` (1e-7 is about one f32 rounding) and compares that with the CPU
//! image by the same rule: where that differs too, the scene is chaotic (sensitive to
//! rounding, as deep paths in curved mirror and glass cavities are), and GPU-versus-CPU
//! differences there say nothing about the GPU. With `--twin DIR` it compares each
//! scene's CPU image with the CPU image of `DIR/` + the same file name (for example
//! the scene with every coordinate moved by one f32 ulp). `--f32-inputs` compares each
//! scene's CPU image with the CPU image of the same scene with its camera, lights and
//! shapes rounded to `f32`, the GPU's inputs: where they differ, input rounding alone
//! explains a GPU difference. `--pixels` prints the pixels outside the tolerance. The
//! loader's warnings about each scene are printed before its result.

#[path = "../../../tests/integration/support/mod.rs"]
#[allow(dead_code)]
mod support;

use support::pipeline;

use gpu_render::gpu::{AdapterChoice, HeadlessGpu};

fn main() {
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("a GPU adapter");
    let checker = pipeline::PipelineChecker::new(gpu);
    let mut failed = 0;
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let perturb = args.iter().position(|a| a == "--perturb").map(|i| {
        let value = args.get(i + 1).and_then(|v| v.parse::<f64>().ok());
        let value = value.expect("--perturb needs a number");
        args.drain(i..i + 2);
        value
    });
    let pixels = args
        .iter()
        .position(|a| a == "--pixels")
        .map(|i| args.remove(i));
    let f32_inputs = args
        .iter()
        .position(|a| a == "--f32-inputs")
        .map(|i| args.remove(i));
    let twin = args.iter().position(|a| a == "--twin").map(|i| {
        let dir = args.get(i + 1).cloned().expect("--twin needs a folder");
        args.drain(i..i + 2);
        std::path::PathBuf::from(dir)
    });
    let cpu_image = |path: &std::path::Path| {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{e}"));
        let scene = gpu_render::scene::parse_scene(&text, path).unwrap_or_else(|e| panic!("{e}"));
        gpu_render::cpu::render(&scene, None).image
    };
    for path in args {
        if f32_inputs.is_some() {
            let own = std::path::Path::new(&path);
            let text = std::fs::read_to_string(own).unwrap_or_else(|e| panic!("{e}"));
            let scene =
                gpu_render::scene::parse_scene(&text, own).unwrap_or_else(|e| panic!("{e}"));
            let rounded = rounded_to_f32(&scene);
            let c = support::compare::measure(
                &gpu_render::cpu::render(&scene, None).image,
                &gpu_render::cpu::render(&rounded, None).image,
                pipeline::TOLERANCE,
            );
            println!(
                "{path}: CPU against CPU on f32 inputs: {} of {} pixels outside tolerance, \
                 max |Δ| {:.2e}",
                c.outliers, c.pixels, c.max_abs_error
            );
            continue;
        }
        if let Some(dir) = &twin {
            let own = std::path::Path::new(&path);
            let other = dir.join(own.file_name().expect("a file name"));
            let c =
                support::compare::measure(&cpu_image(own), &cpu_image(&other), pipeline::TOLERANCE);
            println!(
                "{path}: CPU against {}: {} of {} pixels outside tolerance, max |Δ| {:.2e}",
                other.display(),
                c.outliers,
                c.pixels,
                c.max_abs_error
            );
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        // The loader's warnings (f32 limits it can see) come before the verdict.
        let warn = |w: &gpu_render::scene::SceneWarning| println!("  warning: {w}");
        let options = gpu_render::scene::LoadOptions {
            warning: Some(&warn),
            ..Default::default()
        };
        let _ = gpu_render::scene::parse_scene_with(&text, std::path::Path::new(&path), &options);
        match checker.check(&text) {
            Ok(passed) => println!(
                "{path}: passes ({} of {} pixels outside tolerance, max |Δ| {:.2e})",
                passed.comparison.outliers, passed.pixels, passed.comparison.max_abs_error
            ),
            Err(fail) => {
                failed += 1;
                println!("{path}: FAILS: {}", fail.reason);
                if let (Some(_), Some((cpu, gpu))) = (&pixels, &fail.images) {
                    for (i, (c, g)) in cpu.pixels.iter().zip(&gpu.pixels).enumerate() {
                        if (0..3).any(|k| !pipeline::TOLERANCE.channel_passes(c[k], g[k])) {
                            println!(
                                "  ({}, {}): cpu {:?} gpu {:?}",
                                i as u32 % cpu.width,
                                i as u32 / cpu.width,
                                &c[..3],
                                &g[..3]
                            );
                        }
                    }
                }
            }
        }
        if let Some(relative) = perturb {
            let scene = gpu_render::scene::parse_scene(&text, std::path::Path::new(&path))
                .unwrap_or_else(|e| panic!("{e}"));
            let mut moved = scene.clone();
            moved.camera.eye *= 1.0 + relative;
            let original = gpu_render::cpu::render(&scene, None).image;
            let moved = gpu_render::cpu::render(&moved, None).image;
            let c = support::compare::measure(&original, &moved, pipeline::TOLERANCE);
            println!(
                "  CPU with the eye moved by {relative:e}: {} of {} pixels outside tolerance, \
                 max |Δ| {:.2e}",
                c.outliers, c.pixels, c.max_abs_error
            );
        }
    }
    std::process::exit(i32::from(failed > 0));
}

/// `scene` with its camera, lights and shapes rounded to `f32`, as the GPU receives them.
fn rounded_to_f32(scene: &gpu_render::scene::Scene) -> gpu_render::scene::Scene {
    use gpu_render::scene::{Light, Shape};
    let v = |v: glam::DVec3| v.as_vec3().as_dvec3();
    let x = |x: f64| f64::from(x as f32);
    let mut rounded = scene.clone();
    rounded.camera.eye = v(scene.camera.eye);
    rounded.camera.look_at = v(scene.camera.look_at);
    rounded.camera.up = v(scene.camera.up);
    for light in &mut rounded.lights {
        match light {
            Light::Point {
                position,
                intensity,
            } => {
                *position = v(*position);
                *intensity = v(*intensity);
            }
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => {
                *position = v(*position);
                *direction = v(*direction);
                *intensity = v(*intensity);
                *cos_inner = x(*cos_inner);
                *cos_outer = x(*cos_outer);
            }
            Light::Directional {
                direction,
                irradiance,
            } => {
                *direction = v(*direction);
                *irradiance = v(*irradiance);
            }
        }
    }
    for shape in &mut rounded.shapes {
        match shape {
            Shape::Sphere { center, radius, .. } => {
                *center = v(*center);
                *radius = x(*radius);
            }
            Shape::Plane { normal, offset, .. } => {
                *normal = v(*normal);
                *offset = x(*offset);
            }
            Shape::Polygon { vertices, .. } => vertices.iter_mut().for_each(|p| *p = v(*p)),
            Shape::Triangle { vertices, .. } => vertices.iter_mut().for_each(|p| *p = v(*p)),
        }
    }
    rounded
}
