//! Model files placed in scene files (`[[objects]] type = "model"`): where their
//! triangles land, what they shade with, the round trip through a glTF file written by
//! another tool (Python's trimesh) against the same triangles typed into TOML, and the
//! errors of bad placements, each naming the scene file, the object and the problem.

use std::path::{Path, PathBuf};

use glam::DVec3;
use gpu_render::cpu::render;
use gpu_render::scene::{LoadOptions, Scene, load_scene, load_scene_with};

fn manifest(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A scene file beside the test fixtures, so that `file` names them relatively.
struct SceneDir {
    dir: tempfile::TempDir,
}

impl SceneDir {
    fn new() -> Self {
        let dir = tempfile::tempdir().expect("temporary directory");
        for name in [
            "trimesh_scene.glb",
            "trimesh_scene.gltf",
            "gltf_buffer.bin",
            "trimesh_scene.expected.json",
        ] {
            std::fs::copy(
                manifest(&format!("tests/fixtures/models/{name}")),
                dir.path().join(name),
            )
            .expect("copy fixture");
        }
        std::fs::copy(
            manifest("scenes/models/vase.gltf"),
            dir.path().join("vase.gltf"),
        )
        .expect("copy model");
        Self { dir }
    }

    fn write(&self, name: &str, text: &str) -> PathBuf {
        let path = self.dir.path().join(name);
        std::fs::write(&path, text).expect("write scene");
        path
    }
}

const HEADER: &str = r#"
[render]
width = 48
height = 32
samples_per_pixel = 1

[camera]
eye = [0.0, 4.0, 8.0]
look_at = [0.0, 0.3, 0.0]
fov_y_degrees = 45

[[lights]]
type = "point"
position = [3.0, 6.0, 4.0]
intensity = 40.0

[[lights]]
type = "directional"
direction = [-0.3, -1.0, -0.5]
irradiance = 1.0

[materials.grey]
type = "lambert"
albedo = 0.6

[[objects]]
type = "plane"
point = [0.0, -0.6, 0.0]
normal = [0.0, 1.0, 0.0]
material = "grey"
"#;

/// Every world-space triangle of a scene's meshes.
fn mesh_triangles(scene: &Scene) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for mesh in &scene.meshes {
        for instance in &mesh.instances {
            for t in &mesh.triangles {
                out.push(t.map(|i| instance.transform_point3(mesh.positions[i as usize])));
            }
        }
    }
    out
}

#[test]
fn a_placed_model_lands_where_its_transform_says() {
    let dir = SceneDir::new();
    let plain = dir.write(
        "plain.toml",
        &format!("{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"trimesh_scene.glb\"\n"),
    );
    let moved = dir.write(
        "moved.toml",
        &format!(
            "{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"trimesh_scene.glb\"\n\
             translate = [1.0, 2.0, 3.0]\nrotate = [0.0, 90.0, 0.0]\nscale = 2.0\n"
        ),
    );
    let plain = mesh_triangles(&load_scene(&plain).expect("plain scene loads"));
    let moved = mesh_triangles(&load_scene(&moved).expect("moved scene loads"));
    assert!(!plain.is_empty());
    assert_eq!(plain.len(), moved.len());
    // 90 degrees about y takes (x, y, z) to (z, y, -x); then scale 2 and translate.
    let expected = |p: DVec3| DVec3::new(p.z, p.y, -p.x) * 2.0 + DVec3::new(1.0, 2.0, 3.0);
    for (a, b) in plain.iter().zip(&moved) {
        for k in 0..3 {
            assert!(
                expected(a[k]).distance(b[k]) < 1e-9,
                "{:?} moved to {:?}, not {:?}",
                a[k],
                b[k],
                expected(a[k])
            );
        }
    }
}

