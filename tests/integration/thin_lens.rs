//! Thin-lens depth of field (`aperture_radius`, `focus_distance` in `[camera]`), on
//! both backends: an edge on the plane in focus stays sharp, an edge off it blurs into
//! exactly the profile a uniform disk of confusion of radius `r·|1 - D/F|` gives
//! (the closed form of a thin lens, pbrt-v4 §5.2.3), and the GPU traces the same rays
//! as the CPU reference.

use gpu_render::scene::{Scene, parse_scene};

use crate::support::twins::{TWIN_TOLERANCE, assert_backends_agree};

const WIDTH: u32 = 128;
const HEIGHT: u32 = 8;
const SPP: u32 = 256;
const FOV_Y_DEGREES: f64 = 10.0;
const APERTURE: f64 = 0.5;
const FOCUS: f64 = 2.0;

/// A white emitter covering x < 0 on the plane z = -`depth`, seen from the origin
/// looking down -z through a lens focused at `FOCUS`: the image's left half.
fn edge_scene(depth: f64, lens: bool) -> Scene {
    let lens = if lens {
        format!("aperture_radius = {APERTURE}\nfocus_distance = {FOCUS}\n")
    } else {
        String::new()
    };
    let text = format!(
        "[render]\nwidth = {WIDTH}\nheight = {HEIGHT}\nsamples_per_pixel = {SPP}\n\
         [camera]\neye = [0, 0, 0]\nlook_at = [0, 0, -1]\nfov_y_degrees = {FOV_Y_DEGREES}\n{lens}\
         [materials.white]\ntype = \"emissive\"\nradiance = 1\n\
         [[objects]]\ntype = \"polygon\"\nmaterial = \"white\"\n\
         vertices = [[-100, -100, -{depth}], [0, -100, -{depth}], [0, 100, -{depth}], [-100, 100, -{depth}]]\n"
    );
    parse_scene(&text, "edge.toml".as_ref()).expect("the edge scene loads")
}

/// The fraction of a unit disk on the side `d` of a line at signed distance `d` from
/// its centre covers (1 for d >= 1, 0 for d <= -1).
fn disk_fraction(d: f64) -> f64 {
    let d = d.clamp(-1.0, 1.0);
    0.5 + (d * (1.0 - d * d).sqrt() + d.asin()) / std::f64::consts::PI
}

/// The expected value of image column `column` for the edge at `depth`: the rays of a
/// point of the image at horizontal tangent `t` meet the plane z = -depth in a disk of
/// centre `t·depth` and radius `r·|1 - depth/F|` (uniform, as the lens points are),
/// of which the part at x < 0 is white; averaged over the column's width.
fn expected_column(column: u32, depth: f64) -> f64 {
    let half_height = (FOV_Y_DEGREES.to_radians() / 2.0).tan();
    let half_width = half_height * f64::from(WIDTH) / f64::from(HEIGHT);
    let radius = APERTURE * (1.0 - depth / FOCUS).abs();
    let steps = 256;
    (0..steps)
        .map(|i| {
            let x = f64::from(column) + (f64::from(i) + 0.5) / f64::from(steps);
            let tangent = (2.0 * x / f64::from(WIDTH) - 1.0) * half_width;
            let centre = tangent * depth;
            if radius == 0.0 {
                f64::from(u8::from(centre < 0.0))
            } else {
                disk_fraction(-centre / radius)
            }
        })
        .sum::<f64>()
        / f64::from(steps)
}

/// The mean of each image column.
fn columns(image: &gpu_render::film::LinearImage) -> Vec<f64> {
    (0..WIDTH)
        .map(|x| {
            (0..HEIGHT)
                .map(|y| f64::from(image.pixels[(y * WIDTH + x) as usize][0]))
                .sum::<f64>()
                / f64::from(HEIGHT)
        })
        .collect()
}

/// Asserts every column within `tolerance` of its closed form; returns how many
/// columns lie strictly between black and white.
fn assert_profile(label: &str, scene: &Scene, depth: f64, tolerance: f64) -> usize {
    let image = gpu_render::cpu::render(scene, None).image;
    let measured = columns(&image);
    for (column, value) in measured.iter().enumerate() {
        let expected = expected_column(column as u32, depth);
        assert!(
            (value - expected).abs() <= tolerance,
            "{label}: column {column} is {value:.4}, the thin lens gives {expected:.4}"
        );
    }
    measured.iter().filter(|&&v| v > 0.01 && v < 0.99).count()
}

#[test]
fn an_edge_in_focus_is_sharp_and_one_off_it_blurs_as_the_circle_of_confusion_says() {
    // On the plane in focus: as sharp as a pinhole's (the edge's one column).
    let sharp = assert_profile("in focus", &edge_scene(FOCUS, true), FOCUS, 0.02);
    assert!(sharp <= 1, "{sharp} grey columns at the plane in focus");
    // Four times as far: a disk of confusion of radius 1.5 at depth 8, 0.1875 in
    // tangent, 15.6 columns wide; 2048 lens samples a column leave about 1% noise.
    let depth = 4.0 * FOCUS;
    let blurred = assert_profile("out of focus", &edge_scene(depth, true), depth, 0.04);
    assert!(blurred >= 12, "only {blurred} grey columns out of focus");
    // Without the lens the same edge is sharp: the blur is the lens's.
    let pinhole = columns(&gpu_render::cpu::render(&edge_scene(depth, false), None).image);
    assert!(pinhole.iter().filter(|&&v| v > 0.01 && v < 0.99).count() <= 1);
}

#[test]
fn the_gpu_traces_the_thin_lens_as_the_cpu_does() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let mut edge = edge_scene(4.0 * FOCUS, true);
    edge.render.samples_per_pixel = 16;
    assert_backends_agree(&gpu, &renderer, "thin-lens-edge", &edge, TWIN_TOLERANCE);
    // A lit scene of mirrors, glass and diffuse surfaces, both integrators, focused
    // on its middle.
    let mut showcase = crate::support::scenes::reduced(
        crate::support::scenes::shipped("showcase.toml"),
        64,
        gpu_render::scene::RenderOverrides {
            samples_per_pixel: Some(4),
            ..Default::default()
        },
    );
    showcase.camera.lens = Some(gpu_render::scene::ThinLens {
        aperture_radius: 0.2,
        focus_distance: None,
    });
    assert_backends_agree(
        &gpu,
        &renderer,
        "thin-lens-showcase",
        &showcase,
        TWIN_TOLERANCE,
    );
    showcase.render.integrator = gpu_render::scene::Integrator::Path;
    assert_backends_agree(
        &gpu,
        &renderer,
        "thin-lens-showcase-path",
        &showcase,
        TWIN_TOLERANCE,
    );
}
