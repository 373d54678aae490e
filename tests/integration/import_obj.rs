//! The OBJ/MTL importer against small hand-made files with known answers: geometry,
//! groups, the MTL mapping table of `docs/models.md`, textures, the shipped torus, and
//! every kind of bad input (each a clear error naming the file and line, never a panic).

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3, DVec4};
use gpu_render::low_level::color::srgb_decode;
use gpu_render::scene::import::{ImportedModel, WrapMode, import_model, import_obj, parse_obj};
use gpu_render::scene::{AlphaMode, MaterialKind, SceneError};

use crate::support::models::material_named;

/// Writes `files` (name, contents) into a fresh directory and imports the first.
fn import(files: &[(&str, &str)]) -> (tempfile::TempDir, Result<ImportedModel, SceneError>) {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).expect("write fixture");
    }
    let result = import_obj(&dir.path().join(files[0].0));
    (dir, result)
}

fn imported(files: &[(&str, &str)]) -> ImportedModel {
    let (_dir, result) = import(files);
    result.unwrap_or_else(|e| panic!("import failed: {e}"))
}

fn failure(files: &[(&str, &str)]) -> String {
    let (_dir, result) = import(files);
    match result {
        Ok(_) => panic!("the import succeeded"),
        Err(e) => e.to_string(),
    }
}

/// Writes a PNG of `width × height` RGBA texels.
fn write_png(path: &Path, width: u32, height: u32, texels: &[[u8; 4]]) {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    image::RgbaImage::from_raw(width, height, raw)
        .expect("texel count")
        .save(path)
        .expect("write png");
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

const QUAD: &str = "\
v 0 0 0
v 2 0 0
v 2 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1 4/4/1
";

#[test]
fn a_quad_becomes_two_triangles_with_normals_and_flipped_uvs() {
    let model = imported(&[("quad.obj", QUAD)]);
    assert_eq!(model.meshes.len(), 1);
    let mesh = &model.meshes[0];
    assert_eq!(mesh.triangles.len(), 2);
    assert_eq!(mesh.instances, vec![glam::DMat4::IDENTITY]);
    let triangles: Vec<_> = model.world_triangles().collect();
    assert_eq!(
        triangles[0].vertices,
        [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0)
        ]
    );
    assert_eq!(
        triangles[1].vertices,
        [
            DVec3::ZERO,
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0)
        ]
    );
    assert_eq!(triangles[0].normals, Some([DVec3::Z; 3]));
    // OBJ's v grows upwards; imported UVs grow downwards.
    assert_eq!(
        triangles[0].uvs,
        Some([
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0)
        ])
    );
    // No MTL: one default Lambert material.
    assert_eq!(model.materials.len(), 1);
    assert_eq!(model.materials[0].material.kind, MaterialKind::Lambert);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(
        model.bounds(),
        Some((DVec3::ZERO, DVec3::new(2.0, 1.0, 0.0)))
    );
}

#[test]
fn faces_of_any_size_are_fanned_and_relative_indices_resolve() {
    let obj = "\
v 1 0 0
v 0.5 0.866 0
v -0.5 0.866 0
v -1 0 0
v -0.5 -0.866 0
v 0.5 -0.866 0
f -6 -5 -4 -3 -2 -1
";
    let model = imported(&[("hexagon.obj", obj)]);
    let mesh = &model.meshes[0];
    assert_eq!(
        mesh.triangles,
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
    );
    assert!(mesh.normals.is_none() && mesh.uvs.is_none());
}

#[test]
fn objects_groups_and_material_changes_make_meshes() {
    let obj = "\
mtllib two.mtl
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
o first
usemtl red
f 1 2 3
usemtl blue
f 1 2 4
g second
f 1 3 4
";
    let mtl = "newmtl red\nKd 1 0 0\nillum 1\nnewmtl blue\nKd 0 0 1\nillum 1\n";
    let model = imported(&[("groups.obj", obj), ("two.mtl", mtl)]);
    let names: Vec<&str> = model.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "object 'first' (material 'red')",
            "object 'first' (material 'blue')",
            "object 'second' (material 'blue')"
        ]
    );
    let diffuse = |i: usize| {
        model.materials[model.meshes[i].material as usize]
            .material
            .diffuse
    };
    assert_eq!(diffuse(0), DVec3::X);
    assert_eq!(diffuse(1), DVec3::Z);
    assert_eq!(diffuse(2), DVec3::Z);
}

/// One material per row of the mapping table.
const MATERIALS: &str = "\
newmtl flat
Kd 0.5 0.4 0.3
Ks 0.2
illum 1

newmtl plastic
Kd 0.5 0.4 0.3
Ks 0.25 0.25 0.25
Ns 120
illum 2

newmtl no_illum
Kd 0.5
Ks 0.1
Ns 30

newmtl matte
Kd 0.5

newmtl coated
Kd 0.6 0.1 0.1
Ks 0.3
Ns 50
Ni 1.6
illum 3

newmtl fresnel_coat
Kd 0.6 0.1 0.1
illum 5

newmtl glass
Ni 1.45
Tf 0.9 0.95 1.0
d 0.1
illum 4

newmtl glass6
illum 6

newmtl glass7
Ni 2.4
illum 7

newmtl metal
Kd 0.9 0.6 0.2
Pr 0.3
Pm 1.0
illum 2

newmtl lamp
Kd 0.1
Ke 4 3.5 3
illum 1

newmtl hot
Kd 0.9 0.9 0.9
Ks 0.5 0.5 0.5
Ns 10
";

