//! The glTF 2.0 importer against small documents built here with known answers (node
//! transforms, instancing, strips and fans, the three kinds of buffers, cameras, lights,
//! materials and textures), the round trip through a file written by Python's trimesh,
//! the shipped vase, and every kind of bad input (each a clear error naming the file and
//! the element, never a panic).

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::{DMat4, DQuat, DVec2, DVec3, DVec4};
use gpu_render::low_level::camera::CameraFrame;
use gpu_render::low_level::color::srgb_decode;
use gpu_render::scene::import::{
    ImportedModel, LUMENS_PER_WATT, WrapMode, import_gltf, import_model, parse_gltf,
};
use gpu_render::scene::{AlphaMode, Light, MaterialKind, TextureTransform};

use crate::support::compare::max_channel_difference;
use crate::support::models::{assert_tangents, material_named, small_scene};

/// A glTF document under construction: one binary buffer and its views and accessors.
#[derive(Default)]
struct Doc {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl Doc {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn accessor(&mut self, json: String) -> usize {
        self.accessors.push(json);
        self.accessors.len() - 1
    }

    fn vec3(&mut self, data: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        self.accessor(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC3"}}"#,
            data.len()
        ))
    }

    fn vec4(&mut self, data: &[[f32; 4]]) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        self.accessor(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC4"}}"#,
            data.len()
        ))
    }

    fn vec2(&mut self, data: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        self.accessor(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC2"}}"#,
            data.len()
        ))
    }

    /// An accessor of integer components (`component_type` 5120 byte, 5121 unsigned
    /// byte, 5122 short, 5123 unsigned short), each element padded to 4 bytes as glTF
    /// 2.0 §3.6.2.4 requires of vertex attributes.
    fn integers(
        &mut self,
        type_: &str,
        component_type: u32,
        normalized: bool,
        elements: &[Vec<i32>],
    ) -> usize {
        let size = if component_type <= 5121 { 1 } else { 2 };
        let components = elements.first().map_or(1, Vec::len);
        let stride = (components * size).next_multiple_of(4);
        let mut bytes = Vec::new();
        for element in elements {
            for &c in element {
                if size == 1 {
                    bytes.push(c as u8);
                } else {
                    bytes.extend_from_slice(&(c as u16).to_le_bytes());
                }
            }
            bytes.resize(bytes.len().next_multiple_of(4), 0);
        }
        let view = self.view(&bytes);
        self.views[view] = self.views[view].replace('}', &format!(r#","byteStride":{stride}}}"#));
        self.accessor(format!(
            r#"{{"bufferView":{view},"componentType":{component_type},"normalized":{normalized},"count":{},"type":"{type_}"}}"#,
            elements.len()
        ))
    }

    fn indices(&mut self, data: &[u16]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(format!(
            r#"{{"bufferView":{view},"componentType":5123,"count":{},"type":"SCALAR"}}"#,
            data.len()
        ))
    }

    /// The JSON text with `body` (the other top-level properties) and a buffer whose
    /// `uri` is `uri` (none: the GLB binary chunk).
    fn json(&self, body: &str, uri: Option<&str>) -> String {
        let uri = uri.map_or(String::new(), |u| format!(r#","uri":"{u}""#));
        format!(
            r#"{{"asset":{{"version":"2.0"}},{body},"bufferViews":[{}],"accessors":[{}],"buffers":[{{"byteLength":{}{uri}}}]}}"#,
            self.views.join(","),
            self.accessors.join(","),
            self.bin.len()
        )
    }

    fn data_uri(&self) -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        )
    }

    fn embedded(&self, body: &str) -> String {
        self.json(body, Some(&self.data_uri()))
    }

    /// A binary glTF (GLB) container: header, JSON chunk, BIN chunk (glTF 2.0 §4.4).
    fn glb(&self, body: &str) -> Vec<u8> {
        let mut json = self.json(body, None).into_bytes();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// A unit right triangle in the z = 0 plane, with indices, as mesh 0 ('tri'), and the
/// document built so far.
fn triangle_doc() -> (Doc, String) {
    let mut doc = Doc::default();
    let positions = doc.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let indices = doc.indices(&[0, 1, 2]);
    let meshes = format!(
        r#""meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":{positions}}},"indices":{indices}}}]}}]"#
    );
    (doc, meshes)
}

/// Writes `files` into a fresh directory and imports the first.
fn import(files: &[(&str, &[u8])]) -> (tempfile::TempDir, Result<ImportedModel, String>) {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).expect("write fixture");
    }
    let result = import_gltf(&dir.path().join(files[0].0)).map_err(|e| e.to_string());
    (dir, result)
}

fn imported(name: &str, bytes: &[u8]) -> ImportedModel {
    let (_dir, result) = import(&[(name, bytes)]);
    result.unwrap_or_else(|e| panic!("import failed: {e}"))
}

fn failure(name: &str, bytes: &[u8]) -> String {
    let (_dir, result) = import(&[(name, bytes)]);
    result.expect_err("the import succeeded")
}

fn assert_close(a: DVec3, b: DVec3, tolerance: f64) {
    assert!((a - b).length() <= tolerance, "{a} vs {b}");
}

#[test]
fn a_transformed_node_s_triangle_lands_where_the_matrices_say() {
    let (doc, meshes) = triangle_doc();
    // Parent: translate (1, 2, 3) · rotate 90° about z · scale 2; child: a matrix
    // (column-major) translating by (0, 0, -1).
    let body = format!(
        r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[
            {{"translation":[1,2,3],"rotation":[0,0,0.70710677,0.70710677],"scale":[2,2,2],"children":[1]}},
            {{"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-1,1],"mesh":0}}],{meshes}"#
    );
    let model = imported("node.gltf", doc.embedded(&body).as_bytes());
    let world: Vec<_> = model.world_triangles().collect();
    assert_eq!(world.len(), 1);
    // By hand: (x, y, z) → (x, y, z - 1) → ×2 → rotate 90° about z: (-y, x, z) → + (1, 2, 3).
    let expected = [
        DVec3::new(1.0, 2.0, 1.0),
        DVec3::new(1.0, 4.0, 1.0),
        DVec3::new(-1.0, 2.0, 1.0),
    ];
    for (got, want) in world[0].vertices.iter().zip(expected) {
        assert_close(*got, want, 1e-6);
    }
    // And exactly the composed matrices of the file's f32 values.
    let q = DQuat::from_xyzw(
        0.0,
        0.0,
        f64::from(0.707_106_77f32),
        f64::from(0.707_106_77f32),
    );
    let parent = DMat4::from_scale_rotation_translation(
        DVec3::splat(2.0),
        q.normalize(),
        DVec3::new(1.0, 2.0, 3.0),
    );
    let child = DMat4::from_translation(DVec3::new(0.0, 0.0, -1.0));
    let instance = model.meshes[0].instances[0];
    assert!(instance.abs_diff_eq(parent * child, 1e-12), "{instance}");
}

#[test]
fn a_matrix_beside_identity_trs_or_with_rounding_in_its_last_row_is_accepted() {
    let (doc, meshes) = triangle_doc();
    // Identity translation/rotation/scale beside a matrix change nothing, whichever a
    // reader applies; a last row off by 1e-8 is rounding, and is made exact.
    let body = format!(
        r#""scenes":[{{"nodes":[0,1]}}],"nodes":[
            {{"mesh":0,"matrix":[2,0,0,0, 0,2,0,0, 0,0,2,0, 1,2,3,1],"translation":[0,0,0],"rotation":[0,0,0,1],"scale":[1,1,1]}},
            {{"mesh":0,"matrix":[1,0,0,1e-8, 0,1,0,0, 0,0,1,0, 0,0,0,1.00000001]}}],{meshes}"#
    );
    let model = imported("matrix.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let instances = &model.meshes[0].instances;
    assert_eq!(
        instances[0],
        DMat4::from_scale_rotation_translation(
            DVec3::splat(2.0),
            DQuat::IDENTITY,
            DVec3::new(1.0, 2.0, 3.0)
        )
    );
    assert_eq!(instances[1], DMat4::IDENTITY);
}

#[test]
fn a_mesh_under_two_nodes_is_stored_once_with_two_instances() {
    let (doc, meshes) = triangle_doc();
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[
            {{"children":[1,2]}},
            {{"mesh":0,"translation":[-5,0,0]}},
            {{"mesh":0,"translation":[5,0,0]}}],{meshes}"#
    );
    let model = imported("twice.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes.len(), 1);
    assert_eq!(model.meshes[0].instances.len(), 2);
    assert_eq!(model.world_triangle_count(), 2);
    let world: Vec<_> = model.world_triangles().collect();
    assert_eq!(world[0].vertices[0], DVec3::new(-5.0, 0.0, 0.0));
    assert_eq!(world[1].vertices[0], DVec3::new(5.0, 0.0, 0.0));
    let (low, high) = model.bounds().expect("bounds");
    assert_eq!(
        (low, high),
        (DVec3::new(-5.0, 0.0, 0.0), DVec3::new(6.0, 1.0, 0.0))
    );
}

#[test]
fn strips_and_fans_become_triangles_and_indices_are_optional() {
    let mut doc = Doc::default();
    let square = doc.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let strip = doc.indices(&[0, 1, 2, 3]);
    let fan = doc.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]);
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[
            {{"attributes":{{"POSITION":{square}}},"indices":{strip},"mode":5}},
            {{"attributes":{{"POSITION":{fan}}},"mode":6}},
            {{"attributes":{{"POSITION":{square}}},"mode":4}}]}}]"#
    );
    let model = imported("modes.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes.len(), 3);
    assert_eq!(model.meshes[0].triangles, vec![[0, 1, 2], [1, 3, 2]]);
    assert_eq!(model.meshes[1].triangles, vec![[1, 2, 0], [2, 3, 0]]);
    // A list of 4 vertices: one triangle and a warning about the one left over.
    assert_eq!(model.meshes[2].triangles, vec![[0, 1, 2]]);
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("not a multiple of 3"))
    );
    // Every strip and fan triangle faces +z, as the square's vertices are ordered.
    for triangle in model.world_triangles() {
        let [a, b, c] = triangle.vertices;
        assert!((b - a).cross(c - a).z > 0.0, "{triangle:?}");
    }
    assert_eq!(model.meshes[0].name, "mesh 0, primitive 0");
}

/// The value of a normalized integer as glTF 2.0 §3.11 and `KHR_mesh_quantization`
/// decode it.
fn dequantize(component_type: u32, normalized: bool, c: i32) -> f64 {
    let c = f64::from(c);
    match (component_type, normalized) {
        (_, false) => c,
        (5120, true) => (c / 127.0).max(-1.0),
        (5121, true) => c / 255.0,
        (5122, true) => (c / 32767.0).max(-1.0),
        (_, true) => c / 65535.0,
    }
}

