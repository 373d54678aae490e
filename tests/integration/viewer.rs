//! `gpu-render view` through a real window: an X11 window on an Xvfb server this test
//! starts itself, presented by wgpu on the GPU adapter (lavapipe in CI). The
//! screenshot of `--frames N` must match the headless GPU render of the same samples;
//! a scene file that stops parsing while the window is open must leave the old scene
//! on screen and the program running; a broken scene is an error, not a crash.
//!
//! Without Xvfb or a GPU adapter the window tests skip with a note, except when `CI` is
//! set: then they fail (`scripts/test.sh` installs Xvfb and lavapipe).
#![cfg(feature = "viewer")]

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// The most pixels of the screenshot allowed to differ from the headless render by
/// more than one 8-bit level: 0.1%. The draw into the surface's `*Srgb` format
/// rounds in the attachment instead of the display pass's exact quantisation, which
/// moves a value by at most one level; the fraction leaves room for nothing else.
const OUTLIER_FRACTION: f64 = 0.001;

/// An Xvfb server on a display number it chose itself (`-displayfd`), ended on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts Xvfb, or `None` (with a note) where it is not installed outside CI.
///
/// # Panics
///
/// When `CI` is set and Xvfb is missing, or when it starts but names no display.
fn xvfb() -> Option<Xvfb> {
    let spawned = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "1280x1024x24",
            "-nolisten",
            "tcp",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn();
    let mut child = match spawned {
        Ok(child) => child,
        Err(e) if std::env::var_os("CI").is_some() => panic!(
            "\n\n*** CI is set but Xvfb cannot be started ({e}); the viewer's window tests \
             must not be skipped in CI: install xvfb (scripts/test.sh does).\n\n"
        ),
        Err(e) => {
            eprintln!("note: skipping the viewer's window test, no Xvfb: {e}");
            return None;
        }
    };
    // Xvfb writes the display number once it accepts connections.
    let mut line = String::new();
    let stdout = child.stdout.take().expect("piped stdout");
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("read Xvfb's display number");
    let number = line.trim();
    if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit()) {
        let _ = child.kill();
        let _ = child.wait();
        panic!("Xvfb started but named no display (it printed {line:?})");
    }
    Some(Xvfb {
        display: format!(":{number}"),
        child,
    })
}

/// The window tests' preconditions: an X server and a GPU adapter.
fn window_environment() -> Option<Xvfb> {
    let xvfb = xvfb()?;
    crate::support::gpu::headless_gpu()?;
    Some(xvfb)
}

fn output_dir(test: &str) -> PathBuf {
    let dir = crate::support::compare::output_dir()
        .join("viewer")
        .join(test);
    std::fs::create_dir_all(&dir).expect("create the test output directory");
    dir
}

/// `gpu-render ARGS` with the window on `display` (never a Wayland compositor).
fn gpu_render(display: Option<&str>) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_gpu-render"));
    command.env_remove("WAYLAND_DISPLAY");
    match display {
        Some(display) => command.env("DISPLAY", display),
        None => command.env_remove("DISPLAY"),
    };
    command
}

fn run(mut command: Command) -> (Option<i32>, String) {
    let output = command.output().expect("run gpu-render");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(
        !stderr.contains("panicked"),
        "gpu-render panicked:\n{stderr}"
    );
    (output.status.code(), stderr)
}

fn load_rgba(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .to_rgba8()
}

/// The screenshot after N frames of one sample is the headless GPU render of N
/// samples per pixel, within one 8-bit level except [`OUTLIER_FRACTION`] of pixels.
#[test]
fn the_screenshot_matches_the_headless_render_of_the_same_samples() {
    let Some(xvfb) = window_environment() else {
        return;
    };
    let dir = output_dir("screenshot");
    let screenshot = dir.join("window.png");
    let reference = dir.join("headless.png");
    let _ = std::fs::remove_file(&screenshot);
    let size = ["--width", "160", "--height", "96", "--spp", "4"];

    let mut view = gpu_render(Some(&xvfb.display));
    view.args([
        "view",
        "scenes/showcase.toml",
        "--frames",
        "4",
        "--screenshot",
    ])
    .arg(&screenshot)
    .args(size);
    let (status, stderr) = run(view);
    assert_eq!(status, Some(0), "gpu-render view failed:\n{stderr}");
    assert!(
        stderr.contains("4 frames in") && stderr.contains("4 samples per pixel"),
        "the summary names the frames and samples:\n{stderr}"
    );

    let mut render = gpu_render(None);
    render
        .args(["scenes/showcase.toml", "--backend", "gpu", "-o"])
        .arg(&reference)
        .arg("--standard-error")
        .arg(dir.join("headless-se.exr"))
        .args(size);
    let (status, headless_stderr) = run(render);
    assert_eq!(
        status,
        Some(0),
        "the headless render failed:\n{headless_stderr}"
    );
    // The same samples give the same noise estimate, worded alike.
    let noise = |text: &str| {
        text.split("estimated noise ")
            .nth(1)
            .and_then(|rest| rest.split('%').next())
            .map(str::to_owned)
    };
    let shown_noise = noise(&stderr);
    assert!(
        shown_noise.is_some(),
        "the viewer's summary gives the estimated noise:\n{stderr}"
    );
    assert_eq!(
        shown_noise,
        noise(&headless_stderr),
        "the viewer and the headless render estimate the same noise:\n{stderr}\n{headless_stderr}"
    );

    let shown = load_rgba(&screenshot);
    let expected = load_rgba(&reference);
    assert_eq!(
        shown.dimensions(),
        expected.dimensions(),
        "the window's image has the scene's size"
    );
    let mut outliers = 0usize;
    let mut largest = 0u8;
    for (a, b) in shown.pixels().zip(expected.pixels()) {
        let difference = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        largest = largest.max(difference);
        outliers += usize::from(difference > 1);
    }
    let pixels = (shown.width() * shown.height()) as usize;
    let allowed = (pixels as f64 * OUTLIER_FRACTION).floor() as usize;
    assert!(
        outliers <= allowed,
        "{outliers} of {pixels} pixels differ by more than one level (largest {largest}); \
         {allowed} allowed. See {}",
        dir.display()
    );
    // Not a blank window that happens to match: the showcase has many colours.
    let distinct: std::collections::HashSet<[u8; 4]> = shown.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 100, "{} distinct colours", distinct.len());
}

