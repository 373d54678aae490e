//! `[[objects]]` entries and their geometric checks.

use std::collections::HashMap;

use glam::DVec3;
use toml::Spanned;

use super::LoadOptions;
use super::check::{Item, Source};
use super::raw::{RawColor, RawObject, RawVec3};
use crate::echo::{echo, echo_path, short, short3};
use crate::scene::import::{ImportOptions, ImportedModel, ModelPlacement, import_model_with};
use crate::scene::outline::MAX_POLYGON_VERTICES;
use crate::scene::{
    FAR_WALL_PRECISION_LIMIT, Light, SPHERE_PRECISION_LIMIT, SceneError, Shape, SurfacePrecision,
    coincident_spheres, far_wall_precision, flat_precision, sphere_precision,
};

const SPHERE_FIELDS: &[&str] = &["center", "radius", "material"];
const PLANE_FIELDS: &[&str] = &["point", "normal", "material"];
const POLYGON_FIELDS: &[&str] = &["vertices", "material"];
const TRIANGLE_FIELDS: &[&str] = &["vertices", "material"];
const MODEL_FIELDS: &[&str] = &["file", "material", "translate", "rotate", "scale", "smooth"];
/// A vertex farther than this fraction of the bounding-box diagonal from the polygon's
/// plane makes it non-planar.
const PLANARITY_TOLERANCE: f64 = 1e-6;
/// Twice the area, relative to the squared size of the shape, below which a polygon or
/// triangle counts as degenerate.
const DEGENERACY_TOLERANCE: f64 = 1e-12;

/// Material names (sorted) and their indices, for resolving references.
pub struct MaterialTable<'a> {
    indices: HashMap<&'a str, u32>,
    names: &'a [String],
    /// Whether each material emits light (an emitter's outline must be simple).
    emissive: Vec<bool>,
}

impl<'a> MaterialTable<'a> {
    /// The table for `names`, whose positions are the indices of `materials`.
    pub fn new(names: &'a [String], materials: &[crate::scene::Material]) -> Self {
        let indices = names
            .iter()
            .enumerate()
            .filter_map(|(i, n)| Some((n.as_str(), u32::try_from(i).ok()?)))
            .collect();
        let emissive = materials
            .iter()
            .map(|m| m.emission != DVec3::ZERO)
            .collect();
        Self {
            indices,
            names,
            emissive,
        }
    }

    /// Whether material `index` emits light.
    fn emits(&self, index: u32) -> bool {
        self.emissive.get(index as usize).copied().unwrap_or(false)
    }

    fn resolve(&self, item: &Item<'_>, name: &str) -> Result<u32, SceneError> {
        if let Some(&index) = self.indices.get(name) {
            return Ok(index);
        }
        let defined = if self.names.is_empty() {
            "no materials are defined".to_owned()
        } else {
            let quoted: Vec<String> = self
                .names
                .iter()
                .map(|n| format!("`{}`", echo(n)))
                .collect();
            format!("defined materials: {}", quoted.join(", "))
        };
        Err(item.fail(format_args!(
            "material `{}` is not defined ({defined})",
            echo(name)
        )))
    }
}

/// Object `index` (0-based, in file order), checked.
pub fn object(
    source: &Source<'_>,
    materials: &MaterialTable<'_>,
    index: usize,
    raw: Spanned<RawObject>,
) -> Result<Shape, SceneError> {
    let span = raw.span();
    let raw = raw.into_inner();
    let untyped = source.item(format!("objects[{index}]"), Some(span.clone()));
    let kind = untyped.require("type", raw.kind.clone())?;
    let item = source.item(format!("objects[{index}] ({kind})"), Some(span));
    let allowed = match kind.as_str() {
        "sphere" => SPHERE_FIELDS,
        "plane" => PLANE_FIELDS,
        "polygon" => POLYGON_FIELDS,
        "triangle" => TRIANGLE_FIELDS,
        other => {
            return Err(untyped.fail(format_args!(
                "unknown object type `{}` (expected one of: sphere, plane, polygon, \
                 triangle, model)",
                echo(other)
            )));
        }
    };
    item.only_fields(&kind, allowed, &raw.given_fields())?;
    let material_name = item.require("material", raw.material.as_deref())?;
    let material = materials.resolve(&item, material_name)?;
    match kind.as_str() {
        "sphere" => sphere(&item, &raw, material),
        "plane" => plane(&item, &raw, material),
        "polygon" => polygon(&item, &raw, material, materials.emits(material)),
        _ => triangle(&item, &raw, material),
    }
}

