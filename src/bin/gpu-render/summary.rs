//! The one-line summary printed after a render.

use std::path::Path;
use std::time::Duration;

use gpu_render::film::RenderStats;
use gpu_render::low_level::echo::bytes;
use gpu_render::low_level::noise::NoiseEstimate;
use gpu_render::scene::RenderSettings;

/// What the summary line reports.
pub struct Summary<'a> {
    /// The settings rendered with (after the command-line overrides).
    pub settings: &'a RenderSettings,
    /// How many images were rendered (2 for `--compare-gamma`).
    pub passes: u32,
    /// The piece rendered (`tile 1/4 (x 0..32, y 6..12 (32x6))`), if not the whole
    /// image.
    pub piece: Option<&'a str>,
    /// The animation frame rendered, if one was.
    pub frame: Option<u32>,
    /// `GPU (adapter)` or `CPU reference`.
    pub backend: &'a str,
    /// Wall time of the render call(s), without loading or writing.
    pub wall: Duration,
    /// Of the wall time, how long the GPU's kernels took to compile (`None` on the
    /// CPU reference).
    pub compile: Option<Duration>,
    /// Statistics summed over the passes.
    pub stats: RenderStats,
    /// The file written.
    pub output: &'a Path,
    /// The noise estimate, with `--standard-error`.
    pub noise: Option<&'a NoiseEstimate>,
    /// The process's peak resident memory so far and the estimate `--max-memory` was
    /// checked against, in bytes, where the system tells the peak.
    pub memory: Option<(u64, u64)>,
}

impl std::fmt::Display for Summary<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = self.settings;
        let passes = if self.passes > 1 {
            format!("{} x ", self.passes)
        } else {
            String::new()
        };
        let piece = self
            .piece
            .map_or(String::new(), |piece| format!("{piece} of "));
        let frame = self
            .frame
            .map_or(String::new(), |frame| format!(" (frame {frame})"));
        // The trace time is GPU time where timestamps were taken, else wall time; the
        // ray rate is per that time, and the line says which it is.
        let (trace, source) = self.stats.trace_seconds();
        let (rays_per_second, _) = self.stats.trace_rays_per_second();
        let noise = match self.noise.map(NoiseEstimate::relative_error) {
            None => String::new(),
            Some(Some(relative)) => format!(
                ", estimated noise {:.2}% (relative RMSE of luminance)",
                relative * 100.0
            ),
            Some(None) => ", estimated noise unknown (needs 2 spp and light)".to_owned(),
        };
        let memory = self.memory.map_or(String::new(), |(peak, estimate)| {
            format!(
                ", peak memory {} (estimated {})",
                bytes(peak),
                bytes(estimate)
            )
        });
        let compile = self.compile.map_or(String::new(), |compile| {
            format!(" (kernel compile {:.2} s)", compile.as_secs_f64())
        });
        write!(
            f,
            "rendered {passes}{piece}{}x{}{frame}, {} spp, max depth {} on {} in {:.2} s{compile}: {} rays, trace {:.2} s ({source}), {:.1} Mrays/s{noise}{memory} -> {}",
            s.width,
            s.height,
            s.samples_per_pixel,
            s.max_depth,
            self.backend,
            self.wall.as_secs_f64(),
            format_count(self.stats.rays_traced),
            trace,
            rays_per_second / 1e6,
            self.output.display()
        )
    }
}

/// `1234567` as `1.23 M`, small counts as they are.
fn format_count(count: u64) -> String {
    match count {
        0..1_000_000 => count.to_string(),
        1_000_000..1_000_000_000 => format!("{:.2} M", count as f64 / 1e6),
        _ => format!("{:.2} G", count as f64 / 1e9),
    }
}

