//! Tiles and frames end to end, through the built program: tiles rendered in separate
//! processes and merged are the whole render byte for byte (the EXR's and the PNG's
//! files, compared like `cmp`) on each backend; `merge` refuses a missing tile, an
//! overlapping tile and a tile of another scene, frame or backend with a message
//! naming the files and the pixels; `--frame` renders the camera path.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The showcase (polygons, triangles, glass, a mirror, three lights) made small.
const SHOWCASE_ARGS: [&str; 6] = ["--width", "96", "--height", "54", "--spp", "2"];

use crate::support::process::{Run, assert_failed, gpu_render};

fn succeeds(run: Run) -> Run {
    assert_eq!(run.status, Some(0), "stderr:\n{}", run.stderr);
    run
}

fn shipped(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn arg(path: &Path) -> String {
    path.to_string_lossy().into_owned()
}

/// Asserts that two files hold the same bytes, naming the first difference.
fn assert_same_bytes(a: &Path, b: &Path) {
    let (x, y) = (
        std::fs::read(a).expect("read first"),
        std::fs::read(b).expect("read second"),
    );
    let first_difference = x.iter().zip(&y).position(|(p, q)| p != q);
    assert!(
        x.len() == y.len() && first_difference.is_none(),
        "{} ({} bytes) and {} ({} bytes) differ, first at byte {first_difference:?}",
        a.display(),
        x.len(),
        b.display(),
        y.len()
    );
}

/// Renders 4 tiles of `scene` in 4 processes at once, merges them into .exr, .png
/// and .hdr, renders the whole image, and compares the files byte for byte.
fn tiles_merge_into_the_whole_render(backend: &str, scene: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().expect("tempdir");
    let common: Vec<String> = [scene, "--backend", backend, "-q"]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect();
    let children: Vec<_> = (0..4)
        .map(|i| {
            Command::new(env!("CARGO_BIN_EXE_gpu-render"))
                .args(&common)
                .args(["--tile", &format!("{i}/4"), "-o"])
                .arg(dir.path().join("tile-{tile}.exr"))
                .output()
                .expect("spawn a tile")
        })
        .collect();
    // `output` waits, so the four ran one after the other; run them together too.
    let spawned: Vec<_> = (0..4)
        .map(|i| {
            Command::new(env!("CARGO_BIN_EXE_gpu-render"))
                .args(&common)
                .args(["--tile", &format!("{i}/4"), "-o"])
                .arg(dir.path().join("again-{tile}.exr"))
                .spawn()
                .expect("spawn a tile")
        })
        .collect();
    for (i, out) in children.iter().enumerate() {
        assert!(
            out.status.success(),
            "tile {i}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for mut child in spawned {
        assert!(child.wait().expect("wait").success());
    }
    let tiles: Vec<PathBuf> = (0..4)
        .map(|i| dir.path().join(format!("tile-{i}.exr")))
        .collect();
    for (i, tile) in tiles.iter().enumerate() {
        assert_same_bytes(tile, &dir.path().join(format!("again-{i}.exr")));
    }
    for format in ["exr", "png", "hdr"] {
        let merged = dir.path().join(format!("merged.{format}"));
        let whole = dir.path().join(format!("whole.{format}"));
        let mut merge: Vec<String> = vec!["merge".into()];
        // In reverse: the order of the files does not matter.
        merge.extend(tiles.iter().rev().map(|t| arg(t)));
        merge.extend(["-o".into(), arg(&merged), "-q".into()]);
        succeeds(gpu_render(&merge));
        let mut render = common.clone();
        render.extend(["-o".into(), arg(&whole)]);
        succeeds(gpu_render(&render));
        assert_same_bytes(&merged, &whole);
    }
}

#[test]
fn cpu_tiles_merge_into_the_whole_render_byte_for_byte() {
    tiles_merge_into_the_whole_render("cpu", &shipped("showcase.toml"), &SHOWCASE_ARGS);
    // Textures, BRDF maps, PBR and Oren-Nayar.
    tiles_merge_into_the_whole_render(
        "cpu",
        &shipped("materials.toml"),
        &["--width", "64", "--height", "48"],
    );
}

#[test]
fn gpu_tiles_merge_into_the_whole_render_byte_for_byte() {
    // Fails instead of skipping when CI is set (tests/integration/support/gpu.rs).
    if crate::support::gpu::headless_gpu().is_none() {
        return;
    }
    tiles_merge_into_the_whole_render("gpu", &shipped("showcase.toml"), &SHOWCASE_ARGS);
}

#[test]
fn crops_of_a_grid_merge_into_the_whole_render() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = shipped("showcase.toml");
    let base = |extra: &[String]| {
        let mut args: Vec<String> = vec![scene.clone(), "--backend".into(), "cpu".into()];
        args.extend(SHOWCASE_ARGS.iter().map(|s| s.to_string()));
        args.extend(extra.iter().cloned());
        args.push("-q".into());
        args
    };
    let mut tiles = Vec::new();
    for (i, crop) in ["0,0,50,20", "50,0,96,20", "0,20,30,54", "30,20,96,54"]
        .iter()
        .enumerate()
    {
        let path = dir.path().join(format!("crop{i}.exr"));
        succeeds(gpu_render(&base(&[
            "--crop".into(),
            crop.to_string(),
            "-o".into(),
            arg(&path),
        ])));
        tiles.push(arg(&path));
    }
    let merged = dir.path().join("merged.png");
    let mut merge = vec!["merge".to_owned()];
    merge.extend(tiles);
    merge.extend(["-o".into(), arg(&merged)]);
    let run = succeeds(gpu_render(&merge));
    assert!(
        run.stderr.contains("merged 4 tiles into 96x54"),
        "{}",
        run.stderr
    );
    let whole = dir.path().join("whole.png");
    succeeds(gpu_render(&base(&["-o".into(), arg(&whole)])));
    assert_same_bytes(&merged, &whole);
}

/// A small scene, and the 4 CPU tiles of it in `dir` as `tile-I.exr`.
fn four_tiles(dir: &Path, scene_text: &str, name: &str) -> Vec<String> {
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, scene_text).expect("write scene");
    (0..4)
        .map(|i| {
            let out = dir.join(format!("{name}-{i}.exr"));
            succeeds(gpu_render(&[
                arg(&scene),
                "--backend".into(),
                "cpu".into(),
                "--tile".into(),
                format!("{i}/4"),
                "-o".into(),
                arg(&out),
                "-q".into(),
            ]));
            arg(&out)
        })
        .collect()
}