/// The model files a scene file has imported so far, each once, by its canonical path
/// (the path as joined where it cannot be canonicalised).
pub type ModelCache = std::collections::HashMap<std::path::PathBuf, std::rc::Rc<ImportedModel>>;

/// A `type = "model"` object, read and placed but not yet added to the scene.
pub struct PlacedModel {
    /// The model as imported, shared by every object that places the same file.
    pub model: std::rc::Rc<ImportedModel>,
    /// Where it stands, and the material that replaces its own, if any.
    pub placement: ModelPlacement,
}

/// Model object `index` (0-based, in file order): its file imported (relative to the
/// scene file's folder `base`) unless `cache` has it already (then its warnings are
/// not repeated), its transform checked.
pub fn model(
    source: &Source<'_>,
    materials: &MaterialTable<'_>,
    index: usize,
    raw: Spanned<RawObject>,
    base: &std::path::Path,
    options: &LoadOptions<'_>,
    cache: &mut ModelCache,
) -> Result<PlacedModel, SceneError> {
    let span = raw.span();
    let raw = raw.into_inner();
    let name = format!("objects[{index}] (model)");
    let item = source.item(name.clone(), Some(span.clone()));
    item.only_fields("model", MODEL_FIELDS, &raw.given_fields())?;
    let file = item.require("file", raw.file.as_deref())?;
    if options.sandbox {
        // The importers follow the model's own references (material libraries, glTF
        // buffers and images) without confinement, so a sandboxed scene may not load
        // models at all rather than let them name files outside its folder.
        return Err(item.fail(format_args!(
            "file `{}`: model objects are not accepted in sandboxed scenes (the files a \
             model names itself are not confined to the scene's folder)",
            echo_path(std::path::Path::new(file))
        )));
    }
    let material = raw
        .material
        .as_deref()
        .map(|name| materials.resolve(&item, name))
        .transpose()?;
    let translate = match raw.translate {
        Some(v) => item.vector("translate", v)?,
        None => DVec3::ZERO,
    };
    let rotate = match raw.rotate {
        Some(v) => item.vector("rotate", v)?,
        None => DVec3::ZERO,
    };
    let scale = match raw.scale {
        None => DVec3::ONE,
        Some(RawColor::Grey(s)) => DVec3::splat(item.number("scale", s)?),
        Some(RawColor::Rgb(v)) => item.vector("scale", v)?,
    };
    if scale.cmpeq(DVec3::ZERO).any() {
        return Err(item.fail(format_args!(
            "scale must not be 0 on any axis (it would flatten the model), got {}",
            short3(scale)
        )));
    }
    let transform = ModelPlacement::trs(translate, rotate, scale);
    // The importer's error names the model file and its element; this names the scene
    // object that asked for it.
    let path = base.join(file);
    let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
    let model = match cache.get(&key) {
        Some(model) => model.clone(),
        None => {
            let report = |done: u64, total: u64| {
                options.report(crate::scene::LoadProgress::Importing { done, total });
            };
            let import = ImportOptions {
                max_bytes: options.max_bytes,
                progress: Some(&report),
            };
            let model = import_model_with(&path, &import).map_err(|err| {
                item.fail(format_args!(
                    "file `{}`: {err}",
                    echo_path(std::path::Path::new(file))
                ))
            })?;
            if let Some(warn) = options.warning {
                for message in &model.warnings {
                    warn(&item.warning(message));
                }
            }
            let model = std::rc::Rc::new(model);
            cache.insert(key, model.clone());
            model
        }
    };
    Ok(PlacedModel {
        model,
        placement: ModelPlacement {
            transform,
            material,
            smooth: raw.smooth.unwrap_or(true),
        },
    })
}

