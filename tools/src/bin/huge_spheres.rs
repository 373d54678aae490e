//! How large a sphere each backend renders correctly: a white Lambert sphere of radius
//! `r` resting on the origin (centre `(0, -r, 0)`), or with its top 0.5 below it
//! (centre `(0, -(r + 0.5), 0)`, which `f64` cannot hold beyond about 1e15), seen from 5
//! units away, lit by a point light 1.5 units from the origin, for `r` from 1e2 to
//! 1e20. Prints, per case, the closed-form radiance
//! of the ray through the image centre, what the CPU reference and the GPU give there
//! (1 × 1 pixel, 1 sample), and how a 32 × 24 image compares between the two
//! (pixels outside `1e-3 + 5e-3·|cpu|`, largest difference). `docs/numerics.md` quotes
//! the table.
//!
//! ```sh
//! XDG_RUNTIME_DIR=/tmp/xdg WGPU_BACKEND=vulkan cargo run -p gpu-render-tools --bin huge_spheres
//! ```

use std::path::Path;

use glam::DVec3;
use gpu_render::gpu::RendererOptions;
use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer};
use gpu_render::scene::{Scene, SceneWarning, parse_scene_with};

const EYE: DVec3 = DVec3::new(0.0, 3.0, 4.0);
/// A point light of intensity π, so that a white Lambert surface facing it at distance
/// d has radiance 1/d²: the image then shows where the surface is, not only its normal.
const LIGHT: DVec3 = DVec3::new(1.0, 1.0, 0.5);

/// The scene: a white sphere of radius `radius` whose top is `drop` below the origin
/// (centre `(0, -(radius + drop), 0)`, written exactly in decimal).
fn scene_text(radius: f64, drop: f64, width: u32, height: u32) -> String {
    // radius is a power of ten up to 1e20, exactly an integer; drop is 0 or 0.5.
    let centre_y = if drop == 0.0 {
        format!("-{}.0", radius as u128)
    } else {
        format!("-{}.5", radius as u128)
    };
    assert!(drop == 0.0 || drop == 0.5);
    format!(
        "[render]\nwidth = {width}\nheight = {height}\nmax_depth = 0\n\n\
         [camera]\neye = [{}, {}, {}]\nlook_at = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n\n\
         [environment]\nbackground = [0.0, 0.0, 1.0]\n\n\
         [materials.white]\ntype = \"lambert\"\nalbedo = 1.0\n\n\
         [[lights]]\ntype = \"point\"\nposition = [{}, {}, {}]\nintensity = {}\n\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0.0, {centre_y}, 0.0]\nradius = {}.0\nmaterial = \"white\"\n",
        EYE.x,
        EYE.y,
        EYE.z,
        LIGHT.x,
        LIGHT.y,
        LIGHT.z,
        std::f64::consts::PI,
        radius as u128
    )
}

/// The radiance along the ray from the eye to the origin, in closed form with the
/// radius `r` and the drop `h` kept apart: with `c = (0, -(r + h), 0)`,
/// `|p - c|² - r² = |p|² + 2(r + h)·p.y + 2rh + h²`, so along `o + t·d` the quadratic is
/// `t² + 2t(o·d + (r + h)·d.y) + |o|² + 2(r + h)·o.y + 2rh + h² = 0`, whose smaller root
/// is taken in the cancellation-free form `c / q`; the normal is
/// `(p - c)/r = (p + (0, h, 0))/r + (0, 1, 0)`.
fn closed_form(r: f64, h: f64) -> f64 {
    let d = (-EYE).normalize();
    let half_b = EYE.dot(d) + (r + h) * d.y;
    let c = EYE.length_squared() + 2.0 * (r + h) * EYE.y + 2.0 * r * h + h * h;
    let q = -half_b + (half_b * half_b - c).sqrt();
    let t = c / q;
    let p = EYE + d * t;
    let normal = ((p + DVec3::new(0.0, h, 0.0)) / r + DVec3::Y).normalize();
    let to_light = LIGHT - p;
    normal.dot(to_light.normalize()).max(0.0) / to_light.length_squared()
}

/// The red channel, or "background" for the blue background.
fn describe(pixel: [f32; 4]) -> String {
    if pixel[0] == 0.0 && pixel[2] == 1.0 {
        "background".to_owned()
    } else {
        format!("{:.6}", pixel[0])
    }
}

fn load(text: &str, warnings: &mut Vec<String>) -> Scene {
    let collected = std::sync::Mutex::new(Vec::new());
    let hook = |w: &SceneWarning| collected.lock().expect("lock").push(w.to_string());
    let options = gpu_render::scene::LoadOptions {
        warning: Some(&hook),
        ..Default::default()
    };
    let scene = parse_scene_with(text, Path::new("huge-sphere.toml"), &options)
        .unwrap_or_else(|e| panic!("{e}"));
    warnings.extend(collected.into_inner().expect("lock"));
    scene
}

fn main() {
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("a GPU adapter");
    let renderer =
        Renderer::new(&gpu.device, RendererOptions::default()).expect("the GPU renderer");
    let render_gpu = |scene: &Scene| {
        renderer
            .render(&gpu.device, &gpu.queue, scene, None)
            .expect("GPU render")
            .image
    };
    println!("adapter: {}", gpu.adapter_info().name);
    println!(
        "| radius | top below origin | closed form | CPU | GPU | 32x24 pixels outside tolerance | max abs GPU-CPU | warned |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|:--|");
    for (exponent, drop) in (2..=20).map(|e| (e, 0.0)).chain((6..=20).map(|e| (e, 0.5))) {
        let radius = 10f64.powi(exponent);
        let mut warnings = Vec::new();
        let centre = load(&scene_text(radius, drop, 1, 1), &mut warnings);
        let cpu = describe(gpu_render::cpu::render(&centre, None).image.pixels[0]);
        let gpu_value = describe(render_gpu(&centre).pixels[0]);
        let image = load(&scene_text(radius, drop, 32, 24), &mut Vec::new());
        let cpu_image = gpu_render::cpu::render(&image, None).image;
        let gpu_image = render_gpu(&image);
        let (mut outliers, mut max_abs) = (0, 0.0f32);
        for (c, g) in cpu_image.pixels.iter().zip(&gpu_image.pixels) {
            let mut outlier = false;
            for k in 0..3 {
                let d = (c[k] - g[k]).abs();
                max_abs = max_abs.max(if d.is_nan() { f32::INFINITY } else { d });
                outlier |= d.is_nan() || d > 1e-3 + 5e-3 * c[k].abs();
            }
            outliers += usize::from(outlier);
        }
        println!(
            "| 1e{exponent} | {drop} | {:.6} | {cpu} | {gpu_value} | {outliers} / {} | {max_abs:.2e} | {} |",
            closed_form(radius, drop),
            cpu_image.pixels.len(),
            if warnings.is_empty() { "no" } else { "yes" }
        );
        for warning in &warnings {
            eprintln!("  {warning}");
        }
    }
}