/// With `--denoise` the window shows the film denoised in the frame loop: after N
/// frames of one sample, the headless `--denoise` render of N samples per pixel (the
/// same filter on the same samples), within one 8-bit level except
/// [`OUTLIER_FRACTION`] of pixels.
#[test]
fn a_denoised_window_shows_the_headless_denoised_render() {
    let Some(xvfb) = window_environment() else {
        return;
    };
    let dir = output_dir("denoised");
    let screenshot = dir.join("window.png");
    let reference = dir.join("headless.png");
    let _ = std::fs::remove_file(&screenshot);
    let size = ["--width", "64", "--height", "64", "--spp", "4"];
    let mut view = gpu_render(Some(&xvfb.display));
    view.args([
        "view",
        "scenes/cornell-box.toml",
        "--denoise",
        "--frames",
        "4",
        "--screenshot",
    ])
    .arg(&screenshot)
    .args(size);
    let (status, stderr) = run(view);
    assert_eq!(status, Some(0), "gpu-render view failed:\n{stderr}");
    let mut render = gpu_render(None);
    render
        .args([
            "scenes/cornell-box.toml",
            "--backend",
            "gpu",
            "--denoise",
            "-o",
        ])
        .arg(&reference)
        .args(size);
    let (status, headless_stderr) = run(render);
    assert_eq!(
        status,
        Some(0),
        "the headless render failed:\n{headless_stderr}"
    );
    let shown = load_rgba(&screenshot);
    let expected = load_rgba(&reference);
    assert_eq!(shown.dimensions(), expected.dimensions());
    let outliers = shown
        .pixels()
        .zip(expected.pixels())
        .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 1))
        .count();
    let pixels = (shown.width() * shown.height()) as usize;
    let allowed = (pixels as f64 * OUTLIER_FRACTION).floor() as usize;
    assert!(
        outliers <= allowed,
        "{outliers} of {pixels} pixels differ by more than one level; {allowed} allowed. See {}",
        dir.display()
    );
}

/// `--scale 0.5` traces a film of half the window's size and draws it scaled up: each
/// 2 x 2 block of the screenshot is one pixel of the headless render at half size,
/// within one 8-bit level except [`OUTLIER_FRACTION`] of pixels. `--adapter` with a
/// name no adapter has is an error that lists the adapters.
#[test]
fn a_scaled_film_fills_the_window_and_the_adapter_can_be_chosen() {
    let Some(xvfb) = window_environment() else {
        return;
    };
    let dir = output_dir("scaled");
    let screenshot = dir.join("window.png");
    let reference = dir.join("headless-half.png");
    let _ = std::fs::remove_file(&screenshot);
    let mut view = gpu_render(Some(&xvfb.display));
    view.args([
        "view",
        "scenes/showcase.toml",
        "--frames",
        "2",
        "--scale",
        "0.5",
        "--width",
        "160",
        "--height",
        "96",
        "--spp",
        "2",
        "--screenshot",
    ])
    .arg(&screenshot);
    let (status, stderr) = run(view);
    assert_eq!(status, Some(0), "gpu-render view --scale failed:\n{stderr}");

    let mut render = gpu_render(None);
    render
        .args(["scenes/showcase.toml", "--backend", "gpu", "-q", "-o"])
        .arg(&reference)
        .args(["--width", "80", "--height", "48", "--spp", "2"]);
    let (status, stderr) = run(render);
    assert_eq!(status, Some(0), "the headless render failed:\n{stderr}");

    let shown = load_rgba(&screenshot);
    let expected = load_rgba(&reference);
    assert_eq!(shown.dimensions(), (160, 96), "the window keeps its size");
    let mut outliers = 0usize;
    for (x, y, a) in shown.enumerate_pixels() {
        let b = expected.get_pixel(x / 2, y / 2);
        let difference = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        outliers += usize::from(difference > 1);
    }
    let pixels = (shown.width() * shown.height()) as usize;
    let allowed = (pixels as f64 * OUTLIER_FRACTION).floor() as usize;
    assert!(
        outliers <= allowed,
        "{outliers} of {pixels} pixels differ from their half-size pixel by more than one \
         level; {allowed} allowed. See {}",
        dir.display()
    );

    let mut view = gpu_render(Some(&xvfb.display));
    view.args([
        "view",
        "scenes/minimal.toml",
        "--frames",
        "1",
        "--adapter",
        "no such adapter",
    ]);
    let (status, stderr) = run(view);
    assert_eq!(status, Some(1), "{stderr}");
    assert!(
        stderr.contains("matches none of the adapters") && stderr.contains("0: "),
        "the error lists the adapters:\n{stderr}"
    );
}

