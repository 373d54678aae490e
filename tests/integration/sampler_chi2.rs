//! Chi-square tests of every importance sampler against its density (src/sample.rs, the
//! lobe samplers of src/cpu/bxdf.rs, and the tabulated BRDF maps' inverse-CDF sampler of src/cpu/tabulated.rs),
//! as pbrt-v4 and Mitsuba 3 test theirs: the sphere of directions is cut into a grid
//! of cells in (θ, φ), a cell's expected count is the sample count times the density
//! integrated over the cell (the midpoint rule on a 32 × 32 grid in θ and φ, with the
//! sin θ of the solid angle), cells expecting fewer than 5 samples are pooled, and Pearson's statistic is
//! compared with the chi-square distribution. A test fails when its p-value is below
//! the significance 0.01 spread over the tests of this file (Šidák's correction), so
//! the file as a whole fails by chance once in a hundred runs at most; the samples are
//! deterministic (counter-based), so a pass is reproducible. Each density is also
//! checked to integrate to 1 over the sphere.

use std::cell::Cell;

use glam::{DVec2, DVec3};
use gpu_render::low_level::accel::BrdfMapCdf;
use gpu_render::low_level::cpu::bxdf::{
    pdf_beckmann_normal, pdf_blinn_phong_half, pdf_ggx_visible_normal, sample_beckmann_normal,
    sample_blinn_phong_half, sample_ggx_visible_normal,
};
use gpu_render::low_level::cpu::tabulated::{
    TABULATED_COSINE_PROBABILITY, pdf_brdf_map_direction, pdf_tabulated, sample_tabulated,
};
use gpu_render::low_level::sample::*;
use gpu_render::scene::Image;

/// Tests in this file that compute a p-value (for Šidák's correction).
const TESTS: f64 = 25.0;
/// Overall significance.
const ALPHA: f64 = 0.01;
const THETA_CELLS: usize = 24;
const PHI_CELLS: usize = 48;
const SAMPLES: u32 = 400_000;

/// Uniform pairs for test `seed`, from the counter-based generator.
fn uniform_pair(seed: u32, i: u32) -> DVec2 {
    DVec2::new(random_number(i, seed, 0), random_number(i, seed, 1))
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) (Numerical Recipes §6.2:
/// the series below a + 1, the continued fraction above).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut sum, mut term, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * prefactor
    } else {
        // Lentz's method.
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        prefactor * h
    }
}

/// Pearson's test of `observed` against `expected` counts (pooling cells expecting
/// fewer than 5): the p-value.
fn chi_square_p_value(observed: &[f64], expected: &[f64]) -> f64 {
    let (mut statistic, mut cells) = (0.0, 0usize);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pooled_observed += o;
            pooled_expected += e;
        } else {
            statistic += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled_expected >= 5.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        cells += 1;
    } else if pooled_observed > 0.0 && pooled_expected == 0.0 {
        // Samples where the density says there can be none.
        return 0.0;
    }
    gamma_q((cells - 1) as f64 / 2.0, statistic / 2.0)
}

fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Samples a direction sampler, tabulates it over the (θ, φ) grid, and checks it
/// against its density; `None` samples (no direction) count as lost.
fn check_directions(
    name: &str,
    seed: u32,
    sample: impl Fn(DVec2) -> Option<DVec3>,
    pdf: impl Fn(DVec3) -> f64,
) {
    let cells = THETA_CELLS * PHI_CELLS;
    let mut observed = vec![0.0; cells];
    let pi = std::f64::consts::PI;
    for i in 0..SAMPLES {
        let Some(w) = sample(uniform_pair(seed, i)) else {
            continue;
        };
        assert!(
            (w.length() - 1.0).abs() < 1e-9,
            "{name}: a sample of length {}",
            w.length()
        );
        let theta = w.z.clamp(-1.0, 1.0).acos();
        let phi = w.y.atan2(w.x).rem_euclid(2.0 * pi);
        let ti = ((theta / pi * THETA_CELLS as f64) as usize).min(THETA_CELLS - 1);
        let pj = ((phi / (2.0 * pi) * PHI_CELLS as f64) as usize).min(PHI_CELLS - 1);
        observed[ti * PHI_CELLS + pj] += 1.0;
    }
    // The midpoint rule over each cell, 32 × 32 points: densities with an edge (the
    // cone of a sphere) defeat Simpson's rule in the cells the edge cuts.
    let mut expected = vec![0.0; cells];
    let (dt, dp) = (pi / THETA_CELLS as f64, 2.0 * pi / PHI_CELLS as f64);
    const SUB: usize = 32;
    let mut total = 0.0;
    for ti in 0..THETA_CELLS {
        for pj in 0..PHI_CELLS {
            let mut integral = 0.0;
            for a in 0..SUB {
                let theta = dt * (ti as f64 + (a as f64 + 0.5) / SUB as f64);
                for b in 0..SUB {
                    let phi = dp * (pj as f64 + (b as f64 + 0.5) / SUB as f64);
                    integral += pdf(direction(theta, phi)) * theta.sin();
                }
            }
            integral *= dt * dp / (SUB * SUB) as f64;
            total += integral;
            expected[ti * PHI_CELLS + pj] = integral * f64::from(SAMPLES);
        }
    }
    // 0.5%: the reflected GGX density has an integrable peak at wi = -wo, which the
    // grid underestimates at grazing views.
    assert!(
        (total - 1.0).abs() < 5e-3,
        "{name}: the density integrates to {total} over the sphere, not 1"
    );
    let p = chi_square_p_value(&observed, &expected);
    let threshold = 1.0 - (1.0 - ALPHA).powf(1.0 / TESTS);
    assert!(
        p >= threshold,
        "{name}: the samples do not follow the density: p = {p:.3e} < {threshold:.3e}"
    );
}

