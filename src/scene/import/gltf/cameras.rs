//! glTF cameras: the first perspective or orthographic camera a node places.

use ::gltf::camera::Projection;
use glam::{DMat4, DVec3};

use super::importer::{Importer, describe};
use crate::echo::short;
use crate::scene::import::ImportedCamera;
use crate::scene::{Camera, MAX_ORTHOGRAPHIC_HALF_HEIGHT, SceneError};

impl Importer<'_> {
    /// Keeps the first perspective camera placed by a node.
    pub(super) fn camera(
        &mut self,
        camera: &::gltf::Camera<'_>,
        node: &str,
        world: DMat4,
    ) -> Result<(), SceneError> {
        let name = describe("camera", camera.index(), camera.name());
        if self.model.camera.is_some() {
            self.warn(format!(
                "{name} on {node}: only the first camera is imported; ignored"
            ));
            return Ok(());
        }
        // A perspective camera's vertical field of view, or an orthographic one's half
        // height (in its node's space; the node's scale applies) and xmag/ymag.
        let (fov_y_degrees, orthographic, aspect_ratio) = match camera.projection() {
            Projection::Perspective(perspective) => {
                let yfov = f64::from(perspective.yfov());
                if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
                    return Err(self.fail(format!("{name}: yfov {yfov} rad is not in (0, π)")));
                }
                let aspect_ratio = perspective.aspect_ratio().map(f64::from);
                if aspect_ratio.is_some_and(|a| !(a.is_finite() && a > 0.0)) {
                    return Err(self.fail(format!(
                        "{name}: aspectRatio {} is not positive",
                        aspect_ratio.unwrap_or_default()
                    )));
                }
                (yfov.to_degrees(), None, aspect_ratio)
            }
            Projection::Orthographic(orthographic) => {
                // glTF 2.0 §5.13: xmag and ymag must not be zero and should not be
                // negative; a negative one is taken by its size.
                let (xmag, ymag) = (
                    f64::from(orthographic.xmag()).abs(),
                    f64::from(orthographic.ymag()).abs(),
                );
                let y_scale = world.transform_vector3(DVec3::Y).length();
                let half_height = ymag * y_scale;
                let usable = |v: f64| v.is_finite() && v > 0.0 && v <= MAX_ORTHOGRAPHIC_HALF_HEIGHT;
                if !(usable(xmag) && usable(half_height)) {
                    // The half height the view gets is ymag times the node's scale along
                    // its y axis: say both, so that a scale of 0 is seen for what it is.
                    return Err(self.fail(format!(
                        "{name} on {node}: orthographic xmag {} and ymag {} times the node's y scale {} (a half height of {}) must be positive, finite and at most {}",
                        short(orthographic.xmag()),
                        short(orthographic.ymag()),
                        short(y_scale),
                        short(half_height),
                        short(MAX_ORTHOGRAPHIC_HALF_HEIGHT)
                    )));
                }
                (
                    super::super::DEFAULT_FOV_Y_DEGREES,
                    Some(half_height),
                    Some(xmag / ymag),
                )
            }
        };
        // glTF 2.0 §3.10.1: the camera looks along its local -z with +y up.
        let eye = world.transform_point3(DVec3::ZERO);
        let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
        let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
        if forward == DVec3::ZERO || up == DVec3::ZERO || forward.cross(up).length() < 1e-6 {
            self.warn(format!(
                "{name} on {node}: its transform leaves no view direction and up (singular or sheared); ignored"
            ));
            return Ok(());
        }
        self.model.camera = Some(ImportedCamera {
            name: camera.name().map_or_else(|| name.clone(), str::to_string),
            camera: Camera {
                eye,
                look_at: eye + forward,
                up,
                fov_y_degrees,
                orthographic_half_height: orthographic,
                lens: None,
            },
            aspect_ratio,
        });
        Ok(())
    }
}
