//! Property-based fuzzing of the model importers (proptest): whatever the bytes,
//! `parse_obj` and `parse_gltf` return (never panic) within a second, and a model they
//! accept keeps every promise of `ImportedModel` (indices in range, finite positions
//! and invertible instance transforms, materials within the scene format's ranges) and
//! renders a finite image on the CPU at 8 × 6 pixels when flattened into triangles.
//!
//! Inputs are the shipped models and the trimesh fixture, mutated as bytes (numbers
//! replaced by NaN, infinities, huge and negative values; tokens of both formats
//! inserted; bytes flipped; ranges deleted) or truncated, and the glTF ones also taken
//! apart and mutated by structure (JSON numbers replaced and members removed while the
//! JSON stays well-formed; buffer floats set to NaN or infinity, bytes flipped, buffers
//! cut) so that the mutations reach the checks past the parser. OBJ inputs are parsed
//! as `scenes/models/torus.obj` so that its MTL library and texture resolve; glTF inputs
//! beside their own files.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use gpu_render::scene::import::{ImportedModel, parse_gltf, parse_obj};
use gpu_render::scene::{Environment, MaterialKind, RenderSettings, Scene, SceneError, Shape};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// Longest an import may take (milliseconds for these files; catches runaway loops).
const IMPORT_BUDGET: Duration = Duration::from_secs(1);
/// Largest flattened model that is also rendered.
const RENDERED_TRIANGLES: u64 = 5_000;

fn manifest(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The seeds: (path the bytes are parsed as, bytes).
fn seeds() -> Vec<(PathBuf, Vec<u8>)> {
    [
        "scenes/models/torus.obj",
        "scenes/models/vase.gltf",
        "tests/fixtures/models/trimesh_scene.glb",
        "tests/fixtures/models/trimesh_scene.gltf",
    ]
    .iter()
    .map(|p| {
        let path = manifest(p);
        let bytes = std::fs::read(&path).expect("seed model");
        (path, bytes)
    })
    .collect()
}

fn import(path: &Path, bytes: &[u8]) -> Result<ImportedModel, SceneError> {
    if path.extension().is_some_and(|e| e == "obj") {
        parse_obj(bytes, path)
    } else {
        parse_gltf(bytes, path)
    }
}

/// Imports `bytes`; panics (a test failure) if the importer panics or is slow, or an
/// accepted model breaks a promise or renders a NaN.
fn check_model_bytes(path: &Path, bytes: &[u8]) {
    let started = Instant::now();
    let result = std::panic::catch_unwind(|| import(path, bytes));
    let elapsed = started.elapsed();
    let Ok(result) = result else {
        panic!(
            "the importer panicked on {} bytes parsed as {}:\n{}",
            bytes.len(),
            path.display(),
            String::from_utf8_lossy(bytes)
        );
    };
    assert!(elapsed < IMPORT_BUDGET, "import took {elapsed:?}");
    match result {
        Ok(model) => check_model(&model),
        Err(e) => {
            let message = e.to_string();
            assert!(message.contains(&*path.to_string_lossy()) || message.contains(".mtl"));
        }
    }
}

fn check_model(model: &ImportedModel) {
    for mesh in &model.meshes {
        let count = mesh.positions.len();
        assert!(
            mesh.positions.iter().all(|p| p.is_finite()),
            "{}",
            mesh.name
        );
        assert!(!mesh.triangles.is_empty(), "{}", mesh.name);
        assert!(
            mesh.triangles
                .iter()
                .flatten()
                .all(|&i| (i as usize) < count)
        );
        if let Some(normals) = &mesh.normals {
            assert_eq!(normals.len(), count);
            assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-9));
        }
        if let Some(uvs) = &mesh.uvs {
            assert_eq!(uvs.len(), count);
            assert!(uvs.iter().all(|uv| uv.is_finite()));
        }
        assert!((mesh.material as usize) < model.materials.len());
        assert!(!mesh.instances.is_empty());
        for transform in &mesh.instances {
            assert!(transform.is_finite() && transform.determinant() != 0.0);
        }
    }
    for imported in &model.materials {
        let m = imported.material;
        let unit =
            |c: glam::DVec3| c.cmpge(glam::DVec3::ZERO).all() && c.cmple(glam::DVec3::ONE).all();
        assert!(
            unit(m.diffuse) && unit(m.specular) && unit(m.transmittance),
            "{m:?}"
        );
        assert!(m.emission.is_finite() && m.emission.cmpge(glam::DVec3::ZERO).all());
        if m.kind == MaterialKind::BlinnPhong {
            assert!((m.diffuse + m.specular).max_element() <= 1.0 + 1e-12);
            assert!((0.0..=1e6).contains(&m.shininess));
        }
        assert!(m.ior > 0.0 && m.ior.is_finite());
        assert!(m.coat_ior == 0.0 || m.coat_ior >= 1.0);
        assert!((0.0..=1.0).contains(&m.metallic) && (0.0..=1.0).contains(&m.roughness));
        for texture in [
            imported.base_color_texture,
            imported.metallic_roughness_texture,
            imported.emissive_texture,
        ]
        .into_iter()
        .flatten()
        {
            assert!((texture.image as usize) < model.images.len());
        }
    }
    if let Some(camera) = &model.camera {
        let c = camera.camera;
        assert!(c.eye.is_finite() && c.look_at.is_finite() && c.up.is_finite());
        assert!(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0);
    }
    if model.world_triangle_count() <= RENDERED_TRIANGLES {
        render_small(model);
    }
}