#[test]
fn cosine_hemisphere_sampling_follows_its_density() {
    check_directions(
        "cosine hemisphere",
        1,
        |u| Some(sample_cosine_hemisphere(u)),
        pdf_cosine_hemisphere,
    );
}

/// Directions reflected about GGX visible normals, for several roughnesses and view
/// angles: the density of the reflected direction is the visible-normal density
/// times the reflection's Jacobian.
#[test]
fn ggx_visible_normal_reflection_follows_its_density() {
    let mut seed = 10;
    for alpha in [0.25, 0.5, 1.0] {
        for theta_o in [0.3_f64, 1.2] {
            let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
            seed += 1;
            check_directions(
                &format!("GGX VNDF, alpha {alpha}, theta_o {theta_o}"),
                seed,
                |u| Some(reflect_about(wo, sample_ggx_visible_normal(wo, alpha, u))),
                |wi| {
                    let h = (wo + wi).normalize_or_zero();
                    reflected_pdf(pdf_ggx_visible_normal(wo, h, alpha), wo.dot(h))
                },
            );
        }
    }
}

#[test]
fn beckmann_normal_sampling_follows_its_density() {
    for (seed, alpha) in [(20, 0.3), (21, 0.8)] {
        check_directions(
            &format!("Beckmann, alpha {alpha}"),
            seed,
            |u| Some(sample_beckmann_normal(alpha, u)),
            |h| pdf_beckmann_normal(h, alpha),
        );
    }
}

#[test]
fn blinn_phong_half_vector_sampling_follows_its_density() {
    for (seed, n) in [(30, 2.0), (31, 20.0)] {
        check_directions(
            &format!("Blinn-Phong, exponent {n}"),
            seed,
            |u| Some(sample_blinn_phong_half(n, u)),
            |h| pdf_blinn_phong_half(h, n),
        );
    }
}

/// The environment map's sampler (`gpu_render::low_level::accel::EnvironmentLight`) on a
/// non-uniform 16 × 8 map with a black texel and a black row: the grid's pole is the
/// map's +y (the directions are turned by a cyclic permutation of the axes, which
/// keeps solid angle), so the map's texel edges fall on the grid's cell edges and the
/// midpoint rule integrates its piecewise-constant density exactly. A density wrong by
/// the `sin θ` of its Jacobian, or a marginal/conditional mix-up, fails.
#[test]
fn environment_map_sampling_follows_its_density() {
    use gpu_render::low_level::accel::EnvironmentLight;
    use gpu_render::scene::{EnvironmentMap, Image};
    let (width, height) = (16u32, 8u32);
    let texels = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let v = if y == 6 || (x, y) == (3, 2) {
                0.0
            } else {
                // Uneven values, a bright patch, colour.
                let patch = if (5..8).contains(&x) && (1..3).contains(&y) {
                    20.0
                } else {
                    0.0
                };
                0.2 + f64::from((x * 7 + y * 13) % 11) * 0.3 + patch
            };
            [v as f32, (0.5 * v) as f32, (0.8 * v) as f32, 1.0]
        })
        .collect();
    let map = EnvironmentMap {
        image: Image {
            path: "test.exr".into(),
            width,
            height,
            texels,
        },
        rotation_degrees: 0.0,
        scale: DVec3::new(1.0, 2.0, 0.5),
    };
    let light = EnvironmentLight::new(std::sync::Arc::new(map), false);
    // Map (x, y, z) -> grid (z, x, y): the map's +y is the grid's +z.
    let to_grid = |d: DVec3| DVec3::new(d.z, d.x, d.y);
    let from_grid = |w: DVec3| DVec3::new(w.y, w.z, w.x);
    check_directions(
        "environment map",
        50,
        |u| light.sample(u).map(|s| to_grid(s.wi)),
        |w| light.pdf(from_grid(w)),
    );
    // The density the sampler returns is the density function's, also for a rotated
    // map, and the radiance it returns is the texel its direction sees.
    let mut turned = (*light.map).clone();
    turned.rotation_degrees = 37.0;
    let turned = EnvironmentLight::new(std::sync::Arc::new(turned), true);
    assert_eq!(turned.selection, 0.5);
    for environment in [&light, &turned] {
        for i in 0..2000 {
            let Some(s) = environment.sample(uniform_pair(51, i)) else {
                continue;
            };
            let want = environment.pdf(s.wi);
            assert!(
                (s.pdf - want).abs() <= 1e-6 * want,
                "{} against {want}",
                s.pdf
            );
            assert!(s.radiance.distance(environment.map.radiance(s.wi)) <= 1e-9);
            assert!(s.radiance.max_element() > 0.0, "a black texel was sampled");
        }
    }
}

