//! Reading what the program renders: a scene file, or a model file framed as a scene
//! of its own, with the command-line settings applied, and the list of every file the
//! load read, so that no output replaces one of them.

use std::path::Path;

use anyhow::{Result, bail};
use gpu_render::low_level::input::{InputFile, record_inputs};
use gpu_render::output::{self, OutputError};
use gpu_render::scene::{
    self, CameraPath, LoadOptions, LoadProgress, RenderSettings, Scene, SceneFile, SceneWarning,
};

use crate::args::SettingsArgs;
use crate::progress;

/// A scene as the program renders it, and the files it came from.
pub struct Loaded {
    /// The scene, with the command-line settings applied.
    pub scene: Scene,
    /// The camera path of the scene file's `[animation]`, if it has one.
    pub camera_path: Option<CameraPath>,
    /// Every file the load opened: the scene or model file, and what it names (images,
    /// models, material libraries, buffers), including those read and then dropped or
    /// merged into another image.
    pub inputs: Vec<InputFile>,
}

/// How to load: the command line's part.
pub struct LoadArgs<'a> {
    /// The settings flags (`--width`, `--spp`, ...).
    pub settings: &'a SettingsArgs,
    /// `--sandbox`: confine a scene file's references to its folder.
    pub sandbox: bool,
    /// `--quiet`: no warnings, notes or progress.
    pub quiet: bool,
    /// A model is refused while it is read once it would hold more than this.
    pub max_memory: Option<u64>,
}

/// Refuses an output that is the scene file, one of its images (textures, BRDF maps,
/// the environment map), or any other file the load read (`inputs`: models, material
/// libraries, buffers, images read and dropped or merged into another).
pub fn check_inputs_survive(
    output_path: &Path,
    scene_path: &Path,
    scene: &Scene,
    inputs: &[InputFile],
) -> Result<(), OutputError> {
    let named = std::iter::once((scene_path, "scene file")).chain(scene.image_files());
    output::check_not_an_input(output_path, named)?;
    output::check_not_read(output_path, inputs)
}

/// Loads `path`: a model file (OBJ, glTF, GLB) is imported and framed as a scene of its
/// own, anything else is read as a scene file; the command-line settings apply to
/// either.
pub fn load_any(path: &Path, args: &LoadArgs<'_>) -> Result<Loaded> {
    let (loaded, inputs) = record_inputs(|| -> Result<(Scene, Option<CameraPath>)> {
        if scene::import::is_model_path(path) {
            let render =
                crate::apply_overrides(args.settings, RenderSettings::default(), Some(path))?;
            let scene = load_model(path, render, args)?;
            Ok((scene, None))
        } else {
            let file = load(path, args)?;
            Ok((file.scene, file.camera_path))
        }
    });
    let (mut scene, camera_path) = loaded?;
    scene.render = crate::apply_overrides(args.settings, scene.render, Some(path))?;
    Ok(Loaded {
        scene,
        camera_path,
        inputs,
    })
}

/// Loads the scene file (and its camera path, if it has one), with progress after a
/// second and warnings on stderr (unless `quiet`), confined to its folder with
/// `sandbox`, each model it places refused once importing it would hold more than
/// `max_memory` bytes.
fn load(scene_path: &Path, args: &LoadArgs<'_>) -> Result<SceneFile> {
    let warn = |warning: &SceneWarning| eprintln!("warning: {warning}");
    let label = scene_path.display().to_string();
    let scene = progress::while_loading(&label, !args.quiet, |progress| {
        let options = LoadOptions {
            sandbox: args.sandbox,
            progress: Some(progress),
            warning: (!args.quiet).then_some(&warn as &(dyn Fn(&SceneWarning) + Sync)),
            max_bytes: args.max_memory,
        };
        scene::load_scene_file(scene_path, &options)
    })?;
    Ok(scene)
}

/// Imports a model file and frames it as a scene of its own
/// ([`gpu_render::scene::import::ImportedModel::into_scene`]) with `render`'s settings;
/// warnings on stderr unless `quiet`, progress after a second; refused once importing
/// it would hold more than `max_memory` bytes. A model's own references (material
/// libraries, buffers, images) cannot be confined, so `sandbox` refuses model files.
fn load_model(path: &Path, render: RenderSettings, args: &LoadArgs<'_>) -> Result<Scene> {
    if args.sandbox {
        bail!(
            "{}: --sandbox cannot render model files: the files a model names itself \
             (material libraries, buffers, textures) are not confined",
            path.display()
        );
    }
    let label = path.display().to_string();
    let model = progress::while_loading(&label, !args.quiet, |progress| {
        let report = |done: u64, total: u64| progress(LoadProgress::Importing { done, total });
        let options = scene::import::ImportOptions {
            max_bytes: args.max_memory,
            progress: Some(&report),
        };
        scene::import::import_model_with(path, &options)
    })?;
    let scene = model.into_scene(render);
    if !args.quiet {
        for warning in &model.warnings {
            eprintln!(
                "warning: {}",
                gpu_render::low_level::echo::escape_controls(warning)
            );
        }
        if model.camera.is_none() {
            eprintln!(
                "note: {} has no camera; framing its bounds from the front, above right",
                path.display()
            );
        }
        if model.lights.is_empty() {
            eprintln!(
                "note: {} has no lights; using the default three directional lights",
                path.display()
            );
        }
    }
    Ok(scene)
}
