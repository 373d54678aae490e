// The per-pixel noise estimate: Welford's running sum of squared deviations of the
// samples' luminance, kept beside each pixel's sample sum. Twin of src/noise.rs (the
// derivation and sources are there): B. P. Welford, Technometrics 4(3), 1962; Knuth,
// TAOCP vol. 2, 3rd ed., §4.2.2, eq. 15-16.

#import color

// Welford's update of a pixel's m2 for its sample number `index` (0-based) of
// luminance `sample_luminance`, the running means taken from the radiance sums before and
// after the sample: m2 += (y - mean_before)(y - mean_after).
fn luminance_m2_step(m2: f32, sum_before: vec3<f32>, sum_after: vec3<f32>,
                     sample_luminance: f32, index: u32) -> f32 {
    var mean_before = 0.0;
    if index > 0u {
        mean_before = luminance(sum_before) / f32(index);
    }
    let mean_after = luminance(sum_after) / (f32(index) + 1.0);
    return m2 + (sample_luminance - mean_before) * (sample_luminance - mean_after);
}