/// Flattens the model into a scene of triangles with its own or the default camera and
/// lights, and renders it on the CPU.
fn render_small(model: &ImportedModel) {
    let shapes: Vec<Shape> = model
        .world_triangles()
        .filter(|t| !t.is_degenerate())
        .map(|t| Shape::Triangle {
            vertices: t.vertices,
            material: t.material,
        })
        .collect();
    assert!(shapes.iter().all(|s| match s {
        Shape::Triangle { vertices, .. } => vertices.iter().all(|v| v.is_finite()),
        _ => true,
    }));
    let camera = model.camera_or_default(8.0 / 6.0);
    if (camera.look_at - camera.eye).length() == 0.0 {
        return;
    }
    let scene = Scene {
        render: RenderSettings {
            width: 8,
            height: 6,
            ..RenderSettings::default()
        },
        camera,
        environment: Environment::default(),
        materials: model.materials.iter().map(|m| m.material).collect(),
        material_names: model.materials.iter().map(|m| m.name.clone()).collect(),
        lights: model.lights_or_default(),
        shapes,
        meshes: vec![],
        images: Vec::new(),
    };
    let rendered = gpu_render::cpu::render(&scene, None);
    assert!(
        rendered
            .image
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite())),
        "a non-finite pixel"
    );
}

/// Number spellings at the edges, for both formats.
const NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "1e308",
    "3.4028236e38",
    "1e-45",
    "0",
    "-0",
    "-1",
    "-2147483649",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "0.5",
    "2",
    "7",
];

/// Fragments of OBJ, MTL and glTF.
const TOKENS: &[&str] = &[
    "\n",
    " ",
    "\t",
    "/",
    "//",
    "#",
    "\\",
    "-",
    ".",
    "v ",
    "vt ",
    "vn ",
    "f ",
    "l ",
    "o ",
    "g ",
    "usemtl ",
    "mtllib ",
    "newmtl ",
    "illum ",
    "map_Kd ",
    "f 1 2 3\n",
    "f -1 -2 -3\n",
    "f 1/1/1 2/2/2 3/3/3 4/4/4\n",
    "v 1 2 3\n",
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "null",
    "true",
    "\"mode\":",
    "\"count\":",
    "\"byteOffset\":",
    "\"byteStride\":",
    "\"matrix\":",
    "\"children\":[0],",
    "\"mesh\":0,",
    "\"camera\":0,",
    "\"indices\":0,",
    "\"extensionsRequired\":[\"KHR_mesh_quantization\"],",
    "\"sparse\":",
    "\"uri\":",
    "\"data:,\"",
    "\"scale\":[0,0,0],",
    "\"rotation\":[0,0,0,0],",
];

