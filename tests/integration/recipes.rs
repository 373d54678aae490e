//! The scheduler recipes of `distributed/` (docs/distributed.md), checked and run on
//! this machine: every script passes `bash -n`; the Slurm scripts run as an array
//! would run them (each index with `SLURM_ARRAY_TASK_ID`, `submit.sh` through a
//! stand-in `sbatch` that runs the array and then the merge it queues); the
//! Kubernetes manifests parse, agree with each other, and their containers' commands
//! run with `JOB_COMPLETION_INDEX`; the GNU parallel recipe runs for real. Each ends
//! with the merged image compared byte for byte with a whole render.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_norway::Value;

const SCENE: &str = "[render]\nwidth = 24\nheight = 20\nsamples_per_pixel = 2\n\
    [camera]\neye = [0, 0.5, 3]\nlook_at = [0, 0, 0]\n\
    [materials.m]\ntype = \"lambert\"\nalbedo = [0.7, 0.4, 0.2]\n\
    [materials.glass]\ntype = \"dielectric\"\nior = 1.5\n\
    [[lights]]\ntype = \"point\"\nposition = [1, 2, 3]\nintensity = 8\n\
    [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
    [[objects]]\ntype = \"sphere\"\ncenter = [0.6, 0.2, 1.2]\nradius = 0.3\nmaterial = \"glass\"\n";

fn recipes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("distributed")
}

fn binary() -> &'static str {
    env!("CARGO_BIN_EXE_gpu-render")
}

/// A folder with `scene.toml` and the whole render of it, `whole.png`.
fn workspace() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("scene.toml"), SCENE).expect("scene");
    let status = Command::new(binary())
        .arg(dir.path().join("scene.toml"))
        .args(["--backend", "cpu", "-q", "-o"])
        .arg(dir.path().join("whole.png"))
        .status()
        .expect("whole render");
    assert!(status.success());
    dir
}

fn assert_same_bytes(a: &Path, b: &Path) {
    let (x, y) = (std::fs::read(a), std::fs::read(b));
    assert!(
        matches!((&x, &y), (Ok(x), Ok(y)) if x == y),
        "{} and {} differ (or one is missing)",
        a.display(),
        b.display()
    );
}

