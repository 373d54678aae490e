//! `[animation]`: a camera path (see `crate::scene::animation` for the model and
//! `docs/scene-format.md` for the table).

use toml::Spanned;

use super::check::Source;
use super::raw::RawAnimation;
use super::settings::view_problem;
use crate::echo::{echo, short};
use crate::scene::{Camera, CameraKey, CameraPath, Interpolation, MAX_FRAMES, SceneError};

/// `[animation]` with its keyframes, checked: at least one keyframe, times finite
/// and strictly increasing, a positive frame rate, a frame count of 1 to
/// [`MAX_FRAMES`], and a defined view (with `camera`'s `up`) at every frame.
pub fn animation(
    source: &Source<'_>,
    raw: Option<Spanned<RawAnimation>>,
    camera: &Camera,
) -> Result<Option<CameraPath>, SceneError> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    let item = source.item("animation".into(), Some(raw.span()));
    let raw = raw.into_inner();
    let fps = item.number("fps", item.require("fps", raw.fps)?)?;
    if fps <= 0.0 {
        return Err(item.fail(format_args!("fps must be > 0, got {}", short(fps))));
    }
    let interpolation = match raw.interpolation.as_deref() {
        None | Some("linear") => Interpolation::Linear,
        Some("catmull_rom") => Interpolation::CatmullRom,
        Some(other) => {
            return Err(item.fail(format_args!(
                "unknown interpolation \"{}\"; use \"linear\" or \"catmull_rom\"",
                echo(other)
            )));
        }
    };
    if raw.keyframes.is_empty() {
        return Err(item.fail(
            "an animation needs at least one [[animation.keyframes]] entry (time, eye, look_at)",
        ));
    }
    let mut keys: Vec<CameraKey> = Vec::with_capacity(raw.keyframes.len());
    for (i, key) in raw.keyframes.into_iter().enumerate() {
        let key_item = source.item(format!("animation.keyframes[{i}]"), Some(key.span()));
        let key = key.into_inner();
        let time = key_item.number("time", key_item.require("time", key.time)?)?;
        let eye = key_item.vector("eye", key_item.require("eye", key.eye)?)?;
        let look_at = key_item.vector("look_at", key_item.require("look_at", key.look_at)?)?;
        if let Some(previous) = keys.last()
            && time <= previous.time
        {
            return Err(key_item.fail(format_args!(
                "time {time} is not after the previous keyframe's {}; keyframes must be in \
                 increasing time",
                previous.time
            )));
        }
        if let Some(problem) = view_problem(eye, look_at, camera.up) {
            return Err(key_item.fail(problem));
        }
        keys.push(CameraKey { time, eye, look_at });
    }
    let frame_count = match raw.frames {
        Some(frames) if (1..=MAX_FRAMES).contains(&frames) => frames,
        Some(frames) => {
            return Err(item.fail(format_args!(
                "frames must be between 1 and {MAX_FRAMES}, got {frames}"
            )));
        }
        None => CameraPath::spanning_frame_count(&keys, fps).ok_or_else(|| {
            item.fail(format_args!(
                "the keyframes span more than {MAX_FRAMES} frames at {fps} fps"
            ))
        })?,
    };
    let path = CameraPath {
        keys,
        interpolation,
        frames_per_second: fps,
        frame_count,
    };
    // A curve may pass through the look-at point, or turn parallel to `up`, between
    // keyframes that are fine.
    for frame in 0..frame_count {
        let (eye, look_at) = path.eye_and_look_at(path.frame_time(frame));
        let bad_number = [eye, look_at]
            .iter()
            .flat_map(|v| v.to_array())
            .any(|c| !c.is_finite() || c.abs() > f64::from(f32::MAX));
        let problem = if bad_number {
            Some(format!(
                "the camera leaves the range of 32-bit floats ({eye}, {look_at})"
            ))
        } else {
            view_problem(eye, look_at, camera.up)
        };
        if let Some(problem) = problem {
            return Err(item.fail(format_args!(
                "at frame {frame} (t = {} s): {problem}",
                path.frame_time(frame)
            )));
        }
    }
    Ok(Some(path))
}