#[test]
fn quantized_attributes_import_as_their_float_twins() {
    // One triangle per POSITION component type (KHR_mesh_quantization's table), each
    // with quantized normals and texture coordinates; the twin holds the same values as
    // floats.
    let mut quantized = Doc::default();
    let mut float = Doc::default();
    let mut primitives_q = Vec::new();
    let mut primitives_f = Vec::new();
    let kinds = [
        (5120, false),
        (5120, true),
        (5121, false),
        (5121, true),
        (5122, false),
        (5122, true),
        (5123, false),
        (5123, true),
    ];
    for (k, &(position_type, position_normalized)) in kinds.iter().enumerate() {
        let signed = position_type == 5120 || position_type == 5122;
        let big = if position_type <= 5121 { 100 } else { 30000 };
        let low = if signed { -big } else { 0 };
        let positions = vec![vec![low, low, 0], vec![big, low, 0], vec![low, big, 1]];
        // Normals: normalized signed bytes or shorts only, -128 and -32768 included
        // (they clamp to -1).
        let (normal_type, unit, below) = if k % 2 == 0 {
            (5120, 127, -128)
        } else {
            (5122, 32767, -32768)
        };
        let normals = vec![vec![0, 0, unit], vec![0, below, unit], vec![unit, 0, unit]];
        // Texture coordinates: every type, normalized or not, in turn.
        let (uv_type, uv_normalized) = kinds[(k + 3) % kinds.len()];
        let uv_big = if uv_type <= 5121 { 127 } else { 32767 };
        let uv_low = if uv_type == 5120 || uv_type == 5122 {
            -uv_big
        } else {
            0
        };
        let uvs = vec![vec![uv_low, 0], vec![uv_big, 1], vec![0, uv_big]];
        let p = quantized.integers("VEC3", position_type, position_normalized, &positions);
        let n = quantized.integers("VEC3", normal_type, true, &normals);
        let t = quantized.integers("VEC2", uv_type, uv_normalized, &uvs);
        primitives_q.push(format!(
            r#"{{"attributes":{{"POSITION":{p},"NORMAL":{n},"TEXCOORD_0":{t}}}}}"#
        ));
        let as_f32 = |elements: &[Vec<i32>], ty: u32, normalized: bool| -> Vec<Vec<f32>> {
            elements
                .iter()
                .map(|e| {
                    e.iter()
                        .map(|&c| dequantize(ty, normalized, c) as f32)
                        .collect()
                })
                .collect()
        };
        let vec3 =
            |v: Vec<Vec<f32>>| -> Vec<[f32; 3]> { v.iter().map(|e| [e[0], e[1], e[2]]).collect() };
        let p = float.vec3(&vec3(as_f32(
            &positions,
            position_type,
            position_normalized,
        )));
        let n = float.vec3(&vec3(as_f32(&normals, normal_type, true)));
        let t = float.vec2(
            &as_f32(&uvs, uv_type, uv_normalized)
                .iter()
                .map(|e| [e[0], e[1]])
                .collect::<Vec<_>>(),
        );
        primitives_f.push(format!(
            r#"{{"attributes":{{"POSITION":{p},"NORMAL":{n},"TEXCOORD_0":{t}}}}}"#
        ));
    }
    let body = |primitives: &[String]| {
        format!(
            r#""extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],
               "scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"scale":[0.01,0.01,0.01]}}],
               "meshes":[{{"primitives":[{}]}}]"#,
            primitives.join(",")
        )
    };
    let q = imported(
        "quantized.gltf",
        quantized.embedded(&body(&primitives_q)).as_bytes(),
    );
    let f = imported(
        "float.gltf",
        float.embedded(&body(&primitives_f)).as_bytes(),
    );
    assert!(q.warnings.is_empty(), "{:?}", q.warnings);
    assert_eq!(q.meshes.len(), kinds.len());
    assert_eq!(q.meshes.len(), f.meshes.len());
    for (mq, mf) in q.meshes.iter().zip(&f.meshes) {
        assert_eq!(mq.triangles, mf.triangles, "{}", mq.name);
        assert_eq!(mq.instances, mf.instances, "{}", mq.name);
        for (a, b) in mq.positions.iter().zip(&mf.positions) {
            assert_close(*a, *b, 1e-7 * b.length().max(1.0));
        }
        let (nq, nf) = (
            mq.normals.as_ref().expect("normals"),
            mf.normals.as_ref().expect("normals"),
        );
        for (a, b) in nq.iter().zip(nf) {
            assert_close(*a, *b, 1e-7);
        }
        let (uq, uf) = (mq.uvs.as_ref().expect("uvs"), mf.uvs.as_ref().expect("uvs"));
        for (a, b) in uq.iter().zip(uf) {
            assert!(
                (*a - *b).length() <= 1e-7 * b.length().max(1.0),
                "{a} vs {b}"
            );
        }
    }
    // Exactly the specification's formulas: 32767 short → 1, -32768 → -1 (clamped),
    // 65535 unsigned short → 1, -128 byte → -1.
    let short_normalized = &q.meshes[5];
    assert_eq!(
        short_normalized.positions[0],
        DVec3::new(-30000.0 / 32767.0, -30000.0 / 32767.0, 0.0)
    );
    assert_eq!(short_normalized.positions[2].z, 1.0 / 32767.0);
    let normals = q.meshes[1].normals.as_ref().expect("normals");
    assert_eq!(normals[0], DVec3::Z);
    assert_eq!(normals[1], DVec3::new(0.0, -1.0, 1.0).normalize());
    let normals = q.meshes[0].normals.as_ref().expect("normals");
    assert_eq!(normals[1], DVec3::new(0.0, -1.0, 1.0).normalize());
    let uvs = q.meshes[2].uvs.as_ref().expect("uvs");
    assert_eq!(uvs[1].x, 32767.0 / 32767.0, "normalized short");
    let uvs = q.meshes[1].uvs.as_ref().expect("uvs");
    assert_eq!(
        (uvs[0].x, uvs[1].x),
        (-32767.0, 32767.0),
        "short, not normalized"
    );

    // Without the extension listed, the values are read with one warning.
    let unlisted = body(&primitives_q).replace(
        r#""extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],"#,
        "",
    );
    let model = imported("unlisted.gltf", quantized.embedded(&unlisted).as_bytes());
    assert_eq!(model.meshes, q.meshes);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("unlisted.gltf: mesh 0, primitive 0: POSITION (accessor 0) holds I8 components, which only KHR_mesh_quantization allows"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn points_and_lines_are_skipped_with_one_warning() {
    let mut doc = Doc::default();
    let square = doc.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let body = format!(
        r#""scenes":[{{"nodes":[0,1]}}],"nodes":[{{"mesh":0}},{{"mesh":1}}],"meshes":[
            {{"name":"guides","primitives":[
              {{"attributes":{{"POSITION":{square}}},"mode":0}},
              {{"attributes":{{"POSITION":{square}}},"mode":3}}]}},
            {{"primitives":[
              {{"attributes":{{"POSITION":{square}}},"mode":2}},
              {{"attributes":{{"POSITION":{square}}},"mode":5}}]}}]"#
    );
    let model = imported("mixed.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes.len(), 1);
    assert_eq!(model.meshes[0].name, "mesh 1, primitive 1");
    assert_eq!(model.meshes[0].triangles.len(), 2);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].ends_with(
            "mixed.gltf: skipped 3 primitives of points or lines, which are not rendered: mesh 0 ('guides'), primitive 0: POINTS (0); mesh 0 ('guides'), primitive 1: LINE_STRIP (3); mesh 1, primitive 0: LINE_LOOP (2)"
        ),
        "{:?}",
        model.warnings
    );
    // Without the strip, nothing is left to render.
    let body = body.replace(r#""mode":5"#, r#""mode":1"#);
    let message = failure("lines.gltf", doc.embedded(&body).as_bytes());
    assert!(
        message.contains("lines.gltf: no triangles: the primitives it places are points or lines, which are not rendered (mesh 0 ('guides'), primitive 0: POINTS (0); mesh 0 ('guides'), primitive 1: LINE_STRIP (3); mesh 1, primitive 0: LINE_LOOP (2); mesh 1, primitive 1: LINES (1))"),
        "{message}"
    );
}

#[test]
fn vertex_colours_are_read_and_further_sets_named_in_one_warning() {
    let (mut doc, _) = triangle_doc();
    let rgb = doc.integers(
        "VEC3",
        5121,
        true,
        &[vec![255, 0, 0], vec![0, 255, 0], vec![0, 0, 255]],
    );
    let body = format!(
        r#""scenes":[{{"nodes":[0,1]}}],"nodes":[{{"mesh":0}},{{"mesh":0,"translation":[2,0,0]}}],
           "meshes":[{{"name":"painted","primitives":[
              {{"attributes":{{"POSITION":0,"COLOR_0":{rgb}}},"indices":1}},
              {{"attributes":{{"POSITION":0}},"indices":1}},
              {{"attributes":{{"POSITION":0,"COLOR_0":{rgb},"COLOR_1":{rgb}}},"indices":1}}]}}]"#
    );
    let model = imported("colours.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes.len(), 3);
    // Normalized bytes read as [0, 1], linear (glTF 2.0 §3.7.2.1); VEC3 is opaque.
    let primaries = Some(vec![
        DVec4::new(1.0, 0.0, 0.0, 1.0),
        DVec4::new(0.0, 1.0, 0.0, 1.0),
        DVec4::new(0.0, 0.0, 1.0, 1.0),
    ]);
    assert_eq!(model.meshes[0].colors, primaries);
    assert_eq!(model.meshes[1].colors, None);
    assert_eq!(model.meshes[2].colors, primaries);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].ends_with(
            "colours.gltf: only COLOR_0 multiplies the base colour; further vertex colour sets are ignored (mesh 0 ('painted'), primitive 2: COLOR_1)"
        ),
        "{:?}",
        model.warnings
    );
}

