//! Whole-pipeline fuzzing: valid but hostile scene files, generated as TOML text, that
//! must parse, render on both backends without a panic, give finite pixels, and agree
//! per pixel. Shared by `tests/integration/fuzz_pipeline.rs` (a bounded run in CI and the regression
//! corpus) and `tools/src/bin/fuzz_campaign.rs` (long campaigns); see `docs/fuzzing.md`.
//!
//! What is generated, all inside the ranges the loader accepts:
//! - a geometry scale from 1e-3 to 1e4 (lights scaled by its square), tiny images
//!   (1 × 1 to 12 × 10), 1 to 3 samples, depths 0 to 6 or 60 to 64 (these with a
//!   weight cutoff of at least 0.05, or glass would make the ray tree exponential),
//!   short bounce stacks, weight cutoffs, both lighting spaces, fields of view from
//!   0.5° to 179°;
//! - every material type, with extreme but legal parameters (shininess 0 and 1e6,
//!   roughness 0 and 1, indices of refraction from 1 to 10, 1.0001, metallic 0 and 1,
//!   Oren-Nayar σ 90°);
//! - up to 40 lights, point and directional, some with intensities of 1e22 (times the
//!   scale's square for point lights: at most the 1e30 the loader accepts);
//! - spheres (including "ground" spheres of radius up to 1e4 times the scale
//!   (and 1e8, since spheres are intersected relative to their anchor), tangent
//!   pairs and up to 7 concentric dielectric shells, more than the medium stack's 4),
//!   planes, polygons of up to 300 vertices (regular, star-shaped and so concave) in any
//!   orientation, and triangles, some of them slivers.

use std::fmt::Write as _;
use std::panic::AssertUnwindSafe;

use gpu_render::film::LinearImage;
use gpu_render::gpu::{HeadlessGpu, Renderer, RendererOptions};
use proptest::prelude::*;

use crate::support::compare::{Comparison, Tolerance, measure};

/// The rule of `tests/integration/gpu_vs_cpu.rs` (a channel passes when `|gpu - cpu| <= 1e-3 +
/// 5e-3·|cpu|`), with the outliers counted in pixels rather than as a fraction: a
/// 12 × 10 image has 120 pixels, so 0.5% would allow none, while one random sample
/// that grazes a silhouette, a shadow edge or the critical angle can fall on the other
/// side in f32 and f64. At most [`OUTLIER_PIXELS`] pixels may fail.
pub const TOLERANCE: Tolerance = Tolerance {
    absolute: 1e-3,
    relative: 5e-3,
    outlier_fraction: 0.0,
};

/// Pixels allowed outside [`TOLERANCE`] in one image (edge samples; see there).
pub const OUTLIER_PIXELS: usize = 2;

/// A generated scene file's text.
pub fn scene_text() -> impl Strategy<Value = String> {
    (
        settings(),
        camera(),
        environment(),
        prop::collection::vec(material(), 1..6),
        lights(),
        prop::collection::vec(object(), 0..7),
    )
        // A camera on a surface is ill-posed (which side it is on, and the first hit at
        // t ≈ 0, depend on the last bit), and so is a point light on one (the surface
        // around it is lit at cos θ ≈ 0, whose sign and relative size are rounding);
        // shrinking drives coordinates to 0, onto the ground spheres' tops. Keep the
        // eye and the point lights 1e-3 (in units of the scale) off every sphere and
        // plane.
        .prop_filter(
            "the eye or a point light lies on a surface",
            |(_, camera, _, _, lights, objects)| {
                let points = lights
                    .iter()
                    .filter_map(|l| match l {
                        LightSpec::Point { position, .. } => Some(*position),
                        LightSpec::Directional { .. } => None,
                    })
                    .chain(std::iter::once(camera.eye))
                    .collect::<Vec<_>>();
                objects
                    .iter()
                    .all(|o| points.iter().all(|&p| o.distance_from(p) > 1e-3))
            },
        )
        .prop_map(
            |(settings, camera, environment, materials, lights, objects)| {
                let mut text = String::new();
                text.push_str(&settings);
                text.push_str(&camera.text(settings_scale(&settings)));
                text.push_str(&environment);
                let count = materials.len();
                for (i, material) in materials.iter().enumerate() {
                    let _ = writeln!(text, "[materials.m{i}]\n{material}");
                }
                // Dielectric shells need a dielectric; every scene has one more material.
                let _ = writeln!(
                    text,
                    "[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n"
                );
                let _ = writeln!(
                    text,
                    "[materials.water]\ntype = \"dielectric\"\nior = 1.33\n"
                );
                let scale = settings_scale(&settings);
                for light in &lights {
                    text.push_str(&light.text(scale));
                }
                for object in &objects {
                    text.push_str(&object.text(scale, count));
                }
                text
            },
        )
}

