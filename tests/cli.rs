//! The `gpu-render` program end to end: bad input gives a clear error naming the
//! culprit and exit status 1 (never a panic, never a damaged output file); a good
//! scene gives an image of the requested size.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A small valid scene in the documented format.
const TINY_SCENE: &str = r#"
[render]
width = 32
height = 24
[camera]
eye = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
[materials.white]
type = "lambert"
albedo = 0.7
[[lights]]
type = "point"
position = [0.0, 2.0, 3.0]
intensity = 10.0
[[objects]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
"#;

/// Bytes that must survive a failed run untouched.
const OLD_OUTPUT: &[u8] = b"an older image that a failed run must not touch";

struct Run {
    status: Option<i32>,
    stdout: String,
    stderr: String,
}

fn gpu_render(args: &[&str]) -> Run {
    let Output {
        status,
        stdout,
        stderr,
    } = Command::new(env!("CARGO_BIN_EXE_gpu-render"))
        .args(args)
        .output()
        .expect("run gpu-render");
    let run = Run {
        status: status.code(),
        stdout: String::from_utf8_lossy(&stdout).into_owned(),
        stderr: String::from_utf8_lossy(&stderr).into_owned(),
    };
    assert!(
        !run.stderr.contains("panicked"),
        "gpu-render panicked on {args:?}:\n{}",
        run.stderr
    );
    run
}

/// A temporary directory holding `scene.toml` with `text` and an existing `out.png`.
struct Workspace {
    dir: tempfile::TempDir,
}

impl Workspace {
    fn new(scene_text: &str) -> Self {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(dir.path().join("scene.toml"), scene_text).expect("write scene");
        std::fs::write(dir.path().join("out.png"), OLD_OUTPUT).expect("write old output");
        Self { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    fn assert_old_output_kept(&self) {
        let now = std::fs::read(self.path("out.png")).expect("read out.png");
        assert_eq!(now, OLD_OUTPUT, "a failed run changed the existing output");
        let mut names: Vec<String> = std::fs::read_dir(self.dir.path())
            .expect("list workspace")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["out.png", "scene.toml"], "stray files left behind");
    }
}

/// Asserts a failed run: status 1 and every `needle` in stderr.
fn assert_fails_with(run: &Run, needles: &[&str]) {
    assert_eq!(
        run.status,
        Some(1),
        "expected exit 1, stderr:\n{}",
        run.stderr
    );
    assert!(run.stderr.starts_with("error: "), "stderr:\n{}", run.stderr);
    for needle in needles {
        assert!(
            run.stderr.contains(needle),
            "stderr lacks {needle:?}:\n{}",
            run.stderr
        );
    }
    assert!(run.stdout.is_empty(), "stdout: {}", run.stdout);
}

fn read_png_size(path: &Path) -> (u32, u32) {
    let image = image::open(path).expect("open output image");
    (image.width(), image.height())
}

// ---------------------------------------------------------------- bad input

#[test]
fn missing_scene_file() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("no-such-scene.toml"),
        "-o",
        &ws.arg("out.png"),
        "--backend",
        "cpu",
    ]);
    assert_fails_with(&run, &["no-such-scene.toml", "cannot read"]);
    ws.assert_old_output_kept();
}

#[test]
fn unknown_output_extension() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[&ws.arg("scene.toml"), "-o", &ws.arg("out.jpg")]);
    assert_fails_with(&run, &["out.jpg", "unsupported output format", ".png"]);
    ws.assert_old_output_kept();
}

#[test]
fn output_into_missing_directory() {
    let ws = Workspace::new(TINY_SCENE);
    let target = ws.path("no-such-dir").join("out.png");
    let run = gpu_render(&[&ws.arg("scene.toml"), "-o", &target.to_string_lossy()]);
    assert_fails_with(&run, &["no-such-dir", "does not exist"]);
    ws.assert_old_output_kept();
}

#[test]
fn zero_width() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("scene.toml"),
        "-o",
        &ws.arg("out.png"),
        "--width",
        "0",
    ]);
    assert_fails_with(&run, &["--width 0", "width must be between 1 and"]);
    ws.assert_old_output_kept();
}

#[test]
fn compare_gamma_needs_png() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("scene.toml"),
        "-o",
        &ws.arg("out.exr"),
        "--compare-gamma",
    ]);
    assert_fails_with(&run, &["out.exr", "--compare-gamma", ".png"]);
    ws.assert_old_output_kept();
}

#[test]
fn adapter_with_cpu_backend_is_refused() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("scene.toml"),
        "-o",
        &ws.arg("out.png"),
        "--backend",
        "cpu",
        "--adapter",
        "0",
    ]);
    assert_fails_with(&run, &["--adapter", "--backend cpu"]);
    ws.assert_old_output_kept();
}