const SMALL: &str = "[render]\nwidth = 20\nheight = 16\n\
    [camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
    [materials.m]\ntype = \"lambert\"\nalbedo = 0.6\n\
    [[lights]]\ntype = \"point\"\nposition = [1, 2, 3]\nintensity = 8\n\
    [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";

fn merge_into(out: &Path, tiles: &[String]) -> Run {
    let mut args = vec!["merge".to_owned()];
    args.extend(tiles.iter().cloned());
    args.extend(["-o".into(), arg(out)]);
    gpu_render(&args)
}

#[test]
fn merge_refuses_a_missing_tile_naming_it_and_its_pixels() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiles = four_tiles(dir.path(), SMALL, "s");
    let out = dir.path().join("out.png");
    std::fs::write(&out, b"old").expect("old output");
    let run = merge_into(
        &out,
        &[tiles[0].clone(), tiles[1].clone(), tiles[3].clone()],
    );
    assert_failed(
        &run,
        &[
            "the tiles leave 80 of the 20x16 pixels uncovered",
            "x 0..20, y 8..12",
            "missing: tile 2/4",
        ],
    );
    assert_eq!(std::fs::read(&out).expect("read"), b"old");
}

#[test]
fn merge_refuses_an_overlapping_tile_naming_both_files_and_the_pixels() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiles = four_tiles(dir.path(), SMALL, "s");
    let scene = arg(&dir.path().join("s.toml"));
    let crop = dir.path().join("crop.exr");
    succeeds(gpu_render(&[
        scene.as_str(),
        "--backend",
        "cpu",
        "--crop",
        "5,2,9,6",
        "-o",
        &arg(&crop),
        "-q",
    ]));
    let mut with_crop = tiles.clone();
    with_crop.push(arg(&crop));
    let run = merge_into(&dir.path().join("out.png"), &with_crop);
    assert_failed(
        &run,
        &[
            "s-0.exr and ",
            "crop.exr overlap in the pixels x 5..9, y 2..4 (4x2)",
        ],
    );
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn merge_refuses_a_tile_of_another_scene_or_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiles = four_tiles(dir.path(), SMALL, "s");
    let other = four_tiles(
        dir.path(),
        &SMALL.replace("albedo = 0.6", "albedo = 0.5"),
        "other",
    );
    let run = merge_into(
        &dir.path().join("out.png"),
        &[
            tiles[0].clone(),
            tiles[1].clone(),
            other[2].clone(),
            tiles[3].clone(),
        ],
    );
    assert_failed(
        &run,
        &[
            "other-2.exr: not the same scene as ",
            "s-0.exr",
            "(of other.toml) here, hash ",
            "(of s.toml) there",
        ],
    );
    let more = four_tiles(
        dir.path(),
        &SMALL.replace("height = 16", "height = 16\nsamples_per_pixel = 3"),
        "more",
    );
    let run = merge_into(
        &dir.path().join("out.png"),
        &[
            tiles[0].clone(),
            more[1].clone(),
            tiles[2].clone(),
            tiles[3].clone(),
        ],
    );
    assert_failed(
        &run,
        &[
            "more-1.exr: not the same render settings as ",
            "20x16, 3 spp",
            "20x16, 1 spp",
        ],
    );
    // A plain EXR (a whole render) is not a tile.
    let plain = dir.path().join("plain.exr");
    succeeds(gpu_render(&[
        arg(&dir.path().join("s.toml")),
        "--backend".into(),
        "cpu".into(),
        "-o".into(),
        arg(&plain),
        "-q".into(),
    ]));
    let run = merge_into(&dir.path().join("out.png"), &[arg(&plain)]);
    assert_failed(
        &run,
        &["plain.exr: not a gpu-render tile: attribute `gpuRender.tileFormat`"],
    );
}

