//! Loading is linear in the size of the scene: 4x the objects take about 4x the time.
//!
//! A ratio, never a wall-clock limit: the machine's speed varies, a quadratic loader
//! (each item's line worked out by scanning from the start of the file) does not pass
//! whatever the machine. Each size is timed a few times and the fastest run counts, so
//! a burst of load from other processes does not decide the ratio.

use std::path::Path;
use std::time::{Duration, Instant};

use gpu_render::scene::parse_scene;

/// Scene text with `spheres` spheres, one `[[objects]]` table each, built in memory.
fn scene_with_spheres(spheres: usize) -> String {
    let mut text = String::with_capacity(spheres * 96 + 256);
    text.push_str("[camera]\neye = [0, 0, 10]\nlook_at = [0, 0, 0]\n");
    text.push_str("[materials.grey]\ntype = \"lambert\"\nalbedo = 0.5\n");
    for i in 0..spheres {
        let (x, y) = ((i % 1000) as f64 * 0.01, (i / 1000) as f64 * 0.01);
        text.push_str(&format!(
            "[[objects]]\ntype = \"sphere\"\ncenter = [{x}, {y}, -1.5]\nradius = 0.004\nmaterial = \"grey\"\n"
        ));
    }
    text
}

/// The fastest of `runs` parses of `text`; checks the scene has `spheres` shapes.
fn fastest_parse(text: &str, spheres: usize, runs: usize) -> Duration {
    (0..runs)
        .map(|_| {
            let started = Instant::now();
            let scene = match parse_scene(text, Path::new("<generated>")) {
                Ok(scene) => scene,
                Err(e) => panic!("the generated scene is invalid: {e}"),
            };
            let elapsed = started.elapsed();
            assert_eq!(scene.shapes.len(), spheres);
            elapsed
        })
        .min()
        .unwrap_or(Duration::MAX)
}

#[test]
fn a_200k_object_scene_loads_in_linear_time() {
    let (small, large) = (50_000, 200_000);
    let small_text = scene_with_spheres(small);
    let large_text = scene_with_spheres(large);
    // Warm the allocator and caches once before timing.
    fastest_parse(&small_text, small, 1);
    let small_time = fastest_parse(&small_text, small, 3);
    let large_time = fastest_parse(&large_text, large, 3);
    let ratio = large_time.as_secs_f64() / small_time.as_secs_f64().max(1e-9);
    eprintln!("{small} objects: {small_time:?}, {large} objects: {large_time:?}, ratio {ratio:.2}");
    // Linear is 4; quadratic would be 16.
    assert!(
        ratio < 8.0,
        "loading {large} objects took {ratio:.1}x as long as {small} ({large_time:?} against {small_time:?}); expected about 4x"
    );
}