/// A scene file that stops parsing while the window is open: the viewer reports the
/// error, keeps the old scene and goes on; fixing the file reloads it.
#[test]
fn a_broken_reload_keeps_the_old_scene_and_a_fixed_one_reloads() {
    let Some(xvfb) = window_environment() else {
        return;
    };
    let dir = output_dir("reload");
    let scene_path = dir.join("scene.toml");
    let scene = std::fs::read_to_string("scenes/minimal.toml").expect("read the minimal scene");
    std::fs::write(&scene_path, &scene).expect("write the scene");

    let mut view = gpu_render(Some(&xvfb.display));
    view.args([
        "view", "--width", "64", "--height", "48", "--frames", "1000000",
    ])
    .arg(&scene_path)
    .stdout(Stdio::null())
    .stderr(Stdio::piped());
    let mut child = view.spawn().expect("start gpu-render view");
    let stderr = child.stderr.take().expect("piped stderr");
    let (lines_tx, lines) = mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        let mut reader = BufReader::new(stderr);
        loop {
            let mut line = String::new();
            match reader.read_line(&mut line) {
                Ok(0) | Err(_) => break,
                Ok(_) => {
                    all.push_str(&line);
                    let _ = lines_tx.send(line);
                }
            }
        }
        let mut rest = String::new();
        let _ = reader.read_to_string(&mut rest);
        all + &rest
    });
    // Generous bounds on waiting for the program, never assertions on its speed.
    let wait_for = |needle: &str| -> bool {
        while let Ok(line) = lines.recv_timeout(Duration::from_secs(300)) {
            if line.contains(needle) {
                return true;
            }
        }
        false
    };
    let opened = wait_for("viewer: ");
    let mut saw_error = false;
    let mut saw_reload = false;
    if opened {
        // Modification times may be coarse: change the size as well.
        std::fs::write(&scene_path, "[render\nwidth = ").expect("break the scene");
        saw_error = wait_for("error: reloading");
        std::fs::write(&scene_path, format!("{scene}\n# fixed\n")).expect("fix the scene");
        saw_reload = wait_for("viewer: reloaded");
    }
    let still_running = child.try_wait().expect("poll the viewer").is_none();
    let _ = child.kill();
    let _ = child.wait();
    let stderr = reader.join().expect("stderr reader");
    assert!(
        !stderr.contains("panicked"),
        "the viewer panicked:\n{stderr}"
    );
    assert!(opened, "the viewer never opened its window:\n{stderr}");
    assert!(
        saw_error,
        "no reload error reported for the broken file:\n{stderr}"
    );
    assert!(saw_reload, "the fixed file was not reloaded:\n{stderr}");
    assert!(still_running, "the viewer stopped:\n{stderr}");
}

/// Cheap errors need neither a window nor a GPU: a broken scene file is an error
/// naming it, `--screenshot` needs `--frames` and a .png.
#[test]
fn bad_input_is_an_error_before_any_window() {
    let dir = output_dir("errors");
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, "[camera\n").expect("write a broken scene");
    let mut view = gpu_render(None);
    view.arg("view").arg(&broken);
    let (status, stderr) = run(view);
    assert_eq!(status, Some(1), "{stderr}");
    assert!(
        stderr.contains("error:") && stderr.contains("broken.toml"),
        "{stderr}"
    );

    for bad in ["0", "1.5", "-1", "half"] {
        let mut view = gpu_render(None);
        view.args(["view", "scenes/minimal.toml", &format!("--scale={bad}")]);
        let (status, stderr) = run(view);
        assert_eq!(status, Some(2), "--scale {bad}:\n{stderr}");
        assert!(stderr.contains("--scale"), "{stderr}");
    }

    let mut view = gpu_render(None);
    view.args(["view", "scenes/minimal.toml", "--screenshot", "x.png"]);
    let (status, stderr) = run(view);
    assert_eq!(
        status,
        Some(2),
        "clap refuses --screenshot alone:\n{stderr}"
    );

    let mut view = gpu_render(None);
    view.args([
        "view",
        "scenes/minimal.toml",
        "--frames",
        "1",
        "--screenshot",
    ])
    .arg(dir.join("shot.exr"));
    let (status, stderr) = run(view);
    assert_eq!(status, Some(1), "{stderr}");
    assert!(stderr.contains(".png"), "{stderr}");
}
