//! A primitive's vertex attributes beyond its positions: tangents, texture coordinates
//! and vertex colours, with the component types glTF (and `KHR_mesh_quantization`)
//! allows, and the checks of a position accessor's declared bounds and of quantized
//! types the file does not declare.

use ::gltf::accessor::{DataType, Dimensions};
use glam::{DVec2, DVec3, DVec4};

use super::extensions::MESH_QUANTIZATION;
use super::importer::Importer;
use crate::echo::short3;
use crate::scene::import::accessor::{Expect, Normalized, read};

/// Component types of `POSITION`: `FLOAT` (glTF 2.0 §3.7.2.1), and under
/// `KHR_mesh_quantization` (its table "Extending Mesh Attributes") signed and unsigned
/// bytes and shorts, normalized or not.
pub(super) const POSITION_TYPES: &[DataType] = &[
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];
/// Component types of `NORMAL`: `FLOAT`, and under `KHR_mesh_quantization` normalized
/// signed bytes and shorts.
pub(super) const NORMAL_TYPES: &[DataType] = &[DataType::F32, DataType::I8, DataType::I16];
/// Component types of `TEXCOORD_n`: `FLOAT` and normalized unsigned bytes and shorts
/// (glTF 2.0 §3.7.2.1), and under `KHR_mesh_quantization` also signed ones and both
/// not normalized.
pub(super) const TEXCOORD_TYPES: &[DataType] = &[
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];
/// Component types of `COLOR_0`: `FLOAT` and normalized unsigned bytes and shorts
/// (glTF 2.0 §3.7.2.1).
pub(super) const COLOR_TYPES: &[DataType] = &[DataType::F32, DataType::U8, DataType::U16];

