//! Measuring the speed/accuracy trade: render a converged reference, sweep the knobs
//! that trade one for the other (samples per pixel, maximum depth, ray-weight cutoff),
//! and measure each setting's time and its error against the reference, in linear
//! RMSE, in relative luminance RMSE ([`crate::film::relative_rmse`]) and in FLIP
//! (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG
//! 2020), then find the Pareto front of time versus error. Each integrator (Whitted,
//! path) is a series of its own, measured against its own converged reference, and
//! [`time_to_error`] says how long each takes to reach a relative error.
//!
//! Every figure comes from images rendered in the run; nothing is tabulated by hand.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::film::LinearImage;
use crate::output::{self, OutputError};
use crate::scene::Integrator;

/// One setting of the speed/accuracy knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knobs {
    /// The integrator.
    pub integrator: Integrator,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Maximum bounce depth.
    pub max_depth: u32,
    /// Ray-weight cutoff.
    pub min_ray_weight: f64,
}

/// What one setting cost and how far it landed from the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// The setting.
    pub knobs: Knobs,
    /// Trace time in seconds (the best of the timed runs).
    pub seconds: f64,
    /// Rays traced.
    pub rays: u64,
    /// Root-mean-square error of the linear RGB channels against the reference.
    pub rmse: f64,
    /// Relative RMSE of the luminance against the reference's
    /// ([`crate::film::relative_rmse`]).
    pub relative_error: f64,
    /// The same error as the render's own noise estimate predicts it
    /// ([`crate::noise::NoiseEstimate::relative_error`]), where it has one.
    pub estimated_error: Option<f64>,
    /// Mean FLIP error of the 8-bit display image against the reference's (0 = same).
    pub flip: f64,
}

/// The default sweep of `integrator`. Whitted: every combination of 1–16 samples,
/// depth 1–8 and cutoffs 0, 0.05 and 0.2 (60 settings). Path: 1–64 samples at depth
/// 2, 4 and 8 (21 settings); its noise falls with the samples only, and the cutoff
/// does not apply (Russian roulette ends its paths).
pub fn default_sweep(integrator: Integrator) -> Vec<Knobs> {
    match integrator {
        Integrator::Whitted => sweep(
            integrator,
            &[1, 2, 4, 8, 16],
            &[1, 2, 4, 8],
            &[0.0, 0.05, 0.2],
        ),
        Integrator::Path => sweep(integrator, &[1, 2, 4, 8, 16, 32, 64], &[2, 4, 8], &[0.0]),
    }
}

/// Every combination of `samples`, `depths` and `cutoffs` for `integrator`, samples
/// outermost.
pub fn sweep(
    integrator: Integrator,
    samples: &[u32],
    depths: &[u32],
    cutoffs: &[f64],
) -> Vec<Knobs> {
    let mut knobs = Vec::new();
    for &samples_per_pixel in samples {
        for &max_depth in depths {
            for &min_ray_weight in cutoffs {
                knobs.push(Knobs {
                    integrator,
                    samples_per_pixel,
                    max_depth,
                    min_ray_weight,
                });
            }
        }
    }
    knobs
}

/// How long an integrator takes to reach a relative error ([`time_to_error`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeToError {
    /// Trace seconds.
    pub seconds: f64,
    /// Samples per pixel it takes.
    pub samples_per_pixel: f64,
    /// Whether a measured setting reached the error, so that the figure is
    /// interpolated between two measured settings (`false`: extrapolated past the
    /// largest).
    pub measured: bool,
    /// The exponent `k` of `error ∝ spp^k` through the two largest settings (−1/2
    /// for independent noise); where extrapolated, the one used.
    pub exponent: f64,
}

