//! Bad input to the advanced materials gives a located error naming the field (and
//! the file, for images); never a panic.

use std::path::Path;

use gpu_render::scene::{LoadOptions, SceneWarning, parse_scene, parse_scene_with};

/// Parses a scene in `scenes/` (so image paths resolve there) with one material.
fn error_for(material: &str) -> String {
    let text =
        format!("[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n{material}\n");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/inline.toml");
    match parse_scene(&text, &path) {
        Ok(_) => panic!("accepted: {material}"),
        Err(e) => e.to_string(),
    }
}

fn assert_error(material: &str, fragments: &[&str]) {
    let message = error_for(material);
    assert!(
        message.contains("inline.toml:5:1: materials.m"),
        "{message}"
    );
    for fragment in fragments {
        assert!(message.contains(fragment), "{message} lacks {fragment}");
    }
}

#[test]
fn roughness_outside_the_unit_interval() {
    assert_error(
        "type = \"cook_torrance\"\nconductor = \"gold\"\nroughness = 1.5",
        &["roughness must be in [0, 1], got 1.5"],
    );
    assert_error(
        "type = \"pbr\"\nbase_color = 0.5\nroughness = -0.1",
        &["roughness must be in [0, 1]"],
    );
}

#[test]
fn negative_albedo_and_bad_sigma() {
    assert_error(
        "type = \"oren_nayar\"\nalbedo = [0.5, -0.1, 0.5]\nsigma_degrees = 20",
        &["albedo.g must be in [0, 1]"],
    );
    assert_error(
        "type = \"oren_nayar\"\nalbedo = 0.5\nsigma_degrees = 120",
        &["sigma_degrees must be in [0, 90]"],
    );
}

#[test]
fn ior_and_fresnel_sources() {
    assert_error(
        "type = \"cook_torrance\"\nior = 0.0\nroughness = 0.5",
        &["ior must be > 0"],
    );
    assert_error(
        "type = \"cook_torrance\"\nconductor = \"gold\"\nior = 1.5\nroughness = 0.5",
        &["exactly one Fresnel source"],
    );
    assert_error(
        "type = \"cook_torrance\"\nconductor = \"brass\"\nroughness = 0.5",
        &["unknown conductor `brass`"],
    );
    assert_error(
        "type = \"cook_torrance\"\neta = [0, 1, 1]\nk = 3\nroughness = 0.5",
        &["eta must be > 0"],
    );
    assert_error(
        "type = \"cook_torrance\"\nconductor = \"gold\"\nroughness = 0.5\ndistribution = \"phong\"",
        &["unknown distribution `phong`"],
    );
}

#[test]
fn missing_unreadable_and_wrong_shaped_images() {
    assert_error(
        "type = \"tabulated\"\nbrdf_map = \"brdf/missing.png\"",
        &[
            "brdf_map `brdf/missing.png`",
            "missing.png",
            "cannot read the file",
        ],
    );
    // A TOML file is not an image.
    assert_error(
        "type = \"lambert\"\nalbedo_texture = \"minimal.toml\"",
        &["albedo_texture `minimal.toml`", "not a readable image"],
    );
    assert_error(
        "type = \"lambert\"\nalbedo_texture = \"textures/checker.png\"\ntexture_scale = 0",
        &["texture_scale must be > 0"],
    );
    assert_error(
        "type = \"oren_nayar\"\nsigma_degrees = 10",
        &["missing required field `albedo` (or `albedo_texture`)"],
    );
}

#[test]
fn a_brdf_map_must_be_square() {
    let dir = tempfile::tempdir().expect("temporary directory");
    image::RgbImage::new(3, 2)
        .save(dir.path().join("wide.png"))
        .expect("writes");
    let text = "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n\
                type = \"tabulated\"\nbrdf_map = \"wide.png\"\n";
    let error = parse_scene(text, &dir.path().join("scene.toml"))
        .expect_err("a 3x2 map is rejected")
        .to_string();
    assert!(
        error.contains("scene.toml:5:1: materials.m (tabulated): brdf_map `wide.png`")
            && error.contains("must be square")
            && error.contains("got 3x2"),
        "{error}"
    );
}

#[test]
fn materials_naming_one_file_share_one_image() {
    let text = "[camera]\neye = [0, 1, 5]\nlook_at = [0, 0, 0]\n\
        [materials.a]\ntype = \"lambert\"\nalbedo_texture = \"textures/checker.png\"\n\
        [materials.b]\ntype = \"oren_nayar\"\nsigma_degrees = 20\nalbedo_texture = \"textures/checker.png\"\n";
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/shared-texture.toml");
    let scene = parse_scene(text, &scene_path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.images.len(), 1);
    assert!(scene.materials.iter().all(|m| m.albedo_texture == Some(0)));
}

