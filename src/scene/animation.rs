//! A camera path: keyframes of the eye and the look-at point at given times, and the
//! frames of an animation sampled from it (`[animation]` in the scene file,
//! `docs/scene-format.md`).
//!
//! Frame `k` is at time `t_0 + k / fps`, where `t_0` is the first keyframe's time;
//! before the first keyframe and after the last the camera holds still. Between two
//! keyframes the eye and the look-at point are interpolated on their own (the `up`
//! direction and the field of view are the `[camera]` table's):
//!
//! - `linear`: `p = (1 - u) p_i + u p_{i+1}`, `u = (t - t_i) / (t_{i+1} - t_i)`;
//! - `catmull_rom`: the cubic Hermite curve through the keyframes with Catmull-Rom
//!   tangents for keys at any times, `m_i = (p_{i+1} - p_{i-1}) / (t_{i+1} - t_{i-1})`
//!   (one-sided at the two ends, `m_0 = (p_1 - p_0) / (t_1 - t_0)`), after Catmull and
//!   Rom 1974 ("A class of local interpolating splines"): it passes through every
//!   keyframe, and its velocity is continuous across them.
//!
//! Both reproduce every keyframe's position exactly at its time.

use glam::DVec3;

use super::Camera;

/// The most frames an animation may have.
pub const MAX_FRAMES: u32 = 1_000_000;

/// How positions between keyframes are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Straight lines between keyframes, at constant speed.
    #[default]
    Linear,
    /// A smooth curve through the keyframes (see the module's documentation).
    CatmullRom,
}

/// The camera at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraKey {
    /// Seconds.
    pub time: f64,
    /// The centre of projection.
    pub eye: DVec3,
    /// The point looked at.
    pub look_at: DVec3,
}

/// A camera path and the frames sampled from it.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraPath {
    /// At least one keyframe, in strictly increasing time.
    pub keys: Vec<CameraKey>,
    /// How positions between keyframes are found.
    pub interpolation: Interpolation,
    /// Frames per second (> 0).
    pub frames_per_second: f64,
    /// Frames in the animation (1 to [`MAX_FRAMES`]).
    pub frame_count: u32,
}

impl CameraPath {
    /// The frame count that spans the keyframes: every frame from the first
    /// keyframe's time up to and including the last's, `floor((t_n - t_0) · fps) + 1`
    /// (with a margin of 1e-9 frames for times written in decimals, so that 2 s at 24
    /// fps is 49 frames), or `None` above [`MAX_FRAMES`].
    pub fn spanning_frame_count(keys: &[CameraKey], frames_per_second: f64) -> Option<u32> {
        let (first, last) = (keys.first()?, keys.last()?);
        let frames = ((last.time - first.time) * frames_per_second + 1e-9).floor() + 1.0;
        (frames <= f64::from(MAX_FRAMES)).then_some(frames as u32)
    }

    /// The time of `frame`, in seconds.
    pub fn frame_time(&self, frame: u32) -> f64 {
        self.keys[0].time + f64::from(frame) / self.frames_per_second
    }

    /// The eye and look-at point at `time` (seconds).
    pub fn eye_and_look_at(&self, time: f64) -> (DVec3, DVec3) {
        let keys = &self.keys;
        let (first, last) = (keys[0], keys[keys.len() - 1]);
        if keys.len() == 1 || time <= first.time {
            return (first.eye, first.look_at);
        }
        if time >= last.time {
            return (last.eye, last.look_at);
        }
        // The segment [t_i, t_{i+1}] holding `time`: first.time < time < last.time.
        let i = keys.partition_point(|key| key.time <= time) - 1;
        let (a, b) = (keys[i], keys[i + 1]);
        let span = b.time - a.time;
        let u = (time - a.time) / span;
        match self.interpolation {
            Interpolation::Linear => (
                a.eye * (1.0 - u) + b.eye * u,
                a.look_at * (1.0 - u) + b.look_at * u,
            ),
            Interpolation::CatmullRom => {
                let tangent = |j: usize, point: fn(&CameraKey) -> DVec3| {
                    let (before, after) = (j.saturating_sub(1), (j + 1).min(keys.len() - 1));
                    (point(&keys[after]) - point(&keys[before]))
                        / (keys[after].time - keys[before].time)
                };
                let hermite = |point: fn(&CameraKey) -> DVec3| {
                    let (u2, u3) = (u * u, u * u * u);
                    point(&a) * (2.0 * u3 - 3.0 * u2 + 1.0)
                        + tangent(i, point) * (span * (u3 - 2.0 * u2 + u))
                        + point(&b) * (-2.0 * u3 + 3.0 * u2)
                        + tangent(i + 1, point) * (span * (u3 - u2))
                };
                (hermite(|k| k.eye), hermite(|k| k.look_at))
            }
        }
    }