/// A sphere subtending a wide cone, off the grid's axis.
#[test]
fn sphere_cone_sampling_follows_its_density() {
    let point = DVec3::new(0.2, -0.1, 0.0);
    let center = DVec3::new(1.0, 0.5, 1.6);
    let radius = 1.1;
    check_directions(
        "sphere cone",
        40,
        |u| sample_sphere_cone(point, center, radius, u).map(|(w, _)| w),
        |w| pdf_sphere_cone(point, center, radius, w),
    );
    // The density the sampler returns is the density function's.
    for i in 0..1000 {
        let (w, pdf) = sample_sphere_cone(point, center, radius, uniform_pair(41, i))
            .expect("outside the sphere");
        let want = pdf_sphere_cone(point, center, radius, w);
        assert!((pdf - want).abs() <= 1e-9 * want, "{pdf} against {want}");
    }
    assert!(sample_sphere_cone(center, center, radius, DVec2::splat(0.5)).is_none());
}

/// Triangle points uniform in area: an 8 × 8 grid over (b₁, b₂), the cells the
/// diagonal b₁ + b₂ = 1 cuts expecting half.
#[test]
fn triangle_sampling_is_uniform_in_area() {
    let n = 8;
    let mut observed = vec![0.0; n * n];
    let mut expected = vec![0.0; n * n];
    for i in 0..SAMPLES {
        let b = sample_triangle_barycentrics(uniform_pair(50, i));
        assert!(b.min_element() >= 0.0 && (b.x + b.y + b.z - 1.0).abs() < 1e-12);
        let x = ((b.y * n as f64) as usize).min(n - 1);
        let y = ((b.z * n as f64) as usize).min(n - 1);
        observed[y * n + x] += 1.0;
    }
    for y in 0..n {
        for x in 0..n {
            let area = if x + y + 2 <= n {
                1.0
            } else if x + y + 1 == n {
                0.5
            } else {
                0.0
            };
            // The triangle's area is half the square's.
            expected[y * n + x] = f64::from(SAMPLES) * area / (n * n) as f64 * 2.0;
        }
    }
    let p = chi_square_p_value(&observed, &expected);
    assert!(p >= 1.0 - (1.0 - ALPHA).powf(1.0 / TESTS), "p = {p:.3e}");
}

/// The counter-based generator: uniform in one dimension and in pairs of dimensions.
#[test]
fn random_numbers_are_uniform_alone_and_in_pairs() {
    let mut single = vec![0.0; 64];
    let mut pairs = vec![0.0; 256];
    for i in 0..SAMPLES {
        let (pixel, sample) = (i % 4096, i / 4096);
        let a = random_number(pixel, sample, 3);
        let b = random_number(pixel, sample, 4);
        single[(a * 64.0) as usize] += 1.0;
        pairs[(a * 16.0) as usize * 16 + (b * 16.0) as usize] += 1.0;
    }
    let threshold = 1.0 - (1.0 - ALPHA).powf(1.0 / TESTS);
    let p = chi_square_p_value(&single, &vec![f64::from(SAMPLES) / 64.0; 64]);
    assert!(p >= threshold, "single: p = {p:.3e}");
    let p = chi_square_p_value(&pairs, &vec![f64::from(SAMPLES) / 256.0; 256]);
    assert!(p >= threshold, "pairs: p = {p:.3e}");
}

/// The chi-square machinery itself: known values of Q, and a sampler with a wrong
/// density is rejected (so a pass above means something).
#[test]
fn the_test_rejects_a_wrong_density() {
    // Q(1, x) = e^-x; Q(0.5, x) = erfc(√x).
    assert!((gamma_q(1.0, 2.0) - (-2f64).exp()).abs() < 1e-12);
    assert!((gamma_q(1.0, 30.0) - (-30f64).exp()).abs() < 1e-20);
    assert!((gamma_q(0.5, 1.0) - 0.157_299_207_050_285_13).abs() < 1e-12);
    assert!((gamma_q(10.0, 10.0) - 0.457_929_714_471_852_1).abs() < 1e-10);
    // Cosine-weighted samples against the uniform hemisphere density.
    let result = std::panic::catch_unwind(|| {
        check_directions(
            "cosine against uniform",
            60,
            |u| Some(sample_cosine_hemisphere(u)),
            |w| {
                if w.z > 0.0 {
                    1.0 / (2.0 * std::f64::consts::PI)
                } else {
                    0.0
                }
            },
        );
    });
    assert!(result.is_err(), "a wrong density passed the test");
}