/// The scale recorded in the settings' first comment line.
fn settings_scale(settings: &str) -> f64 {
    settings
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("# scale "))
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0)
}

/// A float as TOML writes it (Rust's shortest round-trip form is valid TOML).
fn num(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) {
        s
    } else {
        format!("{s}.0")
    }
}

fn vector(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]))
}

fn settings() -> impl Strategy<Value = String> {
    (
        prop::sample::select(vec![1e-3, 1e-2, 1.0, 1.0, 1.0, 10.0, 1e2, 1e4]),
        1u32..=12,
        1u32..=10,
        1u32..=3,
        // Whitted's tree doubles at every dielectric hit: a depth of 60 or more comes
        // with a weight cutoff of at least 0.05, which bounds it (see docs/fuzzing.md).
        prop_oneof![
            (
                0u32..=6,
                prop::sample::select(vec![0.0, 0.0, 0.0, 0.01, 0.5, 1.0])
            ),
            (60u32..=64, prop::sample::select(vec![0.05, 0.1, 0.5, 1.0])),
        ],
        prop::option::weighted(0.2, 1u32..=4),
        prop::bool::weighted(0.15),
    )
        .prop_map(
            |(scale, width, height, spp, (depth, cutoff), stack, gamma)| {
                let mut s = format!(
                    "# scale {scale:?}\n[render]\nwidth = {width}\nheight = {height}\n\
                     samples_per_pixel = {spp}\nmax_depth = {depth}\nmin_ray_weight = {}\n",
                    num(cutoff)
                );
                if let Some(stack) = stack {
                    let _ = writeln!(s, "stack_size = {stack}");
                }
                if gamma {
                    s.push_str("lighting = \"naive_gamma\"\n");
                }
                s.push('\n');
                s
            },
        )
}

#[derive(Debug, Clone)]
struct CameraSpec {
    eye: [f64; 3],
    look_at: [f64; 3],
    fov: f64,
}

impl CameraSpec {
    fn text(&self, scale: f64) -> String {
        let eye = self.eye.map(|c| c * scale);
        let look_at = self.look_at.map(|c| c * scale);
        let view = [
            look_at[0] - eye[0],
            look_at[1] - eye[1],
            look_at[2] - eye[2],
        ];
        let length = (view[0] * view[0] + view[1] * view[1] + view[2] * view[2]).sqrt();
        // Up must not be parallel to the view: take x when the view is nearly vertical.
        let up = if (view[0] * view[0] + view[2] * view[2]).sqrt() < 1e-3 * length {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        format!(
            "[camera]\neye = {}\nlook_at = {}\nup = {}\nfov_y_degrees = {}\n\n",
            vector(eye),
            vector(look_at),
            vector(up),
            num(self.fov)
        )
    }
}

fn coordinate(range: f64) -> impl Strategy<Value = f64> {
    (-range..range).prop_map(|x| (x * 1000.0).round() / 1000.0)
}

fn point(range: f64) -> impl Strategy<Value = [f64; 3]> {
    [coordinate(range), coordinate(range), coordinate(range)]
}

fn camera() -> impl Strategy<Value = CameraSpec> {
    (
        point(6.0),
        point(1.0),
        prop::sample::select(vec![0.5, 10.0, 45.0, 45.0, 60.0, 90.0, 150.0, 179.0]),
    )
        .prop_filter("eye and look_at must differ", |(eye, look_at, _)| {
            eye.iter().zip(look_at).any(|(a, b)| (a - b).abs() > 0.05)
        })
        .prop_map(|(eye, look_at, fov)| CameraSpec { eye, look_at, fov })
}

fn fraction() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![0.0, 0.05, 0.3, 0.5, 0.8, 0.95, 1.0])
}