/// Adds the statistics of two passes. The GPU time is the sum only when both passes
/// have one; otherwise it is `None` and the summary falls back to wall time.
pub fn add_stats(a: RenderStats, b: RenderStats) -> RenderStats {
    RenderStats {
        rays_traced: a.rays_traced + b.rays_traced,
        elapsed: a.elapsed + b.elapsed,
        gpu_time: a.gpu_time.zip(b.gpu_time).map(|(a, b)| a + b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpu_render::scene::LightingSpace;

    #[test]
    fn counts() {
        assert_eq!(format_count(999_999), "999999");
        assert_eq!(format_count(1_234_567), "1.23 M");
        assert_eq!(format_count(4_560_000_000), "4.56 G");
    }

    #[test]
    fn line_names_everything() {
        let settings = RenderSettings {
            width: 32,
            height: 24,
            samples_per_pixel: 4,
            max_depth: 5,
            stack_size: 6,
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: gpu_render::scene::Integrator::Whitted,
            texture_filtering: gpu_render::scene::TextureFiltering::Trilinear,
        };
        let summary = Summary {
            settings: &settings,
            passes: 1,
            piece: None,
            frame: None,
            backend: "GPU (Test)",
            wall: Duration::from_millis(1500),
            compile: Some(Duration::from_millis(250)),
            stats: RenderStats {
                rays_traced: 3_000_000,
                elapsed: Duration::from_secs(1),
                gpu_time: None,
            },
            output: Path::new("out.png"),
            noise: None,
            memory: None,
        };
        assert_eq!(
            summary.to_string(),
            "rendered 32x24, 4 spp, max depth 5 on GPU (Test) in 1.50 s (kernel compile 0.25 s): 3.00 M rays, trace 1.00 s (wall clock), 3.0 Mrays/s -> out.png"
        );
        let timed = Summary {
            stats: RenderStats {
                gpu_time: Some(Duration::from_millis(750)),
                ..summary.stats
            },
            ..summary
        };
        assert_eq!(
            timed.to_string(),
            "rendered 32x24, 4 spp, max depth 5 on GPU (Test) in 1.50 s (kernel compile 0.25 s): 3.00 M rays, trace 0.75 s (GPU timestamps), 4.0 Mrays/s -> out.png"
        );
        let cpu = Summary {
            backend: "CPU reference",
            compile: None,
            ..timed
        };
        assert!(
            cpu.to_string()
                .contains("on CPU reference in 1.50 s: 3.00 M rays"),
            "{cpu}"
        );
        let tile = Summary {
            piece: Some("tile 1/4 (x 0..32, y 6..12 (32x6))"),
            frame: Some(7),
            ..timed
        };
        assert!(
            tile.to_string().starts_with(
                "rendered tile 1/4 (x 0..32, y 6..12 (32x6)) of 32x24 (frame 7), 4 spp"
            ),
            "{tile}"
        );
        // One pixel, mean luminance 2, standard error 0.05: 2.5% noise.
        let estimate = NoiseEstimate {
            width: 1,
            height: 1,
            samples: 4,
            mean_luminance: vec![2.0],
            standard_error: vec![0.05],
        };
        let noisy = Summary {
            noise: Some(&estimate),
            ..summary
        };
        assert!(
            noisy.to_string().ends_with(
                "3.0 Mrays/s, estimated noise 2.50% (relative RMSE of luminance) -> out.png"
            ),
            "{noisy}"
        );
    }

    #[test]
    fn gpu_time_adds_only_when_both_passes_have_it() {
        let timed = RenderStats {
            rays_traced: 10,
            elapsed: Duration::from_secs(2),
            gpu_time: Some(Duration::from_secs(1)),
        };
        let untimed = RenderStats {
            gpu_time: None,
            ..timed
        };
        let both = add_stats(timed, timed);
        assert_eq!(both.gpu_time, Some(Duration::from_secs(2)));
        assert_eq!(both.elapsed, Duration::from_secs(4));
        assert_eq!(add_stats(timed, untimed).gpu_time, None);
    }
}
