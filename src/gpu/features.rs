//! Specialising the trace shader to a scene: code for primitive types, material models
//! and effects that the scene does not use is left out of the compiled module.
//!
//! The WGSL sources mark such code with line directives, `//#if NAME` (or
//! `//#if A || B`), `//#else` and `//#endif`, which may nest. [`specialise`] keeps or
//! drops the lines between them. This is plain source composition, chosen over WGSL
//! `override` constants because overrides only fold branches: the code (and the
//! registers it needs) stays in the module, and naga has no dead-function elimination
//! to remove it. Dropping the text means a module for a scene without glass really
//! has no refraction code, which `tests/integration/specialisation.rs` checks on the naga module.

use super::cpu_device::unrolled::UnrolledPrimitives;
use crate::accel::MAX_POLYGON_VERTICES;
use crate::scene::{Material, MaterialKind, Scene, Shape};

/// Which optional parts of the trace shader a module contains.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ShaderFeatures {
    /// Ray/sphere intersection (`SPHERES`).
    pub spheres: bool,
    /// Ray/plane intersection (`PLANES`).
    pub planes: bool,
    /// Ray/polygon intersection (`POLYGONS`).
    pub polygons: bool,
    /// Ray/triangle intersection (`TRIANGLES`).
    pub triangles: bool,
    /// Refraction through dielectrics and the medium stack (`REFRACTION`).
    pub refraction: bool,
    /// The normalized Blinn-Phong BRDF (`BLINN_PHONG`).
    pub blinn_phong: bool,
    /// The Cook-Torrance microfacet BRDF (`COOK_TORRANCE`).
    pub cook_torrance: bool,
    /// The Oren-Nayar BRDF (`OREN_NAYAR`).
    pub oren_nayar: bool,
    /// Tabulated BRDF maps (`TABULATED`).
    pub tabulated: bool,
    /// The glTF metal/roughness BRDF (`PBR`).
    pub pbr: bool,
    /// Albedo textures (`TEXTURES`).
    pub textures: bool,
    /// Mesh vertex normals and texture coordinates: smooth shading, the shadow
    /// terminator fix and UV lookups (`MESH_ATTRIBUTES`).
    pub mesh_attributes: bool,
    /// Instanced meshes: entering their trees with transformed rays, and their hit
    /// records (`INSTANCES`; see `crate::accel::instance`).
    pub instances: bool,
    /// The path-tracing integrator (`PATH`, `shaders/path.wgsl`); a module with it
    /// traces with it only when the trace's flags ask for it.
    pub path: bool,
    /// An environment map as the background and, for the path integrator, a light
    /// (`ENVIRONMENT_MAP`, `shaders/environment.wgsl`).
    pub environment_map: bool,
    /// Alpha coverage (`ALPHA`, glTF's `alphaMode` `MASK` and `BLEND`): the
    /// traversal finds each candidate hit's coverage (`hit_coverage` in
    /// `shaders/traverse.wgsl`), skipping a mask's points below its cutoff and passing
    /// blended surfaces as the trace's rule says; the integrators branch at blended
    /// hits. Scenes whose materials are all opaque compile the kernels without it, the
    /// general module too ([`ShaderFeatures::ALL`] leaves it out).
    pub alpha: bool,
    /// The auxiliary passes of the camera rays' first hits (`AOV`,
    /// `shaders/aov.wgsl`): chosen at upload ([`super::RendererOptions::aov`]), never
    /// by [`ShaderFeatures::for_scene`]; a module with it records them only when the
    /// trace's flags ask for it. The image does not depend on it.
    pub aov: bool,
    /// The records every traversal step reads (BVH nodes and primitive references,
    /// spheres, polygons and their points, triangles, materials, lights) are uniform
    /// arrays of a fixed length rather than storage buffers: chosen at upload for
    /// small scenes on CPU devices (see
    /// `src/gpu/cpu_device/uniform_records.rs`), never by [`ShaderFeatures::for_scene`]. Not a
    /// directive: the bindings' declarations differ, not the code.
    pub uniform_records: bool,
    /// The wide BVH nodes are read from the texels of a texture (`load_wide_node` of
    /// `src/gpu/cpu_device/node_texture.rs`) rather than from their storage buffer:
    /// chosen at upload on CPU devices for scenes whose records do not fit uniform
    /// arrays ([`ShaderFeatures::uniform_records`]), never by
    /// [`ShaderFeatures::for_scene`]. Not a directive either: only the declarations
    /// differ. The image does not depend on it.
    pub node_texture: bool,
    /// The fused kernel's Whitted traversals give way once few lanes of their subgroup
    /// still traverse, so that the lanes whose rays finished shade and start their
    /// next rays (`REFILL_LANES`; Aila and Laine's "replacing terminated rays", see
    /// `shaders/traverse.wgsl`). Needs [`wgpu::Features::SUBGROUP`], so it is chosen
    /// at upload from the device where [`super::RendererOptions::refill_lanes`] asks
    /// for it (see `super::scene_buffers`), never by [`ShaderFeatures::for_scene`],
    /// and [`ShaderFeatures::ALL`] leaves it out. The image does not depend on it.
    pub refill_lanes: bool,
    /// The fused kernel's Whitted samples start in lockstep: a lane whose sample is
    /// done waits for the other lanes of its subgroup to finish theirs, so that the
    /// rays a SIMD vector traverses together are all camera rays, or all shadow rays
    /// of one light, of neighbouring pixels (`LOCKSTEP_SAMPLES`, see
    /// `shaders/wavefront.wgsl`). Needs [`wgpu::Features::SUBGROUP`], so it is chosen
    /// at upload from the device where [`super::RendererOptions::lockstep_samples`]
    /// asks for it (see `super::scene_buffers`), never by
    /// [`ShaderFeatures::for_scene`], and [`ShaderFeatures::ALL`] leaves it out. The
    /// image does not depend on it.
    pub lockstep_samples: bool,
    /// The closest-hit test of a small scene as straight-line code over its primitives
    /// (`UNROLLED`; see [`super::cpu_device::unrolled`]), instead of the BVH's walk: chosen at
    /// upload for small scenes on CPU devices, never by [`ShaderFeatures::for_scene`],
    /// and [`ShaderFeatures::ALL`] leaves it out. The image does not depend on it.
    pub unrolled: Option<UnrolledPrimitives>,
    /// The scene's triangles are found by the device's ray queries in hardware
    /// acceleration structures, the analytic shapes by the software walk
    /// (`HARDWARE_TRAVERSAL`, `shaders/ray_query.wgsl`; see `super::ray_query`). Needs
    /// [`wgpu::Features::EXPERIMENTAL_RAY_QUERY`], so it is chosen at upload from the
    /// device and [`super::Traversal`], never by [`ShaderFeatures::for_scene`], and
    /// [`ShaderFeatures::ALL`] leaves it out. The image depends on it only where the
    /// hardware's triangle test and ours differ (an edge-grazing ray, a tie between
    /// two triangles: `docs/model.md`, "Hardware traversal").
    pub hardware_traversal: bool,
}