#[test]
fn power_heuristic_weights_sum_to_one() {
    for (a, b) in [(1.0, 1.0), (0.1, 3.0), (5.0, 0.0)] {
        assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-12);
    }
    assert_eq!(power_heuristic(0.0, 0.0), 0.0);
}

/// A BRDF map of `n × n` texels holding `π·f = value(θi, θr)` in every channel.
fn brdf_map(n: u32, value: impl Fn(f64, f64) -> f64) -> Image {
    let angle = |i: u32| f64::from(i) / f64::from(n - 1) * std::f64::consts::FRAC_PI_2;
    let texels = (0..n * n)
        .map(|i| {
            let v = value(angle(i % n), angle(i / n)) as f32;
            [v, v, v, 1.0]
        })
        .collect();
    Image {
        path: "test map".into(),
        width: n,
        height: n,
        texels,
    }
}

/// The tabulated sampler needs a third number (the lobe and the row): drawn from the
/// same generator, in the order `check_directions` draws its pairs.
fn tabulated_sampler(cdf: &BrdfMapCdf, wo: DVec3, seed: u32) -> impl Fn(DVec2) -> Option<DVec3> {
    let index = Cell::new(0u32);
    move |u| {
        let i = index.get();
        index.set(i + 1);
        Some(sample_tabulated(cdf, wo, random_number(i, seed, 2), u))
    }
}

/// Tabulated BRDF maps sampled by inverse CDF, mixed with the cosine lobe, against the
/// mixture's density, for outgoing angles on a row of the map (0° and 45°), between
/// rows and near grazing: a glossy map peaked along θi = θr (65 × 65, 64 bands of
/// 1.41°) and one bright only at grazing angles (33 × 33). Both sides are chosen so
/// that the bands' edges fall on the integration grid's (24 cells of 7.5° in θ over the
/// sphere, 32 points each), where the piecewise-constant density jumps.
#[test]
fn tabulated_brdf_map_sampling_follows_its_density() {
    let glossy = brdf_map(65, |ti, tr| {
        0.05 + 5.0 * (-((ti - tr) / 0.08).powi(2)).exp()
    });
    let grazing = brdf_map(33, |ti, tr| 3.6 * (ti.sin() * tr.sin()).powi(6));
    let mut seed = 70;
    for (name, map) in [("glossy", glossy), ("grazing", grazing)] {
        let cdf = BrdfMapCdf::new(&map).expect("a square map");
        for theta_o in [0.0, 45f64.to_radians(), 0.55, 1.45] {
            let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
            seed += 1;
            check_directions(
                &format!("tabulated {name}, theta_o {theta_o:.3}"),
                seed,
                tabulated_sampler(&cdf, wo, seed),
                |wi| pdf_tabulated(&cdf, wo, wi),
            );
        }
    }
}

/// The test has the power to see a subtle error of the tabulated density: mixing the
/// two rows around θo with each other's weight. Row 0 of this 3 × 3 map reflects only
/// towards grazing, rows 1 and 2 only towards the normal; at θo = 30° the rows weigh
/// 1/3 and 2/3.
#[test]
fn the_test_rejects_a_tabulated_density_with_swapped_row_weights() {
    let map = brdf_map(3, |ti, tr| {
        let grazing = ti > 1.0;
        if (tr < 0.1) == grazing { 1.0 } else { 0.0 }
    });
    let cdf = BrdfMapCdf::new(&map).expect("a square map");
    let theta_o = 30f64.to_radians();
    let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
    // The right density passes.
    check_directions("3x3 map", 90, tabulated_sampler(&cdf, wo, 90), |wi| {
        pdf_tabulated(&cdf, wo, wi)
    });
    // θr = 15° weighs the same rows 2/3 and 1/3.
    let swapped = 15f64.to_radians().cos();
    let result = std::panic::catch_unwind(|| {
        check_directions("swapped rows", 91, tabulated_sampler(&cdf, wo, 91), |wi| {
            let c = TABULATED_COSINE_PROBABILITY;
            c * pdf_cosine_hemisphere(wi) + (1.0 - c) * pdf_brdf_map_direction(&cdf, swapped, wi)
        });
    });
    assert!(
        result.is_err(),
        "a density with swapped row weights passed the test"
    );
}
