//! A camera and lights for a model that brings none: the model's bounding box seen from
//! the front, slightly from the right and above, lit by a three-light studio rig.

use glam::DVec3;

use crate::scene::{Camera, Light};

/// Vertical field of view of [`default_camera`], in degrees.
pub const DEFAULT_FOV_Y_DEGREES: f64 = 40.0;
/// Azimuth of the default view, in degrees to the right (towards +x) of the +z axis, the
/// side glTF models face (glTF 2.0 §3.4: "the front of a glTF asset faces +Z").
const VIEW_AZIMUTH_DEGREES: f64 = 30.0;
/// Elevation of the default view above the horizontal plane, in degrees.
const VIEW_ELEVATION_DEGREES: f64 = 20.0;
/// Room left around the bounding sphere: it fills 1 / 1.1 of the narrower field of view.
const FRAMING_MARGIN: f64 = 1.1;

/// A camera that frames the box `bounds` (world-space `(min, max)`) in an image of
/// `aspect` (width over height; anything not positive and finite counts as 1): it looks
/// at the box's centre with +y up from 30° to the right of +z and 20° above, far enough
/// back that the sphere around the box fits the narrower of the two fields of view with a
/// 10% margin, at [`DEFAULT_FOV_Y_DEGREES`]. Without bounds (a model with no triangles)
/// it looks at the origin from `(0, 0, 5)`.
pub fn default_camera(bounds: Option<(DVec3, DVec3)>, aspect: f64) -> Camera {
    let fov_y = DEFAULT_FOV_Y_DEGREES.to_radians();
    let Some((low, high)) = bounds.filter(|(l, h)| l.is_finite() && h.is_finite()) else {
        return Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: DEFAULT_FOV_Y_DEGREES,
            orthographic_half_height: None,
            lens: None,
        };
    };
    let aspect = if aspect.is_finite() && aspect > 0.0 {
        aspect
    } else {
        1.0
    };
    let center = (low + high) * 0.5;
    let radius = ((high - low).length() * 0.5).max(f64::MIN_POSITIVE.sqrt());
    let half_y = fov_y * 0.5;
    let half_x = ((fov_y * 0.5).tan() * aspect).atan();
    let distance = FRAMING_MARGIN * radius / half_y.min(half_x).sin();
    let (azimuth, elevation) = (
        VIEW_AZIMUTH_DEGREES.to_radians(),
        VIEW_ELEVATION_DEGREES.to_radians(),
    );
    let direction = DVec3::new(
        azimuth.sin() * elevation.cos(),
        elevation.sin(),
        azimuth.cos() * elevation.cos(),
    );
    Camera {
        eye: center + direction * distance,
        look_at: center,
        up: DVec3::Y,
        fov_y_degrees: DEFAULT_FOV_Y_DEGREES,
        orthographic_half_height: None,
        lens: None,
    }
}

/// The default light rig: three white directional lights, so that it lights a model of
/// any size alike (irradiance in W/m² on a surface facing each light):
///
/// | light | comes from (towards) | irradiance |
/// |---|---|---|
/// | key | upper front left, `(-1, 2, 1.5)` | 2.5 |
/// | fill | front right, low, `(1.5, 0.3, 1)` | 0.8 |
/// | rim | behind, above, `(0.3, 1, -1.5)` | 1.2 |
///
/// A white Lambert surface (albedo 0.8) facing the key light has radiance
/// `0.8 / π × 2.5 ≈ 0.64`, well exposed in an sRGB image.
pub fn default_lights() -> Vec<Light> {
    let light = |towards: DVec3, irradiance: f64| Light::Directional {
        direction: -towards.normalize(),
        irradiance: DVec3::splat(irradiance),
    };
    vec![
        light(DVec3::new(-1.0, 2.0, 1.5), 2.5),
        light(DVec3::new(1.5, 0.3, 1.0), 0.8),
        light(DVec3::new(0.3, 1.0, -1.5), 1.2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit sphere's silhouette seen from the default camera touches the narrower
    /// field of view at 1/1.1 of its half-angle.
    #[test]
    fn the_default_camera_frames_the_bounding_sphere() {
        let (low, high) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        for aspect in [0.5, 1.0, 2.0] {
            let camera = default_camera(Some((low, high)), aspect);
            assert_eq!(camera.look_at, DVec3::ZERO);
            let distance = camera.eye.length();
            let radius = 3f64.sqrt();
            let seen = (radius / distance).asin();
            let half_y = (DEFAULT_FOV_Y_DEGREES * 0.5).to_radians();
            let half_x = (half_y.tan() * aspect).atan();
            let expected = half_y.min(half_x).sin() / FRAMING_MARGIN;
            assert!((seen.sin() - expected).abs() < 1e-12, "aspect {aspect}");
            assert!(camera.eye.z > 0.0 && camera.eye.y > 0.0 && camera.eye.x > 0.0);
        }
    }

    #[test]
    fn the_default_lights_are_directional_and_normalized() {
        for light in default_lights() {
            let Light::Directional { direction, .. } = light else {
                panic!("not directional: {light:?}");
            };
            assert!((direction.length() - 1.0).abs() < 1e-12);
        }
    }
}