#[test]
fn mtl_illumination_models_map_as_documented() {
    let mut obj = String::from("mtllib all.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    let names = [
        "flat",
        "plastic",
        "no_illum",
        "matte",
        "coated",
        "fresnel_coat",
        "glass",
        "glass6",
        "glass7",
        "metal",
        "lamp",
        "hot",
    ];
    for name in names {
        obj.push_str(&format!("usemtl {name}\nf 1 2 3\n"));
    }
    let model = imported(&[("all.obj", &obj), ("all.mtl", MATERIALS)]);
    let material = |name: &str| material_named(&model, name).material;
    let flat = material("flat");
    assert_eq!(flat.kind, MaterialKind::Lambert, "illum 1 ignores Ks");
    assert_eq!(flat.diffuse, DVec3::new(0.5, 0.4, 0.3));

    let plastic = material("plastic");
    assert_eq!(plastic.kind, MaterialKind::BlinnPhong);
    assert_eq!(plastic.specular, DVec3::splat(0.25));
    assert_eq!(plastic.shininess, 120.0, "Ns is the Blinn-Phong exponent");
    assert_eq!(plastic.coat_ior, 0.0);
    assert_eq!(material("no_illum").kind, MaterialKind::BlinnPhong);
    assert_eq!(
        material("no_illum").diffuse,
        DVec3::splat(0.5),
        "one value is grey"
    );
    assert_eq!(
        material("matte").kind,
        MaterialKind::Lambert,
        "Ks 0: Lambert"
    );

    let coated = material("coated");
    assert_eq!(coated.kind, MaterialKind::BlinnPhong);
    assert_eq!(coated.coat_ior, 1.6, "illum 3: a coat of index Ni");
    let fresnel = material("fresnel_coat");
    assert_eq!(fresnel.kind, MaterialKind::Lambert);
    assert_eq!(fresnel.coat_ior, 1.5, "illum 5 without Ni: 1.5");

    let glass = material("glass");
    assert_eq!(glass.kind, MaterialKind::Dielectric);
    assert_eq!(glass.ior, 1.45);
    assert_eq!(glass.transmittance, DVec3::new(0.9, 0.95, 1.0));
    assert_eq!(material("glass6").kind, MaterialKind::Dielectric);
    assert_eq!(material("glass6").ior, 1.5);
    assert_eq!(material("glass7").ior, 2.4);

    let metal = material("metal");
    assert_eq!(metal.kind, MaterialKind::Pbr);
    assert_eq!(metal.diffuse, DVec3::new(0.9, 0.6, 0.2));
    assert_eq!((metal.metallic, metal.roughness), (1.0, 0.3));

    let lamp = material("lamp");
    assert_eq!(lamp.emission, DVec3::new(4.0, 3.5, 3.0));

    // Kd + Ks = 1.4: both scaled by 1/1.4 so the surface conserves energy, with a warning.
    let hot = material("hot");
    assert!(close(hot.diffuse, DVec3::splat(0.9 / 1.4)));
    assert!(close(hot.specular, DVec3::splat(0.5 / 1.4)));
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("material 'hot'") && w.contains("Kd + Ks")),
        "{:?}",
        model.warnings
    );
    // d on glass is not a warning; it would be on an opaque material.
    assert!(!model.warnings.iter().any(|w| w.contains("'glass'")));
}