#[test]
fn tiles_of_one_scene_in_files_of_other_names_merge_into_the_whole_render() {
    // docs/distributed.md: paths are not part of the scene hash; nor is the file's name.
    let dir = tempfile::tempdir().expect("tempdir");
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).expect("folder");
    let a = four_tiles(dir.path(), SMALL, "a");
    let b = four_tiles(&elsewhere, SMALL, "copy of a");
    let merged = dir.path().join("merged.png");
    let run = succeeds(merge_into(
        &merged,
        &[a[0].clone(), b[1].clone(), a[2].clone(), b[3].clone()],
    ));
    assert!(run.stderr.contains("merged 4 tiles"), "{}", run.stderr);
    let whole = dir.path().join("whole.png");
    succeeds(gpu_render(&[
        arg(&dir.path().join("a.toml")),
        "--backend".into(),
        "cpu".into(),
        "-o".into(),
        arg(&whole),
        "-q".into(),
    ]));
    assert_same_bytes(&merged, &whole);
}

#[test]
fn tile_and_crop_arguments_are_checked_before_rendering() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, SMALL).expect("scene");
    let scene = arg(&scene);
    let out = arg(&dir.path().join("t.exr"));
    let png = arg(&dir.path().join("t.png"));
    let named = arg(&dir.path().join("t{tile}.exr"));
    let cases: [(Vec<&str>, &[&str]); 5] = [
        (
            vec!["--tile", "1/4", "-o", &png],
            &["records its window (for `gpu-render merge`), so the output must be an .exr"],
        ),
        (
            vec!["--tile", "5/40", "-o", &out],
            &["--tile 5/40", "the image has 16"],
        ),
        (
            vec!["--crop", "0,0,21,4", "-o", &out],
            &["--crop 0,0,21,4", "does not lie inside the 20x16 image"],
        ),
        (
            vec!["--frame", "0", "-o", &png],
            &["s.toml: --frame 0", "no [animation]"],
        ),
        (vec!["-o", &named], &["needs --tile I/N"]),
    ];
    for (extra, needles) in cases {
        let mut args = vec![scene.as_str(), "--backend", "cpu"];
        args.extend(extra);
        assert_failed(&gpu_render(&args), needles);
    }
    let entries = std::fs::read_dir(dir.path()).expect("list").count();
    assert_eq!(entries, 1, "only the scene is there");
    let run = gpu_render(&[scene.as_str(), "--tile", "4/4", "-o", &out]);
    assert_eq!(run.status, Some(2), "a usage error: {}", run.stderr);
    assert!(
        run.stderr.contains("the index must be below the count"),
        "{}",
        run.stderr
    );
}

#[test]
fn a_frame_at_a_keyframe_is_the_still_of_that_camera() {
    let dir = tempfile::tempdir().expect("tempdir");
    let orbit = shipped("animation/orbit.toml");
    let small = [
        "--width",
        "48",
        "--height",
        "27",
        "--spp",
        "1",
        "--backend",
        "cpu",
        "-q",
    ];
    let pattern = arg(&dir.path().join("orbit-{frame}.png"));
    // Frame 24 is at t = 1 s, the third keyframe: eye [0, 2.8, -5], look-at [0, 0.5, 0].
    let mut args = vec![orbit.as_str(), "--frame", "24", "-o", pattern.as_str()];
    args.extend(small);
    succeeds(gpu_render(&args));
    let frame = dir.path().join("orbit-0024.png");
    assert!(frame.exists(), "the {{frame}} name is padded to 4 digits");

    let text = std::fs::read_to_string(&orbit).expect("read orbit");
    let still = text.replace(
        "eye = [0.0, 1.6, 5.0]\nlook_at = [0.0, 0.6, 0.0]\nup",
        "eye = [0.0, 2.8, -5.0]\nlook_at = [0.0, 0.5, 0.0]\nup",
    );
    assert_ne!(still, text, "the [camera] table was found");
    let still_path = dir.path().join("still.toml");
    std::fs::write(&still_path, still).expect("write still");
    let still_png = arg(&dir.path().join("still.png"));
    let mut args = vec![arg(&still_path), "-o".into(), still_png.clone()];
    args.extend(small.iter().map(|s| s.to_string()));
    succeeds(gpu_render(&args));
    assert_same_bytes(&frame, Path::new(&still_png));

    // Between keyframes the camera moves: frame 12 differs from frames 0 and 24.
    let mut args = vec![orbit.as_str(), "--frame", "12", "-o", pattern.as_str()];
    args.extend(small);
    succeeds(gpu_render(&args));
    let twelve = std::fs::read(dir.path().join("orbit-0012.png")).expect("frame 12");
    assert_ne!(twelve, std::fs::read(&frame).expect("frame 24"));

    let mut args = vec![orbit.as_str(), "--frame", "49", "-o", pattern.as_str()];
    args.extend(small);
    assert_failed(
        &gpu_render(&args),
        &["--frame 49: the animation has 49 frames (0 to 48)"],
    );
}