#[test]
fn usage_errors_keep_clap_status() {
    let run = gpu_render(&["scene.toml"]);
    assert_eq!(run.status, Some(2), "stderr:\n{}", run.stderr);
    assert!(run.stderr.contains("--output"), "stderr:\n{}", run.stderr);
    let run = gpu_render(&["scene.toml", "-o", "x.png", "--width", "wide"]);
    assert_eq!(run.status, Some(2), "stderr:\n{}", run.stderr);
    let run = gpu_render(&["--adapter", "0"]);
    assert_eq!(run.status, Some(2), "stderr:\n{}", run.stderr);
}

#[test]
fn help_describes_rendering() {
    let run = gpu_render(&["--help"]);
    assert_eq!(run.status, Some(0));
    for needle in [
        "SCENE",
        "--output",
        "--spp",
        "--backend",
        "--adapter",
        ".exr",
    ] {
        assert!(
            run.stdout.contains(needle),
            "help lacks {needle}:\n{}",
            run.stdout
        );
    }
}

#[test]
fn adapter_list_exits_zero() {
    let run = gpu_render(&["--adapter", "list"]);
    assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
    assert!(!run.stdout.trim().is_empty(), "nothing listed");
}

// The tests below need the real scene parser (and, for the renders, the CPU tracer);
// they pass once those are merged.

#[test]
fn malformed_toml() {
    let ws = Workspace::new("[render]\nwidth = 32\nheight = = 24\n");
    let run = gpu_render(&[&ws.arg("scene.toml"), "-o", &ws.arg("out.png")]);
    // The parser reports file:line:col; the error is on line 3.
    assert_fails_with(&run, &["scene.toml:3:"]);
    ws.assert_old_output_kept();
}

#[test]
fn undefined_material() {
    let scene = TINY_SCENE.replace("material = \"white\"", "material = \"chalk\"");
    let ws = Workspace::new(&scene);
    let run = gpu_render(&[&ws.arg("scene.toml"), "-o", &ws.arg("out.png")]);
    assert_fails_with(&run, &["scene.toml:", "chalk"]);
    ws.assert_old_output_kept();
}

#[test]
fn cpu_render_writes_png_of_requested_size() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("scene.toml"),
        "-o",
        &ws.arg("out.png"),
        "--backend",
        "cpu",
        "--width",
        "32",
        "--height",
        "24",
    ]);
    assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
    assert!(run.stdout.is_empty(), "stdout: {}", run.stdout);
    assert!(run.stderr.contains("32x24"), "summary:\n{}", run.stderr);
    assert!(run.stderr.contains("out.png"), "summary:\n{}", run.stderr);
    assert_eq!(read_png_size(&ws.path("out.png")), (32, 24));
}

#[test]
fn cpu_render_writes_exr_and_hdr_quietly() {
    let ws = Workspace::new(TINY_SCENE);
    for name in ["out.exr", "out.hdr"] {
        let run = gpu_render(&[
            &ws.arg("scene.toml"),
            "-o",
            &ws.arg(name),
            "--backend",
            "cpu",
            "--width",
            "16",
            "--height",
            "8",
            "--quiet",
        ]);
        assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
        assert!(run.stderr.is_empty(), "quiet run printed:\n{}", run.stderr);
        assert_eq!(read_png_size(&ws.path(name)), (16, 8));
    }
}

#[test]
fn compare_gamma_is_twice_as_wide() {
    let ws = Workspace::new(TINY_SCENE);
    let run = gpu_render(&[
        &ws.arg("scene.toml"),
        "-o",
        &ws.arg("out.png"),
        "--backend",
        "cpu",
        "--compare-gamma",
    ]);
    assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
    assert_eq!(read_png_size(&ws.path("out.png")), (64, 24));
}

fn shipped_path(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(name)
        .to_string_lossy()
        .into_owned()
}

#[test]
fn brdf_check_accepts_a_plausible_map() {
    let run = gpu_render(&["brdf-check", &shipped_path("scenes/brdf/plausible.png")]);
    assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
    for rule in ["positivity:", "energy:", "reciprocity:"] {
        let line = run
            .stdout
            .lines()
            .find(|l| l.starts_with(rule))
            .unwrap_or_else(|| panic!("no {rule} line in:\n{}", run.stdout));
        assert!(line.contains(" ok "), "{line}");
    }
}

#[test]
fn brdf_check_reports_every_violated_rule() {
    let path = shipped_path("scenes/brdf/implausible.exr");
    let run = gpu_render(&["brdf-check", &path]);
    assert_eq!(run.status, Some(1), "stderr:\n{}", run.stderr);
    assert_eq!(run.stdout.matches("VIOLATED").count(), 3, "{}", run.stdout);
    assert!(run.stderr.contains("implausible.exr"), "{}", run.stderr);
    let missing = gpu_render(&["brdf-check", "/nonexistent/map.png"]);
    assert_fails_with(&missing, &["/nonexistent/map.png", "cannot read"]);
}
