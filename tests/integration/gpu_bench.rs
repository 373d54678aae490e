//! `scripts/gpu-bench.sh`, the real-GPU benchmark (issue 30), run here in its smoke
//! mode (tiny images, one run) with this build's `gpu-render`, so that the script
//! cannot rot between the rare runs on a real GPU: every row of its table must be there,
//! with a positive figure. The tools crate's `bench` (the million-triangle row) is not
//! part of this build, so that row is left out with `--no-bench` and must say so.

use std::process::{Command, Output};

use crate::support::repo_root;

fn script() -> std::path::PathBuf {
    repo_root().join("scripts/gpu-bench.sh")
}

fn describe(output: &Output) -> String {
    format!(
        "status {}\n--- stdout\n{}--- stderr\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// The table's rows (the lines starting with `| `, its header and rule left out), each
/// as its cells.
fn rows(table: &str) -> Vec<Vec<String>> {
    table
        .lines()
        .filter(|line| line.starts_with("| ") && !line.starts_with("| benchmark |"))
        .map(|line| {
            line.trim_matches('|')
                .split(" | ")
                .map(|cell| cell.trim().to_owned())
                .collect()
        })
        .collect()
}

/// The row whose first cell starts with `label`.
fn row<'a>(rows: &'a [Vec<String>], label: &str, table: &str) -> &'a [String] {
    rows.iter()
        .find(|cells| cells[0].starts_with(label))
        .unwrap_or_else(|| panic!("no row {label:?} in the table:\n{table}"))
}

/// The number that starts the figure cell (`**6.5 M rays/s**`), which must be positive
/// and in `unit`.
fn figure(cells: &[String], unit: &str, table: &str) -> f64 {
    let text = cells[2].trim_matches('*');
    let (number, rest) = text.split_once(' ').unwrap_or((text, ""));
    let value: f64 = number.parse().unwrap_or_else(|e| {
        panic!(
            "{:?}: figure {text:?} is not a number ({e}):\n{table}",
            cells[0]
        )
    });
    assert!(
        value > 0.0 && value.is_finite(),
        "{:?}: figure {value}:\n{table}",
        cells[0]
    );
    assert!(
        rest.starts_with(unit),
        "{:?}: {text:?} is not in {unit}:\n{table}",
        cells[0]
    );
    value
}

#[test]
fn smoke_run_fills_every_row() {
    let out = tempfile::tempdir().expect("tempdir");
    let output = Command::new("bash")
        .arg(script())
        .args([
            "--smoke",
            "--no-bench",
            "--model",
            "scenes/models/vase.gltf",
        ])
        .arg("--gpu-render")
        .arg(env!("CARGO_BIN_EXE_gpu-render"))
        .arg("--out")
        .arg(out.path())
        .current_dir(repo_root())
        .output()
        .expect("run bash");
    // Status 3: no adapter at all. Allowed on a developer machine, never in CI.
    if output.status.code() == Some(3) && std::env::var_os("CI").is_none() {
        eprintln!(
            "note: skipping the gpu-bench smoke run, no GPU adapter:\n{}",
            describe(&output)
        );
        return;
    }
    assert!(
        output.status.success(),
        "gpu-bench.sh --smoke failed:\n{}",
        describe(&output)
    );
    let table = String::from_utf8(output.stdout.clone()).expect("UTF-8 table");
    let rows = rows(&table);

    let adapter = row(&rows, "adapter", &table);
    assert!(!adapter[1].is_empty(), "no adapter name:\n{table}");
    for feature in [
        "SUBGROUP",
        "TIMESTAMP_QUERY",
        "EXPERIMENTAL_RAY_QUERY",
        "PIPELINE_CACHE",
    ] {
        assert!(
            adapter[3].contains(&format!("{feature} yes"))
                || adapter[3].contains(&format!("{feature} no")),
            "the adapter row does not say whether it has {feature}:\n{table}"
        );
    }
    figure(row(&rows, "showcase", &table), "M rays/s", &table);
    figure(
        row(&rows, "Cornell box, path traced", &table),
        "M samples/s",
        &table,
    );
    figure(row(&rows, "model vase.gltf", &table), "M rays/s", &table);
    figure(row(&rows, "kernel compile, cold", &table), "s", &table);
    figure(row(&rows, "kernel compile, warm", &table), "s", &table);
    let software = row(&rows, "million-triangle, software BVH", &table);
    assert_eq!(software[2], "skipped", "{table}");
    assert!(software[3].contains("--no-bench"), "{table}");
    // The hardware row: skipped like the software one where the adapter has ray
    // queries (lavapipe has), n/a where it has none.
    let hardware = row(&rows, "million-triangle, hardware ray queries", &table);
    if adapter[3].contains("EXPERIMENTAL_RAY_QUERY yes") {
        assert_eq!(hardware[2], "skipped", "{table}");
        assert!(hardware[4].contains("--gpu-traversal hardware"), "{table}");
    } else {
        assert!(hardware[2].starts_with("n/a"), "{table}");
    }
    // Every row names its command (but an n/a one), and the file holds the same table.
    for cells in &rows {
        if !cells[2].starts_with("n/a") {
            assert!(
                cells[4].starts_with('`'),
                "{:?} lacks its command:\n{table}",
                cells[0]
            );
        }
    }
    let written = std::fs::read_to_string(out.path().join("gpu-bench.md")).expect("gpu-bench.md");
    assert_eq!(written, table, "gpu-bench.md differs from what was printed");
    assert!(
        out.path().join("images/showcase.png").is_file(),
        "no image kept in --out"
    );
}

#[test]
fn missing_binaries_are_a_clear_error() {
    let empty = tempfile::tempdir().expect("tempdir");
    let output = Command::new("bash")
        .arg(script())
        .args(["--smoke", "--bin-dir"])
        .arg(empty.path())
        .current_dir(repo_root())
        .output()
        .expect("run bash");
    assert_eq!(output.status.code(), Some(2), "{}", describe(&output));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("gpu-render not found")
            && stderr.contains(&empty.path().display().to_string()),
        "{}",
        describe(&output)
    );
    assert!(output.stdout.is_empty(), "{}", describe(&output));
}

#[test]
fn script_parses_and_explains_itself() {
    let output = Command::new("bash")
        .arg("-n")
        .arg(script())
        .output()
        .expect("run bash");
    assert!(output.status.success(), "{}", describe(&output));
    let help = Command::new("bash")
        .arg(script())
        .arg("--help")
        .output()
        .expect("run bash");
    assert!(help.status.success(), "{}", describe(&help));
    let text = String::from_utf8_lossy(&help.stdout);
    for option in ["--smoke", "--bin-dir", "--out", "--no-bench"] {
        assert!(text.contains(option), "--help lacks {option}:\n{text}");
    }
}
