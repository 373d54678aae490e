//! The path integrator's emitters on the device: the shared [`AreaLights`]
//! distribution (emitters chosen by power, spheres sampled by cone, triangles by area)
//! as a storage buffer of [`GpuEmitter`] records that `shaders/path.wgsl` samples, and
//! the constants it shares with `shaders/path_types.wgsl` (checked by
//! `tests/integration/layout.rs`).

use bytemuck::{Pod, Zeroable};

use crate::accel::SceneGeometry;
use crate::accel::{AreaLights, EmitterEntry, EmitterEntryShape};
use crate::gpu::layout::NO_INSTANCE;
use crate::gpu::upload::InstanceLayout;
use crate::scene::{Image, Material};

/// `FrameUniforms.flags`: trace with the path integrator (`FLAG_PATH` in WGSL).
pub const FLAG_PATH: u32 = 4;
/// `PathState.phase` of the path integrator's emitter shadow ray (`PHASE_EMITTER`).
pub const PHASE_EMITTER: u32 = 8;
/// `PathState.phase` of the path integrator once the lights are done and the emitter
/// sample is to be drawn (`PHASE_START_EMITTER`).
pub const PHASE_START_EMITTER: u32 = 11;
/// [`GpuEmitter::kind`] of a sphere.
pub const EMITTER_SPHERE: u32 = 0;
/// [`GpuEmitter::kind`] of a triangle.
pub const EMITTER_TRIANGLE: u32 = 1;
/// [`GpuEmitter::kind`] of the padding record of a scene without emitters.
pub const EMITTER_NONE: u32 = 2;
/// [`GpuEmitter::kind`] of a triangle that emits from both sides (a `two_sided`
/// material).
pub const EMITTER_TWO_SIDED_TRIANGLE: u32 = 3;

/// One emitter (`Emitter` in WGSL), in the CPU's selection order, which is ascending
/// (instance, [`crate::accel::PrimRef`]) order, the scene's own primitives (instance
/// `NO_INSTANCE`) last.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuEmitter {
    /// Sphere: its centre; triangle: its first vertex.
    pub v0: [f32; 3],
    /// `EMITTER_*`.
    pub kind: u32,
    /// Sphere: `(radius, 0, 0)`; triangle: its second vertex.
    pub v1: [f32; 3],
    /// The primitive a ray hits on it (a `PrimRef`).
    pub prim: u32,
    /// Triangle: its third vertex.
    pub v2: [f32; 3],
    /// Cumulative selection probability up to and including it.
    pub cdf: f32,
    /// Triangle: the unit normal of its emitting side.
    pub normal: [f32; 3],
    /// Its selection probability.
    pub selection: f32,
    /// Its radiance.
    pub radiance: [f32; 3],
    /// Triangle: selection probability over area (its density per unit area).
    pub area_density: f32,
    /// The instance a ray hits it in, or `NO_INSTANCE` for the scene's own primitives.
    pub instance: u32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

impl GpuEmitter {
    /// The padding record of a scene without emitters (a storage binding cannot be
    /// empty).
    pub const NONE: Self = Self {
        v0: [0.0; 3],
        kind: EMITTER_NONE,
        v1: [0.0; 3],
        prim: 0,
        v2: [0.0; 3],
        cdf: 0.0,
        normal: [0.0; 3],
        selection: 0.0,
        radiance: [0.0; 3],
        area_density: 0.0,
        instance: NO_INSTANCE,
        _pad0: 0,
        _pad1: 0,
        _pad2: 0,
    };
}