/// A directory with `scene.toml` (one material `m` of `material`) and an EXR image
/// `name` whose texels are `texels` (a 2x2 image).
fn scene_with_exr(
    material: &str,
    name: &str,
    texels: [[f32; 4]; 4],
) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let data: Vec<f32> = texels.iter().flatten().copied().collect();
    image::Rgba32FImage::from_raw(2, 2, data)
        .expect("2x2")
        .save(dir.path().join(name))
        .expect("writes the EXR");
    let text =
        format!("[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n{material}\n");
    (dir, text)
}

const GREY: [f32; 4] = [0.5, 0.5, 0.5, 1.0];

#[test]
fn negative_texels_are_refused_naming_the_file_and_the_texel() {
    for material in [
        "type = \"lambert\"\nalbedo_texture = \"bad.exr\"",
        "type = \"tabulated\"\nbrdf_map = \"bad.exr\"",
    ] {
        let (dir, text) = scene_with_exr(
            material,
            "bad.exr",
            [GREY, GREY, [0.5, -0.99, 0.5, 1.0], GREY],
        );
        let error = parse_scene(&text, &dir.path().join("scene.toml"))
            .expect_err("a negative texel is refused")
            .to_string();
        for needle in [
            "scene.toml:5:1: materials.m",
            "`bad.exr`",
            "texel (0, 1)",
            "g = -0.99",
            ">= 0",
        ] {
            assert!(error.contains(needle), "{error} lacks {needle}");
        }
    }
}

#[test]
fn albedo_texels_above_one_are_clamped_with_a_warning() {
    let material = "type = \"lambert\"\nalbedo_texture = \"bright.exr\"";
    let (dir, text) = scene_with_exr(
        material,
        "bright.exr",
        [GREY, [3.0, 0.5, 1.5, 1.0], GREY, [1.25, 1.0, 0.0, 1.0]],
    );
    let warnings = std::sync::Mutex::new(Vec::new());
    let warn = |w: &SceneWarning| warnings.lock().expect("lock").push(w.to_string());
    let options = LoadOptions {
        warning: Some(&warn),
        ..LoadOptions::default()
    };
    let scene = parse_scene_with(&text, &dir.path().join("scene.toml"), &options)
        .unwrap_or_else(|e| panic!("{e}"));
    let texels = &scene.images[0].texels;
    assert_eq!(texels[1], [1.0, 0.5, 1.0, 1.0]);
    assert_eq!(texels[3], [1.0, 1.0, 0.0, 1.0]);
    assert_eq!(texels[0], GREY);
    let warnings = warnings.into_inner().expect("lock");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    for needle in [
        "scene.toml:5:1: materials.m",
        "bright.exr",
        "2 texels",
        "largest 3 at (1, 0)",
        "clamped to 1",
    ] {
        assert!(
            warnings[0].contains(needle),
            "{} lacks {needle}",
            warnings[0]
        );
    }
    // Without a hook the scene loads the same, silently.
    let quiet =
        parse_scene(&text, &dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(quiet.images, scene.images);
}

#[test]
fn a_brdf_map_above_one_is_kept_and_a_file_used_both_ways_is_loaded_twice() {
    let (dir, mut text) = scene_with_exr(
        "type = \"tabulated\"\nbrdf_map = \"map.exr\"",
        "map.exr",
        [[2.0, 2.0, 2.0, 1.0], GREY, GREY, GREY],
    );
    text.push_str("[materials.n]\ntype = \"lambert\"\nalbedo_texture = \"map.exr\"\n");
    let scene =
        parse_scene(&text, &dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.images.len(), 2);
    let map = scene.materials[0].brdf_map.expect("a map") as usize;
    let albedo = scene.materials[1].albedo_texture.expect("a texture") as usize;
    assert_eq!(scene.images[map].texels[0][0], 2.0);
    assert_eq!(scene.images[albedo].texels[0][0], 1.0);
}

#[cfg(unix)]
#[test]
fn a_fifo_as_texture_is_refused_without_blocking() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let fifo = dir.path().join("pipe.png");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let text = "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n\
                type = \"lambert\"\nalbedo_texture = \"pipe.png\"\n";
    let scene_path = dir.path().join("scene.toml");
    // Opening a FIFO for reading blocks until a writer comes: a hang, not a failure,
    // would be the bug, so the parse runs on a thread that is given 30 s.
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(
            parse_scene(text, &scene_path)
                .map(|_| ())
                .map_err(|e| e.to_string()),
        );
    });
    let result = receive
        .recv_timeout(std::time::Duration::from_secs(30))
        .expect("parse_scene blocked on a FIFO");
    let error = result.expect_err("a FIFO is refused");
    assert!(
        error.contains("`pipe.png`") && error.contains("a FIFO, not a regular file"),
        "{error}"
    );
}