#[test]
fn float_and_short_vertex_colours_read_with_alpha_and_range_warned_about() {
    let (mut doc, _) = triangle_doc();
    // VEC4 floats: one out of range (clamped), one alpha below 1 (kept: it multiplies
    // the base colour's alpha).
    let rgba = doc.vec4(&[
        [0.25, 0.5, 0.75, 1.0],
        [2.0, 0.0, 0.0, 0.5],
        [0.0, 0.0, 1.0, 1.0],
    ]);
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"COLOR_0":{rgba}}},"indices":1}}]}}]"#
    );
    let model = imported("rgba.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(
        model.meshes[0].colors,
        Some(vec![
            DVec4::new(0.25, 0.5, 0.75, 1.0),
            DVec4::new(1.0, 0.0, 0.0, 0.5),
            DVec4::new(0.0, 0.0, 1.0, 1.0)
        ])
    );
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings.iter().any(|w| w.ends_with(
            "rgba.gltf: mesh 0, primitive 0: 1 vertex colour outside [0, 1] (the first at vertex 1: [2, 0, 0, 0.5]); clamped"
        )),
        "{:?}",
        model.warnings
    );

    // Unnormalized shorts are not colours: left out, with a warning, the model renders.
    let (mut doc, _) = triangle_doc();
    let rgb = doc.integers(
        "VEC3",
        5123,
        false,
        &[vec![1, 0, 0], vec![0, 1, 0], vec![0, 0, 1]],
    );
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"COLOR_0":{rgb}}},"indices":1}}]}}]"#
    );
    let model = imported("shorts.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes[0].colors, None);
    assert!(
        model.warnings[0].contains("COLOR_0 (accessor")
            && model.warnings[0].ends_with("; the vertex colours are ignored"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn application_specific_attributes_are_not_read() {
    // glTF 2.0 §3.7.2.1: attribute names that start with `_` are the application's own
    // (Cesium's `_BATCHID`, `_FEATURE_ID_0`).
    let (doc, meshes) = triangle_doc();
    let body = format!(r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],{meshes}"#)
        .replace(r#""POSITION":0"#, r#""POSITION":0,"_BATCHID":0"#);
    let model = imported("batched.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.meshes[0].triangles.len(), 1);
}

#[test]
fn embedded_external_and_glb_buffers_give_the_same_model() {
    let mut doc = Doc::default();
    let positions = doc.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let normals = doc.vec3(&[[0.0, 0.0, 1.0]; 3]);
    let uvs = doc.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"translation":[0,0,-2]}}],
           "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{positions},"NORMAL":{normals},"TEXCOORD_0":{uvs}}}}}]}}]"#
    );
    let embedded = imported("embedded.gltf", doc.embedded(&body).as_bytes());
    let (_dir, external) = import(&[
        (
            "external.gltf",
            doc.json(&body, Some("data%20file.bin")).as_bytes(),
        ),
        ("data file.bin", &doc.bin),
    ]);
    let external = external.expect("external buffer");
    let glb = imported("binary.glb", &doc.glb(&body));
    assert_eq!(embedded.meshes, external.meshes);
    assert_eq!(embedded.meshes, glb.meshes);
    let mesh = &embedded.meshes[0];
    assert_eq!(mesh.normals.as_deref(), Some(&[DVec3::Z; 3][..]));
    assert_eq!(mesh.uvs.as_ref().map(|u| u[1].x), Some(1.0));
    // A byte-order mark before the JSON is tolerated.
    let bom = [b"\xEF\xBB\xBF".as_slice(), doc.embedded(&body).as_bytes()].concat();
    assert_eq!(imported("bom.gltf", &bom).meshes, embedded.meshes);
    // A .glb by content, whatever its name.
    let renamed = imported("binary.gltf", &doc.glb(&body));
    assert_eq!(renamed.meshes, glb.meshes);
}

#[test]
fn a_gltf_camera_reproduces_a_known_view() {
    // At (0, 2, 2), turned 45° down about x: it looks at the origin along (0, -1, -1).
    let (doc, meshes) = triangle_doc();
    let s = (-22.5f64).to_radians().sin();
    let c = (-22.5f64).to_radians().cos();
    let body = format!(
        r#""scenes":[{{"nodes":[0,1]}}],"nodes":[{{"mesh":0}},
            {{"camera":0,"translation":[0,2,2],"rotation":[{s},0,0,{c}]}}],
           "cameras":[{{"name":"view","type":"perspective","perspective":{{"yfov":0.5,"aspectRatio":1.5,"znear":0.1}}}}],{meshes}"#
    );
    let model = imported("camera.gltf", doc.embedded(&body).as_bytes());
    let imported = model.camera.as_ref().expect("a camera");
    assert_eq!(imported.name, "view");
    assert_eq!(imported.aspect_ratio, Some(1.5));
    let camera = imported.camera;
    assert_close(camera.eye, DVec3::new(0.0, 2.0, 2.0), 1e-6);
    assert!((camera.fov_y_degrees - 0.5f64.to_degrees()).abs() < 1e-5);
    let frame = CameraFrame::new(&camera, 300, 200);
    // The centre of the image looks at the origin...
    let centre = frame.ray_direction(150.0, 100.0, 300, 200);
    assert_close(centre, -camera.eye.normalize(), 1e-6);
    // ... with +y up on screen (the top edge's centre is higher in the world) ...
    let top = frame.ray_direction(150.0, 0.0, 300, 200);
    assert!(top.y > centre.y);
    // ... and the top edge is yfov / 2 away from the centre.
    assert!((top.angle_between(centre) - 0.25).abs() < 1e-6);
    assert_eq!(model.camera_or_default(2.0), camera);
}

#[test]
fn punctual_lights_convert_to_our_units() {
    let (doc, meshes) = triangle_doc();
    let s = (-45f64).to_radians().sin();
    let c = (-45f64).to_radians().cos();
    let body = format!(
        r#""extensionsUsed":["KHR_lights_punctual"],
           "extensions":{{"KHR_lights_punctual":{{"lights":[
              {{"type":"point","intensity":683,"color":[1,0.5,0.25]}},
              {{"type":"directional","intensity":1366}},
              {{"type":"spot","intensity":68.3,"range":10,"spot":{{"outerConeAngle":0.5}}}}]}}}},
           "scenes":[{{"nodes":[0,1,2,3]}}],"nodes":[{{"mesh":0}},
            {{"translation":[1,2,3],"extensions":{{"KHR_lights_punctual":{{"light":0}}}}}},
            {{"rotation":[{s},0,0,{c}],"extensions":{{"KHR_lights_punctual":{{"light":1}}}}}},
            {{"translation":[0,5,0],"extensions":{{"KHR_lights_punctual":{{"light":2}}}}}}],{meshes}"#
    );
    let model = imported("lights.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.lights.len(), 3);
    let Light::Point {
        position,
        intensity,
    } = model.lights[0]
    else {
        panic!("not a point light: {:?}", model.lights[0]);
    };
    assert_eq!(position, DVec3::new(1.0, 2.0, 3.0));
    assert_close(intensity, DVec3::new(1.0, 0.5, 0.25), 1e-12);
    let Light::Directional {
        direction,
        irradiance,
    } = model.lights[1]
    else {
        panic!("not directional: {:?}", model.lights[1]);
    };
    // -z turned -90° about x points down.
    assert_close(direction, DVec3::new(0.0, -1.0, 0.0), 1e-6);
    assert_close(irradiance, DVec3::splat(1366.0 / LUMENS_PER_WATT), 1e-12);
    // A spot light along the node's -z, its cone from the angles (inner defaults to 0).
    let Light::Spot {
        position,
        direction,
        intensity,
        cos_inner,
        cos_outer,
    } = model.lights[2]
    else {
        panic!("not a spot light: {:?}", model.lights[2]);
    };
    assert_eq!(position, DVec3::new(0.0, 5.0, 0.0));
    assert_eq!(direction, DVec3::NEG_Z);
    assert_close(intensity, DVec3::splat(0.1), 1e-7);
    assert_eq!(cos_inner, 1.0);
    assert_eq!(cos_outer, f64::from(0.5f32).cos());
    let warnings = model.warnings.join("\n");
    assert!(!warnings.contains("spot"), "{warnings}");
    assert!(warnings.contains("light 2: range is ignored"), "{warnings}");
    assert_eq!(model.lights_or_default(), model.lights);

    // Cones out of order or beyond a right angle: located errors.
    for (cone, angles) in [
        (
            r#"{"innerConeAngle":0.6,"outerConeAngle":0.5}"#,
            "innerConeAngle 0.6 and outerConeAngle 0.5",
        ),
        (
            r#"{"innerConeAngle":0.5,"outerConeAngle":0.5}"#,
            "innerConeAngle 0.5 and outerConeAngle 0.5",
        ),
        (
            r#"{"outerConeAngle":2}"#,
            "innerConeAngle 0 and outerConeAngle 2",
        ),
    ] {
        let body = body.replace(r#"{"outerConeAngle":0.5}"#, cone);
        let message = failure("cone.gltf", doc.embedded(&body).as_bytes());
        assert!(
            message.contains(&format!(
                "cone.gltf: light 2 on node 3: spot {angles} must satisfy 0 <= inner < outer <= pi/2"
            )),
            "{message}"
        );
    }
}

/// A PNG file's bytes.
fn png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    let image = image::RgbaImage::from_raw(width, height, raw).expect("texel count");
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, image::ImageFormat::Png)
        .expect("encode png");
    bytes.into_inner()
}