/// One model file placed four times (twice with its own materials, once smooth-less,
/// once with a scene material) is imported once and held once per distinct (material,
/// smooth) pair: three copies of each of its meshes, not four, its materials added
/// once; the world-space triangles are those of the four placements, and the CPU
/// renders the scene as it renders the same placements added one by one.
#[test]
fn a_model_placed_several_times_is_held_once_per_material() {
    let dir = SceneDir::new();
    let placements = [
        "translate = [-1.5, 0.0, 0.0]",
        "translate = [1.5, 0.0, 0.0]\nrotate = [0.0, 40.0, 0.0]",
        "translate = [0.0, 0.0, -1.5]\nsmooth = false",
        "translate = [0.0, 1.0, 1.0]\nmaterial = \"grey\"",
    ];
    let objects: String = placements
        .iter()
        .map(|p| format!("\n[[objects]]\ntype = \"model\"\nfile = \"vase.gltf\"\n{p}\n"))
        .collect();
    let path = dir.write("four.toml", &format!("{HEADER}{objects}"));
    let scene = load_scene(&path).expect("the scene loads");
    let model = gpu_render::scene::import::import_model(&dir.dir.path().join("vase.gltf"))
        .expect("the vase imports");
    assert_eq!(
        scene.meshes.len(),
        3 * model.meshes.len(),
        "one copy per (material, smooth)"
    );
    let placed: usize = scene.meshes.iter().map(|m| m.instances.len()).sum();
    let per_placement: usize = model.meshes.iter().map(|m| m.instances.len()).sum();
    assert_eq!(placed, 4 * per_placement);
    // The header's one material, and the vase's once.
    assert_eq!(scene.materials.len(), 1 + model.materials.len());

    // The same placements added one by one, each with its own copy.
    let mut separate = load_scene(&dir.write("empty.toml", HEADER)).expect("the header loads");
    for (k, p) in placements.iter().enumerate() {
        let one = load_scene(&dir.write(
            &format!("one{k}.toml"),
            &format!("{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"vase.gltf\"\n{p}\n"),
        ))
        .expect("one placement loads");
        let base = separate.materials.len() as u32 - 1;
        for material in &one.materials[1..] {
            separate.materials.push(*material);
            separate.material_names.push(format!("copy {k}"));
        }
        for mut mesh in one.meshes {
            if mesh.material > 0 {
                mesh.material += base;
            }
            separate.meshes.push(mesh);
        }
    }
    let mut once = mesh_triangles(&scene);
    let mut each = mesh_triangles(&separate);
    let key = |t: &[DVec3; 3]| t.map(|p| p.to_array()).concat();
    once.sort_by(|a, b| key(a).partial_cmp(&key(b)).expect("finite"));
    each.sort_by(|a, b| key(a).partial_cmp(&key(b)).expect("finite"));
    assert_eq!(once, each, "the same world-space triangles");
    let a = render(&scene, None).image;
    let b = render(&separate, None).image;
    let differing = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 1e-5))
        .count();
    // Only exact ties between coincident surfaces could resolve differently; there
    // are none here.
    assert_eq!(differing, 0, "{differing} pixels differ");
}

/// Side triangles of the renderer's geometry (normals mostly horizontal; instanced
/// meshes' triangles as they stand in world space), and how many of them face away from
/// the vase's vertical axis.
fn outward_side_triangles(scene: &Scene) -> (usize, usize) {
    let geometry = gpu_render::low_level::accel::SceneGeometry::new(scene);
    let mut world: Vec<[DVec3; 3]> = geometry.triangles.iter().map(|t| t.vertices).collect();
    for instance in &geometry.instances {
        let mesh = &geometry.instanced_meshes[instance.mesh as usize];
        world
            .extend((0..mesh.triangles.len()).map(|j| instance.world_triangle(mesh, j).0.vertices));
    }
    let (mut outward, mut sides) = (0, 0);
    for vertices in &world {
        let [a, b, c] = *vertices;
        let normal = (b - a).cross(c - a).normalize();
        let centre = (a + b + c) / 3.0;
        let radial = DVec3::new(centre.x, 0.0, centre.z);
        if radial.length() > 1e-3 && normal.dot(radial.normalize()).abs() > 0.5 {
            sides += 1;
            outward += usize::from(normal.dot(radial) > 0.0);
        }
    }
    (outward, sides)
}

