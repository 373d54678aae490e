//! The singleton tables: `[render]`, `[camera]` and `[environment]`.

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use toml::Spanned;

use super::LoadOptions;
use super::budget::{LoadBudget, load_scene_image};
use super::check::{ColourRange, Item, Source};
use super::paths::confined_path;
use super::raw::{
    RawCamera, RawEnvironment, RawIntegrator, RawLighting, RawRender, RawTextureFiltering,
};
use crate::echo::{echo_path, short};
use crate::scene::{
    Camera, Environment, EnvironmentMap, Image, Integrator, LightingSpace,
    MAX_ORTHOGRAPHIC_HALF_HEIGHT, MAX_RADIANCE, RenderSettings, SceneError, TextureFiltering,
    ThinLens,
};

/// Default image width in pixels.
const DEFAULT_WIDTH: u32 = 640;
/// Default image height in pixels.
const DEFAULT_HEIGHT: u32 = 480;
/// Default bounce depth.
const DEFAULT_MAX_DEPTH: u32 = 5;
/// Default vertical field of view in degrees.
const DEFAULT_FOV_Y_DEGREES: f64 = 45.0;
/// Below this, the view direction and `up` count as parallel.
const PARALLEL_TOLERANCE: f64 = 1e-6;

/// `[render]` with defaults applied, checked by [`RenderSettings::check`].
pub fn render(
    source: &Source<'_>,
    raw: Option<Spanned<RawRender>>,
) -> Result<RenderSettings, SceneError> {
    let span = raw.as_ref().map(Spanned::span);
    let raw = raw.map(Spanned::into_inner).unwrap_or_default();
    let max_depth = raw.max_depth.unwrap_or(DEFAULT_MAX_DEPTH);
    let settings = RenderSettings {
        width: raw.width.unwrap_or(DEFAULT_WIDTH),
        height: raw.height.unwrap_or(DEFAULT_HEIGHT),
        samples_per_pixel: raw.samples_per_pixel.unwrap_or(1),
        max_depth,
        stack_size: raw
            .stack_size
            .unwrap_or_else(|| RenderSettings::sufficient_stack_size(max_depth)),
        lighting_space: match raw.lighting {
            None | Some(RawLighting::Linear) => LightingSpace::Linear,
            Some(RawLighting::NaiveGamma) => LightingSpace::NaiveGamma,
        },
        min_ray_weight: raw.min_ray_weight.unwrap_or(0.0),
        integrator: match raw.integrator {
            None | Some(RawIntegrator::Whitted) => Integrator::Whitted,
            Some(RawIntegrator::Path) => Integrator::Path,
        },
        texture_filtering: match raw.texture_filtering {
            None | Some(RawTextureFiltering::Anisotropic) => TextureFiltering::Anisotropic,
            Some(RawTextureFiltering::Trilinear) => TextureFiltering::Trilinear,
            Some(RawTextureFiltering::None) => TextureFiltering::None,
        },
    };
    let item = source.item("render".into(), span);
    settings.check().map_err(|message| item.fail(message))?;
    Ok(settings)
}

/// `[camera]`: required, with a distinct eye and target and a usable `up`.
pub fn camera(source: &Source<'_>, raw: Option<Spanned<RawCamera>>) -> Result<Camera, SceneError> {
    let Some(raw) = raw else {
        return Err(source.error(None, "missing the required [camera] table"));
    };
    let item = source.item("camera".into(), Some(raw.span()));
    let raw = raw.into_inner();
    let eye = item.vector("eye", item.require("eye", raw.eye)?)?;
    let look_at = item.vector("look_at", item.require("look_at", raw.look_at)?)?;
    let up = item.vector("up", raw.up.unwrap_or([0.0, 1.0, 0.0]))?;
    let fov_y_degrees = item.number(
        "fov_y_degrees",
        raw.fov_y_degrees.unwrap_or(DEFAULT_FOV_Y_DEGREES),
    )?;
    if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
        return Err(item.fail(format_args!(
            "fov_y_degrees must be in (0, 180), got {}",
            short(fov_y_degrees)
        )));
    }
    if let Some(problem) = view_problem(eye, look_at, up) {
        return Err(item.fail(problem));
    }
    let orthographic_half_height = match raw.orthographic_half_height {
        None => None,
        Some(_) if raw.fov_y_degrees.is_some() => {
            return Err(item.fail(
                "fov_y_degrees and orthographic_half_height exclude each other: \
                 a camera is either a pinhole (fov_y_degrees) or orthographic",
            ));
        }
        Some(half_height) => {
            let half_height = item.number("orthographic_half_height", half_height)?;
            if !(half_height > 0.0 && half_height <= MAX_ORTHOGRAPHIC_HALF_HEIGHT) {
                return Err(item.fail(format_args!(
                    "orthographic_half_height must be in (0, {}], got {}",
                    short(MAX_ORTHOGRAPHIC_HALF_HEIGHT),
                    short(half_height)
                )));
            }
            Some(half_height)
        }
    };
    let lens = match (raw.aperture_radius, raw.focus_distance) {
        (None, None) => None,
        (None, Some(_)) => {
            return Err(item.fail(
                "focus_distance needs aperture_radius: a pinhole camera has everything in focus",
            ));
        }
        (Some(_), _) if orthographic_half_height.is_some() => {
            return Err(item.fail(
                "aperture_radius (a thin lens) needs a pinhole camera, not an orthographic one",
            ));
        }
        (Some(aperture_radius), focus_distance) => {
            let lens = ThinLens {
                aperture_radius: item.number("aperture_radius", aperture_radius)?,
                focus_distance: focus_distance
                    .map(|d| item.number("focus_distance", d))
                    .transpose()?,
            };
            if let Some(problem) = lens.problem() {
                return Err(item.fail(problem));
            }
            Some(lens)
        }
    };
    Ok(Camera {
        eye,
        look_at,
        up,
        fov_y_degrees,
        orthographic_half_height,
        lens,
    })
}