#[test]
fn the_sandbox_keeps_textures_inside_the_scene_folder() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let sandboxed = LoadOptions {
        sandbox: true,
        ..LoadOptions::default()
    };
    let texture = |file: &str| {
        format!(
            "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n\
             type = \"lambert\"\nalbedo_texture = \"{file}\"\n"
        )
    };
    let inside = texture("textures/checker.png");
    assert!(parse_scene_with(&inside, &scenes.join("s.toml"), &sandboxed).is_ok());
    let absolute = scenes.join("textures/checker.png");
    let outside = [
        (texture(&absolute.to_string_lossy()), "absolute path"),
        (texture("../scenes/textures/checker.png"), "`..`"),
    ];
    for (text, why) in outside {
        // Trusted without the sandbox, refused with it.
        assert!(parse_scene(&text, &scenes.join("s.toml")).is_ok());
        let error = parse_scene_with(&text, &scenes.join("s.toml"), &sandboxed)
            .expect_err("escapes the folder")
            .to_string();
        assert!(
            error.contains("s.toml:5:1: materials.m")
                && error.contains("albedo_texture")
                && error.contains(why),
            "{error}"
        );
    }
}

/// The sandbox's check and the texture's open are one step: a texture swapped between
/// a regular file inside the folder and a symbolic link to a file outside it, as fast
/// as a second thread can, is never read from outside. Every load either reads the
/// inside texel or is refused (by the link check or a missing file mid-swap).
#[cfg(unix)]
#[test]
fn a_texture_swapped_for_a_link_during_the_load_is_never_read_from_outside() {
    use std::sync::atomic::{AtomicBool, Ordering};

    let root = tempfile::tempdir().expect("tempdir");
    let scene_dir = root.path().join("scene");
    let secret_dir = root.path().join("secret");
    std::fs::create_dir(&scene_dir).expect("mkdir");
    std::fs::create_dir(&secret_dir).expect("mkdir");
    let red = image::RgbImage::from_pixel(1, 1, image::Rgb([255, 0, 0]));
    let blue = image::RgbImage::from_pixel(1, 1, image::Rgb([0, 0, 255]));
    red.save(scene_dir.join("red.png")).expect("write");
    blue.save(secret_dir.join("blue.png")).expect("write");
    let text = "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\n[materials.m]\n\
                type = \"lambert\"\nalbedo_texture = \"tex.png\"\n";
    let scene_path = scene_dir.join("s.toml");
    let sandboxed = LoadOptions {
        sandbox: true,
        ..LoadOptions::default()
    };
    // The texture exists before the swapping starts.
    std::fs::copy(scene_dir.join("red.png"), scene_dir.join("tex.png")).expect("copy");
    let stop = AtomicBool::new(false);
    let (mut inside, mut refused) = (0, 0);
    let mut outcomes = Vec::new();
    std::thread::scope(|scope| {
        scope.spawn(|| {
            let tex = scene_dir.join("tex.png");
            let staged = scene_dir.join("staged.png");
            let link = scene_dir.join("link.png");
            let _ = std::os::unix::fs::symlink(secret_dir.join("blue.png"), &link);
            while !stop.load(Ordering::Relaxed) {
                // A regular copy of the red texel, then the link, each renamed into place.
                std::fs::copy(scene_dir.join("red.png"), &staged).expect("copy");
                std::fs::rename(&staged, &tex).expect("rename");
                let _ = std::fs::remove_file(&link);
                std::os::unix::fs::symlink(secret_dir.join("blue.png"), &link).expect("symlink");
                std::fs::rename(&link, &tex).expect("rename");
            }
        });
        // Outcomes are judged after the swapping thread has stopped, so that a failed
        // assertion cannot leave it running (the scope would wait for it forever).
        // At least 400 loads, and on until both kinds of file were met (a busy machine
        // may not run the swapping thread for a while), for at most 60 seconds.
        let started = std::time::Instant::now();
        let (mut regular, mut link) = (0, 0);
        while outcomes.len() < 400
            || (regular == 0 || link == 0) && started.elapsed().as_secs() < 60
        {
            let outcome = parse_scene_with(text, &scene_path, &sandboxed)
                .map(|scene| scene.images[0].texels[0]);
            match &outcome {
                Ok(_) => regular += 1,
                Err(_) => link += 1,
            }
            outcomes.push(outcome);
        }
        stop.store(true, Ordering::Relaxed);
    });
    for outcome in outcomes {
        match outcome {
            Ok(texel) => {
                assert!(
                    texel[0] > 0.9 && texel[2] < 0.1,
                    "a texel from outside the folder was read: {texel:?}"
                );
                inside += 1;
            }
            Err(error) => {
                let error = error.to_string();
                assert!(
                    error.contains("symbolic link") || error.contains("No such file"),
                    "{error}"
                );
                refused += 1;
            }
        }
    }
    // Both outcomes happened, so the swap raced the loads.
    assert!(
        inside > 0 && refused > 0,
        "inside {inside}, refused {refused}"
    );
}
