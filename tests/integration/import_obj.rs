//! The OBJ/MTL importer against small hand-made files with known answers: geometry,
//! groups, the MTL mapping table of `docs/models.md`, textures, the shipped torus, and
//! every kind of bad input (each a clear error naming the file and line, never a panic).

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use gpu_render::color::srgb_decode;
use gpu_render::scene::import::{ImportedModel, WrapMode, import_model, import_obj, parse_obj};
use gpu_render::scene::{MaterialKind, SceneError};

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
    let material = |name: &str| {
        model
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("no material {name}"))
            .material
    };
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
    assert!(
        model.warnings.iter().any(|w| w.contains("-s 2 2")),
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
    ("v 0 0 0 0\n", "bad.obj:1:9: position w is 0"),
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
    ("usemtl\n", "bad.obj:1:1: `usemtl` needs a material name"),
    ("mtllib\n", "bad.obj:1:1: `mtllib` needs a file name"),
    (
        "mtllib missing.mtl\n",
        "bad.obj:1:1: mtllib missing.mtl: cannot read the material library",
    ),
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
    ("newmtl\n", "lib.mtl:1:1: `newmtl` needs a material name"),
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
        "newmtl a\nmap_Kd\n",
        "lib.mtl:2:1: `map_Kd` needs a file name",
    ),
    (
        "newmtl a\nKe 1 1 1\nmap_Ke missing.png\n",
        "lib.mtl:3:1: material 'a': map_Ke: the texture",
    ),
    (
        "newmtl a\nmap_Kd missing.png\n",
        "lib.mtl:2:1: material 'a': map_Kd: the texture",
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