fn colour() -> impl Strategy<Value = String> {
    prop_oneof![
        fraction().prop_map(num),
        [fraction(), fraction(), fraction()].prop_map(vector),
    ]
}

fn radiance() -> impl Strategy<Value = String> {
    prop::sample::select(vec![0.0, 0.0, 0.01, 0.3, 1.0, 4.0, 1e3]).prop_map(num)
}

fn environment() -> impl Strategy<Value = String> {
    (
        radiance(),
        prop::sample::select(vec![0.0, 0.0, 0.0, 0.05, 0.5]),
    )
        .prop_map(|(background, ambient)| {
            format!(
                "[environment]\nbackground = {background}\nambient = {}\n\n",
                num(ambient)
            )
        })
}

fn emission_line() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => Just(String::new()),
        1 => radiance().prop_map(|r| format!("emission = {r}\n")),
    ]
}

fn coat_line() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => Just(String::new()),
        1 => prop::sample::select(vec![1.0, 1.0001, 1.5, 3.0, 10.0])
            .prop_map(|ior| format!("coat_ior = {}\n", num(ior))),
    ]
}

fn ior() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![1.0, 1.0001, 1.33, 1.5, 1.5, 2.42, 4.0, 10.0])
}

fn material() -> impl Strategy<Value = String> {
    prop_oneof![
        (colour(), coat_line(), emission_line()).prop_map(|(albedo, coat, emission)| format!(
            "type = \"lambert\"\nalbedo = {albedo}\n{coat}{emission}"
        )),
        (
            fraction(),
            fraction(),
            prop::sample::select(vec![0.0, 1.0, 50.0, 1e4, 1e6]),
            coat_line(),
        )
            .prop_map(|(diffuse, specular, shininess, coat)| format!(
                "type = \"blinn_phong\"\ndiffuse = {}\nspecular = {}\nshininess = {}\n{coat}",
                num(diffuse),
                num(specular * (1.0 - diffuse)),
                num(shininess)
            )),
        (colour(), emission_line()).prop_map(|(reflectance, emission)| format!(
            "type = \"mirror\"\nreflectance = {reflectance}\n{emission}"
        )),
        (ior(), colour()).prop_map(|(ior, transmittance)| format!(
            "type = \"dielectric\"\nior = {}\ntransmittance = {transmittance}\n",
            num(ior)
        )),
        radiance().prop_map(|radiance| format!("type = \"emissive\"\nradiance = {radiance}\n")),
        (
            prop::sample::select(vec![0.0, 0.01, 0.3, 1.0]),
            prop::sample::select(vec!["ggx", "beckmann"]),
            prop::sample::select(vec!["exact", "schlick"]),
            prop_oneof![
                prop::sample::select(vec!["gold", "silver", "copper", "aluminium"])
                    .prop_map(|c| format!("conductor = \"{c}\"\n")),
                (ior(), fraction()).prop_map(|(ior, d)| format!(
                    "ior = {}\ndiffuse = {}\n",
                    num(ior),
                    num(d)
                )),
            ],
        )
            .prop_map(|(roughness, distribution, fresnel, base)| format!(
                "type = \"cook_torrance\"\nroughness = {}\ndistribution = \"{distribution}\"\n\
                 fresnel = \"{fresnel}\"\n{base}",
                num(roughness)
            )),
        (colour(), prop::sample::select(vec![0.0, 20.0, 90.0])).prop_map(|(albedo, sigma)| {
            format!(
                "type = \"oren_nayar\"\nalbedo = {albedo}\nsigma_degrees = {}\n",
                num(sigma)
            )
        }),
        (colour(), fraction(), fraction()).prop_map(|(base, metallic, roughness)| format!(
            "type = \"pbr\"\nbase_color = {base}\nmetallic = {}\nroughness = {}\n",
            num(metallic),
            num(roughness)
        )),
    ]
}