fn sphere(item: &Item<'_>, raw: &RawObject, material: u32) -> Result<Shape, SceneError> {
    let center = item.vector("center", item.require("center", raw.center)?)?;
    let radius = item.number("radius", item.require("radius", raw.radius)?)?;
    if radius <= 0.0 {
        return Err(item.fail(format_args!("radius must be > 0, got {}", short(radius))));
    }
    Ok(Shape::Sphere {
        center,
        radius,
        material,
    })
}

/// The warning for a sphere, triangle or polygon that a backend cannot place precisely
/// enough, relative to its distance from the camera at `eye` (see
/// [`crate::scene::sphere_precision`] and [`crate::scene::flat_precision`]), or `None`
/// for a plane and for a shape both backends place well.
pub fn precision_warning(shape: &Shape, eye: DVec3) -> Option<String> {
    let (what, precision, remedy) = match shape {
        Shape::Sphere { center, radius, .. } => (
            format!("radius {radius:e}"),
            sphere_precision(*center, *radius, eye),
            "use a plane for a floor",
        ),
        Shape::Triangle { vertices, .. } => (
            "its corners".to_string(),
            flat_precision(vertices, eye),
            "split it into smaller triangles or use a plane for a floor",
        ),
        Shape::Polygon { vertices, .. } => (
            "its vertices".to_string(),
            flat_precision(vertices, eye),
            "split it into smaller polygons or use a plane for a floor",
        ),
        Shape::Plane { .. } => return None,
    };
    precision_message(&what, &precision, remedy)
}

/// The warning for a surface placed with `precision` (see [`precision_warning`]):
/// `None` where both backends place it well; `what` names the shape's size.
pub fn precision_message(what: &str, precision: &SurfacePrecision, remedy: &str) -> Option<String> {
    let consequence = match (precision.cpu_hopeless(), precision.gpu_hopeless()) {
        (false, false) => return None,
        (true, _) => format!("neither backend can place it precisely: {remedy}"),
        (false, true) => "the GPU cannot place it precisely (the CPU reference can: --backend \
             auto renders this scene on the CPU); move the scene nearer the origin or scale it"
            .to_string(),
    };
    Some(format!(
        "{what} at {:.3e} from the camera: its surface is placed to about {:.1e} units on \
         the CPU reference (f64, {:.1e} of that distance) and {:.1e} on the GPU (f32, \
         {:.1e}), more than {SPHERE_PRECISION_LIMIT:e}; {consequence}",
        precision.distance,
        precision.cpu,
        precision.cpu_relative(),
        precision.gpu,
        precision.gpu_relative(),
    ))
}

/// The extent of the scene that paths across a sphere around the camera come back to
/// ([`crate::scene::far_wall_precision`]): the largest side of the box around the eye,
/// the point lights, the polygons and triangles, and the spheres that neither contain
/// the eye nor are 100 times larger than their distance from it (those look like
/// planes from the camera, and planes, which are unbounded, are left out too).
pub fn scene_extent(shapes: &[Shape], lights: &[Light], eye: DVec3) -> f64 {
    let mut lo = eye;
    let mut hi = eye;
    let mut include = |a: DVec3, b: DVec3| {
        lo = lo.min(a);
        hi = hi.max(b);
    };
    for light in lights {
        if let Light::Point { position, .. } | Light::Spot { position, .. } = light {
            include(*position, *position);
        }
    }
    for shape in shapes {
        match shape {
            Shape::Sphere { center, radius, .. } => {
                let precision = sphere_precision(*center, *radius, eye);
                let inside = (eye - *center).length() < *radius;
                if !inside && precision.distance * 100.0 > *radius {
                    include(*center - *radius, *center + *radius);
                }
            }
            Shape::Polygon { vertices, .. } => vertices.iter().for_each(|v| include(*v, *v)),
            Shape::Triangle { vertices, .. } => vertices.iter().for_each(|v| include(*v, *v)),
            Shape::Plane { .. } => {}
        }
    }
    (hi - lo).max_element()
}