impl Importer<'_> {
    /// Reads `TANGENT` of `primitive` (of `count` vertices), if it has it: `VEC4` of
    /// floats, or under `KHR_mesh_quantization` normalized signed bytes or shorts.
    pub(super) fn tangents(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Result<Option<Vec<glam::DVec4>>, String> {
        let Some(accessor) = primitive.get(&::gltf::Semantic::Tangents) else {
            return Ok(None);
        };
        if accessor.count() != count {
            return Err(format!(
                "TANGENT has {} elements but POSITION has {count}",
                accessor.count()
            ));
        }
        let values = read(
            &accessor,
            &Expect {
                name: "TANGENT",
                dimensions: Dimensions::Vec4,
                types: NORMAL_TYPES,
                normalized: Normalized::Always,
            },
            &self.buffers,
        )?;
        self.check_quantization(&accessor, name, "TANGENT", false);
        Ok(Some(
            values
                .chunks_exact(4)
                .map(|c| glam::DVec4::new(c[0], c[1], c[2], c[3]))
                .collect(),
        ))
    }

    /// Reads `TEXCOORD_{set}` of `primitive` (of `count` vertices), if it has it.
    pub(super) fn texcoords(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        set: u32,
        count: usize,
    ) -> Result<Option<Vec<DVec2>>, String> {
        let Some(accessor) = primitive.get(&::gltf::Semantic::TexCoords(set)) else {
            return Ok(None);
        };
        let uv_name = format!("TEXCOORD_{set}");
        if accessor.count() != count {
            return Err(format!(
                "{uv_name} has {} elements but POSITION has {count}",
                accessor.count()
            ));
        }
        let values = read(
            &accessor,
            &Expect {
                name: &uv_name,
                dimensions: Dimensions::Vec2,
                types: TEXCOORD_TYPES,
                normalized: Normalized::Either,
            },
            &self.buffers,
        )?;
        self.check_quantization(&accessor, name, &uv_name, true);
        Ok(Some(
            values
                .chunks_exact(2)
                .map(|c| DVec2::new(c[0], c[1]))
                .collect(),
        ))
    }

    /// Reads `COLOR_0` of `primitive` (of `count` vertices), if it has it: `VEC3` or
    /// `VEC4` of floats or normalized unsigned bytes or shorts (glTF 2.0 §3.7.2.1),
    /// `VEC3` with alpha 1. An accessor that breaks these rules is left out with a
    /// warning: the model still renders, in its materials' colours.
    pub(super) fn colors(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Option<Vec<DVec4>> {
        let accessor = primitive.get(&::gltf::Semantic::Colors(0))?;
        let dimensions = accessor.dimensions();
        let read_colors = || -> Result<Vec<f64>, String> {
            if accessor.count() != count {
                return Err(format!(
                    "COLOR_0 has {} elements but POSITION has {count}",
                    accessor.count()
                ));
            }
            if !matches!(dimensions, Dimensions::Vec3 | Dimensions::Vec4) {
                return Err(format!(
                    "COLOR_0 (accessor {}) holds {dimensions:?} elements, expected Vec3 or Vec4",
                    accessor.index()
                ));
            }
            read(
                &accessor,
                &Expect {
                    name: "COLOR_0",
                    dimensions,
                    types: COLOR_TYPES,
                    normalized: Normalized::Always,
                },
                &self.buffers,
            )
        };
        let values = match read_colors() {
            Ok(values) => values,
            Err(e) => {
                self.warn(format!("{name}: {e}; the vertex colours are ignored"));
                return None;
            }
        };
        let components = dimensions.multiplicity();
        Some(
            values
                .chunks_exact(components)
                .map(|c| DVec4::new(c[0], c[1], c[2], c.get(3).copied().unwrap_or(1.0)))
                .collect(),
        )
    }

    /// Warns when positions lie outside the `min` and `max` their accessor declares, as
    /// the glTF validator does (ACCESSOR_MIN_MISMATCH, ACCESSOR_MAX_MISMATCH): the
    /// declared bounds are wrong or the positions are damaged. The model is framed by
    /// the positions read, never by the declaration. A position within a relative
    /// 1e-5 of the declared box (the JSON numbers' rounding) is inside.
    pub(super) fn check_declared_bounds(
        &mut self,
        accessor: &::gltf::Accessor<'_>,
        primitive: &str,
        positions: &[DVec3],
    ) {
        let declared = |value: Option<::gltf::json::Value>| -> Option<DVec3> {
            let array = value?;
            let array = array.as_array()?;
            let component = |i: usize| array.get(i)?.as_f64();
            Some(DVec3::new(component(0)?, component(1)?, component(2)?))
        };
        let (Some(min), Some(max)) = (declared(accessor.min()), declared(accessor.max())) else {
            return;
        };
        let slack = (max - min).abs().max_element().max(1.0) * 1e-5;
        let outside = |p: &DVec3| {
            (0..3).any(|axis| !(p[axis] >= min[axis] - slack && p[axis] <= max[axis] + slack))
        };
        let count = positions.iter().filter(|p| outside(p)).count();
        let Some((first, at)) = positions.iter().enumerate().find(|(_, p)| outside(p)) else {
            return;
        };
        self.warn(format!(
            "{primitive}: POSITION (accessor {}) has {count} of {} vertices outside the min {} \
             and max {} it declares (the first, vertex {first}, at {}); the bounds are wrong or \
             the positions damaged, and the model is framed by the positions as read",
            accessor.index(),
            positions.len(),
            short3(min),
            short3(max),
            short3(*at)
        ));
    }

    /// Warns (once per file) when `accessor` holds one of the component types that only
    /// `KHR_mesh_quantization` allows but the file does not list the extension in
    /// `extensionsUsed` (glTF 2.0 §3.12: an extension a file uses must be listed). The
    /// values are unambiguous either way, so they are read.
    pub(super) fn check_quantization(
        &mut self,
        accessor: &::gltf::Accessor<'_>,
        primitive: &str,
        attribute: &str,
        texcoord: bool,
    ) {
        let data_type = accessor.data_type();
        let core = data_type == DataType::F32
            || (texcoord
                && accessor.normalized()
                && matches!(data_type, DataType::U8 | DataType::U16));
        if !core
            && !self
                .document
                .extensions_used()
                .any(|e| e == MESH_QUANTIZATION)
        {
            self.warn_once(
                "quantization",
                format!(
                    "{primitive}: {attribute} (accessor {}) holds {}{data_type:?} components, which only {MESH_QUANTIZATION} allows, but the file does not list that extension in extensionsUsed; read anyway",
                    accessor.index(),
                    if accessor.normalized() { "normalized " } else { "" }
                ),
            );
        }
    }
}