/// Runs `command`, panicking with its output unless it succeeds.
fn run(command: &mut Command, what: &str) {
    let output = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        output.status.success(),
        "{what} failed ({}):\n{}{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

fn scripts() -> Vec<PathBuf> {
    let mut scripts = Vec::new();
    for sub in ["slurm", "parallel"] {
        for entry in std::fs::read_dir(recipes().join(sub)).expect("recipe folder") {
            let path = entry.expect("entry").path();
            if path.extension().is_some_and(|e| e == "sh" || e == "sbatch") {
                scripts.push(path);
            }
        }
    }
    scripts.sort();
    scripts
}

#[test]
fn every_script_parses_as_bash() {
    let scripts = scripts();
    assert_eq!(scripts.len(), 4, "{scripts:?}");
    for script in scripts {
        run(
            Command::new("bash").arg("-n").arg(&script),
            &script.display().to_string(),
        );
    }
}

#[test]
fn the_slurm_array_and_its_merge_run_as_slurm_would_run_them() {
    let dir = workspace();
    let slurm = recipes().join("slurm");
    let env = |command: &mut Command| {
        command
            .env("SCENE", dir.path().join("scene.toml"))
            .env("OUT_DIR", dir.path().join("tiles"))
            .env("OUTPUT", dir.path().join("merged.png"))
            .env("GPU_RENDER", binary())
            .env("BACKEND", "cpu")
            .env_remove("TILES")
            .current_dir(dir.path());
    };
    // Each task of `sbatch --array=0-4`, with the variables Slurm sets.
    for index in 0..5 {
        let mut task = Command::new("bash");
        task.arg(slurm.join("render.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", index.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", "5");
        env(&mut task);
        run(&mut task, &format!("array task {index}"));
    }
    let mut merge = Command::new("bash");
    merge.arg(slurm.join("merge.sbatch"));
    env(&mut merge);
    run(&mut merge, "merge.sbatch");
    assert_same_bytes(
        &dir.path().join("merged.png"),
        &dir.path().join("whole.png"),
    );

    // submit.sh through a stand-in sbatch: it logs its arguments, runs an array's
    // tasks one after the other and prints a job id, as `sbatch --parsable` does.
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).expect("bin");
    let fake = bin.join("sbatch");
    std::fs::write(
        &fake,
        "#!/usr/bin/env bash\nset -eu\necho \"$*\" >> \"$SBATCH_LOG\"\narray=''\n\
         for a in \"$@\"; do case \"$a\" in --array=*) array=${a#--array=};; -*) ;; *) script=$a;; esac; done\n\
         if [ -n \"$array\" ]; then\n  first=${array%-*}; last=${array#*-}\n\
           for i in $(seq \"$first\" \"$last\"); do\n\
             SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$((last - first + 1)) bash \"$script\"\n  done\n\
         else bash \"$script\"; fi\necho $((1000 + $(wc -l < \"$SBATCH_LOG\")))\n",
    )
    .expect("fake sbatch");
    run(Command::new("chmod").arg("+x").arg(&fake), "chmod");
    std::fs::remove_dir_all(dir.path().join("tiles")).expect("clear tiles");
    let log = dir.path().join("sbatch.log");
    let mut submit = Command::new("bash");
    submit
        .arg(slurm.join("submit.sh"))
        .env(
            "PATH",
            format!(
                "{}:{}",
                bin.display(),
                std::env::var("PATH").unwrap_or_default()
            ),
        )
        .env("SBATCH_LOG", &log)
        .env("OUTPUT", dir.path().join("submitted.png"));
    env(&mut submit);
    submit
        .env("TILES", "3")
        .env("OUTPUT", dir.path().join("submitted.png"));
    run(&mut submit, "submit.sh");
    let calls = std::fs::read_to_string(&log).expect("sbatch log");
    let calls: Vec<&str> = calls.lines().collect();
    assert_eq!(calls.len(), 2, "{calls:?}");
    assert!(calls[0].contains("--array=0-2") && calls[0].ends_with("render.sbatch"));
    assert!(
        calls[1].contains("--dependency=afterok:1001") && calls[1].ends_with("merge.sbatch"),
        "{calls:?}"
    );
    assert_same_bytes(
        &dir.path().join("submitted.png"),
        &dir.path().join("whole.png"),
    );
}

fn manifest(name: &str) -> Value {
    let path = recipes().join("kubernetes").join(name);
    let text = std::fs::read_to_string(&path).expect("manifest");
    serde_norway::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn at<'a>(value: &'a Value, path: &[&str]) -> &'a Value {
    path.iter()
        .fold(value, |v, key| match key.parse::<usize>() {
            Ok(i) => &v[i],
            Err(_) => &v[*key],
        })
}

fn text<'a>(value: &'a Value, path: &[&str]) -> &'a str {
    at(value, path)
        .as_str()
        .unwrap_or_else(|| panic!("{path:?} is not a string in {value:?}"))
}

/// The container's `env` as a map.
fn container_env(job: &Value) -> BTreeMap<String, String> {
    let list = at(job, &["spec", "template", "spec", "containers", "0", "env"])
        .as_sequence()
        .expect("env list");
    list.iter()
        .map(|e| {
            (
                text(e, &["name"]).to_owned(),
                text(e, &["value"]).to_owned(),
            )
        })
        .collect()
}

/// Runs the container's `command` and `args` here, with `env` over the manifest's.
fn run_container(job: &Value, env: &[(&str, String)], bin: &Path, what: &str) {
    let container = at(job, &["spec", "template", "spec", "containers", "0"]);
    let command: Vec<&str> = at(container, &["command"])
        .as_sequence()
        .expect("command")
        .iter()
        .chain(at(container, &["args"]).as_sequence().expect("args"))
        .map(|v| v.as_str().expect("a string"))
        .collect();
    let mut process = Command::new(command[0]);
    process.args(&command[1..]).envs(container_env(job)).env(
        "PATH",
        format!(
            "{}:{}",
            bin.display(),
            std::env::var("PATH").unwrap_or_default()
        ),
    );
    for (name, value) in env {
        process.env(name, value);
    }
    run(&mut process, what);
}

