//! A long whole-pipeline fuzzing campaign: the generator and check of
//! `tests/integration/fuzz_pipeline.rs` (`tests/integration/support/pipeline.rs`) run for `--cases N` scenes from
//! `--seed S`, continuing past failures. Each failing scene is shrunk to a small one and
//! written, with the failure as a comment, to
//! `tests/fixtures/pipeline-open/campaign-S-K.toml` (open finds: triage them, see
//! `docs/fuzzing.md`, and move the fixed ones to `tests/fixtures/pipeline-regressions/`,
//! which the test replays); a line with the date, seed, cases, time and finds is
//! appended to the record in `docs/fuzzing.md`.
//!
//! ```sh
//! XDG_RUNTIME_DIR=/tmp/xdg WGPU_BACKEND=vulkan \
//!     cargo run --release -p gpu-render-tools --bin fuzz_campaign -- --cases 10000 --seed 1
//! ```
//!
//! `--no-record` leaves `docs/fuzzing.md` alone; `--minutes M` stops after M minutes
//! (recording the cases actually run); `--keep N` writes at most N finds (default 25;
//! the rest are counted, and most are more of the same).
//!
//! Each failing case is also classified by what the loader says about it: a scene it
//! warns about as beyond `f32` (a sphere, triangle or view the GPU cannot place, the
//! far side of a sphere around the camera, coincident spheres: `docs/numerics.md`) is
//! a known limit, counted apart; only the unwarned ones are kept for triage.

#[path = "../../../tests/integration/support/mod.rs"]
#[allow(dead_code)]
mod support;

use support::pipeline;

use std::io::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use gpu_render::gpu::{AdapterChoice, HeadlessGpu};
use gpu_render::scene::{LoadOptions, SceneWarning, parse_scene_with};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

struct Args {
    cases: u64,
    seed: u64,
    minutes: Option<f64>,
    record: bool,
    keep: u64,
}

fn parse_args() -> Args {
    let mut args = Args {
        cases: 1000,
        seed: 1,
        minutes: None,
        record: true,
        keep: 25,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .unwrap_or_else(|| panic!("{name} needs a value"))
                .parse::<f64>()
                .unwrap_or_else(|e| panic!("{name}: {e}"))
        };
        match flag.as_str() {
            "--cases" => args.cases = value("--cases") as u64,
            "--seed" => args.seed = value("--seed") as u64,
            "--minutes" => args.minutes = Some(value("--minutes")),
            "--no-record" => args.record = false,
            "--keep" => args.keep = value("--keep") as u64,
            other => panic!(
                "unknown argument {other:?} (use --cases N, --seed S, --minutes M, --keep N, \
                 --no-record)"
            ),
        }
    }
    args
}

/// Shrinks a failing case the way proptest does: simplify while it still fails,
/// complicate back when it passes, at most 256 checks.
fn shrink(
    checker: &pipeline::PipelineChecker,
    mut tree: impl ValueTree<Value = String>,
    mut reason: String,
) -> (String, String) {
    let mut last_failing = tree.current();
    if !tree.simplify() {
        return (last_failing, reason);
    }
    for _ in 0..256 {
        match checker.check(&tree.current()) {
            Err(failed) => {
                last_failing = tree.current();
                reason = failed.reason;
                if !tree.simplify() {
                    break;
                }
            }
            Ok(_) => {
                if !tree.complicate() {
                    break;
                }
            }
        }
    }
    (last_failing, reason)
}

fn main() {
    let args = parse_args();
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).expect("a GPU adapter");
    let adapter = gpu.adapter_info().name;
    let checker = pipeline::PipelineChecker::new(gpu);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&args.seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &bytes),
    );
    let strategy = pipeline::scene_text();
    let corpus =
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("tests/fixtures/pipeline-open");
    std::fs::create_dir_all(&corpus).expect("tests/fixtures/pipeline-open/ created");
    let started = Instant::now();
    let deadline = args
        .minutes
        .map(|m| started + Duration::from_secs_f64(m * 60.0));
    let (mut run, mut finds, mut warned) = (0u64, Vec::new(), 0u64);
    while run < args.cases && deadline.is_none_or(|d| Instant::now() < d) {
        let tree = strategy
            .new_tree(&mut runner)
            .expect("a scene is generated");
        run += 1;
        if let Err(failed) = checker.check(&tree.current()) {
            if warned_beyond_f32(&tree.current()) {
                warned += 1;
                continue;
            }
            if finds.len() as u64 >= args.keep {
                finds.push((run, failed.reason));
                continue;
            }
            let (text, reason) = shrink(&checker, tree, failed.reason);
            let path = corpus.join(format!("campaign-{}-{run}.toml", args.seed));
            let header: String = reason.lines().map(|l| format!("# {l}\n")).collect();
            std::fs::write(&path, format!("{header}{text}")).expect("corpus file written");
            eprintln!("case {run}: {reason}\n  -> {}", path.display());
            finds.push((run, reason));
        }
        if run % 500 == 0 {
            eprintln!(
                "{run} cases, {} finds unwarned, {warned} warned as beyond f32, {:.0} s",
                finds.len(),
                started.elapsed().as_secs_f64()
            );
        }
    }
    let elapsed = started.elapsed().as_secs_f64();
    let summary = format!(
        "| {} | {} | {run} | {:.0} s | {adapter} | {} |",
        date(),
        args.seed,
        elapsed,
        if finds.is_empty() && warned == 0 {
            "none".to_owned()
        } else {
            format!(
                "{} failing cases: {warned} warned at load as beyond f32, {} unwarned ({} kept as \
                 `campaign-{}-CASE.toml` in tests/fixtures/pipeline-open/)",
                finds.len() as u64 + warned,
                finds.len(),
                finds.len().min(args.keep as usize),
                args.seed
            )
        }
    );
    println!("{summary}");
    if args.record {
        let doc = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("docs/fuzzing.md");
        let mut file = std::fs::OpenOptions::new()
            .append(true)
            .open(&doc)
            .expect("docs/fuzzing.md exists");
        writeln!(file, "{summary}").expect("record appended");
    }
}

/// Whether the loader warns that scene `text` is beyond what the GPU's `f32` can place
/// (its warnings that name the GPU's f32 precision).
fn warned_beyond_f32(text: &str) -> bool {
    let found = std::sync::atomic::AtomicBool::new(false);
    let warn = |w: &SceneWarning| {
        if w.message.contains("(f32") {
            found.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    };
    let options = LoadOptions {
        warning: Some(&warn),
        ..LoadOptions::default()
    };
    parse_scene_with(text, Path::new("<fuzz>"), &options).is_ok()
        && found.load(std::sync::atomic::Ordering::Relaxed)
}

/// Today's UTC date as YYYY-MM-DD (civil-from-days, Howard Hinnant's algorithm).
fn date() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}