#[derive(Debug, Clone)]
enum LightSpec {
    Point {
        position: [f64; 3],
        intensity: f64,
    },
    Directional {
        direction: [f64; 3],
        irradiance: f64,
    },
}

impl LightSpec {
    fn text(&self, scale: f64) -> String {
        match self {
            LightSpec::Point {
                position,
                intensity,
            } => format!(
                "[[lights]]\ntype = \"point\"\nposition = {}\nintensity = {}\n\n",
                vector(position.map(|c| c * scale)),
                num(intensity * scale * scale)
            ),
            LightSpec::Directional {
                direction,
                irradiance,
            } => format!(
                "[[lights]]\ntype = \"directional\"\ndirection = {}\nirradiance = {}\n\n",
                vector(*direction),
                num(*irradiance)
            ),
        }
    }
}

fn light() -> impl Strategy<Value = LightSpec> {
    // The largest times the largest scale squared (1e4²) is the loader's limit, 1e30.
    let strength = prop::sample::select(vec![0.0, 0.5, 5.0, 20.0, 100.0, 1e22]);
    prop_oneof![
        (point(6.0), strength.clone()).prop_map(|(position, intensity)| LightSpec::Point {
            position,
            intensity
        }),
        (point(1.0), strength)
            .prop_filter("a direction is non-zero", |(d, _)| d
                .iter()
                .any(|c| c.abs() > 0.01))
            .prop_map(|(direction, irradiance)| LightSpec::Directional {
                direction,
                irradiance
            }),
    ]
}

fn lights() -> impl Strategy<Value = Vec<LightSpec>> {
    prop_oneof![
        4 => prop::collection::vec(light(), 0..4),
        1 => prop::collection::vec(light(), 20..41),
    ]
}

#[derive(Debug, Clone)]
enum ObjectSpec {
    Sphere {
        center: [f64; 3],
        radius: f64,
        material: usize,
    },
    /// A sphere of radius `radius` (in units of the scale) resting on y = 0 below `at`.
    Ground {
        at: [f64; 3],
        radius: f64,
        material: usize,
    },
    /// Two spheres touching at one point.
    Tangent {
        center: [f64; 3],
        radius: f64,
        material: usize,
    },
    /// Concentric dielectric spheres, outermost first.
    Shells { center: [f64; 3], radii: Vec<f64> },
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
        material: usize,
    },
    /// A regular (or, with `star`, alternately indented) polygon of `sides` vertices.
    Polygon {
        center: [f64; 3],
        normal: [f64; 3],
        radius: f64,
        sides: usize,
        star: bool,
        material: usize,
    },
    Triangle {
        vertices: [[f64; 3]; 3],
        sliver: bool,
        material: usize,
    },
}

/// An orthonormal pair perpendicular to the unit vector `n`.
fn basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let normalize = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    let u = normalize(cross(n, helper));
    let v = cross(n, u);
    (u, v)
}

fn normalized(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / l)
}