/// A placement that mirrors the model (a negative scale) flips every triangle's winding,
/// so that the closed vase still faces out and its materials shade the outside.
#[test]
fn a_mirrored_placement_keeps_the_triangles_facing_out() {
    let dir = SceneDir::new();
    // The vase's own placements are off its axis; put one copy at the origin.
    let place = |scale: &str| {
        dir.write(
            "vase.toml",
            &format!(
                "{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"vase.gltf\"\n\
                 scale = {scale}\n"
            ),
        )
    };
    let plain = load_scene(&place("1.0")).expect("scene loads");
    let mirrored = load_scene(&place("[-1.0, 1.0, 1.0]")).expect("mirrored scene loads");
    // Recentre each instance on the axis through its own bounds.
    let recentred = |mut scene: Scene| {
        for mesh in &mut scene.meshes {
            for instance in &mut mesh.instances {
                let points: Vec<DVec3> = mesh
                    .positions
                    .iter()
                    .map(|p| instance.transform_point3(*p))
                    .collect();
                let (lo, hi) = points.iter().fold(
                    (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                    |(lo, hi), p| (lo.min(*p), hi.max(*p)),
                );
                let centre = (lo + hi) / 2.0;
                *instance = glam::DMat4::from_translation(DVec3::new(-centre.x, 0.0, -centre.z))
                    * *instance;
            }
        }
        scene
    };
    let (out_plain, sides_plain) = outward_side_triangles(&recentred(plain));
    let (out_mirrored, sides_mirrored) = outward_side_triangles(&recentred(mirrored));
    assert!(sides_plain > 10, "only {sides_plain} side triangles found");
    assert_eq!(sides_plain, sides_mirrored);
    assert!(
        out_plain * 10 >= sides_plain * 9,
        "the vase faces out: {out_plain} of {sides_plain}"
    );
    assert_eq!(
        out_plain,
        out_mirrored,
        "mirroring turned {} of {sides_plain} side triangles inside out",
        out_plain.abs_diff(out_mirrored)
    );
}

#[test]
fn smooth_false_drops_the_vertex_normals() {
    let dir = SceneDir::new();
    let smooth = dir.write(
        "smooth.toml",
        &format!("{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"trimesh_scene.glb\"\n"),
    );
    let flat = dir.write(
        "flat.toml",
        &format!(
            "{HEADER}\n[[objects]]\ntype = \"model\"\nfile = \"trimesh_scene.glb\"\n\
             smooth = false\n"
        ),
    );
    let smooth = load_scene(&smooth).expect("loads");
    let flat = load_scene(&flat).expect("loads");
    assert!(smooth.meshes.iter().all(|m| m.normals.is_some()));
    assert!(flat.meshes.iter().all(|m| m.normals.is_none()));
}

/// The triangles trimesh computed for its own file, typed into TOML.
fn trimesh_triangles_as_toml(material: &str) -> String {
    let expected: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(manifest(
            "tests/fixtures/models/trimesh_scene.expected.json",
        ))
        .expect("expected geometry"),
    )
    .expect("json");
    let mut toml = String::new();
    for triangle in expected["triangles"].as_array().expect("triangles") {
        let corners: Vec<String> = triangle
            .as_array()
            .expect("corners")
            .iter()
            .map(|c| {
                let c: Vec<String> = c
                    .as_array()
                    .expect("point")
                    .iter()
                    .map(|x| format!("{:?}", x.as_f64().expect("number")))
                    .collect();
                format!("[{}]", c.join(", "))
            })
            .collect();
        toml.push_str(&format!(
            "\n[[objects]]\ntype = \"triangle\"\nvertices = [{}]\nmaterial = \"{material}\"\n",
            corners.join(", ")
        ));
    }
    toml
}