/// The warning for a sphere around the camera whose far side the GPU places to more
/// than [`FAR_WALL_PRECISION_LIMIT`] of `extent` ([`scene_extent`]), or `None`.
pub fn far_wall_warning(shape: &Shape, eye: DVec3, extent: f64) -> Option<String> {
    let Shape::Sphere { center, radius, .. } = shape else {
        return None;
    };
    // Zero (nothing but the eye) or NaN: nothing to judge against.
    if extent.is_nan() || extent <= 0.0 {
        return None;
    }
    let far = far_wall_precision(*center, *radius, eye, extent)?;
    far.hopeless().then(|| {
        format!(
            "radius {radius:e} around the camera: the GPU (f32) places points on its far \
             side, up to {:.1e} away, to about {:.1e} units, {:.1e} of the {:.1e} across \
             the rest of the scene spans (more than {FAR_WALL_PRECISION_LIMIT:e}); paths \
             that cross it and come back (shadow rays from its far side, reflections) may \
             pass the scene's objects on another side on the GPU than on the CPU \
             reference (--backend cpu); make the sphere smaller",
            2.0 * radius,
            far.gpu,
            far.relative(),
            extent,
        )
    })
}

/// The warning for two large spheres whose surfaces near the camera lie closer than
/// the GPU can place them ([`crate::scene::coincident_spheres`]), naming the other
/// sphere `other` (as `objects[K]`), or `None`.
pub fn coincident_warning(
    first: &Shape,
    second: &Shape,
    other: &str,
    eye: DVec3,
) -> Option<String> {
    let (
        Shape::Sphere {
            center: c1,
            radius: r1,
            ..
        },
        Shape::Sphere {
            center: c2,
            radius: r2,
            ..
        },
    ) = (first, second)
    else {
        return None;
    };
    let gap = coincident_spheres((*c1, *r1), (*c2, *r2), eye)?;
    let consequence = if gap.cpu < gap.gap {
        format!(
            "f32 rounding on the GPU (the CPU reference places them to {:.1e}: --backend \
             cpu)",
            gap.cpu
        )
    } else {
        format!(
            "rounding on both backends (the CPU reference, f64, places them to {:.1e})",
            gap.cpu
        )
    };
    Some(format!(
        "radius {r1:e}: near the camera its surface lies {:.1e} from that of {other}, \
         less than the {:.1e} to which the GPU (f32) places them, so which of the two \
         is in front is decided by {consequence}; move the spheres apart",
        gap.gap, gap.gpu,
    ))
}

fn plane(item: &Item<'_>, raw: &RawObject, material: u32) -> Result<Shape, SceneError> {
    let point = item.vector("point", item.require("point", raw.point)?)?;
    let normal = item.vector("normal", item.require("normal", raw.normal)?)?;
    let Some(normal) = normal.try_normalize() else {
        return Err(item.fail("normal is the zero vector"));
    };
    let offset = item.number("normal · point", normal.dot(point))?;
    Ok(Shape::Plane {
        normal,
        offset,
        material,
    })
}

fn vertices(item: &Item<'_>, raw: &RawObject) -> Result<Vec<DVec3>, SceneError> {
    let raw_vertices: &[RawVec3] = item.require("vertices", raw.vertices.as_deref())?;
    raw_vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| item.vector(&format!("vertices[{i}]"), v))
        .collect()
}

fn polygon(
    item: &Item<'_>,
    raw: &RawObject,
    material: u32,
    emissive: bool,
) -> Result<Shape, SceneError> {
    let vertices = vertices(item, raw)?;
    if vertices.len() < 3 {
        return Err(item.fail(format_args!(
            "a polygon needs at least 3 vertices, got {}",
            vertices.len()
        )));
    }
    let normal = check_planar_polygon(item, &vertices)?;
    check_simple_outline(item, &vertices, normal, emissive)?;
    Ok(Shape::Polygon { vertices, material })
}