impl ObjectSpec {
    /// The distance from `p` to the object's spheres and planes, in units of the scale
    /// (infinite for polygons and triangles).
    fn distance_from(&self, p: [f64; 3]) -> f64 {
        let to_sphere = |c: [f64; 3], r: f64| {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - r).abs()
        };
        match self {
            ObjectSpec::Sphere { center, radius, .. } => to_sphere(*center, *radius),
            ObjectSpec::Ground { at, radius, .. } => to_sphere([at[0], -radius, at[2]], *radius),
            ObjectSpec::Tangent { center, radius, .. } => to_sphere(*center, *radius).min(
                to_sphere([center[0] + 2.0 * radius, center[1], center[2]], *radius),
            ),
            ObjectSpec::Shells { center, radii } => radii
                .iter()
                .map(|r| to_sphere(*center, *r))
                .fold(f64::INFINITY, f64::min),
            ObjectSpec::Plane { point, normal, .. } => {
                let n = normalized(*normal);
                ((0..3).map(|a| n[a] * (p[a] - point[a])).sum::<f64>()).abs()
            }
            ObjectSpec::Polygon { .. } | ObjectSpec::Triangle { .. } => f64::INFINITY,
        }
    }

    fn text(&self, scale: f64, materials: usize) -> String {
        let s = |p: [f64; 3]| p.map(|c| c * scale);
        let m = |i: usize| format!("m{}", i % materials);
        match self {
            ObjectSpec::Sphere {
                center,
                radius,
                material,
            } => sphere(s(*center), radius * scale, &m(*material)),
            ObjectSpec::Ground {
                at,
                radius,
                material,
            } => sphere(
                [at[0] * scale, -radius * scale, at[2] * scale],
                radius * scale,
                &m(*material),
            ),
            ObjectSpec::Tangent {
                center,
                radius,
                material,
            } => {
                let c = s(*center);
                let r = radius * scale;
                sphere(c, r, &m(*material))
                    + &sphere([c[0] + 2.0 * r, c[1], c[2]], r, &m(*material + 1))
            }
            ObjectSpec::Shells { center, radii } => radii
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let material = if i % 2 == 0 { "glass" } else { "water" };
                    sphere(s(*center), r * scale, material)
                })
                .collect(),
            ObjectSpec::Plane {
                point,
                normal,
                material,
            } => format!(
                "[[objects]]\ntype = \"plane\"\npoint = {}\nnormal = {}\nmaterial = \"{}\"\n\n",
                vector(s(*point)),
                vector(*normal),
                m(*material)
            ),
            ObjectSpec::Polygon {
                center,
                normal,
                radius,
                sides,
                star,
                material,
            } => {
                let (u, v) = basis(normalized(*normal));
                let c = s(*center);
                let vertices: Vec<String> = (0..*sides)
                    .map(|k| {
                        let angle = std::f64::consts::TAU * k as f64 / *sides as f64;
                        let r = radius * scale * if *star && k % 2 == 1 { 0.4 } else { 1.0 };
                        let (cos, sin) = (angle.cos() * r, angle.sin() * r);
                        vector([0, 1, 2].map(|a| c[a] + cos * u[a] + sin * v[a]))
                    })
                    .collect();
                format!(
                    "[[objects]]\ntype = \"polygon\"\nvertices = [{}]\nmaterial = \"{}\"\n\n",
                    vertices.join(", "),
                    m(*material)
                )
            }
            ObjectSpec::Triangle {
                vertices,
                sliver,
                material,
            } => {
                let mut v = vertices.map(s);
                if *sliver {
                    // The third corner 1e-3 of the way from the first edge's midpoint
                    // towards itself: thin, but far from the loader's 1e-12 limit.
                    let (a, b, c) = (v[0], v[1], v[2]);
                    v[2] = [0, 1, 2].map(|k| {
                        let mid = 0.5 * (a[k] + b[k]);
                        mid + 1e-3 * (c[k] - mid)
                    });
                }
                format!(
                    "[[objects]]\ntype = \"triangle\"\nvertices = [{}, {}, {}]\nmaterial = \"{}\"\n\n",
                    vector(v[0]),
                    vector(v[1]),
                    vector(v[2]),
                    m(*material)
                )
            }
        }
    }
}

fn sphere(center: [f64; 3], radius: f64, material: &str) -> String {
    format!(
        "[[objects]]\ntype = \"sphere\"\ncenter = {}\nradius = {}\nmaterial = \"{material}\"\n\n",
        vector(center),
        num(radius)
    )
}