/// One edit of a model file's bytes.
#[derive(Debug, Clone)]
enum Edit {
    /// Replace the number-like run of bytes at this fraction of the file.
    Number(f64, usize),
    /// Insert a token here.
    Insert(f64, usize),
    /// Delete this many bytes here.
    Delete(f64, usize),
    /// XOR the byte here with a mask.
    Flip(f64, u8),
}

fn edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0.0..1.0f64, 0..NUMBERS.len()).prop_map(|(at, n)| Edit::Number(at, n)),
        (0.0..1.0f64, 0..TOKENS.len()).prop_map(|(at, n)| Edit::Insert(at, n)),
        (0.0..1.0f64, 1..64usize).prop_map(|(at, n)| Edit::Delete(at, n)),
        (0.0..1.0f64, 1..=255u8).prop_map(|(at, m)| Edit::Flip(at, m)),
    ]
}

fn position(bytes: &[u8], fraction: f64) -> usize {
    ((bytes.len() as f64) * fraction) as usize
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    match *edit {
        Edit::Number(fraction, n) => {
            let at = position(bytes, fraction);
            let is_part = |b: u8| b.is_ascii_alphanumeric() || b"+-.".contains(&b);
            let start = (0..at)
                .rev()
                .take_while(|&i| is_part(bytes[i]))
                .last()
                .unwrap_or(at);
            let end = (at..bytes.len())
                .find(|&i| !is_part(bytes[i]))
                .unwrap_or(bytes.len());
            bytes.splice(start..end, NUMBERS[n].bytes());
        }
        Edit::Insert(fraction, n) => {
            let at = position(bytes, fraction);
            bytes.splice(at..at, TOKENS[n].bytes());
        }
        Edit::Delete(fraction, n) => {
            let start = position(bytes, fraction);
            let end = (start + n).min(bytes.len());
            bytes.drain(start..end);
        }
        Edit::Flip(fraction, mask) => {
            let at = position(bytes, fraction);
            if let Some(byte) = bytes.get_mut(at) {
                *byte ^= mask;
            }
        }
    }
}

/// How a glTF seed keeps its binary buffer.
#[derive(Debug, Clone, Copy)]
enum Container {
    /// A base64 data URI in the JSON.
    Embedded,
    /// A `.bin` file beside the JSON (written to a temporary directory).
    External,
    /// The BIN chunk of a GLB file.
    Glb,
}

/// A glTF seed taken apart, so that its JSON values and binary bytes can be mutated
/// while the JSON stays well-formed and the GLB container consistent: these reach the
/// importer's checks of buffers, accessors, nodes and materials, past the parser.
struct GltfSeed {
    path: PathBuf,
    json: serde_json::Value,
    bin: Vec<u8>,
    container: Container,
}

fn gltf_seeds() -> Vec<GltfSeed> {
    use base64::Engine;
    let vase = manifest("scenes/models/vase.gltf");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&vase).expect("vase")).expect("json");
    let uri = json["buffers"][0]["uri"].as_str().expect("data uri");
    let bin = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',').expect("data uri").1)
        .expect("base64");
    let glb_path = manifest("tests/fixtures/models/trimesh_scene.glb");
    let glb = std::fs::read(&glb_path).expect("glb");
    let json_length = u32::from_le_bytes(glb[12..16].try_into().expect("4 bytes")) as usize;
    let glb_json = serde_json::from_slice(&glb[20..20 + json_length]).expect("glb json");
    let glb_bin = glb[20 + json_length + 8..].to_vec();
    let external = manifest("tests/fixtures/models/trimesh_scene.gltf");
    let (features_json, features_bin) = features_document();
    vec![
        GltfSeed {
            path: manifest("tests/fixtures/models/features.glb"),
            json: features_json,
            bin: features_bin,
            container: Container::Glb,
        },
        GltfSeed {
            path: vase,
            json,
            bin,
            container: Container::Embedded,
        },
        GltfSeed {
            path: glb_path,
            json: glb_json,
            bin: glb_bin,
            container: Container::Glb,
        },
        GltfSeed {
            json: serde_json::from_slice(&std::fs::read(&external).expect("gltf")).expect("json"),
            bin: std::fs::read(manifest("tests/fixtures/models/gltf_buffer.bin")).expect("bin"),
            path: external,
            container: Container::External,
        },
    ]
}

