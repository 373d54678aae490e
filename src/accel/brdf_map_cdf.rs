//! The inverse-CDF tables of tabulated BRDF maps, built once per scene on the host and
//! shared by both backends, as [`super::AreaLights`] is: the CPU reference samples from
//! them in `src/cpu/tabulated.rs`, the GPU twin (`shaders/tabulated.wgsl`) from the
//! same `f32` values, uploaded in the alpha channel of the map's own layer of the image
//! array (no material reads an image's alpha otherwise).
//!
//! A map (`docs/materials.md`) holds `π·f(θi, θr)` on a corner-aligned `N × N` grid,
//! `θi = x/(N−1)·π/2` across and `θr = y/(N−1)·π/2` down, bilinear in between and
//! independent of azimuth. Row `y` of the table is a piecewise-constant distribution
//! of the incident direction over the `N − 1` bands `θi ∈ [θ_b, θ_{b+1}]` for the
//! outgoing angle `θr = θ_y`, each band weighted by what the path integrator
//! estimates, `f · cos θi` over it:
//!
//! `W_b = ½ (L(b, y) + L(b+1, y)) · (sin² θ_{b+1} − sin² θ_b)`,
//!
//! with `L` the luminance of a texel, the mean of the two ends of the band (the map is
//! linear across it) times the band's projected solid angle over π,
//! `∫ cos θ dω = π (sin² θ_{b+1} − sin² θ_b)`. Texel `(x, y)` of the table holds the
//! cumulative `Σ_{b<x} W_b / Σ W` rounded to `f32`, so `x = 0` holds 0 and `x = N − 1`
//! holds 1; a band's probability is the difference of two neighbours, which keeps the
//! sampler and its density consistent in `f32` on both backends. A row whose weights
//! are all zero or not finite falls back to weights `sin² θ_{b+1} − sin² θ_b`, the
//! cosine distribution.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;

use crate::color::luminance;
use crate::scene::{Image, Material, MaterialKind};

/// The inverse-CDF table of one `N × N` BRDF map (see the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfMapCdf {
    /// `N`, the map's side.
    size: u32,
    /// `N × N` cumulative values, row `y` (outgoing angle θ_y) after row `y − 1`.
    cdf: Vec<f32>,
}

impl BrdfMapCdf {
    /// The table of a square map of at least 2 × 2 texels; `None` for any other image.
    pub fn new(map: &Image) -> Option<Self> {
        if map.width != map.height
            || map.width < 2
            || map.texels.len() != (map.width as usize) * (map.height as usize)
        {
            return None;
        }
        let n = map.width;
        let bands = (n - 1) as usize;
        let mut cdf = Vec::with_capacity((n * n) as usize);
        let mut weights = vec![0.0; bands];
        for y in 0..n {
            let texel_luminance = |x: u32| {
                let t = map.texel(x, y);
                luminance(DVec3::new(
                    f64::from(t[0]),
                    f64::from(t[1]),
                    f64::from(t[2]),
                ))
            };
            for (b, weight) in weights.iter_mut().enumerate() {
                let x = b as u32;
                *weight = 0.5
                    * (texel_luminance(x) + texel_luminance(x + 1))
                    * band_projected_solid_angle(x, n);
            }
            let total: f64 = weights.iter().sum();
            if !(total.is_finite() && total > 0.0) {
                for (b, weight) in weights.iter_mut().enumerate() {
                    *weight = band_projected_solid_angle(b as u32, n);
                }
            }
            let total: f64 = weights.iter().sum();
            let mut running = 0.0;
            cdf.push(0.0);
            for (b, weight) in weights.iter().enumerate() {
                running += weight;
                cdf.push(if b + 1 == bands {
                    1.0
                } else {
                    (running / total) as f32
                });
            }
        }
        Some(Self { size: n, cdf })
    }

    /// `N`, the side of the map and of the table.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The cumulative probability of the bands before `x` in row `y` (both below
    /// [`Self::size`]).
    pub fn value(&self, x: u32, y: u32) -> f32 {
        self.cdf[(y * self.size + x) as usize]
    }

    /// Every value, row-major, `N × N`.
    pub fn values(&self) -> &[f32] {
        &self.cdf
    }
}

/// `sin² θ_{b+1} − sin² θ_b` for band `b` of an `n`-texel axis (`θ_b = b/(n−1)·π/2`),
/// the band's projected solid angle over π, written as `sin(θ_{b+1} + θ_b) ·
/// sin(θ_{b+1} − θ_b)` so that no difference of nearly equal numbers is taken.
pub fn band_projected_solid_angle(b: u32, n: u32) -> f64 {
    let step = FRAC_PI_2 / f64::from(n - 1);
    (f64::from(2 * b + 1) * step).sin() * step.sin()
}

/// The inverse-CDF tables of a scene's BRDF maps, indexed like its images: an entry
/// for every image a tabulated material uses as its map, `None` for the others.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BrdfMapCdfs {
    per_image: Vec<Option<BrdfMapCdf>>,
}

