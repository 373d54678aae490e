//! No output replaces a file the render read (issue 49, items 1 and 2): every file a
//! scene or model opens (textures, coverage and bump images read and merged or
//! dropped, material libraries, glTF buffers, placed models) is compared with the
//! output by device and inode, and two outputs of one command are compared as files,
//! not as text. Each case checks the refusal and that the file is byte for byte as
//! before.

use std::path::{Path, PathBuf};

use crate::support::process::{assert_fails_with, gpu_render};

/// An 8-bit RGB PNG of 4x4 texels of one colour.
fn write_png(path: &Path, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(4, 4, image::Rgb(rgb))
        .save(path)
        .unwrap_or_else(|e| panic!("write {}: {e}", path.display()));
}

/// A folder with an OBJ triangle whose material names a colour texture, a coverage
/// texture, a bump map, roughness and metallic maps, and its material library under an
/// image's name (`lib.png`), so that each can be the target of `-o`.
struct ObjModel {
    dir: tempfile::TempDir,
}

/// The images the model's material names, each a file `-o` must not replace.
const MODEL_IMAGES: [&str; 5] = ["tex.png", "mask.png", "bump.png", "rough.png", "metal.png"];

impl ObjModel {
    fn new() -> Self {
        let dir = tempfile::tempdir().expect("tempdir");
        for (name, grey) in MODEL_IMAGES.iter().zip([200u8, 128, 128, 100, 20]) {
            write_png(&dir.path().join(name), [grey, grey / 2, 50]);
        }
        std::fs::write(
            dir.path().join("lib.png"),
            "newmtl a\nKd 1 1 1\nmap_Kd tex.png\nmap_d mask.png\nmap_Bump bump.png\n\
             Pr 0.5\nmap_Pr rough.png\nPm 0.5\nmap_Pm metal.png\n",
        )
        .expect("write the material library");
        std::fs::write(
            dir.path().join("m.obj"),
            "mtllib lib.png\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
             usemtl a\nf 1/1 2/2 3/3\n",
        )
        .expect("write the OBJ");
        std::fs::write(
            dir.path().join("scene.toml"),
            "[render]\nwidth = 16\nheight = 16\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
             [[lights]]\ntype = \"directional\"\ndirection = [0, 0, -1]\nirradiance = 1.0\n\
             [[objects]]\ntype = \"model\"\nfile = \"m.obj\"\n",
        )
        .expect("write the scene");
        Self { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    /// Renders `input` onto `output` (both in the folder) and asserts the refusal
    /// naming `output`, with `output` unchanged.
    fn assert_refused(&self, input: &str, output: &str) {
        let before = std::fs::read(self.path(output)).expect("read before");
        let run = gpu_render(&[
            &self.arg(input),
            "-o",
            &self.arg(output),
            "--backend",
            "cpu",
            "--width",
            "8",
            "--height",
            "8",
            "-q",
        ]);
        assert_fails_with(&run, &[output, "would destroy the input"]);
        assert_eq!(
            std::fs::read(self.path(output)).expect("read after"),
            before,
            "{input} -o {output} changed {output}"
        );
    }
}

#[test]
fn no_image_a_model_reads_is_replaced_by_the_render() {
    let model = ObjModel::new();
    for image in MODEL_IMAGES {
        model.assert_refused("m.obj", image);
    }
}

#[test]
fn no_image_of_a_model_placed_in_a_scene_is_replaced_by_the_render() {
    let model = ObjModel::new();
    for image in MODEL_IMAGES {
        model.assert_refused("scene.toml", image);
    }
}

#[test]
fn the_material_library_and_the_model_file_are_never_the_output() {
    let model = ObjModel::new();
    model.assert_refused("m.obj", "lib.png");
    model.assert_refused("scene.toml", "lib.png");
    // The OBJ itself, placed by a scene, under an image's name.
    std::fs::rename(model.path("m.obj"), model.path("model.obj")).expect("rename");
    std::fs::hard_link(model.path("model.obj"), model.path("m.png")).expect("hard link");
    let scene = std::fs::read_to_string(model.path("scene.toml")).expect("read");
    std::fs::write(
        model.path("scene.toml"),
        scene.replace("m.obj", "model.obj"),
    )
    .expect("write");
    model.assert_refused("scene.toml", "m.png");
}

#[test]
fn a_hard_link_or_another_spelling_of_an_input_is_refused() {
    let model = ObjModel::new();
    std::fs::hard_link(model.path("mask.png"), model.path("other.png")).expect("hard link");
    model.assert_refused("m.obj", "other.png");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(model.path("bump.png"), model.path("link.png"))
            .expect("symlink");
        model.assert_refused("m.obj", "link.png");
    }
}

/// A glTF triangle whose positions are in an external buffer file called `name`.
fn gltf_with_buffer(dir: &Path, name: &str) -> PathBuf {
    let positions: [f32; 9] = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join(name), &bytes).expect("write the buffer");
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
"min":[-1,-1,0],"max":[1,1,0]}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"buffers":[{{"uri":"{name}","byteLength":36}}]}}"#
    );
    let path = dir.join("model.gltf");
    std::fs::write(&path, json).expect("write the glTF");
    path
}