/// A document that uses every feature the importer reads, so that the structural
/// mutations reach the code for each: a node hierarchy of TRS and matrix transforms,
/// instancing, a strip, a fan and a sparse accessor, normals and normalized `u16` UVs,
/// textures from a data URI and from a buffer view with samplers, transmission, IOR and
/// emissive strength, three kinds of light and two cameras.
fn features_document() -> (serde_json::Value, Vec<u8>) {
    use base64::Engine;
    let png = |rgba: [u8; 4]| {
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::RgbaImage::from_pixel(2, 2, image::Rgba(rgba))
            .write_to(&mut bytes, image::ImageFormat::Png)
            .expect("png");
        bytes.into_inner()
    };
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}),
        );
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let square = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0]);
    let positions = view(&mut bin, &square);
    let normals = view(&mut bin, &f32s(&[0.0, 0.0, 1.0].repeat(4)));
    let uvs: Vec<u8> = [0u16, 0, 65535, 0, 0, 65535, 65535, 65535]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let uvs = view(&mut bin, &uvs);
    let strip: Vec<u8> = [0u8, 1, 2, 3].to_vec();
    let strip = view(&mut bin, &strip);
    let sparse_indices = view(&mut bin, &[3u8]);
    let sparse_values = view(&mut bin, &f32s(&[2.0, 2.0, 0.5]));
    let texture = view(&mut bin, &png([200, 100, 50, 255]));
    let data_png = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png([0, 128, 255, 255]))
    );
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength",
                           "KHR_materials_ior", "KHR_materials_transmission"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 100, "color": [1, 0.9, 0.8]},
            {"type": "spot", "intensity": 50, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 3}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 5]}],
        "nodes": [
            {"translation": [0, 1, 0], "rotation": [0, 0.38268343, 0, 0.9238795], "children": [1, 2, 3, 4]},
            {"mesh": 0, "scale": [2, 2, 2]},
            {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3, 0, 0, 1]},
            {"camera": 0, "translation": [0, 0, 5], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"mesh": 1, "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"camera": 1, "rotation": [-0.38268343, 0, 0, 0.9238795],
             "extensions": {"KHR_lights_punctual": {"light": 2}}}],
        "cameras": [
            {"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1, "zfar": 100}},
            {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "meshes": [
            {"name": "square", "primitives": [
                {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "mode": 5, "material": 0},
                {"attributes": {"POSITION": 4}, "mode": 6, "material": 1}]},
            {"name": "plain", "primitives": [{"attributes": {"POSITION": 0}, "mode": 4}]}],
        "materials": [
            {"name": "textured",
             "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.5, "roughnessFactor": 0.5,
                "baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}},
             "emissiveFactor": [0.1, 0.2, 0.3], "emissiveTexture": {"index": 0},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2}}},
            {"name": "glass", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                            "KHR_materials_ior": {"ior": 1.5}}}],
        "samplers": [{"wrapS": 33071, "wrapT": 33648}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
        "images": [{"bufferView": texture, "mimeType": "image/png"}, {"uri": data_png}],
        "accessors": [
            {"bufferView": positions, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": normals, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": uvs, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
            {"bufferView": strip, "componentType": 5121, "count": 4, "type": "SCALAR"},
            {"bufferView": positions, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [2, 2, 0.5],
             "sparse": {"count": 1, "indices": {"bufferView": sparse_indices, "componentType": 5121},
                        "values": {"bufferView": sparse_values}}}],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    (json, bin)
}

/// A (mutated) glTF seed put back together: the path to parse it as, its bytes, and
/// the temporary directory that holds its external buffer, if any.
fn assemble(seed: &GltfSeed) -> (PathBuf, Vec<u8>, Option<tempfile::TempDir>) {
    use base64::Engine;
    let mut json = seed.json.clone();
    match seed.container {
        Container::Embedded => {
            let uri = format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&seed.bin)
            );
            if let Some(buffer) = json.pointer_mut("/buffers/0") {
                buffer["uri"] = uri.into();
            }
            let text = serde_json::to_vec(&json).expect("serialise");
            (seed.path.clone(), text, None)
        }
        Container::External => {
            let dir = tempfile::tempdir().expect("temporary directory");
            std::fs::write(dir.path().join("gltf_buffer.bin"), &seed.bin).expect("bin");
            let text = serde_json::to_vec(&json).expect("serialise");
            (dir.path().join("scene.gltf"), text, Some(dir))
        }
        Container::Glb => {
            let mut text = serde_json::to_vec(&json).expect("serialise");
            while !text.len().is_multiple_of(4) {
                text.push(b' ');
            }
            let mut bin = seed.bin.clone();
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            let mut glb = b"glTF".to_vec();
            glb.extend_from_slice(&2u32.to_le_bytes());
            glb.extend_from_slice(&((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
            glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
            glb.extend_from_slice(b"JSON");
            glb.extend_from_slice(&text);
            glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            glb.extend_from_slice(b"BIN\0");
            glb.extend_from_slice(&bin);
            (seed.path.clone(), glb, None)
        }
    }
}

/// Imports a (mutated) glTF seed through [`check_model_bytes`].
fn check_gltf_seed(seed: &GltfSeed) {
    let (path, bytes, _dir) = assemble(seed);
    check_model_bytes(&path, &bytes);
}

/// JSON numbers that stay valid JSON: edges of glTF's integer and f32 ranges.
const JSON_NUMBERS: &[f64] = &[
    -1.0,
    0.0,
    0.5,
    1.0,
    2.0,
    3.0,
    5.0,
    6.0,
    7.0,
    255.0,
    5121.0,
    5123.0,
    5125.0,
    5126.0,
    65535.0,
    4294967295.0,
    4294967296.0,
    9007199254740992.0,
    1e39,
    -1e39,
    1e-45,
];

/// One structure-aware edit of a glTF seed.
#[derive(Debug, Clone)]
enum GltfEdit {
    /// Replace the number at this fraction of all the JSON's numbers.
    Number(f64, usize),
    /// Remove the member or element at this fraction of all of them.
    Remove(f64),
    /// Write a special `f32` (NaN, ±infinity, huge) at this fraction of the buffer.
    Float(f64, usize),
    /// XOR a buffer byte with a mask.
    Flip(f64, u8),
    /// Cut the buffer at this fraction.
    Truncate(f64),
}

fn gltf_edit_strategy() -> impl Strategy<Value = GltfEdit> {
    prop_oneof![
        3 => (0.0..1.0f64, 0..JSON_NUMBERS.len()).prop_map(|(at, n)| GltfEdit::Number(at, n)),
        2 => (0.0..1.0f64).prop_map(GltfEdit::Remove),
        2 => (0.0..1.0f64, 0..4usize).prop_map(|(at, n)| GltfEdit::Float(at, n)),
        1 => (0.0..1.0f64, 1..=255u8).prop_map(|(at, m)| GltfEdit::Flip(at, m)),
        1 => (0.0..1.0f64).prop_map(GltfEdit::Truncate),
    ]
}

/// JSON pointers to every number (`numbers`) or every member and element (`all`).
fn pointers(value: &serde_json::Value, at: String, numbers: bool, out: &mut Vec<String>) {
    let children: Vec<(String, &serde_json::Value)> = match value {
        serde_json::Value::Object(map) => map
            .iter()
            .map(|(k, v)| {
                (
                    format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")),
                    v,
                )
            })
            .collect(),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(i, v)| (format!("{at}/{i}"), v))
            .collect(),
        _ => Vec::new(),
    };
    for (pointer, child) in children {
        if !numbers || child.is_number() {
            out.push(pointer.clone());
        }
        // The base64 data URI is not worth descending into or counting twice.
        pointers(child, pointer, numbers, out);
    }
}

fn apply_gltf(seed: &mut GltfSeed, edit: &GltfEdit) {
    let pick = |list: &[String], fraction: f64| -> Option<String> {
        list.get(((list.len() as f64) * fraction) as usize).cloned()
    };
    match *edit {
        GltfEdit::Number(fraction, n) => {
            let mut list = Vec::new();
            pointers(&seed.json, String::new(), true, &mut list);
            if let Some(pointer) = pick(&list, fraction)
                && let Some(slot) = seed.json.pointer_mut(&pointer)
            {
                let value = JSON_NUMBERS[n];
                *slot = if value.fract() == 0.0 && value.abs() < 1e19 {
                    serde_json::json!(value as i64)
                } else {
                    serde_json::json!(value)
                };
            }
        }
        GltfEdit::Remove(fraction) => {
            let mut list = Vec::new();
            pointers(&seed.json, String::new(), false, &mut list);
            if let Some(pointer) = pick(&list, fraction)
                && let Some((parent, key)) = pointer.rsplit_once('/')
                && let Some(container) = seed.json.pointer_mut(parent)
            {
                match container {
                    serde_json::Value::Object(map) => {
                        map.remove(&key.replace("~1", "/").replace("~0", "~"));
                    }
                    serde_json::Value::Array(items) => {
                        if let Ok(i) = key.parse::<usize>()
                            && i < items.len()
                        {
                            items.remove(i);
                        }
                    }
                    _ => {}
                }
            }
        }
        GltfEdit::Float(fraction, n) => {
            let value = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 3.0e38][n];
            let at = position(&seed.bin, fraction) & !3;
            if at + 4 <= seed.bin.len() {
                seed.bin[at..at + 4].copy_from_slice(&value.to_le_bytes());
            }
        }
        GltfEdit::Flip(fraction, mask) => {
            let at = position(&seed.bin, fraction);
            if let Some(byte) = seed.bin.get_mut(at) {
                *byte ^= mask;
            }
        }
        GltfEdit::Truncate(fraction) => {
            let at = position(&seed.bin, fraction);
            seed.bin.truncate(at);
        }
    }
}