/// glTF 2.0 §3.9.4: alphaMode MASK with its alphaCutoff (default 0.5), BLEND and the
/// base colour factor's alpha are read, without warnings; OPAQUE ignores alpha; the
/// base colour texture keeps its own (linear) alpha channel.
#[test]
fn alpha_modes_cutoffs_and_the_base_colour_s_alpha_are_read() {
    let (mut doc, _) = triangle_doc();
    let checker = png(2, 1, &[[255, 255, 255, 255], [255, 255, 255, 64]]);
    let view = doc.view(&checker);
    let primitive =
        |m: usize| format!(r#"{{"attributes":{{"POSITION":0}},"indices":1,"material":{m}}}"#);
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[{},{},{},{}]}}],
           "materials":[
              {{"name":"leaf","alphaMode":"MASK","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.8],"baseColorTexture":{{"index":0}}}}}},
              {{"name":"fence","alphaMode":"MASK","alphaCutoff":0.25}},
              {{"name":"glass","alphaMode":"BLEND","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.5]}}}},
              {{"name":"wall","alphaMode":"OPAQUE","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.5]}}}}],
           "textures":[{{"source":0}}],
           "images":[{{"bufferView":{view},"mimeType":"image/png"}}]"#,
        primitive(0),
        primitive(1),
        primitive(2),
        primitive(3)
    );
    let model = imported("alpha.gltf", doc.embedded(&body).as_bytes());
    let material = |name: &str| material_named(&model, name);
    let leaf = material("leaf");
    assert_eq!(leaf.material.alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert!((leaf.material.alpha - 0.8).abs() < 1e-7);
    let texture = leaf.base_color_texture.expect("base colour texture");
    let image = &model.images[texture.image as usize];
    assert_eq!(image.texel(0, 0)[3], 1.0);
    assert_eq!(
        image.texel(1, 0)[3],
        64.0 / 255.0,
        "alpha is linear, not decoded"
    );
    assert_eq!(
        material("fence").material.alpha_mode,
        AlphaMode::Mask { cutoff: 0.25 }
    );
    let glass = material("glass").material;
    assert_eq!(glass.alpha_mode, AlphaMode::Blend);
    assert_eq!(glass.alpha, 0.5);
    assert_eq!(material("wall").material.alpha_mode, AlphaMode::Opaque);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn materials_map_with_their_textures_and_wrap_modes() {
    let (mut doc, _) = triangle_doc();
    let emissive_png = png(1, 1, &[[255, 128, 0, 255]]);
    let emissive_view = doc.view(&emissive_png);
    let mr_png = png(1, 1, &[[0, 128, 64, 255]]);
    let mr_uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&mr_png)
    );
    let body = format!(
        r#""extensionsUsed":["KHR_materials_emissive_strength","KHR_materials_transmission","KHR_materials_ior"],
           "scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[
              {{"attributes":{{"POSITION":0}},"indices":1,"material":0}},
              {{"attributes":{{"POSITION":0}},"indices":1,"material":1}},
              {{"attributes":{{"POSITION":0}},"indices":1}}]}}],
           "materials":[
              {{"name":"painted","pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.6,0.7,1],"metallicFactor":0.25,"roughnessFactor":0.75,
                  "baseColorTexture":{{"index":0}},"metallicRoughnessTexture":{{"index":1}}}},
                "emissiveFactor":[1,0.5,0],"emissiveTexture":{{"index":2}},
                "extensions":{{"KHR_materials_emissive_strength":{{"emissiveStrength":4}}}}}},
              {{"name":"water","pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.9,1,1],"metallicFactor":0,"roughnessFactor":0}},
                "extensions":{{"KHR_materials_transmission":{{"transmissionFactor":1}},"KHR_materials_ior":{{"ior":1.33}}}}}}],
           "samplers":[{{"wrapS":33071,"wrapT":33648}}],
           "textures":[{{"source":0,"sampler":0}},{{"source":1}},{{"source":2}}],
           "images":[{{"uri":"base.png"}},{{"uri":"{mr_uri}"}},{{"bufferView":{emissive_view}}}]"#
    );
    let base_png = png(2, 1, &[[128, 128, 128, 255], [255, 255, 255, 255]]);
    let (_dir, result) = import(&[
        ("materials.gltf", doc.embedded(&body).as_bytes()),
        ("base.png", &base_png),
    ]);
    let model = result.expect("imports");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let painted = &model.materials[model.meshes[0].material as usize];
    assert_eq!(painted.name, "painted");
    let m = painted.material;
    assert_eq!(m.kind, MaterialKind::Pbr);
    assert_close(m.diffuse, DVec3::new(0.5, 0.6, 0.7), 1e-7);
    assert_eq!((m.metallic, m.roughness), (0.25, 0.75));
    assert_close(m.emission, DVec3::new(4.0, 2.0, 0.0), 1e-12);

    let base = painted.base_color_texture.expect("base colour texture");
    assert_eq!(
        (base.wrap_u, base.wrap_v),
        (WrapMode::ClampToEdge, WrapMode::MirroredRepeat)
    );
    let texel = model.images[base.image as usize].texel(0, 0);
    assert!(
        (texel[0] - srgb_decode(128.0 / 255.0) as f32).abs() < 1e-6,
        "sRGB linearised"
    );
    let mr = painted
        .metallic_roughness_texture
        .expect("metallic-roughness texture");
    assert_eq!((mr.wrap_u, mr.wrap_v), (WrapMode::Repeat, WrapMode::Repeat));
    let texel = model.images[mr.image as usize].texel(0, 0);
    assert!(
        (texel[1] - 128.0 / 255.0).abs() < 1e-6,
        "data, not linearised: {texel:?}"
    );
    assert!(
        (texel[2] - 64.0 / 255.0).abs() < 1e-6,
        "data, not linearised: {texel:?}"
    );
    let emissive = painted.emissive_texture.expect("emissive texture");
    let texel = model.images[emissive.image as usize].texel(0, 0);
    assert!((texel[1] - srgb_decode(128.0 / 255.0) as f32).abs() < 1e-6);
    assert_eq!(model.images.len(), 3);

    let water = model.materials[model.meshes[1].material as usize].material;
    assert_eq!(water.kind, MaterialKind::Dielectric);
    assert!((water.ior - 1.33).abs() < 1e-6);
    assert_close(water.transmittance, DVec3::new(0.8, 0.9, 1.0), 1e-7);

    let default = model.materials[model.meshes[2].material as usize].material;
    assert_eq!(default.kind, MaterialKind::Pbr);
    assert_eq!((default.diffuse, default.metallic), (DVec3::ONE, 0.0));

    // Placed in a scene, the base colour, metallic/roughness and emissive textures
    // travel with the material (each image once), with their wrap modes.
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
    let placed = scene.materials[model.meshes[0].material as usize];
    let mr = placed
        .metallic_roughness_texture
        .expect("the metallic/roughness texture is placed");
    let texel = scene.images[mr as usize].texel(0, 0);
    assert!((texel[1] - 128.0 / 255.0).abs() < 1e-6, "{texel:?}");
    assert_eq!(
        placed.metallic_roughness_wrap,
        [gpu_render::scene::TextureWrap::Repeat; 2]
    );
    assert!(placed.albedo_texture.is_some_and(|a| a != mr));
    let emission = placed
        .emission_texture
        .expect("the emissive texture is placed");
    let texel = scene.images[emission as usize].texel(0, 0);
    assert!(
        (texel[1] - srgb_decode(128.0 / 255.0) as f32).abs() < 1e-6,
        "{texel:?}"
    );
    assert_eq!(
        placed.emission_wrap,
        [gpu_render::scene::TextureWrap::Repeat; 2]
    );
    assert_eq!(
        placed.texture_mapping,
        gpu_render::scene::TextureMapping::Uv
    );
    assert_eq!(scene.images.len(), 3, "each image once");
}

/// A triangle with two texture coordinate sets (`TEXCOORD_1` = `TEXCOORD_0` + 10) and
/// a material whose base colour, metallic-roughness and emissive textures ask for the
/// sets given (`None`: no such texture); the JSON body.
fn two_uv_sets(doc: &mut Doc, base: Option<u32>, mr: Option<u32>, emissive: Option<u32>) -> String {
    let uv0 = doc.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let uv1 = doc.vec2(&[[10.0, 10.0], [11.0, 10.0], [10.0, 11.0]]);
    let texture = |slot: &str, set: Option<u32>| match set {
        Some(set) => format!(r#""{slot}":{{"index":0,"texCoord":{set}}},"#),
        None => String::new(),
    };
    let png = png(1, 1, &[[200, 100, 50, 255]]);
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    );
    format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":{uv0},"TEXCOORD_1":{uv1}}},"indices":1,"material":0}}]}}],
           "materials":[{{"name":"multi",{}"pbrMetallicRoughness":{{{}"metallicFactor":0}}}}],
           "textures":[{{"source":0}}],"images":[{{"uri":"{uri}"}}]"#,
        texture("emissiveTexture", emissive).replace(
            r#""emissiveTexture""#,
            r#""emissiveFactor":[1,1,1],"emissiveTexture""#
        ),
        texture("baseColorTexture", base) + &texture("metallicRoughnessTexture", mr),
    )
}