impl ShaderFeatures {
    /// Every feature but [`ShaderFeatures::alpha`]: the general module that renders
    /// any scene (with storage buffers for the records, which hold scenes of any
    /// size), to which the upload adds `alpha` for a scene whose materials need it
    /// (the alpha test inlined into every primitive test made lavapipe compile the
    /// general module's kernels many times slower, and opaque scenes keep the
    /// kernels they had).
    pub const ALL: Self = Self {
        spheres: true,
        planes: true,
        polygons: true,
        triangles: true,
        refraction: true,
        blinn_phong: true,
        cook_torrance: true,
        oren_nayar: true,
        tabulated: true,
        pbr: true,
        textures: true,
        mesh_attributes: true,
        instances: true,
        path: true,
        environment_map: true,
        alpha: false,
        aov: true,
        uniform_records: false,
        node_texture: false,
        refill_lanes: false,
        lockstep_samples: false,
        unrolled: None,
        hardware_traversal: false,
    };

    /// Exactly the features `scene` uses.
    pub fn for_scene(scene: &Scene) -> Self {
        let has_shape = |wanted: fn(&Shape) -> bool| scene.shapes.iter().any(wanted);
        let has_kind = |kind: MaterialKind| scene.materials.iter().any(|m| m.kind == kind);
        Self {
            spheres: has_shape(|s| matches!(s, Shape::Sphere { .. })),
            planes: has_shape(|s| matches!(s, Shape::Plane { .. })),
            // Polygons of many vertices are traced as their triangles (see
            // `crate::accel::MAX_POLYGON_VERTICES`).
            polygons: has_shape(
                |s| matches!(s, Shape::Polygon { vertices, .. } if vertices.len() <= MAX_POLYGON_VERTICES),
            ),
            triangles: !scene.meshes.is_empty()
                || has_shape(|s| {
                    matches!(s, Shape::Triangle { .. })
                        || matches!(s, Shape::Polygon { vertices, .. } if vertices.len() > MAX_POLYGON_VERTICES)
                }),
            refraction: has_kind(MaterialKind::Dielectric),
            blinn_phong: has_kind(MaterialKind::BlinnPhong),
            cook_torrance: has_kind(MaterialKind::CookTorrance),
            oren_nayar: has_kind(MaterialKind::OrenNayar),
            tabulated: has_kind(MaterialKind::Tabulated),
            pbr: has_kind(MaterialKind::Pbr),
            textures: scene.materials.iter().any(|m| {
                m.albedo_texture.is_some()
                    || m.metallic_roughness_texture.is_some()
                    || m.emission_texture.is_some()
                    || m.normal_texture.is_some()
            }),
            mesh_attributes: scene.meshes.iter().any(|m| {
                m.normals.is_some()
                    || m.uvs.is_some()
                    || m.uvs1.is_some()
                    || m.colors.is_some()
                    || m.tangents.is_some()
            }),
            instances: crate::accel::instance::has_instances(&scene.meshes),
            path: scene.render.integrator == crate::scene::Integrator::Path,
            environment_map: scene.environment.map.is_some(),
            alpha: scene.materials.iter().any(Material::uses_alpha),
            aov: false,
            uniform_records: false,
            node_texture: false,
            refill_lanes: false,
            lockstep_samples: false,
            unrolled: None,
            hardware_traversal: false,
        }
    }

