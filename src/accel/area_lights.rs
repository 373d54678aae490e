//! The emitters of a scene for the path integrator, shared by both backends: every
//! emissive sphere, polygon, triangle and instanced mesh triangle with its radiance,
//! and the distribution by power by which next-event estimation picks one. The CPU
//! reference samples it (`src/cpu/path.rs`); the GPU uploads its entries
//! (`src/gpu/area_lights.rs`).

use glam::DVec3;

use super::{HitKey, PrimKind, PrimRef, SceneGeometry};
use crate::color::luminance;
use crate::scene::{Image, Material, project_to_plane};
use crate::texture::mean_texel;

/// An emissive shape that next-event estimation samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum EmitterShape {
    /// A sphere, sampled by the cone of directions it subtends.
    Sphere { center: DVec3, radius: f64 },
    /// A triangle (of a triangle, a mesh or a polygon), sampled uniformly by area; it
    /// emits on the side its unit `normal` points to, and on both if `two_sided`.
    Triangle {
        vertices: [DVec3; 3],
        normal: DVec3,
        two_sided: bool,
    },
}

/// One emitter: its shape, the surface a ray hits on it (an instanced mesh's triangle
/// with its instance), and its material's constant radiance (`Material::emission`; an
/// emission texture modulates it at the sampled point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Emitter {
    pub(crate) shape: EmitterShape,
    pub(crate) key: HitKey,
    pub(crate) radiance: DVec3,
}

/// The emissive spheres, polygons and triangles of a scene and the distribution by
/// which next-event estimation picks one: in proportion to luminance times area (its
/// power, up to π), so that every point of the flat emitters has the same density per
/// unit area. An emitter whose material has an emission texture counts with its
/// emission times the texture's mean texel ([`mean_texel`]); the radiance it adds is
/// looked up at the sampled point. Infinite planes are never sampled: their emission
/// is found by BRDF sampling alone.
#[derive(Debug, Clone, Default)]
pub struct AreaLights {
    emitters: Vec<Emitter>,
    /// The first emitter of each surface.
    first_of: std::collections::HashMap<HitKey, usize>,
    /// Cumulative selection weights.
    cdf: Vec<f64>,
    total: f64,
    /// Per material: the mean texel of its emission texture (1 without one), which
    /// scales its emitters' selection weights.
    power_scale: Vec<DVec3>,
}

impl AreaLights {
    /// The emitters of `geometry` with `materials` (in the lighting space) and the
    /// scene's `images` (for the mean of emission textures).
    pub fn new(geometry: &SceneGeometry, materials: &[Material], images: &[Image]) -> Self {
        let mut lights = Self {
            power_scale: materials
                .iter()
                .map(|m| match m.emission_texture {
                    Some(image) => images.get(image as usize).map_or(DVec3::ONE, mean_texel),
                    None => DVec3::ONE,
                })
                .collect(),
            ..Self::default()
        };
        let emission = |material: u32| materials[material as usize].emission;
        let two_sided = |material: u32| materials[material as usize].two_sided;
        // Emissive instanced meshes first (the order of hit keys, which the GPU's
        // binary search by surface needs): each instance's triangles moved to world
        // space for sampling (the BVH keeps the mesh once; the emitter list has every
        // copy).
        for (i, instance) in geometry.instances.iter().enumerate() {
            let radiance = emission(instance.material);
            if radiance.max_element() <= 0.0 {
                continue;
            }
            let mesh = &geometry.instanced_meshes[instance.mesh as usize];
            for j in 0..mesh.triangles.len() {
                let (t, _) = instance.world_triangle(mesh, j);
                let [a, b, c] = t.vertices;
                let normal = (b - a).cross(c - a).normalize_or_zero();
                if normal != DVec3::ZERO {
                    let key = HitKey {
                        prim: PrimRef::new(PrimKind::Triangle, j as u32),
                        instance: Some(i as u32),
                    };
                    lights.push_triangle(
                        t.vertices,
                        normal,
                        (instance.material, two_sided(instance.material)),
                        key,
                        radiance,
                    );
                }
            }
        }
        for (i, s) in geometry.spheres.iter().enumerate() {
            let radiance = emission(s.material);
            if radiance.max_element() > 0.0 {
                let area = 4.0 * std::f64::consts::PI * s.radius * s.radius;
                lights.push(
                    Emitter {
                        shape: EmitterShape::Sphere {
                            center: s.center,
                            radius: s.radius,
                        },
                        key: HitKey::world(PrimRef::new(PrimKind::Sphere, i as u32)),
                        radiance,
                    },
                    area,
                    s.material,
                );
            }
        }
        for (i, p) in geometry.polygons.iter().enumerate() {
            let radiance = emission(p.material);
            if radiance.max_element() <= 0.0 || p.plane.normal == DVec3::ZERO {
                continue;
            }
            let prim = HitKey::world(PrimRef::new(PrimKind::Polygon, i as u32));
            for vertices in polygon_triangles(&p.vertices, p.plane.dropped_axis) {
                lights.push_triangle(
                    vertices,
                    p.plane.normal,
                    (p.material, two_sided(p.material)),
                    prim,
                    radiance,
                );
            }
        }
        for (i, t) in geometry.triangles.iter().enumerate() {
            let radiance = emission(t.material);
            if radiance.max_element() <= 0.0 {
                continue;
            }
            let [a, b, c] = t.vertices;
            let normal = (b - a).cross(c - a).normalize_or_zero();
            if normal != DVec3::ZERO {
                let prim = HitKey::world(PrimRef::new(PrimKind::Triangle, i as u32));
                lights.push_triangle(
                    t.vertices,
                    normal,
                    (t.material, two_sided(t.material)),
                    prim,
                    radiance,
                );
            }
        }
        lights
    }