/// The time `integrator`'s spp series takes to reach relative error `target`: the
/// measurements at its deepest depth without a cutoff, at most `max_spp` samples
/// (keep the reference at least 16 times the samples, so that its own noise moves the
/// measured errors by at most about 3%). If a setting reached `target`, the power law
/// through it and the setting before gives the samples where the error crossed it,
/// at the reaching setting's time per sample (measured); else the power law `error ∝ spp^k` through the two largest settings,
/// extended from the largest to `target` with its time per sample. Stratified camera
/// samples make an error fall faster than `1/√spp` while edges dominate it; the path
/// integrator's independent path samples then leave `1/√spp`, so its `k` is taken
/// no steeper than −1/2 (Whitted's stratified edges keep theirs). `None` with fewer
/// than two usable settings or an exponent that is not negative.
pub fn time_to_error(
    measurements: &[Measurement],
    integrator: Integrator,
    target: f64,
    max_spp: u32,
) -> Option<TimeToError> {
    let depth = measurements
        .iter()
        .filter(|m| m.knobs.integrator == integrator)
        .map(|m| m.knobs.max_depth)
        .max()?;
    let mut series: Vec<&Measurement> = measurements
        .iter()
        .filter(|m| {
            m.knobs.integrator == integrator
                && m.knobs.max_depth == depth
                && m.knobs.min_ray_weight == 0.0
                && m.knobs.samples_per_pixel <= max_spp
                && m.relative_error > 0.0
                && m.relative_error.is_finite()
        })
        .collect();
    series.sort_by_key(|m| m.knobs.samples_per_pixel);
    series.dedup_by_key(|m| m.knobs.samples_per_pixel);
    let [.., before, largest] = series[..] else {
        return None;
    };
    let spp = f64::from(largest.knobs.samples_per_pixel);
    let fitted = (largest.relative_error / before.relative_error).ln()
        / (spp / f64::from(before.knobs.samples_per_pixel)).ln();
    if fitted.is_nan() || fitted >= 0.0 {
        return None;
    }
    if let Some(reached) = series.iter().position(|m| m.relative_error <= target) {
        let m = series[reached];
        let spp = f64::from(m.knobs.samples_per_pixel);
        let Some(previous) = reached.checked_sub(1).map(|i| series[i]) else {
            return Some(TimeToError {
                seconds: m.seconds,
                samples_per_pixel: spp,
                measured: true,
                exponent: fitted,
            });
        };
        // Between the last setting above the target and the first at or under it,
        // along the power law through the two.
        let previous_spp = f64::from(previous.knobs.samples_per_pixel);
        let exponent =
            (m.relative_error / previous.relative_error).ln() / (spp / previous_spp).ln();
        let samples = if exponent < 0.0 {
            (previous_spp * (target / previous.relative_error).powf(1.0 / exponent)).min(spp)
        } else {
            spp
        };
        return Some(TimeToError {
            seconds: m.seconds / spp * samples,
            samples_per_pixel: samples,
            measured: true,
            exponent,
        });
    }
    let exponent = match integrator {
        Integrator::Path => fitted.max(-0.5),
        Integrator::Whitted => fitted,
    };
    let samples = spp * (target / largest.relative_error).powf(1.0 / exponent);
    Some(TimeToError {
        seconds: largest.seconds / spp * samples,
        samples_per_pixel: samples,
        measured: false,
        exponent,
    })
}

/// Root-mean-square difference of the RGB channels of two images of the same size.
pub fn rmse(reference: &LinearImage, image: &LinearImage) -> f64 {
    let mut sum = 0.0;
    for (r, i) in reference.pixels.iter().zip(&image.pixels) {
        for c in 0..3 {
            let d = f64::from(i[c]) - f64::from(r[c]);
            sum += d * d;
        }
    }
    (sum / (3 * reference.pixels.len().max(1)) as f64).sqrt()
}

/// Mean FLIP error between two 8-bit sRGB RGBA images of `width × height`, at FLIP's
/// default viewing condition (67 pixels per degree: a 0.7 m wide 4K monitor seen from
/// 0.7 m).
pub fn mean_flip(reference_rgba8: &[u8], test_rgba8: &[u8], width: u32, height: u32) -> f64 {
    let rgb = |rgba: &[u8]| -> Vec<u8> {
        rgba.chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference_rgba8));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test_rgba8));
    let error_map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    f64::from(nv_flip::FlipPool::from_image(&error_map).mean())
}

/// Indices of the measurements on the Pareto fronts of (time, FLIP error), one front
/// per integrator: those that no other measurement of their integrator beats in both,
/// Whitted's first, each sorted by time.
pub fn pareto_front(measurements: &[Measurement]) -> Vec<usize> {
    [Integrator::Whitted, Integrator::Path]
        .into_iter()
        .flat_map(|integrator| {
            let indices: Vec<usize> = (0..measurements.len())
                .filter(|&i| measurements[i].knobs.integrator == integrator)
                .collect();
            front_of(measurements, indices)
        })
        .collect()
}

/// The Pareto front of the measurements `order` indexes.
fn front_of(measurements: &[Measurement], mut order: Vec<usize>) -> Vec<usize> {
    order.sort_by(|&a, &b| {
        measurements[a]
            .seconds
            .total_cmp(&measurements[b].seconds)
            .then(measurements[a].flip.total_cmp(&measurements[b].flip))
    });
    let mut front = Vec::new();
    let mut best_error = f64::INFINITY;
    for index in order {
        if measurements[index].flip < best_error {
            best_error = measurements[index].flip;
            front.push(index);
        }
    }
    front
}