/// Refuses an outline that crosses or touches itself where the tracers would not fill
/// it by the even-odd rule: beyond [`MAX_POLYGON_VERTICES`] vertices (where it is
/// triangulated) or on an emitter (whose area is sampled by its triangles). Smaller
/// outlines are filled by the even-odd crossing test, self-crossing or not.
fn check_simple_outline(
    item: &Item<'_>,
    vertices: &[DVec3],
    normal: DVec3,
    emissive: bool,
) -> Result<(), SceneError> {
    let large = vertices.len() > MAX_POLYGON_VERTICES;
    if !(large || emissive) {
        return Ok(());
    }
    let Some((i, j)) = crate::scene::outline::self_crossing(vertices, normal) else {
        return Ok(());
    };
    let why = if large {
        format!(
            "a polygon of more than {MAX_POLYGON_VERTICES} vertices is triangulated, which \
             needs a simple outline"
        )
    } else {
        "an emitting polygon's area is sampled by its triangles, which need a simple \
         outline"
            .to_owned()
    };
    Err(item.fail(format_args!(
        "the polygon's outline crosses itself: edge {i} (vertices {i}-{}) meets edge {j} \
         (vertices {j}-{}); {why}. Split it into polygons whose outlines do not cross \
         (polygons of at most {MAX_POLYGON_VERTICES} vertices that emit nothing are \
         filled by the even-odd rule whatever their outline)",
        (i + 1) % vertices.len(),
        (j + 1) % vertices.len()
    )))
}

fn triangle(item: &Item<'_>, raw: &RawObject, material: u32) -> Result<Shape, SceneError> {
    let vertices = vertices(item, raw)?;
    let Ok(vertices) = <[DVec3; 3]>::try_from(vertices.as_slice()) else {
        return Err(item.fail(format_args!(
            "a triangle needs exactly 3 vertices, got {}",
            vertices.len()
        )));
    };
    let [a, b, c] = vertices;
    let longest = (b - a).length().max((c - b).length()).max((a - c).length());
    let twice_area = (b - a).cross(c - a).length();
    if negligible(twice_area, longest * longest) {
        return Err(item
            .fail("the triangle is degenerate: its vertices are (nearly) collinear or coincide"));
    }
    Ok(Shape::Triangle { vertices, material })
}

/// Rejects degenerate polygons and those whose vertices do not lie on one plane;
/// returns the unit normal (Newell's).
fn check_planar_polygon(item: &Item<'_>, vertices: &[DVec3]) -> Result<DVec3, SceneError> {
    let centroid = vertices.iter().sum::<DVec3>() / vertices.len() as f64;
    let (min, max) = vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let diagonal = (max - min).length();
    let newell = newell_normal(vertices, centroid);
    if negligible(newell.length(), diagonal * diagonal) {
        return Err(item.fail("the polygon is degenerate: its vertices enclose (nearly) no area"));
    }
    let normal = newell.normalize();
    let (worst, distance) = vertices
        .iter()
        .map(|&v| (v - centroid).dot(normal).abs())
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, d)| if d > best.1 { (i, d) } else { best },
        );
    let tolerance = PLANARITY_TOLERANCE * diagonal;
    if distance > tolerance {
        return Err(item.fail(format_args!(
            "the polygon is not planar: vertex {worst} lies {distance:e} from the plane \
             through the centroid (tolerance {tolerance:e})"
        )));
    }
    Ok(normal)
}

/// Whether an area is (nearly) zero relative to `scale`, a squared length; also true
/// when the comparison is undefined (NaN from overflowing coordinates).
fn negligible(twice_area: f64, scale: f64) -> bool {
    twice_area.partial_cmp(&(DEGENERACY_TOLERANCE * scale)) != Some(std::cmp::Ordering::Greater)
}

/// Newell's normal (twice the area vector) of the closed loop `vertices`, computed
/// relative to `origin` for accuracy.
fn newell_normal(vertices: &[DVec3], origin: DVec3) -> DVec3 {
    let next = vertices.iter().cycle().skip(1);
    vertices
        .iter()
        .zip(next)
        .map(|(&a, &b)| (a - origin).cross(b - origin))
        .sum()
}
