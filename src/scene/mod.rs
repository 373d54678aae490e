//! The scene: its in-memory model and the TOML scene-file format that fills it
//! (documented field by field in `docs/scene-format.md`).

mod animation;
mod environment;
mod error;
mod file;
mod image;
pub mod import;
mod medium;
mod model;
pub mod outline;
mod precision;
mod sphere;

pub use animation::{CameraKey, CameraPath, Interpolation, MAX_FRAMES};
pub use environment::{Bilinear, EnvironmentMap, direction_to_uv, texel_at, uv_to_direction};
pub use error::{SceneError, SceneWarning};
pub(crate) use file::view_problem;
pub use file::{
    CONDUCTOR_PRESETS, LoadOptions, LoadProgress, MAX_SCENE_FILE_BYTES, SandboxError, SceneFile,
    confined_path, load_scene, load_scene_file, load_scene_with, parse_scene, parse_scene_file,
    parse_scene_with,
};
pub use image::{
    DECODED_BYTES_PER_TEXEL, DECODING_BYTES_PER_TEXEL, EncodedImage, ImageError,
    MAX_IMAGE_FILE_BYTES, MAX_IMAGE_SIDE, decode_image, decoding_transient_bytes, image_dimensions,
    load_confined_image, load_image,
};
pub use medium::{MEDIUM_STACK_SIZE, MediumStack};
pub use model::*;
pub use precision::{
    CAMERA_PRECISION_LIMIT, FlatShapeBeyondTheGpu, camera_pixel_precision, flat_precision,
    flat_shape_beyond_the_gpu, light_beyond_the_gpu, mesh_triangle_beyond_the_gpu,
};
pub use sphere::{
    FAR_WALL_PRECISION_LIMIT, FarWallPrecision, SPHERE_PRECISION_LIMIT, SphereGap,
    SurfacePrecision, coincident_spheres, far_wall_precision, sphere_anchor, sphere_level,
    sphere_precision,
};
