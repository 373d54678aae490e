//! The viewer's camera controls: orbit, pan and zoom around the camera's look-at
//! point, as pure functions of a [`Camera`] and a mouse motion in window pixels.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;
use gpu_render::scene::Camera;

/// Radians of orbit per window pixel dragged.
const ORBIT_RADIANS_PER_PIXEL: f64 = 0.005;
/// How close (radians) the view direction may come to the up axis: the camera's
/// basis is undefined on it.
const POLE_MARGIN: f64 = 0.01;
/// The distance factor of one wheel notch (a line of scrolling).
const ZOOM_PER_LINE: f64 = 0.9;
/// The nearest the eye may come to the look-at point, as a fraction of the distance
/// it started at, and in scene units.
const MIN_DISTANCE: f64 = 1e-3;

/// Turns the eye around `look_at` by a drag of `(dx, dy)` pixels: left-right about
/// the camera's up axis, up-down towards or away from it (stopping short of the
/// poles). The distance to `look_at` is kept.
pub fn orbit(camera: &Camera, dx: f64, dy: f64) -> Camera {
    let up = camera.up.normalize();
    let offset = camera.eye - camera.look_at;
    let distance = offset.length();
    let direction = offset / distance;
    // The angle from the up axis, and the azimuth in the plane orthogonal to it.
    let polar = direction.dot(up).clamp(-1.0, 1.0).acos();
    let reference = any_orthogonal(up);
    let side = up.cross(reference);
    let planar = direction - up * direction.dot(up);
    let azimuth = planar.dot(side).atan2(planar.dot(reference));
    let azimuth = azimuth - dx * ORBIT_RADIANS_PER_PIXEL;
    let polar =
        (polar - dy * ORBIT_RADIANS_PER_PIXEL).clamp(POLE_MARGIN, 2.0 * FRAC_PI_2 - POLE_MARGIN);
    let direction =
        up * polar.cos() + (reference * azimuth.cos() + side * azimuth.sin()) * polar.sin();
    Camera {
        eye: camera.look_at + direction * distance,
        ..*camera
    }
}

/// Moves the eye and `look_at` together in the view plane so that the point at
/// `look_at` follows a drag of `(dx, dy)` pixels in a window `height` pixels tall.
pub fn pan(camera: &Camera, dx: f64, dy: f64, height: u32) -> Camera {
    let offset = camera.look_at - camera.eye;
    let distance = offset.length();
    let forward = offset / distance;
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    // World units per pixel at the look-at point's distance.
    let scale =
        2.0 * distance * (camera.fov_y_degrees.to_radians() / 2.0).tan() / f64::from(height.max(1));
    let shift = (-right * dx + up * dy) * scale;
    Camera {
        eye: camera.eye + shift,
        look_at: camera.look_at + shift,
        ..*camera
    }
}

/// Moves the eye towards `look_at` (`lines > 0`) or away from it by
/// [`ZOOM_PER_LINE`] per line of wheel scrolling.
pub fn zoom(camera: &Camera, lines: f64) -> Camera {
    let offset = camera.eye - camera.look_at;
    let distance = offset.length();
    let new_distance = (distance * ZOOM_PER_LINE.powf(lines)).max(MIN_DISTANCE);
    Camera {
        eye: camera.look_at + offset * (new_distance / distance),
        ..*camera
    }
}

/// A unit vector orthogonal to the unit vector `v`.
fn any_orthogonal(v: DVec3) -> DVec3 {
    let helper = if v.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    v.cross(helper).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 45.0,
            orthographic_half_height: None,
            lens: None,
        }
    }

    /// Whether the camera's basis is defined (as `set_camera` checks it).
    fn defined(camera: &Camera) -> bool {
        let view = (camera.look_at - camera.eye).normalize();
        view.is_finite() && view.cross(camera.up.normalize()).length() > 1e-6
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    #[test]
    fn orbit_keeps_the_distance_and_the_look_at_point() {
        let start = camera();
        let distance = (start.eye - start.look_at).length();
        for (dx, dy) in [(100.0, 0.0), (0.0, 50.0), (-300.0, -80.0), (0.0, 10_000.0)] {
            let moved = orbit(&start, dx, dy);
            assert_eq!(moved.look_at, start.look_at);
            let d = (moved.eye - moved.look_at).length();
            assert!(
                (d - distance).abs() < 1e-9,
                "{dx},{dy}: {d} against {distance}"
            );
            assert!(moved.eye != start.eye, "{dx},{dy} moved nothing");
        }
        assert!(close(orbit(&start, 0.0, 0.0).eye, start.eye));
    }

    #[test]
    fn orbit_stops_short_of_the_poles() {
        for dy in [10_000.0, -10_000.0] {
            let moved = orbit(&camera(), 0.0, dy);
            let direction = (moved.eye - moved.look_at).normalize();
            let angle = direction.dot(DVec3::Y).abs().acos();
            assert!(
                angle >= POLE_MARGIN * 0.99,
                "dy {dy}: {angle} rad from the pole"
            );
            assert!(defined(&moved), "dy {dy}: the view is undefined");
        }
    }

    #[test]
    fn orbit_left_right_turns_about_the_up_axis() {
        let start = camera();
        let moved = orbit(&start, 200.0, 0.0);
        // The height above the look-at point is unchanged.
        assert!((moved.eye.y - start.eye.y).abs() < 1e-9);
    }

    #[test]
    fn pan_moves_eye_and_look_at_together() {
        let start = camera();
        let moved = pan(&start, 40.0, -25.0, 720);
        let shift = moved.look_at - start.look_at;
        assert!(shift.length() > 0.0);
        assert!(close(moved.eye - start.eye, shift));
        // The shift lies in the view plane.
        let forward = (start.look_at - start.eye).normalize();
        assert!(shift.dot(forward).abs() < 1e-9);
        // A drag to the right moves the scene right: the camera moves left.
        let right = forward.cross(start.up).normalize();
        assert!(shift.dot(right) < 0.0);
    }

    #[test]
    fn zoom_scales_the_distance_and_never_reaches_the_look_at_point() {
        let start = camera();
        let distance = (start.eye - start.look_at).length();
        let closer = zoom(&start, 1.0);
        assert!(((closer.eye - closer.look_at).length() - distance * 0.9).abs() < 1e-9);
        let back = zoom(&closer, -1.0);
        assert!(close(back.eye, start.eye));
        let far_in = zoom(&start, 1e6);
        assert!((far_in.eye - far_in.look_at).length() >= MIN_DISTANCE);
        assert!(defined(&far_in));
    }
}