fn object() -> impl Strategy<Value = ObjectSpec> {
    let material = 0usize..8;
    let radius = prop::sample::select(vec![1e-3, 0.05, 0.3, 0.5, 1.0, 2.0]);
    prop_oneof![
        4 => (point(3.0), radius.clone(), material.clone()).prop_map(|(center, radius, material)| {
            ObjectSpec::Sphere { center, radius, material }
        }),
        1 => (point(2.0), prop::sample::select(vec![10.0, 1e3, 1e4, 1e8]), material.clone())
            .prop_map(|(at, radius, material)| ObjectSpec::Ground { at, radius, material }),
        1 => (point(2.0), radius.clone(), material.clone()).prop_map(|(center, radius, material)| {
            ObjectSpec::Tangent { center, radius, material }
        }),
        1 => (point(2.0), 2usize..=7, prop::sample::select(vec![0.5, 1.0, 2.0]))
            .prop_map(|(center, n, outer)| ObjectSpec::Shells {
                center,
                radii: (0..n).map(|k| outer * (1.0 - k as f64 / (n as f64 + 0.5))).collect(),
            }),
        2 => (point(2.0), point(1.0), material.clone())
            .prop_filter("a normal is non-zero", |(_, n, _)| n.iter().any(|c| c.abs() > 0.01))
            .prop_map(|(point, normal, material)| ObjectSpec::Plane { point, normal, material }),
        2 => (
            point(2.0),
            point(1.0),
            radius.clone(),
            prop_oneof![3usize..=8, 100usize..=300],
            any::<bool>(),
            material.clone(),
        )
            .prop_filter("a normal is non-zero", |(_, n, ..)| n.iter().any(|c| c.abs() > 0.01))
            .prop_filter("a star needs an even count", |(_, _, _, sides, star, _)| {
                !*star || sides % 2 == 0
            })
            .prop_map(|(center, normal, radius, sides, star, material)| ObjectSpec::Polygon {
                center,
                normal,
                radius,
                sides,
                star,
                material,
            }),
        2 => (point(3.0), point(3.0), point(3.0), prop::bool::weighted(0.3), material)
            .prop_filter("a triangle is not degenerate", |(a, b, c, ..)| {
                let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let cross = [
                    e1[1] * e2[2] - e1[2] * e2[1],
                    e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0],
                ];
                (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt() > 0.1
            })
            .prop_map(|(a, b, c, sliver, material)| ObjectSpec::Triangle {
                vertices: [a, b, c],
                sliver,
                material,
            }),
    ]
}

/// One GPU device and renderer for every case, with the general (unspecialised) trace
/// shader so that no case waits for a pipeline of its own.
pub struct PipelineChecker {
    gpu: HeadlessGpu,
    renderer: Renderer,
}

/// What a passing case measured.
#[derive(Debug, Clone, Copy)]
pub struct Passed {
    /// The GPU-versus-CPU comparison.
    pub comparison: Comparison,
    /// The image's pixel count.
    pub pixels: usize,
}

/// Why a case failed, with the images where there are two.
#[derive(Debug)]
pub struct Failed {
    /// What went wrong.
    pub reason: String,
    /// CPU and GPU images, when both were rendered.
    pub images: Option<(LinearImage, LinearImage)>,
}

impl PipelineChecker {
    /// A checker on `gpu`: every case with the general trace module walking the BVH,
    /// one module for all cases (compiled once).
    pub fn new(gpu: HeadlessGpu) -> Self {
        let options = RendererOptions {
            specialise: false,
            unrolled: false,
            ..RendererOptions::default()
        };
        let renderer = Renderer::new(&gpu.device, options)
            .unwrap_or_else(|e| panic!("Renderer::new failed: {e}"));
        Self { gpu, renderer }
    }

    /// A checker on `gpu` whose cases, on CPU devices, test their primitives unrolled
    /// (`gpu_render::low_level::gpu::cpu_device::unrolled`): a module of its own for every case, as each
    /// names its primitives, so a few seconds of compiling per case on lavapipe.
    pub fn unrolled(gpu: HeadlessGpu) -> Self {
        let options = RendererOptions {
            specialise: false,
            ..RendererOptions::default()
        };
        let renderer = Renderer::new(&gpu.device, options)
            .unwrap_or_else(|e| panic!("Renderer::new failed: {e}"));
        Self { gpu, renderer }
    }