    /// Whether the feature called `name` in the WGSL directives is on.
    fn named(&self, name: &str) -> Option<bool> {
        FEATURE_NAMES
            .iter()
            .find(|(known, _)| *known == name)
            .map(|(_, is_on)| is_on(self))
    }

    /// A short label for pipeline names, listing the features that are on.
    pub fn label(&self) -> String {
        let mut on: Vec<String> = FEATURE_NAMES
            .iter()
            .filter(|(_, is_on)| is_on(self))
            .map(|(name, _)| name.to_lowercase())
            .collect();
        if self.uniform_records {
            on.push("uniform_records".into());
        }
        if self.node_texture {
            on.push("node_texture".into());
        }
        if on.is_empty() {
            "none".into()
        } else {
            on.join("+")
        }
    }
}

/// Reads one flag of a feature set.
type FeatureFlag = fn(&ShaderFeatures) -> bool;

/// The name of each feature in the WGSL directives, with the flag it reads.
const FEATURE_NAMES: [(&str, FeatureFlag); 21] = [
    ("SPHERES", |f| f.spheres),
    ("PLANES", |f| f.planes),
    ("POLYGONS", |f| f.polygons),
    ("TRIANGLES", |f| f.triangles),
    ("REFRACTION", |f| f.refraction),
    ("BLINN_PHONG", |f| f.blinn_phong),
    ("COOK_TORRANCE", |f| f.cook_torrance),
    ("OREN_NAYAR", |f| f.oren_nayar),
    ("TABULATED", |f| f.tabulated),
    ("PBR", |f| f.pbr),
    ("TEXTURES", |f| f.textures),
    ("MESH_ATTRIBUTES", |f| f.mesh_attributes),
    ("INSTANCES", |f| f.instances),
    ("PATH", |f| f.path),
    ("ENVIRONMENT_MAP", |f| f.environment_map),
    ("ALPHA", |f| f.alpha),
    ("AOV", |f| f.aov),
    ("REFILL_LANES", |f| f.refill_lanes),
    ("LOCKSTEP_SAMPLES", |f| f.lockstep_samples),
    ("UNROLLED", |f| f.unrolled.is_some()),
    ("HARDWARE_TRAVERSAL", |f| f.hardware_traversal),
];

/// A malformed feature directive in a WGSL source: a bug in our own shaders, which the
/// tests catch. Lines count from 1.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DirectiveError {
    /// `//#if` names a feature that [`ShaderFeatures`] does not have.
    #[error("line {line}: unknown shader feature `{name}`")]
    UnknownFeature {
        /// The directive's line.
        line: usize,
        /// The unknown name.
        name: String,
    },
    /// `//#else` outside any `//#if` block.
    #[error("line {line}: //#else without //#if")]
    ElseWithoutIf {
        /// The directive's line.
        line: usize,
    },
    /// `//#endif` outside any `//#if` block.
    #[error("line {line}: //#endif without //#if")]
    EndifWithoutIf {
        /// The directive's line.
        line: usize,
    },
    /// The source ends inside `//#if` blocks.
    #[error("{count} //#if without //#endif")]
    UnclosedIf {
        /// The blocks left open.
        count: usize,
    },
}

