//! Measuring the speed/accuracy trade: render a converged reference, sweep the knobs
//! that trade one for the other (samples per pixel, maximum depth, ray-weight cutoff),
//! and measure each setting's time and its error against the reference, in linear
//! RMSE and in FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating
//! Images", HPG 2020), then find the Pareto front of time versus error.
//!
//! Every figure comes from images rendered in the run; nothing is tabulated by hand.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::film::LinearImage;
use crate::output::{self, OutputError};

/// One setting of the speed/accuracy knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knobs {
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
    /// Mean FLIP error of the 8-bit display image against the reference's (0 = same).
    pub flip: f64,
}

/// The default sweep: every combination of 1–16 samples, depth 1–8 and cutoffs 0,
/// 0.05 and 0.2 (60 settings).
pub fn default_sweep() -> Vec<Knobs> {
    let mut knobs = Vec::new();
    for samples_per_pixel in [1, 2, 4, 8, 16] {
        for max_depth in [1, 2, 4, 8] {
            for min_ray_weight in [0.0, 0.05, 0.2] {
                knobs.push(Knobs {
                    samples_per_pixel,
                    max_depth,
                    min_ray_weight,
                });
            }
        }
    }
    knobs
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

/// Indices of the measurements on the Pareto front of (time, FLIP error): those that
/// no other measurement beats in both, sorted by time.
pub fn pareto_front(measurements: &[Measurement]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..measurements.len()).collect();
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
        "samples_per_pixel,max_depth,min_ray_weight,seconds,rays,rmse_linear,mean_flip,pareto\n",
    );
    for (index, m) in measurements.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{},{},{},{:.6},{},{:.6e},{:.6},{}",
            m.knobs.samples_per_pixel,
            m.knobs.max_depth,
            m.knobs.min_ray_weight,
            m.seconds,
            m.rays,
            m.rmse,
            m.flip,
            front.contains(&index)
        );
    }
    csv
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

/// Draws time (log scale) against mean FLIP error for every measurement, the Pareto
/// front as a line, and writes it to the PNG file `path`.
pub fn plot_png(
    path: &Path,
    title: &str,
    measurements: &[Measurement],
    front: &[usize],
) -> Result<(), PlotError> {
    let draw = |e: &dyn std::fmt::Display| PlotError::Draw(e.to_string());
    plotters::style::register_font("sans-serif", FontStyle::Normal, PLOT_FONT)
        .map_err(|_| PlotError::Draw("the bundled font is unreadable".into()))?;
    let (width, height) = (960u32, 640u32);
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw(&e))?;
        let max_time = measurements.iter().map(|m| m.seconds).fold(1e-3, f64::max);
        let min_time = measurements
            .iter()
            .map(|m| m.seconds)
            .fold(max_time, f64::min)
            .max(1e-4);
        let max_error = measurements.iter().map(|m| m.flip).fold(1e-3, f64::max);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (min_time * 0.8..max_time * 1.25).log_scale(),
                0.0..max_error * 1.1,
            )
            .map_err(|e| draw(&e))?;
        chart
            .configure_mesh()
            .x_desc("trace time (s, log scale)")
            .y_desc("mean FLIP error vs reference")
            .x_labels(10)
            .x_label_formatter(&|seconds| format_seconds(*seconds))
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| draw(&e))?;
        chart
            .draw_series(
                measurements
                    .iter()
                    .map(|m| Circle::new((m.seconds, m.flip), 3, RGBColor(150, 150, 150).filled())),
            )
            .map_err(|e| draw(&e))?
            .label("setting")
            .legend(|(x, y)| Circle::new((x, y), 3, RGBColor(150, 150, 150).filled()));
        let front_points: Vec<(f64, f64)> = front
            .iter()
            .map(|&i| (measurements[i].seconds, measurements[i].flip))
            .collect();
        chart
            .draw_series(LineSeries::new(front_points.clone(), RED.stroke_width(2)))
            .map_err(|e| draw(&e))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new([(x - 8, y), (x + 8, y)], RED.stroke_width(2)));
        chart
            .draw_series(front.iter().map(|&i| {
                let m = &measurements[i];
                let label = format!(
                    "{} spp, d{}, w{}",
                    m.knobs.samples_per_pixel, m.knobs.max_depth, m.knobs.min_ray_weight
                );
                EmptyElement::at((m.seconds, m.flip))
                    + Circle::new((0, 0), 4, RED.filled())
                    + Text::new(label, (6, -14), ("sans-serif", 12))
            }))
            .map_err(|e| draw(&e))?;
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
                samples_per_pixel: 1,
                max_depth: 1,
                min_ray_weight: 0.0,
            },
            seconds,
            rays: 0,
            rmse: 0.0,
            flip,
        }
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
        plot_png(&dir.path().join("plot.png"), "test", &points, &front).expect("plot");
        let plot = image::open(dir.path().join("plot.png")).expect("a PNG");
        assert_eq!((plot.width(), plot.height()), (960, 640));
        let csv = to_csv(&points, &front);
        assert_eq!(csv.lines().count(), 3);
        assert!(csv.lines().nth(2).is_some_and(|l| l.ends_with(",true")));
    }
}