#[test]
fn the_kubernetes_indexed_job_and_its_merge_agree_and_run() {
    let tiles = manifest("render-tiles.yaml");
    let merge = manifest("merge.yaml");
    for job in [&tiles, &merge] {
        assert_eq!(text(job, &["apiVersion"]), "batch/v1");
        assert_eq!(text(job, &["kind"]), "Job");
        assert_eq!(
            text(job, &["spec", "template", "spec", "restartPolicy"]),
            "Never"
        );
    }
    assert_eq!(text(&tiles, &["spec", "completionMode"]), "Indexed");
    let completions = at(&tiles, &["spec", "completions"])
        .as_u64()
        .expect("completions");
    assert_eq!(
        at(&tiles, &["spec", "parallelism"]).as_u64(),
        Some(completions)
    );
    let env = container_env(&tiles);
    assert_eq!(env["TILES"], completions.to_string(), "TILES = completions");
    assert_eq!(container_env(&merge)["OUT_DIR"], env["OUT_DIR"]);
    let claim = |job: &Value| {
        text(
            job,
            &[
                "spec",
                "template",
                "spec",
                "volumes",
                "0",
                "persistentVolumeClaim",
                "claimName",
            ],
        )
        .to_owned()
    };
    assert_eq!(claim(&tiles), claim(&merge));

    // Every pod's command, here: gpu-render on PATH, the scene and folders local.
    let dir = workspace();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).expect("bin");
    std::os::unix::fs::symlink(binary(), bin.join("gpu-render")).expect("link");
    let local = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let out_dir = ("OUT_DIR", local("tiles"));
    for index in 0..completions {
        run_container(
            &tiles,
            &[
                ("JOB_COMPLETION_INDEX", index.to_string()),
                ("SCENE", local("scene.toml")),
                ("BACKEND", "cpu".into()),
                out_dir.clone(),
            ],
            &bin,
            &format!("pod {index}"),
        );
    }
    run_container(
        &merge,
        &[out_dir, ("OUTPUT", local("merged.png"))],
        &bin,
        "merge pod",
    );
    assert_same_bytes(
        &dir.path().join("merged.png"),
        &dir.path().join("whole.png"),
    );
}

#[test]
fn the_gnu_parallel_recipe_renders_tiles_and_frames() {
    let installed = Command::new("parallel")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !installed {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but GNU parallel is missing (scripts/test.sh installs it)"
        );
        eprintln!("note: skipping the GNU parallel recipe: parallel is not installed");
        return;
    }
    let dir = workspace();
    let script = recipes().join("parallel").join("render.sh");
    let mut tiles = Command::new("bash");
    tiles
        .arg(&script)
        .args(["tiles"])
        .arg(dir.path().join("scene.toml"))
        .arg("11")
        .arg(dir.path().join("merged.png"))
        .env("GPU_RENDER", binary())
        .env("JOBS", "2")
        .env("BACKEND", "cpu")
        .env_remove("ADAPTERS")
        .env("WORK_DIR", dir.path().join("tiles"));
    run(&mut tiles, "render.sh tiles");
    assert_same_bytes(
        &dir.path().join("merged.png"),
        &dir.path().join("whole.png"),
    );
    // Zero-padded like {tile}: 11 tiles are 00 to 10.
    assert!(dir.path().join("tiles").join("tile-07.exr").exists());

    let orbit = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/animation/orbit.toml");
    let mut frames = Command::new("bash");
    frames
        .arg(&script)
        .arg("frames")
        .arg(&orbit)
        .args(["46", "48"])
        .env("GPU_RENDER", binary())
        .env("JOBS", "2")
        .env("BACKEND", "cpu")
        .env("GPU_RENDER_ARGS", "--width 32 --height 18 --spp 1")
        .env_remove("ADAPTERS")
        .env("FRAME_NAME", dir.path().join("frames/f-{frame}.png"));
    run(&mut frames, "render.sh frames");
    for frame in ["0046", "0047", "0048"] {
        let path = dir.path().join(format!("frames/f-{frame}.png"));
        assert!(path.exists(), "{}", path.display());
    }
}