    /// Whether `text`'s scene, prepared by this checker, tests its primitives unrolled.
    pub fn unrolls(&self, text: &str) -> bool {
        gpu_render::scene::parse_scene(text, std::path::Path::new("<fuzz>"))
            .ok()
            .and_then(|scene| {
                self.renderer
                    .upload(&self.gpu.device, &self.gpu.queue, &scene)
                    .ok()
            })
            .is_some_and(|prepared| prepared.features().unrolled.is_some())
    }

    /// Parses `text` (which must be accepted), renders it on the CPU and the GPU and
    /// compares the images: no panic, every pixel finite on both, at most
    /// [`OUTLIER_PIXELS`] pixels outside [`TOLERANCE`].
    pub fn check(&self, text: &str) -> Result<Passed, Failed> {
        let fail = |reason: String| Failed {
            reason,
            images: None,
        };
        let scene = gpu_render::scene::parse_scene(text, std::path::Path::new("<fuzz>"))
            .map_err(|e| fail(format!("the generated scene does not parse: {e}")))?;
        let cpu =
            std::panic::catch_unwind(AssertUnwindSafe(|| gpu_render::cpu::render(&scene, None)))
                .map_err(|p| fail(format!("the CPU render panicked: {}", panic_message(&p))))?;
        let gpu = std::panic::catch_unwind(AssertUnwindSafe(|| {
            self.renderer
                .render(&self.gpu.device, &self.gpu.queue, &scene, None)
        }))
        .map_err(|p| fail(format!("the GPU render panicked: {}", panic_message(&p))))?
        .map_err(|e| fail(format!("the GPU render failed: {e}")))?;
        let (cpu, gpu) = (cpu.image, gpu.image);
        let non_finite = |image: &LinearImage| {
            image
                .pixels
                .iter()
                .position(|p| p.iter().any(|c| !c.is_finite()))
        };
        let comparison = measure(&cpu, &gpu, TOLERANCE);
        let reason = if let Some(i) = non_finite(&cpu) {
            Some(format!("CPU pixel {i} is {:?}", cpu.pixels[i]))
        } else if let Some(i) = non_finite(&gpu) {
            Some(format!("GPU pixel {i} is {:?}", gpu.pixels[i]))
        } else if comparison.outliers > OUTLIER_PIXELS {
            Some(format!(
                "{} of {} pixels differ beyond |Δ| <= {} + {}·|cpu| (allowed {OUTLIER_PIXELS}); \
                 max |Δ| = {}, RMSE = {:.3e}; worst pixel {}",
                comparison.outliers,
                comparison.pixels,
                TOLERANCE.absolute,
                TOLERANCE.relative,
                comparison.max_abs_error,
                comparison.rmse,
                worst_pixel(&cpu, &gpu)
            ))
        } else {
            None
        };
        match reason {
            Some(reason) => Err(Failed {
                reason,
                images: Some((cpu, gpu)),
            }),
            None => Ok(Passed {
                comparison,
                pixels: cpu.pixels.len(),
            }),
        }
    }
}

/// "(x, y): cpu [...] gpu [...]" for the pixel with the largest difference.
fn worst_pixel(cpu: &LinearImage, gpu: &LinearImage) -> String {
    let mut worst = (0, -1.0f32);
    for (i, (c, g)) in cpu.pixels.iter().zip(&gpu.pixels).enumerate() {
        let d = (0..3).map(|k| (c[k] - g[k]).abs()).fold(0.0, f32::max);
        if d > worst.1 {
            worst = (i, d);
        }
    }
    let i = worst.0;
    format!(
        "({}, {}): cpu {:?} gpu {:?}",
        i as u32 % cpu.width,
        i as u32 / cpu.width,
        &cpu.pixels[i][..3],
        &gpu.pixels[i][..3]
    )
}

fn panic_message(payload: &Box<dyn std::any::Any + Send>) -> String {
    payload
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| payload.downcast_ref::<&str>().map(|s| (*s).to_owned()))
        .unwrap_or_else(|| "(no message)".into())
}