fn vec3(v: glam::DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// The record of one emitter of [`AreaLights::entries`].
pub fn emitter_record(entry: &EmitterEntry) -> GpuEmitter {
    let mut record = GpuEmitter {
        prim: entry.prim.0,
        instance: entry.instance.unwrap_or(NO_INSTANCE),
        cdf: entry.cdf as f32,
        selection: entry.selection as f32,
        radiance: vec3(entry.radiance),
        ..GpuEmitter::zeroed()
    };
    match entry.shape {
        EmitterEntryShape::Sphere { center, radius } => {
            record.kind = EMITTER_SPHERE;
            record.v0 = vec3(center);
            record.v1 = [radius as f32, 0.0, 0.0];
        }
        EmitterEntryShape::Triangle {
            vertices,
            normal,
            two_sided,
        } => {
            record.kind = if two_sided {
                EMITTER_TWO_SIDED_TRIANGLE
            } else {
                EMITTER_TRIANGLE
            };
            record.v0 = vec3(vertices[0]);
            record.v1 = vec3(vertices[1]);
            record.v2 = vec3(vertices[2]);
            record.normal = vec3(normal);
            record.area_density = (entry.selection / entry.area) as f32;
        }
    }
    record
}

/// The emitter records of `geometry` with `materials` (in the lighting space) and the
/// scene's `images`, as the CPU's [`AreaLights::new`] finds them, their instances named
/// by where `layout` puts the instances' records (after the tree the GPU walks: the
/// scene's, [`InstanceLayout::new`], or with the hardware traversal the analytic
/// shapes'); [`GpuEmitter::NONE`] alone when there are none.
pub fn emitter_records(
    geometry: &SceneGeometry,
    layout: &InstanceLayout,
    materials: &[Material],
    images: &[Image],
) -> Vec<GpuEmitter> {
    let mut records: Vec<GpuEmitter> = AreaLights::new(geometry, materials, images)
        .entries()
        .iter()
        .map(|entry| {
            let mut record = emitter_record(entry);
            if let Some(instance) = entry.instance {
                // The names the GPU's hits carry: the triangle's place in the
                // triangle buffer and the node index of the instance's records.
                (record.prim, record.instance) =
                    layout.surface(geometry, instance, entry.prim.index());
            }
            record
        })
        .collect();
    if let Some(last) = records.last_mut() {
        // The last cumulative probability is 1 exactly, whatever the rounding.
        last.cdf = 1.0;
    } else {
        records.push(GpuEmitter::NONE);
    }
    records
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::accel::{BuildMethod, PrimKind, PrimRef};
    use crate::scene::{MaterialKind, Shape};

    #[test]
    fn records_are_in_ascending_prim_order_with_a_cumulative_distribution() {
        let lamp = Material {
            emission: DVec3::splat(4.0),
            ..Material::blank(MaterialKind::Emissive)
        };
        let materials = [Material::lambert(DVec3::splat(0.5)), lamp];
        let square = [
            DVec3::new(-1.0, 2.0, -1.0),
            DVec3::new(1.0, 2.0, -1.0),
            DVec3::new(1.0, 2.0, 1.0),
            DVec3::new(-1.0, 2.0, 1.0),
        ];
        let shapes = [
            Shape::Triangle {
                vertices: [DVec3::ZERO, DVec3::X, DVec3::Z],
                material: 1,
            },
            Shape::Polygon {
                vertices: square.to_vec(),
                material: 1,
            },
            Shape::Sphere {
                center: DVec3::new(0.0, 3.0, 0.0),
                radius: 0.5,
                material: 1,
            },
            Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
                material: 0,
            },
        ];
        let geometry = SceneGeometry::from_shapes(&shapes, BuildMethod::Sah);
        let records = emitter_records(&geometry, &InstanceLayout::new(&geometry), &materials, &[]);
        // The lamp sphere, the square's two triangles, the triangle.
        assert_eq!(records.len(), 4, "{records:?}");
        assert!(records.windows(2).all(|w| w[0].prim <= w[1].prim));
        assert!(records.windows(2).all(|w| w[0].cdf <= w[1].cdf));
        assert_eq!(records[0].kind, EMITTER_SPHERE);
        assert_eq!(PrimRef(records[1].prim).kind(), PrimKind::Polygon);
        assert_eq!(records[1].prim, records[2].prim);
        assert_eq!(records[3].kind, EMITTER_TRIANGLE);
        assert_eq!(records[3].cdf, 1.0);
        let total: f32 = records.iter().map(|r| r.selection).sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
        // Every piece of a flat emitter has the same density per unit area.
        assert!((records[1].area_density - records[3].area_density).abs() < 1e-6);
        let dark = [materials[0], materials[0]];
        assert_eq!(
            emitter_records(&geometry, &InstanceLayout::new(&geometry), &dark, &[]),
            vec![GpuEmitter::NONE]
        );
    }
}