#[test]
fn a_gltf_buffer_is_never_the_output() {
    let dir = tempfile::tempdir().expect("tempdir");
    let model = gltf_with_buffer(dir.path(), "data.exr");
    let buffer = dir.path().join("data.exr");
    let before = std::fs::read(&buffer).expect("read");
    let run = gpu_render(&[
        model.as_os_str(),
        "-o".as_ref(),
        buffer.as_os_str(),
        "--backend".as_ref(),
        "cpu".as_ref(),
        "-q".as_ref(),
    ]);
    assert_fails_with(&run, &["data.exr", "would destroy the input"]);
    assert_eq!(std::fs::read(&buffer).expect("read"), before);
}

#[test]
fn two_outputs_naming_one_file_are_refused_however_spelled() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(
        dir.path().join("scene.toml"),
        "[render]\nwidth = 8\nheight = 8\nintegrator = \"path\"\n\
         [camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
         [materials.white]\ntype = \"lambert\"\nalbedo = 0.5\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.0\nmaterial = \"white\"\n",
    )
    .expect("write the scene");
    let scene = dir.path().join("scene.toml");
    let image = dir.path().join("img.exr");
    let spelled = dir.path().join(".").join("img.exr");
    let render = |output: &Path, standard_error: &Path| {
        gpu_render(&[
            scene.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
            "--standard-error".as_ref(),
            standard_error.as_os_str(),
            "--backend".as_ref(),
            "cpu".as_ref(),
        ])
    };
    // Neither exists yet: compared by folder and name.
    let run = render(&image, &spelled);
    assert_fails_with(&run, &["--standard-error", "same file as the image (-o)"]);
    assert!(
        !image.exists(),
        "a refused render wrote {}",
        image.display()
    );
    // Both exist, one a link to the other.
    std::fs::write(&image, b"old").expect("write");
    #[cfg(unix)]
    {
        let link = dir.path().join("link.exr");
        std::os::unix::fs::symlink(&image, &link).expect("symlink");
        let run = render(&link, &image);
        assert_fails_with(&run, &["--standard-error", "same file as the image (-o)"]);
        assert_eq!(std::fs::read(&image).expect("read"), b"old");
    }
    // Distinct files are fine.
    let run = render(&image, &dir.path().join("se.exr"));
    assert_eq!(run.status, Some(0), "{}", run.stderr);
}

#[test]
fn merge_never_writes_over_one_of_its_tiles_however_spelled() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[render]\nwidth = 8\nheight = 8\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
         [materials.white]\ntype = \"lambert\"\nalbedo = 0.5\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.0\nmaterial = \"white\"\n",
    )
    .expect("write the scene");
    for index in 0..2 {
        let run = gpu_render(&[
            scene.to_string_lossy().as_ref(),
            "-o",
            &dir.path().join(format!("t{index}.exr")).to_string_lossy(),
            "--tile",
            &format!("{index}/2"),
            "--backend",
            "cpu",
            "-q",
        ]);
        assert_eq!(run.status, Some(0), "{}", run.stderr);
    }
    let tile = dir.path().join("t1.exr");
    let before = std::fs::read(&tile).expect("read");
    let spelled = dir.path().join(".").join("t1.exr");
    let run = gpu_render(&[
        "merge",
        &dir.path().join("t0.exr").to_string_lossy(),
        &spelled.to_string_lossy(),
        "-o",
        &tile.to_string_lossy(),
    ]);
    assert_fails_with(&run, &["t1.exr", "would destroy the input"]);
    assert_eq!(std::fs::read(&tile).expect("read"), before);
}
