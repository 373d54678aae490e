//! Bad input to the advanced materials gives a located error naming the field (and
//! the file, for images); never a panic.

use std::path::Path;

use gpu_render::scene::parse_scene;

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