/// The round trip: trimesh's glTF file placed in a scene renders as the triangles
/// trimesh says it holds, typed into TOML (flat shaded, one material: TOML triangles
/// have no vertex normals). Per pixel in linear float: within 1e-4 relative, except at
/// most 1% of the pixels, where the f32 positions of the file move an edge.
#[test]
fn a_gltf_file_written_by_trimesh_renders_as_its_triangles_typed_into_toml() {
    let dir = SceneDir::new();
    let materials = "\n[materials.paint]\ntype = \"blinn_phong\"\ndiffuse = [0.6, 0.3, 0.2]\n\
                     specular = 0.2\nshininess = 40\n";
    for file in ["trimesh_scene.glb", "trimesh_scene.gltf"] {
        let model = dir.write(
            "model.toml",
            &format!(
                "{HEADER}{materials}\n[[objects]]\ntype = \"model\"\nfile = \"{file}\"\n\
                 material = \"paint\"\nsmooth = false\n"
            ),
        );
        let typed = dir.write(
            "typed.toml",
            &format!("{HEADER}{materials}{}", trimesh_triangles_as_toml("paint")),
        );
        let empty = dir.write("empty.toml", &format!("{HEADER}{materials}"));
        let empty = render(&load_scene(&empty).expect("empty scene loads"), None).image;
        let model = render(&load_scene(&model).expect("model scene loads"), None).image;
        let covered = model
            .pixels
            .iter()
            .zip(&empty.pixels)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            covered * 10 >= model.pixels.len(),
            "{file}: the model shows in only {covered} pixels"
        );
        let typed = render(&load_scene(&typed).expect("typed scene loads"), None).image;
        let mut outliers = 0;
        let mut lit = 0;
        for (a, b) in model.pixels.iter().zip(&typed.pixels) {
            let scale = a[..3]
                .iter()
                .chain(&b[..3])
                .fold(1e-3_f32, |m, v| m.max(*v));
            if (0..3).any(|c| (a[c] - b[c]).abs() > 1e-4 * scale) {
                outliers += 1;
            }
            if a[..3].iter().any(|v| *v > 0.0) {
                lit += 1;
            }
        }
        assert!(
            lit > model.pixels.len() / 2,
            "{file}: the image is mostly black"
        );
        assert!(
            outliers * 100 <= model.pixels.len(),
            "{file}: {outliers} of {} pixels differ from the typed triangles",
            model.pixels.len()
        );
    }
}

fn load_error(dir: &SceneDir, object: &str, sandbox: bool) -> String {
    let path = dir.write("bad.toml", &format!("{HEADER}\n[[objects]]\n{object}"));
    let options = LoadOptions {
        sandbox,
        ..LoadOptions::default()
    };
    match load_scene_with(&path, &options) {
        Ok(_) => panic!("accepted:\n{object}"),
        Err(err) => err.to_string(),
    }
}

#[test]
fn bad_placements_name_the_scene_the_object_and_the_problem() {
    let dir = SceneDir::new();
    let cases: [(&str, bool, &[&str]); 7] = [
        (
            "type = \"model\"\nfile = \"missing.glb\"\n",
            false,
            &[
                "bad.toml:",
                "objects[1] (model): file `missing.glb`",
                "cannot read",
            ],
        ),
        (
            "type = \"model\"\n",
            false,
            &["bad.toml", "objects[1]", "file"],
        ),
        (
            "type = \"model\"\nfile = \"vase.gltf\"\nscale = [1.0, 0.0, 1.0]\n",
            false,
            &["bad.toml", "objects[1]", "scale must not be 0"],
        ),
        (
            "type = \"model\"\nfile = \"vase.gltf\"\nradius = 1.0\n",
            false,
            &["bad.toml", "radius"],
        ),
        (
            "type = \"model\"\nfile = \"vase.gltf\"\nmaterial = \"nope\"\n",
            false,
            &["bad.toml", "nope"],
        ),
        (
            "type = \"model\"\nfile = \"vase.gltf\"\ntranslate = [0.0, nan, 0.0]\n",
            false,
            &["bad.toml", "translate"],
        ),
        (
            "type = \"model\"\nfile = \"vase.gltf\"\n",
            true,
            &["bad.toml", "sandbox"],
        ),
    ];
    for (object, sandbox, needles) in cases {
        let message = load_error(&dir, object, sandbox);
        for needle in needles {
            assert!(
                message.contains(needle),
                "{needle:?} missing from {message:?} for\n{object}"
            );
        }
    }
}