/// What makes a view undefined, if anything: `eye` and `look_at` the same point, a
/// zero `up`, or an `up` parallel to the view direction.
pub fn view_problem(eye: DVec3, look_at: DVec3, up: DVec3) -> Option<String> {
    let Some(view) = (look_at - eye).try_normalize() else {
        return Some(
            "eye and look_at are the same point; the view direction is undefined".to_owned(),
        );
    };
    let Some(up_unit) = up.try_normalize() else {
        return Some("up is the zero vector".to_owned());
    };
    (view.cross(up_unit).length() < PARALLEL_TOLERANCE).then(|| {
        format!(
            "up {up} is parallel to the view direction {view} (look_at - eye); choose another up"
        )
    })
}

/// `[environment]`: background and ambient radiance, black by default, or an
/// environment map (`map`, relative to the scene file's folder `base`, with
/// `rotation` in degrees about +y and a radiance `scale`) instead of the background.
pub fn environment(
    source: &Source<'_>,
    raw: Option<Spanned<RawEnvironment>>,
    base: &Path,
    options: &LoadOptions<'_>,
    budget: &mut LoadBudget,
) -> Result<Environment, SceneError> {
    let span = raw.as_ref().map(Spanned::span);
    let raw = raw.map(Spanned::into_inner).unwrap_or_default();
    let item = source.item("environment".into(), span);
    let map = match &raw.map {
        Some(file) => {
            if raw.background.is_some() {
                return Err(item.fail(
                    "give either background or map: the map is the radiance of rays that hit nothing",
                ));
            }
            let rotation_degrees = item.number("rotation", raw.rotation.unwrap_or(0.0))?;
            let scale = item.colour_or("scale", raw.scale, ColourRange::Radiance, DVec3::ONE)?;
            let image = environment_image(&item, file, base, options, budget)?;
            // The GPU holds radiance and the sampling tables in f32.
            let brightest = image
                .texels
                .iter()
                .map(|t| {
                    (DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2])) * scale)
                        .max_element()
                })
                .fold(0.0, f64::max);
            if brightest > MAX_RADIANCE {
                return Err(item.fail(format_args!(
                    "map `{}` times scale reaches {brightest:e}, above the {MAX_RADIANCE:e} \
                     accepted (the GPU sums radiance in 32-bit floats); lower scale",
                    echo_path(Path::new(file)),
                )));
            }
            Some(Arc::new(EnvironmentMap {
                image,
                rotation_degrees,
                scale,
            }))
        }
        None => {
            if raw.rotation.is_some() || raw.scale.is_some() {
                return Err(item.fail("rotation and scale apply to a map; there is no map"));
            }
            None
        }
    };
    Ok(Environment {
        map,
        background: item.colour_or(
            "background",
            raw.background,
            ColourRange::Radiance,
            DVec3::ZERO,
        )?,
        ambient: item.colour_or("ambient", raw.ambient, ColourRange::Radiance, DVec3::ZERO)?,
    })
}

/// The environment map's image `file` (relative to `base`, confined to it in a
/// sandbox): readable, finite (checked by [`load_image`]) and without a negative
/// channel (a radiance cannot be negative). Errors name the file and the texel.
fn environment_image(
    item: &Item<'_>,
    file: &str,
    base: &Path,
    options: &LoadOptions<'_>,
    budget: &mut LoadBudget,
) -> Result<Image, SceneError> {
    let path = if options.sandbox {
        confined_path(base, file).map_err(|e| item.fail(format_args!("map {e}")))?
    } else {
        base.join(file)
    };
    let fail = |message: String| {
        item.fail(format_args!(
            "map `{}` ({}): {message}",
            echo_path(Path::new(file)),
            echo_path(&path)
        ))
    };
    let image = load_scene_image(item, "map", (file, &path), base, options, budget)?;
    for (i, texel) in image.texels.iter().enumerate() {
        for (channel, value) in ["r", "g", "b"].into_iter().zip(texel.iter().copied()) {
            if value < 0.0 {
                let (x, y) = (i as u32 % image.width, i as u32 / image.width);
                return Err(fail(format!(
                    "texel ({x}, {y}) has {channel} = {}; texels must be >= 0 (a radiance cannot be negative)",
                    short(value)
                )));
            }
        }
    }
    Ok(image)
}
