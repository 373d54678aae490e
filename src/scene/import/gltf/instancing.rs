//! `EXT_mesh_gpu_instancing` (Khronos glTF registry, "EXT_mesh_gpu_instancing"): a mesh
//! node placed many times, each instance a translation, rotation and scale applied
//! before the node's world transform (`NodeWorldXform * InstanceXform`, with
//! `InstanceXform = T * R * S`), read into the model's instance list as the placements
//! of several nodes are.

use ::gltf::accessor::{Accessor, DataType, Dimensions};
use glam::{DMat4, DQuat, DVec3};

use super::importer::Importer;
use crate::scene::SceneError;
use crate::scene::import::MAX_MODEL_INSTANCES;
use crate::scene::import::accessor::{Expect, Normalized, read};

/// The extension's name, as files list it.
pub(super) const GPU_INSTANCING: &str = "EXT_mesh_gpu_instancing";

/// Component types of `ROTATION`: floats, or normalized signed bytes or shorts (the
/// extension's table of attributes). `TRANSLATION` and `SCALE` are floats only.
const ROTATION_TYPES: &[DataType] = &[DataType::F32, DataType::I8, DataType::I16];

impl Importer<'_> {
    /// The instance transforms (`T * R * S`, each missing part the identity) that a
    /// node's `EXT_mesh_gpu_instancing` gives, or `None` where the node has no such
    /// extension. `name` describes the node for messages.
    ///
    /// Errors, naming the node and the attribute: extension JSON without an
    /// `attributes` object, an attribute that is not an accessor index or names none,
    /// accessors of different counts or of the wrong type, more instances than
    /// [`MAX_MODEL_INSTANCES`], and a translation, rotation or scale that is not finite
    /// or a rotation quaternion of length 0.
    pub(super) fn gpu_instances(
        &mut self,
        node: &::gltf::Node<'_>,
        name: &str,
    ) -> Result<Option<Vec<DMat4>>, SceneError> {
        let Some(extension) = node.extension_value(GPU_INSTANCING) else {
            return Ok(None);
        };
        let fail = |message: String| self.fail(format!("{name}: {GPU_INSTANCING}: {message}"));
        let Some(attributes) = extension.get("attributes").and_then(|a| a.as_object()) else {
            return Err(fail("it has no \"attributes\" object".into()));
        };
        let accessor = |key: &str| -> Result<Option<Accessor<'_>>, SceneError> {
            let Some(value) = attributes.get(key) else {
                return Ok(None);
            };
            let count = self.document.accessors().len();
            value
                .as_u64()
                .and_then(|index| usize::try_from(index).ok())
                .and_then(|index| self.document.accessors().nth(index))
                .map(Some)
                .ok_or_else(|| {
                    fail(format!(
                        "{key} is {value}, which is not the index of one of the file's {count} accessors"
                    ))
                })
        };
        let translation = accessor("TRANSLATION")?;
        let rotation = accessor("ROTATION")?;
        let scale = accessor("SCALE")?;
        let given: Vec<(&str, &Accessor<'_>)> = [
            ("TRANSLATION", &translation),
            ("ROTATION", &rotation),
            ("SCALE", &scale),
        ]
        .into_iter()
        .filter_map(|(key, accessor)| accessor.as_ref().map(|a| (key, a)))
        .collect();
        let Some(&(first, first_accessor)) = given.first() else {
            self.warn(format!(
                "{name}: {GPU_INSTANCING} gives none of TRANSLATION, ROTATION and SCALE; the mesh is placed once, by the node"
            ));
            return Ok(None);
        };
        let count = first_accessor.count();
        if let Some((key, other)) = given.iter().find(|(_, a)| a.count() != count) {
            return Err(fail(format!(
                "{first} has {count} elements but {key} has {} (every attribute must have the same count)",
                other.count()
            )));
        }
        if count > MAX_MODEL_INSTANCES {
            return Err(fail(format!(
                "{count} instances, more than the {MAX_MODEL_INSTANCES} accepted"
            )));
        }
        let read_attribute = |accessor: &Option<Accessor<'_>>,
                              key: &str,
                              dimensions: Dimensions,
                              types: &'static [DataType]|
         -> Result<Option<Vec<f64>>, SceneError> {
            let Some(accessor) = accessor else {
                return Ok(None);
            };
            let expect = Expect {
                name: key,
                dimensions,
                types,
                normalized: Normalized::Either,
            };
            read(accessor, &expect, &self.buffers)
                .map(Some)
                .map_err(&fail)
        };
        let floats = &[DataType::F32];
        let translations = read_attribute(&translation, "TRANSLATION", Dimensions::Vec3, floats)?;
        let rotations = read_attribute(&rotation, "ROTATION", Dimensions::Vec4, ROTATION_TYPES)?;
        let scales = read_attribute(&scale, "SCALE", Dimensions::Vec3, floats)?;
        (0..count)
            .map(|i| {
                instance_transform(
                    translations.as_deref().map(|t| &t[3 * i..3 * i + 3]),
                    rotations.as_deref().map(|r| &r[4 * i..4 * i + 4]),
                    scales.as_deref().map(|s| &s[3 * i..3 * i + 3]),
                )
                .map_err(|e| fail(format!("instance {i}: {e}")))
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }
}

/// One instance's `T * R * S` from its translation, rotation quaternion (x, y, z, w;
/// normalized here, as a node's is) and scale, each `None` for the identity.
fn instance_transform(
    translation: Option<&[f64]>,
    rotation: Option<&[f64]>,
    scale: Option<&[f64]>,
) -> Result<DMat4, String> {
    let translation = translation.map_or(DVec3::ZERO, DVec3::from_slice);
    let scale = scale.map_or(DVec3::ONE, DVec3::from_slice);
    if !translation.is_finite() {
        return Err(format!("its TRANSLATION {translation} is not finite"));
    }
    if !scale.is_finite() {
        return Err(format!("its SCALE {scale} is not finite"));
    }
    let rotation = rotation.map_or(DQuat::IDENTITY, DQuat::from_slice);
    let length = rotation.length();
    if !length.is_finite() || length == 0.0 {
        return Err(format!(
            "its ROTATION quaternion {rotation} is not a rotation"
        ));
    }
    Ok(DMat4::from_scale_rotation_translation(
        scale,
        rotation / length,
        translation,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_instance_is_translation_times_rotation_times_scale() {
        let quarter_turn_z = [
            0.0,
            0.0,
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        ];
        let m = instance_transform(
            Some(&[1.0, 2.0, 3.0]),
            Some(&quarter_turn_z),
            Some(&[2.0, 2.0, 2.0]),
        )
        .expect("a valid instance");
        // (1, 0, 0) → scale 2 → (2, 0, 0) → rotate 90° about z → (0, 2, 0) → + (1, 2, 3).
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 4.0, 3.0)).length() < 1e-12, "{p}");
        assert_eq!(instance_transform(None, None, None), Ok(DMat4::IDENTITY));
        // An unnormalized quaternion is normalized, as a node's rotation is.
        let doubled = instance_transform(None, Some(&[0.0, 0.0, 0.0, 2.0]), None);
        assert_eq!(doubled, Ok(DMat4::IDENTITY));
    }

    #[test]
    fn non_finite_parts_and_a_zero_quaternion_are_refused() {
        assert!(instance_transform(Some(&[f64::NAN, 0.0, 0.0]), None, None).is_err());
        assert!(instance_transform(None, None, Some(&[1.0, f64::INFINITY, 1.0])).is_err());
        assert!(instance_transform(None, Some(&[0.0; 4]), None).is_err());
    }
}