#[test]
fn textures_read_the_texture_coordinate_set_they_ask_for() {
    let first_u = |uvs: &Option<Vec<DVec2>>| uvs.as_ref().expect("uvs")[1].x;
    let sets = |model: &ImportedModel| {
        let m = &model.materials[0];
        [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.emissive_texture,
        ]
        .map(|t| t.map(|t| t.transform.set))
    };
    // Every texture on TEXCOORD_1: both sets are read, without a warning.
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, Some(1), Some(1), Some(1));
    let model = imported("one.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(first_u(&model.meshes[0].uvs), 1.0);
    assert_eq!(first_u(&model.meshes[0].uvs1), 11.0);
    assert_eq!(sets(&model), [Some(1); 3]);

    // MultiUVTest: base colour on TEXCOORD_0, emission on TEXCOORD_1: each its own.
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, Some(0), None, Some(1));
    let model = imported("multi.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(first_u(&model.meshes[0].uvs), 1.0);
    assert_eq!(first_u(&model.meshes[0].uvs1), 11.0);
    assert_eq!(sets(&model), [Some(0), None, Some(1)]);

    // No texture on TEXCOORD_1: the second set is not read.
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, Some(0), Some(0), None);
    let model = imported("zero.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes[0].uvs1, None);

    // A set beyond 1: TEXCOORD_0, with a warning.
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, Some(2), None, None);
    let model = imported("two.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(sets(&model), [Some(0), None, None]);
    assert!(
        model.warnings[0].ends_with(
            "two.gltf: material 0 ('multi'): baseColorTexture uses TEXCOORD_2, but only TEXCOORD_0 and TEXCOORD_1 are read; TEXCOORD_0 is used"
        ),
        "{:?}",
        model.warnings
    );

    // Only emission, on TEXCOORD_1, but the primitive has no such set: TEXCOORD_0.
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, None, None, Some(1)).replace(r#","TEXCOORD_1":3"#, "");
    let model = imported("missing.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(first_u(&model.meshes[0].uvs1), 1.0);
    assert!(
        model.warnings[0].ends_with(
            "missing.gltf: mesh 0, primitive 0: its material's textures use TEXCOORD_1, which it does not have; TEXCOORD_0 is used"
        ),
        "{:?}",
        model.warnings
    );
}

#[test]
fn texture_transforms_are_read_as_offset_rotation_and_scale() {
    let transformed = |extension: &str| {
        let (mut doc, _) = triangle_doc();
        let body = two_uv_sets(&mut doc, Some(0), None, None).replace(
            r#""baseColorTexture":{"index":0,"texCoord":0}"#,
            &format!(
                r#""baseColorTexture":{{"index":0,"texCoord":0,"extensions":{{"KHR_texture_transform":{extension}}}}}"#
            ),
        );
        (doc, body)
    };
    let (doc, body) = transformed(
        r#"{"offset":[0.5,-1],"rotation":1.5707963705062866,"scale":[2,3],"texCoord":1}"#,
    );
    let model = imported("transform.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let transform = model.materials[0]
        .base_color_texture
        .expect("texture")
        .transform;
    // texCoord overridden by the extension; the second set read for it.
    assert_eq!(transform.set, 1);
    assert!(model.meshes[0].uvs1.is_some());
    // T · R · S of (1, 0): scaled to (2, 0), rotated by 90° to (0, -2) (R =
    // [[cos, sin], [-sin, cos]]), offset to (0.5, -3).
    let p = transform.apply(DVec2::X);
    assert!((p - DVec2::new(0.5, -3.0)).length() < 1e-6, "{p}");
    let expected = TextureTransform::offset_rotation_scale(
        1,
        DVec2::new(0.5, -1.0),
        f64::from(1.570_796_4_f32),
        DVec2::new(2.0, 3.0),
    );
    assert_eq!(transform, expected);

    // Bad input: a located error, never a silently wrong image.
    for (extension, what) in [
        (r#"{"scale":[1e7,1]}"#, "scale [10000000, 1]"),
        (r#"{"offset":[1e300,0]}"#, "offset [inf, 0]"),
    ] {
        let (doc, body) = transformed(extension);
        let message = failure("bad.gltf", doc.embedded(&body).as_bytes());
        assert!(
            message.contains(
                "bad.gltf: material 0 ('multi'): baseColorTexture: KHR_texture_transform offset"
            ) && message.contains(what)
                && message.contains("must be finite, the offset and scale at most 1000000 in size"),
            "{message}"
        );
    }
}

#[test]
fn occlusion_textures_are_left_to_the_path_tracer_and_normal_maps_get_flat_normals() {
    let (mut doc, _) = triangle_doc();
    let body = two_uv_sets(&mut doc, None, None, None).replace(
        r#""name":"multi","#,
        r#""name":"baked","occlusionTexture":{"index":0},"#,
    );
    let model = imported("baked.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    // A normal map on a triangle without NORMAL: flat normals, as glTF 2.0 §3.7.2.1
    // asks (the winding normal, +z here), and MikkTSpace's tangents from them and the
    // texture coordinates (u along +x, v along +y, so the image's "up" is −y: tangent
    // +x, handedness −1).
    let body = body.replace(r#""occlusionTexture""#, r#""normalTexture""#);
    let model = imported("bumpy.gltf", doc.embedded(&body).as_bytes());
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert!(model.materials[0].normal_texture.is_some());
    let mesh = &model.meshes[0];
    assert_eq!(mesh.normals.as_deref(), Some(&[DVec3::Z; 3][..]));
    assert_tangents(mesh.tangents.as_ref(), DVec4::new(1.0, 0.0, 0.0, -1.0));
    // Without texture coordinates no tangents can be made: a warning.
    let bare = body
        .replace(r#","TEXCOORD_0":2,"TEXCOORD_1":3"#, "")
        .replace(r#","texCoord":1"#, "");
    assert_ne!(bare, body, "the texture coordinates are removed");
    let model = imported("bare.gltf", doc.embedded(&bare).as_bytes());
    assert!(
        model.warnings.iter().any(|w| w.ends_with(
            "bare.gltf: mesh 0, primitive 0: its material's normalTexture needs tangents, and without TANGENT they are generated from NORMAL and the normal map's texture coordinates, which it lacks; the normal map is not applied"
        )),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.meshes[0].tangents, None);
}

#[test]
fn jpeg_textures_load() {
    let (doc, _) = triangle_doc();
    let image = image::RgbImage::from_pixel(4, 2, image::Rgb([200, 100, 50]));
    let mut jpeg = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut jpeg, image::ImageFormat::Jpeg)
        .expect("encode jpeg");
    let body = r#""scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],
        "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
        "textures":[{"source":0}],"images":[{"uri":"photo.jpg","mimeType":"image/jpeg"}]"#;
    let (_dir, result) = import(&[
        ("photo.gltf", doc.embedded(body).as_bytes()),
        ("photo.jpg", &jpeg.into_inner()),
    ]);
    let model = result.expect("imports");
    let texture = model.materials[0].base_color_texture.expect("texture");
    let image = &model.images[texture.image as usize];
    assert_eq!((image.width, image.height), (4, 2));
    // JPEG is lossy: within a few 8-bit steps of the sRGB value, linearised.
    let expected = srgb_decode(200.0 / 255.0) as f32;
    assert!(
        (image.texel(1, 1)[0] - expected).abs() < 0.03,
        "{:?}",
        image.texel(1, 1)
    );
}

#[test]
fn a_model_without_camera_or_lights_gets_the_default_framing() {
    let (doc, meshes) = triangle_doc();
    let body = format!(r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],{meshes}"#);
    let model = imported("plain.gltf", doc.embedded(&body).as_bytes());
    assert!(model.camera.is_none() && model.lights.is_empty());
    let camera = model.camera_or_default(1.0);
    assert_close(camera.look_at, DVec3::new(0.5, 0.5, 0.0), 1e-12);
    assert!(camera.eye.z > 0.0, "in front of the model (+z)");
    assert_eq!(model.lights_or_default().len(), 3);
}

fn manifest(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The round trip: a scene exported by trimesh (`scripts/make_gltf_fixture.py`) imports
/// as the world-space triangles trimesh itself computed for it.
#[test]
fn a_scene_exported_by_trimesh_imports_as_trimesh_sees_it() {
    let expected: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(manifest(
            "tests/fixtures/models/trimesh_scene.expected.json",
        ))
        .expect("expected geometry"),
    )
    .expect("json");
    let point = |v: &serde_json::Value| {
        let c: Vec<f64> = v
            .as_array()
            .expect("point")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect();
        DVec3::new(c[0], c[1], c[2])
    };
    let triangles: Vec<[DVec3; 3]> = expected["triangles"]
        .as_array()
        .expect("triangles")
        .iter()
        .map(|t| {
            let corners: Vec<DVec3> = t.as_array().expect("corners").iter().map(point).collect();
            [corners[0], corners[1], corners[2]]
        })
        .collect();
    for file in ["trimesh_scene.glb", "trimesh_scene.gltf"] {
        let model = import_model(&manifest(&format!("tests/fixtures/models/{file}")))
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let world: Vec<_> = model.world_triangles().collect();
        assert_eq!(world.len(), triangles.len(), "{file}");
        // Each of trimesh's triangles is one of ours, with the same winding (up to a
        // rotation of its corners); f32 storage gives ~1e-7 relative error.
        let mut used = vec![false; world.len()];
        for want in &triangles {
            let found = world.iter().enumerate().position(|(i, got)| {
                !used[i]
                    && (0..3)
                        .any(|r| (0..3).all(|k| got.vertices[(k + r) % 3].distance(want[k]) < 1e-5))
            });
            let found = found.unwrap_or_else(|| panic!("{file}: no triangle {want:?}"));
            used[found] = true;
        }
        let box_mesh = model
            .meshes
            .iter()
            .find(|m| m.name.contains("'box'"))
            .expect("the box");
        assert_eq!(box_mesh.instances.len(), 2, "{file}: one mesh, two nodes");
        for (name, want) in expected["materials"].as_object().expect("materials") {
            let got = model
                .materials
                .iter()
                .find(|m| &m.name == name)
                .unwrap_or_else(|| panic!("{file}: no material {name}"))
                .material;
            assert_eq!(got.kind, MaterialKind::Pbr);
            assert_close(got.diffuse, point(&want["base_color"]), 1e-6);
            assert!((got.metallic - want["metallic"].as_f64().expect("metallic")).abs() < 1e-6);
            assert!((got.roughness - want["roughness"].as_f64().expect("roughness")).abs() < 1e-6);
        }
        let (low, high) = model.bounds().expect("bounds");
        let bounds = expected["bounds"].as_array().expect("bounds");
        // Our box is conservative for the rotated instance; trimesh's is exact.
        let (want_low, want_high) = (point(&bounds[0]), point(&bounds[1]));
        assert!(low.cmple(want_low + 1e-5).all() && high.cmpge(want_high - 1e-5).all());
    }
}

#[test]
fn the_shipped_vase_imports_cleanly() {
    let model = import_model(&manifest("scenes/models/vase.gltf")).expect("imports");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.meshes.len(), 2, "two primitives");
    for mesh in &model.meshes {
        assert_eq!(mesh.instances.len(), 2, "placed by two nodes");
        assert!(mesh.normals.is_some());
    }
    assert_eq!(model.meshes[0].triangles.len(), 6 * 10 * 2);
    assert_eq!(model.meshes[1].triangles.len(), 10, "the fan bottom");
    assert_eq!(model.materials.len(), 1);
    assert_eq!(model.materials[0].material.kind, MaterialKind::Pbr);
    for triangle in model.world_triangles() {
        let [a, b, c] = triangle.vertices;
        let geometric = (b - a).cross(c - a);
        let normals = triangle.normals.expect("normals");
        assert!(
            normals.iter().all(|n| n.dot(geometric) > 0.0),
            "flat normals follow the winding"
        );
    }
}

/// Documents with one thing wrong, and what the message must say.
fn bad_documents() -> Vec<(&'static str, Vec<u8>, &'static str)> {
    let (doc, meshes) = triangle_doc();
    let scene = r#""scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}]"#;
    let ok = doc.embedded(&format!("{scene},{meshes}"));
    let mut cases: Vec<(&'static str, Vec<u8>, &'static str)> = vec![
        ("empty", Vec::new(), "not a valid glTF file: the file is empty"),
        ("not json", b"solid cube\nfacet".to_vec(), "not a valid glTF file"),
        (
            "truncated json",
            ok.as_bytes()[..ok.len() / 2].to_vec(),
            "not a valid glTF file: EOF while parsing",
        ),
        (
            "glTF 1",
            ok.replace(r#""version":"2.0""#, r#""version":"1.0""#).into_bytes(),
            r#"the file is glTF 1.0 (asset.version is "1.0"); only glTF 2.0 is read"#,
        ),
        (
            "glTF 1 structure",
            br#"{"asset":{"version":"1.0"},"accessors":{"accessor_21":{"bufferView":"bufferView_29","componentType":5123,"count":36,"type":"SCALAR"}}}"#.to_vec(),
            r#"the file is glTF 1.0 (asset.version is "1.0"); only glTF 2.0 is read: convert it first, e.g. with gltf-pipeline"#,
        ),
        (
            "glTF 1 structure without a version",
            br#"{"meshes":{"mesh_0":{"primitives":[]}},"scene":"defaultScene"}"#.to_vec(),
            "the file is glTF 1.0 (its meshes are an object keyed by id, glTF 1.0's layout); only glTF 2.0 is read",
        ),
        (
            "binary glTF 1",
            [b"glTF".as_slice(), &1u32.to_le_bytes(), &40u32.to_le_bytes(), &[0; 28]].concat(),
            "the file is glTF 1.0 (a GLB container of version 1, glTF 1.0's KHR_binary_glTF); only glTF 2.0 is read",
        ),
        (
            "Draco required",
            ok.replacen(
                '{',
                r#"{"extensionsUsed":["KHR_draco_mesh_compression","KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization","KHR_draco_mesh_compression"],"#,
                1,
            )
            .into_bytes(),
            "the file requires the extension KHR_draco_mesh_compression, which is not supported (supported: EXT_mesh_gpu_instancing, KHR_lights_punctual, KHR_materials_emissive_strength, KHR_materials_ior, KHR_materials_transmission, KHR_materials_unlit, KHR_mesh_quantization, KHR_texture_transform). Its meshes are Draco-compressed (KHR_draco_mesh_compression), and Draco mesh compression is not supported: decompress the file first, e.g. with `gltf-transform cp IN OUT`",
        ),
        (
            "meshopt required",
            ok.replacen(
                '{',
                r#"{"extensionsUsed":["EXT_meshopt_compression"],"extensionsRequired":["EXT_meshopt_compression"],"#,
                1,
            )
            .into_bytes(),
            "requires the extension EXT_meshopt_compression, which is not supported (supported: EXT_mesh_gpu_instancing, KHR_lights_punctual, KHR_materials_emissive_strength, KHR_materials_ior, KHR_materials_transmission, KHR_materials_unlit, KHR_mesh_quantization, KHR_texture_transform). Its buffers are meshopt-compressed (EXT_meshopt_compression), and meshopt compression is not supported: decompress the file first, e.g. with `gltfpack -i IN -o OUT`",
        ),
        (
            "several required extensions",
            ok.replacen(
                '{',
                r#"{"extensionsRequired":["KHR_materials_sheen","KHR_lights_punctual","KHR_materials_clearcoat","EXT_meshopt_compression"],"#,
                1,
            )
            .into_bytes(),
            "the file requires 3 extensions that are not supported: KHR_materials_sheen, KHR_materials_clearcoat, EXT_meshopt_compression (supported: EXT_mesh_gpu_instancing, KHR_lights_punctual, KHR_materials_emissive_strength, KHR_materials_ior, KHR_materials_transmission, KHR_materials_unlit, KHR_mesh_quantization, KHR_texture_transform). Its buffers are meshopt-compressed (EXT_meshopt_compression)",
        ),
        (
            // As gltf-transform's BoxDraco.gltf: Draco used, not required, and no
            // uncompressed copy.
            "Draco without a fallback",
            ok.replacen('{', r#"{"extensionsUsed":["KHR_draco_mesh_compression"],"#, 1)
                .replace(r#""bufferView":0,"#, "")
                .replace(r#""bufferView":1,"#, "")
                .into_bytes(),
            "the file's meshes are Draco-compressed (KHR_draco_mesh_compression) without uncompressed copies (accessors 0, 1 have no bufferView), and Draco mesh compression is not supported: decompress the file first",
        ),
        (
            "dangling reference",
            ok.replace(r#"{"mesh":0}"#, r#"{"mesh":7}"#).into_bytes(),
            "not a valid glTF file: nodes[0].mesh: Index out of bounds",
        ),
        (
            // gltf-json's own validation would index the accessors with it (and panic).
            "POSITION accessor out of range",
            ok.replace(r#""POSITION":0"#, r#""POSITION":9"#).into_bytes(),
            "meshes[0].primitives[0].attributes[\"POSITION\"] refers to accessor 9, but there are 2 accessors",
        ),
        (
            "two parents",
            ok.replace(
                r#""nodes":[{"mesh":0}]"#,
                r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}]"#,
            )
            .into_bytes(),
            "node 0 is reached twice",
        ),
        (
            "infinite matrix",
            ok.replace(
                r#"{"mesh":0}"#,
                r#"{"mesh":0,"matrix":[1e39,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}"#,
            )
            .into_bytes(),
            "node 0: its matrix has a component that is not finite",
        ),
        (
            "matrix and translation",
            ok.replace(
                r#"{"mesh":0}"#,
                r#"{"name":"both","mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,5,0,0,1],"translation":[1,0,0],"scale":[1,1,1],"rotation":[0,0,1,0]}"#,
            )
            .into_bytes(),
            "bad.gltf: node 0 ('both'): it has both a matrix and translation, rotation (glTF 2.0 §3.5.3: a node's transform is a matrix or translation/rotation/scale, not both); which applies is ambiguous",
        ),
        (
            "projective matrix",
            ok.replace(
                r#"{"mesh":0}"#,
                r#"{"name":"lens","mesh":0,"matrix":[1,0,0,0.5,0,1,0,0,0,0,1,0,0,0,0,1]}"#,
            )
            .into_bytes(),
            "bad.gltf: node 0 ('lens'): its matrix's last row is [0.5, 0, 0, 1], not [0, 0, 0, 1]: a projective transform",
        ),
        (
            "only lines",
            ok.replace(r#""indices":1}"#, r#""indices":1,"mode":1}"#).into_bytes(),
            "bad.gltf: no triangles: the primitives it places are points or lines, which are not rendered (mesh 0 ('tri'), primitive 0: LINES (1))",
        ),
        (
            "remote buffer",
            doc.json(&format!("{scene},{meshes}"), Some("https://example.com/tri.bin"))
                .into_bytes(),
            "buffer 0: the URI https://example.com/tri.bin is neither a relative file path nor a data URI",
        ),
        (
            "missing buffer file",
            doc.json(&format!("{scene},{meshes}"), Some("nowhere.bin")).into_bytes(),
            "cannot read buffer 0",
        ),
        (
            "short buffer",
            ok.replace(
                &format!(r#""byteLength":{}"#, doc.bin.len()),
                &format!(r#""byteLength":{}"#, doc.bin.len() + 100),
            )
            .into_bytes(),
            "buffer 0: holds 42 bytes, fewer than its byteLength 142",
        ),
        (
            "bad base64",
            doc.json(&format!("{scene},{meshes}"), Some("data:application/octet-stream;base64,%%%"))
                .into_bytes(),
            "buffer 0: the data URI is not valid base64",
        ),
        (
            "accessor past its view",
            ok.replace(r#""count":3,"type":"VEC3""#, r#""count":30,"type":"VEC3""#)
                .into_bytes(),
            "mesh 0 ('tri'), primitive 0: POSITION (accessor 0): 30 elements of 12 bytes every 12 from byte 0 do not fit in bufferView 0 (36 bytes)",
        ),
        (
            "absurd count",
            ok.replace(r#""count":3,"type":"VEC3""#, r#""count":4000000000,"type":"VEC3""#)
                .into_bytes(),
            "mesh 0 ('tri'), primitive 0: 4000000000 vertices, more than the 16777216 accepted",
        ),
        (
            "wrong type",
            ok.replace(r#""count":3,"type":"VEC3""#, r#""count":3,"type":"VEC2""#)
                .into_bytes(),
            "POSITION (accessor 0): holds Vec2 elements, expected Vec3",
        ),
        (
            "view past its buffer",
            ok.replace(r#""byteOffset":0,"byteLength":36"#, r#""byteOffset":20,"byteLength":36"#)
                .into_bytes(),
            "bufferView 0 (bytes 20..20+36) lies outside buffer 0, which holds 42 bytes",
        ),
        (
            "negative light",
            ok.replacen(
                '{',
                r#"{"extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","intensity":-1}]}},"#,
                1,
            )
            .replace(
                r#"{"mesh":0}"#,
                r#"{"mesh":0,"extensions":{"KHR_lights_punctual":{"light":0}}}"#,
            )
            .into_bytes(),
            "light 0: intensity -1 is negative or not finite",
        ),
        (
            "light index without lights",
            ok.replace(
                r#"{"mesh":0}"#,
                r#"{"mesh":0,"extensions":{"KHR_lights_punctual":{"light":0}}}"#,
            )
            .into_bytes(),
            "nodes[0].extensions.khrLightsPunctual.light: Index out of bounds",
        ),
        (
            "light index out of range",
            ok.replacen(
                '{',
                r#"{"extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","intensity":1}]}},"#,
                1,
            )
            .replace(
                r#"{"mesh":0}"#,
                r#"{"mesh":0,"extensions":{"KHR_lights_punctual":{"light":3}}}"#,
            )
            .into_bytes(),
            "nodes[0].extensions.khrLightsPunctual.light: Index out of bounds",
        ),
        (
            "missing texture",
            ok.replace(
                r#""indices":1}"#,
                r#""indices":1,"material":0}"#,
            )
            .replacen(
                '{',
                r#"{"materials":[{"name":"m","pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],"textures":[{"source":0}],"images":[{"uri":"missing.png"}],"#,
                1,
            )
            .into_bytes(),
            "material 0 ('m'): baseColorTexture: image 0: the texture",
        ),
        (
            "image without a source",
            ok.replace(r#""indices":1}"#, r#""indices":1,"material":0}"#)
                .replacen(
                    '{',
                    r#"{"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],"textures":[{"source":0}],"images":[{"mimeType":"image/png"}],"#,
                    1,
                )
                .into_bytes(),
            "material 0: baseColorTexture: image 0: it has neither a uri nor a bufferView",
        ),
        (
            "out of range factor",
            ok.replace(r#""indices":1}"#, r#""indices":1,"material":0}"#)
                .replacen(
                    '{',
                    r#"{"materials":[{"pbrMetallicRoughness":{"baseColorFactor":[2,0,0,1]}}],"#,
                    1,
                )
                .into_bytes(),
            "material 0: baseColorFactor",
        ),
    ];
    // Index 5 of 3 vertices, and a NaN position: the buffer itself is edited.
    let mut bad_index = Doc::default();
    let positions = bad_index.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let indices = bad_index.indices(&[0, 1, 5]);
    let body = format!(
        r#"{scene},"meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":{positions}}},"indices":{indices}}}]}}]"#
    );
    cases.push((
        "index out of range",
        bad_index.embedded(&body).into_bytes(),
        "mesh 0 ('tri'), primitive 0: triangle 0 refers to vertex 5, but there are only 3 vertices",
    ));
    let mut nan = Doc::default();
    let positions = nan.vec3(&[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let body = format!(
        r#"{scene},"meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":{positions}}}}}]}}]"#
    );
    cases.push((
        "NaN position",
        nan.embedded(&body).into_bytes(),
        "mesh 0 ('tri'), primitive 0: vertex 1 has a position that is not a finite number",
    ));
    cases
}

#[test]
fn bad_gltf_files_name_the_file_and_the_element() {
    for (what, bytes, expected) in bad_documents() {
        let message = failure("bad.gltf", &bytes);
        assert!(
            message.contains("bad.gltf") && message.contains(expected),
            "{what}: expected {expected:?} in {message:?}"
        );
    }
}

#[test]
fn truncated_glb_files_are_errors() {
    let (doc, meshes) = triangle_doc();
    let glb = doc.glb(&format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],{meshes}"#
    ));
    imported("whole.glb", &glb);
    for cut in [4, 12, 19, 40, glb.len() / 2, glb.len() - 30, glb.len() - 1] {
        let message = failure("cut.glb", &glb[..cut]);
        assert!(message.contains("cut.glb: "), "cut at {cut}: {message}");
        assert!(
            message.contains("GLB") || message.contains("glTF") || message.contains("buffer"),
            "cut at {cut}: {message}"
        );
    }
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let mut doc = Doc::default();
    let positions = doc.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ]);
    let indices = doc.indices(&[0, 1, 2, 0, 1, 3, 2, 2, 0]);
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"name":"thin","primitives":[{{"attributes":{{"POSITION":{positions}}},"indices":{indices}}}]}}]"#
    );
    let model = imported("thin.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(model.meshes[0].triangles, vec![[0, 1, 2]]);
    assert!(
        model.warnings.iter().any(|w| w.contains(
            "thin.gltf: mesh 0 ('thin'), primitive 0: skipped 2 degenerate triangles (of 3)"
        )),
        "{:?}",
        model.warnings
    );
}

#[test]
fn unsupported_features_that_are_not_required_are_warnings() {
    let (doc, meshes) = triangle_doc();
    let body = format!(
        r#""extensionsUsed":["KHR_materials_sheen"],"scenes":[{{"nodes":[0]}},{{"nodes":[]}}],
           "nodes":[{{"mesh":0}},{{"mesh":0,"scale":[0,0,0]}},{{"camera":0}}],
           "cameras":[{{"type":"orthographic","orthographic":{{"xmag":1,"ymag":1,"zfar":10,"znear":0.1}}}}],{meshes}"#
    );
    let body = body.replace(
        r#""scenes":[{"nodes":[0]}"#,
        r#""scenes":[{"nodes":[0,1,2]}"#,
    );
    let model = parse_gltf(doc.embedded(&body).as_bytes(), Path::new("odd.gltf")).expect("imports");
    let warnings = model.warnings.join("\n");
    assert!(
        warnings.contains("KHR_materials_sheen, which is not supported"),
        "{warnings}"
    );
    assert!(warnings.contains("the file has 2 scenes"), "{warnings}");
    assert!(
        warnings.contains("node 1: its transform is singular"),
        "{warnings}"
    );
    assert!(!warnings.contains("orthographic"), "{warnings}");
    assert_eq!(model.meshes[0].instances.len(), 1);
    // The orthographic camera is imported: half its view height is ymag.
    let camera = model.camera.expect("a camera");
    assert_eq!(camera.camera.orthographic_half_height, Some(1.0));
    assert_eq!(camera.aspect_ratio, Some(1.0));

    // A node scale of zero along y: a located error that quotes the scale and the
    // half height it makes, not only xmag and ymag (issue 49, item 6).
    let flat = body.replace(r#"{"camera":0}"#, r#"{"camera":0,"scale":[1,0,1]}"#);
    let message = failure("flat.gltf", doc.embedded(&flat).as_bytes());
    assert!(
        message.contains("flat.gltf: camera 0 on node 2: orthographic xmag 1 and ymag 1 times the node's y scale 0 (a half height of 0) must be positive, finite and at most 1000000000000000"),
        "{message}"
    );
    // xmag or ymag of zero: the same located error.
    let body = body.replace(r#""ymag":1,"#, r#""ymag":0,"#);
    let message = failure("flat.gltf", doc.embedded(&body).as_bytes());
    assert!(
        message.contains("flat.gltf: camera 0 on node 2: orthographic xmag 1 and ymag 0 times the node's y scale 1 (a half height of 0) must be positive"),
        "{message}"
    );
}

/// A quad facing +z (normals +z, `v` down the image as `y` falls) with a normal map of
/// 2 × 2 different tilts, with or without a `TANGENT` of +x and handedness +1 (the
/// bitangent `normal × tangent` = +y, up the image: glTF's "+Y is up").
fn normal_mapped_quad(with_tangents: bool) -> (Doc, String) {
    normal_mapped_quad_with(
        with_tangents,
        &[
            [200, 128, 220, 255],
            [60, 128, 220, 255],
            [128, 200, 220, 255],
            [128, 60, 220, 255],
        ],
        "",
    )
}

/// [`normal_mapped_quad`] with a normal map of one texel or of 2 × 2 `texels`, and
/// `extra` JSON members of its `normalTexture` (after its `scale`).
fn normal_mapped_quad_with(with_tangents: bool, texels: &[[u8; 4]], extra: &str) -> (Doc, String) {
    let mut doc = Doc::default();
    let positions = doc.vec3(&[
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let normals = doc.vec3(&[[0.0, 0.0, 1.0]; 4]);
    let uvs = doc.vec2(&[[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let tangents = doc.vec4(&[[1.0, 0.0, 0.0, 1.0]; 4]);
    let indices = doc.indices(&[0, 1, 2, 0, 2, 3]);
    let side = if texels.len() == 1 { 1 } else { 2 };
    let png = png(side, side, texels);
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    );
    let tangent = if with_tangents {
        format!(r#","TANGENT":{tangents}"#)
    } else {
        String::new()
    };
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
           "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{positions},"NORMAL":{normals},"TEXCOORD_0":{uvs}{tangent}}},"indices":{indices},"material":0}}]}}],
           "materials":[{{"normalTexture":{{"index":0,"scale":0.8{extra}}},"pbrMetallicRoughness":{{"metallicFactor":0}}}}],
           "textures":[{{"source":0}}],"images":[{{"uri":"{uri}"}}]"#
    );
    (doc, body)
}

#[test]
fn generated_tangents_give_the_image_given_ones_give() {
    let (doc, body) = normal_mapped_quad(true);
    let given = imported("given.gltf", doc.embedded(&body).as_bytes());
    let (doc, body) = normal_mapped_quad(false);
    let generated = imported("generated.gltf", doc.embedded(&body).as_bytes());
    assert!(given.warnings.is_empty(), "{:?}", given.warnings);
    assert!(generated.warnings.is_empty(), "{:?}", generated.warnings);
    // MikkTSpace's tangents are the given ones: +x, handedness +1.
    assert_tangents(
        generated.meshes[0].tangents.as_ref(),
        DVec4::new(1.0, 0.0, 0.0, 1.0),
    );
    assert_eq!(given.materials[0].material.normal_scale, f64::from(0.8f32));
    // Rendered, the same image; and a different one without the normal map.
    let render = |model: &ImportedModel| {
        let scene = small_scene(model, DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO);
        gpu_render::cpu::render(&scene, None).image
    };
    let (a, b) = (render(&given), render(&generated));
    let largest = max_channel_difference(&a, &b);
    assert!(largest < 1e-5, "images differ by {largest}");
    let mut flat = given.clone();
    flat.materials[0].normal_texture = None;
    let c = render(&flat);
    assert!(
        a.pixels
            .iter()
            .zip(&c.pixels)
            .any(|(p, q)| (p[0] - q[0]).abs() > 1e-2)
    );
}

/// A normal map whose `KHR_texture_transform` turns it a quarter: its axes turn with
/// it, given (`TANGENT`, turned by the importer) or generated (MikkTSpace on the
/// transformed coordinates), and it shades as the map turned by hand does.
#[test]
fn a_normal_map_s_texture_transform_turns_its_axes() {
    const QUARTER: &str = r#","extensions":{"KHR_texture_transform":{"rotation":1.5707964}}"#;
    // Tilted 0.6 towards the map's +x; the same tilt towards its −y.
    let towards_x = [[204, 128, 230, 255]];
    let towards_minus_y = [[128, 51, 230, 255]];
    let model = |tangents: bool, texel: &[[u8; 4]], extra: &str| {
        let (doc, body) = normal_mapped_quad_with(tangents, texel, extra);
        let model = imported("turned.gltf", doc.embedded(&body).as_bytes());
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
        model
    };
    let given = model(true, &towards_x, QUARTER);
    let generated = model(false, &towards_x, QUARTER);
    let turned_by_hand = model(true, &towards_minus_y, "");
    let unturned = model(true, &towards_x, "");
    let transform = given.materials[0].normal_texture.expect("map").transform;
    assert_eq!(
        transform,
        TextureTransform::offset_rotation_scale(
            0,
            DVec2::ZERO,
            f64::from(1.570_796_4_f32),
            DVec2::ONE
        )
    );
    // u' = v, v' = −u: the map's +x runs along increasing v, down the quad (−y); its
    // +y (decreasing v') along +u (+x): a right-handed frame.
    for model in [&given, &generated] {
        assert_tangents(
            model.meshes[0].tangents.as_ref(),
            DVec4::new(0.0, -1.0, 0.0, 1.0),
        );
    }
    let scene = |model: &ImportedModel| small_scene(model, DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO);
    let render = |model: &ImportedModel| gpu_render::cpu::render(&scene(model), None).image;
    let largest = max_channel_difference;
    let reference = render(&turned_by_hand);
    for (what, model) in [("given", &given), ("generated", &generated)] {
        let difference = largest(&render(model), &reference);
        assert!(
            difference < 1e-5,
            "{what} tangents: images differ by {difference}"
        );
    }
    // Read without its transform the map tilts the other way: a different image.
    let difference = largest(&render(&unturned), &reference);
    assert!(
        difference > 1e-2,
        "the quarter turn changes nothing ({difference})"
    );
    // And the GPU agrees, on the transformed lookup and the turned frame.
    if let Some(gpu) = crate::support::gpu::headless_gpu() {
        let renderer = crate::support::gpu::renderer(&gpu);
        crate::support::twins::assert_backends_agree(
            &gpu,
            &renderer,
            "normal-map-quarter-turn",
            &scene(&given),
            crate::support::twins::TWIN_TOLERANCE,
        );
    }

    // Bad input: a located error, as on the other textures.
    let (doc, body) = normal_mapped_quad_with(
        true,
        &towards_x,
        r#","extensions":{"KHR_texture_transform":{"offset":[1e300,0]}}"#,
    );
    let message = failure("bad.gltf", doc.embedded(&body).as_bytes());
    assert!(
        message
            .contains("bad.gltf: material 0: normalTexture: KHR_texture_transform offset [inf, 0]"),
        "{message}"
    );
    let (doc, body) = normal_mapped_quad_with(
        true,
        &towards_x,
        r#","extensions":{"KHR_texture_transform":{"rotation":"a quarter"}}"#,
    );
    let message = failure("bad.gltf", doc.embedded(&body).as_bytes());
    assert!(
        message
            .contains("bad.gltf: material 0: normalTexture: KHR_texture_transform: invalid type"),
        "{message}"
    );
}

/// `KHR_materials_unlit` (required): the base colour, texture included, unshaded: an
/// emitter of that radiance that reflects nothing, so a pixel on it shows exactly its
/// base colour, whatever the lights (Whitted), on both backends.
#[test]
fn unlit_materials_show_their_base_colour_unshaded() {
    let (doc, body) = normal_mapped_quad_with(true, &[[255, 255, 255, 255]], "");
    let body = body.replace(
        r#""materials":[{"normalTexture":{"index":0,"scale":0.8},"pbrMetallicRoughness":{"metallicFactor":0}}]"#,
        r#""materials":[{"name":"flat","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.25,1,1],"baseColorTexture":{"index":0}},"extensions":{"KHR_materials_unlit":{}}}],
           "extensionsUsed":["KHR_materials_unlit"],"extensionsRequired":["KHR_materials_unlit"]"#,
    );
    assert!(
        body.contains("KHR_materials_unlit"),
        "the material is replaced"
    );
    let model = imported("unlit.gltf", doc.embedded(&body).as_bytes());
    let material = &model.materials[0];
    assert_eq!(material.material.kind, MaterialKind::Emissive);
    assert_eq!(material.material.emission, DVec3::new(0.5, 0.25, 1.0));
    assert!(material.emissive_texture.is_some());
    assert_eq!(material.emissive_texture, material.base_color_texture);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains(
            "material 0 ('flat'): KHR_materials_unlit: read as an emitter of its base colour"
        ),
        "{:?}",
        model.warnings
    );
    let scene = small_scene(&model, DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO);
    assert!(
        !scene.lights.is_empty(),
        "lit, to show the lights change nothing"
    );
    let image = gpu_render::cpu::render(&scene, None).image;
    let centre = image.pixels[(12 * 32 + 16) as usize];
    for (c, expected) in [0.5, 0.25, 1.0].into_iter().enumerate() {
        assert!((centre[c] - expected).abs() < 1e-6, "{centre:?}");
    }
    if let Some(gpu) = crate::support::gpu::headless_gpu() {
        let renderer = crate::support::gpu::renderer(&gpu);
        crate::support::twins::assert_backends_agree(
            &gpu,
            &renderer,
            "gltf-unlit",
            &scene,
            crate::support::twins::TWIN_TOLERANCE,
        );
    }
}

/// Positions outside their accessor's declared `min`/`max` (issue 49, item 7:
/// `ZeroLengthBufferView`, whose first vertex lies at x = 2^31 against a declared max
/// of 1) are warned about as the glTF validator reports them, naming the accessor and
/// the vertex; the model is framed by the positions read.
#[test]
fn positions_outside_their_declared_bounds_are_warned_about() {
    let Some(model) = crate::corpus::corpus_model(
        "draco/testdata/ZeroLengthBufferView/ZeroLengthBufferView.gltf",
    ) else {
        return;
    };
    let warning = model
        .warnings
        .iter()
        .find(|w| w.contains("outside the min"))
        .unwrap_or_else(|| panic!("no bounds warning in {:?}", model.warnings));
    assert!(
        warning.contains("POSITION (accessor 1)")
            && warning.contains("1 of 4 vertices")
            && warning.contains("vertex 0")
            && warning.contains("2147483648"),
        "{warning}"
    );
    let (low, high) = model.bounds().expect("bounds");
    assert!(high.x >= 2.0e9 && low.x <= 0.0, "{low} {high}");
    // A file whose positions keep to their bounds gets no such warning.
    let Some(duck) =
        crate::corpus::corpus_model("draco/testdata/KhronosSampleModels/Duck/glTF/Duck.gltf")
    else {
        return;
    };
    assert!(
        !duck.warnings.iter().any(|w| w.contains("outside the min")),
        "{:?}",
        duck.warnings
    );
}

/// `triangle_doc`'s mesh under a node at `node_json` (its other properties) with an
/// `EXT_mesh_gpu_instancing` whose `attributes` are `attributes`, the extension listed
/// as used and required.
fn instanced_body(meshes: &str, node_json: &str, attributes: &str) -> String {
    format!(
        r#""extensionsUsed":["EXT_mesh_gpu_instancing"],"extensionsRequired":["EXT_mesh_gpu_instancing"],
        "scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,{node_json}"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{{attributes}}}}}}}}}],{meshes}"#
    )
}

#[test]
fn gpu_instancing_places_the_mesh_at_each_instance_after_the_node() {
    let (mut doc, meshes) = triangle_doc();
    let translations = doc.vec3(&[[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, -1.0]]);
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let rotations = doc.vec4(&[
        [0.0, 0.0, 0.0, 1.0],
        [0.0, 0.0, half, half],
        [half, 0.0, 0.0, half],
    ]);
    let scales = doc.vec3(&[[1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [1.0, 3.0, 1.0]]);
    let body = instanced_body(
        &meshes,
        r#""translation":[0,0,5],"#,
        &format!(r#""TRANSLATION":{translations},"ROTATION":{rotations},"SCALE":{scales}"#),
    );
    let model = imported("instanced.gltf", doc.embedded(&body).as_bytes());
    assert!(
        !model
            .warnings
            .iter()
            .any(|w| w.contains("EXT_mesh_gpu_instancing")),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.meshes.len(), 1, "one mesh, stored once");
    let instances = &model.meshes[0].instances;
    assert_eq!(instances.len(), 3);
    // NodeWorldXform * T * R * S, from the file's f32 values.
    let node = DMat4::from_translation(DVec3::new(0.0, 0.0, 5.0));
    let half = f64::from(half);
    let expected = [
        DMat4::IDENTITY,
        DMat4::from_scale_rotation_translation(
            DVec3::splat(2.0),
            DQuat::from_xyzw(0.0, 0.0, half, half).normalize(),
            DVec3::new(3.0, 0.0, 0.0),
        ),
        DMat4::from_scale_rotation_translation(
            DVec3::new(1.0, 3.0, 1.0),
            DQuat::from_xyzw(half, 0.0, 0.0, half).normalize(),
            DVec3::new(0.0, 4.0, -1.0),
        ),
    ];
    for (got, want) in instances.iter().zip(expected) {
        assert!(
            got.abs_diff_eq(node * want, 1e-12),
            "{got} vs {}",
            node * want
        );
    }
    // The second instance by hand: (1, 0, 0) → ×2 → rotate 90° about z: (0, 2, 0) →
    // + (3, 0, 0) → + (0, 0, 5).
    let p = instances[1].transform_point3(DVec3::X);
    assert_close(p, DVec3::new(3.0, 2.0, 5.0), 1e-6);
}

#[test]
fn gpu_instancing_reads_any_one_attribute_and_rotations_as_normalized_shorts() {
    let (mut doc, meshes) = triangle_doc();
    // A quarter turn about y as normalized shorts: 23170 / 32767 ≈ 1/√2.
    let rotations = doc.integers(
        "VEC4",
        5122,
        true,
        &[vec![0, 23170, 0, 23170], vec![0, 0, 0, 32767]],
    );
    let body = instanced_body(
        &meshes,
        "",
        &format!(r#""ROTATION":{rotations},"_ID":{rotations}"#),
    );
    let model = imported("rotated.gltf", doc.embedded(&body).as_bytes());
    let instances = &model.meshes[0].instances;
    assert_eq!(instances.len(), 2);
    assert_close(
        instances[0].transform_point3(DVec3::X),
        DVec3::new(0.0, 0.0, -1.0),
        1e-9,
    );
    assert!(
        instances[1].abs_diff_eq(DMat4::IDENTITY, 1e-12),
        "{}",
        instances[1]
    );
}

/// Writes a case's accessors into the document and returns its `attributes` JSON.
type InstancingAttributes = fn(&mut Doc) -> String;

#[test]
fn bad_gpu_instancing_is_refused_naming_the_node_and_the_attribute() {
    let cases: [(&str, InstancingAttributes, &str); 5] = [
        (
            "different counts",
            |doc| {
                let t = doc.vec3(&[[0.0; 3], [1.0, 0.0, 0.0]]);
                let s = doc.vec3(&[[1.0; 3]]);
                format!(r#""TRANSLATION":{t},"SCALE":{s}"#)
            },
            "TRANSLATION has 2 elements but SCALE has 1",
        ),
        (
            "no such accessor",
            |_| r#""TRANSLATION":99"#.into(),
            "TRANSLATION is 99, which is not the index of one of the file's",
        ),
        (
            "not an index",
            |_| r#""SCALE":"big""#.into(),
            "SCALE is \"big\"",
        ),
        (
            "wrong type",
            |doc| {
                let t = doc.vec2(&[[0.0, 1.0]]);
                format!(r#""TRANSLATION":{t}"#)
            },
            "TRANSLATION (accessor",
        ),
        (
            "not finite",
            |doc| {
                let t = doc.vec3(&[[0.0; 3], [f32::NAN, 0.0, 0.0]]);
                format!(r#""TRANSLATION":{t}"#)
            },
            "instance 1: its TRANSLATION",
        ),
    ];
    for (what, attributes, expected) in cases {
        let (mut doc, meshes) = triangle_doc();
        let attributes = attributes(&mut doc);
        let body = instanced_body(&meshes, r#""name":"grass","#, &attributes);
        let message = failure("bad.gltf", doc.embedded(&body).as_bytes());
        assert!(
            message.contains("bad.gltf")
                && message.contains("node 0 ('grass')")
                && message.contains("EXT_mesh_gpu_instancing")
                && message.contains(expected),
            "{what}: {message}"
        );
    }
    // No attributes object at all.
    let (doc, meshes) = triangle_doc();
    let body = format!(
        r#""scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{}}}}}}],{meshes}"#
    );
    let message = failure("empty.gltf", doc.embedded(&body).as_bytes());
    assert!(
        message.contains("has no \"attributes\" object"),
        "{message}"
    );
}

#[test]
fn gpu_instancing_without_a_mesh_or_a_transform_attribute_is_warned_about() {
    let (doc, meshes) = triangle_doc();
    let body = format!(
        r#""scenes":[{{"nodes":[0,1]}}],"nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"_ID":0}}}}}}}},
        {{"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{{"TRANSLATION":0}}}}}}}}],{meshes}"#
    );
    let model = imported("odd.gltf", doc.embedded(&body).as_bytes());
    assert_eq!(
        model.meshes[0].instances,
        vec![DMat4::IDENTITY],
        "placed once, by its node"
    );
    let warned = |text: &str| model.warnings.iter().any(|w| w.contains(text));
    assert!(
        warned("node 0: EXT_mesh_gpu_instancing gives none of TRANSLATION, ROTATION and SCALE"),
        "{:?}",
        model.warnings
    );
    assert!(
        warned("node 1: EXT_mesh_gpu_instancing on a node without a mesh"),
        "{:?}",
        model.warnings
    );
}

/// Khronos's `SimpleInstancing` sample (its README: 125 instances of a unit cube in a
/// 5x5x5 grid, translations 0 to 10, scales 1 to 2, the first instance the unmodified
/// cube), read in place from `../shared/khronos-sample-assets`.
#[test]
fn the_simple_instancing_sample_places_125_cubes() {
    let Some(model) = crate::corpus::khronos_sample_model(
        "Models/SimpleInstancing/glTF-Binary/SimpleInstancing.glb",
    ) else {
        return;
    };
    assert_eq!(model.meshes.len(), 1, "{:?}", model.warnings);
    let instances = &model.meshes[0].instances;
    assert_eq!(instances.len(), 125);
    assert!(
        instances[0].abs_diff_eq(DMat4::IDENTITY, 1e-6),
        "{}",
        instances[0]
    );
    let origins: Vec<DVec3> = instances
        .iter()
        .map(|m| m.transform_point3(DVec3::ZERO))
        .collect();
    let (low, high) = origins
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    assert_close(low, DVec3::ZERO, 1e-6);
    assert_close(high, DVec3::splat(10.0), 1e-5);
    // The last instance is scaled by 2 along every axis.
    let last = instances[124];
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        assert!(
            (last.transform_vector3(axis).length() - 2.0).abs() < 1e-5,
            "{last}"
        );
    }
}