#[test]
fn tiles_of_two_frames_do_not_merge() {
    let dir = tempfile::tempdir().expect("tempdir");
    let orbit = shipped("animation/orbit.toml");
    let tile = |frame: &str, index: u32| {
        let out = dir.path().join(format!("f{frame}-{index}.exr"));
        succeeds(gpu_render(&[
            orbit.as_str(),
            "--frame",
            frame,
            "--tile",
            &format!("{index}/2"),
            "--width",
            "32",
            "--height",
            "18",
            "--spp",
            "1",
            "--backend",
            "cpu",
            "-q",
            "-o",
            &arg(&out),
        ]));
        arg(&out)
    };
    let run = merge_into(&dir.path().join("out.png"), &[tile("3", 0), tile("4", 1)]);
    assert_failed(
        &run,
        &["f4-1.exr: not the same frame as ", "4 here, 3 there"],
    );
    let same = merge_into(&dir.path().join("out.png"), &[tile("3", 0), tile("3", 1)]);
    let same = succeeds(same);
    assert!(same.stderr.contains("frame 3"), "{}", same.stderr);
}

#[test]
fn estimate_prints_a_line_per_tile_and_the_whole() {
    let showcase = shipped("showcase.toml");
    let run = succeeds(gpu_render(&[
        "estimate",
        showcase.as_str(),
        "--tiles",
        "3",
        "--width",
        "96",
        "--height",
        "54",
        "--spp",
        "1",
        "--calibration-pixels",
        "1200",
        "--backend",
        "cpu",
    ]));
    let out = &run.stdout;
    for needle in [
        "calibration: 46x26",
        "setup per process:",
        "-      0/3      x 0..96, y 0..18 (96x18)",
        "-      2/3      x 0..96, y 36..54 (96x18)",
        "whole frame:",
    ] {
        assert!(out.contains(needle), "stdout lacks {needle:?}:\n{out}");
    }
    // The longest tile is the setup plus the slowest row of the table.
    let seconds = |text: &str| -> f64 {
        let mut words = text.split_whitespace();
        let value: f64 = words.next().and_then(|v| v.parse().ok()).expect("a number");
        match words.next() {
            Some("ms") => value / 1e3,
            Some("s") => value,
            other => panic!("unit {other:?} in {text:?}"),
        }
    };
    let after = |marker: &str| -> f64 {
        let line = out.lines().find(|l| l.contains(marker)).expect(marker);
        let rest = &line[line.find(marker).expect(marker) + marker.len()..];
        seconds(
            rest.trim_start_matches([' ', '('])
                .split([',', ')'])
                .next()
                .expect("value"),
        )
    };
    let slowest_row = out
        .lines()
        .filter(|l| l.starts_with("-      "))
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            seconds(&words[words.len() - 2..].join(" "))
        })
        .fold(0.0, f64::max);
    let setup = after("setup per process:");
    let longest = after("the longest");
    assert!(
        (longest - (setup + slowest_row)).abs() <= 1e-4 + 0.02 * longest,
        "the longest tile {longest} s is not the setup {setup} s plus the slowest row \
         {slowest_row} s:\n{out}"
    );
    let animated = succeeds(gpu_render(&[
        "estimate",
        shipped("animation/orbit.toml").as_str(),
        "--width",
        "32",
        "--height",
        "18",
        "--spp",
        "1",
        "--backend",
        "cpu",
    ]));
    for needle in ["0      0/1", "48     0/1", "all 49 frames"] {
        assert!(
            animated.stdout.contains(needle),
            "stdout lacks {needle:?}:\n{}",
            animated.stdout
        );
    }
}