/// The measurements as CSV, one row per setting, with a column marking the front.
pub fn to_csv(measurements: &[Measurement], front: &[usize]) -> String {
    let mut csv = String::from(
        "integrator,samples_per_pixel,max_depth,min_ray_weight,seconds,rays,rmse_linear,\
         relative_error,estimated_error,mean_flip,pareto\n",
    );
    for (index, m) in measurements.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.6},{},{:.6e},{:.6e},{},{:.6},{}",
            integrator_name(m.knobs.integrator),
            m.knobs.samples_per_pixel,
            m.knobs.max_depth,
            m.knobs.min_ray_weight,
            m.seconds,
            m.rays,
            m.rmse,
            m.relative_error,
            m.estimated_error
                .map_or_else(String::new, |e| format!("{e:.6e}")),
            m.flip,
            front.contains(&index)
        );
    }
    csv
}

/// The integrator's name in the scene format: `whitted` or `path`.
pub fn integrator_name(integrator: Integrator) -> &'static str {
    match integrator {
        Integrator::Whitted => "whitted",
        Integrator::Path => "path",
    }
}

/// A failure to draw or write the plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing failed.
    #[error("cannot draw the plot: {0}")]
    Draw(String),
    /// Writing the file failed.
    #[error(transparent)]
    Output(#[from] OutputError),
}

const PLOT_FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// The error a plot shows on its vertical axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorAxis {
    /// [`Measurement::flip`].
    Flip,
    /// [`Measurement::relative_error`], with a line at 1%.
    RelativeError,
}

impl ErrorAxis {
    fn of(self, m: &Measurement) -> f64 {
        match self {
            ErrorAxis::Flip => m.flip,
            ErrorAxis::RelativeError => m.relative_error,
        }
    }

    fn label(self) -> &'static str {
        match self {
            ErrorAxis::Flip => "mean FLIP error vs reference (log scale)",
            ErrorAxis::RelativeError => "relative RMSE of luminance vs reference (log scale)",
        }
    }
}

/// Colours of an integrator's settings and of its front.
fn series_colours(integrator: Integrator) -> (RGBColor, RGBColor) {
    match integrator {
        Integrator::Whitted => (RGBColor(150, 150, 150), RGBColor(220, 30, 30)),
        Integrator::Path => (RGBColor(120, 160, 220), RGBColor(20, 70, 200)),
    }
}