    /// Adds a flat emitter; `material` is its material index and whether that emits
    /// from both sides.
    fn push_triangle(
        &mut self,
        vertices: [DVec3; 3],
        normal: DVec3,
        (material, two_sided): (u32, bool),
        key: HitKey,
        radiance: DVec3,
    ) {
        let [a, b, c] = vertices;
        let area = 0.5 * (b - a).cross(c - a).length();
        if area > 0.0 {
            self.push(
                Emitter {
                    shape: EmitterShape::Triangle {
                        vertices,
                        normal,
                        two_sided,
                    },
                    key,
                    radiance,
                },
                area,
                material,
            );
        }
    }

    /// Adds an emitter of `area` and material index `material`, weighted by the
    /// luminance of its radiance times the mean of its emission texture, times `area`.
    fn push(&mut self, emitter: Emitter, area: f64, material: u32) {
        let power = emitter.radiance
            * self
                .power_scale
                .get(material as usize)
                .copied()
                .unwrap_or(DVec3::ONE);
        let weight = luminance(power).max(1e-12 * power.max_element()) * area;
        if !(weight > 0.0 && weight.is_finite()) {
            return;
        }
        self.total += weight;
        self.cdf.push(self.total);
        self.first_of
            .entry(emitter.key)
            .or_insert(self.emitters.len());
        self.emitters.push(emitter);
    }

    /// Whether the scene has any emitter to sample.
    pub fn is_empty(&self) -> bool {
        self.emitters.is_empty()
    }

    /// The emitters in selection order, which is ascending hit-key order (instances'
    /// triangles first, by instance and triangle, then the scene's own primitives),
    /// each with its cumulative and own selection probabilities (for the GPU twin's
    /// upload, `crate::gpu::area_lights`).
    pub fn entries(&self) -> Vec<EmitterEntry> {
        self.emitters
            .iter()
            .enumerate()
            .map(|(index, emitter)| {
                let below = if index == 0 { 0.0 } else { self.cdf[index - 1] };
                let (shape, area) = match emitter.shape {
                    EmitterShape::Sphere { center, radius } => (
                        EmitterEntryShape::Sphere { center, radius },
                        4.0 * std::f64::consts::PI * radius * radius,
                    ),
                    EmitterShape::Triangle {
                        vertices,
                        normal,
                        two_sided,
                    } => {
                        let [a, b, c] = vertices;
                        (
                            EmitterEntryShape::Triangle {
                                vertices,
                                normal,
                                two_sided,
                            },
                            0.5 * (b - a).cross(c - a).length(),
                        )
                    }
                };
                EmitterEntry {
                    shape,
                    prim: emitter.key.prim,
                    instance: emitter.key.instance,
                    radiance: emitter.radiance,
                    cdf: self.cdf[index] / self.total,
                    selection: (self.cdf[index] - below) / self.total,
                    area,
                }
            })
            .collect()
    }

    /// The first emitter piece of the surface `key` and its selection probability
    /// (every piece of one surface has the same density per unit area).
    pub(crate) fn first_piece(&self, key: &HitKey) -> Option<(&Emitter, f64)> {
        let &index = self.first_of.get(key)?;
        let below = if index == 0 { 0.0 } else { self.cdf[index - 1] };
        Some((
            &self.emitters[index],
            (self.cdf[index] - below) / self.total,
        ))
    }

    /// The emitter chosen by `u ∈ [0, 1)` and its selection probability.
    pub(crate) fn choose(&self, u: f64) -> Option<(&Emitter, f64)> {
        let target = u * self.total;
        let index = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.emitters.len().checked_sub(1)?);
        let below = if index == 0 { 0.0 } else { self.cdf[index - 1] };
        Some((
            &self.emitters[index],
            (self.cdf[index] - below) / self.total,
        ))
    }
}

/// The shape of an [`EmitterEntry`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EmitterEntryShape {
    /// A sphere, sampled by the cone of directions it subtends.
    Sphere {
        /// Its centre.
        center: DVec3,
        /// Its radius.
        radius: f64,
    },
    /// A triangle, sampled uniformly by area, emitting on the side of `normal` (on
    /// both if `two_sided`).
    Triangle {
        /// Its vertices.
        vertices: [DVec3; 3],
        /// The unit normal of its emitting side.
        normal: DVec3,
        /// Whether it emits from its back too.
        two_sided: bool,
    },
}

/// One emitter of [`AreaLights`] as the GPU twin uploads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterEntry {
    /// Its shape.
    pub shape: EmitterEntryShape,
    /// The primitive a ray hits on it (for an instance's triangle: its index in the
    /// instanced mesh).
    pub prim: PrimRef,
    /// The instance it belongs to ([`super::SceneGeometry::instances`]), if any.
    pub instance: Option<u32>,
    /// Its radiance.
    pub radiance: DVec3,
    /// The selection probability of it and every emitter before it.
    pub cdf: f64,
    /// Its selection probability.
    pub selection: f64,
    /// Its area.
    pub area: f64,
}

/// The triangles of a polygon of at most `MAX_POLYGON_VERTICES` vertices (earcut in
/// the projection dropping `dropped_axis`), for sampling it by area.
fn polygon_triangles(vertices: &[DVec3], dropped_axis: u32) -> Vec<[DVec3; 3]> {
    let projected: Vec<[f64; 2]> = vertices
        .iter()
        .map(|v| {
            let (u, w) = project_to_plane(*v, dropped_axis);
            [u, w]
        })
        .collect();
    let mut indices: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(projected.iter().copied(), &[] as &[u32], &mut indices);
    indices
        .chunks_exact(3)
        .map(|c| c.iter().map(|&i| vertices[i as usize]).collect::<Vec<_>>())
        .map(|t| [t[0], t[1], t[2]])
        .collect()
}
