//! `gpu-render estimate SCENE`: the expected time of each tile (and frame) from a
//! short calibration render, so that a user can choose how many pieces to farm out.
//!
//! The calibration image is the scene at a `1/s` scale in each direction (the same
//! view, samples, depth and lighting; `s² ≈ pixels / --calibration-pixels`), split
//! into the same bands as the full image. Each band is rendered on its own, on the
//! backend chosen, and timed on the wall clock. Its time, less the fixed cost of one
//! render call (measured on a 1-pixel render: the BVH, the upload and the buffers),
//! is scaled by the full band's pixels over the calibration band's: a pixel of the
//! calibration image stands for the `s × s` pixels around it, so a band of glass
//! costs more than a band of sky in both. A process also pays a setup once: loading
//! the scene, opening the device and its first render (the shaders' compilation on
//! the GPU), measured as well. How well this predicts is measured in
//! `docs/distributed.md`.

use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use gpu_render::tiles::{PixelWindow, tile_window};

use crate::args::EstimateArgs;
use crate::backend::{Backend, GpuOptions};

/// The most frames of an animation calibrated when no `--frame` is given.
const SAMPLED_FRAMES: u32 = 5;

/// Calibrates and prints the table on stdout.
pub fn run(args: &EstimateArgs) -> Result<()> {
    args.device
        .check_for_backend()
        .map_err(anyhow::Error::msg)?;
    crate::apply_overrides(&args.settings, crate::minimal_settings(), None)?;
    let started = Instant::now();
    // A model file is framed as a scene of its own, as the render command frames it.
    let loaded = crate::loading::load_any(
        &args.scene,
        &crate::loading::LoadArgs {
            settings: &args.settings,
            sandbox: args.sandbox,
            quiet: false,
            max_memory: None,
        },
    )?;
    let (scene, camera_path) = (loaded.scene, loaded.camera_path);
    let load_time = started.elapsed();
    let (width, height) = (scene.render.width, scene.render.height);
    tile_window(0, args.tiles, width, height)
        .map_err(|e| anyhow!("--tiles {}: {e}", args.tiles))?;
    let frames: Vec<Option<u32>> = match (args.frame, &camera_path) {
        (Some(frame), Some(path)) if frame < path.frame_count => vec![Some(frame)],
        (Some(frame), Some(path)) => bail!(
            "{}: --frame {frame}: the animation has {} frames (0 to {})",
            args.scene.display(),
            path.frame_count,
            path.frame_count - 1
        ),
        (Some(frame), None) => bail!(
            "{}: --frame {frame}: the scene has no [animation] camera path",
            args.scene.display()
        ),
        (None, Some(path)) => sampled_frames(path.frame_count)
            .into_iter()
            .map(Some)
            .collect(),
        (None, None) => vec![None],
    };

    let opened = Instant::now();
    let options = GpuOptions {
        iteration_budget: args.device.iteration_budget,
        timeout: args.device.gpu_timeout,
        noise: false,
        aov: false,
        traversal: args.device.traversal.into(),
    };
    let backend = Backend::open(
        args.device.backend,
        args.device.adapter.as_ref(),
        &scene,
        &options,
        false,
    )?;
    let open_time = opened.elapsed();

    let (calibration_width, calibration_height) =
        calibration_size(width, height, args.tiles, args.calibration_pixels);
    let mut calibration = scene.clone();
    calibration.render.width = calibration_width;
    calibration.render.height = calibration_height;
    // The first call pays the shaders' compilation; the second, the cost of any call.
    let pixel = PixelWindow {
        columns: 0..1,
        rows: 0..1,
    };
    let no_progress = |_: u32, _: u32| {};
    let first_call = time(|| backend.render_region(&calibration, &pixel, &no_progress))?;
    let call_cost = time(|| backend.render_region(&calibration, &pixel, &no_progress))?;
    let setup = load_time + open_time + first_call;

    let s = &scene.render;
    println!(
        "{}: {width}x{height}, {} spp, max depth {}, on {}",
        args.scene.display(),
        s.samples_per_pixel,
        s.max_depth,
        backend.describe()
    );
    println!(
        "calibration: {calibration_width}x{calibration_height} ({:.1}% of the pixels), each \
         band timed on its own; one render call's fixed cost {}",
        100.0 * f64::from(calibration_width) * f64::from(calibration_height)
            / (f64::from(width) * f64::from(height)),
        seconds(call_cost)
    );
    println!(
        "setup per process: {} (load {}, device {}, first render {})",
        seconds(setup),
        seconds(load_time),
        seconds(open_time),
        seconds(first_call)
    );
    println!("frame  tile     window                                  expected");
    let mut frame_totals = Vec::new();
    let mut longest_tile = 0.0_f64;
    for frame in &frames {
        let mut frame_scene = calibration.clone();
        if let (Some(frame), Some(path)) = (frame, &camera_path) {
            frame_scene.camera = path.frame_camera(&scene.camera, *frame);
        }
        let mut total = 0.0;
        for index in 0..args.tiles {
            let full = tile_window(index, args.tiles, width, height)?;
            let band = tile_window(index, args.tiles, calibration_width, calibration_height)?;
            let measured = time(|| backend.render_region(&frame_scene, &band, &no_progress))?;
            let expected = expected_seconds(measured, call_cost, band.pixels(), full.pixels());
            total += expected;
            longest_tile = longest_tile.max(expected);
            println!(
                "{:<6} {:<8} {:<39} {}",
                frame.map_or("-".to_owned(), |f| f.to_string()),
                format!("{index}/{}", args.tiles),
                full.to_string(),
                seconds_f64(expected)
            );
        }
        frame_totals.push(total);
    }
    let mean = frame_totals.iter().sum::<f64>() / frame_totals.len() as f64;
    let processes = u64::from(args.tiles);
    match &camera_path {
        Some(path) if args.frame.is_none() => {
            let frames = u64::from(path.frame_count);
            println!(
                "per frame: {} of rendering on average over the {} frames calibrated; all {} \
                 frames: {} of rendering, plus {} of setup per process ({} processes of one \
                 tile of one frame each: {} in all)",
                seconds_f64(mean),
                frame_totals.len(),
                frames,
                seconds_f64(mean * frames as f64),
                seconds(setup),
                frames * processes,
                seconds_f64(
                    mean * frames as f64 + (frames * processes) as f64 * setup.as_secs_f64()
                )
            );
        }
        _ => println!(
            "whole frame: {} of rendering, plus {} of setup per process ({} processes: {} in \
             all, the longest {})",
            seconds_f64(mean),
            seconds(setup),
            processes,
            seconds_f64(mean + processes as f64 * setup.as_secs_f64()),
            seconds_f64(setup.as_secs_f64() + longest_tile)
        ),
    }
    println!(
        "(one process with the device to itself; processes that share a device or the \
         CPU cores each run slower: docs/distributed.md)"
    );
    Ok(())
}

