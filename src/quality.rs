//! Named quality presets: points on the measured speed/accuracy front.
//!
//! Chosen from `gpu-render tradeoff scenes/showcase.toml` on lavapipe (320x180,
//! reference 256 spp at depth 16; figures in `BENCHMARKS.md` and `docs/quality.md`):
//!
//! | preset | spp | depth | cutoff | trace time | mean FLIP |
//! |---|---|---|---|---|---|
//! | draft | 1 | 4 | 0.05 | 40 ms | 0.020 |
//! | preview | 4 | 4 | 0 | 189 ms | 0.0091 |
//! | final | 16 | 8 | 0 | 1154 ms | 0.0042 |
//!
//! Each is on the Pareto front of that run: no measured setting was both faster and
//! more accurate.

use crate::scene::{RenderOverrides, RenderSettings};

/// A named trade between speed and accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QualityPreset {
    /// One sample, four bounces, weak branches skipped: for placing objects.
    Draft,
    /// Four samples, four bounces: for judging materials and light.
    Preview,
    /// Sixteen samples, eight bounces: for the finished image.
    Final,
}

impl QualityPreset {
    /// The settings the preset overrides (samples, depth, cutoff and a sufficient
    /// stack); size and lighting space stay the scene's.
    pub fn overrides(self) -> RenderOverrides {
        let (samples_per_pixel, max_depth, min_ray_weight) = match self {
            QualityPreset::Draft => (1, 4, 0.05),
            QualityPreset::Preview => (4, 4, 0.0),
            QualityPreset::Final => (16, 8, 0.0),
        };
        RenderOverrides {
            samples_per_pixel: Some(samples_per_pixel),
            max_depth: Some(max_depth),
            stack_size: Some(RenderSettings::sufficient_stack_size(max_depth)),
            min_ray_weight: Some(min_ray_weight),
            ..RenderOverrides::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_ordered_by_cost() {
        let base = RenderSettings::default();
        let mut previous_samples = 0;
        for preset in [
            QualityPreset::Draft,
            QualityPreset::Preview,
            QualityPreset::Final,
        ] {
            let settings = base
                .with_overrides(&preset.overrides())
                .expect("a valid preset");
            assert!(settings.samples_per_pixel > previous_samples);
            assert!(settings.stack_size > settings.max_depth);
            previous_samples = settings.samples_per_pixel;
        }
    }
}