fn config() -> Config {
    Config {
        cases: 160,
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_models_never_panic(
        seed in 0..4usize,
        edits in prop::collection::vec(edit_strategy(), 1..6),
    ) {
        let (path, mut bytes) = seeds().swap_remove(seed);
        for edit in &edits {
            apply(&mut bytes, edit);
        }
        check_model_bytes(&path, &bytes);
    }

    #[test]
    fn gltf_with_mutated_values_and_buffers_never_panics(
        seed in 0..4usize,
        edits in prop::collection::vec(gltf_edit_strategy(), 1..5),
    ) {
        let mut seed = gltf_seeds().swap_remove(seed);
        for edit in &edits {
            apply_gltf(&mut seed, edit);
        }
        check_gltf_seed(&seed);
    }

    #[test]
    fn truncated_models_never_panic(seed in 0..4usize, fraction in 0.0..1.0f64) {
        let (path, bytes) = seeds().swap_remove(seed);
        check_model_bytes(&path, &bytes[..position(&bytes, fraction)]);
    }

    #[test]
    fn arbitrary_bytes_never_panic(
        seed in 0..4usize,
        bytes in prop::collection::vec(any::<u8>(), 0..400),
    ) {
        let (path, _) = seeds().swap_remove(seed);
        check_model_bytes(&path, &bytes);
    }
}

/// The unmutated seeds import and render through the same check, so that the check is
/// not vacuous; the glTF seeds also after being taken apart and put back together.
#[test]
fn seed_models_import_and_render_through_the_check() {
    for (path, bytes) in seeds() {
        let model = import(&path, &bytes).unwrap_or_else(|e| panic!("{e}"));
        assert!(model.world_triangle_count() > 0);
        check_model(&model);
    }
    for seed in gltf_seeds() {
        check_gltf_seed(&seed);
    }
    // The feature seed imports whole, with each feature it is there for.
    let (path, bytes, _dir) = assemble(&gltf_seeds()[0]);
    let model = import(&path, &bytes).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(model.meshes.len(), 3);
    assert_eq!(model.meshes[0].instances.len(), 2);
    assert!(model.meshes[0].uvs.is_some() && model.meshes[0].normals.is_some());
    assert_eq!(
        model.meshes[1].positions[3],
        glam::DVec3::new(2.0, 2.0, 0.5),
        "sparse"
    );
    assert_eq!(model.lights.len(), 3);
    assert!(model.camera.is_some());
    assert_eq!(model.images.len(), 2);
    let kinds: Vec<MaterialKind> = model.materials.iter().map(|m| m.material.kind).collect();
    assert!(kinds.contains(&MaterialKind::Dielectric) && kinds.contains(&MaterialKind::Pbr));
}