impl BrdfMapCdfs {
    /// The tables of the maps that `materials` (tabulated ones) use among `images`.
    pub fn new(images: &[Image], materials: &[Material]) -> Self {
        let mut per_image: Vec<Option<BrdfMapCdf>> = vec![None; images.len()];
        for material in materials {
            if material.kind != MaterialKind::Tabulated {
                continue;
            }
            let Some(index) = material.brdf_map.map(|i| i as usize) else {
                continue;
            };
            if let (Some(slot), Some(image)) = (per_image.get_mut(index), images.get(index))
                && slot.is_none()
            {
                *slot = BrdfMapCdf::new(image);
            }
        }
        Self { per_image }
    }

    /// The table of `material`'s BRDF map, if it is a tabulated material with one.
    pub fn of(&self, material: &Material) -> Option<&BrdfMapCdf> {
        if material.kind != MaterialKind::Tabulated {
            return None;
        }
        self.per_image
            .get(material.brdf_map? as usize)
            .and_then(Option::as_ref)
    }

    /// The table of image `index`, if a tabulated material uses it as its map.
    pub fn of_image(&self, index: usize) -> Option<&BrdfMapCdf> {
        self.per_image.get(index).and_then(Option::as_ref)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(n: u32, value: impl Fn(u32, u32) -> f32) -> Image {
        let texels = (0..n * n)
            .map(|i| {
                let v = value(i % n, i / n);
                [v, v, v, 1.0]
            })
            .collect();
        Image {
            path: "test".into(),
            width: n,
            height: n,
            texels,
        }
    }

    #[test]
    fn rows_are_monotonic_from_zero_to_one() {
        let image = map(9, |x, y| (x * y) as f32 * 0.1);
        let table = BrdfMapCdf::new(&image).expect("square");
        for y in 0..9 {
            assert_eq!(table.value(0, y), 0.0);
            assert_eq!(table.value(8, y), 1.0);
            for x in 1..9 {
                assert!(table.value(x, y) >= table.value(x - 1, y));
            }
        }
    }

    /// A constant map (Lambert) gives the cosine distribution: band probabilities in
    /// proportion to their projected solid angle, which sum to 1 over the hemisphere.
    #[test]
    fn a_constant_map_gives_the_cosine_distribution() {
        let n = 17;
        let total: f64 = (0..n - 1).map(|b| band_projected_solid_angle(b, n)).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        let table = BrdfMapCdf::new(&map(n, |_, _| 0.7)).expect("square");
        for y in [0, 5, 16] {
            for b in 0..n - 1 {
                let p = f64::from(table.value(b + 1, y)) - f64::from(table.value(b, y));
                assert!((p - band_projected_solid_angle(b, n)).abs() < 1e-6, "{p}");
            }
        }
    }

    /// A zero row, and a row with an infinite texel, fall back to the cosine
    /// distribution; bands where the map is zero get no probability.
    #[test]
    fn degenerate_rows_fall_back_and_zero_bands_are_never_chosen() {
        let n = 5;
        let image = map(n, |x, y| match y {
            0 => 0.0,
            1 => f32::INFINITY,
            _ => {
                if x >= 3 {
                    1.0
                } else {
                    0.0
                }
            }
        });
        let table = BrdfMapCdf::new(&image).expect("square");
        for y in [0, 1] {
            for b in 0..n - 1 {
                let p = f64::from(table.value(b + 1, y)) - f64::from(table.value(b, y));
                assert!((p - band_projected_solid_angle(b, n)).abs() < 1e-6);
            }
        }
        // Texels 0..2 are zero: bands 0 and 1 cannot be chosen, band 2 (half) and 3 can.
        assert_eq!(table.value(2, 2), 0.0);
        assert!(table.value(3, 2) > 0.0 && table.value(3, 2) < 1.0);
    }

    #[test]
    fn only_square_maps_of_tabulated_materials_get_tables() {
        assert!(BrdfMapCdf::new(&map(1, |_, _| 1.0)).is_none());
        let mut wide = map(4, |_, _| 1.0);
        wide.width = 8;
        wide.height = 2;
        assert!(BrdfMapCdf::new(&wide).is_none());
        let images = [map(4, |_, _| 1.0), map(4, |_, _| 1.0)];
        let tabulated = Material {
            brdf_map: Some(1),
            ..Material::blank(MaterialKind::Tabulated)
        };
        let lambert = Material {
            albedo_texture: Some(0),
            ..Material::lambert(DVec3::ONE)
        };
        let cdfs = BrdfMapCdfs::new(&images, &[lambert, tabulated]);
        assert!(cdfs.of_image(0).is_none());
        assert!(cdfs.of_image(1).is_some());
        assert!(cdfs.of(&tabulated).is_some());
        assert!(cdfs.of(&lambert).is_none());
    }
}