#[test]
fn map_kd_loads_an_srgb_texture_linearised_with_its_wrap_mode() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::create_dir(dir.path().join("maps")).expect("mkdir");
    write_png(
        &dir.path().join("maps/wood grain.png"),
        2,
        1,
        &[[128, 64, 255, 255], [0, 10, 200, 255]],
    );
    std::fs::write(
        dir.path().join("wood.mtl"),
        "newmtl wood\nmap_Kd -clamp on -s 2 2 maps/wood grain.png\nillum 1\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.path().join("wood.obj"),
        "mtllib wood.mtl\nusemtl wood\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .expect("obj");
    let model = import_obj(&dir.path().join("wood.obj")).expect("imports");
    let material = &model.materials[0];
    let texture = material.base_color_texture.expect("a texture");
    assert_eq!(texture.wrap_u, WrapMode::ClampToEdge);
    assert_eq!(texture.wrap_v, WrapMode::ClampToEdge);
    assert_eq!(
        material.material.diffuse,
        DVec3::ONE,
        "without Kd the texture is the colour"
    );
    let image = &model.images[texture.image as usize];
    assert_eq!((image.width, image.height), (2, 1));
    let expected = srgb_decode(128.0 / 255.0) as f32;
    assert!((image.texel(0, 0)[0] - expected).abs() < 1e-6);
    // `-s 2 2 1`: the texture repeats twice along u and v (three.js's `repeat`), about
    // the OBJ's origin at the bottom left, which is v = 1 in our v-down coordinates.
    let t = texture.transform;
    assert_eq!(t.apply(DVec2::new(0.25, 1.0)), DVec2::new(0.5, 1.0));
    assert_eq!(t.apply(DVec2::new(0.0, 0.5)), DVec2::new(0.0, 0.0));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

/// MTL's `-s` and `-o` place the texture as tinyobjloader reads them and three.js's
/// MTLLoader applies them (`uv · s + o` in OBJ's v-up coordinates); a value that is not
/// a finite number is a warning and the texture is placed without the option.
#[test]
fn texture_scale_and_offset_options_place_the_texture() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_png(&dir.path().join("t.png"), 1, 1, &[[255, 255, 255, 255]]);
    std::fs::write(
        dir.path().join("t.mtl"),
        "newmtl placed
map_Kd -o 0.25 0.5 -s 3 0.5 t.png
         newmtl bad
map_Kd -s nan 2 t.png
",
    )
    .expect("mtl");
    std::fs::write(
        dir.path().join("t.obj"),
        format!(
            "mtllib t.mtl
usemtl placed
{QUAD}usemtl bad
f 1/1/1 2/2/1 3/3/1
"
        ),
    )
    .expect("obj");
    let model = import_obj(&dir.path().join("t.obj")).expect("imports");
    let transform = |name: &str| {
        material_named(&model, name)
            .base_color_texture
            .unwrap_or_else(|| panic!("material {name} has no texture"))
            .transform
    };
    // An OBJ texture coordinate (u, v_obj) lands at (3u + 0.25, 0.5 v_obj + 0.5) of the
    // image in OBJ's coordinates; ours run v down (v = 1 − v_obj) on both sides.
    for (u, v_obj) in [(0.0, 0.0), (1.0, 1.0), (0.3, 0.7)] {
        let ours = transform("placed").apply(DVec2::new(u, 1.0 - v_obj));
        let expected = DVec2::new(3.0 * u + 0.25, 1.0 - (0.5 * v_obj + 0.5));
        assert!(
            (ours - expected).length() < 1e-12,
            "{ours} against {expected}"
        );
    }
    assert_eq!(
        transform("bad"),
        gpu_render::scene::TextureTransform::IDENTITY
    );
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0]
            .contains("material 'bad': map_Kd -s nan 2: a scale or offset must be finite"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn map_ke_loads_an_emission_texture_that_the_scene_keeps() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_png(
        &dir.path().join("glow.png"),
        2,
        1,
        &[[0, 0, 0, 255], [255, 128, 255, 255]],
    );
    std::fs::write(
        dir.path().join("lamp.mtl"),
        "newmtl lamp\nKd 0 0 0\nKe 2 2 2\nmap_Ke -clamp on glow.png\nillum 1\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.path().join("lamp.obj"),
        "mtllib lamp.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .expect("obj");
    let model = import_obj(&dir.path().join("lamp.obj")).expect("imports");
    assert!(
        !model.warnings.iter().any(|w| w.contains("map_Ke")),
        "{:?}",
        model.warnings
    );
    let material = &model.materials[0];
    assert_eq!(material.material.emission, DVec3::splat(2.0));
    let texture = material.emissive_texture.expect("an emission texture");
    assert_eq!(texture.wrap_u, WrapMode::ClampToEdge);
    let image = &model.images[texture.image as usize];
    assert!((image.texel(1, 0)[1] - srgb_decode(128.0 / 255.0) as f32).abs() < 1e-6);

    // Placed in a scene, it becomes the material's UV-mapped emission texture.
    let mut scene = gpu_render::scene::Scene {
        render: Default::default(),
        camera: gpu_render::scene::Camera {
            eye: DVec3::Z,
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Default::default(),
        materials: vec![],
        material_names: vec![],
        lights: vec![],
        shapes: vec![],
        meshes: vec![],
        images: vec![],
    };
    model.add_to_scene(
        &mut scene,
        &gpu_render::scene::import::ModelPlacement::IDENTITY,
    );
    let placed = scene.materials[0];
    assert_eq!(placed.emission_texture, Some(0));
    assert_eq!(
        placed.emission_wrap,
        [gpu_render::scene::TextureWrap::ClampToEdge; 2]
    );
    assert_eq!(
        placed.texture_mapping,
        gpu_render::scene::TextureMapping::Uv
    );
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 3\n";
    let model = imported(&[("thin.obj", obj)]);
    assert_eq!(model.meshes[0].triangles.len(), 1);
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("skipped 2 degenerate triangles (of 3)")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn unknown_statements_and_materials_are_warnings() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nowhere\nl 1 2\ncurv 0 1 1 2\nf 1 2 3\n";
    let model = imported(&[("odd.obj", obj)]);
    assert_eq!(model.meshes.len(), 1);
    let warnings = model.warnings.join("\n");
    assert!(warnings.contains(":4: usemtl nowhere"), "{warnings}");
    assert!(
        warnings.contains(":5: `l`: lines are not rendered"),
        "{warnings}"
    );
    assert!(warnings.contains(":6: `curv`: free-form"), "{warnings}");
}

/// `(file contents, what the message must contain)`.
const BAD_OBJ: &[(&str, &str)] = &[
    ("v 0 0\n", "bad.obj:1:1: `v` takes x y z"),
    (
        "v 0 0 zero\n",
        "bad.obj:1:7: position z: `zero` is not a number",
    ),
    (
        "v 0 nan 0\n",
        "bad.obj:1:5: position y is not a finite number (nan)",
    ),
    (
        "v 0 0 inf\n",
        "bad.obj:1:7: position z is not a finite number",
    ),
    ("vt\n", "bad.obj:1:1: `vt` takes u"),
    ("vn 0 1\n", "bad.obj:1:1: `vn` takes i j k"),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
        "bad.obj:4:7: face corner 3: the position index 4 is out of range: 3 positions are defined before this line",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
        "bad.obj:4:7: face corner 3: the position index -4 is out of range",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
        "bad.obj:4:7: face corner 3: the position index 99999999999999999999 is out of range: 3 positions are defined before this line",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -99999999999999999999\n",
        "bad.obj:4:7: face corner 3: the position index -99999999999999999999 is out of range",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/99999999999999999999 2/1 3/1\n",
        "bad.obj:5:3: face corner 1: the texture coordinate index 99999999999999999999 is out of range: 1 texture coordinate is defined",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
        "bad.obj:4:3: face corner 1: the position index is 0 (OBJ counts from 1)",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n",
        "bad.obj:4:3: face corner 1: the texture coordinate index 1 is out of range: 0 texture coordinates are defined",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//x 2 3\n",
        "bad.obj:4:3: face corner 1: the normal index `x` is not an integer",
    ),
    (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n",
        "has more than three indices",
    ),
    ("v 0 0 0\nf /1 1 1\n", "has no position index"),
    // Truncated in the middle of a vertex.
    ("v 0 0 0\nv 1 0 0\nv 0 1", "bad.obj:3:1: `v` takes x y z"),
];

#[test]
fn bad_obj_files_name_the_file_line_and_column() {
    for (text, expected) in BAD_OBJ {
        let message = failure(&[("bad.obj", text)]);
        assert!(
            message.contains(expected),
            "for {text:?}: expected {expected:?} in {message:?}"
        );
    }
}

/// MTL contents and what the message must contain.
const BAD_MTL: &[(&str, &str)] = &[
    (
        "newmtl a\nKd 1 0\n",
        "lib.mtl:2:1: `Kd` takes r g b (or one grey value), got 2",
    ),
    (
        "newmtl a\nKd 1 0 x\n",
        "lib.mtl:2:8: Kd: `x` is not a number",
    ),
    (
        "newmtl a\nKs nan 0 0\n",
        "lib.mtl:2:4: Ks is not a finite number",
    ),
    (
        "newmtl a\nNs\n",
        "lib.mtl:2:1: `Ns` takes one number, got 0",
    ),
    (
        "newmtl a\nNi inf\n",
        "lib.mtl:2:4: Ni is not a finite number",
    ),
    (
        "newmtl a\nillum 2.5\n",
        "lib.mtl:2:7: illum: `2.5` is not an integer",
    ),
    (
        "newmtl a\nillum 11\n",
        "lib.mtl:2:7: illum 11 is not an illumination model",
    ),
    (
        "newmtl a\nillum 99999999999999999999\n",
        "lib.mtl:2:7: illum 99999999999999999999 is not an illumination model (0 to 10)",
    ),
    (
        "newmtl a\nmap_Kd\n",
        "lib.mtl:2:1: `map_Kd` needs a file name",
    ),
];

#[test]
fn bad_mtl_files_name_the_library_line_and_column() {
    let obj = "mtllib lib.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for (mtl, expected) in BAD_MTL {
        let message = failure(&[("model.obj", obj), ("lib.mtl", mtl)]);
        assert!(
            message.contains(expected),
            "for {mtl:?}: expected {expected:?} in {message:?}"
        );
    }
}

#[test]
fn a_texture_that_is_not_an_image_is_an_error_naming_it() {
    let obj = "mtllib lib.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let message = failure(&[
        ("model.obj", obj),
        ("lib.mtl", "newmtl a\nmap_Kd fake.png\n"),
        ("fake.png", "not a png"),
    ]);
    assert!(
        message.contains("lib.mtl:2:1: material 'a': map_Kd: the texture"),
        "{message}"
    );
    assert!(message.contains("fake.png does not load"), "{message}");
}

#[test]
fn missing_and_unreadable_files_are_named() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let missing = dir.path().join("nothing.obj");
    let message = import_obj(&missing).expect_err("missing").to_string();
    assert!(
        message.contains("nothing.obj: cannot read the model file"),
        "{message}"
    );
    let message = import_obj(dir.path()).expect_err("a directory").to_string();
    assert!(message.contains("it is a directory"), "{message}");
    let message = import_model(Path::new("model.stl"))
        .expect_err("stl")
        .to_string();
    assert!(
        message.contains("must end in .obj, .gltf or .glb"),
        "{message}"
    );
}

/// Asserts that `message` holds no control character and is at most `most` characters.
fn assert_one_short_line(message: &str, most: usize) {
    assert!(!message.contains(char::is_control), "{message:?}");
    assert!(
        message.chars().count() <= most,
        "{} characters: {message:?}",
        message.chars().count()
    );
}