/// Draws time (log scale) against `axis`'s error (log scale) for every measurement,
/// each integrator in its own colours with its Pareto front (`front`, from
/// [`pareto_front`]) as a line, and writes it to the PNG file `path`.
pub fn plot_png(
    path: &Path,
    title: &str,
    measurements: &[Measurement],
    front: &[usize],
    axis: ErrorAxis,
) -> Result<(), PlotError> {
    let draw = |e: &dyn std::fmt::Display| PlotError::Draw(e.to_string());
    plotters::style::register_font("sans-serif", FontStyle::Normal, PLOT_FONT)
        .map_err(|_| PlotError::Draw("the bundled font is unreadable".into()))?;
    let (width, height) = (960u32, 640u32);
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    // Errors of exactly 0 (a setting equal to its reference) sit at the axis floor.
    let floor = 1e-4;
    let error = |m: &Measurement| axis.of(m).max(floor);
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw(&e))?;
        let max_time = measurements.iter().map(|m| m.seconds).fold(1e-3, f64::max);
        let min_time = measurements
            .iter()
            .map(|m| m.seconds)
            .fold(max_time, f64::min)
            .max(1e-4);
        let finite = measurements.iter().map(error).filter(|e| e.is_finite());
        let max_error = finite.clone().fold(floor * 10.0, f64::max);
        let mut min_error = finite.fold(max_error, f64::min);
        if axis == ErrorAxis::RelativeError {
            min_error = min_error.min(0.005);
        }
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (min_time * 0.8..max_time * 1.25).log_scale(),
                (min_error * 0.8..max_error * 1.25).log_scale(),
            )
            .map_err(|e| draw(&e))?;
        chart
            .configure_mesh()
            .x_desc("trace time (s, log scale)")
            .y_desc(axis.label())
            .x_labels(10)
            .x_label_formatter(&|seconds| format_seconds(*seconds))
            .y_label_formatter(&|error| format_error(*error))
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw(&e))?;
        if axis == ErrorAxis::RelativeError {
            chart
                .draw_series(LineSeries::new(
                    [(min_time * 0.8, 0.01), (max_time * 1.25, 0.01)],
                    BLACK.stroke_width(1),
                ))
                .map_err(|e| draw(&e))?
                .label("1% relative error")
                .legend(|(x, y)| PathElement::new([(x - 8, y), (x + 8, y)], BLACK));
        }
        for integrator in [Integrator::Whitted, Integrator::Path] {
            let name = integrator_name(integrator);
            let (dot, line) = series_colours(integrator);
            let series: Vec<&Measurement> = measurements
                .iter()
                .filter(|m| m.knobs.integrator == integrator && error(m).is_finite())
                .collect();
            if series.is_empty() {
                continue;
            }
            chart
                .draw_series(
                    series
                        .iter()
                        .map(|m| Circle::new((m.seconds, error(m)), 3, dot.filled())),
                )
                .map_err(|e| draw(&e))?
                .label(format!("{name}: setting"))
                .legend(move |(x, y)| Circle::new((x, y), 3, dot.filled()));
            let on_front: Vec<usize> = front
                .iter()
                .copied()
                .filter(|&i| measurements[i].knobs.integrator == integrator)
                .collect();
            let points: Vec<(f64, f64)> = on_front
                .iter()
                .map(|&i| (measurements[i].seconds, error(&measurements[i])))
                .collect();
            chart
                .draw_series(LineSeries::new(points, line.stroke_width(2)))
                .map_err(|e| draw(&e))?
                .label(format!("{name}: Pareto front (FLIP)"))
                .legend(move |(x, y)| {
                    PathElement::new([(x - 8, y), (x + 8, y)], line.stroke_width(2))
                });
            chart
                .draw_series(on_front.iter().map(|&i| {
                    let m = &measurements[i];
                    let label = format!(
                        "{} spp, d{}, w{}",
                        m.knobs.samples_per_pixel, m.knobs.max_depth, m.knobs.min_ray_weight
                    );
                    EmptyElement::at((m.seconds, error(m)))
                        + Circle::new((0, 0), 4, line.filled())
                        + Text::new(label, (6, -14), ("sans-serif", 12))
                }))
                .map_err(|e| draw(&e))?;
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| draw(&e))?;
        root.present().map_err(|e| draw(&e))?;
    }
    let rgba = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    output::write_png_rgba8(path, width, height, rgba)?;
    Ok(())
}

/// An error as a short axis label with two significant digits: "0.030", "0.0085".
fn format_error(error: f64) -> String {
    if !(error > 0.0 && error.is_finite()) {
        return format!("{error}");
    }
    let digits = (-error.log10().floor()).max(0.0) as usize + 1;
    format!("{error:.digits$}")
}