/// Keeps the lines of `source` whose enclosing `//#if` directives hold for `features`
/// and removes the directive lines. An unknown feature name or unbalanced directives
/// are errors (they are bugs in our own shaders, caught by the tests).
pub fn specialise(source: &str, features: &ShaderFeatures) -> Result<String, DirectiveError> {
    let mut output = String::with_capacity(source.len());
    for (_, line) in kept_lines(source, features)? {
        output.push_str(line);
        output.push('\n');
    }
    Ok(output)
}

/// The lines [`specialise`] keeps, each with its line number in `source` (from 1), so
/// that what is read from them (the composer's `#import` lines) can be reported where
/// it was written.
pub(crate) fn kept_lines<'a>(
    source: &'a str,
    features: &ShaderFeatures,
) -> Result<Vec<(usize, &'a str)>, DirectiveError> {
    // One entry per open `//#if`: its condition and whether its `//#else` was reached.
    let mut open: Vec<(bool, bool)> = Vec::new();
    let mut kept = Vec::new();
    for (index, line) in source.lines().enumerate() {
        let number = index + 1;
        let directive = line.trim_start();
        if let Some(condition) = directive.strip_prefix("//#if ") {
            let mut value = false;
            for name in condition.split("||").map(str::trim) {
                value |= features
                    .named(name)
                    .ok_or_else(|| DirectiveError::UnknownFeature {
                        line: number,
                        name: name.to_string(),
                    })?;
            }
            open.push((value, false));
        } else if directive.starts_with("//#else") {
            let top = open
                .last_mut()
                .ok_or(DirectiveError::ElseWithoutIf { line: number })?;
            top.1 = true;
        } else if directive.starts_with("//#endif") {
            open.pop()
                .ok_or(DirectiveError::EndifWithoutIf { line: number })?;
        } else if open
            .iter()
            .all(|&(condition, in_else)| condition != in_else)
        {
            kept.push((number, line));
        }
    }
    if open.is_empty() {
        Ok(kept)
    } else {
        Err(DirectiveError::UnclosedIf { count: open.len() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_and_drops_nested_blocks() {
        let source = "a\n//#if REFRACTION\nb\n//#if SPHERES || PLANES\nc\n//#else\nd\n//#endif\n//#else\ne\n//#endif\nf\n";
        let none = ShaderFeatures {
            refraction: false,
            spheres: false,
            planes: false,
            ..ShaderFeatures::ALL
        };
        assert_eq!(
            specialise(source, &ShaderFeatures::ALL).as_deref(),
            Ok("a\nb\nc\nf\n")
        );
        assert_eq!(specialise(source, &none).as_deref(), Ok("a\ne\nf\n"));
        let planes_only = ShaderFeatures {
            spheres: false,
            ..ShaderFeatures::ALL
        };
        assert_eq!(
            specialise(source, &planes_only).as_deref(),
            Ok("a\nb\nc\nf\n")
        );
        let no_shapes = ShaderFeatures {
            refraction: true,
            ..none
        };
        assert_eq!(
            specialise(source, &no_shapes).as_deref(),
            Ok("a\nb\nd\nf\n")
        );
    }

    #[test]
    fn rejects_unknown_names_and_unbalanced_directives() {
        assert!(specialise("//#if GLITTER\n//#endif\n", &ShaderFeatures::ALL).is_err());
        assert!(specialise("//#if PBR\n", &ShaderFeatures::ALL).is_err());
        assert!(specialise("//#endif\n", &ShaderFeatures::ALL).is_err());
        assert_eq!(
            specialise("a\n//#if GLITTER\n//#endif\n", &ShaderFeatures::ALL),
            Err(DirectiveError::UnknownFeature {
                line: 2,
                name: "GLITTER".into()
            })
        );
        assert_eq!(
            specialise("//#else\n", &ShaderFeatures::ALL),
            Err(DirectiveError::ElseWithoutIf { line: 1 })
        );
        assert_eq!(
            specialise("//#if PBR\n//#if PBR\n//#endif\n", &ShaderFeatures::ALL),
            Err(DirectiveError::UnclosedIf { count: 1 })
        );
    }
}