#[test]
fn text_from_the_file_is_quoted_escaped_and_cut() {
    let nuls = "\0".repeat(10_000);
    let obj = format!(
        "{nuls}\nmtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\u{1}b\u{1b}[31mred\nf 1 2 3\n\
         o \u{202e}desrever\nusemtl shiny\u{7}\nf 1 2 3\n"
    );
    let mtl = "newmtl shiny\u{7}\nKd 0.5 0.5 0.5\nmap_\u{0}odd x.png\n";
    let (_dir, result) = import(&[("odd.obj", obj.as_str()), ("lib.mtl", mtl)]);
    let model = result.unwrap_or_else(|e| panic!("{e}"));
    for warning in &model.warnings {
        assert_one_short_line(warning, 300);
    }
    let warnings = model.warnings.join("\n");
    let expected_nuls = format!(":1: `{}…`: not supported", r"\0".repeat(40));
    for needle in [
        expected_nuls.as_str(),
        r"usemtl a\u{1}b\u{1b}[31mred: no material library defines it",
        r"material 'shiny\u{7}': map_\0odd is not supported",
    ] {
        assert!(warnings.contains(needle), "{needle:?} not in {warnings}");
    }
    let names: Vec<&str> = model.meshes.iter().map(|m| m.name.as_str()).collect();
    assert!(
        names.contains(&r"object '\u{202e}desrever' (material 'shiny\u{7}')"),
        "{names:?}"
    );

    let long = "x".repeat(5_000);
    for (text, needle) in [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\u{0}\n".to_string(),
            r"the position index `3\0` is not an integer",
        ),
        (format!("v 0 0 {long}\n"), "position z: `xxxxxxxxxx"),
        (
            format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 {long}\n"),
            "the position index `xxxxxxxxxx",
        ),
    ] {
        let message = failure(&[("bad.obj", text.as_str())]);
        assert_one_short_line(&message, 300);
        assert!(message.contains(needle), "{needle:?} not in {message}");
    }
}

#[test]
fn numbers_from_the_file_are_quoted_short() {
    let obj = "mtllib lib.mtl\nv 0 0 1e300x\nv 1 0 0\nv 0 1 0\nv 0 0 0\n\
               usemtl huge\nf 2 3 4\nusemtl tiny\nf 2 3 4\n";
    let mtl = "newmtl huge\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 1e300\n\
               newmtl tiny\nKd 1e300 0.5 -1e-300\nNi -1e-300\nillum 3\n";
    let model = imported(&[("n.obj", obj), ("lib.mtl", mtl)]);
    for warning in &model.warnings {
        assert_one_short_line(warning, 300);
    }
    let warnings = model.warnings.join("\n");
    for needle in [
        "`1e300x` is read as 1e300, the number it starts with",
        "material 'huge': Ns 1e300 is outside [0, 1000000]; clamped",
        "material 'tiny': Kd [1e300, 0.5, -1e-300] is outside [0, 1]; clamped",
        "material 'tiny': Ni -1e-300 is not positive",
    ] {
        assert!(warnings.contains(needle), "{needle:?} not in {warnings}");
    }
}

#[test]
fn a_byte_order_mark_is_skipped() {
    let bytes = "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".as_bytes();
    let model = parse_obj(bytes, Path::new("bom.obj")).expect("imports");
    assert_eq!(model.meshes.len(), 1);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn invalid_utf8_is_read_with_a_warning() {
    let bytes = b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let model = parse_obj(bytes, Path::new("latin1.obj")).expect("imports");
    assert_eq!(model.meshes.len(), 1);
    assert!(model.warnings[0].contains("not valid UTF-8"));
}

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/models")
        .join(name)
}

#[test]
fn the_shipped_torus_imports_cleanly() {
    let model = import_model(&shipped("torus.obj")).expect("imports");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.meshes.len(), 2);
    let torus = &model.meshes[0];
    assert_eq!(torus.triangles.len(), 16 * 8 * 2);
    assert!(torus.normals.is_some() && torus.uvs.is_some());
    // Two hexagons (4 triangles each) and six quads.
    assert_eq!(model.meshes[1].triangles.len(), 2 * 4 + 6 * 2);
    let glaze = &model.materials[torus.material as usize];
    assert_eq!(glaze.material.kind, MaterialKind::BlinnPhong);
    assert_eq!(glaze.material.shininess, 80.0);
    let stone = &model.materials[model.meshes[1].material as usize];
    assert!(stone.base_color_texture.is_some());
    assert_eq!(model.images.len(), 1);
    // Every outward normal agrees with the winding of its triangle.
    for triangle in model.world_triangles() {
        let [a, b, c] = triangle.vertices;
        let geometric = (b - a).cross(c - a);
        if let Some(normals) = triangle.normals {
            assert!(normals.iter().all(|n| n.dot(geometric) > 0.0));
        }
    }
}

/// A ring between radii 1 and 2 drawn as one face, as LightWave writes one: round the
/// rim, across to the hole, round the hole the other way and back across (corners 1 and
/// `segments + 1` are visited twice).
fn ring_obj(segments: usize) -> String {
    let mut obj = String::new();
    for radius in [2.0, 1.0] {
        for k in 0..segments {
            let angle = k as f64 * std::f64::consts::TAU / segments as f64;
            obj.push_str(&format!(
                "v {} {} 0\n",
                radius * angle.cos(),
                radius * angle.sin()
            ));
        }
    }
    obj.push('f');
    let outer = (1..=segments).chain([1]);
    let inner = [segments + 1]
        .into_iter()
        .chain((segments + 2..=2 * segments).rev())
        .chain([segments + 1]);
    for index in outer.chain(inner) {
        obj.push_str(&format!(" {index}"));
    }
    obj.push('\n');
    obj
}

#[test]
fn a_concave_face_keeps_its_hole() {
    let segments = 16;
    let model = imported(&[("ring.obj", &ring_obj(segments))]);
    let triangles: Vec<_> = model.world_triangles().collect();
    // A fan from the first corner would cover the hole: the centre would be inside.
    let inside = |t: &[DVec3; 3], p: DVec3| {
        let side = |a: DVec3, b: DVec3| (b - a).cross(p - a).z;
        let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
        s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0)
    };
    let mut area = 0.0;
    for triangle in &triangles {
        let [a, b, c] = triangle.vertices;
        assert!(
            !inside(&triangle.vertices, DVec3::ZERO),
            "{triangle:?} covers the hole"
        );
        let centroid = ((a + b + c) / 3.0).length();
        assert!(
            (1.0..=2.0).contains(&centroid),
            "{triangle:?} lies outside the ring"
        );
        let normal = (b - a).cross(c - a);
        assert!(normal.z > 0.0, "{triangle:?} is wound against the face");
        area += normal.length() / 2.0;
    }
    let polygon =
        |r: f64| segments as f64 / 2.0 * r * r * (std::f64::consts::TAU / segments as f64).sin();
    let expected = polygon(2.0) - polygon(1.0);
    assert!(
        (area - expected).abs() < 1e-9,
        "area {area}, ring {expected}"
    );
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn a_face_that_crosses_itself_is_fanned_with_a_warning() {
    let obj = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n";
    let model = imported(&[("bow.obj", obj)]);
    assert_eq!(model.meshes[0].triangles.len(), 2);
    let warnings = model.warnings.join("\n");
    assert!(
        warnings.contains("bow.obj:5: 1 face could not be ear-clipped"),
        "{warnings}"
    );
}