/// Seconds as a short axis label: "0.05", "0.5", "2".
fn format_seconds(seconds: f64) -> String {
    let digits = if seconds >= 1.0 {
        0
    } else {
        (-seconds.log10().floor()) as usize
    };
    format!("{seconds:.digits$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measurement(seconds: f64, flip: f64) -> Measurement {
        Measurement {
            knobs: Knobs {
                integrator: Integrator::Whitted,
                samples_per_pixel: 1,
                max_depth: 1,
                min_ray_weight: 0.0,
            },
            seconds,
            rays: 0,
            rmse: 0.0,
            relative_error: flip,
            estimated_error: None,
            flip,
        }
    }

    /// A path-traced setting of `spp` samples whose error is noise, `c/√spp`, and
    /// whose time is 0.1 s per sample.
    fn noisy(spp: u32, c: f64) -> Measurement {
        Measurement {
            knobs: Knobs {
                integrator: Integrator::Path,
                samples_per_pixel: spp,
                max_depth: 8,
                min_ray_weight: 0.0,
            },
            seconds: 0.1 * f64::from(spp),
            relative_error: c / f64::from(spp).sqrt(),
            ..measurement(0.0, 0.5)
        }
    }

    #[test]
    fn time_to_error_extrapolates_the_noise_law() {
        let series: Vec<Measurement> = [1, 4, 16, 64].map(|n| noisy(n, 2.0)).to_vec();
        // 2/√n = 0.01 at n = 40,000: 4,000 s.
        let t = time_to_error(&series, Integrator::Path, 0.01, 64).expect("a fit");
        assert!(!t.measured);
        assert!((t.exponent + 0.5).abs() < 1e-9, "{t:?}");
        assert!(
            (t.samples_per_pixel - 40_000.0).abs() < 1e-6 * 40_000.0,
            "{t:?}"
        );
        assert!((t.seconds - 4_000.0).abs() < 1e-6 * 4_000.0, "{t:?}");
        // Faster than 1/√spp (stratified edges): the path integrator's is taken as
        // −1/2, Whitted's as it is (spp^-1: 0.01 at 200 spp).
        let fast: Vec<Measurement> = [16, 64]
            .map(|n| Measurement {
                relative_error: 2.0 / f64::from(n),
                ..noisy(n, 0.0)
            })
            .to_vec();
        let path = time_to_error(&fast, Integrator::Path, 0.01, 64).expect("a fit");
        assert!((path.exponent + 0.5).abs() < 1e-12);
        assert!((path.samples_per_pixel - 64.0 * (0.01f64 / (2.0 / 64.0)).powf(-2.0)).abs() < 1e-6);
        let whitted: Vec<Measurement> = fast
            .iter()
            .map(|m| Measurement {
                knobs: Knobs {
                    integrator: Integrator::Whitted,
                    ..m.knobs
                },
                ..*m
            })
            .collect();
        let whitted = time_to_error(&whitted, Integrator::Whitted, 0.01, 64).expect("a fit");
        assert!((whitted.exponent + 1.0).abs() < 1e-12);
        assert!(
            (whitted.samples_per_pixel - 200.0).abs() < 1e-6,
            "{whitted:?}"
        );
        // Crossed between 16 (0.5) and 64 spp (0.25): 2/√n = 0.3 at n = 44.4.
        let reached = time_to_error(&series, Integrator::Path, 0.3, 64).expect("a fit");
        assert!(reached.measured);
        let crossing = (2.0f64 / 0.3).powi(2);
        assert!(
            (reached.samples_per_pixel - crossing).abs() < 1e-9,
            "{reached:?}"
        );
        assert!(
            (reached.seconds - 0.1 * crossing).abs() < 1e-9,
            "{reached:?}"
        );
        // Reached by the first setting: its own figure.
        let first = time_to_error(&series, Integrator::Path, 3.0, 64).expect("a fit");
        assert_eq!(first.samples_per_pixel, 1.0);
        // Settings above max_spp are left out; one setting is no fit.
        assert!(time_to_error(&series, Integrator::Path, 0.01, 1).is_none());
        assert!(time_to_error(&series, Integrator::Whitted, 0.01, 64).is_none());
    }

    #[test]
    fn error_labels_are_short() {
        assert_eq!(format_error(0.03), "0.030");
        assert_eq!(format_error(0.0085), "0.0085");
        assert_eq!(format_error(0.5), "0.50");
        assert_eq!(format_error(2.0), "2.0");
    }

    #[test]
    fn each_integrator_has_its_own_front() {
        let points = [
            measurement(1.0, 0.5),
            noisy(1, 0.9), // path: on its own front, whatever Whitted does
            measurement(3.0, 0.2),
        ];
        assert_eq!(pareto_front(&points), vec![0, 2, 1]);
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let points = [
            measurement(1.0, 0.5),
            measurement(2.0, 0.6), // dominated by the first
            measurement(3.0, 0.2),
            measurement(0.5, 0.9),
            measurement(4.0, 0.2), // as good, but slower
        ];
        assert_eq!(pareto_front(&points), vec![3, 0, 2]);
    }

    #[test]
    fn identical_images_have_zero_error() {
        let mut image = LinearImage::new(16, 8);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            *p = [i as f32 / 128.0, 0.5, 0.25, 1.0];
        }
        assert_eq!(rmse(&image, &image), 0.0);
        let display = image.to_display_rgba8(true);
        assert!(mean_flip(&display, &display, 16, 8) < 1e-6);
        let mut darker = image.clone();
        darker.pixels.iter_mut().for_each(|p| p[0] *= 0.5);
        assert!(rmse(&image, &darker) > 0.0);
        assert!(mean_flip(&display, &darker.to_display_rgba8(true), 16, 8) > 0.0);
    }

    #[test]
    fn plot_and_csv_are_written() {
        let dir = tempfile::tempdir().expect("temp dir");
        let points = [measurement(0.1, 0.3), measurement(0.4, 0.1)];
        let front = pareto_front(&points);
        for axis in [ErrorAxis::Flip, ErrorAxis::RelativeError] {
            let points = [points[0], points[1], noisy(4, 1.0)];
            plot_png(&dir.path().join("plot.png"), "test", &points, &front, axis).expect("plot");
            let plot = image::open(dir.path().join("plot.png")).expect("a PNG");
            assert_eq!((plot.width(), plot.height()), (960, 640));
        }
        let csv = to_csv(&points, &front);
        assert_eq!(csv.lines().count(), 3);
        assert!(
            csv.lines()
                .nth(2)
                .is_some_and(|l| l.starts_with("whitted,") && l.ends_with(",true"))
        );
    }
}
