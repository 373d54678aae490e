//! The stage of the model-shading tests (`model_shading`, `model_alpha`): quads of
//! side 1.8 in the plane z = 0, centred at x = -3, -1, 1, 3, seen head on by a pinhole
//! camera at z = 7.5 in a 160 × 48 image, and the probes that read what lands where.

use glam::{DMat4, DVec2, DVec3};
use gpu_render::film::LinearImage as Film;
use gpu_render::scene::{Camera, Mesh};

/// Image width of the stage.
pub const WIDTH: u32 = 160;
/// Image height of the stage.
pub const HEIGHT: u32 = 48;
/// The camera's distance from the plane z = 0.
pub const EYE_Z: f64 = 7.5;
/// The camera's vertical field of view.
pub const FOV_Y_DEGREES: f64 = 18.0;

/// The camera at (0, 0, [`EYE_Z`]) looking at the origin.
pub fn camera() -> Camera {
    Camera {
        eye: DVec3::new(0.0, 0.0, EYE_Z),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        fov_y_degrees: FOV_Y_DEGREES,
        orthographic_half_height: None,
        lens: None,
    }
}

/// The pixel (column, row) that sees the point `(x, y, 0)`.
pub fn pixel_of(x: f64, y: f64) -> (u32, u32) {
    let half_height = EYE_Z * (FOV_Y_DEGREES.to_radians() / 2.0).tan();
    let half_width = half_height * f64::from(WIDTH) / f64::from(HEIGHT);
    let column = (x / half_width + 1.0) / 2.0 * f64::from(WIDTH);
    let row = (1.0 - y / half_height) / 2.0 * f64::from(HEIGHT);
    (column as u32, row as u32)
}

/// The pixel that sees the point of the quad centred at `(centre, 0, 0)` at its
/// texture coordinates `(u, v)` (`v` down).
pub fn pixel_at_uv(centre: f64, u: f64, v: f64) -> (u32, u32) {
    pixel_of(centre - 0.9 + 1.8 * u, 0.9 - 1.8 * v)
}

/// The colour of `film`'s pixel (column, row).
pub fn colour(film: &Film, (x, y): (u32, u32)) -> DVec3 {
    let p = film.pixels[(y * film.width + x) as usize];
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

/// Asserts `film`'s `pixel` within 2e-3 of `expected` in every channel.
pub fn assert_colour(label: &str, film: &Film, pixel: (u32, u32), expected: DVec3) {
    assert_colour_within(label, film, pixel, expected, 2e-3);
}

/// Asserts `film`'s `pixel` within `within` of `expected` in every channel.
pub fn assert_colour_within(
    label: &str,
    film: &Film,
    pixel: (u32, u32),
    expected: DVec3,
    within: f64,
) {
    let got = colour(film, pixel);
    assert!(
        (got - expected).abs().max_element() < within,
        "{label}: pixel {pixel:?} is {got}, expected {expected}"
    );
}

/// A quad of side 1.8 in the plane z = 0 facing +z, texture coordinates running from
/// (0, 0) at its top-left corner to (1, 1) at its bottom-right, placed by `instances`.
pub fn quad(material: u32, instances: Vec<DMat4>) -> Mesh {
    Mesh {
        name: "quad".into(),
        positions: vec![
            DVec3::new(-0.9, -0.9, 0.0),
            DVec3::new(0.9, -0.9, 0.0),
            DVec3::new(0.9, 0.9, 0.0),
            DVec3::new(-0.9, 0.9, 0.0),
        ],
        normals: None,
        uvs: Some(vec![
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 0.0),
        ]),
        uvs1: None,
        colors: None,
        tangents: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        material,
        instances,
    }
}

/// The translation to `(x, 0, 0)`.
pub fn at(x: f64) -> DMat4 {
    DMat4::from_translation(DVec3::new(x, 0.0, 0.0))
}