#[test]
fn the_w_of_a_vertex_is_ignored() {
    let obj = "v 0 0 0 0.1\nv 2 0 0 0.5\nv 0 2 0 0\nf 1 2 3\n";
    let model = imported(&[("w.obj", obj)]);
    assert_eq!(
        model.meshes[0].positions,
        vec![
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0)
        ]
    );
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn vertex_colours_are_read_and_uncoloured_vertices_are_white() {
    let obj = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n";
    let model = imported(&[("colours.obj", obj)]);
    assert_eq!(model.meshes[0].triangles.len(), 1);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(
        model.meshes[0].colors,
        Some(
            [DVec3::X, DVec3::Y, DVec3::Z]
                .map(|c| c.extend(1.0))
                .to_vec()
        )
    );
    // Before and after the coloured ones, as tinyobjloader reads them: white.
    let obj = "v 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n";
    let model = imported(&[("some.obj", obj)]);
    assert_eq!(
        model.meshes[0].colors,
        Some(vec![DVec4::ONE, DVec3::splat(0.5).extend(1.0), DVec4::ONE])
    );
    // No colour anywhere: none.
    let model = imported(&[("none.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")]);
    assert_eq!(model.meshes[0].colors, None);
}

#[test]
fn inline_comments_are_cut_off() {
    let obj = "\
mtllib lib.mtl # the library
v 0 0 0 # origin
v 1 0 0\t#x
v 0 1 0
o part # named
usemtl mat#1 # a hash inside a name stays
f 1 2 3 # one triangle
";
    let mtl = "newmtl mat#1 # red\nKd 1 0 0 # pure red\nillum 1\n";
    let model = imported(&[("comments.obj", obj), ("lib.mtl", mtl)]);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.meshes[0].name, "object 'part' (material 'mat#1')");
    let material = &model.materials[model.meshes[0].material as usize];
    assert_eq!(material.material.diffuse, DVec3::X);
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn one_mtllib_may_name_several_libraries() {
    let obj = format!("mtllib a.mtl b.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\nusemtl blue\nf 3 2 1\n");
    let model = imported(&[
        ("two.obj", &obj),
        ("a.mtl", "newmtl red\nKd 1 0 0\nillum 1\n"),
        ("b.mtl", "newmtl blue\nKd 0 0 1\nillum 1\n"),
    ]);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let diffuse: Vec<DVec3> = model
        .meshes
        .iter()
        .map(|m| model.materials[m.material as usize].material.diffuse)
        .collect();
    assert_eq!(diffuse, [DVec3::X, DVec3::Z]);
}

#[test]
fn a_library_name_with_spaces_is_one_name_unless_no_such_file_exists() {
    let red = "newmtl red\nKd 1 0 0\nillum 1\n";
    let obj = format!("mtllib my red lib.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\n");
    let model = imported(&[("spaces.obj", &obj), ("my red lib.mtl", red)]);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    // tinyobjloader's escaped spaces; the missing first name is a warning.
    let obj = format!("mtllib gone.mtl my\\ red\\ lib.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\n");
    let model = imported(&[("escaped.obj", &obj), ("my red lib.mtl", red)]);
    assert_eq!(model.materials[0].material.diffuse, DVec3::X);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(model.warnings[0].contains("escaped.obj:1: mtllib gone.mtl: cannot read"));
}

