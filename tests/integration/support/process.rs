//! Running the built `gpu-render` program: its exit status and output, with a check
//! that it never panicked.

use std::ffi::OsStr;
use std::process::{Command, Output};

/// What one run of the program printed and returned.
pub struct Run {
    /// The exit status (`None` if a signal ended it).
    pub status: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// The built program. Cargo names it to integration tests only; the examples that
/// share these helpers never run it.
fn program() -> &'static str {
    match option_env!("CARGO_BIN_EXE_gpu-render") {
        Some(path) => path,
        None => panic!("CARGO_BIN_EXE_gpu-render is set for integration tests only"),
    }
}

/// Runs `gpu-render` with `args`; fails the test if it panicked.
pub fn gpu_render<S: AsRef<OsStr>>(args: &[S]) -> Run {
    let Output {
        status,
        stdout,
        stderr,
    } = Command::new(program())
        .args(args)
        .output()
        .expect("run gpu-render");
    let run = Run {
        status: status.code(),
        stdout: String::from_utf8_lossy(&stdout).into_owned(),
        stderr: String::from_utf8_lossy(&stderr).into_owned(),
    };
    let shown: Vec<_> = args.iter().map(|a| a.as_ref().to_string_lossy()).collect();
    assert!(
        !run.stderr.contains("panicked"),
        "gpu-render panicked on {shown:?}:\n{}",
        run.stderr
    );
    run
}

/// Bytes a test writes where a run's output goes, which a failed run must leave
/// untouched.
pub const OLD_OUTPUT: &[u8] = b"an older image that a failed run must not touch";

/// Asserts a failed run: status 1 and an `error: ` message holding every `needle`.
pub fn assert_failed(run: &Run, needles: &[&str]) {
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
}

/// [`assert_failed`], and nothing on standard output.
pub fn assert_fails_with(run: &Run, needles: &[&str]) {
    assert_failed(run, needles);
    assert!(run.stdout.is_empty(), "stdout: {}", run.stdout);
}