/// The frames calibrated for an animation of `count` frames: up to
/// [`SAMPLED_FRAMES`], evenly spread from the first to the last.
fn sampled_frames(count: u32) -> Vec<u32> {
    let last = count.saturating_sub(1);
    let mut frames: Vec<u32> = (0..SAMPLED_FRAMES)
        .map(|i| (u64::from(last) * u64::from(i) / u64::from(SAMPLED_FRAMES - 1)) as u32)
        .collect();
    frames.dedup();
    frames
}

/// The calibration image's size: `width × height` scaled by the same factor in both
/// directions to about `pixels` pixels (never up), with at least one row per tile.
fn calibration_size(width: u32, height: u32, tiles: u32, pixels: u32) -> (u32, u32) {
    let whole = f64::from(width) * f64::from(height);
    let scale = (f64::from(pixels) / whole).sqrt().min(1.0);
    let side = |full: u32, least: u32| {
        ((f64::from(full) * scale).round() as u32).clamp(least.min(full), full)
    };
    (side(width, 1), side(height, tiles.max(1)))
}

/// The expected seconds of a full band of `full_pixels` from a calibration band of
/// `band_pixels` that took `measured`, less the `call_cost` every call pays.
fn expected_seconds(
    measured: Duration,
    call_cost: Duration,
    band_pixels: u64,
    full_pixels: u64,
) -> f64 {
    let per_pixel = measured.saturating_sub(call_cost).as_secs_f64() / band_pixels.max(1) as f64;
    call_cost.as_secs_f64() + per_pixel * full_pixels as f64
}

/// Runs `render` and returns its wall time.
fn time<T>(render: impl FnOnce() -> Result<T>) -> Result<Duration> {
    let started = Instant::now();
    render()?;
    Ok(started.elapsed())
}

fn seconds(duration: Duration) -> String {
    seconds_f64(duration.as_secs_f64())
}

fn seconds_f64(seconds: f64) -> String {
    if seconds < 0.1 {
        format!("{:.1} ms", seconds * 1e3)
    } else if seconds < 10.0 {
        format!("{seconds:.2} s")
    } else {
        format!("{seconds:.1} s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_calibration_keeps_the_aspect_and_a_row_per_tile() {
        assert_eq!(calibration_size(640, 480, 1, 16_384), (148, 111));
        assert_eq!(calibration_size(64, 48, 4, 16_384), (64, 48));
        assert_eq!(calibration_size(1920, 1080, 200, 1_000), (42, 200));
        assert_eq!(calibration_size(10, 3, 3, 1), (2, 3));
    }

    #[test]
    fn frames_spread_from_first_to_last() {
        assert_eq!(sampled_frames(1), vec![0]);
        assert_eq!(sampled_frames(3), vec![0, 1, 2]);
        assert_eq!(sampled_frames(49), vec![0, 12, 24, 36, 48]);
    }

    #[test]
    fn a_band_scales_by_pixels_after_the_fixed_cost() {
        let expected = expected_seconds(
            Duration::from_millis(110),
            Duration::from_millis(10),
            100,
            10_000,
        );
        assert!((expected - (0.01 + 10.0)).abs() < 1e-9, "{expected}");
        let cheap = expected_seconds(Duration::from_millis(5), Duration::from_millis(10), 1, 4);
        assert!((cheap - 0.01).abs() < 1e-12);
    }
}