#[test]
fn a_missing_library_is_one_warning_and_the_default_material() {
    let obj = format!("mtllib missing.mtl\n{TRIANGLE}usemtl a\nf 1 2 3\nusemtl b\nf 3 2 1\n");
    let model = imported(&[("lonely.obj", &obj)]);
    assert_eq!(model.meshes.len(), 2);
    assert_eq!(model.materials.len(), 1);
    assert_eq!(model.materials[0].name, "default");
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0]
            .contains("lonely.obj:1: mtllib missing.mtl: cannot read the material library"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn a_library_that_exists_but_is_not_a_file_is_still_an_error() {
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::create_dir(dir.path().join("lib.mtl")).expect("mkdir");
    let obj = dir.path().join("folder.obj");
    std::fs::write(&obj, format!("{TRIANGLE}mtllib lib.mtl\nf 1 2 3\n")).expect("obj");
    let message = import_obj(&obj).expect_err("a directory").to_string();
    assert!(
        message.contains("folder.obj:4:1: mtllib lib.mtl: cannot read the material library"),
        "{message}"
    );
    assert!(message.contains("a directory"), "{message}");
}

#[test]
fn a_missing_texture_is_a_warning_and_the_material_stays_without_it() {
    let obj = format!("mtllib lib.mtl\n{TRIANGLE}usemtl a\nf 1 2 3\n");
    let mtl = "newmtl a\nKe 1 1 1\nmap_Ke glow.png\nmap_Kd C:\\Users\\me\\wood.png\nillum 1\n";
    let model = imported(&[("textured.obj", &obj), ("lib.mtl", mtl)]);
    let material = &model.materials[0];
    assert!(material.base_color_texture.is_none() && material.emissive_texture.is_none());
    assert_eq!(
        material.material.diffuse,
        DVec3::splat(0.8),
        "the default Kd, not the textured 1"
    );
    assert_eq!(material.material.emission, DVec3::ONE);
    let warnings = model.warnings.join("\n");
    assert_eq!(model.warnings.len(), 2, "{warnings}");
    assert!(
        warnings.contains("material 'a': map_Kd: the texture"),
        "{warnings}"
    );
    assert!(warnings.contains("glow.png does not exist"), "{warnings}");
}

#[test]
fn a_usemtl_before_its_mtllib_finds_its_material_with_a_warning() {
    let obj = format!("{TRIANGLE}usemtl red\nf 1 2 3\nmtllib lib.mtl\n");
    let model = imported(&[
        ("late.obj", &obj),
        ("lib.mtl", "newmtl red\nKd 1 0 0\nillum 1\n"),
    ]);
    assert_eq!(
        model.materials[model.meshes[0].material as usize]
            .material
            .diffuse,
        DVec3::X
    );
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("late.obj:4: usemtl red comes before the mtllib on line 6"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn an_empty_usemtl_and_normal_indices_without_normals_are_warnings() {
    let obj = format!("{TRIANGLE}usemtl\nf 1//1 2//1 3//1\nf 3//1 2//1 1//1\n");
    let model = imported(&[("lenient.obj", &obj)]);
    assert!(model.meshes[0].normals.is_none());
    assert_eq!(model.materials[0].name, "default");
    let warnings = model.warnings.join("\n");
    assert_eq!(model.warnings.len(), 2, "{warnings}");
    assert!(
        warnings.contains("lenient.obj:4: `usemtl` without a material name"),
        "{warnings}"
    );
    assert!(
        warnings.contains("lenient.obj:5: 2 faces give normal indices, but no `vn`"),
        "{warnings}"
    );
}

#[test]
fn a_material_without_a_name_is_skipped_with_a_warning() {
    let obj = format!("mtllib lib.mtl\n{TRIANGLE}usemtl a\nf 1 2 3\n");
    let mtl = "newmtl\nKd 1 0 0\nmap_Kd gone.png\nnewmtl a\nKd 0 1 0\nillum 1\n";
    let model = imported(&[("nameless.obj", &obj), ("lib.mtl", mtl)]);
    let names: Vec<&str> = model.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["a"]);
    assert_eq!(model.materials[0].material.diffuse, DVec3::Y);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("lib.mtl:1: `newmtl` without a material name"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn a_number_followed_by_junk_is_read_by_its_start_with_a_warning() {
    let obj = "v 0 0 0\nv 1e+2 0 0\nv 0 3.1+e2 0\nf 1 2 3\n";
    let model = imported(&[("numbers.obj", obj)]);
    assert_eq!(model.meshes[0].positions[2], DVec3::new(0.0, 3.1, 0.0));
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("numbers.obj:3:5: `3.1+e2` is read as 3.1"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn utf16_with_a_byte_order_mark_is_read() {
    for big_endian in [false, true] {
        let text = format!("# a box\r\n{TRIANGLE}f 1 2 3\r\n");
        let mut bytes = if big_endian {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for unit in text.encode_utf16() {
            bytes.extend(if big_endian {
                unit.to_be_bytes()
            } else {
                unit.to_le_bytes()
            });
        }
        let model = parse_obj(&bytes, Path::new("utf16.obj")).expect("imports");
        assert_eq!(model.meshes[0].triangles.len(), 1);
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    }
}

#[test]
fn a_file_without_triangles_is_an_error_naming_the_file() {
    let utf16_without_bom: Vec<u8> = "v 0 0 0\nf 1 1 1\n"
        .encode_utf16()
        .flat_map(u16::to_be_bytes)
        .collect();
    for (bytes, why) in [
        (&b""[..], "the file is empty"),
        (b"# nothing\n\n", "the file is empty"),
        (b"v 0 0 0\n", "it has no faces"),
        (
            b"v 0 0 0\nv 1 0 0\nl 1 2\n",
            "only lines and points (1 `l` and `p` statement)",
        ),
        (
            b"v 0 0 0\nv 1 0 0\nf 1 2 1\nf 1 2\n",
            "all 2 faces are degenerate",
        ),
        (&utf16_without_bom, "no OBJ statement was recognised"),
    ] {
        let message = parse_obj(bytes, Path::new("blank.obj"))
            .expect_err("no triangles")
            .to_string();
        assert!(
            message.starts_with("blank.obj: no triangles to render: "),
            "{message}"
        );
        assert!(message.contains(why), "{message}");
    }
}

#[test]
fn faces_of_one_object_and_material_make_one_mesh_however_often_they_alternate() {
    let mut obj = String::from("mtllib two.mtl\n");
    for k in 0..100 {
        obj.push_str(&format!(
            "{TRIANGLE}usemtl {}\nf -3 -2 -1\n",
            ["red", "blue"][k % 2]
        ));
    }
    let mtl = "newmtl red\nKd 1 0 0\nillum 1\nnewmtl blue\nKd 0 0 1\nillum 1\n";
    let model = imported(&[("runs.obj", &obj), ("two.mtl", mtl)]);
    let sizes: Vec<usize> = model.meshes.iter().map(|m| m.triangles.len()).collect();
    assert_eq!(sizes, [50, 50]);
}

/// OBJ text of `groups` groups of one triangle each.
fn obj_with_groups(groups: usize) -> String {
    let mut text = String::with_capacity(groups * 64);
    for g in 0..groups {
        let (x, y) = ((g % 1000) as f64, (g / 1000) as f64);
        text.push_str(&format!(
            "v {x} {y} 0\nv {} {y} 0\nv {x} {} 0\ng part{g}\nf -3 -2 -1\n",
            x + 0.5,
            y + 0.5
        ));
    }
    text
}

/// The fastest of `runs` imports of `text` (with the scene and the renderer's geometry
/// built from it, where mesh grouping once compared every pair of meshes).
fn fastest_load(text: &str, groups: usize, runs: usize) -> std::time::Duration {
    (0..runs)
        .map(|_| {
            let started = std::time::Instant::now();
            let model = parse_obj(text.as_bytes(), Path::new("groups.obj")).expect("imports");
            let scene = model.into_scene(Default::default());
            let geometry = gpu_render::low_level::accel::SceneGeometry::new(&scene);
            let elapsed = started.elapsed();
            assert_eq!(model.meshes.len(), groups);
            drop(geometry);
            elapsed
        })
        .min()
        .unwrap_or(std::time::Duration::MAX)
}

/// A ratio, never a wall-clock limit (as `tests/load_time.rs`): the fastest of a few
/// runs of each size counts, so that a burst of load elsewhere does not decide it.
#[test]
fn a_200k_group_obj_loads_in_linear_time() {
    let (small, large) = (50_000, 200_000);
    let small_text = obj_with_groups(small);
    let large_text = obj_with_groups(large);
    fastest_load(&small_text, small, 1);
    let small_time = fastest_load(&small_text, small, 2);
    let large_time = fastest_load(&large_text, large, 2);
    let ratio = large_time.as_secs_f64() / small_time.as_secs_f64().max(1e-9);
    eprintln!("{small} groups: {small_time:?}, {large} groups: {large_time:?}, ratio {ratio:.2}");
    // Linear is 4; quadratic would be 16.
    assert!(
        ratio < 8.0,
        "loading {large} groups took {ratio:.1}x as long as {small} ({large_time:?} against {small_time:?}); expected about 4x"
    );
}

/// The fastest of `runs` placements of `model` once per material override, `count`
/// overrides.
fn fastest_placements(model: &ImportedModel, count: u32, runs: usize) -> std::time::Duration {
    use gpu_render::scene::import::ModelPlacement;
    let placements: Vec<ModelPlacement> = (0..count)
        .map(|material| ModelPlacement {
            material: Some(material),
            ..ModelPlacement::IDENTITY
        })
        .collect();
    (0..runs)
        .map(|_| {
            let mut scene = model.into_scene(Default::default());
            let started = std::time::Instant::now();
            model.add_placements_to_scene(&mut scene, &placements);
            let elapsed = started.elapsed();
            assert_eq!(scene.meshes.len(), 1 + count as usize);
            elapsed
        })
        .min()
        .unwrap_or(std::time::Duration::MAX)
}

/// Placements are grouped by their material override: 4x the placements, each with
/// its own override, take about 4x the time (a ratio, as above).
#[test]
fn placements_with_many_material_overrides_are_added_in_linear_time() {
    let model = imported(&[("triangle.obj", &format!("{TRIANGLE}f 1 2 3\n"))]);
    let (small, large) = (20_000, 80_000);
    fastest_placements(&model, small, 1);
    let small_time = fastest_placements(&model, small, 5);
    let large_time = fastest_placements(&model, large, 5);
    let ratio = large_time.as_secs_f64() / small_time.as_secs_f64().max(1e-9);
    eprintln!("{small} placements: {small_time:?}, {large}: {large_time:?}, ratio {ratio:.2}");
    assert!(
        ratio < 8.0,
        "adding {large} placements took {ratio:.1}x as long as {small} ({large_time:?} against {small_time:?}); expected about 4x"
    );
}

/// `d` and `Tr` are coverage, as tinyobjloader and assimp read them: a blended material
/// of that alpha; glass ignores them, and `d 1` stays opaque.
#[test]
fn dissolve_makes_a_blended_material_of_that_alpha() {
    let mtl = "newmtl quarter\nKd 1 1 1\nd 0.25\n\
               newmtl tr\nKd 1 1 1\nTr 0.75\n\
               newmtl whole\nKd 1 1 1\nd 1\n\
               newmtl glass\nillum 7\nNi 1.5\nd 0.5\n";
    let mut obj = String::from("mtllib d.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for name in ["quarter", "tr", "whole", "glass"] {
        obj.push_str(&format!("usemtl {name}\nf 1 2 3\n"));
    }
    let model = imported(&[("d.obj", &obj), ("d.mtl", mtl)]);
    let material = |name: &str| &material_named(&model, name).material;
    for name in ["quarter", "tr"] {
        assert_eq!(material(name).alpha_mode, AlphaMode::Blend, "{name}");
        assert_eq!(material(name).alpha, 0.25, "{name}");
    }
    assert_eq!(material("whole").alpha_mode, AlphaMode::Opaque);
    assert_eq!(material("glass").alpha_mode, AlphaMode::Opaque);
    assert!(
        !model.warnings.iter().any(|w| w.contains("transparency")),
        "{:?}",
        model.warnings
    );
}

/// `map_d` (MTL's dissolve texture) is coverage, as tinyobjloader, assimp and three.js
/// read it: a grey mask's values, or a cut-out's alpha, become the alpha of the albedo
/// texture (blended, as `d` is), at `map_Kd`'s size; without `map_Kd`, on a white
/// texture that `Kd` colours.
#[test]
fn map_d_is_coverage_in_the_albedo_texture_s_alpha() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_png(
        &dir.path().join("leaf.png"),
        2,
        1,
        &[[255, 0, 0, 255], [0, 255, 0, 255]],
    );
    // A grey mask at twice the size: its texels average in pairs.
    write_png(
        &dir.path().join("leaf mask.png"),
        4,
        2,
        &[
            [0, 0, 0, 255],
            [0, 0, 0, 255],
            [255, 255, 255, 255],
            [128, 128, 128, 255],
        ]
        .repeat(2),
    );
    // A cut-out whose colour is black but whose alpha holds the mask.
    write_png(
        &dir.path().join("cutout.png"),
        2,
        1,
        &[[0, 0, 0, 0], [0, 0, 0, 255]],
    );
    std::fs::write(
        dir.path().join("leaf.mtl"),
        "newmtl leaf\nKd 1 1 1\nmap_Kd leaf.png\nmap_d leaf mask.png\n\
         newmtl cut\nKd 0.5 0.5 0.5\nmap_d -imfchan m cutout.png\n\
         newmtl auto\nmap_d cutout.png\n\
         newmtl glass\nillum 7\nmap_d cutout.png\n\
         newmtl lost\nmap_d nowhere.png\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.path().join("leaf.obj"),
        "mtllib leaf.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
         usemtl leaf\nf 1/1 2/2 3/3\nusemtl cut\nf 1/1 2/2 3/3\nusemtl auto\nf 1/1 2/2 3/3\n\
         usemtl glass\nf 1/1 2/2 3/3\nusemtl lost\nf 1/1 2/2 3/3\n",
    )
    .expect("obj");
    let model = import_obj(&dir.path().join("leaf.obj")).expect("imports");
    let material = |name: &str| material_named(&model, name);
    let texels = |name: &str| {
        let texture = material(name).base_color_texture.expect("a texture");
        let image = &model.images[texture.image as usize];
        (0..image.width)
            .map(|x| image.texel(x, 0))
            .collect::<Vec<_>>()
    };

    // The colour texture keeps its (linearised) colours; its alpha is the mask's mean
    // over each texel, the file's values (a scalar texture is not linearised).
    let leaf = texels("leaf");
    assert_eq!(leaf.len(), 2, "map_Kd's size");
    assert_eq!(leaf[0], [1.0, 0.0, 0.0, 0.0]);
    let grey = (1.0 + 128.0 / 255.0) / 2.0;
    assert!((leaf[1][3] - grey).abs() < 1e-6, "{:?}", leaf[1]);
    assert_eq!(leaf[1][1], 1.0);
    assert_eq!(material("leaf").material.alpha_mode, AlphaMode::Blend);
    assert_eq!(material("leaf").material.alpha, 1.0);
    // `-imfchan m`: the alpha; on white, Kd giving the colour.
    let cut = texels("cut");
    assert_eq!(cut, vec![[1.0, 1.0, 1.0, 0.0], [1.0; 4]]);
    assert_eq!(material("cut").material.diffuse, DVec3::splat(0.5));
    // Without -imfchan an image with alpha gives its alpha (its colour, all black,
    // would cover nothing); without Kd the default grey.
    assert_eq!(texels("auto"), cut);
    assert_eq!(material("auto").material.diffuse, DVec3::splat(0.8));
    // Glass ignores it, as it ignores d; a missing mask is a warning.
    assert_eq!(material("glass").material.alpha_mode, AlphaMode::Opaque);
    assert!(material("glass").base_color_texture.is_none());
    assert_eq!(material("lost").material.alpha_mode, AlphaMode::Opaque);
    for needle in [
        "material 'glass': map_d is ignored on glass",
        "material 'lost': map_d: the texture",
    ] {
        assert!(
            model.warnings.iter().any(|w| w.contains(needle)),
            "{needle}: {:?}",
            model.warnings
        );
    }
    assert_eq!(model.warnings.len(), 2, "{:?}", model.warnings);
}

/// Normal maps: `norm`, and `bump` / `map_Bump` where the image is a tangent-space
/// normal map (Blender's exporter writes its normal maps so, `-bm` the strength); a
/// grey `bump` image is a height map, not supported, and left out with a warning.
/// Tangents come from MikkTSpace over the normals and texture coordinates.
#[test]
fn norm_and_normal_map_bumps_map_normals_and_height_maps_are_warned_about() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // Tilted 0.6 towards the map's +x; a flat blue normal map; a grey height map.
    write_png(&dir.path().join("tilt.png"), 1, 1, &[[204, 128, 230, 255]]);
    write_png(&dir.path().join("blue.png"), 1, 1, &[[128, 128, 255, 255]]);
    write_png(&dir.path().join("height.png"), 1, 1, &[[90, 90, 90, 255]]);
    std::fs::write(
        dir.path().join("maps.mtl"),
        "newmtl norm\nKd 0.8 0.8 0.8\nnorm tilt.png\n\
         newmtl blender\nKd 0.8 0.8 0.8\nmap_Bump -bm 0.5 blue.png\n\
         newmtl height\nKd 0.8 0.8 0.8\nbump height.png\n\
         newmtl plain\nKd 0.8 0.8 0.8\n",
    )
    .expect("mtl");
    let obj = |material: &str| format!("mtllib maps.mtl\nusemtl {material}\n{QUAD}");
    let import_with = |material: &str| {
        std::fs::write(dir.path().join("quad.obj"), obj(material)).expect("obj");
        import_obj(&dir.path().join("quad.obj")).expect("imports")
    };
    let find = |model: &ImportedModel, name: &str| material_named(model, name).clone();

    let model = import_with("norm");
    assert!(find(&model, "norm").normal_texture.is_some());
    assert_eq!(find(&model, "norm").material.normal_scale, 1.0);
    assert_eq!(find(&model, "blender").material.normal_scale, 0.5);
    assert!(find(&model, "blender").normal_texture.is_some());
    assert!(find(&model, "height").normal_texture.is_none());
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("material 'height': bump: the image")
            && model.warnings[0].contains("is grey, a height map: bump mapping is not supported"),
        "{:?}",
        model.warnings
    );
    // MikkTSpace's tangents: along +u (+x), handedness +1 (v runs up +y in OBJ).
    crate::support::models::assert_tangents(
        model.meshes[0].tangents.as_ref(),
        DVec4::new(1.0, 0.0, 0.0, 1.0),
    );

    // Rendered: the tilt shows against the plain quad, on both backends.
    let scene = |model: &ImportedModel| {
        crate::support::models::small_scene(
            model,
            DVec3::new(1.0, 0.5, 4.0),
            DVec3::new(1.0, 0.5, 0.0),
        )
    };
    let mapped = scene(&model);
    let plain = scene(&import_with("plain"));
    let (a, b) = (
        gpu_render::cpu::render(&mapped, None).image,
        gpu_render::cpu::render(&plain, None).image,
    );
    let difference = crate::support::compare::max_channel_difference(&a, &b);
    assert!(
        difference > 1e-2,
        "the normal map changes nothing ({difference})"
    );
    if let Some(gpu) = crate::support::gpu::headless_gpu() {
        let renderer = crate::support::gpu::renderer(&gpu);
        crate::support::twins::assert_backends_agree(
            &gpu,
            &renderer,
            "obj-norm",
            &mapped,
            crate::support::twins::TWIN_TOLERANCE,
        );
    }

    // Without vn the tangents cannot be made: a warning, the map not applied.
    let no_normals = QUAD
        .replace("vn 0 0 1\n", "")
        .replace("/1 ", "/ ")
        .replace("/1\n", "/\n");
    std::fs::write(
        dir.path().join("bare.obj"),
        format!("mtllib maps.mtl\nusemtl norm\n{no_normals}"),
    )
    .expect("obj");
    let bare = import_obj(&dir.path().join("bare.obj")).expect("imports");
    assert!(bare.meshes[0].tangents.is_none());
    assert!(
        bare.warnings
            .iter()
            .any(|w| w.contains("its material's normal map needs tangents")),
        "{:?}",
        bare.warnings
    );
}

/// The PBR extension's `map_Pr` and `map_Pm` (as tinyobjloader reads them) become one
/// metallic/roughness texture laid out as glTF's (green roughness, blue metalness) at
/// the larger map's size; a map replaces its factor (as Blender's importer reads it);
/// the maps alone make the material metal/roughness; `-imfchan` picks a channel,
/// luminance otherwise.
#[test]
fn map_pr_and_map_pm_make_a_metallic_roughness_texture() {
    let dir = tempfile::tempdir().expect("temporary directory");
    write_png(
        &dir.path().join("rough.png"),
        2,
        1,
        &[[51, 51, 51, 255], [204, 204, 204, 255]],
    );
    write_png(&dir.path().join("metal.png"), 1, 1, &[[0, 0, 128, 255]]);
    std::fs::write(
        dir.path().join("pbr.mtl"),
        "newmtl pbr\nKd 0.8 0.8 0.8\nPr 0.5\nmap_Pr rough.png\nmap_Pm -imfchan b metal.png\n\
         newmtl maps_only\nKd 0.8 0.8 0.8\nmap_Pm metal.png\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.path().join("pbr.obj"),
        format!("mtllib pbr.mtl\nusemtl pbr\n{QUAD}usemtl maps_only\nf 1/1/1 2/2/1 3/3/1\n"),
    )
    .expect("obj");
    let model = import_obj(&dir.path().join("pbr.obj")).expect("imports");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let find = |name: &str| material_named(&model, name);
    let pbr = find("pbr");
    assert_eq!(pbr.material.kind, MaterialKind::Pbr);
    assert_eq!(pbr.material.roughness, 1.0, "the map replaces Pr 0.5");
    assert_eq!(pbr.material.metallic, 1.0, "the map gives the metalness");
    let texture = pbr.metallic_roughness_texture.expect("a texture");
    let image = &model.images[texture.image as usize];
    assert_eq!((image.width, image.height), (2, 1));
    let metal = 128.0 / 255.0;
    for (x, rough) in [(0, 51.0 / 255.0), (1, 204.0 / 255.0)] {
        let t = image.texel(x, 0);
        assert!(
            (t[1] - rough).abs() < 1e-6 && (t[2] - metal).abs() < 1e-6,
            "{t:?}"
        );
    }
    // Only map_Pm: a metal/roughness material (roughness 1 as without Pr), the
    // texture's green 1 (no roughness map) and blue the map's luminance.
    let only = find("maps_only");
    assert_eq!(only.material.kind, MaterialKind::Pbr);
    assert_eq!(
        (only.material.roughness, only.material.metallic),
        (1.0, 1.0)
    );
    let image = &model.images[only.metallic_roughness_texture.expect("a texture").image as usize];
    assert_eq!(image.texel(0, 0)[1], 1.0);
    assert!((image.texel(0, 0)[2] - 0.0722 * metal).abs() < 1e-6);
}