    /// `base` (for its `up` and field of view) with the eye and look-at point of
    /// `frame`.
    pub fn frame_camera(&self, base: &Camera, frame: u32) -> Camera {
        let (eye, look_at) = self.eye_and_look_at(self.frame_time(frame));
        Camera {
            eye,
            look_at,
            ..*base
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64, x: f64) -> CameraKey {
        CameraKey {
            time,
            eye: DVec3::new(x, 1.0, 5.0),
            look_at: DVec3::new(x * 0.5, 0.0, 0.0),
        }
    }

    fn path(interpolation: Interpolation, keys: Vec<CameraKey>) -> CameraPath {
        CameraPath {
            frame_count: CameraPath::spanning_frame_count(&keys, 24.0).unwrap_or(1),
            keys,
            interpolation,
            frames_per_second: 24.0,
        }
    }

    #[test]
    fn both_interpolations_pass_through_every_key() {
        let keys = vec![key(0.0, 0.0), key(0.5, 3.0), key(2.0, -1.0), key(2.25, 7.5)];
        for interpolation in [Interpolation::Linear, Interpolation::CatmullRom] {
            let path = path(interpolation, keys.clone());
            for k in &keys {
                assert_eq!(path.eye_and_look_at(k.time), (k.eye, k.look_at));
            }
            assert_eq!(path.eye_and_look_at(-1.0).0, keys[0].eye);
            assert_eq!(path.eye_and_look_at(9.0).0, keys[3].eye);
        }
    }

    #[test]
    fn linear_moves_at_constant_speed() {
        let path = path(Interpolation::Linear, vec![key(1.0, 0.0), key(3.0, 4.0)]);
        assert_eq!(path.eye_and_look_at(1.5).0.x, 1.0);
        assert_eq!(path.eye_and_look_at(2.0).1.x, 1.0);
        // 2 s at 24 fps: frames 0 to 48.
        assert_eq!(path.frame_count, 49);
        assert_eq!(path.frame_time(24), 2.0);
    }

    #[test]
    fn catmull_rom_of_points_on_a_line_at_even_times_is_the_line() {
        // Catmull-Rom reproduces linear motion exactly (its tangents are the chords).
        let keys: Vec<_> = (0..5)
            .map(|i| key(f64::from(i), 2.0 * f64::from(i)))
            .collect();
        let path = path(Interpolation::CatmullRom, keys);
        for t in [0.25, 1.5, 2.75, 3.9] {
            let x = path.eye_and_look_at(t).0.x;
            assert!((x - 2.0 * t).abs() < 1e-12, "t = {t}: {x}");
        }
    }

    #[test]
    fn catmull_rom_is_smooth_across_a_key() {
        let keys = vec![key(0.0, 0.0), key(1.0, 1.0), key(3.0, 0.0)];
        let path = path(Interpolation::CatmullRom, keys);
        let x = |t: f64| path.eye_and_look_at(t).0.x;
        let h = 1e-6;
        let before = (x(1.0) - x(1.0 - h)) / h;
        let after = (x(1.0 + h) - x(1.0)) / h;
        // Both sides have the tangent (0 - 0) / (3 - 0) = 0.
        assert!(
            before.abs() < 1e-5 && after.abs() < 1e-5,
            "{before} {after}"
        );
        // Linear has a corner there.
        let linear = CameraPath {
            interpolation: Interpolation::Linear,
            ..path.clone()
        };
        let y = |t: f64| linear.eye_and_look_at(t).0.x;
        assert!(((y(1.0) - y(1.0 - h)) / h - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_frame_camera_keeps_up_and_fov() {
        let path = path(Interpolation::Linear, vec![key(0.0, 0.0), key(1.0, 24.0)]);
        let base = Camera {
            eye: DVec3::ZERO,
            look_at: DVec3::Z,
            up: DVec3::X,
            fov_y_degrees: 30.0,
            orthographic_half_height: None,
            lens: None,
        };
        let camera = path.frame_camera(&base, 12);
        assert_eq!(camera.eye.x, 12.0);
        assert_eq!((camera.up, camera.fov_y_degrees), (DVec3::X, 30.0));
    }
}
